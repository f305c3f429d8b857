//! `cargo xtask bench`: the headline workloads, each run as its own release-binary process so
//! its peak RSS is its own, reported as JSON (seconds, peak RSS, per-item rates) and, with
//! `--against`, as ratios to a saved baseline.

use crate::report::{build_id, machine, utc_now};
use anyhow::{Context, Result, bail};
use run_io::{RunManifest, write_atomic};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

mod instructions;
pub use instructions::{INSTRUCTION_WORKLOADS, InstructionCount, count_instructions, parse_i_refs};

/// One headline workload: a binary and its arguments (without `--out`).
#[derive(Debug, Clone)]
pub struct Workload {
    /// Stable name, used to match baselines.
    pub name: &'static str,
    /// Binary under `target/release`.
    pub bin: &'static str,
    /// Arguments, separated by spaces (none contains one): the command line as a reader
    /// would type it.
    pub args: &'static str,
    /// What the rate counts.
    pub unit: &'static str,
}

impl Workload {
    /// The arguments one by one, as a process takes them.
    pub fn arg_list(&self) -> impl Iterator<Item = &'static str> {
        self.args.split_whitespace()
    }
}

/// The headline workloads, in the order they run.
pub const WORKLOADS: &[Workload] = &[
    Workload {
        name: "dla-2d-1e6-1thread",
        bin: "dla",
        args: "--dim 2 --particles 1000000 --threads 1 --seed 1",
        unit: "particles per second",
    },
    Workload {
        name: "dla-2d-1e6-2threads",
        bin: "dla",
        args: "--dim 2 --particles 1000000 --threads 2 --seed 1",
        unit: "particles per second",
    },
    Workload {
        name: "dla-3d-1e5",
        bin: "dla",
        args: "--dim 3 --particles 100000 --seed 1",
        unit: "particles per second",
    },
    Workload {
        name: "dla-3d-1e6",
        bin: "dla",
        args: "--dim 3 --particles 1000000 --seed 1",
        unit: "particles per second",
    },
    // The 3D PDLA pair: the speed-up is the ratio of their wall times.
    Workload {
        name: "dla-3d-3e5-1thread",
        bin: "dla",
        args: "--dim 3 --particles 300000 --threads 1 --seed 21",
        unit: "particles per second",
    },
    Workload {
        name: "dla-3d-3e5-2threads",
        bin: "dla",
        args: "--dim 3 --particles 300000 --threads 2 --seed 21",
        unit: "particles per second",
    },
    Workload {
        name: "dlca-1024-50k-to-1",
        bin: "dlca",
        args: "--size 1024 --particles 50000 --target-clusters 1 --seed 1",
        unit: "sweeps per second",
    },
    Workload {
        name: "dlca-1024x512-5pct-to-100",
        bin: "dlca",
        args: "--size 1024x512 --fill 0.05 --seed 1",
        unit: "sweeps per second",
    },
    Workload {
        name: "dlca-grid-1024x512-5pct-to-1",
        bin: "dlca",
        args: "--size 1024x512 --fill 0.05 --search grid --target-clusters 1 --seed 1",
        unit: "sweeps per second",
    },
    Workload {
        name: "dlca-lattice-1024x512-5pct-to-1",
        bin: "dlca",
        args: "--size 1024x512 --fill 0.05 --search lattice --target-clusters 1 --seed 1",
        unit: "sweeps per second",
    },
    Workload {
        name: "animat-1e5-100steps",
        bin: "animat",
        args: "--foxes 13043 --rabbits 86957 --density 0.2 --steps 100 --seed 1",
        unit: "animat-steps per second",
    },
    Workload {
        name: "animat-1e6-10steps",
        bin: "animat",
        args: "--foxes 130430 --rabbits 869570 --density 0.2 --steps 10 --seed 1",
        unit: "animat-steps per second",
    },
];

