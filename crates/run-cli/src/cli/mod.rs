//! Command-line plumbing shared by the model binaries (feature `cli`), so that every binary
//! keeps one contract:
//!
//! - **Usage errors** (a flag, a config file, a checkpoint to resume, an output location that
//!   cannot be written) are found before the first step of work, print one line
//!   `PROGRAM: error: ...` naming the flag or file and what is accepted, exit with code 2 and
//!   leave nothing behind. A binary reports them by returning `Err` from its `params` step or a
//!   [`UsageError`] (see [`usage`]) from its `run` step before it creates `--out`.
//! - **Runtime failures** (a full disk mid-run, a livelock guard) print one line
//!   `PROGRAM: run failed: ...` and exit with code 1.
//! - **Interrupted runs** (SIGINT, SIGTERM, SIGUSR1 or SIGXCPU: [`guard_signals`]) write a
//!   checkpoint, print one line saying how to continue, and exit with code 130; a run whose
//!   memory is about to run out does the same with exit code 1 ([`checkpoints`]).
//! - **Logging**: warnings only by default, `-v` info, `-vv` debug, `RUST_LOG` overrides; a
//!   progress bar on a terminal, and a one-line heartbeat every `--heartbeat` seconds when
//!   there is no bar (a redirected log, or `--quiet`), so a long run is told from a hang;
//!   `-qq` silences it ([`LogArgs`], [`Progress`]).

pub mod checkpoints;
pub mod config;
mod figure_flags;
mod out_dir;
pub mod params;
mod progress;
mod resume;

pub use checkpoints::{CheckpointArgs, guard_signals, stopped};
pub use config::ConfigArgs;
pub use figure_flags::{FigureArgs, FigureHelp};
pub(crate) use out_dir::held;
pub use out_dir::{
    Claim, ClaimError, ENSEMBLE_FILES, EarlierRun, LOCK_FILE, LockHolder, OutDirLock,
    check_out_dir, claim_out_dir, prepare_out_dir,
};
pub use params::{Annotated, FlagStyle, ParamFlags, Plain};
pub use progress::Progress;
pub use resume::{flag_differences, labelled_differences};
pub use run_io::count::{count, count_at_least_1, seed};

use std::process::ExitCode;

/// Exit code of a usage error (bad flags, config, checkpoint or output location).
pub const EXIT_USAGE: u8 = 2;
/// Exit code of a run that failed after it started (I/O error, livelock guard).
pub const EXIT_RUN_FAILED: u8 = 1;
/// Exit code of a run stopped by SIGINT or SIGTERM after saving what it could (128 + SIGINT,
/// as shells report an interrupted command).
pub const EXIT_INTERRUPTED: u8 = 130;

/// The logging and progress flags every model binary takes (`#[command(flatten)]` them into
/// the binary's flags).
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct LogArgs {
    /// No progress bar or summary, warnings only (the heartbeat stays); -qq also silences the
    /// heartbeat.
    #[arg(long, short, action = clap::ArgAction::Count)]
    pub quiet: u8,

    /// More log output (-v info, -vv debug); RUST_LOG overrides.
    #[arg(short, action = clap::ArgAction::Count)]
    pub verbose: u8,

    /// Without a progress bar (stderr is not a terminal, or --quiet), print a one-line
    /// progress report on stderr every this many seconds; 0 never.
    #[arg(long, value_name = "SECONDS", default_value_t = 60.0, value_parser = parse_heartbeat)]
    pub heartbeat: f64,

    /// Colour in log messages: `auto` only when stderr is a terminal, so a redirected log stays
    /// plain text.
    #[arg(long, value_name = "WHEN", value_enum, default_value_t = Color::Auto)]
    pub color: Color,
}

/// When log messages are coloured (`--color`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Color {
    /// Only when stderr is a terminal.
    Auto,
    /// Always (ANSI escape codes even in a file).
    Always,
    /// Never.
    Never,
}

