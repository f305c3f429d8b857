//! Records the git commit of the checkout being built (`AGGSIM_GIT_COMMIT`) for the `provenance`
//! of every `run.json`. Outside a git checkout, or without git, nothing is recorded.
//!
//! Cargo reruns this script when the checkout's `HEAD` or the branch it points to moves, so the
//! recorded commit follows commits and checkouts; uncommitted edits are not recorded.

use std::path::{Path, PathBuf};
use std::process::Command;

fn git(dir: &Path, args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .args(args)
        .current_dir(dir)
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
        .filter(|s| !s.is_empty())
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    // A build from an exported tree (no .git) can name its commit itself.
    println!("cargo:rerun-if-env-changed=AGGSIM_GIT_COMMIT");
    if let Ok(commit) = std::env::var("AGGSIM_GIT_COMMIT") {
        println!("cargo:rustc-env=AGGSIM_GIT_COMMIT={commit}");
        return;
    }
    let dir = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let abs = |p: String| {
        let p = PathBuf::from(p);
        if p.is_absolute() { p } else { dir.join(p) }
    };
    let (Some(git_dir), Some(common)) = (
        git(&dir, &["rev-parse", "--git-dir"]).map(abs),
        git(&dir, &["rev-parse", "--git-common-dir"]).map(abs),
    ) else {
        return;
    };
    // HEAD names the branch; the branch's file (or packed-refs) moves with each commit. Only
    // existing files are watched: cargo reruns the script on every build for a missing one.
    let mut watched = vec![git_dir.join("HEAD"), common.join("packed-refs")];
    if let Some(branch) = git(&dir, &["symbolic-ref", "-q", "HEAD"]) {
        watched.push(common.join(branch));
    }
    for f in watched.iter().filter(|f| f.is_file()) {
        println!("cargo:rerun-if-changed={}", f.display());
    }
    if let Some(commit) = git(&dir, &["rev-parse", "HEAD"]) {
        println!("cargo:rustc-env=AGGSIM_GIT_COMMIT={commit}");
    }
}
