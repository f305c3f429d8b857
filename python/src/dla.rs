//! `aggsim.dla`: off-lattice DLA and PDLA over the `dla_pdla` library (Sosa-Herrera &
//! Rodriguez-Romo, "Variable precision distance search for random fractal cluster
//! simulations").

use crate::checkpoint::{Checkpoint, differences, raise_after_saving};
use crate::convert::{Columns, Count, count, run_error, set_manifest, value_error};
use crate::declared::set_keywords;
use crate::run::{Progress, interruptible, interruptible_guarded};
use dla_pdla::branches::Branches;
use dla_pdla::deposit::Deposit;
use dla_pdla::params::PARAMS;
use dla_pdla::sim::{GROWTH, PARENTS_FILE, POSITIONS_FILE};
use dla_pdla::{Dim, Params, SimError, Simulation, Space};
use numpy::IntoPyArray;
use numpy::ndarray::Array2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use run_io::RunClock;
use std::path::PathBuf;
use std::sync::atomic::Ordering;

/// The library's defaults, which are the `dla` binary's.
fn defaults() -> Params {
    Params::default()
}

/// Particles of `aggsim.dla` when none are given (the binary requires `--particles`): a
/// cluster of a second or so, large enough for a fractal-dimension fit.
const PARTICLES: u64 = 100_000;

/// The result of :func:`aggsim.dla`: the cluster, its growth and every result of the ``dla``
/// binary's ``run.json``.
///
/// Attributes
/// ----------
/// positions : numpy.ndarray
///     float64, shape (N, D): every particle's centre in arrival order (the seed particle
///     first, at the origin); diameters are 1.
/// parent : numpy.ndarray or None
///     int64, shape (N,): the arrival index of the particle each one stuck to, -1 for the
///     seed, as the binary's ``positions_parent.npy`` (None for a run resumed from a
///     checkpoint that recorded no parents).
/// branches : dict[str, numpy.ndarray] or None
///     The Horton-Strahler analysis of ``parent``, as the binary's ``branches.csv``: per
///     order ``order``, ``branches`` (N_k), ``particles`` (uint64), ``mean_length``
///     (float64, particles per branch), ``bifurcation_ratio`` and ``length_ratio`` (float64,
///     NaN at the highest order); the fitted ``bifurcation_ratio``,
///     ``length_ratio``, ``strahler_order``, ``trees`` and ``ratio_fit_orders`` are results
///     of ``run.json`` (below).
/// deposit, deposit_growth : dict[str, numpy.ndarray] or None
///     A deposit's profile and active zone (``substrate_width`` > 0), as the binary's
///     ``deposit.csv`` (per layer of one diameter: ``height``, ``particles``, ``density``,
///     ``trees``) and ``deposit_growth.csv`` (per block of W^(d-1) particles: ``n``,
///     ``height``, ``mean_height``, ``active_zone_width``, ``growing_trees``); the fitted
///     ``density_dimension`` and the other ``deposit_*`` results are in ``run.json``. None
///     for radial growth.
/// growth : dict[str, numpy.ndarray]
///     The growth samples (200 log-spaced sizes per decade and the final size), as the
///     binary's ``growth.csv``, same names and dtypes: ``n`` (uint64, particles),
///     ``radius_of_gyration``, ``r_ext`` (largest centre distance from the origin; both float64,
///     diameters), ``seconds`` (float64, wall time since the start of growth).
/// state_hash : str
///     16 hex digits, a hash of the positions in arrival order: the binary's for the same
///     seed and parameters (with one thread).
/// particles, radius_of_gyration, r_ext, fractal_dimension, fractal_dimension_stderr,
/// fit_points, fit_error, discarded_walkers, pdla_parallel_seconds, pdla_lock_wait_seconds,
/// pdla_phases, tree_memory_bytes, tree_point_slots, distance_map_bytes, bytes_per_particle,
/// simulation_peak_rss_bytes, output_peak_rss_bytes (None: no output stage)
///     The results of ``run.json`` (``fit_error`` only when no fit was possible, and then
///     ``fractal_dimension`` is None).
/// model, version, seed, threads, wall_seconds, cpu_seconds, peak_rss_bytes, provenance
///     The other scalars of ``run.json`` (CPU seconds and peak memory are the whole Python
///     process's).
/// params : dict
///     The validated parameters, as ``run.json`` records them.
/// run_json : dict
///     The whole manifest, as the binary would write it to ``run.json``.
#[pyclass(dict, module = "aggsim")]
pub struct DlaResult {}

