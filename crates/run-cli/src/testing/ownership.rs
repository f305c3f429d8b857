//! The ownership contract of a model binary: `--out` is one run's (locks, earlier runs
//! refused or replaced with `--overwrite`, ensembles continuing only like members).

use super::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// Every file under `dir` (relative paths) with its bytes and modification time: equal before
/// and after a command that must not touch an earlier run.
pub fn files_with_mtimes(dir: &Path) -> BTreeMap<PathBuf, (Vec<u8>, std::time::SystemTime)> {
    tree(dir)
        .into_keys()
        .filter_map(|rel| {
            let path = dir.join(&rel);
            let meta = std::fs::metadata(&path).ok().filter(|m| m.is_file())?;
            let bytes = std::fs::read(&path).expect("reading a listed file");
            Some((rel, (bytes, meta.modified().expect("an mtime"))))
        })
        .collect()
}

/// A model binary and the flags of [`ownership_contract`].
#[derive(Debug, Clone, Copy)]
pub struct Ownership<'a> {
    /// The binary.
    pub binary: &'a Path,
    /// Its name, as its messages start (`dla`).
    pub program: &'a str,
    /// The working directory of the runs.
    pub dir: &'a Path,
    /// Flags of a small, fast run, without `--out`, `--seed` (ensembles are run with them) and
    /// `change`'s flag.
    pub flags: &'a [&'a str],
    /// A parameter flag (saved in `config.toml`) and two values of it:
    /// `("--particles", "200", "300")`.
    pub change: (&'a str, &'a str, &'a str),
    /// Flags of a run that takes a few seconds at least (caught running), without `--out`.
    pub long: &'a [&'a str],
    /// Flags of a run of a second or two that writes a checkpoint early
    /// (`--checkpoint-every N` included), without `--out`.
    pub checkpointed: &'a [&'a str],
}

/// Runs `o.binary` with `args` in `o.dir`, without input: its output and its stderr as text.
fn run_in(o: &Ownership<'_>, args: &[&str]) -> (std::process::Output, String) {
    let out = Command::new(o.binary)
        .args(args)
        .current_dir(o.dir)
        .stdin(Stdio::null())
        .output()
        .expect("the binary runs");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    (out, stderr)
}

/// Runs `binary` with `args` in `dir` and checks a usage refusal: exit code 2 and one stderr
/// line `program: error: ...` containing every one of `needles`. Returns the line.
pub fn expect_refusal(o: &Ownership<'_>, args: &[&str], needles: &[&str]) -> String {
    let (out, stderr) = run_in(o, args);
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert_eq!(lines.len(), 1, "{args:?}: not one line: {stderr}");
    assert!(
        lines[0].starts_with(&format!("{}: error: ", o.program)),
        "{args:?}: {stderr}"
    );
    for n in needles {
        assert!(lines[0].contains(n), "{args:?}: {n:?} not in {stderr}");
    }
    lines[0].to_owned()
}

/// Runs `binary` with `args` in `dir`, asserting success; returns stderr.
fn expect_success(o: &Ownership<'_>, args: &[&str]) -> String {
    let (out, stderr) = run_in(o, args);
    assert!(out.status.success(), "{args:?}: {stderr}");
    stderr
}

/// The command line `run.json` in `dir` records.
fn command_line(dir: &Path) -> Vec<String> {
    manifest(dir)["provenance"]["command_line"]
        .as_array()
        .expect("command_line")
        .iter()
        .filter_map(|a| a.as_str().map(str::to_owned))
        .collect()
}

