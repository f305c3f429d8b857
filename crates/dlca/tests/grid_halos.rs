//! The `grid` strategy (grid boxes with a halo per cluster, box side tuned at run time) gives
//! the trajectory of all-pairs and of the occupancy lattice, to the last cluster, in 2 to 5
//! dimensions; and its boxes list exactly the clusters whose halo overlaps them after every
//! move, merge and re-tuning (checked by the invariant checks, which run the store's own check).

use core_lattice::Boundary;
use dlca::{Init, Params, Search, Simulation};

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
