//! Library behind `cargo xtask`: the scaling experiments that regenerate the papers' tables and
//! figures (`scaling`), the headline benchmarks (`bench`), DLA at the papers' scale (`scale`),
//! and the tables and charts they write.
//! The binary (`src/main.rs`) parses the command line and calls in here; the harness's own
//! test (`tests/scaling.rs`) runs it at a tiny size.

pub mod bench;
pub mod ci;
pub mod codemap;
pub mod compare;
pub mod fuzz;
pub mod generate;

pub mod probe;
pub mod quoted;
pub mod report;
pub mod scale;
pub mod scaling;

use std::path::PathBuf;

/// The workspace root (`xtask/` is one level below it).
pub fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask has a parent")
        .to_path_buf()
}

/// Runs `cmd` to its end; an error names `what` when it cannot start or exits unsuccessfully.
pub fn run_checked(cmd: &mut std::process::Command, what: &str) -> anyhow::Result<()> {
    use anyhow::Context;
    let status = cmd
        .status()
        .with_context(|| format!("could not start {what}"))?;
    if !status.success() {
        anyhow::bail!("{what} failed ({status})");
    }
    Ok(())
}

/// The cargo that runs us (`$CARGO`), or `cargo` from the path.
pub fn cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string())
}

/// For the integration tests: the model binaries (`dla`, `dlca`, `animat`) of the calling test's
/// build profile, built if missing or stale. Returns their directory, `target/<profile>`.
///
/// The build is `cargo test --workspace --no-run`, the README's test command without running
/// the tests: it unifies the dependencies' features exactly as that command does, so under it
/// the build is a no-op, while a plain `cargo build --bins` would resolve other features
/// (without the dev-dependencies') and rebuild the binaries and their dependencies once more.
///
/// # Panics
/// If the test's own path is not `target/<profile>/deps/<test>` or cargo fails.
pub fn model_binaries_for_tests() -> PathBuf {
    let exe = std::env::current_exe().expect("the test's path");
    let profile_dir = exe
        .parent()
        .and_then(std::path::Path::parent)
        .expect("target/<profile>/deps/<test>")
        .to_path_buf();
    let mut cmd = std::process::Command::new(cargo());
    cmd.args(["test", "--workspace", "--no-run", "--quiet"])
        .current_dir(workspace_root());
    if profile_dir.file_name().is_some_and(|n| n == "release") {
        cmd.arg("--release");
    }
    let status = cmd.status().expect("starting cargo test --no-run");
    assert!(status.success(), "building the model binaries failed");
    profile_dir
}
