//! `aggsim.dlca` and `aggsim.DlcaLattice`: diffusion-limited cluster-cluster aggregation over
//! the `dlca` library (Hawick, James & Scogings 2006, "Grid-Boxing for Spatial Simulation
//! Performance Optimisation").

use crate::checkpoint::{Checkpoint, Session, conclude, differences, honour};
use crate::convert::{Columns, Count, count, run_error, set_manifest, value_error};
use crate::declared::set_keywords;
use crate::figure::Animate;
use crate::run::{Progress, interruptible, interruptible_guarded};
use ::dlca::analysis::{gyration, size_distribution};
use ::dlca::figure::{ANIMATION_DEFAULT_EVERY, ANIMATION_DEFAULT_SIDE, Animation};
use ::dlca::params::{PARAMS, Settings, Sizes, flags};
use ::dlca::{Params, Simulation, Snapshot};
use numpy::IntoPyArray;
use numpy::ndarray::{Array1, Array2};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyTuple};
use run_io::{OutputError, RunClock, read_checkpoint, write_checkpoint};
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::sync::{Mutex, MutexGuard, TryLockError};

mod lattice;
pub use lattice::DlcaLattice;

/// Model name in the checkpoint envelope: the `dlca` binary's.
const CHECKPOINT_MODEL: &str = "dlca";

/// `--size`: an int (every axis), a sequence of ints (one per axis) or a string as the binary
/// takes it (`"1024x512"`).
fn sizes(arg: &Bound<'_, PyAny>) -> PyResult<Vec<u64>> {
    if let Ok(s) = arg.cast::<PyString>() {
        return flags::parse_size(s.to_str()?).map_err(value_error);
    }
    let given: Vec<Count> = match arg.extract::<Count>()? {
        Count::NotANumber(t) => arg.extract().map_err(|_| {
            pyo3::exceptions::PyTypeError::new_err(format!(
                "size = a {t}: a size is a count, a sequence of counts or a string (\"1024x512\")"
            ))
        })?,
        v => vec![v],
    };
    given
        .into_iter()
        .map(|v| count(PARAMS, "size", v))
        .collect()
}

/// Declared parameters `aggsim.dlca` and `aggsim.DlcaLattice` take as their own arguments (by
/// position too, and `dim`, whose default depends on `size`), not as keywords of the
/// declaration.
pub const POSITIONAL: &[&str] = &["dim", "size", "fill", "particles"];

/// The parameter of `aggsim.dlca` the declared keywords come before in its signature.
pub const KEYWORDS_BEFORE: &str = "progress";

