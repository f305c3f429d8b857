//! The simulation that ties the pieces together: [`Simulation`] owns the cluster, the growth
//! accounting, the serial walk and the PDLA statistics, grows serially (one walker, a pure
//! function of `(Params, seed)`) up to `serial_until` or the end, then in parallel (PDLA),
//! writes and resumes checkpoints, and fits the fractal dimension.
//!
//! | module | owns |
//! |---|---|
//! | `growth` | what a stored particle changes: count, `R_ext`, `R_g`, hash, samples |
//! | `serial` | serial DLA: one walker at a time on one stream |
//! | `pdla` | PDLA: threads, replicas, the shared log, the re-check |
//! | `checkpoint` | the checkpoint format, writing and rebuilding a run from it |
//!
//! Invariant: `growth.n` particles are stored in `cluster`, in the order `growth` accounted
//! for them.

mod checkpoint;
mod growth;
mod pdla;
mod serial;
#[cfg(test)]
mod tests;

pub use self::checkpoint::CHECKPOINT_MODEL;
pub use self::growth::{GROWTH_SAMPLES, Sample};
pub use self::pdla::{DiscardGuard, MAX_CONSECUTIVE_DISCARDS, OVERLAP_DISTANCE, PURPOSE_PDLA};
pub use self::serial::PURPOSE_WALK;
pub use crate::error::SimError;
pub use crate::walker::{FAR_FIELD_MARGIN, MAP_JUMP_MIN, Walker, direction, first_contact};

use self::growth::Growth;
use self::pdla::PdlaStats;
use self::serial::Serial;
use crate::cluster::Cluster;
use crate::params::Params;
use crate::space::{Dim, Space};
use core_lattice::Fit;
use spatial::orthtree::Orthtree;
use std::path::Path;

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
}

impl<const D: usize> Simulation<D>
where
    Dim<D>: Space<D>,
{
    /// A cluster holding the seed particle at the origin.
    pub fn new(params: Params, seed: u64) -> Result<Self, SimError> {
        params.validate()?;
        if params.dim != D {
            return Err(SimError::DimMismatch(D, params.dim));
        }
        let mut cluster = Cluster::new(&params)?;
        let mut growth = Growth::new(&params);
        growth.add(&mut cluster, [0.0; D], params.particles)?;
        Ok(Simulation {
            serial: Serial::new(&params, seed),
            params,
            seed,
            cluster,
            growth,
            pdla: PdlaStats::default(),
        })
    }

    /// Grow the cluster to `params.particles`, calling `progress(n)` about every 1024
    /// particles.
    pub fn run_with(&mut self, progress: &(dyn Fn(u64) + Sync)) -> Result<(), SimError> {
        let target = self.params.particles;
        let serial_to = if self.params.threads == 1 {
            target
        } else {
            self.params.serial_until.clamp(1, target)
        };
        while self.growth.n < serial_to {
            self.add_one()?;
            if self.growth.n % 1024 == 0 {
                progress(self.growth.n);
            }
        }
        if self.growth.n < target {
            pdla::grow_parallel(
                &self.params,
                self.seed,
                &mut self.cluster,
                &mut self.growth,
                &mut self.pdla,
                progress,
            )?;
        }
        progress(self.growth.n);
        Ok(())
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

    /// Serial DLA with a checkpoint written to `path` every `every` particles (and at the
    /// end), atomically, in the `AGGSIMCK` envelope (model `dla`). Needs `threads == 1` and
    /// `keep_positions` (the checkpoint holds every position in arrival order, from which
    /// [`resume`](Self::resume) rebuilds the tree, `R_g`, `R_ext` and the state hash exactly).
    /// A resumed run ends with the same `state_hash` as an uninterrupted one.
    pub fn run_checkpointed(
        &mut self,
        every: u64,
        path: &Path,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<(), SimError> {
        if self.params.threads != 1 || self.growth.positions.is_none() || every == 0 {
            return Err(SimError::CheckpointUsage(format!(
                "checkpoints need --threads 1, kept positions and every >= 1 (got threads {}, every {every})",
                self.params.threads
            )));
        }
        let target = self.params.particles;
        while self.growth.n < target {
            self.add_one()?;
            if self.growth.n % 1024 == 0 {
                progress(self.growth.n);
            }
            if self.growth.n % every == 0 && self.growth.n < target {
                self.write_checkpoint(path)?;
            }
        }
        self.write_checkpoint(path)?;
        progress(self.growth.n);
        Ok(())
    }

    /// Writes the run's state to `path` (see [`run_checkpointed`](Self::run_checkpointed)).
    pub fn write_checkpoint(&self, path: &Path) -> Result<(), SimError> {
        checkpoint::write(
            path,
            &self.params,
            self.seed,
            &self.serial.rng,
            &self.growth,
        )
    }

    /// Continues a run from a checkpoint written by
    /// [`run_checkpointed`](Self::run_checkpointed): the tree, `R_g`, `R_ext` and the state
    /// hash are rebuilt by storing the checkpointed positions again in arrival order, so they
    /// are bit-identical to those of the run that wrote it.
    pub fn resume(path: &Path) -> Result<Self, SimError> {
        let r = checkpoint::read::<D>(path)?;
        Ok(Simulation {
            serial: Serial::with_rng(&r.params, r.rng),
            params: r.params,
            seed: r.seed,
            cluster: r.cluster,
            growth: r.growth,
            pdla: PdlaStats::default(),
        })
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

    /// Hash of the stored positions in arrival order (f64 bits): equal runs, equal hashes.
    pub fn state_hash(&self) -> String {
        self.growth.hasher.finish_hex()
    }

    /// The growth samples (about 1000, log-spaced in N, the last at the final size).
    pub fn samples(&self) -> &[Sample] {
        &self.growth.samples
    }

    /// Positions in arrival order, if `params.keep_positions`.
    pub fn positions(&self) -> Option<&[[f64; D]]> {
        self.growth.positions.as_deref()
    }

    /// The spatial structure holding the cluster.
    pub fn tree(&self) -> &Orthtree<D> {
        self.cluster.tree()
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
