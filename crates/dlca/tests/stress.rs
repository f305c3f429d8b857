//! Numerical stability of `dlca` at the edges of every accepted range: each case either runs
//! correctly, with every contact search giving the same trajectory and the model's invariants
//! checked after every move (particles conserved, no site holding two, every cluster connected,
//! no two clusters face-adjacent), or is refused with a message naming the flag. Ordinary bad
//! values (`--fill 0`, `--gravity 1`, `--dim 6`, a damaged checkpoint, ...) are in
//! `tests/bad_input.rs`; this suite adds the extremes:
//!
//! | case | why it could fail |
//! |---|---|
//! | lattices of side 1 and 2 in every dimension, periodic, walled and mixed, from one particle to a full lattice | a periodic axis of 1 site is its own neighbour (a move along it maps a cluster onto itself), one of 2 sites has the same neighbour both ways; box layouts and bounding regions degenerate |
//! | full and nearly full lattices (`N = sites`, `sites - 1`, fill 0.999) | one cluster spanning every axis from the start, the only holes one site wide |
//! | very elongated lattices (256 x 1, 2 x 2 x 64, 1 x 1 x 1 x 1 x 64, ...) | effectively one-dimensional motion, grid boxes of one site across |
//! | an axis of `2^62` sites (the longest accepted) and longer ones | the grid strategies add a coordinate to a side: an axis of `2^64 - 1` sites overflowed (a panic); longer axes are now refused |
//! | temperature `1e-300` and the smallest positive `f64` | a move probability that never fires: the state must not change, and the run is not "frozen" |
//! | mobility exponents of 2000 and `f64::MAX` | `2^-2000` is 0: once every cluster has two particles nothing can move, and a run to `--target-clusters` swept forever; it now stops (`Simulation::is_frozen`) with a warning |
//! | gravity 0.999999 against a wall | moves up almost never happen; clusters must pile up at the wall without overlapping it |
//! | more particles than 32-bit ids | refused before placing anything |
//! | NaN, infinities and out-of-range values in every float flag | must be refused with exit code 2 naming the flag |
//! | one particle with `--gyration` | a radius of gyration of 0 and no fit: finite outputs, no panic |

use core_lattice::Boundary;
use dlca::analysis::{fractal_dimension, gyration};
use dlca::params::MAX_SIDE;
use dlca::{Init, Params, Search, Simulation};
use run_cli::testing::refusals;
use std::path::Path;

const STRATEGIES: [Search; 5] = [
    Search::AllPairs,
    Search::Grid,
    Search::GridDoubling,
    Search::Lattice,
    Search::Auto,
];

/// Runs `params` (seed 1) with every strategy, the invariants checked after every move, and
/// asserts they give the same state and cluster series; returns the all-pairs run.
fn run_everywhere(params: &Params) -> Simulation {
    let mut reference: Option<(Simulation, Vec<(u64, u64)>)> = None;
    for search in STRATEGIES {
        let p = Params {
            search,
            ..params.clone()
        };
        let mut sim = Simulation::new(p, 1)
            .unwrap_or_else(|e| panic!("{params:?}: {e}"))
            .with_invariant_checks(true);
        sim.run();
        assert!(sim.is_done());
        let total: usize = sim
            .sets()
            .live()
            .iter()
            .map(|&id| sim.sets().sites(id).len())
            .sum();
        assert_eq!(total as u64, params.particles().unwrap(), "{params:?}");
        let series: Vec<(u64, u64)> = sim
            .records()
            .sweeps()
            .iter()
            .map(|r| (r.clusters, r.largest))
            .collect();
        match &reference {
            None => reference = Some((sim, series)),
            Some((r, s)) => {
                assert_eq!(sim.state_hash(), r.state_hash(), "{search:?}: {params:?}");
                assert_eq!(&series, s, "{search:?}: {params:?}");
            }
        }
    }
    reference.expect("at least one strategy").0
}

fn lattice(size: &[u64], boundary: &[Boundary], init: Init) -> Params {
    Params {
        size: size.to_vec(),
        boundary: boundary.to_vec(),
        init,
        target_clusters: 1,
        max_sweeps: Some(2000),
        ..Params::default()
    }
}

#[test]
fn tiny_lattices_in_every_dimension() {
    let mut runs = 0;
    for dim in 1..=5 {
        let mixed: Vec<u64> = (0..dim).map(|a| 1 + (a as u64 % 2)).collect();
        for size in [vec![1; dim], vec![2; dim], mixed] {
            let sites: u64 = size.iter().product();
            let alternating: Vec<Boundary> = (0..dim)
                .map(|a| {
                    if a % 2 == 0 {
                        Boundary::Wall
                    } else {
                        Boundary::Periodic
                    }
                })
                .collect();
            for boundary in [
                vec![Boundary::Periodic; dim],
                vec![Boundary::Wall; dim],
                alternating,
            ] {
                let mut counts = vec![1, 2, 3, sites - 1, sites];
                counts.retain(|&n| n >= 1 && n <= sites);
                counts.dedup();
                for n in counts {
                    let sim = run_everywhere(&lattice(&size, &boundary, Init::Particles(n)));
                    // Every lattice here is connected through face neighbours, and a cluster
                    // that cannot move along one axis can along another: a single cluster at
                    // the end.
                    assert_eq!(sim.clusters(), 1, "{size:?} {boundary:?} {n}");
                    runs += 1;
                }
            }
        }
    }
    assert!(runs > 100);
}

