//! `aggsim.AnimatWorld`: an animat world stepped from Python (the class; `aggsim.animat` runs
//! one for a number of steps).

use super::*;

/// An animat world to step forward and look at between steps.
///
/// Takes the model parameters of :func:`aggsim.animat` (all but ``steps`` and
/// ``progress``), places the start population and waits: :meth:`step` runs steps, the
/// properties show the state, :meth:`result` gives what :func:`aggsim.animat` returns.
/// Stepping one step at a time gives the very run ``animat`` makes (the same ``state_hash``).
/// Ctrl-C during :meth:`step` stops after the current step with ``KeyboardInterrupt`` and
/// leaves the world valid. One thread at a time may use a world (another gets
/// ``RuntimeError`` while it runs).
#[pyclass(module = "aggsim")]
pub struct AnimatWorld {
    run: Mutex<Run>,
}

impl AnimatWorld {
    pub(super) fn lock(&self) -> PyResult<MutexGuard<'_, Run>> {
        match self.run.try_lock() {
            Ok(g) => Ok(g),
            Err(TryLockError::Poisoned(e)) => Ok(e.into_inner()),
            Err(TryLockError::WouldBlock) => Err(PyRuntimeError::new_err(
                "the world is running in another thread",
            )),
        }
    }
}

#[pymethods]
impl AnimatWorld {
    #[new]
    #[pyo3(signature = (
        seed = 1,
        *,
        config = None,
        density = None,
        timing = false,
        **params,
    ))]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn new(
        py: Python<'_>,
        seed: u64,
        config: Option<PathBuf>,
        density: Option<f64>,
        timing: bool,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let args = Args {
            function: "AnimatWorld",
            config,
            density,
            keywords: params,
        };
        Ok(AnimatWorld {
            run: Mutex::new(Run::new(py, &args, seed, timing)?),
        })
    }

    /// Run up to ``n`` steps (fewer once every animat has died) and return how many ran. In a
    /// step every animat alive at its start, in a fresh random order, runs the first rule of
    /// its species' list whose condition holds. ``progress`` as in :func:`aggsim.animat`.
    /// Ctrl-C stops after the current step (``KeyboardInterrupt``).
    #[pyo3(signature = (n = Count::Int(1), progress = None))]
    fn step(&self, py: Python<'_>, n: Count, progress: Option<&Bound<'_, PyAny>>) -> PyResult<u64> {
        let n = count(&[], "n", n)?;
        let progress = Progress::from_arg(progress, "animat", "steps")?;
        self.lock()?.steps(py, n, &progress, None, None)
    }

    /// The state now as an :class:`AnimatResult`, with ``run.json``'s results (times since
    /// the world was made).
    fn result(&self, py: Python<'_>) -> PyResult<Py<AnimatResult>> {
        self.lock()?.result(py)
    }

    /// Steps made.
    #[getter]
    fn steps(&self) -> PyResult<u64> {
        Ok(self.lock()?.world.steps())
    }

    /// Live foxes.
    #[getter]
    fn foxes(&self) -> PyResult<u64> {
        Ok(self.lock()?.world.foxes())
    }

    /// Live rabbits.
    #[getter]
    fn rabbits(&self) -> PyResult<u64> {
        Ok(self.lock()?.world.rabbits())
    }

    /// Hash of every live animat (the binary's ``state_hash``).
    #[getter]
    fn state_hash(&self) -> PyResult<String> {
        Ok(self.lock()?.world.state_hash())
    }

    /// The validated parameters, as ``run.json`` records them.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v = serde_json::to_value(self.lock()?.world.params()).map_err(run_error)?;
        crate::convert::json(py, &v)
    }

    /// int64 array (M, 2): the cell of every live animat, by increasing id.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.column(py, "positions")
    }

    /// int64 array (M,): ``FOX`` (0) or ``RABBIT`` (1) for every live animat.
    #[getter]
    fn species<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.column(py, "species")
    }

    /// int64 array (M,): every live animat's id.
    #[getter]
    fn id<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.column(py, "id")
    }

    /// int64 array (M,): steps lived.
    #[getter]
    fn age<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.column(py, "age")
    }

    /// int64 array (M,): steps since the last meal (0 for rabbits).
    #[getter]
    fn hunger<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.column(py, "hunger")
    }

    /// Foxes and rabbits after every step so far (dict of arrays, as
    /// :attr:`AnimatResult.populations`).
    #[getter]
    fn populations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.lock()?.populations(py)
    }

    fn __repr__(&self) -> PyResult<String> {
        let r = self.lock()?;
        Ok(format!(
            "<aggsim.AnimatWorld: {} foxes, {} rabbits after {} steps>",
            r.world.foxes(),
            r.world.rabbits(),
            r.world.steps()
        ))
    }
}

impl AnimatWorld {
    fn column<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        self.lock()?
            .animats(py)?
            .get_item(name)?
            .ok_or_else(|| run_error(format!("no column {name}")))
    }
}
