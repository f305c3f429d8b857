//! `aggsim.animat` and `aggsim.AnimatWorld`: the foxes-and-rabbits animat model over the
//! `animat` library (Hawick, James & Scogings 2006, "Grid-Boxing for Spatial Simulation
//! Performance Optimisation", section II.B).

use crate::checkpoint::{Checkpoint, Session, conclude, differences, honour};
use crate::convert::{Columns, Count, count, run_error, set_manifest, value_error};
use crate::declared::{read_config, set_keywords};
use crate::figure::Animate;
use crate::run::{Progress, interruptible_guarded};
use ::animat::checkpoint::{CHECKPOINT_MODEL, Saved};
use ::animat::output::{Animation, PopulationRow, SnapshotFrame, default_animate_every};
use ::animat::params::{DEFAULT_STEPS, PARAMS};
use ::animat::{Params, World, WorldError};
use numpy::IntoPyArray;
use numpy::ndarray::Array2;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use run_io::{OutputError, RunClock, read_checkpoint, write_checkpoint};
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::sync::{Mutex, MutexGuard, TryLockError};

mod world;
pub use world::AnimatWorld;

/// Declared parameters `aggsim.animat` and `aggsim.AnimatWorld` take as their own arguments:
/// none, every model parameter is a keyword made from the declaration.
pub const POSITIONAL: &[&str] = &[];

/// The parameter of their signatures the declared keywords come before.
pub const KEYWORDS_BEFORE: &str = "timing";

/// The model's arguments: a config file, `density` and the declared keywords.
struct Args<'a, 'py> {
    /// The function's name, for errors about its keywords.
    function: &'static str,
    config: Option<PathBuf>,
    density: Option<f64>,
    keywords: Option<&'a Bound<'py, PyDict>>,
}

impl Args<'_, '_> {
    /// Defaults, then the config file, then the keywords (as the binary: defaults, config,
    /// flags), then `density`, validated with the binary's messages.
    fn params(&self) -> PyResult<Params> {
        let mut p = Params::default();
        let mut density = None;
        if let Some(path) = &self.config {
            let read = read_config(&mut p, path, &["density"])?;
            density = read.extras.into_iter().map(|(_, d)| d).next_back();
            // As the binary, whose --start-radius and --density conflict in a config file too.
            if density.is_some() && read.given.contains(&"start_radius") {
                return Err(value_error(format!(
                    "config {}: start_radius cannot be used with density (it sets the start radius)",
                    path.display()
                )));
            }
        }
        let given = set_keywords(&mut p, PARAMS, self.function, POSITIONAL, self.keywords)?;
        let radius_given = given.iter().any(|g| g == "start_radius");
        if self.density.is_some() && radius_given {
            return Err(value_error(
                "--start-radius cannot be used with --density (it sets the start radius)",
            ));
        }
        // A start radius given as an argument overrides the config file's density, as the
        // flag does on the command line.
        if let Some(d) = self.density.or(density.filter(|_| !radius_given)) {
            p.set_density(d).map_err(value_error)?;
        }
        p.validate().map_err(value_error)?;
        Ok(p)
    }
}

/// A world, the population rows so far and the clock (`run.json`'s times count from the
/// world's creation).
struct Run {
    world: World,
    rows: Vec<PopulationRow>,
    clock: RunClock,
    /// Whether the rows record the search's seconds and work (`timing`).
    timing: bool,
}

impl Run {
    fn new(py: Python<'_>, args: &Args<'_, '_>, seed: u64, timing: bool) -> PyResult<Self> {
        let clock = RunClock::start();
        let params = args.params()?;
        // Placing a large population takes a while: without the GIL.
        let world = py.detach(|| World::new(params, seed));
        let mut world = world.map_err(|e| match e {
            WorldError::Params(e) => value_error(e),
            other => value_error(other),
        })?;
        world.set_timing(timing);
        let rows = vec![PopulationRow::of(&world, Default::default())];
        Ok(Run {
            world,
            rows,
            clock,
            timing,
        })
    }