impl Color {
    /// Whether to write ANSI colour codes to stderr.
    pub fn enabled(self) -> bool {
        match self {
            Color::Auto => std::io::IsTerminal::is_terminal(&std::io::stderr()),
            Color::Always => true,
            Color::Never => false,
        }
    }
}

impl Default for LogArgs {
    fn default() -> Self {
        LogArgs {
            quiet: 0,
            verbose: 0,
            heartbeat: 60.0,
            color: Color::Auto,
        }
    }
}

fn parse_heartbeat(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!(
            "'{s}' is not a number of seconds >= 0 (0 turns the heartbeat off)"
        )),
    }
}

impl LogArgs {
    /// `--quiet` given (at least once): no progress bar and no summary line.
    pub fn is_quiet(&self) -> bool {
        self.quiet > 0
    }

    /// Progress of a run of `len` `unit`s: a bar with the indicatif `template` on a terminal
    /// (unless `--quiet`), else a heartbeat line every `--heartbeat` seconds (unless `-qq` or
    /// `--heartbeat 0`), else nothing.
    pub fn progress(&self, program: &str, len: u64, unit: &str, template: &str) -> Progress {
        use std::io::IsTerminal;
        if self.quiet == 0 && std::io::stderr().is_terminal() {
            Progress::bar(len, template)
        } else if self.quiet < 2 && self.heartbeat > 0.0 {
            Progress::heartbeat(program, len, unit, self.heartbeat)
        } else {
            Progress::silent()
        }
    }
}

/// The flag `--overwrite`, flattened into every model binary's flags.
#[derive(Debug, Clone, Copy, Default, clap::Args)]
pub struct OverwriteArgs {
    /// Replace the run already in --out instead of refusing the directory: deletes its run.json,
    /// checkpoint.bin, config.toml and output files (with --seeds: the ensemble's members
    /// seed-NNNN/ and its ensemble.* files), keeping any other file. Not with --resume.
    #[arg(long, conflicts_with = "resume")]
    pub overwrite: bool,
}

/// [`claim_out_dir`] for a binary's `run` step: a refusal is a [`UsageError`] (exit code 2),
/// anything else a failed run.
pub fn own_out_dir(claim: &Claim<'_>) -> anyhow::Result<OutDirLock> {
    claim_out_dir(claim).map_err(|e| match e {
        ClaimError::Refused(m) => usage(m),
        ClaimError::Io(m) => anyhow::anyhow!(m),
    })
}

/// A usage error found by a binary's `run` step before it has created anything (a checkpoint
/// that does not fit the flags, say): [`main_with`] prints it as one line and exits with code
/// 2. Build one with [`usage`].
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

/// A run stopped early by SIGINT or SIGTERM (see [`stop_on_signals`]) after saving what it
/// could: [`main_with`] prints the message (what was saved, how to continue) as one line and
/// exits with code 130.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct Interrupted(pub String);

/// Environment variable an ensemble sets for each member: the ensemble's process id. The
/// member ties its life to that process (`run_cli::ensemble::tie_member_to_ensemble`).
pub const MEMBER_OF: &str = "AGGSIM_MEMBER_OF";

/// Whether this process runs as a member of an ensemble ([`MEMBER_OF`] set).
pub fn is_member() -> bool {
    std::env::var_os(MEMBER_OF).is_some()
}

/// A flag that SIGINT, SIGTERM and SIGXCPU set instead of killing the process, for a run that polls it
/// to checkpoint and stop cleanly. A second signal of the same kind ends the process at once,
/// as usual, so a run that does not stop can still be interrupted; except in an ensemble's
/// member, which may get the same signal twice (from a batch system that signals every process
/// of a job, and from its ensemble passing it on) and is killed with its ensemble anyway
/// ([`tie_member_to_ensemble`](crate::ensemble::tie_member_to_ensemble)).
///
/// # Errors
/// The handlers could not be installed.
pub fn stop_on_signals() -> std::io::Result<std::sync::Arc<std::sync::atomic::AtomicBool>> {
    use signal_hook::consts::{SIGINT, SIGTERM, SIGXCPU};
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let member = is_member();
    for sig in [SIGINT, SIGTERM, SIGXCPU] {
        // Registered first, so it runs when the flag is already set: the second signal.
        if !member {
            signal_hook::flag::register_conditional_default(sig, std::sync::Arc::clone(&stop))?;
        }
        signal_hook::flag::register(sig, std::sync::Arc::clone(&stop))?;
    }
    Ok(stop)
}