#[pymethods]
impl DlaResult {
    /// Write the ``dla`` binary's figure of the cluster, ``dla.png``, to ``path``: the same
    /// file, byte for byte, as ``dla --png`` writes for the same run (the libraries' renderer,
    /// ``dla_pdla::figure``). Axes in particle diameters, a scale bar, N and the seed, and a
    /// colour bar: particles coloured by arrival order on magma (or, where a pixel spans more
    /// than a diameter, particles per pixel on a log scale); 3D to 5D as shaded spheres seen
    /// from +z. Drawn from :attr:`positions`, ``r_ext`` and ``seed``.
    ///
    /// Parameters
    /// ----------
    /// path : str or os.PathLike
    ///     The PNG file, written atomically.
    /// size : int or None
    ///     Side of the raster in pixels (the binary's ``--png-size``), 16..=65536; the axes
    ///     and legend come around it. Default: one pixel per diameter, 512 to 4096.
    #[pyo3(signature = (path, size = None))]
    fn save_png(slf: &Bound<'_, Self>, path: PathBuf, size: Option<Count>) -> PyResult<()> {
        let side = crate::figure::png_side(size)?;
        let (r_ext, seed, dim) = cluster_frame(slf)?;
        let positions = crate::figure::dla_positions(slf.as_any())?;
        let side = side.unwrap_or_else(|| dla_pdla::output::default_png_side(r_ext));
        let flat = positions.as_slice()?;
        check_dim(flat.len(), positions.as_array().ncols(), dim)?;
        dla_pdla::figure::of_positions(flat, dim, r_ext, seed)
            .and_then(|f| f.write_png(&path, side))
            .map_err(|e| crate::figure::write_error(&path, e))
    }

    /// Write the ``dla`` binary's animation of the cluster's growth, ``dla.gif``, to ``path``:
    /// the same file, byte for byte, as ``dla --animate`` writes for the same run. One frame
    /// every ``every`` particles and one of the whole cluster, all on the finished cluster's
    /// frame, as :meth:`save_png` draws them; the GIF repeats forever, 0.1 s a frame and 2 s
    /// on the last. Drawn from :attr:`positions`, which the result holds anyway: no more
    /// memory than two frames.
    ///
    /// Parameters
    /// ----------
    /// path : str or os.PathLike
    ///     The GIF file, written atomically.
    /// size : int or None
    ///     Side of the figures in pixels (``--png-size``), 16..=16384 (default 512).
    /// every : int or None
    ///     Particles between frames (``--animate-every``), 1.. (default: a hundredth of the
    ///     particles).
    ///
    /// Returns
    /// -------
    /// int
    ///     The number of frames.
    #[pyo3(signature = (path, size = None, every = None))]
    fn save_gif(
        slf: &Bound<'_, Self>,
        path: PathBuf,
        size: Option<Count>,
        every: Option<Count>,
    ) -> PyResult<u64> {
        let side = crate::figure::gif_side(size)?;
        let every = every.map(|v| count::<u64>(&[], "every", v)).transpose()?;
        if every == Some(0) {
            return Err(value_error("every = 0 is outside the accepted range 1.."));
        }
        let (r_ext, seed, dim) = cluster_frame(slf)?;
        let positions = crate::figure::dla_positions(slf.as_any())?;
        let flat = positions.as_slice()?;
        check_dim(flat.len(), positions.as_array().ncols(), dim)?;
        let total = (flat.len() / dim.max(1)) as u64;
        let side = side.unwrap_or(dla_pdla::figure::ANIMATION_DEFAULT_SIDE);
        let every = every.unwrap_or_else(|| dla_pdla::figure::default_animation_every(total));
        dla_pdla::figure::of_positions(flat, dim, r_ext, seed)
            .and_then(|f| f.write_animation(&path, side, every))
            .map_err(|e| crate::figure::write_error(&path, e))
    }