/// The measured result of one workload.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Measurement {
    /// Workload name.
    pub name: String,
    /// The command that ran (relative binary path).
    pub command: String,
    /// Wall seconds of the process.
    pub wall_seconds: f64,
    /// CPU seconds reported by the run (user + system).
    pub cpu_seconds: Option<f64>,
    /// Peak resident set size reported by the run.
    pub peak_rss_bytes: Option<u64>,
    /// Items per wall second.
    pub rate: f64,
    /// What the rate counts.
    pub unit: String,
    /// Bytes of peak RSS per item, where an item is a particle or an animat.
    pub bytes_per_item: Option<f64>,
    /// The run's state hash (equal for equal code and seeds).
    pub state_hash: Option<String>,
    /// With `--repeat R > 1`: the wall seconds of every repeat, in run order; the other fields
    /// are those of the fastest repeat (other jobs on a shared machine only ever slow a run
    /// down, so the fastest is the least disturbed).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub wall_seconds_runs: Vec<f64>,
    /// Multi-threaded workloads: the host's core-to-core round trip just before the run, in
    /// nanoseconds ([`crate::probe::core_round_trip_ns`]); the threads' speed-up depends on it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub core_round_trip_ns: Option<f64>,
}

/// The fastest of a workload's repeats, with every repeat's wall seconds attached.
pub fn fastest(runs: Vec<Measurement>) -> Option<Measurement> {
    let walls: Vec<f64> = runs.iter().map(|m| m.wall_seconds).collect();
    let mut best = runs
        .into_iter()
        .min_by(|a, b| a.wall_seconds.total_cmp(&b.wall_seconds))?;
    if walls.len() > 1 {
        best.wall_seconds_runs = walls;
    }
    Some(best)
}

/// A whole `cargo xtask bench` report.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct BenchReport {
    /// When it ran.
    pub date: String,
    /// Where it ran.
    pub machine: String,
    /// What ran: version and git commit.
    #[serde(default)]
    pub build: String,
    /// The measurements.
    pub workloads: Vec<Measurement>,
    /// Instruction counts (`--instructions`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub instructions: Vec<InstructionCount>,
    /// Ratios to a baseline (`--against`), if one was given.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub against: Vec<Ratio>,
}

/// This run against a baseline, for one workload: > 1 means slower / bigger now.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Ratio {
    /// Workload name.
    pub name: String,
    /// Wall seconds now / baseline.
    pub wall_ratio: f64,
    /// Peak RSS now / baseline.
    pub rss_ratio: Option<f64>,
    /// Whether the state hash changed (a different trajectory: the timing compares different
    /// work).
    pub hash_changed: bool,
}

/// The cargo target directory: `$CARGO_TARGET_DIR` (relative to `root` unless absolute) or
/// `root/target`.
pub fn target_dir(root: &Path) -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .map(|p| if p.is_absolute() { p } else { root.join(p) })
        .unwrap_or_else(|| root.join("target"))
}

/// Build the release binaries the workloads need.
pub fn build(root: &Path, cargo: &str) -> Result<()> {
    eprintln!("==> building release binaries");
    crate::run_checked(
        Command::new(cargo)
            .args(["build", "--release", "--bins"])
            .args(["-p", "dla-pdla", "-p", "dlca", "-p", "animat"])
            .current_dir(root),
        "cargo build",
    )
}

/// Items the rate counts, from the run's outputs.
fn items(w: &Workload, m: &RunManifest, dir: &Path) -> Result<(f64, Option<f64>)> {
    let r = &m.results;
    let num = |k: &str| r.get(k).and_then(|v| v.as_f64());
    Ok(match w.bin {
        "dla" => {
            let n = num("particles").context("run.json has no particles")?;
            (n, Some(n))
        }
        "dlca" => (
            num("sweeps").context("run.json has no sweeps")?,
            num("particles"),
        ),
        _ => {
            let (total, peak) = animat_steps(&dir.join("populations.csv"))?;
            (total, Some(peak))
        }
    })
}

/// One row of an animat run's `populations.csv` (the columns the rate needs; others ignored).
#[derive(Debug, Deserialize)]
struct PopulationRow {
    foxes: u64,
    rabbits: u64,
}

