//! `cargo xtask scale`: DLA at the sizes of the variable-precision paper's largest runs, on this
//! machine. Runs the `dla` release binary at 2D 1e6, 1e7, 3e7 and 1e8 and 3D 1e5, 1e6 and 1e7
//! with one thread and at the two largest sizes of each also with two (with `--quick`: 2D 1e5
//! and 1e6, 3D 1e5 and 1e6), and reports wall and CPU time, peak memory, microseconds and bytes
//! per particle, the fractal dimension and the prefactor, and what the walkers did per particle
//! (moves, map reads and jumps, tree queries, near-cache answers and rebuilds); then projects
//! the time and memory of 2D 1e9 and 3D 1e8.
//!
//! The projection uses only measured data: the growth samples of the largest one-thread run
//! give the time at every size, hence the marginal cost of a particle `m(N) = dT/dN`; over the
//! last decade it is fitted as `m(N) = a + b ln N` (the tree deepens with `ln N`) and integrated
//! from the largest size to the projected one. The two-thread projection divides by the
//! speed-up measured at the largest size; memory is a fixed part plus a part per particle, both
//! from the peak memory of the two sizes.

use crate::bench::{build, target_dir};
use crate::report::{Doc, Table, build_id, machine, pm, sig, utc_now};
use anyhow::{Context, Result, bail};
use core_lattice::Fit;
use run_io::RunManifest;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One measured run.
#[derive(Debug, Clone)]
pub struct ScaleRun {
    /// Dimension.
    pub dim: usize,
    /// Particles.
    pub particles: u64,
    /// Threads.
    pub threads: usize,
    /// Wall seconds of the process.
    pub wall: f64,
    /// CPU seconds.
    pub cpu: f64,
    /// Peak resident memory, bytes.
    pub peak_rss: f64,
    /// Fractal dimension and its standard error.
    pub fractal_dimension: (f64, f64),
    /// `ln` of the prefactor `A` of `N = A R_g^D`.
    pub ln_prefactor: f64,
    /// `(N, seconds)` from `growth.csv`.
    pub times: Vec<(f64, f64)>,
    /// The command that made it.
    pub command: String,
    /// What the walkers did (`results.walk_counts` of `run.json`), per particle, in the
    /// order of [`WALK_COUNTS`].
    pub walk: Vec<f64>,
}

/// The walk counts reported per particle (keys of `results.walk_counts`) and their column
/// names.
pub const WALK_COUNTS: [(&str, &str); 9] = [
    ("moves", "moves"),
    ("far_field", "far field"),
    ("map_reads", "map reads"),
    ("map_jumps", "map jumps"),
    ("tree_queries", "tree queries"),
    ("tree_nodes", "tree nodes read"),
    ("near_answers", "near-cache answers"),
    ("near_rebuilds", "near-cache rebuilds"),
    ("contact_tree", "contact searches in the tree"),
];

/// A projection to a size not run.
#[derive(Debug, Clone, Copy)]
pub struct Projection {
    /// Dimension.
    pub dim: usize,
    /// Particles projected to.
    pub particles: u64,
    /// Projected seconds with one thread.
    pub seconds_one: f64,
    /// Projected seconds with two threads.
    pub seconds_two: f64,
    /// Projected peak memory, bytes.
    pub peak_rss: f64,
}

#[derive(Debug, Deserialize)]
struct GrowthRow {
    n: f64,
    radius_of_gyration: f64,
    seconds: f64,
}

