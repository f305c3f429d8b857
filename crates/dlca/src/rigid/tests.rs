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

/// Large clusters moved a word at a time ([`RowMoves::Always`]) and by their faces
/// ([`RowMoves::Never`]) give the same store: the same moves blocked, the same contacts after
/// every move, consistent occupancy bits, members and lists (the store's check) after every
/// move, and the same particles at the end. On lattices whose rows are one word, several words
/// and sixteen words (the spread index), and whose rows start anywhere in a word (first sides
/// that are not multiples of 64), with periodic and walled axes in 1 to 3 dimensions, so that
/// images wrap around their rows and around the other axes.
#[test]
fn moves_by_rows_match_moves_by_faces() {
    use super::RowMoves;
    use Boundary::{Periodic as P, Wall as W};
    use core_lattice::Direction;
    use core_lattice::rng::{RngExt, stream};
    let cases: [(&[u64], &[Boundary]); 12] = [
        (&[512], &[P]),
        (&[64, 32], &[P, P]),
        (&[192, 24], &[P, W]),
        (&[128, 24], &[W, P]),
        (&[1024, 4], &[P, P]),
        (&[64, 8, 8], &[P, P, W]),
        (&[64, 8, 8], &[W, P, P]),
        // Rows at any bit position: first sides that are not multiples of 64.
        (&[300], &[P]),
        (&[100, 30], &[P, P]),
        (&[70, 24], &[W, P]),
        (&[130, 20], &[P, W]),
        (&[96, 8, 8], &[P, W, P]),
    ];
    for (case, &(sizes, boundary)) in cases.iter().enumerate() {
        let lattice = Lattice::new(sizes, boundary).unwrap();
        let mut rng = stream(45, case as u64);
        // Two random connected clusters of 80 particles (large: at least 64), then single
        // particles on sites of even coordinates; no two clusters touch.
        let volume = lattice.volume();
        let mut owner = vec![usize::MAX; volume as usize];
        let free_for = |owner: &[usize], k: u64, c: usize| {
            owner[k as usize] == usize::MAX
                && lattice
                    .neighbours(k)
                    .all(|n| [usize::MAX, c].contains(&owner[n as usize]))
        };
        let mut clusters: Vec<Vec<u64>> = Vec::new();
        while clusters.len() < 2 {
            let c = clusters.len();
            let seed = rng.random_range(0..volume);
            if !free_for(&owner, seed, c) {
                continue;
            }
            let mut sites = vec![seed];
            owner[seed as usize] = c;
            for _ in 0..100_000 {
                if sites.len() == 80 {
                    break;
                }
                let from = sites[rng.random_range(0..sites.len())];
                let dir = Direction::from_index(rng.random_range(0..2 * sizes.len()));
                if let Some(k) = lattice.neighbour(from, dir)
                    && free_for(&owner, k, c)
                {
                    owner[k as usize] = c;
                    sites.push(k);
                }
            }
            clusters.push(sites);
        }
        for k in 0..volume {
            let x = lattice.coords_array(k);
            let c = clusters.len();
            if x.iter().all(|&c| c % 2 == 0) && free_for(&owner, k, c) && rng.random_bool(0.5) {
                owner[k as usize] = c;
                clusters.push(vec![k]);
            }
        }
        let placed: usize = clusters.iter().map(Vec::len).sum();
        let mut sets = SiteSets::new(lattice.clone());
        for c in clusters {
            sets.push(c);
        }
        let mut stores = [
            RigidStore::new(&sets).unwrap(),
            RigidStore::new(&sets).unwrap(),
        ];
        stores[0].set_row_moves(RowMoves::Always);
        stores[1].set_row_moves(RowMoves::Never);
        let (mut out, mut other) = (Vec::new(), Vec::new());
        let mut large_moves = 0;
        for step in 0..3000 {
            let live = stores[0].live();
            if live.len() == 1 {
                break;
            }
            // Half the moves are the largest cluster's.
            let id = if rng.random_bool(0.5) {
                *live.iter().max_by_key(|&&id| stores[0].len_of(id)).unwrap()
            } else {
                live[rng.random_range(0..live.len())]
            };
            let dir = Direction::from_index(rng.random_range(0..2 * sizes.len()));
            large_moves += usize::from(stores[0].len_of(id) >= 64);
            let a = stores[0].try_move(id, dir, &mut out);
            let b = stores[1].try_move(id, dir, &mut other);
            assert_eq!(a, b, "case {case} step {step}");
            assert_eq!(out, other, "case {case} step {step}: contacts");
            if !out.is_empty() {
                let mut group = out.clone();
                group.push(id);
                group.sort_unstable();
                for s in &mut stores {
                    for &from in &group[1..] {
                        s.merge(group[0], from);
                    }
                    s.finish(group[0]);
                }
            }
            stores[0].check();
        }
        stores[1].check();
        assert!(
            large_moves > 500,
            "case {case}: {large_moves} moves of large clusters of {placed} particles"
        );
        let [a, b] = &stores;
        let sites = |s: &RigidStore| {
            let sets = s.to_sets();
            let mut v: Vec<Vec<u64>> = sets
                .live()
                .iter()
                .map(|&id| sets.sites(id).to_vec())
                .collect();
            v.iter_mut().for_each(|c| c.sort_unstable());
            v.sort();
            v
        };
        assert_eq!(sites(a), sites(b), "case {case}");
    }
}
