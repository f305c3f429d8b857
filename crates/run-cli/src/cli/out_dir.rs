//! The `--out DIR` of every binary: checked before any work ([`check_out_dir`]) and created,
//! with the leftovers of an interrupted earlier run removed, only once the run is known to be
//! good ([`claim_out_dir`], or [`prepare_out_dir`] without ownership).
//!
//! A run owns its directory ([`claim_out_dir`]): it holds an exclusive OS lock (`flock`) on
//! `DIR/run.lock`, which records its process id, host and start time, for as long as it runs;
//! the OS releases the lock when the process ends however it ends, so a lock file left by a
//! killed run is recognised as stale and taken over. A directory that another run holds, or
//! that already holds a run (finished or interrupted), is refused unless the run continues it
//! (`--resume DIR --out DIR`) or replaces it (`--overwrite`).

use std::path::{Path, PathBuf};

/// Check, before any work and without creating anything, that `--out DIR` can be written:
/// `DIR` is a directory or does not exist yet, and the nearest existing directory on its path
/// accepts a new file. The message names the flag and the path.
pub fn check_out_dir(out: &Path) -> Result<(), String> {
    let shown = out.display();
    if out.exists() && !out.is_dir() {
        return Err(format!("--out {shown}: exists and is not a directory"));
    }
    let mut existing = out;
    while !existing.exists() {
        existing = match existing.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            // A relative path whose every component is missing: the working directory, unless
            // that is gone too.
            _ if existing != Path::new(".") => Path::new("."),
            _ => {
                return Err(format!(
                    "--out {shown}: the working directory does not exist"
                ));
            }
        };
    }
    if !existing.is_dir() {
        return Err(format!(
            "--out {shown}: {} is not a directory",
            existing.display()
        ));
    }
    // An anonymous temporary file: proves a file can be created there and leaves nothing.
    tempfile::tempfile_in(existing)
        .map(drop)
        .map_err(|e| format!("--out {shown}: cannot write in {}: {e}", existing.display()))?;
    // Another run holding it is named now, before a checkpoint it is writing is read.
    match held(out) {
        Some(holder) => Err(in_use(out, holder)),
        None => Ok(()),
    }
}

/// Whether a live run holds `dir/run.lock` (`Some(its details, if written)`), found without
/// creating or changing anything.
#[cfg(unix)]
pub(crate) fn held(dir: &Path) -> Option<Option<LockHolder>> {
    use nix::fcntl::{Flock, FlockArg};
    let path = dir.join(LOCK_FILE);
    let file = std::fs::File::open(&path).ok()?;
    match Flock::lock(file, FlockArg::LockSharedNonblock) {
        Ok(_) => None,
        Err((_, nix::errno::Errno::EWOULDBLOCK)) => Some(LockHolder::read(&path)),
        Err(_) => None,
    }
}

#[cfg(not(unix))]
pub(crate) fn held(_dir: &Path) -> Option<Option<LockHolder>> {
    None
}

/// The refusal of a directory another run holds.
fn in_use(out: &Path, holder: Option<LockHolder>) -> String {
    let who = holder.map_or_else(|| "a run that is starting".to_string(), |h| h.to_string());
    format!(
        "--out {} is in use by another run ({who}; lock {}); wait for it to end or use another --out",
        out.display(),
        out.join(LOCK_FILE).display()
    )
}

/// Create `--out DIR` (checked by [`check_out_dir`]) and delete the temporary files an
/// interrupted write of an earlier run left in it.
pub fn prepare_out_dir(out: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(out)?;
    for path in run_io::remove_stale_temporaries(out)? {
        tracing::info!("removed {}, left by an interrupted write", path.display());
    }
    Ok(())
}

/// The lock file of a run in its output directory.
pub const LOCK_FILE: &str = "run.lock";

/// Files every model's run writes: its manifest, its checkpoint and its flags (`config.toml`,
/// written first: a run killed before any output leaves it).
const COMMON_RUN_FILES: [&str; 3] = ["run.json", "checkpoint.bin", "config.toml"];

/// Files and directories of an ensemble (`--seeds`) in its directory.
pub const ENSEMBLE_FILES: [&str; 4] = ["ensemble.json", "ensemble.md", "ensemble_*", "seed-*"];

/// Whether `name` matches `pattern`, which is a file name with at most one `*` (any text).
fn matches(pattern: &str, name: &str) -> bool {
    match pattern.split_once('*') {
        None => pattern == name,
        Some((pre, post)) => {
            name.len() >= pre.len() + post.len() && name.starts_with(pre) && name.ends_with(post)
        }
    }
}