#[test]
fn full_and_nearly_full_lattices() {
    for (dim, side) in [(1, 64), (2, 16), (3, 6), (4, 4), (5, 3)] {
        let sites = u64::pow(side, dim as u32);
        for boundary in [Boundary::Periodic, Boundary::Wall] {
            let b = vec![boundary; dim];
            let size = vec![side; dim];
            for init in [
                Init::Particles(sites),
                Init::Particles(sites - 1),
                Init::Particles(sites - 2),
                Init::Fill(0.999),
            ] {
                let p = lattice(&size, &b, init);
                let start = Simulation::new(p.clone(), 1).unwrap();
                if p.particles().unwrap() == sites {
                    assert_eq!(start.clusters(), 1, "a full lattice is one cluster");
                    assert_eq!(start.largest(), sites);
                }
                let sim = run_everywhere(&p);
                assert_eq!(sim.clusters(), 1, "{size:?} {b:?} {init:?}");
            }
        }
    }
}

#[test]
fn very_elongated_lattices() {
    let p = Boundary::Periodic;
    let w = Boundary::Wall;
    for (size, boundary) in [
        (vec![256, 1], vec![p, p]),
        (vec![1, 256], vec![w, w]),
        (vec![128, 2], vec![p, w]),
        (vec![2, 2, 64], vec![p, p, p]),
        (vec![64, 1, 1], vec![w, p, w]),
        (vec![1, 1, 1, 1, 64], vec![p, p, p, p, p]),
        (vec![2, 1, 2, 1, 48], vec![w, w, p, p, w]),
    ] {
        let params = Params {
            max_sweeps: Some(50_000),
            ..lattice(&size, &boundary, Init::Fill(0.05))
        };
        let sim = run_everywhere(&params);
        assert_eq!(sim.clusters(), 1, "{size:?} {boundary:?}");
    }
}

#[test]
fn the_longest_accepted_axis_runs_and_a_longer_one_is_refused() {
    for search in [
        Search::Grid,
        Search::GridDoubling,
        Search::AllPairs,
        Search::Auto,
    ] {
        for n in [1, 5] {
            let p = Params {
                search,
                max_sweeps: Some(50),
                ..lattice(&[MAX_SIDE], &[Boundary::Periodic], Init::Particles(n))
            };
            let mut sim = Simulation::new(p, 1).unwrap().with_invariant_checks(true);
            sim.run();
            assert_eq!(sim.particles(), n);
        }
    }
    for size in [vec![MAX_SIDE + 1], vec![2, u64::MAX]] {
        let p = lattice(
            &size,
            &vec![Boundary::Periodic; size.len()],
            Init::Particles(1),
        );
        let e = Simulation::new(p, 1).err().unwrap().to_string();
        assert!(
            e.starts_with("--size: a side of ") && e.contains("2^62"),
            "{e}"
        );
    }
}

#[test]
fn temperatures_that_never_fire_leave_the_state_alone() {
    for temperature in [1e-300, f64::from_bits(1)] {
        let p = Params {
            temperature,
            max_sweeps: Some(100),
            ..lattice(&[32, 32], &[Boundary::Periodic; 2], Init::Fill(0.1))
        };
        let before = Simulation::new(p.clone(), 1).unwrap().state_hash();
        let sim = run_everywhere(&p);
        assert_eq!(sim.sweeps(), 100);
        assert!(!sim.is_frozen(), "a probability above 0 is not frozen");
        assert_eq!(
            sim.state_hash(),
            before,
            "temperature {temperature:e} moved"
        );
    }
}

#[test]
fn immobile_clusters_stop_the_run_instead_of_sweeping_forever() {
    for gamma in [2000.0, f64::MAX] {
        let p = Params {
            mobility_exponent: gamma,
            max_sweeps: None,
            ..lattice(&[32, 32], &[Boundary::Periodic; 2], Init::Fill(0.1))
        };
        let sim = run_everywhere(&p);
        assert!(sim.is_frozen(), "gamma {gamma:e}");
        assert!(sim.clusters() > 1);
        // Monomers (1^-gamma = 1) still moved until none was left.
        for &id in sim.sets().live() {
            assert!(sim.sets().sites(id).len() >= 2);
        }
    }
    // A small exponent is not frozen: the run reaches its target.
    let p = Params {
        mobility_exponent: 1e-300,
        ..lattice(&[32, 32], &[Boundary::Periodic; 2], Init::Fill(0.1))
    };
    let sim = run_everywhere(&p);
    assert!(!sim.is_frozen());
    assert_eq!(sim.clusters(), 1);
}

