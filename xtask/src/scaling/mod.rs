//! `cargo xtask scaling`: regenerate the papers' quantitative results from our own runs.
//!
//! Each experiment writes, into the output directory, a markdown report (`<name>.md`) with our
//! values, their standard errors and the papers' values side by side, the CSV data behind every
//! table and chart, and PNG charts. `index.md` records the date, machine, command and the time
//! each experiment took. Every number in the reports comes from runs made by the command that
//! wrote them, except the papers' values, which are labelled as such.

pub mod accuracy;
pub mod animat;
pub mod csvfile;
pub mod deposit;
pub mod dla;
pub mod dlca;
pub mod dlca_dimension;
pub mod ensemble;
pub mod family;
pub mod replot;

use crate::report::{Doc, Table, build_id, machine, sig, utc_now};
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// How big the runs are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Scale {
    /// Seconds in total: only for the harness's own test.
    Tiny,
    /// Under three minutes on 2 cores (`--quick`): the same tables at smaller sizes.
    Quick,
    /// The documented full run (see `docs/results/README.md` for its time).
    Full,
}

impl Scale {
    /// Name used in reports.
    pub fn name(self) -> &'static str {
        match self {
            Scale::Tiny => "tiny (harness test)",
            Scale::Quick => "quick",
            Scale::Full => "full",
        }
    }

    /// Pick a value by scale.
    pub fn pick<T>(self, tiny: T, quick: T, full: T) -> T {
        match self {
            Scale::Tiny => tiny,
            Scale::Quick => quick,
            Scale::Full => full,
        }
    }
}

/// The experiments, in the order they run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Experiment {
    /// Hawick, James & Scogings (2006), DLCA: Figs. 4-8 and the sweep cost against N.
    Dlca,
    /// Hawick, James & Scogings (2006), animats: Fig. 9 and Table I.
    Animat,
    /// Sosa-Herrera & Rodriguez-Romo, DLA: Fig. 3, Table 2, the PDLA speed-up.
    Dla,
    /// Accuracy against speed for DLA: precision, step length, far field.
    Accuracy,
    /// The DLA family beyond the plain model: branch orders of the cluster as a tree.
    Family,
    /// Deposits on a substrate with drift, up to ballistic deposition and aggregation.
    Deposit,
}

impl Experiment {
    /// Every experiment.
    pub const ALL: [Experiment; 6] = [
        Experiment::Dlca,
        Experiment::Animat,
        Experiment::Dla,
        Experiment::Accuracy,
        Experiment::Family,
        Experiment::Deposit,
    ];

    /// File stem and flag value.
    pub fn name(self) -> &'static str {
        match self {
            Experiment::Dlca => "dlca",
            Experiment::Animat => "animat",
            Experiment::Dla => "dla",
            Experiment::Accuracy => "accuracy",
            Experiment::Family => "family",
            Experiment::Deposit => "deposit",
        }
    }
}

/// What `cargo xtask scaling` was asked to do.
#[derive(Debug, Clone)]
pub struct Options {
    /// Run sizes.
    pub scale: Scale,
    /// Only these experiments (all when empty).
    pub only: Vec<Experiment>,
    /// Output directory.
    pub out: PathBuf,
    /// Base seed; run `i` of an ensemble uses `seed + i`.
    pub seed: u64,
    /// The command line, recorded in every report.
    pub command: String,
    /// Where the model binaries are (`dla`, `dlca`, `animat`): the multi-seed experiments run
    /// them as ensembles (`--seeds`).
    pub bin_dir: PathBuf,
    /// Where the ensembles' members go (one directory per ensemble, cleared before it runs).
    pub runs: PathBuf,
}

/// Shared by the experiments: where to write, at what scale, and the provenance line.
#[derive(Debug)]
pub struct Ctx {
    /// Run sizes.
    pub scale: Scale,
    /// Output directory.
    pub out: PathBuf,
    /// Base seed.
    pub seed: u64,
    /// Where the model binaries are.
    pub bin_dir: PathBuf,
    /// Where the ensembles' members go.
    pub runs: PathBuf,
    provenance: String,
}

impl Ctx {
    /// Path of an output file.
    pub fn path(&self, file: &str) -> PathBuf {
        self.out.join(file)
    }

    /// A report with its title and provenance paragraph.
    pub fn doc(&self, title: &str) -> Doc {
        let mut d = Doc::new(title);
        d.p(&self.provenance);
        if self.scale != Scale::Full {
            d.p(&format!(
                "**Scale: {}.** These runs are smaller than the papers' and than the full \
                 run (`cargo xtask scaling`); sizes are given in each table. Expect larger \
                 error bars and finite-size shifts.",
                self.scale.name()
            ));
        }
        d
    }

    /// Write a table's CSV next to the report and add the table to the report.
    pub fn table(&self, doc: &mut Doc, table: &Table, csv: &str) -> Result<()> {
        table.write_csv(&self.path(csv))?;
        doc.table(table);
        doc.p(&format!("Data: [`{csv}`]({csv})."));
        Ok(())
    }

    /// Progress on stderr.
    pub fn log(&self, msg: &str) {
        eprintln!("    {msg}");
    }
}