/// How a run wants to use its `--out` directory, for [`claim_out_dir`].
#[derive(Debug, Clone, Copy)]
pub struct Claim<'a> {
    /// The directory (`--out`).
    pub out: &'a Path,
    /// The output files of the model besides `run.json`, `checkpoint.bin` and `config.toml`, as names with at
    /// most one `*` (`growth.csv`, `positions.*`, `snapshot_*.png`): what counts as an earlier
    /// run's results and what `--overwrite` deletes.
    pub run_files: &'a [&'a str],
    /// `--resume DIR`: a run continued in its own directory (`DIR` = `--out`) keeps it.
    pub resume: Option<&'a Path>,
    /// `--overwrite`: the earlier run's files are deleted.
    pub overwrite: bool,
    /// The run is an ensemble (`--seeds`): an earlier ensemble in the directory is continued
    /// (its members are checked by the ensemble), a single run is refused.
    pub ensemble: bool,
}

impl<'a> Claim<'a> {
    /// The claim of a single run (not an ensemble) on `out`.
    pub fn single(
        out: &'a Path,
        run_files: &'a [&'a str],
        resume: Option<&'a Path>,
        overwrite: bool,
    ) -> Self {
        Claim {
            out,
            run_files,
            resume,
            overwrite,
            ensemble: false,
        }
    }
}

/// What an earlier run left in a directory.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct EarlierRun {
    /// Its result files and directories, by name, sorted.
    pub files: Vec<String>,
    /// It finished: `run.json` is there.
    pub finished: bool,
    /// It left a checkpoint (`checkpoint.bin`) to continue from.
    pub checkpoint: bool,
    /// Its files are an ensemble's (`ensemble.json`, `seed-*/`), not a single run's.
    pub ensemble: bool,
}

impl EarlierRun {
    /// What the directory `dir` holds of a run whose files are `run_files` (and of an
    /// ensemble), or `None` when it holds none (missing, empty or only unrelated files).
    pub fn find(dir: &Path, run_files: &[&str]) -> std::io::Result<Option<EarlierRun>> {
        let entries = match std::fs::read_dir(dir) {
            Ok(e) => e,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(e),
        };
        let mut found = EarlierRun::default();
        let mut single = false;
        for entry in entries {
            let entry = entry?;
            let Some(name) = entry.file_name().to_str().map(str::to_owned) else {
                continue;
            };
            let is_dir = entry.file_type()?.is_dir();
            let of_run = !is_dir
                && COMMON_RUN_FILES
                    .iter()
                    .chain(run_files)
                    .any(|p| matches(p, &name));
            // `seed-*` counts as an ensemble's member only as a directory.
            let of_ensemble = ENSEMBLE_FILES
                .iter()
                .any(|p| matches(p, &name) && (is_dir == p.starts_with("seed-")));
            if of_run || of_ensemble {
                single |= of_run;
                found.ensemble |= of_ensemble;
                found.finished |= name == "run.json";
                found.checkpoint |= name == "checkpoint.bin";
                found
                    .files
                    .push(if is_dir { format!("{name}/") } else { name });
            }
        }
        found.ensemble &= !single;
        found.files.sort();
        Ok((!found.files.is_empty()).then_some(found))
    }

    /// What it is, for a message: `a finished run (run.json, growth.csv)`.
    pub fn describe(&self) -> String {
        let what = match (self.ensemble, self.finished, self.checkpoint) {
            (true, _, _) => "an ensemble",
            (false, true, _) => "a finished run",
            (false, false, true) => "an interrupted run with a checkpoint",
            (false, false, false) => "the partial outputs of an interrupted run",
        };
        const SHOWN: usize = 6;
        let mut files = self.files[..self.files.len().min(SHOWN)].join(", ");
        if self.files.len() > SHOWN {
            files.push_str(&format!(" and {} more", self.files.len() - SHOWN));
        }
        format!("{what} ({files})")
    }

    /// Deletes these files and directories from `dir`, and logs each.
    fn remove(&self, dir: &Path) -> std::io::Result<()> {
        for name in &self.files {
            let path = dir.join(name.trim_end_matches('/'));
            let gone = if name.ends_with('/') {
                std::fs::remove_dir_all(&path)
            } else {
                std::fs::remove_file(&path)
            };
            match gone {
                Ok(()) => tracing::info!("--overwrite: removed {}", path.display()),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(e) => return Err(e),
            }
        }
        Ok(())
    }
}

