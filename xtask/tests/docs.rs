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

/// The numbers in `text`, in order, as written (`4.66`, `16.8`; a `-` between two numbers is a
/// range, not a sign).
fn numbers(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    for c in text.chars().chain(std::iter::once(' ')) {
        if c.is_ascii_digit() || (c == '.' && !cur.is_empty()) {
            cur.push(c);
        } else {
            let n = cur.trim_end_matches('.');
            if !n.is_empty() {
                out.push(n.to_string());
            }
            cur.clear();
        }
    }
    out
}

/// Whether `quoted` is `actual` rounded to the decimals `quoted` shows.
fn quotes(quoted: &str, actual: f64) -> bool {
    let decimals = quoted.split_once('.').map_or(0, |(_, d)| d.len());
    format!("{actual:.decimals$}") == quoted
}

/// The benchmark table of `docs/benchmarks.md` and the README's timing table quote the committed
/// `docs/results/bench.json` (wall seconds of each round, CPU seconds, peak memory), so a new
/// benchmark cannot land without the figures the docs show, and a figure cannot be edited by
/// hand away from its measurement.
#[test]
fn the_benchmark_tables_quote_the_committed_bench_json() {
    let root = workspace_root();
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root.join("docs/results/bench.json")).unwrap(),
    )
    .unwrap();
    let workloads = json["workloads"].as_array().unwrap();
    let md = std::fs::read_to_string(root.join("docs/benchmarks.md")).unwrap();
    let rows = core_lattice::spec::markdown_table(&md, "## Headline workloads");
    assert_eq!(
        &rows[0][..6],
        [
            "workload",
            "command (`target/release/...`)",
            "wall s (three rounds)",
            "CPU s",
            "peak RSS",
            "rate"
        ]
    );
    assert_eq!(
        rows.len() - 1,
        workloads.len(),
        "one row per workload of bench.json"
    );
    for (row, w) in rows[1..].iter().zip(workloads) {
        let name = w["name"].as_str().unwrap();
        let f = |k: &str| w[k].as_f64().unwrap();
        let walls = numbers(row[2].split("round trip").next().unwrap());
        let runs: Vec<f64> = w["wall_seconds_runs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert!(
            quotes(&walls[0], f("wall_seconds")),
            "{name}: wall {} in the docs, {} measured",
            walls[0],
            f("wall_seconds")
        );
        assert_eq!(
            walls.len(),
            1 + runs.len(),
            "{name}: the rounds in {:?}",
            row[2]
        );
        for (q, r) in walls[1..].iter().zip(&runs) {
            assert!(quotes(q, *r), "{name}: round {q} in the docs, {r} measured");
        }
        let cpu = &numbers(&row[3])[0];
        assert!(
            quotes(cpu, f("cpu_seconds")),
            "{name}: CPU {cpu} in the docs, {} measured",
            f("cpu_seconds")
        );
        let rss = &numbers(&row[4])[0];
        assert!(row[4].contains(" MB"), "{name}: peak RSS in MB: {}", row[4]);
        assert!(
            quotes(rss, f("peak_rss_bytes") / 1e6),
            "{name}: {rss} MB in the docs, {} bytes measured",
            f("peak_rss_bytes")
        );
    }

    // The README's one-thread 2D 1e6 row: its time range holds the measured rounds, its bytes per
    // particle is the measured peak over N.
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let line = readme
        .lines()
        .find(|l| l.starts_with("| 2D DLA, 1e6 particles, one thread |"))
        .expect("the README's 2D 1e6 row");
    let cell = line.split('|').nth(2).unwrap();
    let q: Vec<f64> = numbers(cell).iter().map(|n| n.parse().unwrap()).collect();
    let w = workloads
        .iter()
        .find(|w| w["name"] == "dla-2d-1e6-1thread")
        .unwrap();
    for r in w["wall_seconds_runs"].as_array().unwrap() {
        let r = r.as_f64().unwrap();
        assert!(
            q[0] <= r && r <= q[1],
            "README: {}-{} s, a round took {r} s",
            q[0],
            q[1]
        );
    }
    let bpp = w["peak_rss_bytes"].as_f64().unwrap() / 1e6;
    assert!(
        quotes(&numbers(cell)[2], bpp),
        "README: {} bytes per particle, {bpp} measured",
        q[2]
    );
}
