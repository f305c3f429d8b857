//! Every contact search gives the same trajectory (docs/dlca.md, "The search strategies"), the
//! same seed gives the same run, and the model's invariants hold after every move.

use core_lattice::Boundary;
use core_lattice::rng::{RngExt, stream};
use dlca::{Init, Params, Search, Simulation};

/// 24 random configurations: d = 1..5, periodic and walled axes, with and without gravity,
/// mobility exponent and temperature below 1. Small enough for all-pairs.
fn configs() -> Vec<Params> {
    let mut rng = stream(2006, 0);
    (0..24)
        .map(|i| {
            let dim = 1 + i % 5;
            let max_side = [0, 300, 40, 14, 8, 6][dim];
            let size: Vec<u64> = (0..dim).map(|_| rng.random_range(3..=max_side)).collect();
            let boundary: Vec<Boundary> = (0..dim)
                .map(|_| {
                    if rng.random_bool(0.35) {
                        Boundary::Wall
                    } else {
                        Boundary::Periodic
                    }
                })
                .collect();
            Params {
                size,
                boundary,
                init: Init::Fill(rng.random_range(0.02..0.15)),
                temperature: if i % 4 == 3 { 0.6 } else { 1.0 },
                gravity: if i % 3 == 1 {
                    rng.random_range(0.1..0.9)
                } else {
                    0.0
                },
                mobility_exponent: if i % 4 == 2 {
                    rng.random_range(0.2..1.5)
                } else {
                    0.0
                },
                target_clusters: 1 + (i as u64 % 3),
                max_sweeps: Some(400),
                ..Params::default()
            }
        })
        .collect()
}

struct Outcome {
    hash: String,
    series: Vec<(u64, u64, u64)>,
    events: Vec<String>,
}

fn run(params: &Params, seed: u64, search: Search, grid_box: Option<u64>, checks: bool) -> Outcome {
    let p = Params {
        search,
        grid_box,
        ..params.clone()
    };
    let mut sim = Simulation::new(p, seed)
        .unwrap()
        .with_invariant_checks(checks);
    sim.run();
    Outcome {
        hash: sim.state_hash(),
        series: sim
            .records()
            .sweeps()
            .iter()
            .map(|r| (r.sweep, r.clusters, r.largest))
            .collect(),
        events: sim.events().iter().map(|e| e.what.clone()).collect(),
    }
}

#[test]
fn every_strategy_gives_the_same_trajectory() {
    let mut doublings = 0;
    let mut fallbacks = 0;
    let mut merged_to_target = 0;
    for (i, params) in configs().iter().enumerate() {
        for seed in [1, 2] {
            // The reference run also checks every invariant after every move.
            let reference = run(params, seed, Search::AllPairs, None, true);
            let mut others = vec![
                ("grid", run(params, seed, Search::Grid, None, false)),
                (
                    "grid-doubling",
                    run(params, seed, Search::GridDoubling, None, false),
                ),
                ("lattice", run(params, seed, Search::Lattice, None, true)),
                ("auto", run(params, seed, Search::Auto, None, false)),
            ];
            // A given box must split the lattice (3A < the shortest side); the grid's own
            // choice (None above) may still start in the all-pairs fallback.
            let shortest = params.size.iter().copied().min().unwrap();
            for (name, search, a) in [
                ("grid A=1", Search::Grid, 1),
                ("grid A=2", Search::Grid, 2),
                ("grid-doubling A=1", Search::GridDoubling, 1),
                ("grid-doubling A=2", Search::GridDoubling, 2),
            ] {
                if 3 * a < shortest {
                    others.push((name, run(params, seed, search, Some(a), false)));
                }
            }
            for (name, o) in &others {
                assert_eq!(
                    o.hash, reference.hash,
                    "config {i} seed {seed}: {name} differs from all-pairs ({params:?})"
                );
                assert_eq!(
                    o.series, reference.series,
                    "config {i} seed {seed}: {name} cluster series differs"
                );
                doublings += o.events.iter().filter(|e| e.contains("doubled")).count();
                fallbacks += o.events.iter().filter(|e| e.contains("all-pairs")).count();
            }
            let last = reference.series.last().unwrap();
            if last.1 <= params.target_clusters {
                merged_to_target += 1;
            }
            // Clusters only merge: the count never rises, the largest never shrinks.
            for w in reference.series.windows(2) {
                assert!(w[1].1 <= w[0].1 && w[1].2 >= w[0].2);
            }
        }
    }
    // The doubling grid's doubling and its fall-back to all-pairs were exercised, and most runs
    // actually aggregated to their target.
    assert!(doublings > 5, "only {doublings} grid doublings");
    assert!(fallbacks > 5, "only {fallbacks} fall-backs to all-pairs");
    assert!(
        merged_to_target > 30,
        "only {merged_to_target} of 48 runs reached their target"
    );
}

#[test]
fn invariants_hold_with_gravity_walls_and_dense_fill() {
    let params = Params {
        size: vec![24, 16],
        boundary: vec![Boundary::Periodic, Boundary::Wall],
        init: Init::Fill(0.3),
        gravity: 0.5,
        target_clusters: 1,
        max_sweeps: Some(300),
        ..Params::default()
    };
    for search in [Search::Lattice, Search::Grid, Search::GridDoubling] {
        let mut sim = Simulation::new(
            Params {
                search,
                ..params.clone()
            },
            9,
        )
        .unwrap()
        .with_invariant_checks(true);
        sim.run();
        assert!(sim.clusters() >= 1);
        assert_eq!(sim.sets().total_sites(), sim.particles());
    }
}

