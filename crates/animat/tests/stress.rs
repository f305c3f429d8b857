//! Numerical stability of `animat` at the edges of every accepted range: each case either runs
//! correctly (populations consistent with the animats listed, no two on a cell, the state hash
//! the same for every grid-box setting) or is refused with a message naming the flag or
//! parameter. Ordinary bad values (`--vision 0`, a breeding probability of 1.5, unknown rules,
//! a damaged checkpoint, ...) are in `tests/bad_input.rs`; this suite adds the extremes:
//!
//! | case | why it could fail |
//! |---|---|
//! | populations that die out (foxes alone starve; both species start at 0) | the run must stop cleanly at the step the last animat died, with the rows so far and finite outputs (an empty snapshot has no bounding box) |
//! | one species absent from the start, with its rule list empty | queries for the missing species, rules that never fire |
//! | a population that explodes (rabbits always breed, no crowding limit) | a birth beyond 2^32 - 1 animats would overflow the 32-bit visiting order; the cap is checked with a lowered limit, and the binary stops a world that outgrows `--max-memory` with an error |
//! | a start population beyond 2^32 - 1, or whose memory exceeds `--max-memory` | 1e12 foxes in a disc of radius 2^30 passed validation and filled memory until the system killed it; a dilute start takes a 36 KiB tile per animat (1e6 animats over a disc of radius 1e8: 35 GiB) |
//! | the densest start (the start disc half full) and a start radius of 2^30 | placement by rejection; a sparse cell index |
//! | vision, crowding radius, start radius and grid box of 2^30 | squared radii near 2^60; the grid boxes of `--grid-box 1` over a huge vision; every setting must give the same trajectory |
//! | animats near the `i64` limits of the plane | a step off the plane must be refused, not wrap; the snapshot's frame spans more than `i64` |
//! | NaN and infinities in `--density` and in a config file's probabilities | must be refused with exit code 2 naming the flag |

use animat::params::{ANIMAT_BYTES, MAX_ANIMATS, MAX_RADIUS};
use animat::{GridBox, Params, Species, World};
use run_cli::testing::refusals;
use std::collections::HashSet;
use std::path::Path;

/// Checks a world between steps: the species counts match the animats listed, no two share a
/// cell, ids are increasing.
fn check(world: &World) {
    let animats: Vec<_> = world.animats().collect();
    let foxes = animats.iter().filter(|a| a.species == Species::Fox).count();
    assert_eq!(foxes as u64, world.foxes());
    assert_eq!((animats.len() - foxes) as u64, world.rabbits());
    let cells: HashSet<[i64; 2]> = animats.iter().map(|a| a.pos).collect();
    assert_eq!(cells.len(), animats.len(), "two animats on one cell");
    assert!(animats.windows(2).all(|w| w[0].id < w[1].id));
}

/// Runs `params` for `steps` steps (seed 1) with every grid-box setting, checking the world
/// after every step, and asserts they agree; returns the run with boxes of the vision radius.
fn run_everywhere(params: &Params, steps: u64) -> World {
    let mut reference: Option<(World, Vec<(u64, u64)>)> = None;
    for grid_box in [GridBox::Vision, GridBox::None, GridBox::Side(1)] {
        let mut w = World::new(
            Params {
                grid_box,
                ..params.clone()
            },
            1,
        )
        .unwrap();
        let mut series = vec![(w.foxes(), w.rabbits())];
        for _ in 0..steps {
            if w.foxes() + w.rabbits() == 0 {
                break;
            }
            w.step();
            check(&w);
            series.push((w.foxes(), w.rabbits()));
        }
        match &reference {
            None => reference = Some((w, series)),
            Some((r, s)) => {
                assert_eq!(w.state_hash(), r.state_hash(), "{grid_box}");
                assert_eq!(&series, s, "{grid_box}");
            }
        }
    }
    reference.expect("a grid setting").0
}

#[test]
fn populations_that_die_out_stop_the_run_cleanly() {
    // Foxes alone starve within `starve + 1` steps.
    let p = Params {
        foxes: 40,
        rabbits: 0,
        start_radius: 20,
        ..Params::default()
    };
    let mut w = run_everywhere(&p, 100);
    assert_eq!((w.foxes(), w.rabbits()), (0, 0));
    let died_at = w.steps();
    assert!(died_at <= u64::from(p.starve) + 1, "{died_at}");
    w.run(50);
    assert_eq!(w.steps(), died_at, "an empty world does not step");
    let dir = tempfile::tempdir().unwrap();
    let frame = animat::output::SnapshotFrame::new(w.params(), None, None);
    animat::output::write_snapshot(&dir.path().join("empty.png"), &w, &frame).unwrap();
    // Both species absent from the start.
    let empty = run_everywhere(
        &Params {
            foxes: 0,
            rabbits: 0,
            ..Params::default()
        },
        10,
    );
    assert_eq!(empty.steps(), 0);
}

