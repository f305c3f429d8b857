//! The simulation that ties the pieces together: [`Simulation`] owns the cluster, the growth
//! accounting, the serial walk and the PDLA statistics, grows serially (one walker, a pure
//! function of `(Params, seed)`) up to `serial_until` or the end, then in parallel (PDLA),
//! writes and resumes checkpoints, and fits the fractal dimension.
//!
//! | module | owns |
//! |---|---|
//! | `growth` | what a stored particle changes: count, `R_ext`, `R_g`, hash, samples |
//! | `serial` | serial DLA: one walker at a time on one stream |
//! | `pdla` | PDLA: threads on one shared tree, the shared log, the re-check, phases |
//! | `checkpoint` | the checkpoint format, writing and rebuilding a run from it |
//!
//! Invariant: `growth.n` particles are stored in `cluster`, in the order `growth` accounted
//! for them.

mod checkpoint;
mod growth;
mod particles;
mod pdla;
mod ring;
mod serial;
#[cfg(test)]
mod tests;

pub use self::checkpoint::{CHECKPOINT_FILE, CHECKPOINT_MODEL, PARENTS_FILE, POSITIONS_FILE};
pub use self::growth::{GROWTH, GROWTH_COLUMNS, SAMPLES_PER_DECADE, Sample};
pub use self::particles::{each_particle, each_position};
pub use self::pdla::{DiscardGuard, MAX_CONSECUTIVE_DISCARDS, OVERLAP_DISTANCE, PURPOSE_PDLA};
pub use self::serial::PURPOSE_WALK;
pub use crate::error::SimError;
pub use crate::space::MAP_JUMP_MIN;
pub use crate::walker::{FAR_FIELD_MARGIN, Walker, direction, first_contact};

use self::growth::{Growth, Streams};
use self::pdla::PdlaStats;
use self::serial::Serial;
use crate::cluster::Cluster;
use crate::params::{Params, ParamsError};
use crate::space::{Dim, Space};
use core_lattice::Fit;
use run_io::NpyWriter;
use run_io::guard::{Guard, Request, StopReason};
use spatial::orthtree::Orthtree;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// A DLA/PDLA run in `D` dimensions (any `D` with `Dim<D>: Space<D>`), a pure function of
/// `(Params, seed)` for one thread.
#[derive(Debug)]
pub struct Simulation<const D: usize> {
    params: Params,
    seed: u64,
    cluster: Cluster<D>,
    growth: Growth<D>,
    serial: Serial<D>,
    pdla: PdlaStats,
    /// Parallel phases run so far (each draws from its own random streams).
    pdla_rounds: u32,
    /// The directory the run streams into ([`Simulation::stream_into`]), if any.
    stream_dir: Option<PathBuf>,
    /// The `positions.npy` a resumed run was rebuilt from, until it streams again.
    resumed_from: Option<PathBuf>,
    /// The seeds of a seed set, until the run streams them ([`stream_into`](Self::stream_into)),
    /// for a run that keeps no positions in memory.
    seeds: Vec<[f64; D]>,
}

