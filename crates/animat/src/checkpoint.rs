//! What a checkpoint of an animat run holds ([`Saved`]), shared by the `animat` binary
//! (`--resume`) and the Python bindings (`checkpoint=`), so that either continues the other's.
//! It is written in `sim_run::io`'s checksummed envelope under model [`CHECKPOINT_MODEL`], to
//! [`CHECKPOINT_FILE`] in the run's directory.

use crate::output::PopulationRow;
use crate::world::Snapshot;

/// File name of a checkpoint in a run's directory.
pub const CHECKPOINT_FILE: &str = "checkpoint.bin";
/// Model name in the checkpoint envelope.
pub const CHECKPOINT_MODEL: &str = "animat";

/// A saved run: the world and the population rows so far (step 0 to the world's step), so a
/// resumed run writes the whole `populations.csv`.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Saved {
    /// The world's state ([`World::snapshot`](crate::World::snapshot)).
    pub world: Snapshot,
    /// One row per step from step 0.
    pub rows: Vec<PopulationRow>,
}
