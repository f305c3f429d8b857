//! Checkpoints of runs without a second copy of the cluster (serial runs between two walkers,
//! PDLA at a quiescent point between two parallel phases). The positions already
//! stream, in arrival order, to `positions.npy` in the run's directory; a checkpoint
//! (`checkpoint.bin`, beside it) holds only what is not in that file: the parameters, the seed,
//! the walk's random stream, the number of parallel phases run, the particle count `n` and the state hash after the first `n`
//! rows, the growth samples and the seconds grown. It is a few kilobytes at any size, written
//! atomically in `sim_run`'s checksummed `AGGSIMCK` envelope (model
//! [`CHECKPOINT_MODEL`]) after `positions.npy` has been flushed and synced.
//!
//! Invariant: restoring stores the first `n` rows of `positions.npy` again in arrival order,
//! which rebuilds the tree, `R_g`, `R_ext` and the state hash bit-identically; the rebuilt
//! hash must equal the recorded one, so a log that does not belong to the checkpoint is
//! refused. A resumed run ends with the state hash of an uninterrupted one, and one resumed
//! with a larger target with that of a run made to the larger target directly.

use super::growth::{Growth, Sample};
use crate::cluster::Cluster;
use crate::error::SimError;
use crate::params::Params;
use crate::space::{Dim, Space};
use core_lattice::rng::SimRng;
use serde::{Deserialize, Serialize};
use sim_run::io::{NpyReader, StateHasher};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Model name in the checkpoint envelope.
pub const CHECKPOINT_MODEL: &str = "dla";
/// File name of a checkpoint in a run's directory.
pub const CHECKPOINT_FILE: &str = "checkpoint.bin";
/// File name of the streamed positions (the arrival log) in a run's directory.
pub const POSITIONS_FILE: &str = "positions.npy";

/// The state a checkpoint holds.
#[derive(Serialize, Deserialize)]
struct Snapshot {
    /// As `(name, text)` pairs, so that adding a parameter does not change the layout: a
    /// checkpoint written before it reads with the parameter at its default.
    #[serde(with = "core_lattice::spec::as_text")]
    params: Params,
    seed: u64,
    rng: SimRng,
    /// Parallel (PDLA) phases run so far: a resumed run's phases draw from new streams.
    pdla_rounds: u32,
    /// Particles stored: the first `n` rows of `positions.npy`.
    n: u64,
    /// The state hash after those `n` particles.
    state_hash: String,
    samples: Vec<Sample>,
    next_sample: u64,
    last_off_schedule: bool,
    /// Wall seconds of growth so far (the `seconds` column of `growth.csv` continues).
    seconds: f64,
}

/// A run rebuilt from a checkpoint.
pub(crate) struct Restored<const D: usize> {
    pub(crate) params: Params,
    pub(crate) seed: u64,
    pub(crate) rng: SimRng,
    pub(crate) pdla_rounds: u32,
    pub(crate) cluster: Cluster<D>,
    pub(crate) growth: Growth<D>,
    /// The `positions.npy` the cluster was rebuilt from.
    pub(crate) log: PathBuf,
}

/// Writes the checkpoint of a serial run streaming its positions into `dir`: syncs the
/// streams, then writes `dir/checkpoint.bin` atomically.
pub(crate) fn write<const D: usize>(
    dir: &Path,
    params: &Params,
    seed: u64,
    rng: &SimRng,
    pdla_rounds: u32,
    growth: &mut Growth<D>,
) -> Result<(), SimError> {
    let streams = growth
        .streams
        .as_mut()
        .filter(|s| s.positions.is_some())
        .ok_or_else(|| {
            SimError::CheckpointUsage(
                "a checkpoint needs the positions streamed to positions.npy (Simulation::stream_into)"
                    .into(),
            )
        })?;
    streams.sync()?;
    let snap = Snapshot {
        params: params.clone(),
        seed,
        rng: rng.clone(),
        pdla_rounds,
        n: growth.n,
        state_hash: growth.hasher.finish_hex(),
        samples: growth.samples.clone(),
        next_sample: growth.next_sample,
        last_off_schedule: growth.last_off_schedule,
        seconds: growth.started.elapsed().as_secs_f64(),
    };
    sim_run::io::write_checkpoint(dir.join(CHECKPOINT_FILE), CHECKPOINT_MODEL, &snap)?;
    Ok(())
}