    fn __repr__(slf: &Bound<'_, Self>) -> PyResult<String> {
        let n: u64 = slf.getattr("particles")?.extract()?;
        let dim: usize = slf.getattr("params")?.get_item("dim")?.extract()?;
        let rg: f64 = slf.getattr("radius_of_gyration")?.extract()?;
        let hash: String = slf.getattr("state_hash")?.extract()?;
        Ok(format!(
            "<aggsim.DlaResult: {n} particles in {dim}D, R_g {rg:.2}, state_hash {hash}>"
        ))
    }
}

/// Grow an off-lattice DLA cluster (PDLA with ``threads`` > 1) and return it as a
/// :class:`DlaResult`.
///
/// The model and every parameter are those of the ``dla`` binary (``dla --help``), keyword
/// names being its flags with dashes as underscores; the defaults are its defaults, from the
/// library (see :func:`aggsim.defaults`). A seed particle sits at the origin; walkers
/// (balls of diameter 1) are born on a sphere just outside the cluster, jump by the
/// variable-precision distance to the cluster when far from it (Sosa-Herrera &
/// Rodriguez-Romo, "Variable precision distance search for random fractal cluster
/// simulations"), take short steps near it, and stick at exact contact. With one thread
/// the run is a pure function of (parameters, seed) and its ``state_hash`` is the binary's.
///
/// The model's parameters are keyword arguments made from the library's declaration of them,
/// listed last below; ``dim``, ``particles`` and ``threads`` may also be given by position.
///
/// Parameters
/// ----------
/// dim : int
///     Space dimension, one of {2, 3, 4, 5} (default 2).
/// particles : int
///     Particles in the final cluster, seed particle included, 1..=3000000000 in 2D and 3D,
///     1..=2500000000 in 4D and 5D (default 100000).
/// seed : int
///     Seed of every random stream (default 1).
/// threads : int
///     Walkers moving at once (PDLA), 1..=1024 (default 1, which is DLA and deterministic).
/// paper_settings : bool
///     The variable-precision paper's walk (the binary's ``--paper-settings``, whose help lists
///     the values it sets) (default False). The parameters it sets may then not be given.
/// progress : bool or callable
///     True prints progress to ``sys.stderr``; a callable is called as
///     ``progress(done, total)`` about twice a second (default None: quiet).
/// checkpoint : str, os.PathLike or None
///     A directory for the run's checkpoint (default None: no checkpoints). If it holds a
///     ``checkpoint.bin``, the run continues from it: the same parameters and seed are required
///     (else ``ValueError`` naming what differs; ``particles`` may grow); else the run starts
///     afresh, creating the directory. It checkpoints every ``checkpoint_interval``, and when it is
///     stopped (Ctrl-C, SIGTERM, an exception of ``progress``, memory about to run out) before the
///     exception propagates, so the same call, run again, continues it. A run that ends removes
///     ``checkpoint.bin`` and the ``positions.npy`` and ``growth.csv`` it needed, and returns as
///     without a checkpoint; with one thread it ends with the ``state_hash`` of an uninterrupted
///     run (with more, PDLA, a valid cluster, as PDLA never repeats itself). The files are the
///     ``dla`` binary's: ``dla --resume DIR`` continues a run checkpointed here, and this continues
///     one the binary checkpointed.
/// checkpoint_interval : float or None
///     Seconds of wall time between checkpoints, > 0 (default 300, the binaries'
///     ``--checkpoint-interval``); None: checkpoints only when the run is stopped.
///
/// Returns
/// -------
/// DlaResult
///
/// Raises
/// ------
/// ValueError
///     A parameter outside its accepted range, with the binary's message.
/// KeyboardInterrupt
///     Ctrl-C (SIGINT), and with ``checkpoint`` SIGTERM too: the run stops within a particle
///     (PDLA: at the phase's next quiescent point), writes its checkpoint if it has one, and
///     nothing is returned.
/// MemoryError
///     With ``checkpoint``: memory about to run out (the machine's or the cgroup's; the figures in
///     the message). The run writes its checkpoint and stops within a particle its checkpoint:
///     continue it on a machine with more memory.
///
/// The run releases the GIL: other Python threads run meanwhile.
#[pyfunction]
#[pyo3(signature = (
    dim = defaults().dim,
    particles = Count::Int(PARTICLES as i128),
    seed = 1,
    threads = Count::Int(defaults().threads as i128),
    *,
    paper_settings = false,
    progress = None,
    checkpoint = None,
    checkpoint_interval = Some(crate::checkpoint::DEFAULT_INTERVAL),
    **params,
))]
#[allow(clippy::too_many_arguments)]
pub fn dla(
    py: Python<'_>,
    dim: usize,
    particles: Count,
    seed: u64,
    threads: Count,
    paper_settings: bool,
    progress: Option<&Bound<'_, PyAny>>,
    checkpoint: Option<PathBuf>,
    checkpoint_interval: Option<f64>,
    params: Option<&Bound<'_, PyDict>>,
) -> PyResult<Py<DlaResult>> {
    let clock = RunClock::start();
    let checkpoint = Checkpoint::from_args(checkpoint, checkpoint_interval)?;
    let mut p = Params {
        dim,
        particles: count(PARAMS, "particles", particles)?,
        threads: count::<u64>(PARAMS, "threads", threads)? as usize,
        // The positions are returned, each particle's parent with them.
        keep_positions: true,
        connectivity: true,
        ..defaults()
    };
    let given = set_keywords(&mut p, PARAMS, "dla", POSITIONAL, params)?;
    let given = |name: &str| given.iter().any(|g| g == name);
    let params = if paper_settings {
        // The library's rule, as the binary's: the fields it sets may not be given beside it.
        p.with_paper_settings(given).map_err(value_error)?
    } else {
        p
    };
    params.validate_given(given).map_err(value_error)?;
    let progress = Progress::from_arg(progress, "dla", "particles")?;
    // The library's one run-time dimension dispatch, as in the binary.
    let ck = checkpoint.as_ref();
    dla_pdla::with_dim!(params.dim, D => grow::<D>(py, params, seed, &progress, &clock, ck), d => {
        Err(value_error(dla_pdla::ParamsError::dim(d)))
    })
}

