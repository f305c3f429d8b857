//! A run saved between sweeps and restored reaches the same final state as one never
//! interrupted (docs/dlca.md, "Outputs"), for every strategy, through the checkpoint envelope.

use core_lattice::Boundary;
use dlca::{Init, Params, Search, Simulation, Snapshot};
use run_io::checkpoint::{decode_checkpoint, encode_checkpoint};

fn configs() -> Vec<Params> {
    vec![
        Params {
            size: vec![64, 64],
            init: Init::Fill(0.05),
            target_clusters: 2,
            ..Params::default()
        },
        Params {
            size: vec![40, 30],
            boundary: vec![Boundary::Periodic, Boundary::Wall],
            init: Init::Fill(0.06),
            gravity: 0.3,
            target_clusters: 3,
            ..Params::default()
        },
        Params {
            size: vec![12, 10, 9],
            boundary: vec![Boundary::Periodic, Boundary::Wall, Boundary::Periodic],
            init: Init::Fill(0.05),
            mobility_exponent: 0.5,
            target_clusters: 2,
            max_sweeps: Some(400),
            ..Params::default()
        },
        Params {
            size: vec![6; 5],
            boundary: vec![Boundary::Periodic; 5],
            init: Init::Fill(0.02),
            target_clusters: 3,
            max_sweeps: Some(200),
            ..Params::default()
        },
    ]
}

fn records(sim: &Simulation) -> Vec<(u64, u64, u64)> {
    sim.records()
        .sweeps()
        .iter()
        .map(|r| (r.sweep, r.clusters, r.largest))
        .collect()
}

#[test]
fn restored_runs_end_where_uninterrupted_runs_end() {
    for (i, params) in configs().into_iter().enumerate() {
        for search in [
            Search::Lattice,
            Search::Grid,
            Search::GridDoubling,
            Search::AllPairs,
        ] {
            let p = Params {
                search,
                ..params.clone()
            };
            let mut whole = Simulation::new(p.clone(), 5).unwrap();
            whole.run();
            for stop in [0, 1, 7, 40] {
                let mut first = Simulation::new(p.clone(), 5).unwrap();
                while !first.is_done() && first.sweeps() < stop {
                    first.sweep();
                }
                let bytes = encode_checkpoint("dlca", &first.snapshot()).unwrap();
                let snapshot: Snapshot = decode_checkpoint(&bytes, "dlca").unwrap();
                let mut resumed = Simulation::restore(snapshot).unwrap();
                assert_eq!(resumed.state_hash(), first.state_hash());
                resumed.run();
                let what = format!("config {i}, {search:?}, stopped after {stop} sweeps");
                assert_eq!(resumed.state_hash(), whole.state_hash(), "{what}");
                assert_eq!(records(&resumed), records(&whole), "{what}");
                assert_eq!(resumed.strategy(), whole.strategy(), "{what}");
            }
        }
    }
}
