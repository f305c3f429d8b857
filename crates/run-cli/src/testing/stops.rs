//! The stopping contract every binary keeps without a checkpoint flag: a signal at any moment
//! of a run checkpoints it and exits with code 130, memory about to run out checkpoints it and
//! exits with code 1, and `--resume` then ends the run as the uninterrupted one; a run that
//! ends normally leaves no checkpoint behind.

use super::manifest;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The `state_hash` of the finished run in `dir`.
pub fn state_hash(dir: &Path) -> String {
    manifest(dir)["results"]["state_hash"]
        .as_str()
        .unwrap_or_default()
        .to_string()
}

/// A delay drawn from the clock's nanoseconds, in `[lo, hi)`: each test run signals at
/// another moment (the delay is in every failure's message).
fn random_delay(lo: Duration, hi: Duration) -> Duration {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let span = hi.saturating_sub(lo).as_secs_f64();
    lo + Duration::from_secs_f64(span * f64::from(nanos % 1_000_000) / 1e6)
}

/// Checks the contract for `binary` (messages start `program: `) run with `flags` (which hold
/// no checkpoint flag and no `--out`) in the directory `dir`:
///
/// - the uninterrupted run leaves no `checkpoint.bin` (nor any file named in `unasked`);
/// - for SIGTERM, SIGINT, SIGUSR1 and SIGXCPU, sent at a random moment of the run: exit code
///   130, one line naming the signal and `--resume`, a `checkpoint.bin`; then `--resume DIR
///   --out DIR` ends with the uninterrupted run's state hash;
/// - with the machine's memory faked to nearly none ([`FAKE_MEMORY_ENV`]): exit code 1, one
///   line `program: run failed: memory nearly exhausted ...`, a checkpoint, and the same
///   resume.
///
/// Returns one description per broken clause.
///
/// [`FAKE_MEMORY_ENV`]: run_io::guard::FAKE_MEMORY_ENV
pub fn stop_contract(
    binary: &Path,
    program: &str,
    dir: &Path,
    flags: &[&str],
    unasked: &[&str],
) -> Vec<String> {
    let mut failures = Vec::new();
    let run = |out: &Path| {
        let mut c = Command::new(binary);
        c.args(flags)
            .arg("--out")
            .arg(out)
            .stdin(Stdio::null())
            .stdout(Stdio::null());
        c
    };
    let whole = dir.join("whole");
    let start = Instant::now();
    let o = run(&whole).stderr(Stdio::piped()).output().expect("runs");
    let took = start.elapsed();
    if !o.status.success() {
        return vec![format!(
            "the uninterrupted run failed: {}",
            String::from_utf8_lossy(&o.stderr)
        )];
    }
    let hash = state_hash(&whole);
    for f in std::iter::once(&"checkpoint.bin").chain(unasked) {
        if whole.join(f).exists() {
            failures.push(format!("a finished run left {f}, which it did not ask for"));
        }
    }
    let resume = |out: &Path, what: &str, failures: &mut Vec<String>| {
        let o = run(out)
            .arg("--resume")
            .arg(out)
            .stderr(Stdio::piped())
            .output()
            .expect("runs");
        if !o.status.success() {
            failures.push(format!(
                "{what}: --resume failed: {}",
                String::from_utf8_lossy(&o.stderr).trim()
            ));
        } else if state_hash(out) != hash {
            failures.push(format!(
                "{what}: resumed to state {}, not the uninterrupted {hash}",
                state_hash(out)
            ));
        } else if out.join("checkpoint.bin").exists() {
            failures.push(format!(
                "{what}: the finished resumed run left checkpoint.bin"
            ));
        }
    };
    #[cfg(unix)]
    for (sig, name) in [
        (nix::sys::signal::Signal::SIGTERM, "SIGTERM"),
        (nix::sys::signal::Signal::SIGINT, "SIGINT"),
        (nix::sys::signal::Signal::SIGUSR1, "SIGUSR1"),
        (nix::sys::signal::Signal::SIGXCPU, "SIGXCPU"),
    ] {
        let out = dir.join(name);
        // A moment of the run's middle: after its start, well before its end.
        let delay = random_delay(took / 10, took / 2);
        let what = format!("{name} after {delay:?} of a {took:?} run");
        let mut child = run(&out).stderr(Stdio::piped()).spawn().expect("starts");
        std::thread::sleep(delay);
        if child.try_wait().expect("waits").is_some() {
            failures.push(format!("{what}: the run ended before the signal"));
            continue;
        }
        let pid = nix::unistd::Pid::from_raw(i32::try_from(child.id()).expect("a pid"));
        nix::sys::signal::kill(pid, sig).expect("the signal is sent");
        let o = child.wait_with_output().expect("waits");
        let err = String::from_utf8_lossy(&o.stderr);
        let lines: Vec<&str> = err.lines().collect();
        if o.status.code() != Some(130)
            || lines.len() != 1
            || !lines[0].starts_with(&format!("{program}: {name}: interrupted"))
            || !lines[0].contains("--resume")
        {
            failures.push(format!(
                "{what}: exit {:?} with {err:?}, not 130 and one line naming {name} and --resume",
                o.status.code()
            ));
            continue;
        }
        if !out.join("checkpoint.bin").exists() {
            failures.push(format!("{what}: no checkpoint.bin"));
            continue;
        }
        resume(&out, &what, &mut failures);
    }
    // Memory: the faked machine has nothing left beyond the process's own memory.
    let out = dir.join("memory");
    let o = run(&out)
        .env(run_io::guard::FAKE_MEMORY_ENV, "16M")
        .stderr(Stdio::piped())
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&o.stderr);
    let lines: Vec<&str> = err.lines().collect();
    if o.status.code() != Some(1)
        || lines.len() != 1
        || !lines[0].starts_with(&format!("{program}: run failed: memory nearly exhausted"))
        || !lines[0].contains("--resume")
    {
        failures.push(format!(
            "memory: exit {:?} with {err:?}, not 1 and one line saying memory ran out",
            o.status.code()
        ));
    } else if !out.join("checkpoint.bin").exists() {
        failures.push("memory: no checkpoint.bin".into());
    } else {
        resume(&out, "memory", &mut failures);
    }
    failures
}
