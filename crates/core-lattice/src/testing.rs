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