impl<const D: usize> Simulation<D>
where
    Dim<D>: Space<D>,
{
    /// A cluster holding the seed particle at the origin, or, on a substrate, an empty
    /// deposit.
    pub fn new(params: Params, seed: u64) -> Result<Self, SimError> {
        params.validate()?;
        if params.dim != D {
            return Err(SimError::DimMismatch(D, params.dim));
        }
        let mut cluster = Cluster::new(&params)?;
        let mut growth = Growth::new(&params);
        let mut initial = Vec::new();
        match &params.seed_set {
            Some(set) => {
                let seeds = crate::seeds::read::<D>(Path::new(&set.0))
                    .map_err(|e| SimError::Params(ParamsError::SeedSet(e)))?;
                if seeds.len() as u64 > params.particles {
                    return Err(SimError::Params(ParamsError::SeedSet(format!(
                        "--seed-set {}: {} seeds, more than --particles {}",
                        set.0,
                        seeds.len(),
                        params.particles
                    ))));
                }
                if let Some(s) = params.substrate() {
                    let half = 0.5 * s.width;
                    if let Some(p) = seeds.iter().find(|p| {
                        p[D - 1] < 0.0 || p[..D - 1].iter().any(|&x| x < -half || x >= half)
                    }) {
                        return Err(SimError::Params(ParamsError::SeedSet(format!(
                            "--seed-set {}: the seed at {p:?} is not in the strip [-{half}, {half}) on or above the substrate (height >= 0)",
                            set.0
                        ))));
                    }
                }
                for p in &seeds {
                    growth.add(&mut cluster, *p, None, params.particles)?;
                }
                initial = seeds;
            }
            None if params.substrate().is_none() => {
                growth.add(&mut cluster, [0.0; D], None, params.particles)?;
            }
            None => {}
        }
        Ok(Simulation {
            serial: Serial::new(&params, seed),
            params,
            seed,
            cluster,
            growth,
            pdla: PdlaStats::default(),
            pdla_rounds: 0,
            stream_dir: None,
            resumed_from: None,
            seeds: initial,
        })
    }

    /// Grow the cluster to `params.particles`, calling `progress(n)` about every 1024
    /// particles.
    pub fn run_with(&mut self, progress: &(dyn Fn(u64) + Sync)) -> Result<(), SimError> {
        self.run_until(&AtomicBool::new(false), progress)
            .map(|_| ())
    }

    /// Grow the cluster towards `params.particles`, calling `progress(n)` about every 1024
    /// particles, and return early once `stop` is set (by another thread or from `progress`):
    /// serially after the particle being grown, in PDLA at the phase's next quiescent point.
    /// Returns whether the target was reached. The run stays valid either way, and a later
    /// call continues it: with one thread, a run stopped and continued any number of times
    /// ends as an uninterrupted one (the same `state_hash`). For front ends that must stay
    /// responsive (the Python bindings stop on Ctrl-C this way).
    pub fn run_until(
        &mut self,
        stop: &AtomicBool,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<bool, SimError> {
        let target = self.params.particles;
        while self.growth.n < self.serial_to() {
            if stop.load(Ordering::Relaxed) {
                return Ok(false);
            }
            self.add_one()?;
            if self.growth.n % 1024 == 0 {
                progress(self.growth.n);
            }
        }
        if self.growth.n < target {
            self.grow_parallel(target, stop, progress)?;
        }
        progress(self.growth.n);
        Ok(self.growth.n == target)
    }

    /// The size up to which the run grows with one walker: the target with one thread,
    /// `serial_until` (at least the seed particle) with more.
    fn serial_to(&self) -> u64 {
        let target = self.params.particles;
        if self.params.threads == 1 {
            target
        } else {
            self.params.serial_until.clamp(1, target)
        }
    }

    /// PDLA up to `until`, or to a quiescent point once `halt` is set.
    fn grow_parallel(
        &mut self,
        until: u64,
        halt: &AtomicBool,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<(), SimError> {
        pdla::grow_parallel(
            &self.params,
            self.seed,
            &mut self.pdla_rounds,
            until,
            halt,
            &mut self.cluster,
            &mut self.growth,
            &mut self.pdla,
            progress,
        )
    }

    /// Grow to `params.particles` without progress reports.
    pub fn run(&mut self) -> Result<(), SimError> {
        self.run_with(&|_| {})
    }

    /// Release one walker and grow the cluster by the particle it becomes (serial DLA).
    pub fn add_one(&mut self) -> Result<[f64; D], SimError> {
        self.serial
            .add_one(&self.params, &mut self.cluster, &mut self.growth)
    }

    /// Grows with a checkpoint (see [`write_checkpoint`](Self::write_checkpoint)) every
    /// `every` particles and at the end, stopping early, after a final checkpoint, once `stop`
    /// is set (a signal handler sets it). Needs the positions streamed
    /// ([`stream_into`](Self::stream_into)). Returns whether the run reached its target.
    ///
    /// With one thread a resumed run ends with the same `state_hash` as an uninterrupted one.
    /// With more (PDLA), each stretch of `every` particles is one parallel phase that ends at a
    /// quiescent point (every stored particle applied everywhere, walkers on their way
    /// dropped), where the checkpoint is taken; a resumed PDLA run is a valid PDLA cluster (no
    /// overlap, every particle in contact), not a copy of the uninterrupted one, which PDLA
    /// never is.
    pub fn run_checkpointed(
        &mut self,
        every: u64,
        stop: &AtomicBool,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<bool, SimError> {
        let poll = || {
            if stop.load(Ordering::Relaxed) {
                Request::Stop(StopReason::Signal(run_io::guard::PROGRAM_STOP))
            } else {
                Request::None
            }
        };
        let stopped = self.grow_polled(Some(every), stop, &poll, true, progress)?;
        Ok(stopped.is_none())
    }

    /// Grows to the target while honouring `guard`'s requests (a front end's timed
    /// checkpoints, signals and memory watch: `run_io::guard`): a requested checkpoint is
    /// written and the run goes on; a requested stop writes one and returns its reason. With
    /// `every`, a checkpoint every `every` particles and one at the end as well. With `write`
    /// false nothing is written (a stop just stops). Returns `None` when the target was
    /// reached. The same `state_hash` as [`run`](Self::run) with one thread, whenever the
    /// checkpoints fall; with more, a checkpoint ends the parallel phase at a quiescent point,
    /// as in [`run_checkpointed`](Self::run_checkpointed).
    ///
    /// # Errors
    /// `every == Some(0)`, `write` without the positions streamed, I/O errors.
    pub fn run_guarded(
        &mut self,
        every: Option<u64>,
        guard: &Guard,
        write: bool,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Option<StopReason>, SimError> {
        self.grow_polled(every, guard.flag(), &|| guard.take(), write, progress)
    }

    /// The loop of [`run_checkpointed`](Self::run_checkpointed) and
    /// [`run_guarded`](Self::run_guarded): `flag` set means `poll()` has a request.
    fn grow_polled(
        &mut self,
        every: Option<u64>,
        flag: &AtomicBool,
        poll: &dyn Fn() -> Request,
        write: bool,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Option<StopReason>, SimError> {
        if every == Some(0) {
            return Err(SimError::CheckpointUsage(
                "checkpoints need every >= 1".into(),
            ));
        }
        if write && !self.streams_positions() {
            return Err(SimError::CheckpointUsage(
                "a checkpoint needs the positions streamed to positions.npy (Simulation::stream_into)"
                    .into(),
            ));
        }
        let checkpoint = |s: &mut Self| -> Result<(), SimError> {
            if write {
                s.write_checkpoint()?;
            }
            Ok(())
        };
        // What the run does with a request: `Some(reason)` to stop, after its checkpoint.
        let honour = |s: &mut Self| -> Result<Option<StopReason>, SimError> {
            match poll() {
                Request::Stop(r) => {
                    checkpoint(s)?;
                    progress(s.growth.n);
                    Ok(Some(r))
                }
                Request::Checkpoint => checkpoint(s).map(|()| None),
                Request::None => Ok(None),
            }
        };
        let target = self.params.particles;
        while self.growth.n < self.serial_to() {
            if flag.load(Ordering::Relaxed)
                && let Some(r) = honour(self)?
            {
                return Ok(Some(r));
            }
            self.add_one()?;
            if self.growth.n % 1024 == 0 {
                progress(self.growth.n);
            }
            if let Some(e) = every
                && self.growth.n % e == 0
                && self.growth.n < target
            {
                checkpoint(self)?;
            }
        }
        while self.growth.n < target {
            let until = every.map_or(target, |e| ((self.growth.n / e + 1) * e).min(target));
            // Ends at a quiescent point at `until` or once `flag` is set.
            self.grow_parallel(until, flag, progress)?;
            if flag.load(Ordering::Relaxed) {
                if let Some(r) = honour(self)? {
                    return Ok(Some(r));
                }
            } else if self.growth.n < target {
                checkpoint(self)?;
            }
        }
        if every.is_some() {
            checkpoint(self)?;
        }
        progress(self.growth.n);
        Ok(None)
    }

    /// Stops streaming the positions without syncing `positions.npy` (its header keeps the
    /// rows of the last checkpoint, which a resume reads up to): for a run that streamed them
    /// only for its checkpoints and has ended (the binary's default), which then removes the
    /// file, after its outputs and `checkpoint.bin`, with
    /// [`remove_positions_file`](Self::remove_positions_file). `growth.csv` and
    /// `positions_parent.npy` (8 bytes a particle, which the branch analysis reads) stream on;
    /// `positions_parent.npy` is removed with `positions.npy`. Returns whether positions were
    /// streamed.
    pub fn discard_positions(&mut self) -> bool {
        self.growth
            .streams
            .as_mut()
            .is_some_and(|s| s.positions.take().is_some())
    }

    /// Removes `positions.npy` from the directory the run streams into, if it is there.
    ///
    /// # Errors
    /// The file exists but cannot be removed.
    pub fn remove_positions_file(&self) -> Result<(), SimError> {
        let Some(dir) = &self.stream_dir else {
            return Ok(());
        };
        for file in [POSITIONS_FILE, PARENTS_FILE] {
            let path = dir.join(file);
            match std::fs::remove_file(&path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    return Err(SimError::Stream(format!(
                        "removing {}: {e}",
                        path.display()
                    )));
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// Whether `positions.npy` is being written ([`stream_into`](Self::stream_into) with
    /// positions).
    pub fn streams_positions(&self) -> bool {
        self.growth
            .streams
            .as_ref()
            .is_some_and(|s| s.positions.is_some())
    }

    /// Writes the run's state to `checkpoint.bin` in the directory it streams into, after
    /// flushing and syncing `positions.npy` and `growth.csv` there: a few kilobytes, however
    /// large the cluster (the positions are in `positions.npy`).
    ///
    /// # Errors
    /// [`SimError::CheckpointUsage`] without positions streamed or with more than one thread;
    /// I/O errors.
    pub fn write_checkpoint(&mut self) -> Result<(), SimError> {
        let dir = self.stream_dir.clone().ok_or_else(|| {
            SimError::CheckpointUsage(
                "a checkpoint needs the positions streamed to positions.npy (Simulation::stream_into)"
                    .into(),
            )
        })?;
        checkpoint::write(
            &dir,
            &self.params,
            self.seed,
            &self.serial.rng,
            self.pdla_rounds,
            &mut self.growth,
        )
    }

    /// Flushes what the run streams (`growth.csv`, `positions.npy`, whose header then counts
    /// every stored particle); the first write error of the run so far, if any. A no-op for a
    /// run that streams nothing.
    pub fn sync_streams(&mut self) -> Result<(), SimError> {
        match &mut self.growth.streams {
            Some(s) => s.sync(),
            None => Ok(()),
        }
    }

    /// Continues the run checkpointed in `dir` (`checkpoint.bin` and `positions.npy`, as
    /// [`write_checkpoint`](Self::write_checkpoint) left them): the tree, `R_g`, `R_ext` and
    /// the state hash are rebuilt by storing the first `n` positions of `positions.npy` again in
    /// arrival order, so they are bit-identical to those of the run that wrote it. With
    /// `particles`, the run's target becomes that (at least the particles stored): a run
    /// extended so ends as a run made to that size directly. Nothing is written; call
    /// [`stream_into`](Self::stream_into) to go on streaming (into `dir` or elsewhere).
    ///
    /// # Errors
    /// The checkpoint's errors; [`SimError::CheckpointUsage`] for another dimension, a target
    /// below the particles stored, or a `positions.npy` that is short or not the one the
    /// checkpoint was written with.
    pub fn resume(dir: &Path, particles: Option<u64>) -> Result<Self, SimError> {
        let r = checkpoint::read::<D>(dir, particles)?;
        Ok(Simulation {
            serial: Serial::with_rng(&r.params, r.rng),
            params: r.params,
            seed: r.seed,
            cluster: r.cluster,
            growth: r.growth,
            pdla: PdlaStats::default(),
            pdla_rounds: r.pdla_rounds,
            stream_dir: None,
            resumed_from: Some(r.log),
            seeds: Vec::new(),
        })
    }

    /// Streams the run's history into `dir` from now on: `growth.csv` (rewritten with the
    /// samples so far, then a line per sample as it is taken) and, with `positions`,
    /// `positions.npy` (every stored position, arrival order, `(N, D)` float64, readable by
    /// `numpy.load(..., mmap_mode="r")`), which checkpoints need. The positions stored so far
    /// come from the resumed run's `positions.npy` (copied unless it is this file), from memory
    /// (`keep_positions`), or are the seed particle alone.
    ///
    /// # Errors
    /// I/O errors naming the file; [`SimError::CheckpointUsage`] if positions were stored that
    /// none of those sources holds.
    pub fn stream_into(&mut self, dir: &Path, positions: bool) -> Result<(), SimError> {
        let stream_error = |e: &dyn std::fmt::Display| SimError::Stream(e.to_string());
        let parents = if positions && self.params.connectivity {
            Some(self.parents_log(dir)?)
        } else {
            None
        };
        let log = if positions {
            let path = dir.join(POSITIONS_FILE);
            let log = match &self.resumed_from {
                Some(src) => {
                    let same = std::fs::canonicalize(src)
                        .ok()
                        .is_some_and(|a| std::fs::canonicalize(&path).ok().is_some_and(|b| a == b));
                    if !same {
                        std::fs::copy(src, &path).map_err(|e| {
                            SimError::Stream(format!(
                                "copying {} to {}: {e}",
                                src.display(),
                                path.display()
                            ))
                        })?;
                    }
                    NpyWriter::resume(&path, D, self.growth.n).map_err(|e| stream_error(&e))?
                }
                None => {
                    let mut w = NpyWriter::create(&path, D).map_err(|e| stream_error(&e))?;
                    match &self.growth.positions {
                        Some(v) => {
                            for p in v {
                                w.push(p).map_err(|e| stream_error(&e))?;
                            }
                        }
                        // A deposit starts empty.
                        None if self.growth.n == 0 => {}
                        None if !self.seeds.is_empty()
                            && self.growth.n == self.seeds.len() as u64 =>
                        {
                            for p in &self.seeds {
                                w.push(p).map_err(|e| stream_error(&e))?;
                            }
                        }
                        None if self.growth.n == 1 => {
                            w.push(&[0.0; D]).map_err(|e| stream_error(&e))?;
                        }
                        None => {
                            return Err(SimError::CheckpointUsage(format!(
                                "{} positions are stored but not kept: stream positions before growing",
                                self.growth.n
                            )));
                        }
                    }
                    w
                }
            };
            Some(log)
        } else {
            None
        };
        self.growth.streams = Some(
            Streams::open(dir, &self.growth.samples, log, parents).map_err(|e| stream_error(&e))?,
        );
        self.stream_dir = Some(dir.to_path_buf());
        self.resumed_from = None;
        Ok(())
    }

    /// `positions_parent.npy` in `dir`, holding the parents of the particles stored so far: the
    /// resumed run's (copied unless it is this file), those kept in memory, or the seed's.
    fn parents_log(&self, dir: &Path) -> Result<NpyWriter, SimError> {
        let stream_error = |e: &dyn std::fmt::Display| SimError::Stream(e.to_string());
        let path = dir.join(PARENTS_FILE);
        if let Some(positions) = &self.resumed_from {
            let src = positions.with_file_name(PARENTS_FILE);
            let same = std::fs::canonicalize(&src)
                .ok()
                .is_some_and(|a| std::fs::canonicalize(&path).ok().is_some_and(|b| a == b));
            if !same {
                std::fs::copy(&src, &path).map_err(|e| {
                    SimError::Stream(format!(
                        "copying {} to {}: {e}",
                        src.display(),
                        path.display()
                    ))
                })?;
            }
            return NpyWriter::resume_ints(&path, self.growth.n).map_err(|e| stream_error(&e));
        }
        let mut w = NpyWriter::create_ints(&path).map_err(|e| stream_error(&e))?;
        match &self.growth.parents {
            Some(v) => {
                for &p in v {
                    w.push_int(p).map_err(|e| stream_error(&e))?;
                }
            }
            None if self.growth.n == 0 => {}
            None if !self.seeds.is_empty() && self.growth.n == self.seeds.len() as u64 => {
                for _ in &self.seeds {
                    w.push_int(-1).map_err(|e| stream_error(&e))?;
                }
            }
            None if self.growth.n == 1 => w.push_int(-1).map_err(|e| stream_error(&e))?,
            None => {
                return Err(SimError::CheckpointUsage(format!(
                    "{} parents are recorded but not kept: stream positions before growing",
                    self.growth.n
                )));
            }
        }
        Ok(w)
    }
}

impl<const D: usize> Simulation<D> {
    /// The parameters.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Particles in the cluster.
    pub fn particles(&self) -> u64 {
        self.growth.n
    }

    /// Largest centre distance from the origin.
    pub fn r_ext(&self) -> f64 {
        self.growth.r_ext
    }

    /// The half side of the square a picture of the run frames: `R_ext` for a radial cluster,
    /// half the larger of the strip's width and the height for a deposit (framed from the
    /// substrate up, centred at half the height).
    pub fn picture_half(&self) -> f64 {
        match self.params.substrate() {
            Some(s) => (0.5 * s.width).max(0.5 * self.growth.r_ext),
            None => self.growth.r_ext,
        }
    }

    /// Radius of gyration of the cluster.
    pub fn radius_of_gyration(&self) -> f64 {
        self.growth.gyration.radius()
    }

    /// PDLA walkers discarded at the re-check (0 for one thread).
    pub fn discarded_walkers(&self) -> u64 {
        self.pdla.discarded
    }

    /// Wall seconds of the parallel (PDLA) phase; 0 for one thread.
    pub fn parallel_seconds(&self) -> f64 {
        self.pdla.seconds
    }

    /// Seconds PDLA threads spent waiting for the shared log's mutex, summed over threads (the
    /// serialised part of PDLA; 0 for one thread).
    pub fn lock_wait_seconds(&self) -> f64 {
        self.pdla.lock_wait_seconds
    }

    /// What this process's walkers did (serial and parallel phases; a resumed run counts from
    /// its resume): the software counts behind the cost per particle.
    pub fn walk_counts(&self) -> crate::walker::WalkCounts {
        let mut c = self.serial.walk.counts;
        c.add(&self.pdla.walk);
        c
    }

    /// PDLA phases run: one per growth call or checkpoint interval, plus one each time the
    /// shared tree needed more room than reserved (0 with one thread).
    pub fn pdla_phases(&self) -> u64 {
        self.pdla.phases
    }

    /// Hash of the stored positions in arrival order (f64 bits): equal runs, equal hashes.
    pub fn state_hash(&self) -> String {
        self.growth.hasher.finish_hex()
    }

    /// The growth samples ([`SAMPLES_PER_DECADE`] per decade of N, the last at the final size).
    pub fn samples(&self) -> &[Sample] {
        &self.growth.samples
    }

    /// Whether the run streams `growth.csv` ([`stream_into`](Self::stream_into)).
    pub fn streams_growth(&self) -> bool {
        self.growth.streams.is_some()
    }

    /// Positions in arrival order, if `params.keep_positions`.
    pub fn positions(&self) -> Option<&[[f64; D]]> {
        self.growth.positions.as_deref()
    }

    /// The positions in arrival order, if `params.keep_positions`, moved out of the finished
    /// run without a copy (the Python bindings hand them to NumPy this way).
    pub fn into_positions(self) -> Option<Vec<[f64; D]>> {
        self.growth.positions
    }

    /// Each particle's parent in arrival order (the arrival index of the particle it stuck
    /// to, `-1` for the seed), if `params.keep_positions` and `params.connectivity`.
    pub fn parents(&self) -> Option<&[i64]> {
        self.growth.parents.as_deref()
    }

    /// [`into_positions`](Self::into_positions) with [`parents`](Self::parents).
    pub fn into_positions_and_parents(self) -> (Option<Vec<[f64; D]>>, Option<Vec<i64>>) {
        (self.growth.positions, self.growth.parents)
    }

    /// The spatial structure holding the cluster.
    pub fn tree(&self) -> &Orthtree<D> {
        self.cluster.tree()
    }

    /// Lowers the number of nodes, leaves and point slots the orthtree may use (see
    /// [`Orthtree::set_index_limit`]): a run that needs more stops with
    /// [`SimError::Tree`]`(`[`OrthtreeError::CapacityExceeded`](spatial::orthtree::OrthtreeError::CapacityExceeded)`)`.
    /// For tests of that error without billions of particles.
    pub fn set_tree_index_limit(&mut self, limit: u64) {
        self.cluster.set_tree_index_limit(limit);
    }

    /// The cluster (orthtree and distance map).
    pub fn cluster(&self) -> &Cluster<D> {
        &self.cluster
    }

    /// Fractal dimension from `log N = D log R_g + c` over the samples with `N >= fit_from`.
    pub fn fractal_dimension(&self) -> Result<Fit, core_lattice::stats::StatsError> {
        let (rg, n): (Vec<f64>, Vec<f64>) = self
            .growth
            .samples
            .iter()
            .filter(|s| s.n >= self.params.fit_from)
            .map(|s| (s.radius_of_gyration, s.n as f64))
            .unzip();
        Fit::log_log(&rg, &n)
    }
}
