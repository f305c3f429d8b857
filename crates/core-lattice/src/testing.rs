//! Test support for the model binaries (feature `test-support`, for their integration tests
//! only): drive a binary with bad inputs and check the usage-error contract of
//! [`cli`](crate::cli): exit code 2, one line on stderr naming the culprit, nothing created.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// Every file and directory under `dir` (relative paths) with the file sizes.
pub fn tree(dir: &Path) -> BTreeMap<PathBuf, u64> {
    let mut out = BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let path = e.path();
            let meta = e.metadata().expect("metadata of a listed entry");
            let rel = path.strip_prefix(dir).expect("under dir").to_path_buf();
            if meta.is_dir() {
                todo.push(path);
                out.insert(rel, 0);
            } else {
                out.insert(rel, meta.len());
            }
        }
    }
    out
}

/// Runs `binary` (whose messages start `program: error: `) in the working directory `dir`
/// once per case `(args, culprit)`, and checks each is refused as a usage error: exit code 2,
/// exactly one line on stderr, starting `program: error: ` and containing `culprit`, and no
/// file or directory created or changed under `dir`. Returns one description per case that
/// broke the contract (empty when all held), so a test reports every failure at once.
pub fn refusals(
    binary: &Path,
    program: &str,
    dir: &Path,
    cases: &[(&[&str], &str)],
) -> Vec<String> {
    let mut failures = Vec::new();
    for (args, culprit) in cases {
        let before = tree(dir);
        let out = Command::new(binary)
            .args(*args)
            .current_dir(dir)
            .stdin(Stdio::null())
            .output()
            .expect("the binary runs");
        let stderr = String::from_utf8_lossy(&out.stderr);
        let lines: Vec<&str> = stderr.lines().collect();
        let after = tree(dir);
        let mut wrong = Vec::new();
        if out.status.code() != Some(2) {
            wrong.push(format!("exit {:?}, not 2", out.status.code()));
        }
        if lines.len() != 1 {
            wrong.push(format!("{} stderr lines, not 1", lines.len()));
        }
        let prefix = format!("{program}: error: ");
        if !lines
            .first()
            .is_some_and(|l| l.starts_with(&prefix) && l.contains(culprit))
        {
            wrong.push(format!("stderr does not name {culprit:?} after {prefix:?}"));
        }
        if before != after {
            let created: Vec<_> = after.keys().filter(|k| !before.contains_key(*k)).collect();
            wrong.push(format!("files changed (new: {created:?})"));
        }
        if !wrong.is_empty() {
            failures.push(format!(
                "{program} {}: {}; stderr: {}",
                args.join(" "),
                wrong.join(", "),
                stderr.trim()
            ));
        }
    }
    failures
}

/// Whether this process can create a file in a directory without write permission (root
/// can): tests of unwritable output locations skip themselves then.
pub fn permissions_are_bypassed() -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let Ok(dir) = tempfile::tempdir() else {
            return true;
        };
        let ro = dir.path().join("ro");
        if std::fs::create_dir(&ro).is_err()
            || std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).is_err()
        {
            return true;
        }
        let bypassed = std::fs::write(ro.join("probe"), b"").is_ok();
        let _ = std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755));
        bypassed
    }
    #[cfg(not(unix))]
    {
        true
    }
}

