//! Seed 000, animats (sections II.B, IV.B): neighbour-search time per step against population
//! for grid boxes of 60, 120 and 240 cells and no grid (Fig. 9), and the fitted log-log
//! gradients (Table I).

use super::Ctx;
use crate::plot::{self, Chart, Series, Style};
use crate::report::{Table, pm, sig};
use animat::{GridBox, Params, World};
use anyhow::Result;
use core_lattice::LogLogFit;

/// Animats per cell of the start disc, the same for every population of the ladder.
pub const DENSITY: f64 = 0.01;

/// Seed 000, Table I: fitted gradients and their errors, as printed.
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

/// Build a world of `animats` at [`DENSITY`] with the default species ratio, run `steps` steps
/// (with the per-query search timer when `timing`) and return the per-step costs.
pub fn measure(animats: u64, grid: GridBox, steps: u64, seed: u64, timing: bool) -> Result<Point> {
    let d = Params::default();
    let foxes = (animats as f64 * d.foxes as f64 / (d.foxes + d.rabbits) as f64).round() as u64;
    let params = Params {
        foxes,
        rabbits: animats - foxes,
        start_radius: Params::radius_for_density(animats, DENSITY),
        grid_box: grid,
        ..d
    };
    let mut world = World::new(params, seed)?;
    world.set_timing(timing);
    let (mut pop, mut search, mut evals) = (0.0, 0.0, 0.0);
    let scanned_before = world.grid().stats().items_scanned;
    let start = std::time::Instant::now();
    for _ in 0..steps {
        pop += (world.foxes() + world.rabbits()) as f64;
        let s = world.step();
        search += s.search_seconds;
        evals += s.distance_evals as f64;
    }
    let scanned = (world.grid().stats().items_scanned - scanned_before) as f64;
    let n = steps as f64;
    Ok(Point {
        population: pop / n,
        search_seconds: search / n,
        distance_evals: evals / n,
        items_scanned: scanned / n,
        step_seconds: start.elapsed().as_secs_f64() / n,
    })
}

/// Run Fig. 9 / Table I and write `animat.md`.
pub fn run(ctx: &Ctx) -> Result<()> {
    let ladder: Vec<u64> = ctx.scale.pick(
        vec![300, 1000, 3000],
        vec![1000, 3000, 10_000, 30_000, 100_000],
        vec![1000, 3000, 10_000, 30_000, 100_000, 300_000, 1_000_000],
    );
    let none_max = ctx.scale.pick(3000, 10_000, 30_000);
    let steps = ctx.scale.pick(2, 3, 5);
    let grids = [
        GridBox::Side(60),
        GridBox::Side(120),
        GridBox::Side(240),
        GridBox::None,
    ];
    let mut doc =
        ctx.doc("Seed 000: animats, neighbour-search cost against population (Fig. 9, Table I)");
    doc.p(&format!(
        "Worlds of N animats (foxes and rabbits in the default ratio, default rules and \
         parameters, vision 60) placed uniformly on a disc at a fixed density of {DENSITY} \
         animats per cell, then {steps} timed steps. The search time is the time spent inside \
         perception queries (`--timing`). The items the searches examine are counted exactly \
         (N per query without boxes, the halo's items with them), so their gradient has no \
         timer noise; distance evaluations count only the candidates that pass the per-axis \
         test, so they grow like N with or without boxes. Every grid setting gives the same \
         trajectory."
    ));
    let mut data = Table::new(&[
        "grid",
        "animats",
        "search_seconds_per_step",
        "distance_evals_per_step",
        "items_scanned_per_step",
        "step_seconds",
    ]);
    let mut table = Table::new(&[
        "grid box (cells)",
        "populations",
        "gradient of search time (ours)",
        "gradient of items examined (ours)",
        "gradient (seed 000, Table I)",
    ]);
    let mut series = Vec::new();
    let mut throughput = Vec::new();
    for grid in grids {
        let mut pts = Vec::new();
        for &n in ladder
            .iter()
            .filter(|&&n| grid != GridBox::None || n <= none_max)
        {
            ctx.log(&format!("grid {}: {n} animats", grid_name(grid)));
            let p = measure(n, grid, steps, ctx.seed, true)?;
            data.row(vec![
                grid_name(grid),
                format!("{:.0}", p.population),
                format!("{:e}", p.search_seconds),
                format!("{:.0}", p.distance_evals),
                format!("{:.0}", p.items_scanned),
                format!("{:e}", p.step_seconds),
            ]);
            if grid == GridBox::Side(60) {
                // Whole steps without the per-query timer.
                let q = measure(n, grid, steps, ctx.seed, false)?;
                throughput.push((q.population, q.population / q.step_seconds));
            }
            pts.push(p);
        }
        let x: Vec<f64> = pts.iter().map(|p| p.population).collect();
        let t: Vec<f64> = pts.iter().map(|p| p.search_seconds).collect();
        let e: Vec<f64> = pts.iter().map(|p| p.items_scanned).collect();
        let ft = LogLogFit::fit(&x, &t)?;
        let fe = LogLogFit::fit(&x, &e)?;
        let paper = TABLE_I
            .iter()
            .find(|r| r.0 == grid_name(grid))
            .map(|r| pm(r.1, r.2))
            .unwrap_or_default();
        table.row(vec![
            grid_name(grid),
            format!("{:.0} to {:.0}", x[0], x[x.len() - 1]),
            pm(ft.slope, ft.slope_stderr),
            pm(fe.slope, fe.slope_stderr),
            paper,
        ]);
        series.push(Series::new(
            format!("grid {}", grid_name(grid)),
            x.iter().copied().zip(t.iter().copied()).collect(),
            Style::LinePoints,
        ));
    }
    ctx.table(&mut doc, &table, "animat_table1.csv")?;
    doc.p(
        "Gradients are least-squares slopes of log(cost) against log(population), ± their \
         standard errors. Seed 000 fitted its curves over the populations its runs reached; our \
         ladder is given in the table. Target for 60-cell boxes: gradient <= 1.10.",
    );
    data.write_csv(&ctx.path("animat_fig9.csv"))?;
    plot::write_png(
        &Chart {
            title: "Animats: neighbour-search seconds per step against population".into(),
            x_label: "animats".into(),
            y_label: "search seconds per step".into(),
            log_x: true,
            log_y: true,
            series,
        },
        &ctx.path("animat_fig9.png"),
    )?;
    doc.image("search time against population", "animat_fig9.png");
    doc.p("Data: [`animat_fig9.csv`](animat_fig9.csv).");
    doc.h2("Whole-step throughput (60-cell boxes)");
    doc.p(
        "The same worlds stepped again without the search timer: animats alive at the start of \
         each step, summed over the steps, per wall second of stepping (world construction \
         excluded), on one core.",
    );
    let mut t = Table::new(&["animats", "animat-steps per second", "target"]);
    for (n, r) in throughput {
        t.row(vec![
            format!("{n:.0}"),
            sig(r, 3),
            if (n - 1e5).abs() < 2e4 {
                ">= 5e6 at 1e5 animats".into()
            } else {
                String::new()
            },
        ]);
    }
    ctx.table(&mut doc, &t, "animat_throughput.csv")?;
    doc.write(&ctx.path("animat.md"))
}
