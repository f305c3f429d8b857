//! The distance maps in front of the orthtree, seen through a grown cluster.

use dla_pdla::space::{Dim, Space};
use dla_pdla::{Params, Simulation};

/// Asserts that the walker's bound from the maps never exceeds the exact distance to the
/// nearest particle (brute force), at 4000 random points around a grown cluster, and that the
/// maps answer at most of them.
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
    if threads == 1 {
        assert!(cluster.maps().iter().all(|m| m.len() == n));
    }
    let pos = sim.positions().unwrap();
    let r = sim.r_ext() + 80.0;
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
    }
    assert!(
        used > 3000,
        "the maps cover the birth region ({used} of 4000)"
    );
}

/// After serial growth and after PDLA (shared maps lowered by both threads).
#[test]
fn map_bound_is_below_the_exact_distance() {
    bound_is_below_exact::<2>(3000, 1);
    bound_is_below_exact::<3>(1500, 1);
    bound_is_below_exact::<2>(3000, 2);
    bound_is_below_exact::<3>(1500, 2);
}
