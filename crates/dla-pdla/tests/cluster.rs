//! The distance maps in front of the orthtree, seen through a grown cluster.

use dla_pdla::space::{Dim, Space};
use dla_pdla::{Params, Simulation};
use spatial::distmap::PointMap;

/// Asserts that the walker's bound from the maps never exceeds the exact distance to the
/// nearest particle (brute force), and their upper bound is never below it, at 4000 random
/// points around a grown cluster, and that the maps answer at most of them.
fn bound_is_below_exact<const D: usize>(n: u64, threads: usize)
where
    Dim<D>: Space<D>,
{
    let params = Params {
        dim: D,
        particles: n,
        threads,
        keep_positions: true,
        ..Params::default()
    };
    let mut sim = Simulation::<D>::new(params, 5).unwrap();
    sim.run().unwrap();
    let cluster = sim.cluster();
    assert_eq!(cluster.maps().len(), Dim::<D>::MAP_LEVELS.len());
    let pos = sim.positions().unwrap();
    if threads == 1 {
        // The finest map holds every particle, the coarser ones the box of every leaf, or
        // (2D's coarsest two) every sub-box of their cells that holds a leaf.
        assert_eq!(cluster.maps()[0].len(), n);
        let leaves = cluster.tree().leaf_count() as u64;
        let s = cluster.tree().leaf_side();
        for m in &cluster.maps()[1..] {
            let boxes = if m.sub_boxes() == 0 {
                leaves
            } else {
                let side = m.cell_side() / m.sub_boxes() as f64;
                let held: std::collections::HashSet<[i64; D]> = pos
                    .iter()
                    .map(|q| q.map(|x| (((x / s).floor() + 0.5) * s / side).floor() as i64))
                    .collect();
                assert!((held.len() as u64) < leaves);
                held.len() as u64
            };
            assert_eq!(
                m.len(),
                boxes,
                "{D}D: inserts into the map of {} cells",
                m.cell_side()
            );
        }
    }
    // In 4D and 5D nearly all of a wide cube's volume lies in corners beyond the maps' reach
    // (which is at least their cap and cell beyond every particle).
    let r = sim.r_ext() + if D <= 3 { 80.0 } else { 10.0 };
    let mut rng = core_lattice::rng::stream(9, 0);
    let mut used = 0;
    for _ in 0..4000 {
        let mut p = [0.0; D];
        for x in &mut p {
            *x = (2.0 * core_lattice::rng::uniform01(&mut rng) - 1.0) * r;
        }
        let exact = pos
            .iter()
            .map(|q| (0..D).map(|i| (p[i] - q[i]).powi(2)).sum::<f64>().sqrt())
            .fold(f64::INFINITY, f64::min);
        if let Some((lb, _)) = cluster.map_bound(&p) {
            assert!(
                lb <= exact,
                "{D}D: map bound {lb} above exact {exact} at {p:?}"
            );
            used += 1;
        }
        if let Some((lb, ub, _)) = cluster.map_bounds(&p) {
            assert!(
                lb <= exact && exact <= ub,
                "{D}D: {lb} <= {exact} <= {ub} fails"
            );
        }
    }
    assert!(
        used > 3000,
        "the maps cover the birth region ({used} of 4000)"
    );
    // Near the cluster, where the sparse fine map (3D) answers: probes up to 10 diameters
    // from a random particle.
    let mut fine = 0;
    for _ in 0..2000 {
        let a = pos[(core_lattice::rng::uniform01(&mut rng) * pos.len() as f64) as usize];
        let mut p = a;
        for x in &mut p {
            *x += (2.0 * core_lattice::rng::uniform01(&mut rng) - 1.0) * 10.0 / (D as f64).sqrt();
        }
        let exact = pos
            .iter()
            .map(|q| (0..D).map(|i| (p[i] - q[i]).powi(2)).sum::<f64>().sqrt())
            .fold(f64::INFINITY, f64::min);
        if let Some((lb, ub, capped)) = cluster.map_bounds(&p) {
            assert!(
                lb <= exact && exact <= ub,
                "{D}D near: {lb} <= {exact} <= {ub} fails"
            );
            if !capped && ub - lb < 4.0 {
                fine += 1;
            }
        }
    }
    if let Some(sparse) = cluster.sparse_map() {
        assert!(
            fine > 1000,
            "{D}D: the sparse map answers near the cluster ({fine})"
        );
        if threads == 1 {
            assert_eq!(sparse.len(), n);
        }
    }
}

/// After serial growth and after PDLA (shared maps lowered by both threads), in 2D and 3D
/// (two maps, the coarser one holding leaf boxes; 3D also the sparse fine map in front) and
/// 4D and 5D (one map).
#[test]
fn map_bound_is_below_the_exact_distance() {
    bound_is_below_exact::<2>(3000, 1);
    bound_is_below_exact::<3>(1500, 1);
    bound_is_below_exact::<2>(3000, 2);
    bound_is_below_exact::<3>(1500, 2);
    bound_is_below_exact::<4>(600, 1);
    bound_is_below_exact::<5>(300, 1);
}
