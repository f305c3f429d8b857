//! The `--out DIR` of every binary: checked before any work ([`check_out_dir`]) and created,
//! with the leftovers of an interrupted earlier run removed, only once the run is known to be
//! good ([`prepare_out_dir`]).

use std::path::Path;

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
        .map_err(|e| format!("--out {shown}: cannot write in {}: {e}", existing.display()))
}

/// Create `--out DIR` (checked by [`check_out_dir`]) and delete the temporary files an
/// interrupted write of an earlier run left in it.
pub fn prepare_out_dir(out: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(out)?;
    for path in crate::io::remove_stale_temporaries(out)? {
        tracing::info!("removed {}, left by an interrupted write", path.display());
    }
    Ok(())
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