/// Who holds (or held) a lock: the content of `run.lock`.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct LockHolder {
    /// Process id.
    pub pid: u32,
    /// Host name.
    pub host: String,
    /// Start of the run, UTC (`2026-01-02T03:04:05Z`).
    pub since: String,
}

impl LockHolder {
    fn this_process() -> Self {
        LockHolder {
            pid: std::process::id(),
            host: run_io::provenance::host_name(),
            since: run_io::provenance::utc_iso8601(std::time::SystemTime::now()),
        }
    }

    fn read(path: &Path) -> Option<Self> {
        serde_json::from_slice(&std::fs::read(path).ok()?).ok()
    }
}

impl std::fmt::Display for LockHolder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "pid {} on host {} since {}",
            self.pid, self.host, self.since
        )
    }
}

/// The lock a run holds on its output directory (see [`claim_out_dir`]). Dropping it deletes
/// `run.lock` and releases the lock; a process that ends without dropping it (killed) leaves
/// the file, and the OS releases the lock.
#[derive(Debug)]
pub struct OutDirLock {
    path: PathBuf,
    keep: bool,
    #[cfg(unix)]
    _lock: nix::fcntl::Flock<std::fs::File>,
}

impl Drop for OutDirLock {
    fn drop(&mut self) {
        // Deleted while still locked, so no other run can lock this file and then lose it.
        if !self.keep {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Why a directory could not be locked.
enum Locking {
    /// Another live process holds it (`None`: it has not written its details yet).
    Held(Option<LockHolder>),
    Io(std::io::Error),
}

/// Locks `dir/run.lock` without waiting; returns the lock and the holder a stale lock file
/// names (a process that ended without releasing it), and whether the file was created here.
#[cfg(unix)]
fn lock(dir: &Path) -> Result<(OutDirLock, Option<LockHolder>, bool), Locking> {
    use nix::fcntl::{Flock, FlockArg};
    use std::os::unix::fs::MetadataExt;
    let path = dir.join(LOCK_FILE);
    // A run that ends deletes the file it locked: locking a file that is no longer at `path`
    // proves nothing, so try again with the new one.
    for _ in 0..100 {
        let existed = path.exists();
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(Locking::Io)?;
        // A few quick retries: another process's `check_out_dir` holds a shared lock for an
        // instant, which is not a run.
        let mut file = file;
        let mut tries = 0;
        let file = loop {
            match Flock::lock(file, FlockArg::LockExclusiveNonblock) {
                Ok(f) => break f,
                Err((f, nix::errno::Errno::EWOULDBLOCK)) if tries < 5 => {
                    tries += 1;
                    file = f;
                    std::thread::sleep(std::time::Duration::from_millis(5));
                }
                Err((_, nix::errno::Errno::EWOULDBLOCK)) => {
                    return Err(Locking::Held(LockHolder::read(&path)));
                }
                Err((_, e)) => return Err(Locking::Io(e.into())),
            }
        };
        let same = match (file.metadata(), std::fs::metadata(&path)) {
            (Ok(a), Ok(b)) => a.ino() == b.ino() && a.dev() == b.dev(),
            _ => false,
        };
        if same {
            let stale = existed.then(|| LockHolder::read(&path)).flatten();
            return Ok((
                OutDirLock {
                    path,
                    keep: false,
                    _lock: file,
                },
                stale,
                !existed,
            ));
        }
    }
    Err(Locking::Io(std::io::Error::other(format!(
        "{} keeps changing",
        path.display()
    ))))
}

/// Without `flock`, the lock file only records the holder.
#[cfg(not(unix))]
fn lock(dir: &Path) -> Result<(OutDirLock, Option<LockHolder>, bool), Locking> {
    let path = dir.join(LOCK_FILE);
    let existed = path.exists();
    let stale = existed.then(|| LockHolder::read(&path)).flatten();
    Ok((OutDirLock { path, keep: false }, stale, !existed))
}

/// Whether `a` and `b` name the same directory.
fn same_dir(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    }
}

/// Why [`claim_out_dir`] failed.
#[derive(Debug, thiserror::Error)]
pub enum ClaimError {
    /// The directory is another run's, or holds an earlier run: a usage error (exit code 2),
    /// one line naming what is there and the ways on.
    #[error("{0}")]
    Refused(String),
    /// The directory or its lock file could not be created or written.
    #[error("{0}")]
    Io(String),
}

/// Takes `--out` for this run: creates the directory, locks it (`run.lock` with this process's
/// id, host and start time), refuses it if another live run holds it or it holds an earlier
/// run that this one neither continues (`--resume` of the same directory) nor replaces
/// (`--overwrite`, which deletes that run's files first), and deletes the
/// temporary files an interrupted write left. A stale lock file (of a killed run) is taken
/// over, with a warning naming it. On refusal nothing is created or changed. Keep the returned
/// lock until the run ends.
pub fn claim_out_dir(c: &Claim<'_>) -> Result<OutDirLock, ClaimError> {
    let shown = c.out.display();
    let io = |what: &str, e: std::io::Error| ClaimError::Io(format!("{what} {shown}: {e}"));
    // The topmost directory this call creates, removed again if the claim is refused.
    let created = {
        let mut top = None;
        let mut p = c.out;
        while !p.as_os_str().is_empty() && !p.exists() {
            top = Some(p.to_path_buf());
            p = p.parent().unwrap_or(Path::new(""));
        }
        top
    };
    std::fs::create_dir_all(c.out).map_err(|e| io("creating output directory", e))?;
    let undo = |lock: Option<OutDirLock>, new_file: bool| {
        if let Some(mut l) = lock {
            // A stale lock file found here is left as it was.
            l.keep = !new_file;
        }
        // Only empty directories: another run may have created the same ones meanwhile.
        if let Some(top) = &created {
            for dir in c.out.ancestors() {
                if std::fs::remove_dir(dir).is_err() || dir == top {
                    break;
                }
            }
        }
    };
    let (lock, stale, new_file) = match lock(c.out) {
        Ok(l) => l,
        Err(Locking::Held(holder)) => return Err(ClaimError::Refused(in_use(c.out, holder))),
        Err(Locking::Io(e)) => {
            undo(None, false);
            return Err(io("locking", e));
        }
    };
    let continued = c.resume.is_some_and(|r| same_dir(r, c.out));
    let earlier = match EarlierRun::find(c.out, c.run_files) {
        Ok(e) => e,
        Err(e) => {
            undo(Some(lock), new_file);
            return Err(io("reading", e));
        }
    };
    if let Some(earlier) = earlier.filter(|e| !(continued || c.ensemble && e.ensemble)) {
        if !c.overwrite {
            undo(Some(lock), new_file);
            let resume = if earlier.checkpoint && !c.ensemble {
                format!("continue it with --resume {shown}, ")
            } else {
                String::new()
            };
            return Err(ClaimError::Refused(format!(
                "--out {shown} holds {}; {resume}use another --out, or add --overwrite to delete it and start over",
                earlier.describe()
            )));
        }
        if let Err(e) = earlier.remove(c.out) {
            return Err(io("--overwrite: deleting the earlier run in", e));
        }
    }
    if c.overwrite && c.ensemble {
        // The ensemble starts over: its members and combined results go too.
        if let Ok(Some(earlier)) = EarlierRun::find(c.out, c.run_files) {
            earlier
                .remove(c.out)
                .map_err(|e| io("--overwrite: deleting the earlier ensemble in", e))?;
        }
    }
    if let Some(h) = stale {
        tracing::warn!(
            "taking over the stale lock {} of a run that ended without releasing it ({h})",
            lock.path.display()
        );
    }
    let me = serde_json::to_vec(&LockHolder::this_process()).unwrap_or_default();
    std::fs::write(&lock.path, me).map_err(|e| io("writing the lock file in", e))?;
    for path in run_io::remove_stale_temporaries(c.out).map_err(|e| io("cleaning", e))? {
        tracing::info!("removed {}, left by an interrupted write", path.display());
    }
    Ok(lock)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_dir_checks_name_the_flag_and_create_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("f");
        std::fs::write(&file, b"x").unwrap();
        let e = check_out_dir(&file).unwrap_err();
        assert!(
            e.starts_with("--out ") && e.contains("not a directory"),
            "{e}"
        );
        let e = check_out_dir(&file.join("a/b")).unwrap_err();
        assert!(
            e.starts_with("--out ") && e.contains("is not a directory"),
            "{e}"
        );
        // A new nested directory is accepted without being created; an existing one too.
        assert_eq!(check_out_dir(&dir.path().join("new/nested")), Ok(()));
        assert_eq!(check_out_dir(dir.path()), Ok(()));
        let mut names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        names.sort();
        assert_eq!(names, vec![std::ffi::OsString::from("f")]);
    }

    fn claim(out: &Path, overwrite: bool) -> Result<OutDirLock, ClaimError> {
        claim_out_dir(&Claim {
            out,
            run_files: &["growth.csv", "positions.*"],
            resume: None,
            overwrite,
            ensemble: false,
        })
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut n: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        n.sort();
        n
    }

    #[test]
    fn earlier_runs_are_found_by_their_files() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let find = |d: &Path| EarlierRun::find(d, &["growth.csv", "positions.*"]).unwrap();
        assert_eq!(find(&d.join("missing")), None);
        std::fs::write(d.join("notes.txt"), b"x").unwrap();
        std::fs::write(d.join("seed-0001"), b"a file, not a member").unwrap();
        assert_eq!(find(d), None, "unrelated files");
        std::fs::write(d.join("positions.npy"), b"x").unwrap();
        let e = find(d).unwrap();
        assert!(!e.finished && !e.checkpoint && !e.ensemble, "{e:?}");
        assert_eq!(e.files, ["positions.npy"]);
        std::fs::write(d.join("checkpoint.bin"), b"x").unwrap();
        assert!(
            find(d)
                .unwrap()
                .describe()
                .starts_with("an interrupted run with a checkpoint")
        );
        std::fs::write(d.join("run.json"), b"{}").unwrap();
        assert!(find(d).unwrap().describe().starts_with("a finished run ("));
        let ens = d.join("ens");
        std::fs::create_dir_all(ens.join("seed-0002")).unwrap();
        let e = find(&ens).unwrap();
        assert!(e.ensemble && e.files == ["seed-0002/"], "{e:?}");
    }

