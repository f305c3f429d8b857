//! The run's files (feature `files`): streaming the history into an output directory
//! (`growth.csv`, `positions.npy`, `positions_parent.npy`), checkpoints and their timing, and
//! resuming from one.

use super::checkpoint;
use super::growth::Streams;
use super::{PARENTS_FILE, POSITIONS_FILE, Serial, Simulation};
use crate::error::SimError;
use crate::sim::PdlaStats;
use crate::space::{Dim, Space};
use run_io::NpyWriter;
use run_io::guard::{Guard, Request, StopReason};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

impl<const D: usize> Simulation<D>
where
    Dim<D>: Space<D>,
{
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

    /// Whether the run streams `growth.csv` ([`stream_into`](Self::stream_into)).
    pub fn streams_growth(&self) -> bool {
        self.growth.streams.is_some()
    }
}