/// Declared parameters `aggsim.dla` takes as its own arguments (by position too), not as
/// keywords of the declaration.
pub const POSITIONAL: &[&str] = &["dim", "particles", "threads"];

/// The parameter of `aggsim.dla` the declared keywords come before in its signature.
pub const KEYWORDS_BEFORE: &str = "paper_settings";

fn grow<const D: usize>(
    py: Python<'_>,
    params: Params,
    seed: u64,
    progress: &Progress,
    clock: &RunClock,
    checkpoint: Option<&Checkpoint>,
) -> PyResult<Py<DlaResult>>
where
    Dim<D>: Space<D>,
{
    let total = params.particles;
    let resuming = checkpoint.filter(|c| c.exists());
    let mut sim = match resuming {
        Some(ck) => resume::<D>(ck, &params, seed)?,
        None => Simulation::<D>::new(params, seed).map_err(|e| match e {
            SimError::Params(e) => value_error(e),
            other => run_error(other),
        })?,
    };
    match checkpoint {
        None => {
            let reached = interruptible(py, progress, total, |shared| {
                sim.run_until(&shared.stop, &|n| shared.done.store(n, Ordering::Relaxed))
            })?
            .map_err(run_error)?;
            if !reached {
                return Err(run_error("stopped before the target size"));
            }
        }
        Some(ck) => {
            if resuming.is_none() {
                ck.create_dir()?;
            }
            // The checkpoint refers to the positions streamed to DIR/positions.npy (the
            // binary's format); growth.csv streams beside them.
            sim.stream_into(&ck.dir, true).map_err(run_error)?;
            let session = ck.start(py, dla_pdla::params::CHECKPOINT_RESERVE_BYTES)?;
            let guard = &session.guard;
            let (end, failure) =
                interruptible_guarded(py, progress, total, Some(guard), |shared| {
                    sim.run_guarded(None, guard, true, &|n| {
                        shared.done.store(n, Ordering::Relaxed);
                    })
                })?;
            if let Some(e) = failure {
                let finished = end
                    .as_ref()
                    .map(Option::is_none)
                    .map_err(ToString::to_string);
                let save = || sim.write_checkpoint().map_err(|e| e.to_string());
                return Err(raise_after_saving(py, e, finished, save));
            }
            let end = end.map_err(run_error)?;
            if let Some(reason) = end {
                let at = format!("at {} of {total} particles", sim.particles());
                return Err(session.stopped(&reason, &at));
            }
            if sim.positions().is_none() {
                // Resumed from a checkpoint of the binary, which keeps no positions in memory:
                // positions.npy holds them.
                sim.sync_streams().map_err(run_error)?;
            }
        }
    }
    let m = dla_pdla::output::manifest(&sim, clock).map_err(run_error)?;
    let samples = sim.samples();
    let growth = Columns::default()
        .add(py, "n", samples.iter().map(|s| s.n).collect())
        .add(
            py,
            "radius_of_gyration",
            samples.iter().map(|s| s.radius_of_gyration).collect(),
        )
        .add(py, "r_ext", samples.iter().map(|s| s.r_ext).collect())
        .add(py, "seconds", samples.iter().map(|s| s.seconds).collect())
        .into_dict(py)?;
    let mut m = m;
    let links = sim.params().connectivity;
    let m_substrate = sim.params().substrate().map(|s| s.width);
    let (positions, parents) = match (sim.positions().is_some(), checkpoint) {
        (false, Some(ck)) => {
            let n = usize::try_from(sim.particles()).unwrap_or(0);
            let mut v = Vec::with_capacity(n);
            let mut up = Vec::with_capacity(if links { n } else { 0 });
            dla_pdla::sim::each_particle(&sim, &ck.dir, |_, p, parent| {
                v.push(*p);
                up.extend(parent);
                Ok(())
            })
            .map_err(run_error)?;
            // Read from the files: the manifest could not analyse them.
            if links {
                let b = Branches::from_parents(&up).map_err(run_error)?;
                dla_pdla::output::set_branch_results(&mut m, &b);
            }
            (v, links.then_some(up))
        }
        _ => {
            let (v, up) = sim.into_positions_and_parents();
            (
                v.ok_or_else(|| run_error("the positions were not kept"))?,
                up,
            )
        }
    };
    // The run is over (its streams closed): what only the checkpoint needed goes.
    if let Some(ck) = checkpoint {
        ck.remove(&[POSITIONS_FILE, PARENTS_FILE, GROWTH.file])?;
    }
    let branches = match &parents {
        Some(up) => {
            let b = Branches::from_parents(up).map_err(run_error)?;
            let col =
                |f: &dyn Fn(&dla_pdla::branches::Order) -> u64| b.orders.iter().map(f).collect();
            Some(
                Columns::default()
                    .add(py, "order", col(&|o| u64::from(o.order)))
                    .add(py, "branches", col(&|o| o.branches))
                    .add(py, "particles", col(&|o| o.particles))
                    .add(
                        py,
                        "mean_length",
                        b.orders.iter().map(|o| o.mean_length()).collect(),
                    )
                    .add(
                        py,
                        "bifurcation_ratio",
                        b.ratios().iter().map(|r| r.0.unwrap_or(f64::NAN)).collect(),
                    )
                    .add(
                        py,
                        "length_ratio",
                        b.ratios().iter().map(|r| r.1.unwrap_or(f64::NAN)).collect(),
                    )
                    .into_dict(py)?,
            )
        }
        None => None,
    };
    let (deposit, deposit_growth) = match (m_substrate, &parents) {
        (Some(width), Some(up)) => {
            let mut d = Deposit::new(D, width);
            for (p, &parent) in positions.iter().zip(up) {
                d.push(p, parent).map_err(run_error)?;
            }
            d.finish();
            dla_pdla::deposit::set_results(&mut m, &d);
            let trees = d.surviving_trees();
            let layers = d.layers.len();
            let profile = Columns::default()
                .add(py, "height", (0..layers).map(|k| k as f64).collect())
                .add(py, "particles", d.layers.clone())
                .add(py, "density", (0..layers).map(|k| d.density(k)).collect())
                .add(py, "trees", trees)
                .into_dict(py)?;
            let b = &d.blocks;
            let blocks = Columns::default()
                .add(py, "n", b.iter().map(|b| b.n).collect())
                .add(py, "height", b.iter().map(|b| b.height).collect())
                .add(py, "mean_height", b.iter().map(|b| b.mean_height).collect())
                .add(
                    py,
                    "active_zone_width",
                    b.iter().map(|b| b.active_zone_width).collect(),
                )
                .add(
                    py,
                    "growing_trees",
                    b.iter().map(|b| b.growing_trees).collect(),
                )
                .into_dict(py)?;
            (Some(profile), Some(blocks))
        }
        _ => (None, None),
    };
    // `Vec<[f64; D]>` becomes an (N, D) array and NumPy takes it over: no copy.
    let positions = Array2::from(positions).into_pyarray(py);
    let out = Bound::new(py, DlaResult {})?;
    set_manifest(out.as_any(), &m)?;
    out.setattr("positions", positions)?;
    out.setattr("parent", parents.map(|up| up.into_pyarray(py)))?;
    out.setattr("branches", branches)?;
    out.setattr("deposit", deposit)?;
    out.setattr("deposit_growth", deposit_growth)?;
    out.setattr("growth", growth)?;
    Ok(out.unbind())
}

