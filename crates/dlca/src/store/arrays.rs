//! The clusters as k-index arrays ([`ClusterArrays`]): what the strategies other than rigid
//! clusters search, and what a strategy hands over when another is installed in its place.
//!
//! Invariant: each cluster's sites were last sorted by k-index when it had `sorted_size`
//! particles; after merges it is sorted again once it has at least 64 and at least twice that
//! many. The order of sites carries no meaning for the model.

use spatial::lattice::SiteSets;

/// The clusters as k-index arrays, with what keeps large clusters' sites in memory order.
#[derive(Debug, Clone)]
pub(crate) struct ClusterArrays {
    pub(super) sets: SiteSets,
    /// Size of each cluster when its sites were last sorted.
    pub(super) sorted_size: Vec<usize>,
    /// Scratch: the sites of the moving cluster before its move.
    pub(super) old: Vec<u64>,
}

impl ClusterArrays {
    /// The clusters of `sets`, none of them sorted yet.
    pub(crate) fn new(sets: SiteSets) -> Self {
        ClusterArrays {
            sorted_size: vec![0; sets.id_bound()],
            sets,
            old: Vec::new(),
        }
    }

    /// The clusters.
    pub(crate) fn sets(&self) -> &SiteSets {
        &self.sets
    }

    /// No clusters, on the same lattice (what a store leaves behind when it hands its clusters
    /// over).
    pub(super) fn empty_like(&self) -> Self {
        ClusterArrays::new(SiteSets::new(self.sets.lattice().clone()))
    }
}
