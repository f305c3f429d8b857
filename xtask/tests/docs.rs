//! The documentation holds: every link and file reference in the Markdown files and the
//! binaries' `--help` texts points at something in the repository, and the README's per-model
//! commands run (at small sizes).

use std::path::{Path, PathBuf};
use std::process::Command;
use xtask::workspace_root;

/// Every Markdown file of the repository (not under `target/` or a hidden directory).
fn markdown_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if name.starts_with('.') || name == "target" {
            continue;
        }
        if p.is_dir() {
            markdown_files(&p, out);
        } else if name.ends_with(".md") {
            out.push(p);
        }
    }
}

/// Targets of `[text](target)` links: relative ones only, without their `#fragment`.
fn links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("](") {
        rest = &rest[i + 2..];
        let Some(end) = rest.find(')') else { break };
        let target = rest[..end].split('#').next().unwrap_or("").trim();
        let external = target.contains("://") || target.starts_with("mailto:");
        if !target.is_empty() && !external {
            out.push(target.to_string());
        }
    }
    out
}

/// Repository paths named in `backticks` (or in help text words): words that start with one
/// of the repository's top-level directories or are a top-level file, with no placeholder.
fn path_references(text: &str) -> Vec<String> {
    const ROOTS: [&str; 8] = [
        "docs/",
        "crates/",
        "data/",
        "xtask/",
        "examples/",
        "python/",
        ".ci/",
        ".cargo/",
    ];
    const FILES: [&str; 4] = ["README.md", "CHANGELOG.md", "CITATION.cff", "Cargo.toml"];
    text.split(|c: char| c.is_whitespace() || "`()[],;\"'".contains(c))
        .map(|w| w.trim_end_matches(['.', ':']))
        .filter(|w| ROOTS.iter().any(|r| w.starts_with(r)) || FILES.contains(w))
        // Placeholders and outputs a run makes (docs/results/quick/ is written by the main
        // command, not committed).
        .filter(|w| !w.contains(['<', '*', '{', '$']) && !w.contains("DIR") && !w.contains("NNNN"))
        .filter(|w| !w.starts_with("docs/results/quick"))
        .map(str::to_string)
        .collect()
}

#[test]
fn every_link_and_file_reference_in_the_docs_exists() {
    let root = workspace_root();
    let mut files = Vec::new();
    markdown_files(&root, &mut files);
    assert!(files.len() > 10, "found only {files:?}");
    let mut missing = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let shown = f.strip_prefix(&root).unwrap().display().to_string();
        for target in links(&text) {
            if !f.parent().unwrap().join(&target).exists() {
                missing.push(format!("{shown}: link ({target})"));
            }
        }
        for path in path_references(&text) {
            // Relative to the repository root, as the docs write them.
            if !root.join(&path).exists() {
                missing.push(format!("{shown}: `{path}`"));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "missing targets:\n{}",
        missing.join("\n")
    );
}

#[test]
fn help_texts_name_only_files_in_the_repository() {
    let bins = xtask::model_binaries_for_tests();
    let root = workspace_root();
    let mut missing = Vec::new();
    for bin in ["dla", "dlca", "animat"] {
        let o = Command::new(bins.join(bin)).arg("--help").output().unwrap();
        assert!(o.status.success());
        let help = String::from_utf8_lossy(&o.stdout);
        for path in path_references(&help) {
            if !root.join(&path).exists() {
                missing.push(format!("{bin} --help: {path}"));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "missing targets:\n{}",
        missing.join("\n")
    );
}

/// The README's model commands (`cargo dla ...`, `target/release/dla ...` and the same for
/// `dlca` and `animat`), run with the test build of the binaries at small sizes: particle and
/// step counts capped, ensembles of two seeds, outputs in a temporary directory.
#[test]
fn the_readme_commands_run() {
    let bins = xtask::model_binaries_for_tests();
    let root = workspace_root();
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let mut in_code = false;
    let mut ran = 0;
    for line in readme.lines() {
        if line.starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if !in_code {
            continue;
        }
        let command = line.split(" #").next().unwrap().trim();
        let mut words = command.split_whitespace();
        let bin = match (words.next(), words.next()) {
            (Some("cargo"), Some(b @ ("dla" | "dlca" | "animat"))) => b.to_string(),
            (Some(p), rest) if p.starts_with("target/release/") => {
                words = command.split_whitespace();
                words.next();
                let _ = rest;
                p.trim_start_matches("target/release/").to_string()
            }
            _ => continue,
        };
        let mut args: Vec<String> = Vec::new();
        let mut it = words.peekable();
        while let Some(w) = it.next() {
            args.push(w.to_string());
            let small = match w {
                "--particles" => Some(3_000),
                "--steps" => Some(30),
                _ => None,
            };
            if let Some(cap) = small {
                let v: u64 = it.next().unwrap().parse().unwrap();
                args.push(v.min(cap).to_string());
            } else if w == "--seeds" {
                it.next();
                args.push("1..=2".into());
            } else if w == "--out" || w == "--merge" {
                let d = it.next().unwrap();
                args.push(tmp.path().join(d).to_string_lossy().into_owned());
            }
        }
        // `--merge DIR` takes nothing else.
        if args[0] != "--merge" {
            args.push("-qq".into());
        }
        let o = Command::new(bins.join(&bin))
            .args(&args)
            .current_dir(&root)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "README: `{command}` (run as {bin} {args:?}): {}",
            String::from_utf8_lossy(&o.stderr)
        );
        ran += 1;
    }
    assert!(ran >= 5, "only {ran} README commands found");
}