#[test]
fn same_seed_same_run_different_seed_different_run() {
    let params = Params {
        size: vec![64, 64],
        init: Init::Fill(0.05),
        target_clusters: 5,
        ..Params::default()
    };
    let a = run(&params, 7, Search::Auto, None, false);
    let b = run(&params, 7, Search::Auto, None, false);
    let c = run(&params, 8, Search::Auto, None, false);
    assert_eq!(a.hash, b.hash);
    assert_eq!(a.series, b.series);
    assert_ne!(a.hash, c.hash);
}

#[test]
fn initial_adjacent_particles_form_one_cluster() {
    // A dense fill: many particles start face-adjacent and must start merged.
    let params = Params {
        size: vec![20, 20],
        init: Init::Fill(0.4),
        max_sweeps: Some(0),
        ..Params::default()
    };
    let sim = Simulation::new(params, 3)
        .unwrap()
        .with_invariant_checks(true);
    assert_eq!(sim.particles(), 160);
    assert!(sim.clusters() < 160, "no particles merged at the start");
    assert!(sim.largest() > 1);
}

#[test]
fn power_of_two_periodic_lattices_match_all_pairs() {
    // All-periodic power-of-two lattices take the lattice strategy's bit-field frames in 1D to
    // 3D (4D and 5D use the plain occupancy lattice): the spread site index in 1D and where the
    // first side is 1 024 or more, else the field-wise sum; sides of 1 and 2 are the edge cases
    // of their field arithmetic.
    let sizes: [&[u64]; 8] = [
        &[256],
        &[1024, 2],
        // Large enough for clusters of more than 64 particles absorbing small ones (parts).
        &[64, 48],
        &[32, 16],
        &[2, 64],
        &[16, 1, 8],
        &[8, 4, 8, 2],
        &[4, 4, 4, 4, 8],
    ];
    for (i, size) in sizes.iter().enumerate() {
        let params = Params {
            size: size.to_vec(),
            boundary: vec![Boundary::Periodic; size.len()],
            init: Init::Fill(0.08),
            gravity: if i % 2 == 1 { 0.4 } else { 0.0 },
            target_clusters: 1,
            max_sweeps: Some(300),
            ..Params::default()
        };
        for seed in [1, 2] {
            let reference = run(&params, seed, Search::AllPairs, None, false);
            let lattice = run(&params, seed, Search::Lattice, None, true);
            assert_eq!(lattice.hash, reference.hash, "{size:?} seed {seed}");
            assert_eq!(lattice.series, reference.series, "{size:?} seed {seed}");
        }
    }
}

// The `grid` strategy (grid boxes with a halo per cluster, box side tuned at run time) gives
// the trajectory of all-pairs and of the occupancy lattice, to the last cluster, in 2 to 5
// dimensions; and its boxes list exactly the clusters whose halo overlaps them after every
// move, merge and re-tuning (checked by the invariant checks, which run the store's own check).

fn params(size: &[u64], boundary: &[Boundary], fill: f64, gravity: f64) -> Params {
    Params {
        size: size.to_vec(),
        boundary: boundary.to_vec(),
        init: Init::Fill(fill),
        gravity,
        target_clusters: 1,
        max_sweeps: Some(20_000),
        ..Params::default()
    }
}

#[test]
fn halo_grid_matches_all_pairs_and_lattice_to_one_cluster() {
    use Boundary::{Periodic as P, Wall as W};
    let cases = [
        params(&[48, 40], &[P, P], 0.05, 0.0),
        params(&[64, 32], &[P, P], 0.12, 0.0),
        params(&[40, 30], &[P, W], 0.08, 0.3),
        params(&[12, 10, 14], &[P, P, P], 0.05, 0.0),
        params(&[10, 10, 10], &[W, P, P], 0.1, 0.0),
        params(&[6, 7, 6, 6], &[P, P, P, P], 0.06, 0.0),
        params(&[4, 5, 4, 4, 5], &[P, P, W, P, P], 0.08, 0.0),
    ];
    let mut retunings = 0;
    for (i, p) in cases.iter().enumerate() {
        for seed in [1, 2, 3] {
            let reference = run(p, seed, Search::AllPairs, None, false);
            assert_eq!(
                reference.series.last().unwrap().1,
                1,
                "case {i} seed {seed} did not reach one cluster"
            );
            // The grid with its own side, checked after every move; then forced to start with
            // the smallest box and with a large one, so that re-tuning has work to do.
            let shortest = p.size.iter().copied().min().unwrap();
            let mut others = vec![
                ("grid", run(p, seed, Search::Grid, None, true)),
                ("lattice", run(p, seed, Search::Lattice, None, false)),
                ("grid A=1", run(p, seed, Search::Grid, Some(1), seed == 1)),
            ];
            let large = (shortest / 4).max(1).next_power_of_two() / 2;
            if large > 1 && 3 * large < shortest {
                others.push((
                    "grid A=large",
                    run(p, seed, Search::Grid, Some(large), seed == 1),
                ));
            }
            for (name, o) in &others {
                assert_eq!(o.hash, reference.hash, "case {i} seed {seed}: {name}");
                assert_eq!(o.series, reference.series, "case {i} seed {seed}: {name}");
                retunings += o.events.iter().filter(|e| e.contains("re-tuned")).count();
            }
        }
    }
    assert!(
        retunings > 10,
        "only {retunings} re-tunings of the box side"
    );
}

#[test]
fn halo_grid_never_falls_back_to_all_pairs() {
    // The doubling grid gives up once 3A >= L; the halo grid keeps its boxes to the end.
    let p = params(&[64, 64], &[Boundary::Periodic; 2], 0.1, 0.0);
    let mut sim = Simulation::new(
        Params {
            search: Search::Grid,
            ..p
        },
        4,
    )
    .unwrap();
    sim.run();
    assert_eq!(sim.clusters(), 1);
    assert_eq!(sim.strategy(), Search::Grid);
}
