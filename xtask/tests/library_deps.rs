//! The model libraries alone (`--no-default-features`: without their binary's command line,
//! feature `cli`, their figures, feature `figures`, and their files, feature `files`) stay
//! small: a program that only simulates does not build a figure stack, image encoders, clap,
//! or the file formats of a run's outputs and checkpoints. Each library's packages are counted
//! as the distinct names `cargo tree -p LIB --no-default-features -e normal --prefix none`
//! lists, and held to the count in `LIMITS` (at most 20); a change that needs more raises it
//! here, in the same commit, where a reviewer sees it.

use std::collections::BTreeSet;
use std::process::Command;

/// Each model library and the most packages its `cargo tree` may list. The floor is the
/// simulation's own: serde with its derive (parameters and states), thiserror, rand and
/// rand_pcg through core-lattice, rustc-hash through spatial, and run-io without its files
/// (xxhash for state hashes).
const LIMITS: &[(&str, usize)] = &[("dla-pdla", 18), ("dlca", 18), ("animat", 18)];

/// Crates of the figure stack, of the command line and of the run's files: none may appear in
/// a library alone.
const FORBIDDEN: &[&str] = &[
    "plotters",
    "plotters-backend",
    "plotters-bitmap",
    "ab_glyph",
    "ttf-parser",
    "colorous",
    "gif",
    "png",
    "clap",
    "anyhow",
    "tracing-subscriber",
    "indicatif",
    "signal-hook",
    "serde_json",
    "bincode",
    "csv",
    "tempfile",
    "nix",
    "tracing",
];

/// The distinct package names `cargo tree` lists for `package` alone.
fn tree(package: &str) -> BTreeSet<String> {
    let out = Command::new(xtask::cargo())
        .current_dir(xtask::workspace_root())
        .args([
            "tree",
            "--offline",
            "--locked",
            "-p",
            package,
            "--no-default-features",
            "-e",
            "normal",
            "--prefix",
            "none",
        ])
        .output()
        .expect("cargo tree starts");
    assert!(
        out.status.success(),
        "cargo tree -p {package} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout)
        .expect("cargo tree prints UTF-8")
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_string)
        .collect()
}

#[test]
fn model_libraries_alone_stay_within_their_package_counts() {
    let mut over = Vec::new();
    for &(package, limit) in LIMITS {
        let names = tree(package);
        let forbidden: Vec<&str> = FORBIDDEN
            .iter()
            .copied()
            .filter(|f| names.contains(*f))
            .collect();
        assert!(
            forbidden.is_empty(),
            "{package} --no-default-features pulls in {forbidden:?}: put the code that needs \
             them behind its feature `files`, `figures` or `cli`"
        );
        if names.len() > limit {
            over.push(format!(
                "{package}: {} packages, at most {limit}: {}",
                names.len(),
                names.iter().cloned().collect::<Vec<_>>().join(" ")
            ));
        }
    }
    assert!(
        over.is_empty(),
        "model libraries alone grew (cargo tree --no-default-features -e normal):\n{}",
        over.join("\n")
    );
}