/// The run checkpointed in `ck`, if this call continues it: the same parameters and seed
/// (`particles` may grow), as the binary's `--resume`.
fn resume<const D: usize>(ck: &Checkpoint, params: &Params, seed: u64) -> PyResult<Simulation<D>>
where
    Dim<D>: Space<D>,
{
    let sim =
        Simulation::<D>::resume(&ck.dir, Some(params.particles)).map_err(|e| ck.refused(e))?;
    // Python keeps the positions in memory, the binary does not: not a parameter of the run.
    let differ = differences(
        serde_json::to_value(sim.params()),
        serde_json::to_value(params),
        &[("keep_positions", None), ("connectivity", None)],
    );
    ck.check_same(differ, (sim.seed(), seed))?;
    Ok(sim)
}

/// What frames a result's figure: its `r_ext`, `seed` and dimension (`params["dim"]`).
fn cluster_frame(slf: &Bound<'_, DlaResult>) -> PyResult<(f64, u64, usize)> {
    let r_ext: f64 = slf.getattr("r_ext")?.extract()?;
    let seed: u64 = slf.getattr("seed")?.extract()?;
    let dim: usize = slf.getattr("params")?.get_item("dim")?.extract()?;
    Ok((r_ext, seed, dim))
}

/// The positions' columns are the run's dimension, and there is a particle.
fn check_dim(len: usize, cols: usize, dim: usize) -> PyResult<()> {
    if cols != dim || len == 0 {
        return Err(value_error(format!(
            "positions have {cols} columns and {} rows; the cluster is {dim}D and has a particle",
            len / cols.max(1)
        )));
    }
    Ok(())
}

/// The `dla` binary's defaults, from the library's parameter table (`particles`: this
/// module's, as the binary has none).
pub fn defaults_dict(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    let mut o = dla_pdla::params::defaults();
    o.insert("particles".into(), PARTICLES.into());
    o.insert("seed".into(), 1.into());
    crate::convert::json(py, &serde_json::Value::Object(o))
}