/// The parameters of the arguments, checked as the binary checks its flags: `size`, `fill`,
/// `particles` and `dim` as the functions take them, the declared keyword arguments
/// (`kwargs`, those of [`Settings`]) on the library's defaults.
fn params(
    function: &str,
    size: &Bound<'_, PyAny>,
    (fill, particles, dim): (Option<f64>, Option<Count>, Option<usize>),
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<Params> {
    let lengths = sizes(size)?;
    let mut s = Settings {
        // A sequence of lengths gives the dimension; one length takes the binary's default.
        dim: dim.unwrap_or(if lengths.len() > 1 {
            lengths.len()
        } else {
            Settings::default().dim
        }),
        size: Some(Sizes(lengths)),
        fill,
        particles: particles
            .map(|n| count(PARAMS, "particles", n))
            .transpose()?,
        ..Settings::default()
    };
    let given = set_keywords(&mut s, PARAMS, function, POSITIONAL, kwargs)?;
    s.to_params(|name| given.iter().any(|g| g == name))
        .map_err(value_error)
}

/// A run and its clock (`run.json`'s times count from the lattice's creation).
struct Run {
    sim: Simulation,
    clock: RunClock,
}

impl Run {
    fn new(py: Python<'_>, params: Params, seed: u64) -> PyResult<Self> {
        let clock = RunClock::start();
        // Placing a large lattice takes a while: without the GIL.
        let sim = py
            .detach(|| Simulation::new(params, seed))
            .map_err(value_error)?;
        Ok(Run { sim, clock })
    }

    /// The run checkpointed in `ck`, if this call continues it: the same parameters and seed
    /// (`target_clusters` and `max_sweeps` may change), as the binary's `--resume`.
    fn resume(py: Python<'_>, ck: &Checkpoint, params: Params, seed: u64) -> PyResult<Self> {
        let clock = RunClock::start();
        let mut snapshot: Snapshot =
            read_checkpoint(ck.file(), CHECKPOINT_MODEL).map_err(|e| ck.refused(e))?;
        snapshot.set_stop(params.target_clusters, params.max_sweeps);
        let differ = differences(
            serde_json::to_value(snapshot.params()),
            serde_json::to_value(&params),
            ::dlca::params::COMBINED_KEYWORDS,
        );
        ck.check_same(differ, (snapshot.seed(), seed))?;
        // Rebuilding a large lattice takes a while: without the GIL.
        let sim = py
            .detach(|| Simulation::restore(snapshot))
            .map_err(|e| ck.refused(e))?;
        Ok(Run { sim, clock })
    }

    /// Up to `n` sweeps, fewer once the run is done; returns the sweeps made.
    fn sweeps(&mut self, py: Python<'_>, n: u64, progress: &Progress) -> PyResult<u64> {
        let sim = &mut self.sim;
        interruptible(py, progress, n, |shared| {
            let mut k = 0;
            while k < n && !sim.is_done() && !shared.stop.load(Ordering::Relaxed) {
                sim.sweep();
                k += 1;
                shared.done.store(k, Ordering::Relaxed);
            }
            k
        })
    }

    /// Sweeps until the run is done (as the binary); returns the sweeps made. Progress counts
    /// merges, as the binary's. With `animate` the run writes the binary's `dlca.gif` of these
    /// sweeps to its path, unless it is interrupted. With `checkpoint` the run honours its
    /// session's requests between sweeps, writing `checkpoint.bin` as the binary does; a
    /// stop raises after the checkpoint.
    fn until_done(
        &mut self,
        py: Python<'_>,
        progress: &Progress,
        animate: Option<&Animate>,
        checkpoint: Option<(&Checkpoint, &Session)>,
    ) -> PyResult<u64> {
        let sim = &mut self.sim;
        let target = sim.params().target_clusters;
        let initial = sim.clusters();
        let merges = |sim: &Simulation| initial - sim.clusters().max(target).min(initial);
        let guard = checkpoint.map(|(_, s)| &*s.guard);
        let save = |sim: &Simulation, ck: &Checkpoint| {
            write_checkpoint(ck.file(), CHECKPOINT_MODEL, &sim.snapshot())
                .map_err(|e| ck.write_error(e))
        };
        let drawn = |e: OutputError| Animate::error(animate, e);
        let total = initial.saturating_sub(target);
        let (made, failure) = interruptible_guarded(py, progress, total, guard, |shared| {
            let mut stopped = None;
            let mut animation = match animate {
                Some(a) => Some(
                    Animation::start(
                        sim,
                        sim.seed(),
                        &a.path,
                        a.side.unwrap_or(ANIMATION_DEFAULT_SIDE),
                    )
                    .map_err(drawn)?,
                ),
                None => None,
            };
            let every = animate
                .and_then(|a| a.every)
                .unwrap_or(ANIMATION_DEFAULT_EVERY);
            let mut k = 0;
            shared.done.store(merges(sim), Ordering::Relaxed);
            while !sim.is_done() {
                let next = honour(checkpoint, &shared.stop, |ck| save(sim, ck))?;
                if let ControlFlow::Break(r) = next {
                    stopped = r;
                    break;
                }
                sim.sweep();
                k += 1;
                if let Some(a) = animation.as_mut()
                    && Animation::due(sim, every)
                {
                    a.frame(sim).map_err(drawn)?;
                }
                shared.done.store(merges(sim), Ordering::Relaxed);
            }
            // An interrupted run raises KeyboardInterrupt: its animation is dropped unwritten.
            if let Some(a) = animation
                && !shared.stop.load(Ordering::Relaxed)
                && stopped.is_none()
            {
                a.finish().map_err(drawn)?;
            }
            Ok::<_, PyErr>((k, stopped))
        })?;
        let at = || {
            let (sweeps, clusters) = (sim.sweeps(), sim.clusters());
            format!("after sweep {sweeps} ({clusters} clusters)")
        };
        conclude(py, made, failure, checkpoint, |ck| save(sim, ck), at)
    }

    /// Every particle's site (int64, (N, D)) and cluster id (int64, (N,)), in the order of
    /// the binary's `particles.csv`.
    fn particles<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let sim = &self.sim;
        let l = sim.lattice();
        let d = l.dim();
        let n = sim.particles() as usize;
        let mut x = Vec::with_capacity(n * d);
        let mut cluster = Vec::with_capacity(n);
        ::dlca::output::each_particle(sim, |id, k| -> Result<(), ()> {
            x.extend((0..d).map(|a| l.coord(k, a) as i64));
            cluster.push(i64::from(id));
            Ok(())
        })
        .map_err(|()| run_error("reading the particles"))?;
        let x = Array2::from_shape_vec((cluster.len(), d), x).map_err(run_error)?;
        Ok((
            x.into_pyarray(py).into_any(),
            Array1::from(cluster).into_pyarray(py).into_any(),
        ))
    }

    fn per_sweep<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let r = self.sim.records().sweeps();
        let mut c = Columns::default()
            .add(py, "sweep", r.iter().map(|s| s.sweep).collect())
            .add(py, "clusters", r.iter().map(|s| s.clusters).collect())
            .add(py, "largest", r.iter().map(|s| s.largest).collect());
        if self.sim.params().timing {
            c = c.add(
                py,
                "seconds",
                r.iter().map(|s| s.seconds.unwrap_or(0.0)).collect(),
            );
        }
        c.into_dict(py)
    }

    fn sizes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let h = size_distribution(&self.sim);
        Columns::default()
            .add(py, "size", h.iter().map(|(s, _)| s).collect())
            .add(py, "count", h.iter().map(|(_, c)| c).collect())
            .into_dict(py)
    }

    fn result(&self, py: Python<'_>) -> PyResult<Py<DlcaResult>> {
        let sim = &self.sim;
        let measures = sim.params().gyration.then(|| gyration(sim));
        let m = ::dlca::output::manifest(sim, sim.seed(), &self.clock, measures.as_deref())
            .map_err(run_error)?;
        let out = Bound::new(py, DlcaResult {})?;
        set_manifest(out.as_any(), &m)?;
        let (x, cluster) = self.particles(py)?;
        out.setattr("positions", x)?;
        out.setattr("cluster", cluster)?;
        out.setattr("per_sweep", self.per_sweep(py)?)?;
        out.setattr("sizes", self.sizes(py)?)?;
        let g = match &measures {
            Some(ms) => Columns::default()
                .add(py, "cluster", ms.iter().map(|c| i64::from(c.id)).collect())
                .add(py, "size", ms.iter().map(|c| c.size).collect())
                .add(
                    py,
                    "radius_of_gyration",
                    ms.iter().map(|c| c.radius_of_gyration).collect(),
                )
                .add(py, "wraps", ms.iter().map(|c| c.wraps).collect())
                .into_dict(py)?
                .into_any(),
            None => py.None().into_bound(py),
        };
        out.setattr("gyration", g)?;
        let hist = if !sim.params().records_histograms() {
            py.None().into_bound(py)
        } else {
            let (mut s, mut c, mut k) = (Vec::new(), Vec::new(), Vec::new());
            for (sweep, h) in sim.records().histograms() {
                for (candidates, moves) in h.iter() {
                    s.push(*sweep);
                    c.push(candidates);
                    k.push(moves);
                }
            }
            Columns::default()
                .add(py, "sweep", s)
                .add(py, "candidates", c)
                .add(py, "moves", k)
                .into_dict(py)?
                .into_any()
        };
        out.setattr("histogram", hist)?;
        Ok(out.unbind())
    }
}