/// Reads the checkpoint in `dir` and rebuilds its run in `D` dimensions from
/// `dir/positions.npy`, with the target raised to `particles` if given (at least the
/// particles stored).
pub(crate) fn read<const D: usize>(
    dir: &Path,
    particles: Option<u64>,
) -> Result<Restored<D>, SimError>
where
    Dim<D>: Space<D>,
{
    let snap: Snapshot = sim_run::io::read_checkpoint(dir.join(CHECKPOINT_FILE), CHECKPOINT_MODEL)?;
    let mut params = snap.params;
    params.validate()?;
    if params.dim != D {
        return Err(SimError::CheckpointUsage(format!(
            "--dim {} in the checkpoint, {D} given",
            params.dim
        )));
    }
    let extended = particles.is_some_and(|m| m != params.particles);
    if let Some(m) = particles {
        if m < snap.n {
            return Err(SimError::CheckpointUsage(format!(
                "--particles {m} is below the {} particles the checkpoint holds",
                snap.n
            )));
        }
        params.particles = m;
        params.validate()?;
    }
    if snap.n == 0 || snap.n > params.particles {
        return Err(SimError::CheckpointUsage(format!(
            "the checkpoint holds {} particles, outside 1..={}",
            snap.n, params.particles
        )));
    }
    let log = dir.join(POSITIONS_FILE);
    let bad_log = |why: String| SimError::CheckpointUsage(format!("{}: {why}", log.display()));
    // Two passes over the log: the first hashes its first `n` rows (the stored positions, so
    // their hash is the state hash) and refuses a log that is not the checkpoint's before
    // anything is built from it: a damaged or foreign row far from the origin (1e6 diameters)
    // would otherwise size the distance maps for it (tens of gigabytes) before the hash could
    // refuse it. The second stores them.
    let open = || -> Result<NpyReader, SimError> {
        let reader = NpyReader::open(&log).map_err(|e| SimError::CheckpointUsage(e.to_string()))?;
        if reader.cols() != D {
            return Err(bad_log(format!("{} columns, not {D}", reader.cols())));
        }
        Ok(reader)
    };
    let mut p = [0.0; D];
    let mut reader = open()?;
    let mut hasher = StateHasher::new();
    for i in 0..snap.n {
        let more = reader
            .read_beyond(&mut p)
            .map_err(|e| SimError::CheckpointUsage(e.to_string()))?;
        if !more {
            return Err(bad_log(format!(
                "holds {i} positions, the checkpoint needs {}",
                snap.n
            )));
        }
        for x in p {
            hasher.f64(x);
        }
    }
    if hasher.finish_hex() != snap.state_hash {
        return Err(bad_log(format!(
            "does not belong to the checkpoint: its first {} positions hash to {}, the checkpoint recorded {}",
            snap.n,
            hasher.finish_hex(),
            snap.state_hash
        )));
    }
    let mut reader = open()?;
    let mut cluster = Cluster::new(&params)?;
    let mut growth = Growth::new(&params);
    for _ in 0..snap.n {
        let more = reader
            .read_beyond(&mut p)
            .map_err(|e| SimError::CheckpointUsage(e.to_string()))?;
        if !more {
            return Err(bad_log("changed while it was read".into()));
        }
        growth.add(&mut cluster, p, None, params.particles)?;
    }
    // Storing a position returns it unchanged (the log holds stored positions), so the
    // rebuilt state has the hash just checked; anything else is a log that changed between
    // the passes.
    if growth.hasher.finish_hex() != snap.state_hash {
        return Err(bad_log("changed while it was read".into()));
    }
    growth.samples = snap.samples;
    growth.next_sample = snap.next_sample;
    growth.last_off_schedule = snap.last_off_schedule;
    // The sample taken only because the old target was reached is not one a run made to the
    // new target takes.
    if extended && growth.last_off_schedule {
        growth.samples.pop();
        growth.last_off_schedule = false;
    }
    // A NaN (a damaged checkpoint) counts as no time rather than a panic.
    let seconds = Duration::try_from_secs_f64(snap.seconds.clamp(0.0, 1e9)).unwrap_or_default();
    if let Some(t) = Instant::now().checked_sub(seconds) {
        growth.started = t;
    }
    Ok(Restored {
        params,
        seed: snap.seed,
        rng: snap.rng,
        pdla_rounds: snap.pdla_rounds,
        cluster,
        growth,
        log,
    })
}
