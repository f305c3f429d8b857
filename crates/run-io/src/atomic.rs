//! Atomic file writes: a temporary file in the same directory, `fsync`, then `rename`.
//!
//! Readers see either the old file or the complete new one, never a partial write, and a run
//! that fails part-way leaves no half-written outputs (`docs/architecture.md`: every output file
//! is written atomically). If an [`AtomicFile`] is dropped without [`AtomicFile::commit`], its
//! temporary file is deleted.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use tempfile::NamedTempFile;

/// A file being written atomically. Write through [`std::io::Write`], then call
/// [`AtomicFile::commit`].
#[derive(Debug)]
pub struct AtomicFile {
    target: PathBuf,
    writer: BufWriter<NamedTempFile>,
}

impl AtomicFile {
    /// Start writing `path`. The temporary file is created in `path`'s directory (so the final
    /// rename never crosses file systems); that directory must exist.
    pub fn create(path: impl AsRef<Path>) -> io::Result<Self> {
        let target = path.as_ref().to_path_buf();
        let dir = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let name = target.file_name().ok_or_else(|| {
            io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("{} is not a file path", target.display()),
            )
        })?;
        let prefix = format!(".{}.", name.to_string_lossy());
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(".tmp");
        // An output file is an ordinary file: created 0666 less the process umask (0644 under
        // umask 022), as `File::create` would, not tempfile's private 0600.
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
        let tmp = builder.tempfile_in(&dir).map_err(|e| naming(&target, e))?;
        Ok(AtomicFile {
            target,
            writer: BufWriter::with_capacity(1 << 16, tmp),
        })
    }

    /// The final path.
    pub fn path(&self) -> &Path {
        &self.target
    }

    /// Flush, `fsync` the data, rename over the target, and `fsync` the directory so the rename
    /// itself is durable.
    pub fn commit(self) -> io::Result<()> {
        let target = self.target;
        let tmp = self
            .writer
            .into_inner()
            .map_err(|e| naming(&target, e.into_error()))?;
        tmp.as_file().sync_all().map_err(|e| naming(&target, e))?;
        tmp.persist(&target).map_err(|e| naming(&target, e.error))?;
        sync_parent_dir(&target);
        Ok(())
    }
}

/// `e` with the file it concerns in front (`out/run.json: No space left on device`), so a
/// failed write says which output it was.
fn naming(path: &Path, e: io::Error) -> io::Error {
    io::Error::new(e.kind(), format!("{}: {e}", path.display()))
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.writer.write(buf).map_err(|e| naming(&self.target, e))
    }
    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.writer
            .write_all(buf)
            .map_err(|e| naming(&self.target, e))
    }
    fn flush(&mut self) -> io::Result<()> {
        self.writer.flush().map_err(|e| naming(&self.target, e))
    }
}

/// Whether `name` is a temporary file of an [`AtomicFile`]: `.{target}.{6 random
/// characters}.tmp`.
fn is_atomic_temporary(name: &str) -> bool {
    let Some(stem) = name.strip_prefix('.').and_then(|n| n.strip_suffix(".tmp")) else {
        return false;
    };
    match stem.rsplit_once('.') {
        Some((target, random)) => {
            !target.is_empty()
                && random.len() == 6
                && random.bytes().all(|b| b.is_ascii_alphanumeric())
        }
        None => false,
    }
}

/// Delete the temporary files that [`AtomicFile`]s left in `dir` when their process was killed
/// mid-write (a dropped `AtomicFile` deletes its own), and return their paths. Only names of
/// the form `.{target}.{6 random characters}.tmp` are touched.
pub fn remove_stale_temporaries(dir: &Path) -> io::Result<Vec<PathBuf>> {
    let mut removed = Vec::new();
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let name = entry.file_name();
        if entry.file_type()?.is_file() && name.to_str().is_some_and(is_atomic_temporary) {
            std::fs::remove_file(entry.path())?;
            removed.push(entry.path());
        }
    }
    Ok(removed)
}

/// Best-effort `fsync` of the directory holding `path` (POSIX needs it for a durable rename;
/// other systems do not allow opening directories, so errors are ignored).
fn sync_parent_dir(path: &Path) {
    #[cfg(unix)]
    if let Some(dir) = path.parent() {
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        if let Ok(f) = File::open(dir) {
            let _ = f.sync_all();
        }
    }
    #[cfg(not(unix))]
    let _ = path;
}

/// Write `bytes` to `path` atomically.
pub fn write_atomic(path: impl AsRef<Path>, bytes: &[u8]) -> io::Result<()> {
    let mut f = AtomicFile::create(path)?;
    f.write_all(bytes)?;
    f.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn commit_replaces_and_leaves_no_temporaries() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.txt");
        write_atomic(&p, b"first").unwrap();
        write_atomic(&p, b"second").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"second");
        assert_eq!(entries(dir.path()), vec!["out.txt"]);
    }

    #[test]
    fn dropped_without_commit_writes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.txt");
        {
            let mut f = AtomicFile::create(&p).unwrap();
            f.write_all(b"partial").unwrap();
            // While writing, only a hidden temporary exists, never the target.
            assert!(!p.exists());
        }
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn stale_temporaries_are_removed_and_nothing_else() {
        let dir = tempfile::tempdir().unwrap();
        // A temporary left by a killed write, next to files that only look alike.
        let mut stale = AtomicFile::create(dir.path().join("checkpoint.bin")).unwrap();
        stale.write_all(b"partial").unwrap();
        let (_, kept) = stale.writer.into_inner().unwrap().keep().unwrap();
        let keep = [
            ".hidden.tmp",
            "run.json",
            ".x.abc.tmp",
            "a.b12345.tmp",
            ".y.ab-def.tmp",
        ];
        for name in keep {
            std::fs::write(dir.path().join(name), b"x").unwrap();
        }
        std::fs::create_dir(dir.path().join(".d.abcdef.tmp")).unwrap();
        let removed = remove_stale_temporaries(dir.path()).unwrap();
        assert_eq!(removed, vec![kept]);
        let mut expected: Vec<String> = keep.iter().map(|s| s.to_string()).collect();
        expected.push(".d.abcdef.tmp".into());
        expected.sort();
        assert_eq!(entries(dir.path()), expected);
    }

    /// The process umask, from `/proc/self/status` (Linux 4.7 and later).
    #[cfg(target_os = "linux")]
    fn umask() -> Option<u32> {
        let status = std::fs::read_to_string("/proc/self/status").ok()?;
        let line = status.lines().find(|l| l.starts_with("Umask:"))?;
        u32::from_str_radix(line["Umask:".len()..].trim(), 8).ok()
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn files_get_the_ordinary_mode_under_the_umask() {
        use std::os::unix::fs::PermissionsExt;
        let Some(mask) = umask() else { return };
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.txt");
        write_atomic(&p, b"x").unwrap();
        let mode = std::fs::metadata(&p).unwrap().permissions().mode() & 0o777;
        // 0644 under the usual umask 022, where tempfile alone would give 0600.
        assert_eq!(mode, 0o666 & !mask, "mode {mode:o} under umask {mask:03o}");
    }

    #[test]
    fn missing_directory_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        assert!(write_atomic(dir.path().join("no/such/dir/f"), b"x").is_err());
    }
}
