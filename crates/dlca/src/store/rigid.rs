//! The `lattice` strategy with rigid clusters ([`RigidStore`]) as a [`ClusterStore`]: the
//! store keeps the clusters as origins plus relative sites, so the k-index arrays that outputs
//! read are built on demand and cached until the clusters change.
//!
//! Invariant: the cached arrays, when present, equal the store's clusters (the simulation calls
//! [`ClusterStore::forget_views`] before any change).

use super::arrays::ClusterArrays;
use super::strategy::{ClusterStore, Merged};
use crate::params::Search;
use crate::rigid::RigidStore;
use core_lattice::{Blocked, Direction};
use spatial::lattice::{ItemId, SiteSets};
use std::sync::OnceLock;

/// Rigid clusters over an occupancy lattice, with their k-index arrays built on demand.
#[derive(Debug)]
pub(crate) struct RigidClusters {
    store: RigidStore,
    /// The clusters as k-index arrays, built by [`ClusterStore::sets`] and dropped by
    /// [`ClusterStore::forget_views`].
    materialized: OnceLock<SiteSets>,
}

impl RigidClusters {
    /// The strategy over `store`.
    pub(crate) fn new(store: RigidStore) -> Self {
        RigidClusters {
            store,
            materialized: OnceLock::new(),
        }
    }
}

impl ClusterStore for RigidClusters {
    forward_clusters!(s => s.store);

    #[inline]
    fn prefetch_record(&self, id: ItemId) {
        self.store.prefetch_record(id);
    }

    #[inline]
    fn prefetch_lists(&self, id: ItemId) {
        self.store.prefetch_lists(id);
    }

    fn kind(&self) -> Search {
        Search::Lattice
    }

    fn grid_side(&self) -> Option<u64> {
        None
    }

    fn merge(&mut self, survivor: ItemId, others: &[ItemId], _: &mut Vec<String>) -> Merged {
        for &other in others {
            self.store.merge(survivor, other);
        }
        self.store.finish(survivor);
        Merged {
            size: self.store.len_of(survivor),
            to_all_pairs: false,
        }
    }

    fn sets(&self) -> &SiteSets {
        self.materialized.get_or_init(|| self.store.to_sets())
    }

    fn forget_views(&mut self) {
        self.materialized.take();
    }

    /// The store's own bookkeeping: occupancy, labels, face and probe lists.
    fn check(&self) {
        let mut copy = self.store.clone();
        copy.check();
    }

    fn take_arrays(&mut self) -> ClusterArrays {
        // The store keeps its clusters; a strategy installed in its place takes copies.
        ClusterArrays::new(self.store.to_sets())
    }
}
