//! The memory contract of a model binary: a run that cannot fit is refused, the estimate
//! bounds the measured peak.

use super::*;
use std::path::Path;
use std::process::{Command, Stdio};

/// The memory contract of a model binary (`run_io::memory`), with the flags of a small run
/// `flags` whose estimated peak memory is `estimate` bytes, checked in the working directory
/// `dir`:
///
/// - with `--max-memory 1K` the run "cannot fit": exit code 2, one line naming the estimate
///   and `--max-memory`, nothing created;
/// - with a generous `--max-memory 1T` it runs (exit code 0), and without the flag too (the
///   memory available);
/// - the estimate is an upper bound of the run's measured peak RSS (`peak_rss_bytes` in its
///   `run.json`), within `tolerance` times it (generous: the estimate is for sizes where the
///   fixed part does not dominate).
///
/// Returns one description per broken clause (empty when all held).
pub fn memory_contract(
    binary: &Path,
    program: &str,
    dir: &Path,
    flags: &[&str],
    estimate: u64,
    tolerance: f64,
) -> Vec<String> {
    let with = |extra: &[&str]| -> Vec<String> {
        flags
            .iter()
            .chain(extra)
            .map(|s| s.to_string())
            .collect::<Vec<_>>()
    };
    let refused = with(&["--max-memory", "1K", "--out", "refused"]);
    let refused: Vec<&str> = refused.iter().map(String::as_str).collect();
    let mut failures = refusals(
        binary,
        program,
        dir,
        &[(&refused, "over --max-memory 1.0 KiB")],
    );
    // The estimate under `--max-memory 1K` may differ from `estimate` (dlca's `auto` search
    // then leaves out the occupancy lattice), so only its wording is checked here.
    let needs = "the run needs about ";
    let out = Command::new(binary)
        .args(&refused)
        .current_dir(dir)
        .output()
        .expect("the binary runs");
    if !String::from_utf8_lossy(&out.stderr).contains(needs) {
        failures.push(format!(
            "the refusal does not say {needs:?}: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    for (name, extra) in [
        ("generous", &["--max-memory", "1T"][..]),
        ("default", &[][..]),
    ] {
        let args = with(extra);
        let out = Command::new(binary)
            .args(&args)
            .args(["-qq", "--out", name])
            .current_dir(dir)
            .stdin(Stdio::null())
            .output()
            .expect("the binary runs");
        if !out.status.success() {
            failures.push(format!(
                "{program} {} --out {name}: exit {:?}: {}",
                args.join(" "),
                out.status.code(),
                String::from_utf8_lossy(&out.stderr).trim()
            ));
            continue;
        }
        let peak = manifest(&dir.join(name))["peak_rss_bytes"]
            .as_u64()
            .unwrap_or(0);
        if peak == 0 {
            continue; // no peak RSS on this system
        }
        if estimate < peak || estimate as f64 > tolerance * peak as f64 {
            failures.push(format!(
                "{program} {}: estimate {estimate} bytes against a measured peak of {peak} \
                 (want peak <= estimate <= {tolerance} peak)",
                args.join(" ")
            ));
        }
    }
    failures
}