#[test]
fn strong_gravity_piles_clusters_against_the_wall() {
    let mean_height = |gravity: f64| {
        let p = Params {
            gravity,
            max_sweeps: Some(300),
            target_clusters: 1,
            ..lattice(
                &[64, 32],
                &[Boundary::Periodic, Boundary::Wall],
                Init::Fill(0.05),
            )
        };
        let sim = run_everywhere(&p);
        let l = sim.lattice();
        let (mut sum, mut n) = (0.0, 0.0);
        for &id in sim.sets().live() {
            for &k in sim.sets().sites(id) {
                sum += l.decode(k).unwrap()[1] as f64;
                n += 1.0;
            }
        }
        sum / n
    };
    let settled = mean_height(0.999_999);
    assert!(
        settled < 8.0 && settled < mean_height(0.0) - 5.0,
        "mean height {settled} under gravity"
    );
}

#[test]
fn a_single_particle_with_gyration_has_finite_results() {
    for dim in 1..=5 {
        let p = Params {
            gyration: true,
            ..lattice(
                &vec![4; dim],
                &vec![Boundary::Periodic; dim],
                Init::Particles(1),
            )
        };
        let sim = run_everywhere(&p);
        assert_eq!(sim.sweeps(), 0);
        let g = gyration(&sim);
        assert_eq!(g.len(), 1);
        assert_eq!(g[0].radius_of_gyration, 0.0);
        assert!(fractal_dimension(&g, 2).is_err());
    }
}

#[test]
fn counts_beyond_32_bit_ids_are_refused_without_placing_anything() {
    let p = lattice(
        &[65536, 65536, 2],
        &[Boundary::Periodic; 3],
        Init::Fill(0.6),
    );
    let e = Simulation::new(p, 1).err().unwrap().to_string();
    assert!(e.contains("--fill 0.6") && e.contains("5153960755"), "{e}");
}

const DLCA: &str = env!("CARGO_BIN_EXE_dlca");

#[test]
fn float_flags_refuse_nan_infinity_and_out_of_range_values() {
    let tmp = tempfile::tempdir().unwrap();
    let base = ["--size", "32", "--out", "out"];
    let cases: Vec<(Vec<&str>, &str)> = [
        (vec!["--fill", "NaN"], "--fill NaN"),
        (vec!["--fill", "inf"], "--fill inf"),
        (vec!["--fill", "-inf"], "--fill -inf"),
        (vec!["--fill", "-0.1"], "--fill -0.1"),
        (
            vec!["--fill", "0.1", "--temperature", "NaN"],
            "--temperature NaN",
        ),
        (
            vec!["--fill", "0.1", "--temperature", "inf"],
            "--temperature inf",
        ),
        (
            vec!["--fill", "0.1", "--temperature", "-inf"],
            "--temperature -inf",
        ),
        (
            vec!["--fill", "0.1", "--temperature", "1.5"],
            "--temperature 1.5",
        ),
        (vec!["--fill", "0.1", "--gravity", "NaN"], "--gravity NaN"),
        (vec!["--fill", "0.1", "--gravity", "inf"], "--gravity inf"),
        (vec!["--fill", "0.1", "--gravity", "-inf"], "--gravity -inf"),
        (
            vec!["--fill", "0.1", "--mobility-exponent", "NaN"],
            "--mobility-exponent NaN",
        ),
        (
            vec!["--fill", "0.1", "--mobility-exponent", "inf"],
            "--mobility-exponent inf",
        ),
        (
            vec!["--fill", "0.1", "--mobility-exponent", "-inf"],
            "--mobility-exponent -inf",
        ),
        (
            vec!["--dim", "3", "--size", "65536x65536x2", "--fill", "0.6"],
            "--fill 0.6",
        ),
    ]
    .into_iter()
    .map(|(extra, culprit)| {
        let mut v = base.to_vec();
        v.extend(extra);
        (v, culprit)
    })
    .collect();
    let cases: Vec<(&[&str], &str)> = cases.iter().map(|(a, c)| (a.as_slice(), *c)).collect();
    let failures = refusals(Path::new(DLCA), "dlca", tmp.path(), &cases);
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn a_frozen_run_ends_with_a_warning_and_its_outputs() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("frozen");
    let o = std::process::Command::new(DLCA)
        .args([
            "--size",
            "32",
            "--fill",
            "0.1",
            "--mobility-exponent",
            "2000",
        ])
        .args(["--target-clusters", "1", "-q", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(stderr.contains("no cluster can move any more"), "{stderr}");
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert!(run["results"]["clusters"].as_u64().unwrap() > 1);
}
