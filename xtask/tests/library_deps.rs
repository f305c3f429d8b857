//! The model libraries alone (`--no-default-features`: without their binary's command line,
//! feature `cli`, and without their pictures, feature `figures`) stay small: a program that
//! only simulates does not build a plotting stack, a font rasteriser, colour maps, image
//! encoders or clap. Each library's packages are counted as
//! `cargo tree -p LIB --no-default-features -e normal --prefix none | sort -u | wc -l` counts
//! them, and held to the count in `LIMITS`; a change that needs more raises it here, in the
//! same commit, where a reviewer sees it.

use std::collections::BTreeSet;
use std::process::Command;

/// Each model library and the most lines its `cargo tree` may list. The floor is the
/// libraries' own dependencies (serde with its derive, serde_json, thiserror, rand through
/// core-lattice, parking_lot for PDLA) and sim-run's I/O
/// (bincode for checkpoints, csv, tempfile for atomic writes, nix for run.json's
/// provenance and usage, xxhash for state hashes).
const LIMITS: &[(&str, usize)] = &[("dla-pdla", 51), ("dlca", 51), ("animat", 46)];

/// Crates of the figure stack and of the command line: none may appear in a library alone.
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
];

/// The distinct lines of `cargo tree` for `package` alone, as the shell pipeline above.
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
        .filter(|l| !l.is_empty())
        .map(str::to_string)
        .collect()
}

#[test]
fn model_libraries_alone_stay_within_their_package_counts() {
    let mut over = Vec::new();
    for &(package, limit) in LIMITS {
        let lines = tree(package);
        let names: BTreeSet<&str> = lines
            .iter()
            .filter_map(|l| l.split_whitespace().next())
            .collect();
        let forbidden: Vec<&str> = FORBIDDEN
            .iter()
            .copied()
            .filter(|f| names.contains(f))
            .collect();
        assert!(
            forbidden.is_empty(),
            "{package} --no-default-features pulls in {forbidden:?}: put the code that needs \
             them behind its feature `figures` or `cli`"
        );
        if lines.len() > limit {
            over.push(format!(
                "{package}: {} lines, at most {limit}:\n  {}",
                lines.len(),
                lines.iter().cloned().collect::<Vec<_>>().join("\n  ")
            ));
        }
    }
    assert!(
        over.is_empty(),
        "model libraries alone grew (cargo tree --no-default-features -e normal):\n{}",
        over.join("\n")
    );
}
