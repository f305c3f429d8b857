//! Strategies over the clusters as k-index arrays ([`ClusterArrays`]): a
//! [`ContactSearch`] of the `spatial` crate kept in step with the arrays ([`Indexed`]). Serves
//! all-pairs and, in the dimensions without a rigid-cluster kernel, the occupancy lattice; the
//! grid strategy (`super::grid`) builds on it.
//!
//! Invariant: the search has registered exactly the live clusters of the arrays, at their
//! current sites.

use super::arrays::ClusterArrays;
use super::strategy::{ClusterStore, Merged};
use crate::params::Search;
use core_lattice::{Blocked, Direction};
use spatial::lattice::{AllPairs, ContactSearch, ItemId, Occupancy, SiteSets};

/// A [`ContactSearch`] that serves as a DLCA strategy on its own.
pub(crate) trait SetSearch: ContactSearch {
    /// The strategy it implements.
    const KIND: Search;
}

impl SetSearch for AllPairs {
    const KIND: Search = Search::AllPairs;
}

/// The plain occupancy lattice, used by the `lattice` strategy where there is no rigid-cluster
/// kernel for the dimension.
impl SetSearch for Occupancy {
    const KIND: Search = Search::Lattice;
}

/// The clusters as k-index arrays with the contact search `S` over them.
#[derive(Debug, Clone)]
pub(crate) struct Indexed<S> {
    arrays: ClusterArrays,
    search: S,
}

impl<S: ContactSearch> Indexed<S> {
    /// `search` over `arrays`, registering every live cluster in it (in live order).
    pub(crate) fn new(arrays: ClusterArrays, mut search: S) -> Self {
        for &id in arrays.sets.live() {
            search.insert(&arrays.sets, id);
        }
        Indexed { arrays, search }
    }

    /// `search` over `arrays`, which it has registered already.
    pub(crate) fn registered(arrays: ClusterArrays, search: S) -> Self {
        Indexed { arrays, search }
    }

    /// The search.
    pub(crate) fn search(&self) -> &S {
        &self.search
    }

    /// The search and the clusters it indexes.
    pub(crate) fn search_mut(&mut self) -> (&mut S, &SiteSets) {
        (&mut self.search, &self.arrays.sets)
    }

    /// The clusters.
    pub(crate) fn sets(&self) -> &SiteSets {
        &self.arrays.sets
    }

    /// See [`ClusterStore::live`].
    #[inline]
    pub(crate) fn live(&self) -> &[ItemId] {
        self.arrays.sets.live()
    }

    /// See [`ClusterStore::contains`].
    #[inline]
    pub(crate) fn contains(&self, id: ItemId) -> bool {
        self.arrays.sets.contains(id)
    }

    /// See [`ClusterStore::len_of`].
    #[inline]
    pub(crate) fn len_of(&self, id: ItemId) -> usize {
        self.arrays.sets.sites(id).len()
    }

    /// See [`ClusterStore::try_move`].
    #[inline]
    pub(crate) fn try_move(
        &mut self,
        id: ItemId,
        dir: Direction,
        contacts: &mut Vec<ItemId>,
    ) -> Result<usize, Blocked> {
        let a = &mut self.arrays;
        a.sets.translate(id, dir, &mut a.old)?;
        self.search
            .moved(&a.sets, id, &a.old, a.sets.sites(id), dir);
        Ok(self.search.contacts(&a.sets, id, contacts))
    }

    /// Merge cluster `other` into `survivor`, in the arrays and the search.
    pub(crate) fn merge_one(&mut self, survivor: ItemId, other: ItemId) {
        let sets = &mut self.arrays.sets;
        let from_len = sets.merge(survivor, other);
        self.search.merge(sets, survivor, other, from_len);
    }

    /// After the merges into `survivor`: its size, having sorted its sites if it has at least 64
    /// and has doubled since they were last sorted. Keeping large clusters' sites in k-index
    /// order makes moves walk per-site arrays in memory order; amortised O(log s) per particle.
    pub(crate) fn finish_merge(&mut self, survivor: ItemId) -> usize {
        let a = &mut self.arrays;
        let size = a.sets.sites(survivor).len();
        if size >= 64 && size >= 2 * a.sorted_size[survivor as usize] {
            a.sets.sort_sites(survivor);
            a.sorted_size[survivor as usize] = size;
        }
        size
    }

    /// See [`ClusterStore::take_arrays`].
    pub(crate) fn take_arrays(&mut self) -> ClusterArrays {
        let empty = self.arrays.empty_like();
        std::mem::replace(&mut self.arrays, empty)
    }
}

impl<S: SetSearch> ClusterStore for Indexed<S> {
    forward_clusters!(s => s);

    fn kind(&self) -> Search {
        S::KIND
    }

    fn grid_side(&self) -> Option<u64> {
        None
    }

    fn merge(&mut self, survivor: ItemId, others: &[ItemId], _: &mut Vec<String>) -> Merged {
        for &other in others {
            self.merge_one(survivor, other);
        }
        Merged {
            size: self.finish_merge(survivor),
            to_all_pairs: false,
        }
    }

    fn sets(&self) -> &SiteSets {
        &self.arrays.sets
    }

    fn forget_views(&mut self) {}

    fn check(&self) {
        // The arrays are the clusters; the simulation checks them.
    }

    fn take_arrays(&mut self) -> ClusterArrays {
        Indexed::take_arrays(self)
    }
}
