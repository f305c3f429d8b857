//! `cargo xtask compare`: our binaries against other public codes for the same workload, in
//! interleaved pairs on this machine (the other codes are built by the user from their own
//! sources, outside this repository; their paths are the arguments).
//!
//! Each pair runs both programs once, in alternating order (ours first in odd pairs, theirs
//! first in even ones), so a drift of the host's speed falls on both; the report gives every
//! wall time, the medians and the median of the per-pair ratios.

use anyhow::{Context, Result, bail};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

/// A workload run by ours and by another code.
#[derive(Debug, Clone)]
pub struct Rival {
    /// Short name of the workload.
    pub name: &'static str,
    /// The other code (its repository).
    pub code: &'static str,
    /// Our binary (in the release target directory) and its arguments; the pair's seed is
    /// appended as `--seed S`, then `-qq --out DIR`.
    pub ours: (&'static str, &'static [&'static str]),
    /// The other code's arguments, `{seed}` and `{dir}` substituted; it runs in the pair's
    /// directory with its standard output discarded.
    pub theirs: &'static [&'static str],
}

/// The comparisons `cargo xtask compare` knows, keyed by the flag that gives the other code.
pub const RIVALS: &[(&str, Rival)] = &[
    (
        "fastdla",
        Rival {
            name: "2D DLA, 1e6 particles, one thread",
            code: "mathsjames/fastDLA",
            ours: (
                "dla",
                &["--dim", "2", "--particles", "1000000", "--no-checkpoint"],
            ),
            theirs: &["1000000", "{dir}/fastdla.txt", "{seed}"],
        },
    ),
    (
        "dlaf",
        Rival {
            name: "3D DLA, 1e5 particles, attraction distance 1",
            code: "fogleman/dlaf (built with D = 3, DefaultAttractionDistance = 1)",
            ours: (
                "dla",
                &["--dim", "3", "--particles", "100000", "--no-checkpoint"],
            ),
            theirs: &[],
        },
    ),
    (
        "dlca-cpp",
        Rival {
            name: "DLCA 1024^2, 50 000 particles to one cluster",
            code: "rob10campbell/DLCA (bin/dlca 2 1024 50000 zout 1 100000000)",
            ours: (
                "dlca",
                &[
                    "--size",
                    "1024",
                    "--particles",
                    "50000",
                    "--target-clusters",
                    "1",
                    "--no-checkpoint",
                ],
            ),
            theirs: &["2", "1024", "50000", "zout", "1", "100000000"],
        },
    ),
];

/// One workload's pairs.
#[derive(Debug, Serialize)]
pub struct Comparison {
    /// The workload ([`Rival::name`]).
    pub name: String,
    /// The other code ([`Rival::code`]).
    pub code: String,
    /// Our command (the seed varies by pair).
    pub ours: String,
    /// Their command.
    pub theirs: String,
    /// Wall seconds of our runs, pair by pair.
    pub ours_seconds: Vec<f64>,
    /// Wall seconds of theirs, pair by pair.
    pub theirs_seconds: Vec<f64>,
    /// Their time over ours, pair by pair (> 1: ours is faster).
    pub ratios: Vec<f64>,
    /// Median of `ours_seconds`.
    pub median_ours: f64,
    /// Median of `theirs_seconds`.
    pub median_theirs: f64,
    /// Median of `ratios`.
    pub median_ratio: f64,
}

/// The report `--save` writes.
#[derive(Debug, Serialize)]
pub struct Report {
    /// When the pairs ran (UTC).
    pub date: String,
    /// The host, as `cargo xtask bench` names it.
    pub machine: String,
    /// Our build.
    pub build: String,
    /// One per other code given.
    pub comparisons: Vec<Comparison>,
}

/// The median of `v` (the mean of the middle two for an even count); NaN when empty.
pub fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    match s.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => s[n / 2],
        n => 0.5 * (s[n / 2 - 1] + s[n / 2]),
    }
}

