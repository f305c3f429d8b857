//! The experiments' multi-seed runs, made by the models' own ensembles: `PROG --seeds A..=B
//! [flags] --out DIR`, then `DIR/ensemble.json` read back. "Run seeds, combine" has one
//! implementation (`run_cli::ensemble`), the one users run; the members stay on disk as
//! ordinary runs (`DIR/seed-NNNN/`, with `run.json` and the model's CSV files) for inspection.

use super::Ctx;
use anyhow::{Context, Result, bail};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One statistic of `ensemble.json`'s `results`.
#[derive(Debug, Clone, Copy, Deserialize)]
pub struct Stats {
    /// Mean over the members.
    pub mean: f64,
    /// Sample standard deviation.
    pub std: f64,
    /// Standard error of the mean.
    pub stderr: f64,
    /// Members that reported it.
    pub n: usize,
}

/// One member as `ensemble.json` lists it.
#[derive(Debug, Clone, Deserialize)]
pub struct Member {
    /// Its seed.
    pub seed: u64,
    /// Its directory, relative to the ensemble's.
    pub dir: String,
    /// Its scalar results (`run.json`'s `results`, numbers only).
    pub results: BTreeMap<String, f64>,
}

#[derive(Debug, Deserialize)]
struct EnsembleJson {
    results: BTreeMap<String, Stats>,
    per_member: Vec<Member>,
    #[serde(default)]
    unfinished: Vec<serde_json::Value>,
    #[serde(default)]
    invalid: Vec<serde_json::Value>,
}

/// A finished ensemble.
#[derive(Debug)]
pub struct Ensemble {
    /// Its directory.
    pub dir: PathBuf,
    /// The combined statistics by result name.
    pub results: BTreeMap<String, Stats>,
    /// The members in seed order.
    pub members: Vec<Member>,
}

impl Ensemble {
    /// The combined statistics of result `name`.
    pub fn stat(&self, name: &str) -> Result<Stats> {
        self.results
            .get(name)
            .copied()
            .with_context(|| format!("{}: no result {name:?}", self.dir.display()))
    }

    /// Result `name` of every member, in seed order.
    pub fn values(&self, name: &str) -> Result<Vec<f64>> {
        self.members
            .iter()
            .map(|m| {
                m.results
                    .get(name)
                    .copied()
                    .with_context(|| format!("member {}: no result {name:?}", m.seed))
            })
            .collect()
    }

    /// Directory of member `m`.
    pub fn member_dir(&self, m: &Member) -> PathBuf {
        self.dir.join(&m.dir)
    }
}

/// Numeric columns `names` of a CSV file a model wrote, one vector per column.
pub fn columns(path: &Path, names: &[&str]) -> Result<Vec<Vec<f64>>> {
    let mut reader =
        csv::Reader::from_path(path).with_context(|| format!("reading {}", path.display()))?;
    let header = reader.headers()?.clone();
    let idx: Vec<usize> = names
        .iter()
        .map(|n| {
            header
                .iter()
                .position(|h| h == *n)
                .with_context(|| format!("{}: no column {n:?}", path.display()))
        })
        .collect::<Result<_>>()?;
    let mut cols = vec![Vec::new(); names.len()];
    for rec in reader.records() {
        let rec = rec?;
        for (c, &i) in cols.iter_mut().zip(&idx) {
            c.push(
                rec[i].parse().with_context(|| {
                    format!("{}: {:?} is not a number", path.display(), &rec[i])
                })?,
            );
        }
    }
    Ok(cols)
}

impl Ctx {
    /// Runs `program --seeds S..=S+count-1 args --out RUNS/name -q` (a fresh directory: members
    /// of an earlier invocation, perhaps of other code, are never reused) and reads the combined
    /// result. Fails unless every member finished.
    pub fn ensemble(
        &self,
        program: &str,
        name: &str,
        count: u64,
        args: &[String],
    ) -> Result<Ensemble> {
        let dir = self.runs.join(name);
        if dir.exists() {
            std::fs::remove_dir_all(&dir).with_context(|| format!("clearing {}", dir.display()))?;
        }
        let bin = self.bin_dir.join(program);
        let seeds = format!("{}..={}", self.seed, self.seed + count.max(1) - 1);
        let status = Command::new(&bin)
            .arg("--seeds")
            .arg(&seeds)
            .args(args)
            .arg("--out")
            .arg(&dir)
            .arg("-q")
            .status()
            .with_context(|| format!("starting {}", bin.display()))?;
        if !status.success() {
            bail!(
                "`{program} --seeds {seeds} {} --out {}` failed ({status}); members' logs are in \
                 {}/seed-*/member.log",
                args.join(" "),
                dir.display(),
                dir.display()
            );
        }
        let path = dir.join("ensemble.json");
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("reading {}", path.display()))?;
        let json: EnsembleJson =
            serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
        if !json.unfinished.is_empty()
            || !json.invalid.is_empty()
            || json.per_member.len() as u64 != count
        {
            bail!(
                "{}: {} members combined of {count} ({} unfinished, {} invalid)",
                path.display(),
                json.per_member.len(),
                json.unfinished.len(),
                json.invalid.len()
            );
        }
        let mut members = json.per_member;
        members.sort_by_key(|m| m.seed);
        Ok(Ensemble {
            dir,
            results: json.results,
            members,
        })
    }
}