/// Run the chosen experiments; returns the seconds each took.
pub fn run(opts: &Options) -> Result<Vec<(Experiment, f64)>> {
    std::fs::create_dir_all(&opts.out)
        .with_context(|| format!("creating {}", opts.out.display()))?;
    let date = utc_now();
    let host = machine();
    let ctx = Ctx {
        scale: opts.scale,
        out: opts.out.clone(),
        seed: opts.seed,
        bin_dir: opts.bin_dir.clone(),
        runs: opts.runs.clone(),
        provenance: format!(
            "Generated by `{}` on {date} with {}. Machine: {host}. Scale: {}. Base seed {}.",
            opts.command,
            build_id(),
            opts.scale.name(),
            opts.seed
        ),
    };
    let chosen: Vec<Experiment> = if opts.only.is_empty() {
        Experiment::ALL.to_vec()
    } else {
        Experiment::ALL
            .into_iter()
            .filter(|e| opts.only.contains(e))
            .collect()
    };
    let mut times = Vec::new();
    for e in chosen {
        eprintln!("==> {} ({})", e.name(), opts.scale.name());
        let start = Instant::now();
        match e {
            Experiment::Dlca => dlca::run(&ctx),
            Experiment::Animat => animat::run(&ctx),
            Experiment::Dla => dla::run(&ctx),
            Experiment::Accuracy => accuracy::run(&ctx),
            Experiment::Family => family::run(&ctx),
            Experiment::Deposit => deposit::run(&ctx),
        }
        .with_context(|| format!("experiment {}", e.name()))?;
        let secs = start.elapsed().as_secs_f64();
        eprintln!("    {} done in {secs:.1} s", e.name());
        times.push((e, secs));
    }
    write_index(&ctx, &opts.out, &times, &date, &host, &opts.command)?;
    Ok(times)
}

fn write_index(
    ctx: &Ctx,
    out: &Path,
    times: &[(Experiment, f64)],
    date: &str,
    host: &str,
    command: &str,
) -> Result<()> {
    let path = out.join("index.md");
    // Rows of experiments this invocation did not run are kept from the previous index, marked
    // with the date and command that made them.
    let previous = std::fs::read_to_string(&path).unwrap_or_default();
    let mut doc = Doc::new("Scaling results: index");
    let mut t = Table::new(&["experiment", "report", "seconds", "made by", "date"]);
    for e in Experiment::ALL {
        if let Some((_, s)) = times.iter().find(|(x, _)| *x == e) {
            t.row(vec![
                e.name().to_string(),
                format!("[{0}.md]({0}.md)", e.name()),
                sig(*s, 3),
                format!("`{command}`"),
                date.to_string(),
            ]);
        } else if let Some(row) = previous_row(&previous, e) {
            t.row(row);
        }
    }
    doc.p(&format!(
        "Last command: `{command}`. Date: {date}. Machine: {host}. Scale: {}. Each report \
         states the command, date and machine that made it.",
        ctx.scale.name()
    ));
    doc.table(&t);
    doc.write(&path)
}

/// The row of `e` in a previous index written by [`write_index`], if any.
fn previous_row(index: &str, e: Experiment) -> Option<Vec<String>> {
    let prefix = format!("| {} | ", e.name());
    let line = index.lines().find(|l| l.starts_with(&prefix))?;
    let cells: Vec<String> = line
        .trim_matches('|')
        .split(" | ")
        .map(|c| c.trim().to_string())
        .collect();
    (cells.len() == 5).then_some(cells)
}

/// About `n` log-spaced integers from `lo` to `hi` inclusive, deduplicated.
pub fn log_spaced(lo: u64, hi: u64, n: usize) -> Vec<u64> {
    let (a, b) = ((lo.max(1) as f64).ln(), (hi.max(1) as f64).ln());
    let mut v: Vec<u64> = (0..n)
        .map(|i| {
            (a + (b - a) * i as f64 / (n.max(2) - 1) as f64)
                .exp()
                .round() as u64
        })
        .collect();
    v.dedup();
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_keeps_rows_of_experiments_not_rerun() {
        let dir = tempfile::tempdir().unwrap();
        let ctx = Ctx {
            scale: Scale::Tiny,
            out: dir.path().to_path_buf(),
            seed: 1,
            bin_dir: PathBuf::new(),
            runs: PathBuf::new(),
            provenance: String::new(),
        };
        write_index(
            &ctx,
            dir.path(),
            &[(Experiment::Dlca, 1.0), (Experiment::Dla, 2.0)],
            "d1",
            "m",
            "c1",
        )
        .unwrap();
        write_index(&ctx, dir.path(), &[(Experiment::Dla, 3.0)], "d2", "m", "c2").unwrap();
        let text = std::fs::read_to_string(dir.path().join("index.md")).unwrap();
        assert!(
            text.contains("| dlca | [dlca.md](dlca.md) | 1.00 | `c1` | d1 |"),
            "{text}"
        );
        assert!(
            text.contains("| dla | [dla.md](dla.md) | 3.00 | `c2` | d2 |"),
            "{text}"
        );
        assert!(!text.contains("animat"));
    }

    #[test]
    fn log_spaced_has_constant_ratio_and_ends_included() {
        assert_eq!(log_spaced(1, 1000, 4), vec![1, 10, 100, 1000]);
        // Consecutive ratios are equal (up to rounding to integers) and both ends are included.
        let v = log_spaced(10, 1_000_000, 11);
        assert_eq!((v[0], *v.last().unwrap()), (10, 1_000_000));
        let ratio = (1e5f64).powf(0.1);
        for w in v.windows(2) {
            let r = w[1] as f64 / w[0] as f64;
            assert!((r / ratio - 1.0).abs() < 0.05, "{v:?}");
        }
        // Rounding collisions at the low end are removed, not repeated.
        let d = log_spaced(1, 4, 10);
        assert!(d.windows(2).all(|w| w[0] < w[1]), "{d:?}");
        assert_eq!((d[0], *d.last().unwrap()), (1, 4));
    }
}