/// Prints `line` and a line break on standard error in one `write`, so that a process stopped
/// while it prints (a member killed with its MPI rank) never leaves half a line in its log:
/// `eprintln!` writes each piece of its format separately.
pub fn say(line: &str) {
    use std::io::Write;
    let mut text = String::with_capacity(line.len() + 1);
    text.push_str(line);
    text.push('\n');
    let _ = std::io::stderr().lock().write_all(text.as_bytes());
}

/// The text of `PROG --version` (after the program's name): the version, the optional
/// features built in (`mpi`, or `none`, with how to get it) and the git commit, so that two
/// binaries of the same name (an MPI build and a plain one) are told apart.
pub fn version() -> &'static str {
    static TEXT: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    TEXT.get_or_init(|| {
        let features = if cfg!(feature = "mpi") {
            "mpi"
        } else {
            "none, so no ensembles over MPI ranks"
        };
        let commit = run_io::provenance::GIT_COMMIT.map_or("unknown", |c| &c[..c.len().min(12)]);
        format!(
            "{} (features: {features}; commit {commit})",
            env!("CARGO_PKG_VERSION")
        )
    })
}

/// A [`UsageError`] as an `anyhow::Error`, for `run` steps that return `anyhow::Result`.
pub fn usage(message: impl Into<String>) -> anyhow::Error {
    UsageError(message.into()).into()
}

/// The first step of a model binary: `Some(exit code 1)`, after one line on standard error, when
/// the processor lacks an instruction-set feature the build was compiled to use
/// ([`cpu`](core_lattice::cpu)), rather than an illegal instruction later in the run.
pub fn refuse_unsupported_cpu(program: &str) -> Option<ExitCode> {
    let why = core_lattice::cpu::unsupported()?;
    say(&format!("{program}: {why}"));
    Some(ExitCode::from(EXIT_RUN_FAILED))
}

/// The whole life of a model binary: parse the flags (help, version and parse errors handled
/// as in [`parse_or_exit`]), set up logging from the [`LogArgs`] that `logging` reads off them,
/// turn the flags into validated parameters (an `Err` is a usage error), then `run`. A
/// [`UsageError`] from `run` is a usage error too (exit code 2); any other error is a failed
/// run (exit code 1). Either prints one line.
pub fn main_with<C: clap::Parser, P>(
    program: &str,
    logging: impl FnOnce(&C) -> LogArgs,
    params: impl FnOnce(&C) -> Result<P, String>,
    run: impl FnOnce(&C, P) -> anyhow::Result<()>,
) -> ExitCode {
    main_parsed(program, parse_or_exit(program), logging, params, run)
}

/// [`main_with`] for a binary whose flags include [`ConfigArgs`]: `--config FILE` stands for
/// the flags in the file and `--dump-config` prints the effective ones ([`config`]).
pub fn main_with_config<C: clap::Parser, P>(
    program: &str,
    logging: impl FnOnce(&C) -> LogArgs,
    params: impl FnOnce(&C) -> Result<P, String>,
    run: impl FnOnce(&C, P) -> anyhow::Result<()>,
) -> ExitCode {
    main_parsed(
        program,
        config::parse_with_config(program),
        logging,
        params,
        run,
    )
}