/// Runs `dla` with `args` into a fresh directory under `work` and reads what it measured.
fn measure(
    bin: &Path,
    work: &Path,
    dim: usize,
    particles: u64,
    threads: usize,
) -> Result<ScaleRun> {
    let out = work.join(format!("dla-{dim}d-{particles}-{threads}t"));
    if out.exists() {
        std::fs::remove_dir_all(&out).with_context(|| format!("clearing {}", out.display()))?;
    }
    let mut args = vec![
        "--dim".to_string(),
        dim.to_string(),
        "--particles".to_string(),
        particles.to_string(),
        "--threads".to_string(),
        threads.to_string(),
        "--seed".to_string(),
        "1".to_string(),
    ];
    if threads > 1 {
        // As the paper does: serially to a hundredth, then in parallel.
        args.extend(["--serial-until".to_string(), (particles / 100).to_string()]);
    }
    let command = format!("target/release/dla {} -q --out DIR", args.join(" "));
    eprintln!("==> {command}");
    crate::run_checked(
        Command::new(bin)
            .args(&args)
            .args(["-q", "--heartbeat", "60", "--out"])
            .arg(&out),
        &command,
    )?;
    let m = RunManifest::read(out.join("run.json")).context("reading run.json")?;
    let num = |k: &str| m.results.get(k).and_then(|v| v.as_f64());
    let mut times = Vec::new();
    let (mut rg, mut n) = (Vec::new(), Vec::new());
    let path = out.join("growth.csv");
    let mut reader =
        csv::Reader::from_path(&path).with_context(|| format!("reading {}", path.display()))?;
    for row in reader.deserialize::<GrowthRow>() {
        let row = row.with_context(|| format!("parsing {}", path.display()))?;
        times.push((row.n, row.seconds));
        if row.n >= 1000.0 {
            rg.push(row.radius_of_gyration);
            n.push(row.n);
        }
    }
    let fit = Fit::log_log(&rg, &n).context("fitting N against R_g")?;
    let counts = m
        .results
        .get("walk_counts")
        .context("run.json has no results.walk_counts")?;
    let walk = WALK_COUNTS
        .iter()
        .map(|(key, _)| {
            counts
                .get(key)
                .and_then(|v| v.as_f64())
                .map(|v| v / particles as f64)
                .with_context(|| format!("run.json has no walk_counts.{key}"))
        })
        .collect::<Result<_>>()?;
    let run = ScaleRun {
        walk,
        dim,
        particles,
        threads,
        wall: m.wall_seconds,
        cpu: m.cpu_seconds.unwrap_or(f64::NAN),
        peak_rss: m.peak_rss_bytes.map_or(f64::NAN, |b| b as f64),
        fractal_dimension: (fit.slope, fit.slope_stderr),
        ln_prefactor: fit.intercept,
        times,
        command,
    };
    if num("particles") != Some(particles as f64) {
        bail!(
            "{}: run.json does not report {particles} particles",
            out.display()
        );
    }
    // Only the manifest and the growth samples are kept.
    Ok(run)
}

/// The marginal cost of a particle over the last decade of `times`, fitted as `a + b ln N`:
/// `(a, b)`.
pub fn marginal_cost(times: &[(f64, f64)]) -> Result<(f64, f64)> {
    let last = times.last().context("no growth samples")?.0;
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for w in times.windows(2) {
        let ((n0, t0), (n1, t1)) = (w[0], w[1]);
        if n0 >= last / 10.0 && n1 > n0 {
            x.push(((n0 + n1) / 2.0).ln());
            y.push((t1 - t0) / (n1 - n0));
        }
    }
    let fit = Fit::linear(&x, &y).context("fitting the marginal cost")?;
    Ok((fit.intercept, fit.slope))
}

/// Seconds to grow from `from` to `to` particles at marginal cost `a + b ln N`.
pub fn integrate_cost((a, b): (f64, f64), from: f64, to: f64) -> f64 {
    let antiderivative = |n: f64| a * n + b * (n * n.ln() - n);
    antiderivative(to) - antiderivative(from)
}