    #[test]
    fn a_held_directory_is_refused_naming_the_holder_and_released_on_drop() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("a/b");
        let first = claim(&out, false).unwrap();
        let holder = LockHolder::read(&out.join(LOCK_FILE)).unwrap();
        assert_eq!(holder.pid, std::process::id());
        // flock locks belong to an open file: a second open in this process conflicts too.
        match claim(&out, false) {
            Err(ClaimError::Refused(m)) => {
                assert!(
                    m.contains("in use by another run") && m.contains(&holder.to_string()),
                    "{m}"
                )
            }
            other => panic!("{other:?}"),
        }
        drop(first);
        assert!(names(&out).is_empty(), "the lock file stays after the run");
        drop(claim(&out, false).unwrap());
    }

    #[test]
    fn an_earlier_run_is_refused_unchanged_or_overwritten_and_a_stale_lock_taken_over() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        std::fs::create_dir(&out).unwrap();
        let stale = r#"{"pid":4000000,"host":"gone","since":"2020-01-01T00:00:00Z"}"#;
        for (name, text) in [
            ("run.json", "{}"),
            ("growth.csv", "n\n"),
            ("config.toml", ""),
            ("notes.txt", "mine"),
            (LOCK_FILE, stale),
        ] {
            std::fs::write(out.join(name), text).unwrap();
        }
        match claim(&out, false) {
            Err(ClaimError::Refused(m)) => assert!(
                m.contains("a finished run (config.toml, growth.csv, run.json)")
                    && m.contains("--overwrite")
                    && !m.contains("--resume"),
                "{m}"
            ),
            other => panic!("{other:?}"),
        }
        assert_eq!(
            std::fs::read_to_string(out.join(LOCK_FILE)).unwrap(),
            stale,
            "a refusal changed the stale lock"
        );
        let lock = claim(&out, true).unwrap();
        assert_eq!(names(&out), ["notes.txt", LOCK_FILE]);
        assert_eq!(
            LockHolder::read(&out.join(LOCK_FILE)).unwrap().pid,
            std::process::id()
        );
        drop(lock);
        // A new directory is created, and one refused is removed again.
        let fresh = dir.path().join("x/y");
        drop(claim(&fresh, false).unwrap());
        assert!(fresh.is_dir());
    }

    #[test]
    fn prepare_creates_the_directory_and_clears_stale_temporaries() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        prepare_out_dir(&out).unwrap();
        std::fs::write(out.join(".run.json.q1w2e3.tmp"), b"partial").unwrap();
        std::fs::write(out.join("run.json"), b"{}").unwrap();
        prepare_out_dir(&out).unwrap();
        let names: Vec<_> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("run.json")]);
    }
}