fn main_parsed<C, P>(
    program: &str,
    parsed: Result<C, ExitCode>,
    logging: impl FnOnce(&C) -> LogArgs,
    params: impl FnOnce(&C) -> Result<P, String>,
    run: impl FnOnce(&C, P) -> anyhow::Result<()>,
) -> ExitCode {
    let cli: C = match parsed {
        Ok(cli) => cli,
        Err(code) => return code,
    };
    let log = logging(&cli);
    init_logging(log.quiet > 0, log.verbose, log.color);
    let params = match params(&cli) {
        Ok(p) => p,
        Err(msg) => return usage_error(program, &msg),
    };
    match run(&cli, params) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => match e.downcast_ref::<UsageError>() {
            Some(u) => usage_error(program, &u.0),
            None if e.downcast_ref::<Interrupted>().is_some() => {
                say(&format!("{program}: {e}"));
                ExitCode::from(EXIT_INTERRUPTED)
            }
            None => {
                say(&format!("{program}: run failed: {}", error_line(&e)));
                ExitCode::from(EXIT_RUN_FAILED)
            }
        },
    }
}

/// An error and its causes on one line, `outer: cause: root`, leaving out a cause whose text
/// the message before it already contains (errors that print their source, as many
/// `thiserror` types do, would otherwise show it twice); line breaks are folded.
pub fn error_line(e: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        let text = text.split_whitespace().collect::<Vec<_>>().join(" ");
        if line.contains(&text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(&text);
    }
    line
}

/// Parse the command line into `C`. Help and version requests print and return
/// `Err(ExitCode::SUCCESS)`; any parse error prints clap's message folded onto one line,
/// prefixed by `program`, and returns `Err` with exit code 2.
pub fn parse_or_exit<C: clap::Parser>(program: &str) -> Result<C, ExitCode> {
    C::try_parse().map_err(|e| clap_error(program, e))
}

/// A clap error as [`parse_or_exit`] reports it: help and version print and give
/// `ExitCode::SUCCESS`; anything else is one line, prefixed by `program`, with exit code 2.
pub fn clap_error(program: &str, e: clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
        let _ = e.print();
        return ExitCode::SUCCESS;
    }
    // clap's message and its tips (`tip: a similar argument exists: '--particles'`), up to
    // the usage line, folded onto one line; the blank lines between them are dropped.
    let text = e.to_string();
    let message = text
        .split("\n\n")
        .take_while(|p| !p.starts_with("Usage:") && !p.starts_with("For more information"))
        .map(|p| p.split_whitespace().collect::<Vec<_>>().join(" "))
        .filter(|p| !p.is_empty())
        .collect::<Vec<_>>()
        .join("; ");
    usage_error(program, message.trim_start_matches("error: "))
}

/// Print `program: error: msg` on one line and return exit code 2 (bad input).
pub fn usage_error(program: &str, msg: &str) -> ExitCode {
    let msg = msg.split_whitespace().collect::<Vec<_>>().join(" ");
    say(&format!("{program}: error: {msg}"));
    ExitCode::from(EXIT_USAGE)
}

/// Log to stderr with `tracing`: warnings only when `quiet` or without `-v`, info with `-v`,
/// debug with `-vv`; `RUST_LOG` overrides. Colour as `color` says.
pub fn init_logging(quiet: bool, verbose: u8, color: Color) {
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
        .with_ansi(color.enabled())
        .try_init();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, thiserror::Error)]
    #[error("checkpoint I/O: {0}")]
    struct Wrapping(#[from] std::io::Error);

    #[test]
    fn error_line_shows_each_cause_once() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "no such file");
        let e = anyhow::Error::from(Wrapping(io)).context("reading x.bin");
        assert_eq!(
            error_line(&e),
            "reading x.bin: checkpoint I/O: no such file"
        );
        let e = anyhow::anyhow!("two\n lines").context("outer");
        assert_eq!(error_line(&e), "outer: two lines");
    }

    #[test]
    fn usage_errors_survive_context_and_downcast() {
        let e = usage("--resume d: not a checkpoint");
        assert_eq!(
            e.downcast_ref::<UsageError>().map(|u| u.0.as_str()),
            Some("--resume d: not a checkpoint")
        );
    }
}