#[test]
fn one_species_alone_runs_with_the_other_rules_empty() {
    let rabbits_only = Params {
        foxes: 0,
        rabbits: 300,
        start_radius: 30,
        fox_rules: vec![],
        ..Params::default()
    };
    let w = run_everywhere(&rabbits_only, 60);
    assert_eq!(w.foxes(), 0);
    assert!(w.rabbits() > 0);
    let foxes_only = Params {
        foxes: 100,
        rabbits: 0,
        start_radius: 30,
        rabbit_rules: vec![],
        ..Params::default()
    };
    let w = run_everywhere(&foxes_only, 10);
    assert_eq!(w.rabbits(), 0);
}

/// Rabbits that breed whenever another is adjacent, with no crowding limit.
fn explosive() -> Params {
    Params {
        foxes: 0,
        rabbits: 50,
        start_radius: 10,
        rabbit_breed_p: 1.0,
        crowd_max: u32::MAX - 1,
        ..Params::default()
    }
}

#[test]
fn an_exploding_population_stops_at_the_animat_cap() {
    let limit = 2000;
    let mut w = World::new(explosive(), 1).unwrap();
    w.set_animat_limit(limit);
    let mut reached = 0;
    for _ in 0..80 {
        w.step();
        check(&w);
        let n = w.foxes() + w.rabbits();
        assert!(n <= limit, "{n} animats over the cap {limit}");
        reached = reached.max(n);
    }
    assert!(
        reached > limit * 9 / 10,
        "the cap was never approached: {reached}"
    );
    // The memory estimate follows the population.
    assert!(w.memory_bytes() >= reached * ANIMAT_BYTES);
}

#[test]
fn start_populations_beyond_the_cap_are_refused() {
    let e = Params {
        foxes: MAX_ANIMATS,
        rabbits: 1,
        start_radius: MAX_RADIUS,
        ..Params::default()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("4294967296 animats") && e.contains("--foxes"),
        "{e}"
    );
}

#[test]
fn the_start_memory_estimate_matches_the_world_it_builds() {
    for (animats, radius) in [(20_000, 200), (2000, 1_000_000), (300, MAX_RADIUS)] {
        let p = Params {
            foxes: animats / 10,
            rabbits: animats - animats / 10,
            start_radius: radius,
            ..Params::default()
        };
        let w = World::new(p.clone(), 1).unwrap();
        let (estimate, actual) = (p.start_memory_bytes() as f64, w.memory_bytes() as f64);
        assert!(
            (0.8..1.25).contains(&(estimate / actual)),
            "{animats} animats, radius {radius}: estimate {estimate}, built {actual}"
        );
    }
    // A dilute start costs a tile per animat.
    let dilute = Params {
        foxes: 100_000,
        rabbits: 900_000,
        start_radius: 100_000_000,
        ..Params::default()
    };
    assert!(dilute.start_memory_bytes() > 30 << 30);
}

#[test]
fn the_densest_start_and_the_largest_radii() {
    // The start disc exactly half full.
    let mut dense = Params {
        foxes: 20,
        start_radius: 12,
        ..Params::default()
    };
    dense.rabbits = dense.start_capacity() - dense.foxes;
    let w = World::new(dense.clone(), 1).unwrap();
    check(&w);
    run_everywhere(&dense, 5);
    // Every radius at its largest: squared radii near 2^60.
    let huge = Params {
        foxes: 30,
        rabbits: 300,
        start_radius: MAX_RADIUS,
        vision: MAX_RADIUS,
        crowd_radius: MAX_RADIUS,
        ..Params::default()
    };
    run_everywhere(&huge, 20);
    run_everywhere(
        &Params {
            grid_box: GridBox::Side(MAX_RADIUS),
            ..huge.clone()
        },
        20,
    );
}

