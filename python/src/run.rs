//! Running a model from Python: the work runs on a worker thread without the GIL while the
//! calling thread waits, checks for signals (Ctrl-C) every [`POLL`] and reports progress. On a
//! signal the worker is told to stop at its next consistent point (a stop flag the model
//! polls, and with `checkpoint=` a stop request of its guard, which writes a checkpoint
//! first), joined, and the signal's exception (`KeyboardInterrupt`) raised.

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyAny;
use run_io::guard::Guard;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::{Duration, Instant};

/// How often the calling thread wakes to check for signals: Ctrl-C is seen within this.
const POLL: Duration = Duration::from_millis(50);

/// How often progress is reported (and once at the end).
const REPORT_EVERY: Duration = Duration::from_millis(500);

/// Environment variable that sets the time between progress reports for tests, in seconds:
/// `0` reports at every poll, so that a test can stop a run at its first report however fast
/// the machine runs it.
pub const REPORT_EVERY_ENV: &str = "AGGSIM_TEST_REPORT_EVERY";

/// [`REPORT_EVERY`], or the test hook's [`REPORT_EVERY_ENV`] if it is set to seconds >= 0.
fn report_every() -> Duration {
    std::env::var(REPORT_EVERY_ENV)
        .ok()
        .and_then(|s| s.trim().parse::<f64>().ok())
        .and_then(|s| Duration::try_from_secs_f64(s).ok())
        .unwrap_or(REPORT_EVERY)
}

/// How often progress goes to `sys.stderr` when it is neither a terminal nor Jupyter.
const LOG_EVERY: Duration = Duration::from_secs(10);

/// Stack of the worker thread: that of a main thread, which the binaries run on.
const WORKER_STACK: usize = 8 << 20;

/// What the worker shares with the waiting thread.
pub struct Shared {
    /// Set when the run must stop at its next consistent point.
    pub stop: AtomicBool,
    /// Work done so far (particles, merges, steps), for progress reports.
    pub done: AtomicU64,
}

/// Where progress goes: nowhere, a line on `sys.stderr`, or a callable.
pub enum Progress {
    /// No reports.
    Off,
    /// `PROGRAM: done/total UNIT (p%), s elapsed, eta s` on `sys.stderr`: rewritten in place
    /// on a terminal or in Jupyter, else a line every [`LOG_EVERY`] (a log file stays short).
    Stderr {
        /// The model's name.
        label: &'static str,
        /// What is counted.
        unit: &'static str,
        /// Whether the line is rewritten in place (`\r`).
        in_place: bool,
        /// Reports so far, for the lines of a log.
        reports: std::cell::Cell<u64>,
    },
    /// `callback(done, total)`.
    Callback(Py<PyAny>),
}

impl Progress {
    /// From the `progress` argument: `False`/`None` off, `True` on `sys.stderr`, a callable is
    /// called with `(done, total)`.
    pub fn from_arg(
        arg: Option<&Bound<'_, PyAny>>,
        label: &'static str,
        unit: &'static str,
    ) -> PyResult<Self> {
        let Some(arg) = arg else {
            return Ok(Progress::Off);
        };
        if arg.is_none() {
            return Ok(Progress::Off);
        }
        if arg.is_callable() {
            return Ok(Progress::Callback(arg.clone().unbind()));
        }
        Ok(if arg.is_truthy()? {
            let stderr = arg.py().import("sys")?.getattr("stderr")?;
            let tty = stderr.call_method0("isatty")?.is_truthy()?;
            let module: String = stderr.get_type().getattr("__module__")?.extract()?;
            Progress::Stderr {
                label,
                unit,
                in_place: tty || module.starts_with("ipykernel"),
                reports: std::cell::Cell::new(0),
            }
        } else {
            Progress::Off
        })
    }

