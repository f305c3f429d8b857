//! Project automation, run as `cargo xtask <command>` (the alias lives in `.cargo/config.toml`).
//!
//! - `cargo xtask ci`: the checks CI runs (the one list, in `xtask::ci`): formatting, clippy with warnings denied (also on the
//!   model libraries without their `cli` feature), rustdoc with
//!   warnings denied, and the test suite (the README's test command).
//! - `cargo xtask scaling [--quick] [--only ...] [--out DIR]`: regenerate the papers' tables
//!   and figures from our own runs (see `docs/results/README.md`).
//! - `cargo xtask bench [--save FILE] [--against FILE] [--repeat R] [--instructions]`: the
//!   headline speed and memory figures as JSON, and their ratios to a saved baseline; with
//!   `--instructions`, instructions per particle counted by cachegrind.
//! - `cargo xtask compare [--fastdla P] [--dlaf P] [--dlca-cpp P] [--pairs N] [--save FILE]`:
//!   our binaries against other public codes, in interleaved pairs (`xtask::compare`).
//! - `cargo xtask generate`: the docs' flag tables and the Python stubs' keyword arguments
//!   written from the models' parameter declarations (`xtask::generate`).
//! - `cargo xtask fuzz [--cases N] [--only TEXT]`: every reader of user files fuzzed with N
//!   cases (default 1e5; `xtask::fuzz`).

use anyhow::Result;
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::time::Instant;
use xtask::scaling::{Experiment, Options, Scale};
use xtask::{cargo, workspace_root};

