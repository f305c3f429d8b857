//! Command-line plumbing shared by the model binaries (feature `cli`): the "errors, not panics"
//! convention of `docs/architecture.md` for binaries (bad input is one line naming the value, exit
//! code 2, nothing written) and its logging convention (`-v`, `RUST_LOG`, quiet by default).

use std::path::Path;
use std::process::ExitCode;

/// The logging and progress flags every model binary takes (`#[command(flatten)]` them into
/// the binary's flags).
#[derive(Debug, Clone, Copy, Default, clap::Args)]
pub struct LogArgs {
    /// No progress bar or summary, warnings only.
    #[arg(long, short)]
    pub quiet: bool,

    /// More log output (-v info, -vv debug); RUST_LOG overrides.
    #[arg(short, action = clap::ArgAction::Count)]
    pub verbose: u8,
}

impl LogArgs {
    /// A progress bar of `len` steps on stderr with the indicatif `template`, or `None` under
    /// `--quiet` or when stderr is not a terminal (so redirected logs get no bar).
    pub fn progress_bar(&self, len: u64, template: &str) -> Option<indicatif::ProgressBar> {
        use std::io::IsTerminal;
        (!self.quiet && std::io::stderr().is_terminal()).then(|| {
            let bar = indicatif::ProgressBar::new(len);
            bar.set_style(
                indicatif::ProgressStyle::with_template(template)
                    .expect("the binaries' progress templates are valid"),
            );
            bar
        })
    }
}

/// The whole life of a model binary: parse the flags (help, version and parse errors handled
/// as in [`parse_or_exit`]), set up logging from the [`LogArgs`] that `logging` reads off them,
/// turn the flags into validated parameters (an `Err` is bad input: one line, exit code 2, nothing
/// written), then `run`; a run error prints its full chain on one line and exits with code 1.
pub fn main_with<C: clap::Parser, P, E: std::fmt::Display>(
    program: &str,
    logging: impl FnOnce(&C) -> LogArgs,
    params: impl FnOnce(&C) -> Result<P, String>,
    run: impl FnOnce(&C, P) -> Result<(), E>,
) -> ExitCode {
    let cli: C = match parse_or_exit(program) {
        Ok(cli) => cli,
        Err(code) => return code,
    };
    let log = logging(&cli);
    init_logging(log.quiet, log.verbose);
    let params = match params(&cli) {
        Ok(p) => p,
        Err(msg) => return usage_error(program, &msg),
    };
    match run(&cli, params) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{program}: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// Parse the command line into `C`. Help and version requests print and return
/// `Err(ExitCode::SUCCESS)`; any parse error prints clap's message folded onto one line,
/// prefixed by `program`, and returns `Err` with exit code 2.
pub fn parse_or_exit<C: clap::Parser>(program: &str) -> Result<C, ExitCode> {
    C::try_parse().map_err(|e| {
        use clap::error::ErrorKind;
        if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        // clap's message up to its blank line, folded onto one line.
        let text = e.to_string();
        let message: Vec<&str> = text
            .lines()
            .take_while(|l| !l.trim().is_empty())
            .map(str::trim)
            .collect();
        usage_error(program, message.join(" ").trim_start_matches("error: "))
    })
}

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

/// Print `program: error: msg` on one line and return exit code 2 (bad input).
pub fn usage_error(program: &str, msg: &str) -> ExitCode {
    eprintln!("{program}: error: {msg}");
    ExitCode::from(2)
}

/// Log to stderr with `tracing`: warnings only when `quiet` or without `-v`, info with `-v`,
/// debug with `-vv`; `RUST_LOG` overrides.
pub fn init_logging(quiet: bool, verbose: u8) {
    let default = match (quiet, verbose) {
        (true, _) | (false, 0) => "warn",
        (false, 1) => "info",
        _ => "debug",
    };
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(default));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        // Colour codes only on a terminal: a redirected log stays plain text.
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .try_init();
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
