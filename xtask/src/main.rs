//! Project automation, run as `cargo xtask <command>` (the alias lives in `.cargo/config.toml`).
//!
//! - `cargo xtask ci`: the checks CI runs: formatting, clippy with warnings denied, rustdoc with
//!   warnings denied, and the test suite (the README's test command).

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::Command;
use std::time::Instant;

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
    /// `cargo doc --no-deps` with warnings denied, and `cargo test --workspace`.
    Ci {
        /// Skip the test suite (formatting, lints and docs only).
        #[arg(long)]
        no_tests: bool,
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

fn workspace_root() -> PathBuf {
    // xtask/ is one level below the workspace root.
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask has a parent")
        .to_path_buf()
}

fn cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string())
}

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