    /// The run checkpointed in `ck`, if this call continues it: the same parameters and seed,
    /// and at most `steps` steps made (`steps` may grow), as the binary's `--resume`.
    fn resume(
        py: Python<'_>,
        ck: &Checkpoint,
        args: &Args<'_, '_>,
        seed: u64,
        timing: bool,
        steps: u64,
    ) -> PyResult<Self> {
        let clock = RunClock::start();
        let params = args.params()?;
        let saved: Saved =
            read_checkpoint(ck.file(), CHECKPOINT_MODEL).map_err(|e| ck.refused(e))?;
        let differ = differences(
            serde_json::to_value(saved.world.params()),
            serde_json::to_value(&params),
            &[],
        );
        ck.check_same(differ, (saved.world.seed(), seed))?;
        if saved.world.steps() > steps {
            return Err(ck.refused(format!(
                "the saved run has made {} steps, more than steps = {steps}",
                saved.world.steps()
            )));
        }
        let Saved { world, rows } = saved;
        let mut world = py
            .detach(|| World::restore(world))
            .map_err(|e| ck.refused(e))?;
        if rows.last().map(|r| r.step) != Some(world.steps()) {
            return Err(ck.refused(format!(
                "the population rows do not end at step {}",
                world.steps()
            )));
        }
        world.set_timing(timing);
        Ok(Run {
            world,
            rows,
            clock,
            timing,
        })
    }

    /// Up to `n` steps, fewer once every animat has died (as the binary); returns the steps
    /// made. With `animate` (and the frame's half-side in cells) the run writes the binary's
    /// `animat.gif` for these steps to its path, unless it is interrupted. With `checkpoint`
    /// the run honours its session's requests between steps, writing `checkpoint.bin` as the
    /// binary does; a stop raises after the checkpoint.
    fn steps(
        &mut self,
        py: Python<'_>,
        n: u64,
        progress: &Progress,
        animate: Option<(&Animate, Option<i64>)>,
        checkpoint: Option<(&Checkpoint, &Session)>,
    ) -> PyResult<u64> {
        let (world, rows) = (&mut self.world, &mut self.rows);
        let drawn = |e: OutputError| Animate::error(animate.map(|(a, _)| a), e);
        let save = |world: &World, rows: &[PopulationRow], ck: &Checkpoint| {
            let saved = Saved {
                world: world.snapshot(),
                rows: rows.to_vec(),
            };
            write_checkpoint(ck.file(), CHECKPOINT_MODEL, &saved).map_err(|e| ck.write_error(e))
        };
        let guard = checkpoint.map(|(_, s)| &*s.guard);
        let (made, failure) =
            interruptible_guarded(py, progress, n, guard, |shared| -> PyResult<_> {
                let mut animation = match animate {
                    Some((a, radius)) => Some(
                        Animation::start(
                            world,
                            &a.path,
                            SnapshotFrame::new(world.params(), radius, a.side),
                            a.every.unwrap_or_else(|| default_animate_every(n)),
                        )
                        .map_err(drawn)?,
                    ),
                    None => None,
                };
                let mut k = 0;
                let mut stopped = None;
                while k < n {
                    let next = honour(checkpoint, &shared.stop, |ck| save(world, rows, ck))?;
                    if let ControlFlow::Break(r) = next {
                        stopped = r;
                        break;
                    }
                    if world.foxes() + world.rabbits() == 0 {
                        break;
                    }
                    let s = world.step();
                    rows.push(PopulationRow::of(world, s));
                    if let Some((_, session)) = checkpoint {
                        let reserve = ::animat::checkpoint::reserve_bytes(world, rows.len());
                        session.memory.reserve.store(reserve, Ordering::Relaxed);
                    }
                    if let Some(a) = animation.as_mut() {
                        a.step(world).map_err(drawn)?;
                    }
                    k += 1;
                    shared.done.store(k, Ordering::Relaxed);
                }
                // A stopped run raises KeyboardInterrupt: its animation is dropped unwritten.
                if let Some(a) = animation
                    && !shared.stop.load(Ordering::Relaxed)
                    && stopped.is_none()
                {
                    a.finish(world).map_err(drawn)?;
                }
                Ok((k, stopped))
            })?;
        conclude(
            py,
            made,
            failure,
            checkpoint,
            |ck| save(world, rows, ck),
            || format!("after step {}", world.steps()),
        )
    }

