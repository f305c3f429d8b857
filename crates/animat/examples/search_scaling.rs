//! Neighbour-search time per step against population at fixed density (Hawick, James &
//! Scogings 2006, "Grid-Boxing for Spatial Simulation Performance Optimisation", Fig. 9 and
//! Table I) for grid 60, 120, 240 and none, with log-log gradients; prints markdown tables.
//!
//! `cargo run --release -p animat --example search_scaling -- [MAX_N] [NONE_MAX_N] [BOXES_MAX_N] [REPEATS] [ONLY]`
//!
//! - `ONLY`: run only the series whose label contains it (for example `60 (cells` for the
//!   default search with 60-cell boxes); all by default.
//! - Populations 1e3, 3e3, 1e4, ... up to `MAX_N` (default 1e6), start density 0.2 (the
//!   default start's), default parameters otherwise, seed 1.
//! - Two search set-ups: the default (cell index first, grid boxes behind it) and the grid boxes
//!   alone (the paper's structure; `World::set_cell_search(false)`); `none` is the exhaustive
//!   scan, run up to `NONE_MAX_N` (default 3e4). Grid boxes alone are run up to `BOXES_MAX_N`
//!   (default 1e6) for side 60, a third of it for 120 and a tenth for 240 (their big boxes
//!   make large populations slow).
//! - Every point is run `REPEATS` times (default 2; same trajectory each time) and the fastest
//!   search time kept.
//! - Each point runs `max(3, min(10, 1e5 / N))` steps from the start with timing on; the x
//!   value of the fit is the mean population over those steps (populations grow), the y value
//!   the mean search seconds per step (clock read around each animat's decision).

use animat::GridBox;
use animat::bench::{SCALING_DENSITY, SearchCost, search_scaling_point_with};
use core_lattice::stats::Fit;

const SEED: u64 = 1;

fn ladder(max: u64) -> Vec<u64> {
    let mut out = Vec::new();
    let mut n = 1000u64;
    while n <= max {
        out.push(n);
        out.push(n * 3);
        n *= 10;
    }
    out.retain(|&x| x <= max);
    out
}

fn steps_for(n: u64) -> u64 {
    (100_000 / n).clamp(3, 10)
}

struct Series {
    label: String,
    points: Vec<SearchCost>,
}

impl Series {
    fn fit(&self) -> Option<Fit> {
        let x: Vec<f64> = self
            .points
            .iter()
            .map(|c| c.animat_steps as f64 / c.steps as f64)
            .collect();
        let y: Vec<f64> = self
            .points
            .iter()
            .map(|c| c.search_seconds_per_step)
            .collect();
        Fit::log_log(&x, &y).ok()
    }
}

fn run(label: &str, grid: GridBox, cells: bool, max: u64, repeats: u32) -> Series {
    let mut points = Vec::new();
    for n in ladder(max) {
        // The same run `repeats` times (same trajectory); keep the fastest search, since on a
        // shared machine the noise (preemption, cache sharing) only adds time.
        let c = (0..repeats.max(1))
            .map(|_| {
                search_scaling_point_with(n, SCALING_DENSITY, grid, steps_for(n), SEED, cells)
                    .expect("valid parameters")
            })
            .min_by(|a, b| {
                a.search_seconds_per_step
                    .total_cmp(&b.search_seconds_per_step)
            })
            .expect("at least one repeat");
        eprintln!(
            "{label}: N {n} mean {:.0} steps {} search {:.3} ms/step evals {:.0}/step step {:.3} ms",
            c.animat_steps as f64 / c.steps as f64,
            c.steps,
            c.search_seconds_per_step * 1e3,
            c.distance_evals_per_step,
            c.step_seconds * 1e3
        );
        points.push(c);
    }
    Series {
        label: label.to_string(),
        points,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let only = args.get(4).cloned().unwrap_or_default();
    let a: Vec<u64> = args
        .iter()
        .take(4)
        .map(|s| s.parse::<f64>().expect("number") as u64)
        .collect();
    let max = a.first().copied().unwrap_or(1_000_000);
    let none_max = a.get(1).copied().unwrap_or(30_000);
    let boxes_max = a.get(2).copied().unwrap_or(1_000_000);
    let repeats = a.get(3).copied().unwrap_or(2) as u32;
    let mut plan = Vec::new();
    for side in [60, 120, 240] {
        plan.push((
            format!("{side} (cells + boxes)"),
            GridBox::Side(side),
            true,
            max,
        ));
    }
    for (side, cap) in [(60, boxes_max), (120, boxes_max / 3), (240, boxes_max / 10)] {
        plan.push((
            format!("{side} (boxes alone)"),
            GridBox::Side(side),
            false,
            cap.min(max),
        ));
    }
    plan.push(("none".into(), GridBox::None, false, none_max.min(max)));
    let all: Vec<Series> = plan
        .into_iter()
        .filter(|(label, ..)| label.contains(&only))
        .map(|(label, grid, cells, cap)| run(&label, grid, cells, cap, repeats))
        .collect();

    println!(
        "| grid | N (start) | mean N | steps | search ms/step | search ns/animat | distance evals/animat | whole step ms |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for s in &all {
        for c in &s.points {
            let mean = c.animat_steps as f64 / c.steps as f64;
            println!(
                "| {} | {} | {:.0} | {} | {:.3} | {:.0} | {:.1} | {:.3} |",
                s.label,
                c.animats,
                mean,
                c.steps,
                c.search_seconds_per_step * 1e3,
                c.search_seconds_per_step * 1e9 / mean,
                c.distance_evals_per_step / mean,
                c.step_seconds * 1e3
            );
        }
    }
    println!();
    println!("| grid | points | N range | fitted gradient | R^2 |");
    println!("|---|---|---|---|---|");
    for s in &all {
        let range = match (s.points.first(), s.points.last()) {
            (Some(f), Some(l)) => format!("{}..{}", f.animats, l.animats),
            _ => "-".into(),
        };
        match s.fit() {
            Some(f) => println!(
                "| {} | {} | {range} | {:.3} ± {:.3} | {:.4} |",
                s.label,
                s.points.len(),
                f.slope,
                f.slope_stderr,
                f.r2
            ),
            None => println!("| {} | {} | {range} | - | - |", s.label, s.points.len()),
        }
    }
}
