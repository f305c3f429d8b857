//! Checkpoints of serial runs: the parameters, the seed, the walk's random stream, every
//! position in arrival order and the growth samples, as bincode 2 in `core_lattice`'s atomic
//! `AGGSIMCK` envelope (model [`CHECKPOINT_MODEL`]).
//!
//! Invariant: restoring stores the checkpointed positions again in arrival order, so the tree,
//! `R_g`, `R_ext` and the state hash are bit-identical to those of the run that wrote it, and
//! a resumed run ends with the state hash of an uninterrupted one.

use super::growth::{Growth, Sample};
use crate::cluster::Cluster;
use crate::error::SimError;
use crate::params::Params;
use crate::space::{Dim, Space};
use core_lattice::rng::SimRng;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::time::{Duration, Instant};

/// Model name in the checkpoint envelope.
pub const CHECKPOINT_MODEL: &str = "dla";

/// The state a checkpoint holds.
#[derive(Serialize, Deserialize)]
struct Snapshot {
    params: Params,
    seed: u64,
    rng: SimRng,
    /// Positions in arrival order, `D` coordinates each.
    positions: Vec<f64>,
    samples: Vec<Sample>,
    next_sample: u64,
    /// Wall seconds of growth so far (the `seconds` column of `growth.csv` continues).
    seconds: f64,
}

/// A run rebuilt from a checkpoint.
pub(crate) struct Restored<const D: usize> {
    pub(crate) params: Params,
    pub(crate) seed: u64,
    pub(crate) rng: SimRng,
    pub(crate) cluster: Cluster<D>,
    pub(crate) growth: Growth<D>,
}

/// Writes the state of a serial run to `path`, atomically. Needs `threads == 1` and the
/// positions kept in `growth`.
pub(crate) fn write<const D: usize>(
    path: &Path,
    params: &Params,
    seed: u64,
    rng: &SimRng,
    growth: &Growth<D>,
) -> Result<(), SimError> {
    let positions = growth.positions.as_ref().ok_or_else(|| {
        SimError::CheckpointUsage("a checkpoint needs the positions kept in memory".into())
    })?;
    if params.threads != 1 {
        return Err(SimError::CheckpointUsage(
            "checkpoints are for one thread (PDLA is not deterministic)".into(),
        ));
    }
    let snap = Snapshot {
        params: params.clone(),
        seed,
        rng: rng.clone(),
        positions: positions.iter().flatten().copied().collect(),
        samples: growth.samples.clone(),
        next_sample: growth.next_sample,
        seconds: growth.started.elapsed().as_secs_f64(),
    };
    core_lattice::io::write_checkpoint(path, CHECKPOINT_MODEL, &snap)?;
    Ok(())
}

/// Reads the checkpoint at `path` and rebuilds its run in `D` dimensions.
pub(crate) fn read<const D: usize>(path: &Path) -> Result<Restored<D>, SimError>
where
    Dim<D>: Space<D>,
{
    let snap: Snapshot = core_lattice::io::read_checkpoint(path, CHECKPOINT_MODEL)?;
    snap.params.validate()?;
    if snap.params.dim != D {
        return Err(SimError::CheckpointUsage(format!(
            "--dim {} in the checkpoint, {D} given",
            snap.params.dim
        )));
    }
    if snap.positions.len() % D != 0 || snap.positions.is_empty() {
        return Err(SimError::CheckpointUsage(format!(
            "checkpoint holds {} coordinates, not a whole number of {D}D positions",
            snap.positions.len()
        )));
    }
    let params = snap.params;
    let mut cluster = Cluster::new(&params)?;
    let mut growth = Growth::new(&params);
    for c in snap.positions.chunks_exact(D) {
        let mut p = [0.0; D];
        p.copy_from_slice(c);
        growth.add(&mut cluster, p, params.particles)?;
    }
    growth.samples = snap.samples;
    growth.next_sample = snap.next_sample;
    if let Some(t) =
        Instant::now().checked_sub(Duration::from_secs_f64(snap.seconds.clamp(0.0, 1e9)))
    {
        growth.started = t;
    }
    Ok(Restored {
        params,
        seed: snap.seed,
        rng: snap.rng,
        cluster,
        growth,
    })
}