/// Projects `dim` to `target` particles from the runs of that dimension (the largest size with
/// one and two threads, and the bytes per particle at both sizes).
fn project(runs: &[ScaleRun], dim: usize, target: u64) -> Result<Projection> {
    let of = |t: usize| -> Vec<&ScaleRun> {
        let mut v: Vec<&ScaleRun> = runs
            .iter()
            .filter(|r| r.dim == dim && r.threads == t)
            .collect();
        v.sort_by_key(|r| r.particles);
        v
    };
    let (one, two) = (of(1), of(2));
    let big = *one.last().context("no one-thread run")?;
    let cost = marginal_cost(&big.times)?;
    let t_end = big.times.last().map_or(0.0, |r| r.1);
    let growth_seconds = t_end + integrate_cost(cost, big.particles as f64, target as f64);
    // Process time beyond growth (start-up, outputs) scales with N too.
    let seconds_one = growth_seconds * big.wall / t_end.max(1e-9);
    let speedup = two
        .iter()
        .find(|r| r.particles == big.particles)
        .map_or(1.0, |r| big.wall / r.wall);
    // Peak memory as a fixed part plus a part per particle, from the two sizes.
    let peak_rss = match one.as_slice() {
        [.., a, b] if b.particles > a.particles => {
            let per = (b.peak_rss - a.peak_rss) / (b.particles - a.particles) as f64;
            b.peak_rss + per * (target - b.particles) as f64
        }
        [.., b] => b.peak_rss / b.particles as f64 * target as f64,
        [] => f64::NAN,
    };
    Ok(Projection {
        dim,
        particles: target,
        seconds_one,
        seconds_two: seconds_one / speedup,
        peak_rss,
    })
}

