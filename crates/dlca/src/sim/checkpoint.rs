//! The state of a run between two sweeps ([`Snapshot`]), for checkpoints (`--checkpoint-every`,
//! `--resume`). `Simulation::snapshot` and `Simulation::restore` convert to and from it.
//!
//! Invariant: a snapshot holds everything the rest of the run depends on (clusters with their
//! ids and site order, the random stream, the strategy and the grid box side, the records), so
//! a restored run reaches the same final state as one never interrupted.

use super::strategy::SearchEvent;
use crate::params::{Params, Search};
use crate::record::Records;
use core_lattice::rng::SimRng;
use spatial::lattice::ItemId;

/// The state of a run between two sweeps: `Simulation::restore` continues it to the same final
/// state as an uninterrupted run. Serialisable with serde (the `dlca` binary writes it in
/// `sim_run::io`'s checkpoint envelope).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Snapshot {
    pub(super) params: Params,
    pub(super) seed: u64,
    pub(super) sweep: u64,
    pub(super) rng: SimRng,
    /// Live clusters in increasing id, with their sites (k-indices).
    pub(super) clusters: Vec<(ItemId, Vec<u64>)>,
    /// One more than the largest cluster id.
    pub(super) id_bound: u64,
    pub(super) particles: u64,
    pub(super) largest: u64,
    /// The search in use, and the grid box side if it is the grid.
    pub(super) strategy: Search,
    pub(super) grid_side: Option<u64>,
    pub(super) strategy_reason: String,
    pub(super) events: Vec<SearchEvent>,
    pub(super) records: Records,
}

impl Snapshot {
    /// The parameters of the saved run.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The seed of the saved run.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Sweeps done when it was saved.
    pub fn sweeps(&self) -> u64 {
        self.sweep
    }

    /// Change where the resumed run stops (`--target-clusters`, `--max-sweeps`): the only
    /// parameters that may differ from the saved run's.
    pub fn set_stop(&mut self, target_clusters: u64, max_sweeps: Option<u64>) {
        self.params.target_clusters = target_clusters;
        self.params.max_sweeps = max_sweeps;
    }
}
