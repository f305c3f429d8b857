//! Hawick, James & Scogings (2006), animats (sections II.B, IV.B): neighbour-search time per step
//! against population for grid boxes of 60, 120 and 240 cells and no grid (Fig. 9), and the fitted
//! log-log gradients (Table I).

use super::Ctx;
use super::csvfile::Csv;
use crate::report::{Table, pm, sig};
use animat::bench::{SCALING_DENSITY, scaling_params, step_throughput};
use animat::{GridBox, World};
use anyhow::Result;
use core_lattice::Fit;
use figures::chart::{self, Chart, Series, Style};
use std::path::{Path, PathBuf};

/// Hawick, James & Scogings (2006), Table I: fitted gradients and their errors, as printed.
const TABLE_I: [(&str, f64, f64); 4] = [
    ("none", 1.96384, 0.0112363),
    ("240", 1.70614, 0.0359479),
    ("120", 1.3346, 0.0637962),
    ("60", 1.35362, 0.0576574),
];

fn grid_name(g: GridBox) -> String {
    match g {
        GridBox::None => "none".into(),
        GridBox::Side(a) => a.to_string(),
        GridBox::Vision => "vision".into(),
    }
}

/// One measured point of Fig. 9.
#[derive(Debug, Clone, Copy)]
pub struct Point {
    /// Mean population over the measured steps.
    pub population: f64,
    /// Neighbour-search seconds per step.
    pub search_seconds: f64,
    /// Distance evaluations per step (candidates that passed the per-axis test).
    pub distance_evals: f64,
    /// Items examined by the searches per step: the work measure of the scan (N per query
    /// without boxes, the halo's items with them).
    pub items_scanned: f64,
    /// Whole-step seconds per step.
    pub step_seconds: f64,
}

/// Build a world of `animats` at [`SCALING_DENSITY`] (`animat::bench::scaling_params`), run `steps`
/// steps with the per-query search timer, the cell index on or off, and return the per-step
/// costs.
pub fn measure(animats: u64, grid: GridBox, cells: bool, steps: u64, seed: u64) -> Result<Point> {
    let mut world = World::new(scaling_params(animats, SCALING_DENSITY, grid), seed)?;
    world.set_timing(true);
    world.set_cell_search(cells);
    let (mut pop, mut search, mut evals) = (0.0, 0.0, 0.0);
    let scanned_before = world.grid().map_or(0, |g| g.stats().items_scanned);
    let start = std::time::Instant::now();
    for _ in 0..steps {
        pop += (world.foxes() + world.rabbits()) as f64;
        let s = world.step();
        search += s.search_seconds;
        evals += s.distance_evals as f64;
    }
    let scanned = (world.grid().map_or(0, |g| g.stats().items_scanned) - scanned_before) as f64;
    let n = steps as f64;
    Ok(Point {
        population: pop / n,
        search_seconds: search / n,
        distance_evals: evals / n,
        items_scanned: scanned / n,
        step_seconds: start.elapsed().as_secs_f64() / n,
    })
}

/// The search structure of a row of `animat_fig9.csv` (its `grid` and `cell_index`).
fn structure(grid: &str, cells: bool) -> &'static str {
    match (grid, cells) {
        ("none", _) => "exhaustive scan",
        (_, false) => "boxes",
        _ => "cells + boxes (default)",
    }
}

/// Draws `animat_fig9.png` from `animat_fig9.csv` in `dir`: search seconds per step against
/// the population, one line per grid box side and search structure.
pub fn fig9_chart(dir: &Path) -> Result<Vec<PathBuf>> {
    let data = Csv::read(&dir.join("animat_fig9.csv"))?;
    let (n, t) = (data.num("animats")?, data.num("search_seconds_per_step")?);
    let series = data
        .groups(&["grid", "cell_index"])?
        .into_iter()
        .map(|(key, rows)| {
            Series::new(
                format!("grid {}, {}", key[0], structure(&key[0], key[1] == "true")),
                rows.iter().map(|&i| (n[i], t[i])).collect(),
                Style::LinePoints,
            )
        })
        .collect();
    let path = dir.join("animat_fig9.png");
    chart::write_png(
        &Chart::log_log(
            "Animats: neighbour-search seconds per step against population",
            "animats",
            "search seconds per step",
            series,
        ),
        &path,
    )?;
    Ok(vec![path])
}