/// Animat-steps of a run (the population at each step, summed) and its peak population, from
/// `populations.csv`. A missing column, an unparsable cell or an empty file is an error naming
/// the file, never a silent zero.
fn animat_steps(path: &Path) -> Result<(f64, f64)> {
    let mut reader =
        csv::Reader::from_path(path).with_context(|| format!("reading {}", path.display()))?;
    let (mut total, mut peak, mut rows) = (0u64, 0u64, 0usize);
    for row in reader.deserialize::<PopulationRow>() {
        let row = row.with_context(|| format!("parsing {}", path.display()))?;
        let pop = row.foxes + row.rabbits;
        total += pop;
        peak = peak.max(pop);
        rows += 1;
    }
    if rows == 0 {
        bail!("{} has no rows", path.display());
    }
    Ok((total as f64, peak as f64))
}

/// Run one workload in a temporary directory.
pub fn measure(w: &Workload, bin_dir: &Path) -> Result<Measurement> {
    let out = tempfile::tempdir().context("creating a temporary output directory")?;
    let bin = bin_dir.join(w.bin);
    let command = format!("target/release/{} {} -q --out DIR", w.bin, w.args);
    eprintln!("==> {}: {command}", w.name);
    let threads = w
        .arg_list()
        .skip_while(|a| *a != "--threads")
        .nth(1)
        .and_then(|t| t.parse::<usize>().ok())
        .unwrap_or(1);
    let core_round_trip_ns = if threads > 1 {
        crate::probe::core_round_trip_ns(5, 20_000)
    } else {
        None
    };
    if let Some(ns) = core_round_trip_ns {
        eprintln!("    core-to-core round trip {ns:.0} ns");
    }
    let start = Instant::now();
    let output = Command::new(&bin)
        .args(w.arg_list())
        .arg("-q")
        .arg("--out")
        .arg(out.path())
        .output()
        .with_context(|| format!("could not run {}", bin.display()))?;
    let wall = start.elapsed().as_secs_f64();
    if !output.status.success() {
        bail!(
            "{} failed ({}): {}",
            w.name,
            output.status,
            String::from_utf8_lossy(&output.stderr).trim()
        );
    }
    let m = RunManifest::read(out.path().join("run.json")).context("reading run.json")?;
    let (count, per) = items(w, &m, out.path())?;
    let measurement = Measurement {
        name: w.name.into(),
        command,
        wall_seconds: wall,
        cpu_seconds: m.cpu_seconds,
        peak_rss_bytes: m.peak_rss_bytes,
        rate: count / m.wall_seconds.max(1e-9),
        unit: w.unit.into(),
        bytes_per_item: match (m.peak_rss_bytes, per) {
            (Some(b), Some(n)) if n > 0.0 => Some(b as f64 / n),
            _ => None,
        },
        state_hash: m
            .results
            .get("state_hash")
            .and_then(|v| v.as_str())
            .map(String::from),
        wall_seconds_runs: Vec::new(),
        core_round_trip_ns,
    };
    eprintln!(
        "    {:.2} s wall, {:.3e} {}, peak RSS {} MB",
        wall,
        measurement.rate,
        w.unit,
        m.peak_rss_bytes.map(|b| b / 1_000_000).unwrap_or(0)
    );
    Ok(measurement)
}

/// Ratios of `now` to `base` for the workloads both contain.
pub fn compare(now: &[Measurement], base: &[Measurement]) -> Vec<Ratio> {
    now.iter()
        .filter_map(|n| {
            let b = base.iter().find(|b| b.name == n.name)?;
            Some(Ratio {
                name: n.name.clone(),
                wall_ratio: n.wall_seconds / b.wall_seconds,
                rss_ratio: match (n.peak_rss_bytes, b.peak_rss_bytes) {
                    (Some(x), Some(y)) if y > 0 => Some(x as f64 / y as f64),
                    _ => None,
                },
                hash_changed: n.state_hash != b.state_hash,
            })
        })
        .collect()
}

