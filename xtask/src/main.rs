//! Project automation, run as `cargo xtask <command>` (the alias lives in `.cargo/config.toml`).
//!
//! - `cargo xtask ci`: the checks CI runs: formatting, clippy with warnings denied (also on the
//!   model libraries without their `cli` feature), rustdoc with
//!   warnings denied, and the test suite (the README's test command).
//! - `cargo xtask scaling [--quick] [--only ...] [--out DIR]`: regenerate the papers' tables
//!   and figures from our own runs (see `docs/results/README.md`).
//! - `cargo xtask bench [--save FILE] [--against FILE] [--repeat R]`: the headline speed and
//!   memory figures as JSON, and their ratios to a saved baseline.

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::Command;
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
    /// Run every CI check: `cargo fmt --check`, `cargo clippy --all-targets -- -D warnings`,
    /// the model libraries' clippy without their `cli` feature, `cargo doc --no-deps` with
    /// warnings denied, and `cargo test --workspace`.
    Ci {
        /// Skip the test suite (formatting, lints and docs only).
        #[arg(long)]
        no_tests: bool,
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
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Run size: overrides --quick (`tiny` is the harness test's size).
        #[arg(long, value_enum, hide = true)]
        scale: Option<Scale>,
    },
    /// DLA at the papers' scale: 2D 1e7 and 1e8, 3D 1e6 and 1e7, one and two threads (about
    /// an hour and a half on 2 cores); time, memory, D_f, and projections to 2D 1e9 and 3D
    /// 1e8. Writes scale.md and scale.csv under --out.
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
        #[arg(long, default_value_t = 1)]
        repeat: usize,
    },
}

/// One CI step: a description and a cargo invocation.
struct Step {
    name: &'static str,
    args: &'static [&'static str],
    env: &'static [(&'static str, &'static str)],
}

/// The steps of `cargo xtask ci`, in order. The test step is the README's test command.
const CI_STEPS: &[Step] = &[
    Step {
        name: "format",
        args: &["fmt", "--all", "--", "--check"],
        env: &[],
    },
    Step {
        name: "clippy",
        args: &[
            "clippy",
            "--workspace",
            "--all-targets",
            "--",
            "-D",
            "warnings",
        ],
        env: &[],
    },
    Step {
        name: "libraries without the cli feature",
        args: &[
            "clippy",
            "-p",
            "dlca",
            "-p",
            "dla-pdla",
            "-p",
            "animat",
            "--no-default-features",
            "--",
            "-D",
            "warnings",
        ],
        env: &[],
    },
    Step {
        name: "rustdoc",
        args: &["doc", "--workspace", "--no-deps"],
        env: &[("RUSTDOCFLAGS", "-D warnings")],
    },
    Step {
        name: "tests",
        args: &["test", "--workspace"],
        env: &[],
    },
];

fn run_step(step: &Step) -> Result<()> {
    eprintln!("==> {}: cargo {}", step.name, step.args.join(" "));
    let start = Instant::now();
    let status = Command::new(cargo())
        .args(step.args)
        .envs(step.env.iter().copied())
        .current_dir(workspace_root())
        .status()
        .with_context(|| format!("could not start cargo for the {} step", step.name))?;
    if !status.success() {
        bail!("{} step failed ({status})", step.name);
    }
    eprintln!(
        "    {} passed in {:.1} s",
        step.name,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

fn ci(no_tests: bool) -> Result<()> {
    for step in CI_STEPS {
        if no_tests && step.name == "tests" {
            continue;
        }
        run_step(step)?;
    }
    eprintln!("==> all CI checks passed");
    Ok(())
}

fn main() -> Result<()> {
    match Cli::parse().command {
        Cmd::Ci { no_tests } => ci(no_tests),
        Cmd::Scaling {
            quick,
            only,
            out,
            seed,
            scale,
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
        } => xtask::bench::run(
            &workspace_root(),
            &cargo(),
            only.as_deref(),
            repeat,
            save.as_deref(),
            against.as_deref(),
        )
        .map(|_| ()),
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
            Cmd::Ci { no_tests: true }
        ));
        assert!(Cli::try_parse_from(["xtask", "frobnicate"]).is_err());
    }

    /// The README's test command is the one `cargo xtask ci` and `.ci/run` run.
    #[test]
    fn readme_test_command_matches_ci() {
        let root = workspace_root();
        let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
        let ci_script = std::fs::read_to_string(root.join(".ci/run")).unwrap();
        let test_step = CI_STEPS.iter().find(|s| s.name == "tests").unwrap();
        let command = format!("cargo {}", test_step.args.join(" "));
        assert!(
            readme.contains(&command),
            "README does not mention `{command}`"
        );
        assert!(
            ci_script.lines().any(|l| l.trim() == command),
            ".ci/run does not run `{command}`"
        );
    }
}