    /// The live animats' columns, named and typed as the binary's positions files
    /// (`animat::output::SCHEMA`): positions (int64, (M, 2)), species codes, id, age, hunger
    /// (int64 each).
    fn animats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let w = &self.world;
        let n = (w.foxes() + w.rabbits()) as usize;
        let mut pos = Vec::with_capacity(2 * n);
        let (mut species, mut id, mut age, mut hunger) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for a in w.animats() {
            pos.extend_from_slice(&a.pos);
            species.push(a.species.code() as i64);
            id.push(a.id as i64);
            age.push(i64::from(a.age));
            hunger.push(i64::from(a.hunger));
        }
        let pos = Array2::from_shape_vec((id.len(), 2), pos).map_err(run_error)?;
        let d = Columns::default()
            .add(py, "id", id)
            .add(py, "species", species)
            .add(py, "age", age)
            .add(py, "hunger", hunger)
            .into_dict(py)?;
        d.set_item("positions", pos.into_pyarray(py))?;
        Ok(d)
    }

    fn populations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let r = &self.rows;
        let mut c = Columns::default()
            .add(py, "step", r.iter().map(|x| x.step).collect())
            .add(py, "foxes", r.iter().map(|x| x.foxes).collect())
            .add(py, "rabbits", r.iter().map(|x| x.rabbits).collect());
        if self.timing {
            c = c
                .add(
                    py,
                    "search_seconds",
                    r.iter().map(|x| x.search_seconds).collect(),
                )
                .add(
                    py,
                    "distance_evaluations",
                    r.iter().map(|x| x.distance_evals).collect(),
                );
        }
        c.into_dict(py)
    }

    fn result(&self, py: Python<'_>) -> PyResult<Py<AnimatResult>> {
        let w = &self.world;
        let m = ::animat::output::manifest(w, w.seed(), &self.clock).map_err(run_error)?;
        let out = Bound::new(py, AnimatResult {})?;
        set_manifest(out.as_any(), &m)?;
        for (k, v) in self.animats(py)?.iter() {
            out.setattr(k.cast::<PyString>()?, v)?;
        }
        out.setattr("populations", self.populations(py)?)?;
        Ok(out.unbind())
    }
}

/// The result of :func:`aggsim.animat` (or :meth:`AnimatWorld.result`): populations per step,
/// the final animats and every result of the ``animat`` binary's ``run.json``.
///
/// Attributes
/// ----------
/// populations : dict[str, numpy.ndarray]
///     The binary's ``populations.csv`` from step 0: ``step``, ``foxes``, ``rabbits``
///     (uint64), and with ``timing=True`` ``search_seconds`` and ``distance_evaluations``.
/// positions : numpy.ndarray
///     int64, shape (M, 2): the cell of every live animat at the end, by increasing id.
/// id : numpy.ndarray
///     int64, shape (M,): every live animat's id.
/// species : numpy.ndarray
///     int64, shape (M,): :data:`aggsim.FOX` (0) or :data:`aggsim.RABBIT` (1); the names by
///     code are :data:`aggsim.SPECIES`.
/// age, hunger : numpy.ndarray
///     int64, shape (M,): steps lived, and (foxes) steps since the last meal; names and dtypes
///     as the binary's ``positions.csv`` and ``positions_<name>.npy``.
/// state_hash : str
///     16 hex digits over every live animat: the binary's for the same seed and parameters.
/// steps, foxes, rabbits, distance_evaluations, grid_box, queries
///     The results of ``run.json``.
/// model, version, seed, threads, wall_seconds, cpu_seconds, peak_rss_bytes, provenance, params, run_json
///     The rest of ``run.json``, and the whole of it as a dict.
#[pyclass(dict, module = "aggsim")]
pub struct AnimatResult {}

#[pymethods]
impl AnimatResult {
    /// Write the ``animat`` binary's snapshot of the final world to ``path``: the same file,
    /// byte for byte, as the binary's last ``snapshot_NNNNNN.png`` (``--snapshot-every``) for
    /// the same run and flags (the libraries' renderer, ``animat::output::SnapshotFrame``).
    /// The run's fixed frame, the square of half-side ``frame_radius`` cells around the origin,
    /// with axes in cells, a scale bar, the step, populations and seed, animats outside the
    /// frame counted in the header, and a key: foxes vermillion, rabbits blue, on white.
    /// Drawn from :attr:`positions`, :attr:`species`, ``params["start_radius"]`` and the
    /// results.
    ///
    /// Parameters
    /// ----------
    /// path : str or os.PathLike
    ///     The PNG file, written atomically.
    /// size : int or None
    ///     Side of the raster in pixels (the binary's ``--png-size``), 16..=65536; the axes
    ///     and legend come around it. Default: a whole number of pixels per cell and at least
    ///     512, or one pixel per cell up to 1024.
    /// frame_radius : int or None
    ///     Half the frame's side in cells (``--frame-radius``), 1.. (default: three start
    ///     radii).
    #[pyo3(signature = (path, size = None, frame_radius = None))]
    fn save_png(
        slf: &Bound<'_, Self>,
        path: PathBuf,
        size: Option<Count>,
        frame_radius: Option<Count>,
    ) -> PyResult<()> {
        let side = crate::figure::png_side(size)?;
        let radius = crate::figure::frame_radius(frame_radius)?;
        let start_radius: i64 = slf.getattr("params")?.get_item("start_radius")?.extract()?;
        let rows = crate::figure::animat_rows(slf.as_any())?;
        let census = ::animat::output::Census {
            steps: slf.getattr("steps")?.extract()?,
            foxes: slf.getattr("foxes")?.extract()?,
            rabbits: slf.getattr("rabbits")?.extract()?,
            seed: slf.getattr("seed")?.extract()?,
        };
        let frame = ::animat::output::SnapshotFrame::for_start_radius(start_radius, radius, side);
        let (raster, outside) = frame.raster_of(|| rows.iter().copied());
        frame
            .figure_of(census, &raster, outside)
            .write_png(&path)
            .map_err(|e| crate::figure::write_error(&path, e.into()))
    }

