//! Checkpoints by default: the flags every binary takes for them ([`CheckpointArgs`]), the
//! signal handlers that turn a stop into a checkpoint ([`guard_signals`]), the start of a
//! run's [`Guard`] with its clock and memory watch ([`CheckpointArgs::start`]), and the one
//! line a stopped run ends with ([`stopped`]).

use run_io::guard::{Guard, MemoryWatch, Request, StopReason, Watch};
use std::path::Path;
use std::sync::Arc;
use std::time::Duration;

/// Wall time between checkpoints, `off` for none on the clock (`--checkpoint-interval`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Interval(pub Option<Duration>);

impl std::fmt::Display for Interval {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&run_io::guard::show_interval(self.0))
    }
}

impl std::str::FromStr for Interval {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        run_io::guard::parse_interval(s).map(Interval)
    }
}

/// The checkpoint flags every model binary takes besides its own `--checkpoint-every N`
/// (`#[command(flatten)]` them).
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct CheckpointArgs {
    /// Wall time between checkpoints (OUT/checkpoint.bin, written atomically): seconds, or a
    /// number with s, m or h (90, 30s, 5m, 2h); `off` for none on the clock. Whatever this is,
    /// SIGINT, SIGTERM, SIGUSR1 and SIGXCPU checkpoint and stop the run (exit code 130), and so
    /// does memory about to run out (exit code 1); continue with --resume OUT. A run that ends
    /// normally removes the checkpoint it did not ask for with --checkpoint-every.
    #[arg(long, value_name = "DURATION", default_value_t = Interval(Some(run_io::guard::DEFAULT_INTERVAL)))]
    pub checkpoint_interval: Interval,

    /// No checkpoints at all, not even on a signal (which then stops the run with nothing
    /// saved, exit code 130) or when memory runs out: for short runs where the checkpoint's
    /// files are not wanted. Refused with --checkpoint-every or --checkpoint-interval.
    #[arg(long)]
    pub no_checkpoint: bool,
}

impl CheckpointArgs {
    /// Refuses `--no-checkpoint` beside a checkpoint flag (`every`: `--checkpoint-every`).
    ///
    /// # Errors
    /// One line naming both flags.
    pub fn check(&self, every: Option<u64>) -> Result<(), String> {
        if every == Some(0) {
            return Err("--checkpoint-every 0 is outside the accepted range 1..".into());
        }
        if self.no_checkpoint {
            if every.is_some() {
                return Err("--no-checkpoint and --checkpoint-every contradict each other".into());
            }
            if self.checkpoint_interval != Interval(Some(run_io::guard::DEFAULT_INTERVAL)) {
                return Err(
                    "--no-checkpoint and --checkpoint-interval contradict each other".into(),
                );
            }
        }
        Ok(())
    }

    /// Whether the run checkpoints at all (not `--no-checkpoint`).
    pub fn enabled(&self) -> bool {
        !self.no_checkpoint
    }

    /// The run's guard: signal handlers installed, and (unless `--no-checkpoint`) the clock
    /// and the memory watch started. `reserve` is what the final checkpoint needs beyond the
    /// state (see [`MemoryWatch::reserve`]); the returned [`Watch`] must live as long as the
    /// run.
    ///
    /// # Errors
    /// The handlers or the watch thread could not be installed.
    pub fn start(&self, reserve: u64) -> std::io::Result<(Arc<Guard>, Watch, MemoryWatch)> {
        let guard = Guard::new();
        guard_signals(&guard)?;
        let memory = MemoryWatch::new();
        memory
            .reserve
            .store(reserve, std::sync::atomic::Ordering::Relaxed);
        let watch = if self.no_checkpoint {
            guard.watch(None, None)?
        } else {
            guard.watch(self.checkpoint_interval.0, Some(memory.clone()))?
        };
        Ok((guard, watch, memory))
    }
}

