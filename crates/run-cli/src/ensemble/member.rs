//! One member of an ensemble: its directory (`DIR/seed-NNNN/`), the flags it gets, what it still
//! needs (nothing, a resume or a run), and its process, started, waited for and stopped.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// Subdirectory of member `seed`.
pub fn member_dir(out: &Path, seed: u64) -> PathBuf {
    out.join(format!("seed-{seed:04}"))
}

/// The log file of a member, in its directory.
pub const MEMBER_LOG: &str = "member.log";

/// Flags of the ensemble's command line that a member does not get (with a value).
pub(super) const DROPPED_WITH_VALUE: [&str; 5] =
    ["--seeds", "--jobs", "--out", "--seed", "--heartbeat"];
/// Flags without a value that a member does not get (members run with `-qq`).
pub(super) const DROPPED_BARE: [&str; 3] = ["--quiet", "--verbose", "--overwrite"];

/// The member's flags: the ensemble's, less the ensemble and logging flags.
pub(super) fn member_args(args: impl IntoIterator<Item = OsString>) -> Vec<OsString> {
    let mut out = Vec::new();
    let mut skip_value = false;
    for a in args {
        if skip_value {
            skip_value = false;
            continue;
        }
        let s = a.to_string_lossy();
        if DROPPED_WITH_VALUE.contains(&s.as_ref()) {
            skip_value = true;
            continue;
        }
        let dropped_with_equals = DROPPED_WITH_VALUE
            .iter()
            .any(|f| s.starts_with(&format!("{f}=")));
        let short_log =
            s.len() > 1 && s.starts_with('-') && s[1..].chars().all(|c| c == 'q' || c == 'v');
        if dropped_with_equals || short_log || DROPPED_BARE.contains(&s.as_ref()) {
            continue;
        }
        out.push(a);
    }
    out
}

/// What a member needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Todo {
    /// Nothing: it has a `run.json`.
    Finished,
    /// `--resume` from its `checkpoint.bin`.
    Resume,
    /// A fresh run.
    Run,
}

/// What the member in `dir` needs, from what its directory holds.
pub(super) fn todo(dir: &Path) -> Todo {
    if run_io::RunManifest::read(dir.join("run.json")).is_ok() {
        Todo::Finished
    } else if dir.join("checkpoint.bin").is_file() {
        Todo::Resume
    } else {
        Todo::Run
    }
}

/// How a member ended.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) enum Ended {
    Ok,
    Interrupted,
    Failed(String),
}

/// How to start a member: the binary, the flags every member gets, the ensemble's directory
/// and the environment a member is started with ([`MEMBER_OF`](crate::cli::MEMBER_OF), and
/// its MPI placement).
#[derive(Debug, Clone)]
pub(super) struct Member<'a> {
    pub(super) exe: &'a Path,
    pub(super) args: &'a [OsString],
    pub(super) out: &'a Path,
    pub(super) env: Vec<(&'static str, String)>,
}

/// How long a member waits for its directory to be let go by a run that still holds it (a
/// member of an earlier job that is writing its last checkpoint) before it is reported failed.
pub(super) const HELD_MEMBER_WAIT: Duration = Duration::from_secs(10);

/// Runs one member to its end, passing SIGTERM on once `stop` is set. A member directory that
/// a live process holds (its `run.lock`) is never shared: the member waits for it up to
/// [`HELD_MEMBER_WAIT`], then fails naming the holder. What the member needs (`todo`, as the
/// ensemble saw it when it started) is looked at again once the directory is free.
pub(super) fn run_member(m: &Member<'_>, seed: u64, todo: Todo, stop: &AtomicBool) -> Ended {
    let dir = member_dir(m.out, seed);
    if let Err(e) = std::fs::create_dir_all(&dir) {
        return Ended::Failed(format!("creating {}: {e}", dir.display()));
    }
    let waited_since = std::time::Instant::now();
    while let Some(holder) = crate::cli::held(&dir) {
        if stop.load(Ordering::Relaxed) {
            return Ended::Interrupted;
        }
        if waited_since.elapsed() > HELD_MEMBER_WAIT {
            let who = holder.map_or_else(|| "a run".to_string(), |h| h.to_string());
            return Ended::Failed(format!(
                "{} is in use by another run ({who}) after {} s; not started",
                dir.display(),
                HELD_MEMBER_WAIT.as_secs()
            ));
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let todo = match (todo, self::todo(&dir)) {
        (_, Todo::Finished) => return Ended::Ok,
        (_, now) => now,
    };
    let log_path = dir.join(MEMBER_LOG);
    let log = match std::fs::File::create(&log_path) {
        Ok(f) => f,
        Err(e) => return Ended::Failed(format!("creating {}: {e}", log_path.display())),
    };
    let mut cmd = Command::new(m.exe);
    cmd.args(m.args)
        .arg("--seed")
        .arg(seed.to_string())
        .arg("--out")
        .arg(&dir)
        .arg("-qq")
        .envs(m.env.iter().map(|(k, v)| (k, v)))
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(log);
    // A process group of its own: signals for the ensemble's group (Ctrl-C in a terminal, a
    // launcher killing a rank's group) reach the member only as the ensemble passes them on,
    // once, so it stops at a safe point.
    #[cfg(unix)]
    std::os::unix::process::CommandExt::process_group(&mut cmd, 0);
    match todo {
        Todo::Resume => cmd.arg("--resume").arg(&dir),
        // Partial outputs of a member killed before its first checkpoint (checked to be this
        // ensemble's by `foreign_members`) are replaced.
        _ => cmd.arg("--overwrite"),
    };
    let mut child = match cmd.spawn() {
        Ok(c) => c,
        Err(e) => return Ended::Failed(format!("starting {}: {e}", m.exe.display())),
    };
    let mut signalled = false;
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) => {}
            Err(e) => return Ended::Failed(format!("waiting for the member: {e}")),
        }
        if stop.load(Ordering::Relaxed) && !signalled {
            signalled = true;
            terminate(&child);
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    if status.success() {
        return Ended::Ok;
    }
    if status.code() == Some(i32::from(crate::cli::EXIT_INTERRUPTED)) || signalled {
        return Ended::Interrupted;
    }
    let last = last_line(&log_path);
    Ended::Failed(if last.is_empty() {
        format!("exited with {status}")
    } else {
        last
    })
}

/// The last non-empty line of a member's log (empty if none or unreadable).
pub(super) fn last_line(log: &Path) -> String {
    std::fs::read_to_string(log)
        .ok()
        .and_then(|s| {
            s.lines()
                .rev()
                .find(|l| !l.trim().is_empty())
                .map(str::to_owned)
        })
        .unwrap_or_default()
}

/// Sends SIGTERM to a member (it checkpoints and stops if it checkpoints at all).
#[cfg(unix)]
pub(super) fn terminate(child: &std::process::Child) {
    use nix::sys::signal::{Signal, kill};
    use nix::unistd::Pid;
    if let Ok(pid) = i32::try_from(child.id()) {
        let _ = kill(Pid::from_raw(pid), Signal::SIGTERM);
    }
}

#[cfg(not(unix))]
pub(super) fn terminate(_child: &std::process::Child) {}