    fn __repr__(slf: &Bound<'_, Self>) -> PyResult<String> {
        let s: u64 = slf.getattr("steps")?.extract()?;
        let f: u64 = slf.getattr("foxes")?.extract()?;
        let r: u64 = slf.getattr("rabbits")?.extract()?;
        let hash: String = slf.getattr("state_hash")?.extract()?;
        Ok(format!(
            "<aggsim.AnimatResult: {f} foxes, {r} rabbits after {s} steps, state_hash {hash}>"
        ))
    }
}

/// Run the predator-prey animat model and return an :class:`AnimatResult`.
///
/// The model and every parameter are those of the ``animat`` binary (``animat --help`` and
/// its config file, data/animat-default.toml), keyword names being its flags with dashes as
/// underscores; a parameter not given takes the config file's value (``config``) or the
/// default, from the library (see :func:`aggsim.defaults`). Foxes and rabbits live one per cell on the unbounded
/// integer plane; every step each runs the first rule of its species' priority list whose
/// condition holds (Hawick, James & Scogings 2006, "Grid-Boxing for Spatial Simulation
/// Performance Optimisation", section II.B). The run is a pure function of (parameters, seed):
/// its ``state_hash`` is the binary's.
///
/// The model's parameters (``foxes``, ``vision``, ...) are keyword arguments
/// made from the library's declaration of them, listed last below;
/// ``aggsim.defaults("animat")`` lists every default.
///
/// Parameters
/// ----------
/// steps : int
///     Steps to run (default 1000); the run ends early when every animat has died.
/// seed : int
///     Seed of every random stream (default 1).
/// config : str or path or None
///     A TOML file of model parameters (keys as in data/animat-default.toml, dashes or
///     underscores), read as the binary's ``--config``; the arguments override it.
/// density : float or None
///     Start density in animats per cell, in (0, 0.5]: sets ``start_radius`` to
///     ceil(sqrt(animats / (pi density))) (default None: the start radius is given).
/// timing : bool
///     Record the perception queries' seconds and distance evaluations per step (default
///     False).
/// progress : bool or callable
///     True prints progress (steps) to ``sys.stderr``; a callable is called as
///     ``progress(done, total)`` about twice a second (default None: quiet).
/// animate : str, os.PathLike or None
///     Write the world as a GIF to this path as the run goes: the same file, byte for byte,
///     as ``animat --animate`` writes (``animat.gif``) for the same run. The world at the
///     start, every ``animate_every`` steps and at the end, all on one fixed frame (as
///     :meth:`AnimatResult.save_png` draws it); no more memory than two frames. An
///     interrupted run writes no file (default None: no animation).
/// animate_every : int or None
///     Steps between frames (``--animate-every``), 1.. (default: a hundredth of ``steps``).
/// animate_size : int or None
///     Side of the figures in pixels (``--png-size`` with ``--animate``), 16..=16384
///     (default: a whole number of pixels per cell and at least 512, or one pixel per cell up
///     to 1024).
/// frame_radius : int or None
///     Half the frame's side in cells (``--frame-radius``), 1.. (default: three start radii).
/// checkpoint : str, os.PathLike or None
///     A directory for the run's checkpoint (default None: no checkpoints). If it holds a
///     ``checkpoint.bin``, the run continues from it: the same parameters and seed are required
///     (else ``ValueError`` naming what differs; ``steps`` may grow); else the run starts afresh,
///     creating the directory. It checkpoints every ``checkpoint_interval``, and when it is stopped
///     (Ctrl-C, SIGTERM, an exception of ``progress``, memory about to run out) before the
///     exception propagates, so the same call, run again, continues it. A run that ends removes
///     ``checkpoint.bin`` and returns as without a checkpoint, with the ``state_hash`` and
///     ``populations`` of an uninterrupted run (a resumed run's animation starts at the
///     checkpoint). The files are the ``animat`` binary's: ``animat --resume DIR`` continues a run
///     checkpointed here, and this continues one the binary checkpointed.
/// checkpoint_interval : float or None
///     Seconds of wall time between checkpoints, > 0 (default 300, the binaries'
///     ``--checkpoint-interval``); None: checkpoints only when the run is stopped.
///
/// Returns
/// -------
/// AnimatResult
///
/// Raises
/// ------
/// ValueError
///     A parameter outside its accepted range, with the binary's message.
/// KeyboardInterrupt
///     Ctrl-C, and with ``checkpoint`` SIGTERM too: the run stops after the current step and
///     writes its checkpoint if it has one (or use :class:`AnimatWorld` to keep the state).
/// MemoryError
///     With ``checkpoint``: memory about to run out (the machine's or the cgroup's; the figures in
///     the message). The run writes its checkpoint and stops after the current step: continue it on
///     a machine with more memory.
///
/// The run releases the GIL: other Python threads run meanwhile.
#[pyfunction]
#[pyo3(signature = (
    steps = Count::Int(i128::from(DEFAULT_STEPS)),
    seed = 1,
    *,
    config = None,
    density = None,
    timing = false,
    progress = None,
    animate = None,
    animate_every = None,
    animate_size = None,
    frame_radius = None,
    checkpoint = None,
    checkpoint_interval = Some(crate::checkpoint::DEFAULT_INTERVAL),
    **params,
))]
#[allow(clippy::too_many_arguments)]
pub fn animat(
    py: Python<'_>,
    steps: Count,
    seed: u64,
    config: Option<PathBuf>,
    density: Option<f64>,
    timing: bool,
    progress: Option<&Bound<'_, PyAny>>,
    animate: Option<PathBuf>,
    animate_every: Option<Count>,
    animate_size: Option<Count>,
    frame_radius: Option<Count>,
    checkpoint: Option<PathBuf>,
    checkpoint_interval: Option<f64>,
    params: Option<&Bound<'_, PyDict>>,
) -> PyResult<Py<AnimatResult>> {
    let steps = count(&[], "steps", steps)?;
    let checkpoint = Checkpoint::from_args(checkpoint, checkpoint_interval)?;
    let progress = Progress::from_arg(progress, "animat", "steps")?;
    let animate = Animate::from_args(animate, animate_every, animate_size, "animat")?;
    let frame_radius = crate::figure::frame_radius(frame_radius)?;
    if frame_radius.is_some() && animate.is_none() {
        return Err(value_error(
            "frame_radius frames the animation written to animate; give animate a path (for \
             example animate=\"animat.gif\")",
        ));
    }
    let args = Args {
        function: "animat",
        config,
        density,
        keywords: params,
    };
    let animate = animate.as_ref().map(|a| (a, frame_radius));
    let Some(ck) = checkpoint else {
        let mut run = Run::new(py, &args, seed, timing)?;
        run.steps(py, steps, &progress, animate, None)?;
        return run.result(py);
    };
    let mut run = if ck.exists() {
        Run::resume(py, &ck, &args, seed, timing, steps)?
    } else {
        ck.create_dir()?;
        Run::new(py, &args, seed, timing)?
    };
    let session = ck.start(
        py,
        ::animat::checkpoint::reserve_bytes(&run.world, run.rows.len()),
    )?;
    let more = steps - run.world.steps();
    run.steps(py, more, &progress, animate, Some((&ck, &session)))?;
    ck.finish(session, || run.result(py))
}

/// The `animat` binary's defaults, from the library's parameter declaration.
pub fn defaults_dict(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    let mut o = ::animat::params::defaults();
    o.insert("steps".into(), DEFAULT_STEPS.into());
    o.insert("seed".into(), 1.into());
    o.insert("timing".into(), false.into());
    crate::convert::json(py, &serde_json::Value::Object(o))
}