    fn report(
        &self,
        py: Python<'_>,
        done: u64,
        total: u64,
        started: Instant,
        last: bool,
    ) -> PyResult<()> {
        match self {
            Progress::Off => Ok(()),
            Progress::Callback(f) => f.call1(py, (done, total)).map(|_| ()),
            Progress::Stderr {
                label,
                unit,
                in_place,
                reports,
            } => {
                reports.set(reports.get() + 1);
                let every = (LOG_EVERY.as_millis() / REPORT_EVERY.as_millis()) as u64;
                if !*in_place && !last && reports.get() % every != 0 {
                    return Ok(());
                }
                let secs = started.elapsed().as_secs_f64();
                let frac = if total == 0 {
                    1.0
                } else {
                    done as f64 / total as f64
                };
                let eta = if frac > 0.0 && !last {
                    format!(", eta {:.1} s", secs * (1.0 - frac) / frac)
                } else {
                    String::new()
                };
                let line = format!(
                    "{}{label}: {done}/{total} {unit} ({:.0}%), {secs:.1} s{eta}{}",
                    if *in_place { "\r" } else { "" },
                    100.0 * frac,
                    if last || !*in_place { "\n" } else { "" }
                );
                let stderr = py.import("sys")?.getattr("stderr")?;
                stderr.call_method1("write", (line,))?;
                stderr.call_method0("flush")?;
                Ok(())
            }
        }
    }
}

/// Runs `work` on a worker thread with the GIL released and returns its result. The calling
/// thread checks for signals every [`POLL`]: on one (Ctrl-C raises `KeyboardInterrupt` in the
/// main thread) it sets `Shared::stop`, waits for `work` to return at its next consistent point
/// and raises the signal's exception. An exception of the progress callback stops the run the
/// same way. `total` is the amount of work for progress reports, `work` stores what it has done
/// in `Shared::done`.
pub fn interruptible<T: Send>(
    py: Python<'_>,
    progress: &Progress,
    total: u64,
    work: impl FnOnce(&Shared) -> T + Send,
) -> PyResult<T> {
    let (out, failure) = interruptible_guarded(py, progress, total, None, work)?;
    match failure {
        Some(e) => Err(e),
        None => Ok(out),
    }
}

/// [`interruptible`] for a run that checkpoints (`checkpoint=`): a signal's exception or one
/// of the progress callback also asks `guard` for a stop, which the run honours by writing a
/// checkpoint before it returns. Returns what `work` returned and that exception, if any
/// (also one of the last progress report, after `work` has finished), for the caller to
/// raise once the run's state is saved.
pub fn interruptible_guarded<T: Send>(
    py: Python<'_>,
    progress: &Progress,
    total: u64,
    guard: Option<&Guard>,
    work: impl FnOnce(&Shared) -> T + Send,
) -> PyResult<(T, Option<PyErr>)> {
    let shared = Shared {
        stop: AtomicBool::new(false),
        done: AtomicU64::new(0),
    };
    let finished = (Mutex::new(false), Condvar::new());
    let started = Instant::now();
    let report_every = report_every();
    std::thread::scope(|s| {
        let worker = std::thread::Builder::new()
            .name("aggsim".into())
            .stack_size(WORKER_STACK)
            .spawn_scoped(s, || {
                let out = work(&shared);
                *finished.0.lock().unwrap_or_else(|e| e.into_inner()) = true;
                finished.1.notify_all();
                out
            })
            .map_err(|e| PyRuntimeError::new_err(format!("starting the run's thread: {e}")))?;
        let mut failure: Option<PyErr> = None;
        let mut reported = Instant::now();
        loop {
            // Wait for the worker, at most POLL, without the GIL.
            let done = py.detach(|| {
                let guard = finished.0.lock().unwrap_or_else(|e| e.into_inner());
                let (guard, _) = finished
                    .1
                    .wait_timeout_while(guard, POLL, |f| !*f)
                    .unwrap_or_else(|e| e.into_inner());
                *guard
            });
            if done {
                break;
            }
            if failure.is_none() {
                let mut check = py.check_signals();
                if check.is_ok() && reported.elapsed() >= report_every {
                    reported = Instant::now();
                    let n = shared.done.load(Ordering::Relaxed);
                    check = progress.report(py, n, total, started, false);
                }
                if let Err(e) = check {
                    shared.stop.store(true, Ordering::Relaxed);
                    if let Some(g) = guard {
                        g.request_stop(0);
                    }
                    failure = Some(e);
                }
            }
        }
        let out = match worker.join() {
            Ok(out) => out,
            Err(panic) => std::panic::resume_unwind(panic),
        };
        match failure {
            Some(e) => {
                if let Progress::Stderr { in_place: true, .. } = progress {
                    // End the progress line before the traceback.
                    let stderr = py.import("sys")?.getattr("stderr")?;
                    stderr.call_method1("write", ("\n",))?;
                }
                Ok((out, Some(e)))
            }
            None => {
                let n = shared.done.load(Ordering::Relaxed);
                let last = progress.report(py, n, total, started, true);
                Ok((out, last.err()))
            }
        }
    })
}