/// Installs the handlers that turn SIGINT, SIGTERM, SIGUSR1 and SIGXCPU into a stop request of
/// `guard` (the run checkpoints and stops). A second signal of the same kind ends the process
/// at once, as usual, so a run that does not stop can still be interrupted; except in an
/// ensemble's member, which may get the same signal twice (from a batch system that signals
/// every process of a job, and from its ensemble passing it on) and is killed with its
/// ensemble anyway. A member ignores SIGUSR1, which its ensemble passes on as SIGTERM
/// ([`tie_member_to_ensemble`](crate::ensemble::tie_member_to_ensemble)).
///
/// # Errors
/// The handlers could not be installed.
pub fn guard_signals(guard: &Arc<Guard>) -> std::io::Result<()> {
    use signal_hook::consts::{SIGINT, SIGTERM, SIGUSR1, SIGXCPU};
    let member = super::is_member();
    let signalled = Arc::new(std::sync::atomic::AtomicBool::new(false));
    for sig in [SIGINT, SIGTERM, SIGUSR1, SIGXCPU] {
        if member && sig == SIGUSR1 {
            continue;
        }
        // Registered first, so it runs when the flag is already set: the second signal.
        if !member {
            signal_hook::flag::register_conditional_default(sig, Arc::clone(&signalled))?;
        }
        signal_hook::flag::register(sig, Arc::clone(&signalled))?;
        // The number first, then the flag the run polls.
        let number = usize::try_from(sig).unwrap_or(run_io::guard::PROGRAM_STOP);
        signal_hook::flag::register_usize(sig, guard.signal_slot(), number)?;
        signal_hook::flag::register(sig, guard.flag_arc())?;
    }
    Ok(())
}

/// The error a run stopped by `reason` ends with, after its checkpoint (`saved`) or without
/// one: a signal is an [`Interrupted`](super::Interrupted) run (exit code 130), memory a
/// failed one (exit code 1). `at` says where it stopped (`at 12000 of 100000 particles`).
pub fn stopped(reason: &StopReason, at: &str, out: &Path, saved: bool) -> anyhow::Error {
    let cont = if saved {
        format!(
            "checkpoint in {}: continue with --resume {}",
            out.display(),
            out.display()
        )
    } else {
        "no checkpoint (--no-checkpoint)".to_string()
    };
    match reason {
        StopReason::Signal(sig) => super::Interrupted(format!(
            "{} {at}; {cont}",
            match run_io::guard::signal_name(*sig) {
                "a stop request" => "interrupted".to_string(),
                name => format!("{name}: interrupted"),
            }
        ))
        .into(),
        StopReason::Memory(why) => anyhow::anyhow!(
            "{why}: stopped {at}; {cont}{}",
            if saved {
                " on a machine with more memory"
            } else {
                ""
            }
        ),
    }
}

/// Honours `guard`'s request at a consistent point of a run's loop (after a sweep, a step):
/// a checkpoint is saved (`save`, unless checkpoints are off) and the run goes on (`Ok`); a
/// stop is saved and ends the run with the error of [`stopped`], `at()` saying where it
/// stopped. Call it when [`Guard::is_set`].
///
/// # Errors
/// The stop, or the error of `save`.
pub fn honour(
    guard: &Guard,
    enabled: bool,
    out: &Path,
    save: impl FnOnce() -> anyhow::Result<()>,
    at: impl FnOnce() -> String,
) -> anyhow::Result<()> {
    match guard.take() {
        Request::None => Ok(()),
        Request::Checkpoint if !enabled => Ok(()),
        Request::Checkpoint => save(),
        Request::Stop(reason) => {
            if enabled {
                save()?;
            }
            Err(stopped(&reason, &at(), out, enabled))
        }
    }
}

/// Removes `OUT/checkpoint.bin` after a run that ended normally and did not ask for it
/// (`--checkpoint-every`): a finished run leaves no more files than one without checkpoints.
///
/// # Errors
/// The file exists but cannot be removed.
pub fn remove_unasked_checkpoint(out: &Path, asked: bool) -> std::io::Result<()> {
    if asked {
        return Ok(());
    }
    match std::fs::remove_file(out.join("checkpoint.bin")) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e),
        _ => Ok(()),
    }
}
