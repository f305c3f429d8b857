//! `checkpoint=DIR` of the model functions: where a long run keeps its state so that the same
//! call continues it after Ctrl-C, SIGTERM, an exception of the progress callback or memory
//! about to run out. The files are the binaries' (`DIR/checkpoint.bin`, for DLA also
//! `positions.npy` and `growth.csv`), so `--resume DIR` continues a checkpoint written from
//! Python and the other way round.
//!
//! A run with a checkpoint polls a `run_io::guard::Guard`: its watch thread requests a
//! checkpoint every `checkpoint_interval` and a stop when memory is about to run out, and the
//! waiting thread (`run::interruptible_guarded`) requests a stop on `KeyboardInterrupt` or an
//! exception of the callback. For the run's duration SIGTERM raises `KeyboardInterrupt`, as
//! batch systems send it before they kill a job.

use crate::convert::{run_error, value_error};
use pyo3::exceptions::{PyKeyboardInterrupt, PyMemoryError, PyValueError};
use pyo3::prelude::*;
use run_io::guard::{Guard, MemoryWatch, Request, StopReason, Watch};
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// Default of `checkpoint_interval`, seconds: the binaries' `--checkpoint-interval`.
pub const DEFAULT_INTERVAL: f64 = run_io::guard::DEFAULT_INTERVAL.as_secs() as f64;

/// The binaries' name of a checkpoint in a run's directory.
pub const FILE: &str = "checkpoint.bin";

/// Where a run checkpoints and how often: the `checkpoint` and `checkpoint_interval`
/// arguments.
pub struct Checkpoint {
    /// The directory (created if missing).
    pub dir: PathBuf,
    /// Wall time between checkpoints; `None`: none on the clock.
    interval: Option<Duration>,
}

impl Checkpoint {
    /// From the arguments: no directory, no checkpoints (the interval is then ignored); an
    /// interval must be a positive number of seconds or None.
    pub fn from_args(dir: Option<PathBuf>, interval: Option<f64>) -> PyResult<Option<Self>> {
        let interval = match interval {
            None => None,
            Some(s) if s > 0.0 && s.is_finite() => Some(Duration::from_secs_f64(s)),
            Some(s) => {
                return Err(value_error(format!(
                    "checkpoint_interval = {s} is outside (0, inf) seconds; None for no \
                     checkpoints on the clock"
                )));
            }
        };
        Ok(dir.map(|dir| Checkpoint { dir, interval }))
    }

    /// `DIR/checkpoint.bin`.
    pub fn file(&self) -> PathBuf {
        self.dir.join(FILE)
    }

    /// Whether there is a checkpoint to continue.
    pub fn exists(&self) -> bool {
        self.file().is_file()
    }

    /// Creates the directory for a fresh run.
    pub fn create_dir(&self) -> PyResult<()> {
        std::fs::create_dir_all(&self.dir).map_err(|e| {
            pyo3::exceptions::PyOSError::new_err(format!("creating {}: {e}", self.dir.display()))
        })
    }

    /// Starts the run's guard (clock and memory watch, `reserve` bytes kept free for the final
    /// checkpoint) and, on the main thread, SIGTERM as `KeyboardInterrupt`.
    pub fn start(&self, py: Python<'_>, reserve: u64) -> PyResult<Session> {
        let guard = Guard::new();
        let memory = MemoryWatch::new();
        memory.reserve.store(reserve, Ordering::Relaxed);
        let watch = guard
            .watch(self.interval, Some(memory.clone()))
            .map_err(|e| run_error(format!("starting the checkpoint watch: {e}")))?;
        let sigterm = sigterm_as_interrupt(py)?;
        Ok(Session {
            guard,
            memory,
            dir: self.dir.clone(),
            _watch: watch,
            sigterm,
        })
    }