/// The result of :func:`aggsim.dlca` (or :meth:`DlcaLattice.result`): the final state, its
/// history and every result of the ``dlca`` binary's ``run.json``.
///
/// Attributes
/// ----------
/// positions : numpy.ndarray
///     int64, shape (N, D): every particle's lattice site, in the order of the binary's
///     ``particles.csv`` (clusters by increasing id, each cluster's sites by increasing
///     k-index).
/// cluster : numpy.ndarray
///     int64, shape (N,): each particle's cluster id (``particles.csv``'s ``cluster``).
/// per_sweep : dict[str, numpy.ndarray]
///     The binary's ``sweeps.csv`` from sweep 0: ``sweep``, ``clusters``, ``largest``
///     (uint64), and ``seconds`` (float64) with ``timing=True``.
/// sizes : dict[str, numpy.ndarray]
///     The final size distribution (``sizes.csv``): ``size``, ``count`` (uint64).
/// gyration : dict[str, numpy.ndarray] or None
///     With ``gyration=True``, ``clusters.csv``: ``cluster``, ``size``,
///     ``radius_of_gyration``, ``wraps``.
/// histogram : dict[str, numpy.ndarray] or None
///     With ``histogram=True``, ``histogram.csv``: ``sweep``, ``candidates``, ``moves``.
/// state_hash : str
///     16 hex digits over every particle's site and cluster id: the binary's for the same
///     seed and parameters.
/// particles, clusters, largest_cluster, sweeps, strategy, strategy_requested,
/// strategy_reason, moves, mean_candidates_examined, search_events
///     The results of ``run.json``; with ``gyration=True`` also ``fractal_dimension``,
///     ``fractal_dimension_stderr``, ``fit_clusters``, ``fit_r2`` (or ``fit_error``) and
///     ``wrapping_clusters``.
/// model, version, seed, threads, wall_seconds, cpu_seconds, peak_rss_bytes, provenance, params, run_json
///     The rest of ``run.json``, and the whole of it as a dict.
#[pyclass(dict, module = "aggsim")]
pub struct DlcaResult {}