/// `cargo xtask scale`: build, run, report into `out` (markdown and CSV).
pub fn run(root: &Path, cargo: &str, quick: bool, out: Option<PathBuf>) -> Result<()> {
    let sizes: &[(usize, &[u64], u64)] = if quick {
        &[
            (2, &[100_000, 1_000_000], 1_000_000_000),
            (3, &[100_000, 1_000_000], 100_000_000),
        ]
    } else {
        &[
            (
                2,
                &[1_000_000, 10_000_000, 30_000_000, 100_000_000],
                1_000_000_000,
            ),
            (3, &[100_000, 1_000_000, 10_000_000], 100_000_000),
        ]
    };
    let out = out.unwrap_or_else(|| {
        let base = root.join("docs/results");
        if quick { base.join("quick") } else { base }
    });
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    build(root, cargo)?;
    let bin = target_dir(root).join("release/dla");
    let work = target_dir(root).join("scale-runs");
    let mut runs = Vec::new();
    for &(dim, ns, _) in sizes {
        for &n in ns {
            // Two threads at the two largest sizes of each dimension (the speed-up there
            // goes into the projection); one thread everywhere.
            let largest = ns.iter().rev().take(2).any(|&m| m == n);
            for threads in [1, 2] {
                if threads == 1 || largest {
                    runs.push(measure(&bin, &work, dim, n, threads)?);
                }
            }
        }
    }
    let mut table = Table::new(&[
        "D",
        "N",
        "threads",
        "wall s",
        "CPU s",
        "us/particle",
        "peak MB",
        "bytes/particle",
        "D_f",
        "ln A",
    ]);
    for r in &runs {
        let n = r.particles as f64;
        table.row(vec![
            r.dim.to_string(),
            sig(n, 3),
            r.threads.to_string(),
            format!("{:.1}", r.wall),
            format!("{:.1}", r.cpu),
            format!("{:.2}", r.wall / n * 1e6),
            format!("{:.0}", r.peak_rss / 1e6),
            format!("{:.1}", r.peak_rss / n),
            pm(r.fractal_dimension.0, r.fractal_dimension.1),
            format!("{:.3}", r.ln_prefactor),
        ]);
    }
    let mut names = vec!["D", "N", "threads"];
    names.extend(WALK_COUNTS.iter().map(|(_, name)| *name));
    let mut counts = Table::new(&names);
    for r in &runs {
        let mut row = vec![
            r.dim.to_string(),
            sig(r.particles as f64, 3),
            r.threads.to_string(),
        ];
        row.extend(r.walk.iter().map(|v| format!("{v:.2}")));
        counts.row(row);
    }
    let mut proj = Table::new(&[
        "D",
        "N",
        "one thread",
        "two threads",
        "peak memory",
        "the paper",
    ]);
    let paper = |dim: usize| {
        if dim == 2 {
            "10-14 h, one processor"
        } else {
            "4-4.5 h, one processor"
        }
    };
    for &(dim, _, target) in sizes {
        let p = project(&runs, dim, target)?;
        proj.row(vec![
            p.dim.to_string(),
            sig(p.particles as f64, 2),
            format!("{:.2} h", p.seconds_one / 3600.0),
            format!("{:.2} h", p.seconds_two / 3600.0),
            format!("{:.1} GiB", p.peak_rss / f64::from(1u32 << 30)),
            paper(dim).to_string(),
        ]);
    }
    let mut doc = Doc::new("DLA at scale: measured and projected");
    doc.p(&format!(
        "Generated by `cargo xtask scale{}` on {} with {} ({}). Every run is one process of the \
         `dla` release binary, seed 1; two-thread runs grow serially to a hundredth of their \
         size first. `us/particle` is wall time over N; `bytes/particle` is peak resident \
         memory over N. D_f and ln A are the slope and intercept of ln N = D_f ln R_g + ln A \
         over the growth samples with N >= 1000.",
        if quick { " --quick" } else { "" },
        utc_now(),
        build_id(),
        machine()
    ));
    doc.h2("Measured");
    doc.table(&table);
    table.write_csv(&out.join("scale.csv"))?;
    doc.h2("What the walkers did, per particle");
    doc.p(
        "From `results.walk_counts` of each run's `run.json`, divided by N. Every move is one \
         of: a far-field return, a jump by a distance map's bound, a jump by the tree's or the \
         near cache's distance, or a short step with a contact search. A map read is one per \
         near-field move (it reads one cell of each map level it needs); tree queries are the \
         variable-precision nearest-distance searches, and tree nodes read the nodes and \
         leaves they touched; near-cache rebuilds are range queries of the tree around a \
         walker close to the cluster.",
    );
    doc.table(&counts);
    counts.write_csv(&out.join("scale_counts.csv"))?;
    doc.h2("Projected");
    doc.p(
        "From the largest one-thread run of each dimension: the marginal cost of a particle \
         over its last decade, fitted as a + b ln N and integrated to the projected size; the \
         two-thread time divides that by the speed-up measured at the largest size; memory is a \
         fixed part plus a part per particle, both from the peak memory of the two largest \
         sizes with one thread (two threads share one tree and one set of maps, and peak a few \
         percent higher). The paper \
         (Sosa-Herrera & Rodriguez-Romo) reports its own hardware's times.",
    );
    doc.table(&proj);
    doc.h2("Commands");
    let mut cmds = String::new();
    for r in &runs {
        cmds.push_str(&format!("- `{}`\n", r.command));
    }
    doc.p(&cmds);
    let path = out.join("scale.md");
    doc.write(&path)?;
    eprintln!("==> {}", path.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cost_integral_matches_a_sum_and_the_fit_recovers_its_inputs() {
        // T(N) with marginal cost 2e-6 + 1e-7 ln N, sampled log-spaced.
        let (a, b) = (2e-6, 1e-7);
        let mut times = vec![(1000.0, 0.0)];
        let mut n: f64 = 1000.0;
        while n < 1e6 {
            let next = (n * 1.05).ceil();
            let t = times.last().unwrap().1 + integrate_cost((a, b), n, next);
            times.push((next, t));
            n = next;
        }
        let (fa, fb) = marginal_cost(&times).unwrap();
        assert!((fa - a).abs() < 1e-8 && (fb - b).abs() < 1e-9, "{fa} {fb}");
        // Against a plain sum over particles.
        let sum: f64 = (1000..2000)
            .map(|k| a + b * (f64::from(k) + 0.5).ln())
            .sum();
        assert!((integrate_cost((a, b), 1000.0, 2000.0) - sum).abs() < 1e-9);
    }
}
