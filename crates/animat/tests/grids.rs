//! Every grid-box setting gives a bit-identical trajectory (`docs/animat.md`, "Search, and why
//! every grid size gives the same trajectory").

use animat::{GridBox, Params, World};

/// Population series and final state hash of one run.
fn run(p: &Params, seed: u64, steps: u64) -> (Vec<(u64, u64)>, String, u64) {
    let mut w = World::new(p.clone(), seed).unwrap();
    let mut series = vec![(w.foxes(), w.rabbits())];
    for _ in 0..steps {
        w.step();
        series.push((w.foxes(), w.rabbits()));
    }
    if let Some(g) = w.grid() {
        g.validate().unwrap();
    }
    (series, w.state_hash(), w.queries().total())
}

/// Runs every grid setting for `steps` steps from 2200 animats on each seed and checks that
/// the population series and final state hash agree.
fn check_all_settings(seeds: &[u64], steps: u64) {
    let settings = [
        GridBox::None,
        GridBox::Side(15),
        GridBox::Side(30),
        GridBox::Side(60),
        GridBox::Side(120),
        GridBox::Side(240),
    ];
    for &seed in seeds {
        let base = Params {
            foxes: 300,
            rabbits: 1900,
            ..Params::default()
        };
        assert!(base.foxes + base.rabbits >= 2000);
        let mut reference = None;
        for g in settings {
            let p = Params {
                grid_box: g,
                ..base.clone()
            };
            let got = run(&p, seed, steps);
            assert!(got.0.last().unwrap().0 + got.0.last().unwrap().1 > 0);
            match &reference {
                None => reference = Some((g, got)),
                Some((g0, want)) => {
                    assert_eq!(&got, want, "grid {g} differs from grid {g0}, seed {seed}")
                }
            }
        }
    }
}

/// The default suite's version: 2 seeds, 50 steps (the exhaustive search makes 500 steps cost
/// about a minute per seed at the dev profile; see `full_length` for the 500 steps).
#[test]
fn every_grid_setting_gives_the_same_trajectory() {
    check_all_settings(&[1, 2], 50);
}

/// The full check: 3 seeds, 500 steps from 2200 animats, every grid setting. Slow at
/// the dev profile (several minutes); run with `cargo test -p animat -- --ignored`.
#[test]
#[ignore = "slow: several minutes; run with --ignored"]
fn full_length() {
    check_all_settings(&[1, 2, 3], 500);
}

/// Final state hash and population series with the cell-index search on or off.
fn run_cells(p: &Params, seed: u64, steps: u64, cells: bool) -> (Vec<(u64, u64)>, String) {
    let mut w = World::new(p.clone(), seed).unwrap();
    w.set_cell_search(cells);
    assert_eq!(w.cell_search(), cells && p.grid_box != GridBox::None);
    let mut series = vec![(w.foxes(), w.rabbits())];
    for _ in 0..steps {
        w.step();
        series.push((w.foxes(), w.rabbits()));
    }
    (series, w.state_hash())
}

/// The cell-index search (on by default with boxes) gives the trajectory of the grid boxes
/// alone and of the exhaustive search, also where its ring limit is reached (vision larger
/// than 8 but only a few cells: rings run out and the boxes finish the query) and where it
/// is not used (crowding radius beyond the ring limit), and with a vision of at most 8 (the
/// rings cover the whole disc).
#[test]
fn cell_search_matches_the_grid_boxes() {
    let base = Params {
        foxes: 150,
        rabbits: 900,
        start_radius: 60,
        ..Params::default()
    };
    let variants = [
        base.clone(),
        Params {
            vision: 6,
            prey_needed: 3,
            ..base.clone()
        },
        Params {
            vision: 12,
            crowd_radius: 9,
            crowd_max: 6,
            start_radius: 90,
            ..base.clone()
        },
    ];
    for (v, p) in variants.iter().enumerate() {
        let seed = 10 + v as u64;
        let want = run_cells(
            &Params {
                grid_box: GridBox::None,
                ..p.clone()
            },
            seed,
            40,
            true,
        );
        for g in [GridBox::Side(7), GridBox::Side(60)] {
            let q = Params {
                grid_box: g,
                ..p.clone()
            };
            assert_eq!(
                run_cells(&q, seed, 40, true),
                want,
                "variant {v}, grid {g}, cells on"
            );
            assert_eq!(
                run_cells(&q, seed, 40, false),
                want,
                "variant {v}, grid {g}, cells off"
            );
        }
    }
}
