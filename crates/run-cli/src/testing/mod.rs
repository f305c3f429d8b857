//! Test support for the model binaries (feature `test-support`, for their integration tests
//! only): drive a binary with bad inputs and check the usage-error contract of
//! [`cli`](crate::cli): exit code 2, one line on stderr naming the culprit, nothing created.

mod stops;
pub use stops::{state_hash, stop_contract};

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

/// Like [`kill_once_written`], but `cmd` runs in a process group of its own and the whole group
/// is killed: a process and the children it started (an ensemble and its members), as a node
/// that crashes. Returns whether the process was still running when killed.
pub fn kill_group_once_written(cmd: &mut Command, file: &Path) -> bool {
    #[cfg(unix)]
    std::os::unix::process::CommandExt::process_group(cmd, 0);
    let (mut child, running) = spawn_until_written(cmd, file);
    #[cfg(unix)]
    if let Ok(pid) = i32::try_from(child.id()) {
        use nix::sys::signal::{Signal, killpg};
        let _ = killpg(nix::unistd::Pid::from_raw(pid), Signal::SIGKILL);
    }
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
    run_io::write_checkpoint(dir.join("other/checkpoint.bin"), foreign, &(1u64, 2u64))
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
/// flags `flags` (small and fast), checked in the working directory `dir`; `scalar` names a
/// numeric result every member reports:
///
/// - a bad list, or `--seeds` with `--seed`, is a usage error (exit code 2);
/// - an ensemble of 4 seeds killed (SIGKILL, with its members) after its second member and run
///   again finishes only the missing members, and equals an uninterrupted ensemble;
/// - every member equals the plain run with its seed (same `state_hash`), and every combined
///   mean and standard error equals a direct computation from the members' `run.json`;
/// - a member that cannot run is reported by seed with exit code 1 while the others finish and
///   are combined;
/// - `--merge` combines what is there, reporting a corrupt and a missing member.
pub fn ensemble_contract(binary: &Path, program: &str, dir: &Path, flags: &[&str], scalar: &str) {
    let command = |args: &[&str]| {
        let mut c = Command::new(binary);
        c.args(args)
            .args(flags)
            .arg("-qq")
            .current_dir(dir)
            .stdin(Stdio::null());
        c
    };
    let run = |args: &[&str]| command(args).output().expect("the binary starts");
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

    // Killed midway, with its members (a crashed node), then run again.
    let ens = dir.join("ens");
    let running = kill_group_once_written(
        &mut command(&["--seeds", "1..=4", "--jobs", "1", "--out", "ens"]),
        &ens.join("seed-0002/run.json"),
    );
    assert!(running, "the ensemble ended before it could be killed");
    assert!(!ens.join("ensemble.json").exists());
    let mtime = |seed: u64| {
        std::fs::metadata(ens.join(format!("seed-{seed:04}/run.json")))
            .and_then(|m| m.modified())
            .expect("a finished member")
    };
    let before = (mtime(1), mtime(2));
    let o = run(&["--seeds", "1..=4", "--out", "ens"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        (mtime(1), mtime(2)),
        before,
        "a finished member was run again"
    );
    let o = run(&["--seeds", "1..=4", "--out", "whole"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let doc = manifest_named(&ens, "ensemble.json");
    let whole = manifest_named(&dir.join("whole"), "ensemble.json");
    assert_eq!(doc["members"], 4);
    let results = doc["results"].as_object().expect("results");
    assert!(results.contains_key(scalar), "{doc}");
    assert!(results.get("state_hash").is_none());
    for (key, stats) in results {
        // Times and memory are the machine's, not the model's.
        if !key.contains("seconds") && !key.contains("bytes") {
            assert_eq!(
                *stats, whole["results"][key],
                "{key}: resumed and whole ensembles differ"
            );
        }
        // Against a direct computation from the members' run.json.
        let values: Vec<f64> = (1..=4)
            .filter_map(|s| {
                let m = manifest(&ens.join(format!("seed-{s:04}")));
                // Time and memory are top-level keys of run.json, the rest are results.
                m["results"][key].as_f64().or_else(|| m[key].as_f64())
            })
            .collect();
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1e-300);
        assert_eq!(stats["n"].as_u64(), Some(values.len() as u64), "{key}");
        assert!(
            close(stats["mean"].as_f64().unwrap(), mean),
            "{key}: {stats} against {mean}"
        );
        assert!(
            close(stats["stderr"].as_f64().unwrap(), (var / n).sqrt()),
            "{key}: {stats}"
        );
    }
    for seed in 1u64..=4 {
        let single = format!("single-{seed}");
        let o = run(&["--seed", &seed.to_string(), "--out", &single]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert_eq!(
            manifest(&dir.join(&single))["results"]["state_hash"],
            manifest(&ens.join(format!("seed-{seed:04}")))["results"]["state_hash"],
            "member {seed} differs from the plain run with its seed"
        );
    }

    // A member that cannot run.
    let blocked = dir.join("blocked");
    std::fs::create_dir_all(&blocked).expect("creating a directory");
    std::fs::write(blocked.join("seed-0003"), b"in the way").expect("a blocking file");
    let o = run(&["--seeds", "1..=4", "--out", "blocked"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with(&format!("{program}: run failed: "))
            && err.contains("seed 3:")
            && err.lines().count() == 1,
        "{err}"
    );
    let b = manifest_named(&blocked, "ensemble.json");
    assert_eq!(b["members"], 3, "{b}");
    assert_eq!(b["results"][scalar]["n"], 3, "{b}");

    // --merge with a corrupt and a missing member.
    std::fs::write(ens.join("seed-0004/run.json"), b"{\"model\": ").expect("corrupting");
    std::fs::create_dir_all(ens.join("seed-0009")).expect("an unfinished member");
    let o = Command::new(binary)
        .args(["--merge", "ens"])
        .current_dir(dir)
        .output()
        .expect("the binary starts");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("seed-0004") && err.contains("seed-0009"),
        "{err}"
    );
    let m = manifest_named(&ens, "ensemble.json");
    assert_eq!(m["members"], 3);
    assert_eq!(m["unfinished"][0], "seed-0009");
    assert!(
        m["invalid"][0]
            .as_str()
            .is_some_and(|s| s.starts_with("seed-0004")),
        "{m}"
    );
    assert!(ens.join("ensemble.md").is_file());
}

/// A JSON file in `dir`.
fn manifest_named(dir: &Path, name: &str) -> serde_json::Value {
    let path = dir.join(name);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_slice(&bytes).expect("JSON")
}

/// The provenance and log contract of a model binary run with `flags` (small and fast, without
/// `--out`), checked in the working directory `dir`:
///
/// - `run.json` has a `provenance` with the date, version, this build's git commit, the command
///   line as given, the host, the CPU and the threads;
/// - with stderr redirected (not a terminal), `-v` logs carry no ANSI escape codes, and
///   `--color always` puts them back.
pub fn provenance_and_color_contract(binary: &Path, dir: &Path, flags: &[&str]) {
    let run = |out: &str, extra: &[&str]| {
        let o = Command::new(binary)
            .args(flags)
            .args(extra)
            .args(["-v", "--out", out])
            .current_dir(dir)
            .stdin(Stdio::null())
            .output()
            .expect("the binary starts");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let plain = run("plain", &[]);
    assert!(plain.contains("INFO"), "no info log with -v: {plain}");
    assert!(
        !plain.contains('\u{1b}'),
        "ANSI codes in a redirected log: {plain:?}"
    );
    let coloured = run("coloured", &["--color", "always"]);
    assert!(coloured.contains("\u{1b}["), "--color always: {coloured:?}");

    let m = manifest(&dir.join("plain"));
    let p = &m["provenance"];
    let date = p["date_utc"].as_str().expect("date_utc");
    assert!(
        date.len() == 20 && date.ends_with('Z') && date.starts_with("20"),
        "{date}"
    );
    assert_eq!(p["version"], m["version"]);
    assert_eq!(p["threads"], m["threads"]);
    assert_eq!(
        p["git_commit"].as_str(),
        run_io::provenance::GIT_COMMIT,
        "the binary and this test were built from different commits"
    );
    let line: Vec<&str> = p["command_line"]
        .as_array()
        .expect("command_line")
        .iter()
        .filter_map(|a| a.as_str())
        .collect();
    assert!(line.len() == flags.len() + 4, "{line:?}");
    assert!(line[1..].starts_with(flags), "{line:?}");
    for key in ["host", "cpu"] {
        assert!(!p[key].as_str().unwrap_or("").is_empty(), "{key}: {p}");
    }
    assert!(p["cpus"].as_u64().unwrap_or(0) >= 1, "{p}");
}

/// The config-file contract of a binary with [`crate::cli::ConfigArgs`], run with `flags`
/// (small and fast, without `--out`) in the working directory `dir`:
///
/// - a run saves its effective configuration as `OUT/config.toml`, and `--dump-config` with the
///   same flags prints exactly that file, without running and without `--out`;
/// - `--config OUT/config.toml` repeats the run (same `state_hash`);
/// - a flag on the command line overrides the file.
pub fn config_contract(binary: &Path, dir: &Path, flags: &[&str]) {
    let run = |args: &[&str]| {
        let o = Command::new(binary)
            .args(args)
            .arg("-qq")
            .current_dir(dir)
            .stdin(Stdio::null())
            .output()
            .expect("the binary starts");
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    fn with<'a>(flags: &[&'a str], extra: &[&'a str]) -> Vec<&'a str> {
        flags.iter().chain(extra).copied().collect()
    }
    run(&with(flags, &["--out", "a"]));
    let saved = std::fs::read_to_string(dir.join("a/config.toml")).expect("config.toml");
    let dumped = run(&with(flags, &["--dump-config"]));
    assert_eq!(
        dumped, saved,
        "--dump-config differs from the saved config.toml"
    );
    assert!(!dir.join("b").exists());
    run(&["--config", "a/config.toml", "--out", "b"]);
    let hash = |d: &str| manifest(&dir.join(d))["results"]["state_hash"].clone();
    assert_eq!(
        hash("a"),
        hash("b"),
        "--config OUT/config.toml did not repeat the run"
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("b/config.toml")).unwrap(),
        saved,
        "the repeated run's configuration differs"
    );
    run(&["--config", "a/config.toml", "--seed", "98765", "--out", "c"]);
    assert_ne!(
        hash("a"),
        hash("c"),
        "--seed on the command line did not override the file"
    );
    let c = std::fs::read_to_string(dir.join("c/config.toml")).unwrap();
    assert!(c.contains("seed = 98765"), "{c}");
}

mod memory;
mod ownership;

pub use memory::*;
pub use ownership::*;