#[pymethods]
impl DlcaResult {
    /// Write the ``dlca`` binary's figure of the final lattice, ``dlca.png``, to ``path``: the
    /// same file, byte for byte, as ``dlca --png`` writes for the same run (the libraries'
    /// renderer, ``dlca::figure``). The whole lattice's first two axes (a projection for
    /// d >= 3) in lattice cells, a scale bar, the sweep, clusters, particles and seed; each
    /// cluster in one of eight colour-blind-safe colours on black, neighbouring clusters always
    /// different. Drawn from :attr:`positions`, :attr:`cluster`, ``params["size"]`` and the
    /// results.
    ///
    /// Parameters
    /// ----------
    /// path : str or os.PathLike
    ///     The PNG file, written atomically.
    /// size : int or None
    ///     The raster's longer side in pixels (the binary's ``--png-size``), 16..=65536; the
    ///     axes and legend come around it. Default: a whole number of pixels per site and at
    ///     least 512, or one pixel per site up to 8192.
    #[pyo3(signature = (path, size = None))]
    fn save_png(slf: &Bound<'_, Self>, path: PathBuf, size: Option<Count>) -> PyResult<()> {
        let side = crate::figure::png_side(size)?;
        let sizes: Vec<u64> = slf.getattr("params")?.get_item("size")?.extract()?;
        let rows = crate::figure::dlca_rows(slf.as_any(), &sizes)?;
        let view = ::dlca::figure::View {
            sizes: &sizes,
            sweeps: slf.getattr("sweeps")?.extract()?,
            clusters: slf.getattr("clusters")?.extract()?,
            particles: slf.getattr("particles")?.extract()?,
            seed: slf.getattr("seed")?.extract()?,
            each: |f: &mut ::dlca::figure::Visit<'_>| {
                for &(x, y, id) in &rows {
                    f(x, y, id);
                }
            },
        };
        ::dlca::figure::write_png_of(&view, &path, side)
            .map_err(|e| crate::figure::write_error(&path, e))
    }

    fn __repr__(slf: &Bound<'_, Self>) -> PyResult<String> {
        let c: u64 = slf.getattr("clusters")?.extract()?;
        let s: u64 = slf.getattr("sweeps")?.extract()?;
        let n: u64 = slf.getattr("particles")?.extract()?;
        let hash: String = slf.getattr("state_hash")?.extract()?;
        Ok(format!(
            "<aggsim.DlcaResult: {n} particles in {c} clusters after {s} sweeps, state_hash {hash}>"
        ))
    }
}