#[test]
fn animats_at_the_edges_of_the_plane_stay_on_it() {
    let p = Params {
        foxes: 0,
        rabbits: 0,
        ..Params::default()
    };
    let corners = [
        [i64::MAX, i64::MAX],
        [i64::MIN, i64::MIN],
        [i64::MAX, i64::MIN],
        [i64::MIN + 1, i64::MAX - 1],
    ];
    for grid_box in [GridBox::Vision, GridBox::None] {
        let mut w = World::empty(
            Params {
                grid_box,
                ..p.clone()
            },
            1,
        )
        .unwrap();
        for (i, c) in corners.iter().enumerate() {
            w.add(Species::Rabbit, *c, 0, 0).unwrap();
            w.add(Species::Rabbit, [c[0] / 2 + i as i64, c[1] / 2], 0, 0)
                .unwrap();
        }
        for _ in 0..20 {
            w.step();
            check(&w);
        }
        assert!(w.rabbits() >= corners.len() as u64 * 2);
        let dir = tempfile::tempdir().unwrap();
        let frame = animat::output::SnapshotFrame::new(w.params(), None, None);
        animat::output::write_snapshot(&dir.path().join("edges.png"), &w, &frame).unwrap();
        // The animats at the plane's edges are outside the frame, and counted.
        assert_eq!(
            frame.raster(&w).1,
            w.foxes() + w.rabbits() - frame_count(&w, &frame)
        );
    }
}

/// Animats inside `frame`.
fn frame_count(w: &World, frame: &animat::output::SnapshotFrame) -> u64 {
    let r = i128::from(frame.radius);
    w.animats()
        .filter(|a| a.pos.iter().all(|&c| (-r..=r).contains(&i128::from(c))))
        .count() as u64
}

const ANIMAT: &str = env!("CARGO_BIN_EXE_animat");

#[test]
fn float_values_and_memory_limits_are_refused_by_name() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("nan.toml"), "fox_breed_p = nan\n").unwrap();
    std::fs::write(dir.join("inf.toml"), "rabbit_breed_p = inf\n").unwrap();
    let cases: [(&[&str], &str); 9] = [
        (&["--density", "NaN", "--out", "o"], "--density NaN"),
        (&["--density", "inf", "--out", "o"], "--density inf"),
        (&["--density", "-inf", "--out", "o"], "--density -inf"),
        (
            &["--config", "nan.toml", "--out", "o"],
            "--fox-breed-p NaN is outside the accepted range [0, 1]",
        ),
        (
            &["--config", "inf.toml", "--out", "o"],
            "--rabbit-breed-p inf is outside the accepted range [0, 1]",
        ),
        (&["--max-memory", "lots", "--out", "o"], "lots"),
        (
            &[
                "--foxes",
                "5000000000",
                "--start-radius",
                "1073741824",
                "--out",
                "o",
            ],
            "--foxes",
        ),
        (
            &[
                "--foxes",
                "100000",
                "--rabbits",
                "900000",
                "--start-radius",
                "100000000",
                "--out",
                "o",
            ],
            "over --max-memory 4.0 GiB",
        ),
        (
            &[
                "--foxes",
                "0",
                "--rabbits",
                "2000",
                "--max-memory",
                "100K",
                "--out",
                "o",
            ],
            "over --max-memory 100.0 KiB",
        ),
    ];
    let failures = refusals(Path::new(ANIMAT), "animat", dir, &cases);
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn a_world_that_outgrows_max_memory_stops_with_an_error() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    // The flags of `explosive()`.
    let e = explosive();
    let o = std::process::Command::new(ANIMAT)
        .args(["--steps", "500", "--max-memory", "1M", "-q"])
        .args([
            "--foxes",
            &e.foxes.to_string(),
            "--rabbits",
            &e.rabbits.to_string(),
        ])
        .args(["--start-radius", &e.start_radius.to_string()])
        .args(["--rabbit-breed-p", &e.rabbit_breed_p.to_string()])
        .args(["--crowd-max", &e.crowd_max.to_string()])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(
        lines[0].starts_with("animat: run failed: after step ")
            && lines[0].contains("over --max-memory 1.0 MiB"),
        "{stderr}"
    );
}

#[test]
fn an_extinct_run_through_the_binary_ends_with_its_rows() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let o = std::process::Command::new(ANIMAT)
        .args(["--foxes", "40", "--rabbits", "0", "--start-radius", "20"])
        .args([
            "--steps",
            "200",
            "--snapshot-every",
            "10",
            "--positions",
            "-q",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = std::fs::read_to_string(out.join("populations.csv")).unwrap();
    let last = rows.lines().last().unwrap();
    assert!(last.ends_with(",0,0"), "{last}");
    let steps: u64 = last.split(',').next().unwrap().parse().unwrap();
    assert!(steps < 200);
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(run["results"]["steps"].as_u64(), Some(steps));
    assert_eq!(
        std::fs::read_to_string(out.join("positions.csv"))
            .unwrap()
            .lines()
            .count(),
        1,
        "a header and no animat"
    );
}