/// The output-directory ownership contract of a model binary ([`crate::cli::claim_out_dir`]):
///
/// - a rerun into a finished run's `--out` is refused (exit code 2, one line naming `run.json`
///   and `--overwrite`), and no file of the earlier run changes (bytes and mtimes);
/// - `--overwrite` with `--resume` is refused, nothing changes;
/// - `--overwrite` replaces the run (exit code 0), keeping an unrelated file; an empty
///   directory, or one with only unrelated files, is accepted;
/// - a second run into a directory a running run holds is refused at once, naming the holder's
///   pid, host and start; after that run is killed by SIGKILL, its partial outputs are refused
///   with nothing changed, and `--overwrite` takes over its stale lock, naming it in a warning;
/// - a run killed by SIGKILL after its first checkpoint is refused with `--resume DIR` offered,
///   and `--resume DIR --out DIR` takes over the stale lock and finishes;
/// - an ensemble rerun with another value of `change` is refused, naming each member and the
///   flag with both values, nothing changed (a finished member compared by its `run.json`, an
///   unfinished one by its `config.toml`); the same rerun with `--overwrite` starts over;
/// - a second ensemble into a running ensemble's directory is refused naming the first, and
///   so is a run into the directory of a member that is running;
/// - no finished run, nor one stopped by SIGTERM after a checkpoint, leaves its `run.lock`.
pub fn ownership_contract(o: &Ownership<'_>) {
    let (flag, a, b) = o.change;
    let with = |extra: &[&str]| -> Vec<String> {
        o.flags
            .iter()
            .chain(extra)
            .map(|s| (*s).to_owned())
            .chain(["-qq".to_owned()])
            .collect()
    };
    let refuse = |args: &[String], needles: &[&str]| {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        expect_refusal(o, &args, needles)
    };
    let succeed = |args: &[String]| {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        expect_success(o, &args)
    };
    let lock = crate::cli::LOCK_FILE;

    // A finished run is kept.
    succeed(&with(&[flag, a, "--out", "fin"]));
    let fin = o.dir.join("fin");
    assert!(!fin.join(lock).exists(), "a finished run left its lock");
    std::fs::write(fin.join("notes.txt"), b"mine").expect("an unrelated file");
    let before = files_with_mtimes(&fin);
    let line = refuse(
        &with(&[flag, b, "--out", "fin"]),
        &["--out fin", "a finished run", "run.json", "--overwrite"],
    );
    assert!(
        !line.contains("--resume"),
        "no checkpoint to resume: {line}"
    );
    assert_eq!(
        files_with_mtimes(&fin),
        before,
        "a refused rerun changed fin"
    );
    refuse(
        &with(&[flag, b, "--overwrite", "--resume", "fin", "--out", "fin"]),
        &["--overwrite", "--resume"],
    );
    assert_eq!(
        files_with_mtimes(&fin),
        before,
        "--overwrite --resume changed fin"
    );
    succeed(&with(&[flag, b, "--overwrite", "--out", "fin"]));
    assert!(command_line(&fin).iter().any(|x| x == b), "not replaced");
    assert_eq!(
        std::fs::read(fin.join("notes.txt")).ok(),
        Some(b"mine".to_vec())
    );
    assert!(!fin.join(lock).exists());

    // An empty directory and one with unrelated files are accepted.
    std::fs::create_dir(o.dir.join("empty")).expect("a directory");
    succeed(&with(&[flag, a, "--out", "empty"]));
    std::fs::create_dir(o.dir.join("other")).expect("a directory");
    std::fs::write(o.dir.join("other/data.txt"), b"x").expect("an unrelated file");
    succeed(&with(&[flag, a, "--out", "other"]));

    // Two runs at once: the second is refused, naming the first.
    let busy = o.dir.join("busy");
    let mut first = Command::new(o.binary)
        .args(o.long)
        .args(["-qq", "--out", "busy"])
        .current_dir(o.dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("the binary starts");
    let holder = loop {
        // The lock, and the first file the run writes (so that it leaves partial outputs).
        if let Ok(text) = std::fs::read_to_string(busy.join(lock))
            && !text.is_empty()
            && busy.join("config.toml").exists()
        {
            break text;
        }
        assert!(
            first.try_wait().expect("waiting").is_none(),
            "the long run ended before its lock was seen"
        );
        std::thread::sleep(std::time::Duration::from_millis(2));
    };
    let pid = format!("pid {}", first.id());
    assert!(holder.contains(&first.id().to_string()), "{holder}");
    refuse(
        &with(&[flag, a, "--out", "busy"]),
        &[
            "--out busy",
            "in use by another run",
            &pid,
            "on host",
            "since",
        ],
    );
    assert!(
        first.try_wait().expect("waiting").is_none(),
        "the long run ended while the second was refused: the test proves nothing"
    );
    // Killed (SIGKILL): partial outputs and a stale lock stay.
    let _ = first.kill();
    let _ = first.wait();
    assert!(busy.join(lock).exists());
    let before = files_with_mtimes(&busy);
    refuse(
        &with(&[flag, a, "--out", "busy"]),
        &["--out busy", "interrupted run", "--overwrite"],
    );
    assert_eq!(
        files_with_mtimes(&busy),
        before,
        "a refused rerun changed busy"
    );
    let log = succeed(&with(&[flag, a, "--overwrite", "--out", "busy"]));
    assert!(log.contains("stale lock") && log.contains(&pid), "{log}");
    assert!(!busy.join(lock).exists());

    // Killed after a checkpoint: refused with --resume offered, then resumed in place.
    let ck = o.dir.join("ck");
    let mut cmd = Command::new(o.binary);
    cmd.args(o.checkpointed)
        .args(["-qq", "--out", "ck"])
        .current_dir(o.dir)
        .stdin(Stdio::null());
    assert!(
        kill_once_written(&mut cmd, &ck.join("checkpoint.bin")),
        "the checkpointed run ended before it was killed"
    );
    let stale: crate::cli::LockHolder =
        serde_json::from_slice(&std::fs::read(ck.join(lock)).expect("a stale lock"))
            .expect("the lock names its holder");
    let before = files_with_mtimes(&ck);
    let args: Vec<String> = o
        .checkpointed
        .iter()
        .map(|s| (*s).to_owned())
        .chain(["-qq", "--out", "ck"].map(str::to_owned))
        .collect();
    refuse(
        &args,
        &["--out ck", "checkpoint", "--resume ck", "--overwrite"],
    );
    assert_eq!(files_with_mtimes(&ck), before, "a refused rerun changed ck");
    let resumed: Vec<String> = args
        .iter()
        .cloned()
        .chain(["--resume", "ck"].map(str::to_owned))
        .collect();
    let log = succeed(&resumed);
    assert!(
        log.contains("stale lock") && log.contains(&format!("pid {}", stale.pid)),
        "{log}"
    );
    assert!(ck.join("run.json").is_file() && !ck.join(lock).exists());

    // Stopped by SIGTERM (exit code 130 after a checkpoint): the lock file goes with the run.
    let term = o.dir.join("term");
    let mut cmd = Command::new(o.binary);
    cmd.args(o.checkpointed)
        .args(["-qq", "--out", "term"])
        .current_dir(o.dir)
        .stdin(Stdio::null());
    let (running, code) = terminate_once_written(&mut cmd, &term.join("checkpoint.bin"));
    assert!(running, "the checkpointed run ended before SIGTERM");
    assert_eq!(code, Some(130));
    assert!(!term.join(lock).exists(), "SIGTERM left the lock file");

    // An ensemble rerun with another parameter value.
    succeed(&with(&["--seeds", "1..=2", flag, a, "--out", "ens"]));
    let ens = o.dir.join("ens");
    let before = files_with_mtimes(&ens);
    let differ = format!("seed-0001, seed-0002: {flag} {a} there, {b} given");
    refuse(
        &with(&["--seeds", "1..=2", flag, b, "--out", "ens"]),
        &["--out ens", "other parameters", &differ, "--overwrite"],
    );
    assert_eq!(
        files_with_mtimes(&ens),
        before,
        "a refused ensemble changed ens"
    );
    // The same parameters continue (nothing to do).
    succeed(&with(&["--seeds", "1..=2", flag, a, "--out", "ens"]));
    succeed(&with(&[
        "--seeds",
        "1..=2",
        flag,
        b,
        "--overwrite",
        "--out",
        "ens",
    ]));
    for seed in ["seed-0001", "seed-0002"] {
        assert!(
            command_line(&ens.join(seed)).iter().any(|x| x == b),
            "{seed} was not run again"
        );
        assert!(!ens.join(seed).join(lock).exists());
    }
    assert!(!ens.join(lock).exists());
    // An unfinished member (no run.json) is compared by its config.toml.
    std::fs::remove_file(ens.join("seed-0002/run.json")).expect("unfinishing a member");
    let before = files_with_mtimes(&ens);
    let differ = format!("seed-0001, seed-0002: {flag} {b} there, {a} given");
    refuse(
        &with(&["--seeds", "1..=2", flag, a, "--out", "ens"]),
        &["--out ens", "other parameters", &differ],
    );
    assert_eq!(
        files_with_mtimes(&ens),
        before,
        "a refused ensemble changed ens"
    );
    // Two ensembles at once: the second is refused, naming the first; so is a run into a
    // member's directory that member holds.
    let mut cmd = Command::new(o.binary);
    cmd.args(["--seeds", "1..=2", "--jobs", "1"])
        .args(o.long)
        .args(["-qq", "--out", "ens-busy"])
        .current_dir(o.dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    #[cfg(unix)]
    std::os::unix::process::CommandExt::process_group(&mut cmd, 0);
    let mut first = cmd.spawn().expect("the binary starts");
    let member_lock = o.dir.join("ens-busy/seed-0001").join(lock);
    while !std::fs::read(&member_lock).is_ok_and(|b| !b.is_empty()) {
        assert!(
            first.try_wait().expect("waiting").is_none(),
            "the long ensemble ended before its first member locked its directory"
        );
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    let pid = format!("pid {}", first.id());
    refuse(
        &with(&["--seeds", "1..=2", flag, a, "--out", "ens-busy"]),
        &["--out ens-busy", "in use by another run", &pid],
    );
    refuse(
        &with(&[flag, a, "--out", "ens-busy/seed-0001"]),
        &["--out ens-busy/seed-0001", "in use by another run"],
    );
    #[cfg(unix)]
    if let Ok(id) = i32::try_from(first.id()) {
        use nix::sys::signal::{Signal, killpg};
        let _ = killpg(nix::unistd::Pid::from_raw(id), Signal::SIGKILL);
    }
    let _ = first.kill();
    let _ = first.wait();
    // A single run into the ensemble's directory is refused.
    refuse(
        &with(&[flag, b, "--out", "ens"]),
        &["--out ens", "an ensemble", "--overwrite"],
    );
}
