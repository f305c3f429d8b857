//! `cargo xtask bench --instructions`: the workloads counted in instructions under cachegrind,
//! a figure that does not depend on the host's load.

use super::{Workload, items};
use anyhow::{Context, Result, bail};
use run_io::RunManifest;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::process::Command;

/// Workloads counted in instructions (`cargo xtask bench --instructions`): the same binaries
/// under `valgrind --tool=cachegrind --cache-sim=no`, one thread, so that the figure is the
/// same on a busy or quiet host (and on any x86-64 host for the same build): the cost of a
/// particle without the host's noise. Slow (about 30 times the native run).
pub const INSTRUCTION_WORKLOADS: &[Workload] = &[
    Workload {
        name: "dla-2d-1e6-instructions",
        bin: "dla",
        args: "--dim 2 --particles 1e6 --seed 1 --no-checkpoint",
        unit: "particles",
    },
    Workload {
        name: "dla-3d-1e6-instructions",
        bin: "dla",
        args: "--dim 3 --particles 1e6 --seed 1 --no-checkpoint",
        unit: "particles",
    },
];

/// The instructions a workload of [`INSTRUCTION_WORKLOADS`] executed.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct InstructionCount {
    /// Workload name.
    pub name: String,
    /// The command that ran.
    pub command: String,
    /// Instructions executed, every thread of the process (cachegrind's `I refs`).
    pub instructions: u64,
    /// Instructions per item (particle).
    pub per_item: f64,
    /// What an item is.
    pub unit: String,
    /// The run's state hash: equal hashes, equal work.
    pub state_hash: Option<String>,
}

/// Cachegrind's `I refs` count from its report on stderr (`==123== I   refs:  2,685,370,135`).
pub fn parse_i_refs(stderr: &str) -> Option<u64> {
    stderr.lines().find_map(|l| {
        let words: Vec<&str> = l.split_whitespace().collect();
        let at = words.windows(2).position(|w| w == ["I", "refs:"])?;
        let digits: String = words
            .get(at + 2)?
            .chars()
            .filter(char::is_ascii_digit)
            .collect();
        digits.parse().ok()
    })
}

/// Runs workload `w` under cachegrind (no cache simulation) and counts its instructions.
pub fn count_instructions(w: &Workload, bin_dir: &Path) -> Result<InstructionCount> {
    let out = tempfile::tempdir().context("creating a temporary output directory")?;
    let bin = bin_dir.join(w.bin);
    let command = format!(
        "valgrind --tool=cachegrind --cache-sim=no target/release/{} {} -qq --out DIR",
        w.bin, w.args
    );
    eprintln!("==> {}: {command}", w.name);
    let output = Command::new("valgrind")
        .arg("--tool=cachegrind")
        .arg("--cache-sim=no")
        .arg(format!(
            "--cachegrind-out-file={}",
            out.path().join("cachegrind.out").display()
        ))
        .arg(&bin)
        .args(w.arg_list())
        .arg("-qq")
        .arg("--out")
        .arg(out.path().join("run"))
        .output()
        .context("could not run valgrind (Debian: apt-get install valgrind)")?;
    let stderr = String::from_utf8_lossy(&output.stderr);
    if !output.status.success() {
        bail!(
            "{} failed under valgrind ({}): {}",
            w.name,
            output.status,
            stderr.trim()
        );
    }
    let instructions = parse_i_refs(&stderr)
        .with_context(|| format!("no `I refs` line in cachegrind's report: {stderr}"))?;
    let m =
        RunManifest::read(out.path().join("run").join("run.json")).context("reading run.json")?;
    let (count, _) = items(w, &m, &out.path().join("run"))?;
    let per_item = instructions as f64 / count.max(1.0);
    eprintln!(
        "    {instructions} instructions, {per_item:.0} per {}",
        w.unit.trim_end_matches('s')
    );
    Ok(InstructionCount {
        name: w.name.into(),
        command,
        instructions,
        per_item,
        unit: w.unit.into(),
        state_hash: m
            .results
            .get("state_hash")
            .and_then(|v| v.as_str())
            .map(String::from),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cachegrind_instruction_counts_are_read() {
        let stderr = "==4242== Cachegrind, a high-precision tracing profiler\n\
                      ==4242== \n==4242== I   refs:      2,685,370,135\n";
        assert_eq!(parse_i_refs(stderr), Some(2_685_370_135));
        assert_eq!(parse_i_refs("no report"), None);
    }
}