/// Run diffusion-limited cluster-cluster aggregation to the end and return a
/// :class:`DlcaResult`.
///
/// The model and every parameter are those of the ``dlca`` binary (``dlca --help``), keyword
/// names being its flags with dashes as underscores and its defaults (from the library; see
/// :func:`aggsim.defaults`). Particles on distinct random sites of a periodic or walled
/// lattice form clusters (face-adjacent particles); each sweep moves every cluster one site in
/// a random direction, in a fresh random order, and merges it with every cluster it then
/// touches (Hawick, James & Scogings 2006, "Grid-Boxing for Spatial Simulation Performance
/// Optimisation"). The run is a pure function of (parameters, seed): its ``state_hash`` is the
/// binary's.
///
/// The model's parameters (``boundary``, ``temperature``, ``search``, ...) are keyword arguments
/// made from the library's declaration of them, listed last below; ``size``, ``fill`` and
/// ``particles`` may also be given by position.
///
/// Parameters
/// ----------
/// size : int, sequence of int or str
///     Side lengths: one for every axis, one per axis, or ``"1024x512"`` (required).
/// fill : float
///     Fraction of sites holding a particle at the start, in (0, 1). Give exactly one of
///     ``fill`` and ``particles``.
/// particles : int
///     Number of particles at the start, 1 to the number of sites.
/// dim : int or None
///     Lattice dimension, 1..=5 (default: the number of lengths in ``size``, or 2 for one
///     length, as the binary).
/// seed : int
///     Seed of every random stream (default 1).
/// progress : bool or callable
///     True prints progress (merges) to ``sys.stderr``; a callable is called as
///     ``progress(done, total)`` about twice a second (default None: quiet).
/// animate : str, os.PathLike or None
///     Write the aggregation as a GIF to this path as the run goes: the same file, byte for
///     byte, as ``dlca --animate`` writes (``dlca.gif``) for the same run. A frame of the
///     start, one every ``animate_every`` sweeps and one of the end, on one frame (the
///     lattice's first two axes), each cluster keeping its colour; no more memory than two
///     frames. An interrupted run writes no file (default None: no animation).
/// animate_every : int or None
///     Sweeps between frames (``--animate-every``), 1.. (default 10).
/// animate_size : int or None
///     Longer side of the figures in pixels (``--png-size`` with ``--animate``), 16..=16384
///     (default 512).
/// checkpoint : str, os.PathLike or None
///     A directory for the run's checkpoint (default None: no checkpoints). If it holds a
///     ``checkpoint.bin``, the run continues from it: the same parameters and seed are required
///     (else ``ValueError`` naming what differs; ``target_clusters`` and ``max_sweeps`` may change,
///     as with the binary); else the run starts afresh, creating the directory. It checkpoints
///     every ``checkpoint_interval``, and when it is stopped (Ctrl-C, SIGTERM, an exception of
///     ``progress``, memory about to run out) before the exception propagates, so the same call,
///     run again, continues it. A run that ends removes ``checkpoint.bin`` and returns as without a
///     checkpoint, with the ``state_hash`` and ``per_sweep`` of an uninterrupted run (a resumed
///     run's animation starts at the checkpoint). The files are the ``dlca`` binary's: ``dlca
///     --resume DIR`` continues a run checkpointed here, and this continues one the binary
///     checkpointed.
/// checkpoint_interval : float or None
///     Seconds of wall time between checkpoints, > 0 (default 300, the binaries'
///     ``--checkpoint-interval``); None: checkpoints only when the run is stopped.
///
/// Returns
/// -------
/// DlcaResult
///
/// Raises
/// ------
/// ValueError
///     A parameter outside its accepted range, with the binary's message.
/// KeyboardInterrupt
///     Ctrl-C, and with ``checkpoint`` SIGTERM too: the run stops after the current sweep
///     and writes its checkpoint if it has one (or use :class:`DlcaLattice` to keep the
///     state).
/// MemoryError
///     With ``checkpoint``: memory about to run out (the machine's or the cgroup's; the figures in
///     the message). The run writes its checkpoint and stops after the current sweep: continue it
///     on a machine with more memory.
///
/// The run releases the GIL: other Python threads run meanwhile.
#[pyfunction]
#[pyo3(signature = (
    size,
    fill = None,
    particles = None,
    *,
    dim = None,
    seed = 1,
    progress = None,
    animate = None,
    animate_every = None,
    animate_size = None,
    checkpoint = None,
    checkpoint_interval = Some(crate::checkpoint::DEFAULT_INTERVAL),
    **params,
))]
#[allow(clippy::too_many_arguments)]
pub fn dlca(
    py: Python<'_>,
    size: &Bound<'_, PyAny>,
    fill: Option<f64>,
    particles: Option<Count>,
    dim: Option<usize>,
    seed: u64,
    progress: Option<&Bound<'_, PyAny>>,
    animate: Option<PathBuf>,
    animate_every: Option<Count>,
    animate_size: Option<Count>,
    checkpoint: Option<PathBuf>,
    checkpoint_interval: Option<f64>,
    params: Option<&Bound<'_, PyDict>>,
) -> PyResult<Py<DlcaResult>> {
    let progress = Progress::from_arg(progress, "dlca", "merges")?;
    let animate = Animate::from_args(animate, animate_every, animate_size, "dlca")?;
    let checkpoint = Checkpoint::from_args(checkpoint, checkpoint_interval)?;
    let p = self::params("dlca", size, (fill, particles, dim), params)?;
    let Some(ck) = checkpoint else {
        let mut run = Run::new(py, p, seed)?;
        run.until_done(py, &progress, animate.as_ref(), None)?;
        return run.result(py);
    };
    let mut run = if ck.exists() {
        Run::resume(py, &ck, p, seed)?
    } else {
        ck.create_dir()?;
        Run::new(py, p, seed)?
    };
    let reserve = ::dlca::sim::checkpoint_reserve_bytes(run.sim.particles());
    let session = ck.start(py, reserve)?;
    run.until_done(py, &progress, animate.as_ref(), Some((&ck, &session)))?;
    ck.finish(session, || run.result(py))
}

