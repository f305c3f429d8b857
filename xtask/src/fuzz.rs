//! `cargo xtask fuzz [--cases N] [--only TEXT]`: the fuzz targets of every reader of a file a
//! user can hand the programs, run with many cases. Each target is one proptest test in the
//! reader's crate (`fuzz_*`, inputs from `run_cli::fuzz`); `cargo test` runs a few cases of
//! each (`run_cli::fuzz::DEFAULT_CASES`), this runs `--cases` of each (default 1e5) through
//! `AGGSIM_FUZZ_CASES`, one target at a time, and prints the cases and seconds per reader. A
//! failing case is shrunk by proptest and its seed saved under the crate's
//! `proptest-regressions/`, so it stays a regression test.

use anyhow::{Context, Result, bail};
use std::path::Path;
use std::process::Command;
use std::time::Instant;

/// A fuzz target: the reader it exercises and the test that does it.
#[derive(Debug, Clone, Copy)]
pub struct Target {
    /// The reader, as the report names it.
    pub reader: &'static str,
    /// Package holding the test.
    pub package: &'static str,
    /// `cargo test` arguments selecting the test's target (features, `--lib` or `--test`).
    pub select: &'static [&'static str],
    /// The source file that defines the test, relative to the workspace root.
    pub file: &'static str,
    /// The test's path inside its target.
    pub test: &'static str,
}

const SIM_RUN: &[&str] = &["--features", "cli,test-support", "--lib"];
const FUZZ: &[&str] = &["--test", "fuzz"];

/// Every fuzz target, one per reader.
pub const TARGETS: &[Target] = &[
    Target {
        reader: "checkpoint envelope (run_io::checkpoint)",
        package: "run-cli",
        select: SIM_RUN,
        file: "crates/run-cli/src/fuzz.rs",
        test: "fuzz::tests::fuzz_checkpoint_envelope",
    },
    Target {
        reader: ".npy reader (run_io::npy)",
        package: "run-cli",
        select: SIM_RUN,
        file: "crates/run-cli/src/fuzz.rs",
        test: "fuzz::tests::fuzz_npy_reader",
    },
    Target {
        reader: "run.json (run_io::manifest)",
        package: "run-cli",
        select: SIM_RUN,
        file: "crates/run-cli/src/fuzz.rs",
        test: "fuzz::tests::fuzz_run_manifest",
    },
    Target {
        reader: "--config TOML (run_cli::cli::config)",
        package: "run-cli",
        select: SIM_RUN,
        file: "crates/run-cli/src/fuzz.rs",
        test: "fuzz::tests::fuzz_config_file",
    },
    Target {
        reader: "--merge members (run_cli::ensemble::merge)",
        package: "run-cli",
        select: SIM_RUN,
        file: "crates/run-cli/src/fuzz.rs",
        test: "fuzz::tests::fuzz_merge_members",
    },
    Target {
        reader: "dla --resume (checkpoint.bin, positions.npy)",
        package: "dla-pdla",
        select: FUZZ,
        file: "crates/dla-pdla/tests/fuzz.rs",
        test: "fuzz_dla_resume",
    },
    Target {
        reader: "dlca --resume (checkpoint.bin)",
        package: "dlca",
        select: FUZZ,
        file: "crates/dlca/tests/fuzz.rs",
        test: "fuzz_dlca_checkpoint",
    },
    Target {
        reader: "animat --resume (checkpoint.bin)",
        package: "animat",
        select: FUZZ,
        file: "crates/animat/tests/fuzz.rs",
        test: "fuzz_animat_checkpoint",
    },
];

fn command(cargo: &str, root: &Path, t: &Target) -> Command {
    let mut c = Command::new(cargo);
    c.current_dir(root)
        .args(["test", "-p", t.package])
        .args(t.select);
    c
}

/// Runs every target (or those whose reader or test contains `only`) with `cases` cases and
/// prints a table of cases and seconds per reader; fails at the first target that fails.
///
/// # Errors
/// A build or a fuzz target failed.
pub fn run(root: &Path, cargo: &str, cases: u64, only: Option<&str>) -> Result<()> {
    let chosen: Vec<&Target> = TARGETS
        .iter()
        .filter(|t| only.is_none_or(|o| t.reader.contains(o) || t.test.contains(o)))
        .collect();
    if chosen.is_empty() {
        bail!("no fuzz target matches --only {}", only.unwrap_or(""));
    }
    for t in &chosen {
        let ok = command(cargo, root, t)
            .arg("--no-run")
            .status()
            .context("running cargo")?
            .success();
        if !ok {
            bail!("building the fuzz target {} failed", t.test);
        }
    }
    let mut rows = Vec::new();
    for t in chosen {
        eprintln!("==> {} ({cases} cases): {}", t.reader, t.test);
        let start = Instant::now();
        let ok = command(cargo, root, t)
            .env("AGGSIM_FUZZ_CASES", cases.to_string())
            .args(["--", "--exact", t.test])
            .status()
            .context("running cargo")?
            .success();
        let seconds = start.elapsed().as_secs_f64();
        if !ok {
            bail!(
                "fuzz target {} ({}) failed after {seconds:.1} s; proptest saved the failing seed \
                 under the crate's proptest-regressions/",
                t.test,
                t.reader
            );
        }
        rows.push((t.reader, seconds));
    }
    println!("| reader | cases | seconds |");
    println!("|---|---|---|");
    for (reader, seconds) in rows {
        println!("| {reader} | {cases} | {seconds:.1} |");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_target_names_a_test_that_exists() {
        let root = crate::workspace_root();
        for t in TARGETS {
            let text = std::fs::read_to_string(root.join(t.file)).unwrap();
            let name = t.test.rsplit("::").next().unwrap();
            assert!(
                text.contains(&format!("fn {name}(")),
                "{} has no fn {name}",
                t.file
            );
        }
    }
}