#[derive(Parser)]
#[command(
    name = "cargo xtask",
    about = "Project automation for the aggsim workspace"
)]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run every CI check, in order (the list is in xtask/src/ci.rs; `.ci/run` installs what
    /// they need and runs this): formatting, clippy with warnings denied (also the libraries
    /// without their default features), rustdoc, `cargo test --workspace`, `cargo package` of
    /// every library crate, the Python package and its tests, and feature `mpi` where Open MPI
    /// is installed.
    Ci {
        /// Skip the test suite (the step `tests`).
        #[arg(long)]
        no_tests: bool,
        /// Skip these steps (repeat or comma-separate): format, clippy, libraries-alone,
        /// libraries-figures, rustdoc, tests, loom, package, python-format, python-clippy,
        /// python-install, python-tests, mpi-clippy, mpi-tests.
        #[arg(long, value_delimiter = ',')]
        skip: Vec<String>,
    },
    /// Regenerate the papers' tables and figures from our own runs, with fitted exponents and
    /// error bars beside the published values: markdown, CSV and PNG under --out. Builds the
    /// release binaries first; multi-seed experiments run them as ensembles (`--seeds`) whose
    /// members stay in target/scaling-runs/.
    Scaling {
        /// Smaller sizes, under 3 minutes on 2 cores; every table says so. Default output
        /// directory: docs/results/quick/.
        #[arg(long)]
        quick: bool,
        /// Only these experiments (repeat or comma-separate); default all.
        #[arg(long, value_enum, value_delimiter = ',')]
        only: Vec<Experiment>,
        /// Output directory (default docs/results/, or docs/results/quick/ with --quick).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Base seed; the runs of an ensemble use seed, seed + 1, ...
        #[arg(long, default_value_t = 1, value_parser = run_io::count::count::<u64>)]
        seed: u64,
        /// Run size: overrides --quick (`tiny` is the harness test's size).
        #[arg(long, value_enum, hide = true)]
        scale: Option<Scale>,
        /// Run nothing: draw every chart again whose CSV is in the output directory (the
        /// accuracy sweeps' Pareto charts, Fig. 3, 5, 6, 9, the DLCA histograms and cost, the
        /// vpdist errors), with the functions the experiments draw them with, for a change of
        /// the charts' style.
        #[arg(long)]
        replot: bool,
    },
    /// DLA at the papers' scale: 2D 1e6 to 1e8 and 3D 1e5 to 1e7 with one thread, the two
    /// largest sizes of each also with two (about an hour on 2 cores); time, memory, D_f, what
    /// the walkers did per particle, and projections to 2D 1e9 and 3D 1e8. Writes scale.md,
    /// scale.csv and scale_counts.csv under --out.
    Scale {
        /// 2D 1e5 and 1e6, 3D 1e5 and 1e6 (about a minute); default output docs/results/quick/.
        #[arg(long)]
        quick: bool,
        /// Output directory (default docs/results/, or docs/results/quick/ with --quick).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Run the headline workloads as release binaries and print JSON: seconds, peak RSS,
    /// per-item rates.
    Bench {
        /// Write the JSON report to this file (a baseline for --against).
        #[arg(long)]
        save: Option<PathBuf>,
        /// Compare with a saved report: prints now/baseline ratios (> 1 is slower).
        #[arg(long)]
        against: Option<PathBuf>,
        /// Only workloads whose name contains this text.
        #[arg(long)]
        only: Option<String>,
        /// Run every workload this many times, in rounds, and keep each one's fastest run
        /// (for shared or noisy machines; every repeat's time is in the JSON).
        #[arg(long, default_value_t = 1, value_parser = run_io::count::count_at_least_1::<usize>)]
        repeat: usize,
        /// Count instructions instead of timing: 2D and 3D DLA at 1e6, one thread, under
        /// `valgrind --tool=cachegrind --cache-sim=no` (a few minutes; the same count on a busy
        /// or quiet host), as instructions per particle.
        #[arg(long)]
        instructions: bool,
    },
    /// Time our binaries against other public codes on the same workloads, in interleaved
    /// pairs (alternating which runs first), and print the medians and the median of the
    /// per-pair ratios as a markdown table. The other codes are built by you from their own
    /// sources, outside this repository (docs/benchmarks.md, "Against other codes"); give the
    /// path of each one to compare with. Run it on a quiet machine.
    Compare {
        /// mathsjames/fastDLA's binary: 2D DLA with 1e6 particles, one thread.
        #[arg(long)]
        fastdla: Option<PathBuf>,
        /// fogleman/dlaf's binary built with `D = 3` and `DefaultAttractionDistance = 1`: 3D
        /// DLA with 1e5 particles.
        #[arg(long)]
        dlaf: Option<PathBuf>,
        /// rob10campbell/DLCA's `bin/dlca`: DLCA on 1024^2 with 50 000 particles to one
        /// cluster.
        #[arg(long)]
        dlca_cpp: Option<PathBuf>,
        /// Pairs per comparison (seeds 1, 2, ...).
        #[arg(long, default_value_t = 5, value_parser = run_io::count::count_at_least_1::<usize>)]
        pairs: usize,
        /// Write the JSON report to this file.
        #[arg(long)]
        save: Option<PathBuf>,
    },
    /// Measure this machine's memory latency: a pointer chase through one random cycle of
    /// cache lines, at working sets from 16 KiB to --max (powers of two), with 4 KiB pages and
    /// with transparent huge pages; prints a markdown table (the floor under DLA's cost per
    /// memory read, docs/benchmarks.md "DLA at scale"). Run it on a quiet machine.
    Latency {
        /// Largest working set, in bytes (suffixes K, M, G).
        #[arg(long, default_value = "4G", value_parser = run_io::memory::parse_bytes)]
        max: u64,
        /// Dependent loads timed per size.
        #[arg(long, default_value_t = 20_000_000)]
        loads: u64,
    },
    /// Write what is generated from the models' parameter declarations into the files people
    /// read: the docs' flag tables and the Python stubs' keyword arguments, between their
    /// marker lines (the test suite fails while they are stale).
    Generate,
    /// Fuzz every reader of a file a user can hand the programs (checkpoints, positions.npy,
    /// config files, ensemble members for --merge) with many cases of arbitrary bytes and
    /// mutated valid files; prints cases and seconds per reader (xtask/src/fuzz.rs).
    Fuzz {
        /// Cases per reader.
        #[arg(long, default_value_t = 100_000, value_parser = run_io::count::count::<u64>)]
        cases: u64,
        /// Only readers (or tests) whose name contains this text.
        #[arg(long)]
        only: Option<String>,
    },
}

fn main() -> Result<()> {
    match Cli::parse().command {
        Cmd::Ci { no_tests, mut skip } => {
            if no_tests {
                skip.push("tests".to_string());
            }
            xtask::ci::run(&skip)
        }
        Cmd::Scaling {
            quick,
            only,
            out,
            seed,
            scale,
            replot,
        } => {
            let scale = scale.unwrap_or(if quick { Scale::Quick } else { Scale::Full });
            let out = out.unwrap_or_else(|| {
                let base = workspace_root().join("docs/results");
                if scale == Scale::Full {
                    base
                } else {
                    base.join("quick")
                }
            });
            if replot {
                let done = xtask::scaling::replot::replot(&out)?;
                for p in &done.written {
                    eprintln!("==> {}", p.display());
                }
                for csv in &done.missing {
                    eprintln!(
                        "    no {csv} in {}: its chart is left as it is",
                        out.display()
                    );
                }
                anyhow::ensure!(
                    !done.written.is_empty(),
                    "no chart CSV to replot in {}",
                    out.display()
                );
                return Ok(());
            }
            let command = std::iter::once("cargo xtask".to_string())
                .chain(std::env::args().skip(1))
                .collect::<Vec<_>>()
                .join(" ");
            // The multi-seed experiments run the model binaries' own ensembles.
            let root = workspace_root();
            xtask::bench::build(&root, &cargo())?;
            let target = xtask::bench::target_dir(&root);
            let start = Instant::now();
            let times = xtask::scaling::run(&Options {
                scale,
                only,
                out: out.clone(),
                seed,
                command,
                bin_dir: target.join("release"),
                runs: target
                    .join("scaling-runs")
                    .join(scale.name().split(' ').next().unwrap_or("runs")),
            })?;
            eprintln!(
                "==> {} experiment(s) in {:.1} s; reports in {}",
                times.len(),
                start.elapsed().as_secs_f64(),
                out.display()
            );
            Ok(())
        }
        Cmd::Scale { quick, out } => xtask::scale::run(&workspace_root(), &cargo(), quick, out),
        Cmd::Bench {
            save,
            against,
            only,
            repeat,
            instructions,
        } => xtask::bench::run(
            &workspace_root(),
            &cargo(),
            only.as_deref(),
            repeat,
            instructions,
            save.as_deref(),
            against.as_deref(),
        )
        .map(|_| ()),
        Cmd::Compare {
            fastdla,
            dlaf,
            dlca_cpp,
            pairs,
            save,
        } => {
            let others: Vec<(&str, PathBuf)> =
                [("fastdla", fastdla), ("dlaf", dlaf), ("dlca-cpp", dlca_cpp)]
                    .into_iter()
                    .filter_map(|(f, p)| p.map(|p| (f, p)))
                    .collect();
            xtask::compare::run(&workspace_root(), &cargo(), &others, pairs, save.as_deref())
                .map(|_| ())
        }
        Cmd::Latency { max, loads } => {
            print!("{}", xtask::probe::latency_table(max as usize, loads));
            Ok(())
        }
        Cmd::Generate => {
            let changed = xtask::generate::run(&workspace_root())?;
            for f in &changed {
                eprintln!("==> {f}");
            }
            if changed.is_empty() {
                eprintln!("==> every generated block is current");
            }
            Ok(())
        }
        Cmd::Fuzz { cases, only } => {
            xtask::fuzz::run(&workspace_root(), &cargo(), cases, only.as_deref())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cli_parses() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
        assert!(matches!(
            Cli::try_parse_from(["xtask", "ci", "--no-tests"])
                .unwrap()
                .command,
            Cmd::Ci { no_tests: true, .. }
        ));
        assert!(Cli::try_parse_from(["xtask", "frobnicate"]).is_err());
    }
}
