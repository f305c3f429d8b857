//! The interface every contact-search strategy implements ([`ClusterStore`]): the clusters it
//! keeps, a move with its contact search, merges, and views of the clusters for output.
//!
//! Invariant every implementation keeps: the same calls in the same order give the same
//! clusters, ids, sites (as sets), contacts and merged sizes, whatever the strategy; only speed,
//! memory and the number of candidates examined differ.

use super::arrays::ClusterArrays;
use crate::params::Search;
use core_lattice::{Blocked, Direction};
use spatial::lattice::{ItemId, SiteSets};

/// What a merge left behind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Merged {
    /// Particles in the union.
    pub(crate) size: usize,
    /// The strategy has stopped paying and the run continues with all-pairs (the grid, once a
    /// doubled box has `3A >= L` on some axis).
    pub(crate) to_all_pairs: bool,
}

/// The clusters of a run and a contact search over them.
///
/// Clusters are numbered by [`ItemId`]; a merge keeps the survivor's id and retires the
/// others'. Between two calls no two clusters are face-adjacent (they merge as soon as they
/// touch), which strategies may rely on.
pub(crate) trait ClusterStore {
    /// The strategy, as named on the command line.
    fn kind(&self) -> Search;

    /// The box side, for the grid strategy.
    fn grid_side(&self) -> Option<u64>;

    /// Live cluster ids, in no particular order.
    fn live(&self) -> &[ItemId];

    /// Whether cluster `id` is live.
    fn contains(&self, id: ItemId) -> bool;

    /// Number of particles of live cluster `id`.
    fn len_of(&self, id: ItemId) -> usize;

    /// A hint that cluster `id` takes its turn a few turns from now: the store may start
    /// loading its record into the cache. Changes nothing; by default does nothing.
    fn prefetch_record(&self, _id: ItemId) {}

    /// A hint that cluster `id` takes its turn within a turn or two: the store may start
    /// loading what its move reads beyond the record (the record itself having been asked for
    /// earlier). Changes nothing; by default does nothing.
    fn prefetch_lists(&self, _id: ItemId) {}

    /// Move cluster `id` by `dir`, all or nothing (a wall blocks the whole cluster), and write
    /// the clusters then in contact with it to `contacts`, in increasing id. Returns the number
    /// of candidate clusters examined.
    fn try_move(
        &mut self,
        id: ItemId,
        dir: Direction,
        contacts: &mut Vec<ItemId>,
    ) -> Result<usize, Blocked>;

    /// Merge every cluster of `others` (in increasing id, each above `survivor`) into
    /// `survivor`, pushing changes of the search worth logging to `notes`.
    fn merge(&mut self, survivor: ItemId, others: &[ItemId], notes: &mut Vec<String>) -> Merged;

    /// The clusters as k-index arrays (absolute sites), with the same ids. A store that keeps
    /// clusters in another form builds them on the first call after
    /// [`ClusterStore::forget_views`] and keeps them until the next.
    fn sets(&self) -> &SiteSets;

    /// Drop the views built by [`ClusterStore::sets`]: the clusters changed since. The
    /// simulation calls it before every sweep (and before every invariant check).
    fn forget_views(&mut self);

    /// Panic unless the store's own bookkeeping is consistent. For tests.
    fn check(&self);

    /// Hand the clusters over as k-index arrays, to install another strategy over them. The
    /// store is not used afterwards.
    fn take_arrays(&mut self) -> ClusterArrays;
}