    /// Removes what only the checkpoint needed (`checkpoint.bin` and `others`) after a run
    /// that ended normally; the directory stays.
    pub fn remove(&self, others: &[&str]) -> PyResult<()> {
        for name in std::iter::once(FILE).chain(others.iter().copied()) {
            let path = self.dir.join(name);
            match std::fs::remove_file(&path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    return Err(pyo3::exceptions::PyOSError::new_err(format!(
                        "removing {}: {e}",
                        path.display()
                    )));
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// Ends a run under `session` that ended normally: the session first (its watch, and the
    /// SIGTERM handler put back), then the run's `result`, then `checkpoint.bin`, which stays
    /// if the result cannot be made.
    pub fn finish<T>(&self, session: Session, result: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
        drop(session);
        let out = result()?;
        self.remove(&[])?;
        Ok(out)
    }

    /// The `OSError` of a checkpoint that could not be written.
    pub fn write_error(&self, e: impl std::fmt::Display) -> PyErr {
        pyo3::exceptions::PyOSError::new_err(format!("writing {}: {e}", self.file().display()))
    }

    /// The `ValueError` of a checkpoint that this call cannot continue.
    pub fn refused(&self, why: impl std::fmt::Display) -> PyErr {
        PyValueError::new_err(format!(
            "checkpoint {}: {why}; give another directory, or remove the file to start afresh",
            self.file().display()
        ))
    }

    /// Refuses a checkpoint of other parameters or another seed: `differ` are the parameters
    /// that differ (from [`differences`]), `seeds` the checkpoint's and the call's.
    pub fn check_same(&self, mut differ: Vec<String>, seeds: (u64, u64)) -> PyResult<()> {
        if seeds.0 != seeds.1 {
            differ.push(format!(
                "seed {} in the checkpoint, {} given",
                seeds.0, seeds.1
            ));
        }
        if differ.is_empty() {
            Ok(())
        } else {
            Err(self.refused(format!(
                "the parameters differ from the checkpointed run's: {}",
                differ.join("; ")
            )))
        }
    }
}

/// A run's guard, its watch thread and the SIGTERM handler it replaced; dropping it ends the
/// watch and puts the handler back.
pub struct Session {
    /// What the run polls.
    pub guard: Arc<Guard>,
    /// The memory watch, whose reserve a run whose state grows (animat) keeps up to date.
    pub memory: MemoryWatch,
    dir: PathBuf,
    _watch: Watch,
    sigterm: Option<Py<PyAny>>,
}

impl Session {
    /// The error a run stopped by its guard ends with, after its checkpoint: memory about to
    /// run out is a `MemoryError` with the guard's line; a stop requested otherwise (which the
    /// waiting thread raises itself) a `KeyboardInterrupt`. `at` says where it stopped.
    pub fn stopped(&self, reason: &StopReason, at: &str) -> PyErr {
        let cont = format!(
            "checkpoint in {}: the same call continues the run",
            self.dir.display()
        );
        match reason {
            StopReason::Memory(why) => PyMemoryError::new_err(format!(
                "{why}: stopped {at}; {cont} on a machine with more memory"
            )),
            StopReason::Signal(_) => PyKeyboardInterrupt::new_err(format!("stopped {at}; {cont}")),
        }
    }
}

/// Between two sweeps or steps of a run: with a checkpoint, honours its session's request (a
/// checkpoint written with `save` and the run goes on, or written and the run stops with the
/// guard's reason); without, stops once the waiting thread set `stop`. `Break(None)`: stopped
/// without a checkpoint.
pub fn honour(
    checkpoint: Option<(&Checkpoint, &Session)>,
    stop: &AtomicBool,
    save: impl FnOnce(&Checkpoint) -> PyResult<()>,
) -> PyResult<ControlFlow<Option<StopReason>>> {
    let Some((ck, session)) = checkpoint else {
        return Ok(if stop.load(Ordering::Relaxed) {
            ControlFlow::Break(None)
        } else {
            ControlFlow::Continue(())
        });
    };
    // A stop request of the waiting thread comes through the guard too.
    if !session.guard.is_set() {
        return Ok(ControlFlow::Continue(()));
    }
    match session.guard.take() {
        Request::None => Ok(ControlFlow::Continue(())),
        Request::Checkpoint => save(ck).map(ControlFlow::Continue),
        Request::Stop(r) => save(ck).map(|()| ControlFlow::Break(Some(r))),
    }
}

/// The exception that stopped a run (`KeyboardInterrupt`, one of the progress callback), to
/// raise once the run's state is saved. `finished` is what the run's thread returned:
/// `Ok(false)` when it stopped after writing its checkpoint, `Ok(true)` when it had finished
/// before the exception came (from the last progress report), and then `save` writes the
/// checkpoint so that the same call returns at once; `Err` its error, which, like an error of
/// `save`, becomes the exception's cause.
pub fn raise_after_saving<E: std::fmt::Display>(
    py: Python<'_>,
    failure: PyErr,
    finished: Result<bool, E>,
    save: impl FnOnce() -> Result<(), E>,
) -> PyErr {
    let written = match finished {
        Ok(true) => save(),
        Ok(false) => Ok(()),
        Err(e) => Err(e),
    };
    if let Err(e) = written {
        failure.set_cause(py, Some(run_error(format!("the checkpoint: {e}"))));
    }
    failure
}

/// How a run of steps or sweeps between which it [`honour`]s its checkpoint ends, once
/// `run::interruptible_guarded` has returned what its thread `made` (the steps or sweeps made,
/// and the guard's reason if it stopped the run) and the exception that stopped it, if any
/// (`failure`): that exception, raised after the checkpoint is saved with `save`
/// ([`raise_after_saving`]); the error of a run stopped by its guard ([`Session::stopped`],
/// `at` saying where); else the steps or sweeps made.
///
/// # Errors
/// As above, or the run's own error.
pub fn conclude<T>(
    py: Python<'_>,
    made: PyResult<(T, Option<StopReason>)>,
    failure: Option<PyErr>,
    checkpoint: Option<(&Checkpoint, &Session)>,
    save: impl FnOnce(&Checkpoint) -> PyResult<()>,
    at: impl FnOnce() -> String,
) -> PyResult<T> {
    if let Some(e) = failure {
        return Err(match checkpoint {
            Some((ck, _)) => {
                let finished = made.as_ref().map(|(_, r)| r.is_none());
                let finished = finished.map_err(ToString::to_string);
                let save = || save(ck).map_err(|e| e.to_string());
                raise_after_saving(py, e, finished, save)
            }
            None => e,
        });
    }
    let (k, stopped) = made?;
    if let (Some(r), Some((_, session))) = (stopped, checkpoint) {
        return Err(session.stopped(&r, &at()));
    }
    Ok(k)
}

impl Drop for Session {
    fn drop(&mut self) {
        if let Some(previous) = self.sigterm.take() {
            Python::attach(|py| {
                let restored = py.import("signal").and_then(|signal| {
                    signal.call_method1("signal", (signal.getattr("SIGTERM")?, previous))
                });
                if let Err(e) = restored {
                    e.write_unraisable(py, None);
                }
            });
        }
    }
}

/// On the main thread, makes SIGTERM raise `KeyboardInterrupt` (`signal.default_int_handler`)
/// and returns the handler it replaced; elsewhere (signal handlers belong to the main thread),
/// or when the handler was not installed from Python (and could not be put back), nothing.
fn sigterm_as_interrupt(py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
    let threading = py.import("threading")?;
    let main = threading
        .call_method0("current_thread")?
        .is(&threading.call_method0("main_thread")?);
    if !main {
        return Ok(None);
    }
    let signal = py.import("signal")?;
    let Ok(sigterm) = signal.getattr("SIGTERM") else {
        return Ok(None);
    };
    let previous = signal.call_method1("getsignal", (&sigterm,))?;
    if previous.is_none() {
        return Ok(None);
    }
    signal.call_method1("signal", (&sigterm, signal.getattr("default_int_handler")?))?;
    Ok(Some(previous.unbind()))
}

/// The parameters that differ between a checkpoint's and the call's, named as the keyword
/// arguments: `step_min 0.1 in the checkpoint, 0.2 given`. `renames` names a field otherwise
/// (`None`: not compared). Both sides as `serde_json::to_value` gives them.
pub fn differences(
    checkpointed: serde_json::Result<serde_json::Value>,
    given: serde_json::Result<serde_json::Value>,
    renames: &[(&str, Option<&str>)],
) -> Vec<String> {
    let (Ok(serde_json::Value::Object(old)), Ok(serde_json::Value::Object(new))) =
        (checkpointed, given)
    else {
        return vec!["the parameters cannot be compared".into()];
    };
    let mut out = Vec::new();
    for (field, a) in &old {
        let name = match renames.iter().find(|(f, _)| f == field) {
            Some((_, None)) => continue,
            Some((_, Some(name))) => (*name).to_string(),
            None => field.clone(),
        };
        let b = new.get(field).cloned().unwrap_or(serde_json::Value::Null);
        if *a != b {
            out.push(format!("{name} {a} in the checkpoint, {b} given"));
        }
    }
    out
}
