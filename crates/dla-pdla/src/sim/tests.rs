//! Unit tests of the walk on a grown cluster that need the crate's private walker memory.

use super::*;
use crate::walker::WalkState;
use core_lattice::rng::stream;

/// Walkers on a grown cluster: the number of moves after which the walker's near cache is
/// built and holds the walker.
fn cached_moves<const D: usize>(precision: f64) -> usize
where
    Dim<D>: Space<D>,
{
    let params = Params {
        dim: D,
        particles: 1500,
        precision,
        ..Params::default()
    };
    let mut sim = Simulation::<D>::new(params.clone(), 4).unwrap();
    sim.run().unwrap();
    let mut state = WalkState::<D>::new(&params);
    let mut rng = stream(9, 0);
    let mut live = 0;
    for _ in 0..20 {
        let mut w = Walker::born(sim.growth.r_ext + params.birth_gap, &mut rng);
        state.reset();
        while w
            .advance::<false, _>(
                &mut state,
                &sim.cluster,
                sim.growth.r_ext,
                &params,
                &mut rng,
            )
            .is_none()
        {
            live += usize::from(state.cache_holds(&w.p));
        }
    }
    live
}

#[test]
fn near_cache_is_used_only_where_the_tree_is_exact() {
    // Default precision: (2 - 1/2) leaf diagonals cover the cache's radius.
    assert!(cached_moves::<2>(2.0) > 0);
    assert!(cached_moves::<3>(2.0) > 0);
    // kappa 0.8: exact only within 0.3 leaf diagonals (3.4 in 2D, 4.2 in 3D), less than
    // the radius: the cache must stay off.
    assert_eq!(cached_moves::<2>(0.8), 0);
    assert_eq!(cached_moves::<3>(0.8), 0);
}

/// A PDLA phase whose shared tree runs out of room (here a root reserved far too small) ends at
/// a quiescent point and the next phase reserves more: the run completes with several phases
/// and a valid cluster (every particle touching an earlier one, none overlapping).
#[test]
fn pdla_phases_that_run_out_of_room_continue_in_the_next() {
    pdla::FIRST_RADIUS_IN_TESTS.set(0.0);
    let params = Params {
        particles: 3000,
        threads: 2,
        keep_positions: true,
        ..Params::default()
    };
    let mut sim = Simulation::<2>::new(params, 5).unwrap();
    sim.run().unwrap();
    pdla::FIRST_RADIUS_IN_TESTS.set(1.25);
    assert!(sim.pdla_phases() >= 3, "{} phases", sim.pdla_phases());
    let pos = sim.positions().unwrap();
    assert_eq!(pos.len(), 3000);
    assert_eq!(sim.tree().len(), 3000);
    for (i, p) in pos.iter().enumerate() {
        let mut close = 0;
        sim.tree()
            .for_each_within(p, OVERLAP_DISTANCE, |_| close += 1);
        assert_eq!(close, 1, "particle {i} overlaps another");
        if i > 0 {
            let touches = pos[..i]
                .iter()
                .any(|q| spatial::orthtree::dist_sq(p, q).sqrt() <= 1.0 + 1e-6);
            assert!(touches, "particle {i} touches no earlier particle");
        }
    }
}
