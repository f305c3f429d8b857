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
//! | `files` | streaming into an output directory, checkpoints and their timing, resume (feature `files`) |
//!
//! Invariant: `growth.n` particles are stored in `cluster`, in the order `growth` accounted
//! for them.

#[cfg(feature = "files")]
mod checkpoint;
#[cfg(feature = "files")]
mod files;
mod growth;
#[cfg(feature = "files")]
mod particles;
mod pdla;
mod ring;
mod serial;
#[cfg(test)]
mod tests;

#[cfg(feature = "files")]
pub use self::checkpoint::{CHECKPOINT_FILE, CHECKPOINT_MODEL, PARENTS_FILE, POSITIONS_FILE};
pub use self::growth::{GROWTH, GROWTH_COLUMNS, SAMPLES_PER_DECADE, Sample};
#[cfg(feature = "files")]
pub use self::particles::{each_particle, each_position};
pub use self::pdla::{DiscardGuard, MAX_CONSECUTIVE_DISCARDS, OVERLAP_DISTANCE, PURPOSE_PDLA};
pub use self::serial::PURPOSE_WALK;
pub use crate::error::SimError;
pub use crate::space::MAP_JUMP_MIN;
pub use crate::walker::{FAR_FIELD_MARGIN, Walker, direction, first_contact};

use self::growth::Growth;
use self::pdla::PdlaStats;
use self::serial::Serial;
use crate::cluster::Cluster;
use crate::params::{Params, ParamsError};
use crate::space::{Dim, Space};
use core_lattice::Fit;
use spatial::orthtree::Orthtree;
use std::path::Path;
#[cfg(feature = "files")]
use std::path::PathBuf;
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
    #[cfg(feature = "files")]
    stream_dir: Option<PathBuf>,
    /// The `positions.npy` a resumed run was rebuilt from, until it streams again.
    #[cfg(feature = "files")]
    resumed_from: Option<PathBuf>,
    /// The seeds of a seed set, until the run streams them ([`stream_into`](Self::stream_into)),
    /// for a run that keeps no positions in memory.
    #[cfg_attr(not(feature = "files"), allow(dead_code))]
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
            #[cfg(feature = "files")]
            stream_dir: None,
            #[cfg(feature = "files")]
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

    /// The half side of the square a figure of the run frames: `R_ext` for a radial cluster,
    /// half the larger of the strip's width and the height for a deposit (framed from the
    /// substrate up, centred at half the height).
    pub fn figure_half(&self) -> f64 {
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