/// Runs `cmd` to completion and returns its wall seconds; a failure is an error naming it.
fn timed(cmd: &mut Command, what: &str) -> Result<f64> {
    let start = Instant::now();
    let out = cmd
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .output()
        .with_context(|| format!("could not run {what}"))?;
    let wall = start.elapsed().as_secs_f64();
    if !out.status.success() {
        bail!(
            "{what} failed ({}): {}",
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    Ok(wall)
}

/// `pairs` interleaved pairs of `rival`, ours from `bin_dir` and theirs at `other`; seeds
/// `1..=pairs`.
pub fn compare(rival: &Rival, bin_dir: &Path, other: &Path, pairs: usize) -> Result<Comparison> {
    let ours_bin = bin_dir.join(rival.ours.0);
    let theirs_of = |seed: &str, dir: &str| -> Vec<String> {
        rival
            .theirs
            .iter()
            .map(|a| a.replace("{seed}", seed).replace("{dir}", dir))
            .collect()
    };
    eprintln!("==> {} against {}", rival.name, rival.code);
    let (mut ours_s, mut theirs_s) = (Vec::new(), Vec::new());
    for pair in 0..pairs {
        let seed = pair as u64 + 1;
        let dir = tempfile::tempdir().context("creating a temporary directory")?;
        let mut ours = Command::new(&ours_bin);
        ours.args(rival.ours.1)
            .args(["--seed", &seed.to_string(), "-qq", "--out"])
            .arg(dir.path().join("ours"));
        let mut theirs = Command::new(other);
        theirs
            .args(theirs_of(
                &seed.to_string(),
                &dir.path().display().to_string(),
            ))
            .current_dir(dir.path());
        let (o, t) = if pair % 2 == 0 {
            let o = timed(&mut ours, &ours_bin.display().to_string())?;
            (o, timed(&mut theirs, &other.display().to_string())?)
        } else {
            let t = timed(&mut theirs, &other.display().to_string())?;
            (timed(&mut ours, &ours_bin.display().to_string())?, t)
        };
        eprintln!(
            "    pair {}: ours {o:.2} s, theirs {t:.2} s, ratio {:.2}",
            pair + 1,
            t / o
        );
        ours_s.push(o);
        theirs_s.push(t);
    }
    let ratios: Vec<f64> = ours_s.iter().zip(&theirs_s).map(|(o, t)| t / o).collect();
    Ok(Comparison {
        name: rival.name.into(),
        code: rival.code.into(),
        ours: format!(
            "target/release/{} {} --seed S -qq --out DIR",
            rival.ours.0,
            rival.ours.1.join(" ")
        ),
        theirs: format!("{} {}", other.display(), theirs_of("S", "DIR").join(" "))
            .trim_end()
            .to_string(),
        median_ours: median(&ours_s),
        median_theirs: median(&theirs_s),
        median_ratio: median(&ratios),
        ours_seconds: ours_s,
        theirs_seconds: theirs_s,
        ratios,
    })
}

/// A markdown table of the comparisons.
pub fn table(report: &Report) -> String {
    let mut s = format!(
        "{} ({}, {})\n\n| workload | other code | pairs | ours, median s | theirs, median s | their time / ours, median of pairs (each pair) |\n|---|---|---|---|---|---|\n",
        report.machine, report.build, report.date
    );
    for c in &report.comparisons {
        let each: Vec<String> = c.ratios.iter().map(|r| format!("{r:.2}")).collect();
        s += &format!(
            "| {} | {} | {} | {:.2} | {:.2} | **{:.2}** ({}) |\n",
            c.name,
            c.code,
            c.ratios.len(),
            c.median_ours,
            c.median_theirs,
            c.median_ratio,
            each.join(", ")
        );
    }
    s
}

/// `cargo xtask compare`: builds our release binaries, runs each comparison whose other code
/// is given (`others`: flag name and path), prints the table and saves the JSON if asked.
pub fn run(
    root: &Path,
    cargo: &str,
    others: &[(&str, PathBuf)],
    pairs: usize,
    save: Option<&Path>,
) -> Result<Report> {
    if others.is_empty() {
        bail!("give at least one other code: --fastdla, --dlaf or --dlca-cpp (see --help)");
    }
    crate::bench::build(root, cargo)?;
    let bin_dir = crate::bench::target_dir(root).join("release");
    let mut comparisons = Vec::new();
    for (flag, path) in others {
        let (_, rival) = RIVALS
            .iter()
            .find(|(f, _)| f == flag)
            .with_context(|| format!("no comparison for --{flag}"))?;
        if !path.is_file() {
            bail!("--{flag}: {} is not a file", path.display());
        }
        let path = path
            .canonicalize()
            .with_context(|| format!("--{flag}: {}", path.display()))?;
        comparisons.push(compare(rival, &bin_dir, &path, pairs)?);
    }
    let report = Report {
        date: crate::report::utc_now(),
        machine: crate::report::machine(),
        build: crate::report::build_id(),
        comparisons,
    };
    print!("{}", table(&report));
    if let Some(path) = save {
        std::fs::write(path, serde_json::to_string_pretty(&report)? + "\n")
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&[]).is_nan());
    }

    /// A comparison against a stand-in "other code" (`true`, which ignores its arguments)
    /// runs the pairs, alternates their order and reports positive times and ratios.
    #[test]
    fn pairs_of_a_stand_in() {
        let Some(true_bin) = ["/bin/true", "/usr/bin/true"]
            .iter()
            .map(PathBuf::from)
            .find(|p| p.is_file())
        else {
            return;
        };
        let rival = Rival {
            name: "stand-in",
            code: "true",
            ours: ("true", &[]),
            theirs: &["{seed}", "{dir}"],
        };
        let c = compare(&rival, true_bin.parent().unwrap(), &true_bin, 3).unwrap();
        assert_eq!(c.ratios.len(), 3);
        assert!(
            c.ours_seconds
                .iter()
                .chain(&c.theirs_seconds)
                .all(|&s| s > 0.0)
        );
        assert!(c.theirs.ends_with("S DIR"), "{}", c.theirs);
        let t = table(&Report {
            date: "d".into(),
            machine: "m".into(),
            build: "b".into(),
            comparisons: vec![c],
        });
        assert!(t.contains("| stand-in | true | 3 |"), "{t}");
    }
}
