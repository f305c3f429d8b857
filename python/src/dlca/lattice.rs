//! `aggsim.DlcaLattice`: a DLCA lattice stepped from Python (the class; `aggsim.dlca` runs one
//! to the end).

use super::*;

/// A DLCA lattice to step forward and look at between sweeps (Hawick, James & Scogings
/// 2006, "Grid-Boxing for Spatial Simulation Performance Optimisation").
///
/// Takes the parameters of :func:`aggsim.dlca`, places the particles (face-adjacent ones form
/// the initial clusters) and waits: :meth:`step` runs sweeps, :meth:`run` runs to the end, the
/// properties show the state, :meth:`result` gives what :func:`aggsim.dlca` returns. Sweeping
/// step by step gives the very run ``dlca`` makes (the same ``state_hash``). Ctrl-C during
/// :meth:`step` or :meth:`run` stops after the current sweep with ``KeyboardInterrupt`` and
/// leaves the lattice valid, to continue or inspect. One thread at a time may use a lattice
/// (another gets ``RuntimeError`` while it runs).
#[pyclass(module = "aggsim")]
pub struct DlcaLattice {
    run: Mutex<Run>,
}

impl DlcaLattice {
    pub(super) fn lock(&self) -> PyResult<MutexGuard<'_, Run>> {
        match self.run.try_lock() {
            Ok(g) => Ok(g),
            Err(TryLockError::Poisoned(e)) => Ok(e.into_inner()),
            Err(TryLockError::WouldBlock) => Err(PyRuntimeError::new_err(
                "the lattice is running in another thread",
            )),
        }
    }
}

#[pymethods]
impl DlcaLattice {
    #[new]
    #[pyo3(signature = (size, fill = None, particles = None, *, dim = None, seed = 1, **params))]
    pub(super) fn new(
        py: Python<'_>,
        size: &Bound<'_, PyAny>,
        fill: Option<f64>,
        particles: Option<Count>,
        dim: Option<usize>,
        seed: u64,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let p = self::params("DlcaLattice", size, (fill, particles, dim), params)?;
        Ok(DlcaLattice {
            run: Mutex::new(Run::new(py, p, seed)?),
        })
    }

    /// Run up to ``n`` sweeps (fewer once the run is done: at most ``target_clusters``
    /// clusters left, or ``max_sweeps`` reached) and return how many ran. Each sweep moves
    /// every cluster once, in a fresh random order. ``progress`` as in :func:`aggsim.dlca`,
    /// counting sweeps. Ctrl-C stops after the current sweep (``KeyboardInterrupt``).
    #[pyo3(signature = (n = Count::Int(1), progress = None))]
    fn step(&self, py: Python<'_>, n: Count, progress: Option<&Bound<'_, PyAny>>) -> PyResult<u64> {
        let n = count(&[], "n", n)?;
        let progress = Progress::from_arg(progress, "dlca", "sweeps")?;
        self.lock()?.sweeps(py, n, &progress)
    }

    /// Sweep until the run is done, as the binary does, and return the sweeps made.
    /// ``progress`` counts merges. Ctrl-C stops after the current sweep.
    #[pyo3(signature = (progress = None))]
    fn run(&self, py: Python<'_>, progress: Option<&Bound<'_, PyAny>>) -> PyResult<u64> {
        let progress = Progress::from_arg(progress, "dlca", "merges")?;
        self.lock()?.until_done(py, &progress, None, None)
    }

    /// The state now as a :class:`DlcaResult`, with ``run.json``'s results (times since the
    /// lattice was made).
    fn result(&self, py: Python<'_>) -> PyResult<Py<DlcaResult>> {
        self.lock()?.result(py)
    }

    /// Whether the run is done: at most ``target_clusters`` clusters, or ``max_sweeps``
    /// sweeps made.
    #[getter]
    fn done(&self) -> PyResult<bool> {
        Ok(self.lock()?.sim.is_done())
    }

    /// Sweeps made.
    #[getter]
    fn sweeps(&self) -> PyResult<u64> {
        Ok(self.lock()?.sim.sweeps())
    }

    /// Clusters now.
    #[getter]
    fn clusters(&self) -> PyResult<u64> {
        Ok(self.lock()?.sim.clusters())
    }

    /// Size of the largest cluster.
    #[getter]
    fn largest(&self) -> PyResult<u64> {
        Ok(self.lock()?.sim.largest())
    }

    /// Particles on the lattice.
    #[getter]
    fn particles(&self) -> PyResult<u64> {
        Ok(self.lock()?.sim.particles())
    }

    /// The lattice's side lengths.
    #[getter]
    fn size<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        PyTuple::new(py, self.lock()?.sim.lattice().sizes())
    }

    /// The contact search in use now (``auto`` resolves to one of the others).
    #[getter]
    fn strategy(&self) -> PyResult<&'static str> {
        Ok(self.lock()?.sim.strategy().name())
    }

    /// Hash of every particle's site and cluster id (the binary's ``state_hash``).
    #[getter]
    fn state_hash(&self) -> PyResult<String> {
        Ok(self.lock()?.sim.state_hash())
    }

    /// The validated parameters, as ``run.json`` records them.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v = serde_json::to_value(self.lock()?.sim.params()).map_err(run_error)?;
        crate::convert::json(py, &v)
    }

    /// int64 array (N, D): every particle's site, clusters by increasing id (made on each
    /// access).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(self.lock()?.particles(py)?.0)
    }

    /// int64 array (N,): each particle's cluster id, in the order of :attr:`positions`.
    #[getter]
    fn cluster<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(self.lock()?.particles(py)?.1)
    }

    /// Clusters and largest cluster after every sweep so far (dict of arrays, as
    /// :attr:`DlcaResult.per_sweep`).
    #[getter]
    fn per_sweep<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.lock()?.per_sweep(py)
    }

    /// The size distribution now (dict of arrays ``size``, ``count``).
    #[getter]
    fn sizes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.lock()?.sizes(py)
    }

    fn __repr__(&self) -> PyResult<String> {
        let r = self.lock()?;
        let s = &r.sim;
        Ok(format!(
            "<aggsim.DlcaLattice {:?}: {} particles in {} clusters after {} sweeps>",
            s.lattice().sizes(),
            s.particles(),
            s.clusters(),
            s.sweeps()
        ))
    }
}