/// Starts `cmd` (output discarded) and waits until `file` exists or the process ends; returns
/// the child and whether it is still running.
fn spawn_until_written(cmd: &mut Command, file: &Path) -> (std::process::Child, bool) {
    let mut child = cmd
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("the binary starts");
    while !file.exists() && child.try_wait().expect("wait on the child").is_none() {
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    let running = child.try_wait().expect("wait on the child").is_none();
    (child, running)
}

/// Starts `cmd`, waits until `file` exists (a first checkpoint, say), then kills the process
/// with SIGKILL, as a crash or an out-of-memory kill would. Returns whether the process was
/// still running when killed (false: it had ended first, so nothing was interrupted).
pub fn kill_once_written(cmd: &mut Command, file: &Path) -> bool {
    let (mut child, running) = spawn_until_written(cmd, file);
    // `Child::kill` sends SIGKILL on Unix.
    let _ = child.kill();
    let _ = child.wait();
    running
}

/// Starts `cmd`, waits until `file` exists, then sends it SIGTERM (as a batch system's time
/// limit does) and waits for it. Returns whether it was still running when signalled, and its
/// exit code.
pub fn terminate_once_written(cmd: &mut Command, file: &Path) -> (bool, Option<i32>) {
    let (mut child, running) = spawn_until_written(cmd, file);
    if running {
        send_sigterm(child.id());
    }
    let status = child.wait().expect("wait on the child");
    (running, status.code())
}

/// Next to the good checkpoint `dir/ck/checkpoint.bin`, the broken ones every bad-input table
/// tries: `trunc/` (its first half), `flip/` (one byte of its middle changed) and `other/` (a
/// valid checkpoint of the model `foreign`).
pub fn broken_checkpoints(dir: &Path, foreign: &str) {
    let good = std::fs::read(dir.join("ck/checkpoint.bin")).expect("the good checkpoint");
    let mut flipped = good.clone();
    flipped[good.len() / 2] ^= 0x10;
    for (name, bytes) in [
        ("trunc", good[..good.len() / 2].to_vec()),
        ("flip", flipped),
    ] {
        std::fs::create_dir(dir.join(name)).expect("a fixture directory");
        std::fs::write(dir.join(name).join("checkpoint.bin"), bytes).expect("a fixture");
    }
    std::fs::create_dir(dir.join("other")).expect("a fixture directory");
    crate::io::write_checkpoint(dir.join("other/checkpoint.bin"), foreign, &(1u64, 2u64))
        .expect("a foreign checkpoint");
}

/// Sends SIGTERM to process `pid`.
pub fn send_sigterm(pid: u32) {
    #[cfg(unix)]
    {
        let pid = nix::unistd::Pid::from_raw(i32::try_from(pid).expect("a process id fits i32"));
        nix::sys::signal::kill(pid, nix::sys::signal::Signal::SIGTERM).expect("SIGTERM is sent");
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        panic!("SIGTERM is a Unix signal");
    }
}

/// `run.json` of the run in `dir`, as JSON.
fn manifest(dir: &Path) -> serde_json::Value {
    manifest_named(dir, "run.json")
}

/// The ensemble contract of a model binary (`--seeds`, see [`crate::ensemble`]), with the run
/// flags `flags` (small and fast), checked in the working directory `dir`:
///
/// - a bad list, or `--seeds` with `--seed`, is a usage error (exit code 2);
/// - of `--seeds 1..=3`, a member that cannot run (its directory is taken by a file) is
///   reported by seed with exit code 1 while the others finish and are combined
///   (`ensemble.json` with `results.state_hash` absent and a scalar with `n` = 2);
/// - every member equals the plain run with its seed (same `state_hash`);
/// - rerunning the command runs only the missing member and leaves the finished ones alone;
/// - `--merge DIR` rebuilds the same combined results.
pub fn ensemble_contract(binary: &Path, program: &str, dir: &Path, flags: &[&str], scalar: &str) {
    let run = |args: &[&str]| {
        Command::new(binary)
            .args(args)
            .args(flags)
            .arg("-qq")
            .current_dir(dir)
            .stdin(Stdio::null())
            .output()
            .expect("the binary starts")
    };
    for bad in [
        &["--seeds", "1,1", "--out", "bad"][..],
        &["--seeds", "3..=1", "--out", "bad"],
        &["--seeds", "1..=2", "--seed", "4", "--out", "bad"],
    ] {
        let o = run(bad);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{bad:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(!dir.join("bad").exists(), "{bad:?} created its --out");
    }
    let ens = dir.join("ens");
    std::fs::create_dir_all(&ens).expect("creating the ensemble directory");
    std::fs::write(ens.join("seed-0003"), b"in the way").expect("a blocking file");
    let o = run(&["--seeds", "1..=3", "--out", "ens"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with(&format!("{program}: run failed: "))
            && err.contains("seed 3:")
            && err.lines().count() == 1,
        "{err}"
    );
    let doc = manifest_named(&ens, "ensemble.json");
    assert_eq!(doc["members"], 2, "{doc}");
    assert_eq!(doc["results"][scalar]["n"], 2, "{doc}");
    assert!(doc["results"].get("state_hash").is_none());
    for seed in [1u64, 2] {
        let single = format!("single-{seed}");
        let o = run(&["--seed", &seed.to_string(), "--out", &single]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert_eq!(
            manifest(&dir.join(&single))["results"]["state_hash"],
            manifest(&ens.join(format!("seed-{seed:04}")))["results"]["state_hash"],
            "member {seed} differs from the plain run with its seed"
        );
    }
    std::fs::remove_file(ens.join("seed-0003")).expect("removing the blocking file");
    let before = std::fs::metadata(ens.join("seed-0001/run.json"))
        .and_then(|m| m.modified())
        .expect("mtime");
    let o = run(&["--seeds", "1..=3", "--out", "ens"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let after = std::fs::metadata(ens.join("seed-0001/run.json"))
        .and_then(|m| m.modified())
        .expect("mtime");
    assert_eq!(before, after, "a finished member was run again");
    let doc = manifest_named(&ens, "ensemble.json");
    assert_eq!(doc["members"], 3);
    assert_eq!(doc["results"][scalar]["n"], 3);
    let mean = doc["results"][scalar]["mean"].as_f64().expect("a mean");
    assert!(mean.is_finite());
    std::fs::remove_file(ens.join("ensemble.json")).expect("removing ensemble.json");
    let o = Command::new(binary)
        .args(["--merge", "ens"])
        .current_dir(dir)
        .output()
        .expect("the binary starts");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        manifest_named(&ens, "ensemble.json")["results"],
        doc["results"]
    );
    assert!(ens.join("ensemble.md").is_file());
}

/// A JSON file in `dir`.
fn manifest_named(dir: &Path, name: &str) -> serde_json::Value {
    let path = dir.join(name);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_slice(&bytes).expect("JSON")
}