/// `cargo xtask bench`: build, run the workloads whose name contains `only` (all if `None`)
/// `repeat` times each, in rounds (every workload once, then again), keep each workload's
/// fastest run, print JSON, optionally save it and compare with a baseline.
#[allow(clippy::too_many_arguments)]
pub fn run(
    root: &Path,
    cargo: &str,
    only: Option<&str>,
    repeat: usize,
    instructions: bool,
    save: Option<&Path>,
    against: Option<&Path>,
) -> Result<BenchReport> {
    if repeat == 0 {
        bail!("--repeat 0 is outside the accepted range: 1 or more");
    }
    let baseline: Option<BenchReport> = match against {
        Some(p) => Some(
            serde_json::from_slice(
                &std::fs::read(p).with_context(|| format!("reading {}", p.display()))?,
            )
            .with_context(|| format!("{} is not a bench report", p.display()))?,
        ),
        None => None,
    };
    let chosen: Vec<&Workload> = WORKLOADS
        .iter()
        .filter(|w| !instructions && only.is_none_or(|o| w.name.contains(o)))
        .collect();
    let counted: Vec<&Workload> = INSTRUCTION_WORKLOADS
        .iter()
        .filter(|w| instructions && only.is_none_or(|o| w.name.contains(o)))
        .collect();
    if chosen.is_empty() && counted.is_empty() {
        bail!(
            "--only {} matches no workload; the workloads are: {}",
            only.unwrap_or(""),
            WORKLOADS
                .iter()
                .chain(INSTRUCTION_WORKLOADS)
                .map(|w| w.name)
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    build(root, cargo)?;
    let bin_dir = target_dir(root).join("release");
    // Rounds rather than back-to-back repeats, so a drift of the machine's speed touches
    // every workload alike.
    let mut runs: Vec<Vec<Measurement>> = vec![Vec::new(); chosen.len()];
    for round in 0..repeat {
        if repeat > 1 {
            eprintln!("==> round {} of {repeat}", round + 1);
        }
        for (w, r) in chosen.iter().zip(runs.iter_mut()) {
            r.push(measure(w, &bin_dir)?);
        }
    }
    let workloads: Vec<Measurement> = runs
        .into_iter()
        .map(|r| fastest(r).expect("repeat >= 1"))
        .collect();
    // Instruction counts do not vary between runs: one each.
    let instructions = counted
        .iter()
        .map(|w| count_instructions(w, &bin_dir))
        .collect::<Result<Vec<_>>>()?;
    if repeat > 1 {
        eprintln!("==> fastest of {repeat} per workload");
        for m in &workloads {
            eprintln!(
                "    {:<28} {:.2} s (runs: {}){}",
                m.name,
                m.wall_seconds,
                m.wall_seconds_runs
                    .iter()
                    .map(|t| format!("{t:.2}"))
                    .collect::<Vec<_>>()
                    .join(", "),
                m.core_round_trip_ns
                    .map(|ns| format!(", core-to-core round trip {ns:.0} ns"))
                    .unwrap_or_default()
            );
        }
    }
    let mut report = BenchReport {
        date: utc_now(),
        machine: machine(),
        build: build_id(),
        workloads,
        instructions,
        against: Vec::new(),
    };
    if let Some(b) = &baseline {
        report.against = compare(&report.workloads, &b.workloads);
        for n in &report.instructions {
            if let Some(o) = b.instructions.iter().find(|o| o.name == n.name) {
                eprintln!(
                    "    {:<28} instructions x{:.4}{}",
                    n.name,
                    n.instructions as f64 / o.instructions as f64,
                    if n.state_hash != o.state_hash {
                        " (state hash changed: different trajectory)"
                    } else {
                        ""
                    }
                );
            }
        }
        eprintln!(
            "==> against {} ({})",
            against.expect("set").display(),
            b.date
        );
        for r in &report.against {
            eprintln!(
                "    {:<28} wall x{:.3}{}{}",
                r.name,
                r.wall_ratio,
                r.rss_ratio
                    .map(|x| format!(", peak RSS x{x:.3}"))
                    .unwrap_or_default(),
                if r.hash_changed {
                    " (state hash changed: different trajectory)"
                } else {
                    ""
                }
            );
        }
    }
    let json = serde_json::to_string_pretty(&report)?;
    println!("{json}");
    if let Some(p) = save {
        write_atomic(p, format!("{json}\n").as_bytes())
            .with_context(|| format!("writing {}", p.display()))?;
        eprintln!("==> saved to {}", p.display());
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(name: &str, wall: f64, rss: u64, hash: &str) -> Measurement {
        Measurement {
            name: name.into(),
            command: String::new(),
            wall_seconds: wall,
            cpu_seconds: None,
            peak_rss_bytes: Some(rss),
            rate: 1.0,
            unit: "x".into(),
            bytes_per_item: None,
            state_hash: Some(hash.into()),
            wall_seconds_runs: Vec::new(),
            core_round_trip_ns: None,
        }
    }

    #[test]
    fn animat_steps_sum_populations_and_refuse_bad_files() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("populations.csv");
        std::fs::write(
            &p,
            "step,foxes,rabbits,search_seconds\n0,2,3,0.1\n1,4,5,0.2\n",
        )
        .unwrap();
        assert_eq!(animat_steps(&p).unwrap(), (14.0, 9.0));
        // A missing column, a bad cell and an empty table are errors, not zeros.
        for bad in [
            "step,foxes\n0,2\n",
            "step,foxes,rabbits\n0,2,x\n",
            "step,foxes,rabbits\n",
        ] {
            std::fs::write(&p, bad).unwrap();
            let e = animat_steps(&p).unwrap_err();
            assert!(format!("{e:#}").contains("populations.csv"), "{e:#}");
        }
        assert!(animat_steps(&dir.path().join("missing.csv")).is_err());
    }

    #[test]
    fn fastest_repeat_is_kept_with_every_time() {
        let runs = vec![
            m("a", 3.0, 10, "h1"),
            m("a", 2.0, 11, "h2"),
            m("a", 2.5, 12, "h3"),
        ];
        let f = fastest(runs).unwrap();
        assert_eq!(f.wall_seconds, 2.0);
        assert_eq!(f.peak_rss_bytes, Some(11));
        assert_eq!(f.state_hash.as_deref(), Some("h2"));
        assert_eq!(f.wall_seconds_runs, vec![3.0, 2.0, 2.5]);
        // One run: no list, so reports without --repeat look as before.
        let one = fastest(vec![m("b", 1.0, 1, "h")]).unwrap();
        assert!(one.wall_seconds_runs.is_empty());
        assert!(fastest(Vec::new()).is_none());
        // Old reports (no runs field) still parse.
        let json = serde_json::to_string(&one).unwrap();
        assert!(!json.contains("wall_seconds_runs"));
        let back: Measurement = serde_json::from_str(&json).unwrap();
        assert_eq!(back, one);
    }

    #[test]
    fn ratios_against_a_baseline() {
        let base = vec![m("a", 2.0, 100, "h"), m("b", 1.0, 100, "h")];
        let now = vec![m("a", 3.0, 50, "h"), m("c", 1.0, 1, "h")];
        let r = compare(&now, &base);
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].wall_ratio, 1.5);
        assert_eq!(r[0].rss_ratio, Some(0.5));
        assert!(!r[0].hash_changed);
        let r = compare(&[m("b", 1.0, 100, "other")], &base);
        assert!(r[0].hash_changed);
    }

    #[test]
    fn report_round_trips() {
        let r = BenchReport {
            date: "d".into(),
            machine: "m".into(),
            build: "b".into(),
            workloads: vec![m("a", 1.0, 2, "h")],
            instructions: vec![InstructionCount {
                name: "i".into(),
                command: "c".into(),
                instructions: 10,
                per_item: 2.5,
                unit: "particles".into(),
                state_hash: Some("h".into()),
            }],
            against: Vec::new(),
        };
        let s = serde_json::to_string(&r).unwrap();
        assert_eq!(serde_json::from_str::<BenchReport>(&s).unwrap(), r);
    }
}
