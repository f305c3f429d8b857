//! What a checkpoint of an animat run holds ([`Saved`]), shared by the `animat` binary
//! (`--resume`) and the Python bindings (`checkpoint=`), so that either continues the other's.
//! It is written in `run_io`'s checksummed envelope under model [`CHECKPOINT_MODEL`], to
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

/// Memory a checkpoint of `world` with `rows` population rows needs while it is written,
/// beside the world itself: the snapshot and its encoding, 128 bytes an animat and 128 a row
/// (each holds a few dozen), and 16 MiB for buffers. Front ends keep this free
/// (`run_io::guard::MemoryWatch::reserve`).
pub fn reserve_bytes(world: &crate::World, rows: usize) -> u64 {
    (16 << 20) + 128 * (world.foxes() + world.rabbits()) + 128 * rows as u64
}
