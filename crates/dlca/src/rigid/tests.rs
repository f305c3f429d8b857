//! Unit tests of the rigid-cluster kernels: frame arithmetic and the dimension dispatch. The
//! store's trajectories are checked against all-pairs in `tests/strategies.rs`.

use super::frame::{AnyFrame, Frame, Pow2Frame, SpreadFrame};
use super::geometry::Geometry;
use super::{RigidError, RigidStore};
use core_lattice::{Boundary, Lattice};
use spatial::lattice::SiteSets;

/// From every origin, every relative position a particle can have (`[0, L)` per axis) and every
/// one a probe can have (one step further either way): the power-of-two frame's field-wise sum
/// gives the site index the general frame and the full modular reduction give, with the plain
/// site index (the k-index) and with the spread one.
fn frames_agree<const D: usize>(sizes: [u64; D]) {
    let lattice = Lattice::periodic(&sizes).unwrap();
    let geo = Geometry::<D>::new(&lattice);
    let pow2 = <Pow2Frame as Frame<D>>::new(&geo).expect("periodic powers of two");
    frames_agree_with(&lattice, &geo, pow2);
    let spread = Geometry::<D>::spread(&lattice).expect("periodic powers of two");
    assert!(<Pow2Frame as Frame<D>>::new(&spread).is_none());
    let frame = <SpreadFrame as Frame<D>>::new(&spread).expect("a spread index");
    frames_agree_with(&lattice, &spread, frame);
    // The spread index is one-to-one, in order, below its volume, and converts both ways.
    let mut last = None;
    for k in 0..lattice.volume() {
        let x = lattice.coords_array(k);
        let o: [i64; D] = std::array::from_fn(|a| x[a] as i64);
        let i = spread.site(&o, &[0; D]);
        assert!(
            last < Some(i) && (i as u64) < spread.volume,
            "site {k}: index {i}"
        );
        assert_eq!(spread.index_of(k), i);
        assert_eq!(spread.lattice_site(&o, &[0; D]), k);
        last = Some(i);
    }
}

fn frames_agree_with<const D: usize, F: Frame<D>>(lattice: &Lattice, geo: &Geometry<D>, pow2: F) {
    let sizes = lattice.sizes();
    let any = <AnyFrame as Frame<D>>::new(geo).expect("applies everywhere");
    let span: Vec<i64> = sizes.iter().map(|&l| l as i64 + 2).collect();
    for k in 0..lattice.volume() {
        let x = lattice.coords_array(k);
        let o: [i64; D] = std::array::from_fn(|a| x[a] as i64);
        let (po, ao) = (pow2.origin(geo, &o), any.origin(geo, &o));
        for i in 0..span.iter().product::<i64>() {
            let mut rest = i;
            let r: [i32; D] = std::array::from_fn(|a| {
                let c = rest % span[a] - 1;
                rest /= span[a];
                c as i32
            });
            let want = geo.any(&o, &r).expect("periodic");
            let (pe, ae) = (pow2.entry(geo, &r), any.entry(geo, &r));
            let what = format!("origin {o:?}, relative {r:?}");
            assert_eq!(pow2.probe(geo, po, pe), Some(want), "{what}");
            assert_eq!(any.probe(geo, ao, ae), Some(want), "{what}");
            if (0..D).all(|a| r[a] >= 0 && i64::from(r[a]) < sizes[a] as i64) {
                assert_eq!(pow2.site(geo, po, pe), want, "{what}");
                assert_eq!(any.site(geo, ao, ae), want, "{what}");
            }
        }
    }
}

#[test]
fn power_of_two_frame_gives_the_general_frames_k_index() {
    frames_agree([1]);
    frames_agree([8]);
    frames_agree([2, 4]);
    frames_agree([8, 1]);
    frames_agree([4, 2, 4]);
}

fn store_for(sizes: &[u64], boundary: Boundary) -> Result<RigidStore, RigidError> {
    let lattice = Lattice::new(sizes, &vec![boundary; sizes.len()]).unwrap();
    let mut sets = SiteSets::new(lattice);
    sets.push(vec![0]);
    RigidStore::new(&sets)
}

#[test]
fn dispatch_picks_the_frame_and_refuses_other_dimensions_with_a_typed_error() {
    use Boundary::{Periodic, Wall};
    assert!(matches!(store_for(&[16], Periodic), Ok(RigidStore::S1(_))));
    assert!(matches!(
        store_for(&[1024, 4], Periodic),
        Ok(RigidStore::S2(_))
    ));
    assert!(matches!(
        store_for(&[4, 1024], Periodic),
        Ok(RigidStore::P2(_))
    ));
    assert!(matches!(
        store_for(&[8, 4], Periodic),
        Ok(RigidStore::P2(_))
    ));
    assert!(matches!(
        store_for(&[8, 6], Periodic),
        Ok(RigidStore::D2(_))
    ));
    assert!(matches!(store_for(&[8, 4], Wall), Ok(RigidStore::D2(_))));
    assert!(matches!(
        store_for(&[4, 4, 4], Periodic),
        Ok(RigidStore::P3(_))
    ));
    assert!(matches!(store_for(&[5, 4, 4], Wall), Ok(RigidStore::D3(_))));
    assert_eq!(
        store_for(&[4; 4], Periodic).unwrap_err(),
        RigidError::Dimension(4)
    );
    assert_eq!(
        store_for(&[3; 5], Wall).unwrap_err(),
        RigidError::Dimension(5)
    );
    let long = super::MAX_SIDE + 1;
    assert_eq!(
        store_for(&[long], Wall).unwrap_err(),
        RigidError::Side(long)
    );
}
