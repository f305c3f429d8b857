//! The `grid-doubling` strategy, the paper's own rule: grid boxes over the k-index arrays, with a
//! bounding box per cluster to decide when to double the box side (Hawick, James & Scogings 2006, "Grid-Boxing for Spatial
//! Simulation Performance Optimisation": doubling in section II.A, `3A < L` in section V).
//!
//! Invariants: the box side is a power of two at least the largest extent of any cluster as of
//! its last doubling, and `3A < L` on every axis (once a doubling would break that, the run
//! continues with all-pairs). Contacts never depend on the bounding boxes: the grid-box search is
//! exact for every box side.

use super::arrays::ClusterArrays;
use super::indexed::Indexed;
use super::strategy::{ClusterStore, Merged};
use crate::params::Search;
use core_lattice::{Blocked, Direction, MAX_DIM};
use spatial::lattice::{ItemId, LatticeGridBoxes, SiteSets};

/// Bounding box of a cluster along each axis, relative to its anchor (its first site), in
/// minimum-image offsets. Exact while the cluster spans less than half the lattice on every
/// axis; beyond that the grid has stopped paying anyway (`3A >= L`).
#[derive(Debug, Clone, Copy, Default)]
struct BBox {
    lo: [i64; MAX_DIM],
    hi: [i64; MAX_DIM],
}

/// Grid boxes over the clusters, doubling with the largest cluster.
#[derive(Debug, Clone)]
pub(crate) struct DoublingGrid {
    inner: Indexed<LatticeGridBoxes>,
    bbox: Vec<BBox>,
}

impl DoublingGrid {
    /// Grid boxes over `arrays`, of side `requested` (a power of two, raised to the largest
    /// cluster's extent) or, by default, about the spacing of the clusters: in the dilute regime
    /// that keeps each halo to a few clusters (section V). Gives the arrays back, with a note,
    /// when that box already has `3A >= L` on some axis.
    // Called once per installation: the size of the error (the arrays handed back) is no cost.
    #[allow(clippy::result_large_err)]
    pub(crate) fn new(
        arrays: ClusterArrays,
        requested: Option<u64>,
        notes: &mut Vec<String>,
    ) -> Result<Self, ClusterArrays> {
        let sets = arrays.sets();
        let lattice = sets.lattice();
        let mut bbox = vec![BBox::default(); sets.id_bound()];
        let mut max_extent = 1;
        for &id in sets.live() {
            bbox[id as usize] = measure_bbox(sets, id);
            max_extent = max_extent.max(extent(lattice.dim(), &bbox[id as usize]));
        }
        let side = match requested {
            Some(a) => a.max(max_extent.next_power_of_two()),
            None => {
                let spacing = (lattice.volume() as f64 / sets.len().max(1) as f64)
                    .powf(1.0 / lattice.dim() as f64);
                (spacing.ceil() as u64).max(max_extent).next_power_of_two()
            }
        };
        let mut grid = LatticeGridBoxes::new(lattice, side).expect("power of two");
        if grid.stops_paying() {
            notes.push(format!(
                "grid box {side} has 3A >= L on some axis: grid-boxing does not pay, using all-pairs"
            ));
            return Err(arrays);
        }
        grid.set_side(side, sets).expect("power of two");
        notes.push(format!("grid box side {side}"));
        Ok(DoublingGrid {
            inner: Indexed::registered(arrays, grid),
            bbox,
        })
    }

    /// Union of the bounding boxes of `into` and `from` in the frame of the union's anchor.
    fn merge_bbox(&mut self, into: ItemId, from: ItemId, (anchor_into, anchor_from): (u64, u64)) {
        let sets = self.inner.sets();
        let lattice = sets.lattice();
        let delta = lattice.displacement(anchor_into, anchor_from);
        let (a, b) = (self.bbox[into as usize], self.bbox[from as usize]);
        let mut u = a;
        for axis in 0..lattice.dim() {
            u.lo[axis] = a.lo[axis].min(delta[axis] + b.lo[axis]);
            u.hi[axis] = a.hi[axis].max(delta[axis] + b.hi[axis]);
        }
        // The union's array starts with the larger part: its anchor may be `from`'s.
        if sets.sites(into)[0] != anchor_into {
            for axis in 0..lattice.dim() {
                u.lo[axis] -= delta[axis];
                u.hi[axis] -= delta[axis];
            }
        }
        self.bbox[into as usize] = u;
    }

    /// Double the box side until it holds cluster `id` (section II.A); once `3A >= L` on some
    /// axis (section V), abandon grid-boxing for all-pairs (returns `true`).
    fn maybe_double(&mut self, id: ItemId, notes: &mut Vec<String>) -> bool {
        let dim = self.inner.sets().lattice().dim();
        let extent = extent(dim, &self.bbox[id as usize]);
        let mut side = self.inner.search().side();
        if extent <= side {
            return false;
        }
        while side < extent {
            side *= 2;
        }
        let probe = LatticeGridBoxes::new(self.inner.sets().lattice(), side).expect("power of two");
        if probe.stops_paying() {
            notes.push(format!(
                "largest cluster spans {extent} sites: grid box {side} has 3A >= L, continuing as all-pairs"
            ));
            return true;
        }
        let (grid, sets) = self.inner.search_mut();
        grid.set_side(side, sets).expect("power of two");
        notes.push(format!(
            "largest cluster spans {extent} sites: grid box doubled to {side}"
        ));
        false
    }
}

/// Bounding box of cluster `id` from its sites (minimum image relative to its anchor).
fn measure_bbox(sets: &SiteSets, id: ItemId) -> BBox {
    let lattice = sets.lattice();
    let sites = sets.sites(id);
    let mut b = BBox::default();
    for &k in sites {
        let d = lattice.displacement(sites[0], k);
        for axis in 0..lattice.dim() {
            b.lo[axis] = b.lo[axis].min(d[axis]);
            b.hi[axis] = b.hi[axis].max(d[axis]);
        }
    }
    b
}

/// Largest extent (sites spanned) of bounding box `b` over the `dim` axes.
fn extent(dim: usize, b: &BBox) -> u64 {
    (0..dim)
        .map(|a| (b.hi[a] - b.lo[a] + 1) as u64)
        .max()
        .unwrap_or(1)
}

impl ClusterStore for DoublingGrid {
    forward_clusters!(s => s.inner);

    fn kind(&self) -> Search {
        Search::GridDoubling
    }

    fn grid_side(&self) -> Option<u64> {
        Some(self.inner.search().side())
    }

    fn merge(&mut self, survivor: ItemId, others: &[ItemId], notes: &mut Vec<String>) -> Merged {
        for &other in others {
            let sets = self.inner.sets();
            let anchors = (sets.sites(survivor)[0], sets.sites(other)[0]);
            self.inner.merge_one(survivor, other);
            self.merge_bbox(survivor, other, anchors);
        }
        let size = self.inner.finish_merge(survivor);
        Merged {
            size,
            to_all_pairs: self.maybe_double(survivor, notes),
        }
    }

    fn sets(&self) -> &SiteSets {
        self.inner.sets()
    }

    fn forget_views(&mut self) {}

    fn check(&self) {
        // The arrays are the clusters; the simulation checks them.
    }

    fn take_arrays(&mut self) -> ClusterArrays {
        self.inner.take_arrays()
    }
}