/// Run Fig. 9 / Table I and write `animat.md`.
pub fn run(ctx: &Ctx) -> Result<()> {
    let ladder: Vec<u64> = ctx.scale.pick(
        vec![300, 1000, 3000],
        vec![1000, 3000, 10_000, 30_000, 100_000],
        vec![1000, 3000, 10_000, 30_000, 100_000, 300_000, 1_000_000],
    );
    let steps = ctx.scale.pick(2, 3, 5);
    // (grid, cell index, largest population): the paper's grid boxes alone, the exhaustive
    // scan, and our default (grid boxes behind the dense cell index). The slow structures stop
    // where a step takes seconds (see docs/benchmarks.md, "Animats").
    let configs = [
        (
            GridBox::Side(60),
            false,
            ctx.scale.pick(3000, 100_000, 1_000_000),
        ),
        (
            GridBox::Side(120),
            false,
            ctx.scale.pick(3000, 100_000, 300_000),
        ),
        (
            GridBox::Side(240),
            false,
            ctx.scale.pick(3000, 30_000, 100_000),
        ),
        (GridBox::None, false, ctx.scale.pick(3000, 10_000, 30_000)),
        (
            GridBox::Side(60),
            true,
            ctx.scale.pick(3000, 100_000, 1_000_000),
        ),
    ];
    let mut doc =
        ctx.doc("Hawick, James & Scogings (2006): animats, neighbour-search cost against population (Fig. 9, Table I)");
    doc.p(&format!(
        "Worlds of N animats (foxes and rabbits in the default ratio, default rules and \
         parameters, vision 60) placed uniformly on a disc at a fixed density of {SCALING_DENSITY} \
         animats per cell (the default start's density), then {steps} timed steps. The search \
         time is the time spent inside perception queries (`--timing`). Rows marked *boxes* \
         use the paper's structure, grid boxes alone; the row marked *cells + boxes* is our \
         default, where a dense per-cell index answers adjacency, crowding and the first rings \
         of nearest/count queries before the grid boxes (`docs/animat.md`). The items the grid \
         searches examine are counted exactly (N per query without boxes, the halo's items \
         with them), so their gradient has no timer noise. Every setting gives the same \
         trajectory."
    ));
    let mut data = Table::new(&[
        "grid",
        "cell_index",
        "animats",
        "search_seconds_per_step",
        "distance_evals_per_step",
        "items_scanned_per_step",
        "step_seconds",
    ]);
    let mut table = Table::new(&[
        "grid box (cells)",
        "search structure",
        "populations",
        "gradient of search time (ours)",
        "gradient of items examined by the grid (ours)",
        "gradient (paper, Table I)",
    ]);
    for (grid, cells, max_n) in configs {
        let structure = structure(&grid_name(grid), cells);
        let mut pts = Vec::new();
        for &n in ladder.iter().filter(|&&n| n <= max_n) {
            ctx.log(&format!(
                "grid {}, {structure}: {n} animats",
                grid_name(grid)
            ));
            let p = measure(n, grid, cells, steps, ctx.seed)?;
            data.row(vec![
                grid_name(grid),
                cells.to_string(),
                format!("{:.0}", p.population),
                format!("{:e}", p.search_seconds),
                format!("{:.0}", p.distance_evals),
                format!("{:.0}", p.items_scanned),
                format!("{:e}", p.step_seconds),
            ]);
            pts.push(p);
        }
        let x: Vec<f64> = pts.iter().map(|p| p.population).collect();
        let t: Vec<f64> = pts.iter().map(|p| p.search_seconds).collect();
        let e: Vec<f64> = pts.iter().map(|p| p.items_scanned.max(1.0)).collect();
        let ft = Fit::log_log(&x, &t)?;
        let fe = Fit::log_log(&x, &e)?;
        let paper = if cells {
            "— (not in the paper; target <= 1.10)".to_string()
        } else {
            TABLE_I
                .iter()
                .find(|r| r.0 == grid_name(grid))
                .map(|r| pm(r.1, r.2))
                .unwrap_or_default()
        };
        table.row(vec![
            grid_name(grid),
            structure.into(),
            format!("{:.0} to {:.0}", x[0], x[x.len() - 1]),
            pm(ft.slope, ft.slope_stderr),
            if cells {
                "— (most queries never reach the grid)".into()
            } else {
                pm(fe.slope, fe.slope_stderr)
            },
            paper,
        ]);
    }
    ctx.table(&mut doc, &table, "animat_table1.csv")?;
    doc.p(
        "Gradients are least-squares slopes of log(cost) against log(population), ± their \
         standard errors. The paper fitted its curves over the populations its runs reached; our \
         ladder is given in the table. Populations grow during the measured steps, so each \
         point's population is the mean over them. Target for 60-cell boxes: gradient <= 1.10.",
    );
    data.write_csv(&ctx.path("animat_fig9.csv"))?;
    fig9_chart(&ctx.out)?;
    doc.image("search time against population", "animat_fig9.png");
    doc.p("Data: [`animat_fig9.csv`](animat_fig9.csv).");

    doc.h2("Whole-step throughput (default search: cells + 60-cell boxes)");
    let (warmup, tsteps) = ctx.scale.pick((1, 2), (2, 5), (3, 10));
    doc.p(&format!(
        "`animat::bench::step_throughput`: {warmup} unmeasured steps, then {tsteps} steps \
         without the search timer; animats alive at the start of each step, summed, per wall \
         second of stepping (world construction excluded), on one core."
    ));
    let mut t = Table::new(&[
        "animats at the start",
        "animat-steps per second",
        "thread CPU seconds per animat-step",
        "target",
    ]);
    for &n in ladder.iter().filter(|&&n| n <= 100_000) {
        ctx.log(&format!("throughput: {n} animats"));
        let r = step_throughput(
            n,
            SCALING_DENSITY,
            GridBox::Side(60),
            warmup,
            tsteps,
            ctx.seed,
        )?;
        t.row(vec![
            n.to_string(),
            sig(r.animat_steps_per_second, 3),
            r.cpu_seconds
                .filter(|&c| c > 0.0)
                .map(|c| sig(c / r.animat_steps as f64, 3))
                .unwrap_or_else(|| "n/a".into()),
            if n == 100_000 {
                ">= 5e6 animat-steps per second".into()
            } else {
                String::new()
            },
        ]);
    }
    ctx.table(&mut doc, &t, "animat_throughput.csv")?;
    doc.write(&ctx.path("animat.md"))
}
