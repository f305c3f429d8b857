//! The `grid` strategy as a store ([`HaloStore`]): [`spatial::lattice::HaloGrid`] (rigid
//! shapes listed in small grid boxes by their halos, box side tuned at run time) behind
//! DLCA's [`ClusterStore`] interface, with the log lines of its box side and a k-index view
//! of the clusters built on demand for output.
//!
//! Invariant: as every strategy, the contacts of a move are exactly the clusters touching the
//! mover, in increasing id (the structure's own guarantee), so the trajectory does not depend
//! on the boxes or their side.

use super::arrays::ClusterArrays;
use super::strategy::{ClusterStore, Merged};
use crate::params::Search;
use core_lattice::{Blocked, Direction};
use spatial::lattice::{HaloGrid, ItemId, SiteSets};
use std::sync::OnceLock;

/// The clusters in a [`HaloGrid`], with their k-index view.
#[derive(Debug)]
pub(crate) struct HaloStore {
    grid: HaloGrid,
    /// The clusters as k-index arrays, built by [`ClusterStore::sets`] and dropped by
    /// [`ClusterStore::forget_views`].
    materialized: OnceLock<SiteSets>,
}

impl HaloStore {
    /// The clusters of `arrays`, in grid boxes of side `requested` (a power of two) or, by
    /// default, of the side with the least predicted cost. Pushes the side chosen to `notes`.
    pub(crate) fn new(
        arrays: ClusterArrays,
        requested: Option<u64>,
        notes: &mut Vec<String>,
    ) -> Self {
        let grid = HaloGrid::new(arrays.sets(), requested);
        let side = grid.side();
        notes.push(match requested {
            Some(_) => format!("grid box side {side} (halo per cluster, re-tuned as clusters grow)"),
            None => format!(
                "grid box side {side} (halo per cluster, least predicted cost; re-tuned as clusters grow)"
            ),
        });
        HaloStore {
            grid,
            materialized: OnceLock::new(),
        }
    }
}

impl ClusterStore for HaloStore {
    forward_clusters!(s => s.grid);

    fn kind(&self) -> Search {
        Search::Grid
    }

    fn grid_side(&self) -> Option<u64> {
        Some(self.grid.side())
    }

    fn merge(&mut self, survivor: ItemId, others: &[ItemId], notes: &mut Vec<String>) -> Merged {
        let (size, retuned) = self.grid.merge(survivor, others);
        if let Some(r) = retuned {
            notes.push(format!(
                "{} clusters: grid box side re-tuned from {} to {} (predicted cost per sweep {:.0} -> {:.0})",
                r.clusters, r.from, r.to, r.cost_before, r.cost_after
            ));
        }
        Merged {
            size,
            to_all_pairs: false,
        }
    }

    fn sets(&self) -> &SiteSets {
        self.materialized.get_or_init(|| self.grid.to_sets())
    }

    fn forget_views(&mut self) {
        self.materialized.take();
    }

    fn check(&self) {
        self.grid.check();
    }

    fn take_arrays(&mut self) -> ClusterArrays {
        ClusterArrays::new(self.grid.to_sets())
    }
}