/// The `dlca` binary's defaults, from the library's parameter table (`size` and
/// `fill`/`particles` have none).
pub fn defaults_dict(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    let mut o = ::dlca::params::defaults();
    for required in ["size", "fill", "particles"] {
        o.remove(required);
    }
    o.insert("seed".into(), 1.into());
    crate::convert::json(py, &serde_json::Value::Object(o))
}

/// The fractal dimension of an ensemble of DLCA runs as the literature computes it: one fit of
/// ``log s = D log R_g + c`` over the clusters of every run (pooled), with the jackknife error
/// over runs (the runs are the independent units), beside the mean and standard error of the
/// runs' own fits. The keys are those of ``ensemble.json``'s ``pooled.fractal_dimension`` that
/// ``dlca --seeds ... --gyration`` writes.
///
/// Parameters
/// ----------
/// results : sequence of DlcaResult
///     Runs made with ``gyration=True`` (one per seed, same parameters).
/// fit_min_size : int, optional
///     Smallest cluster in the fit; default: the runs' ``fit_min_size``.
///
/// Returns
/// -------
/// dict
///     ``fractal_dimension``, ``fractal_dimension_stderr`` (jackknife over runs; None for one
///     run), ``stderr_method``, ``fit_stderr`` (the pooled regression's), ``fit_clusters``,
///     ``fit_min_size``, ``members``, ``per_member_mean``, ``per_member_stderr``,
///     ``per_member_fits``.
///
/// Raises
/// ------
/// ValueError
///     A run without ``gyration``, runs with different ``fit_min_size`` and none given, or
///     fewer than 3 clusters to fit.
#[pyfunction]
#[pyo3(signature = (results, fit_min_size = None))]
pub fn dlca_pooled_fit<'py>(
    py: Python<'py>,
    results: Vec<Bound<'py, DlcaResult>>,
    fit_min_size: Option<Count>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut runs = Vec::with_capacity(results.len());
    let mut sizes = Vec::new();
    for (i, r) in results.iter().enumerate() {
        let g = r.getattr("gyration")?;
        if g.is_none() {
            return Err(value_error(format!(
                "results[{i}] was run without gyration=True: it has no clusters to pool"
            )));
        }
        let ids: Vec<u32> = g
            .get_item("cluster")?
            .extract::<Vec<i64>>()?
            .iter()
            .map(|&v| v as u32)
            .collect();
        let size: Vec<u64> = g.get_item("size")?.extract()?;
        let rg: Vec<f64> = g.get_item("radius_of_gyration")?.extract()?;
        let wraps: Vec<bool> = g.get_item("wraps")?.extract()?;
        runs.push(
            (0..ids.len())
                .map(|k| ::dlca::analysis::ClusterMeasure {
                    id: ids[k],
                    size: size[k],
                    radius_of_gyration: rg[k],
                    wraps: wraps[k],
                })
                .collect::<Vec<_>>(),
        );
        sizes.push(
            r.getattr("params")?
                .get_item("fit_min_size")?
                .extract::<u64>()?,
        );
    }
    let min_size = match fit_min_size {
        Some(v) => count(PARAMS, "fit_min_size", v)?,
        None => {
            sizes.dedup();
            match sizes.as_slice() {
                [one] => *one,
                [] => return Err(value_error("results is empty: nothing to pool")),
                _ => {
                    return Err(value_error(
                        "the runs differ in fit_min_size; give fit_min_size",
                    ));
                }
            }
        }
    };
    let summary = ::dlca::output::pooled_summary(&runs, min_size).map_err(value_error)?;
    crate::convert::json(py, &summary)
}
