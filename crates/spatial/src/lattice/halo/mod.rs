//! Rigid lattice shapes listed in small grid boxes by their halos, with a box side tuned at
//! run time ([`HaloGrid`]): exact face-contact search for moving, merging clusters of lattice
//! sites. DLCA's default `grid` strategy; the grid-boxing paper's own boxes are
//! [`LatticeGridBoxes`](super::LatticeGridBoxes), its baseline setting. It follows the
//! paper's closing advice (Hawick, James & Scogings 2006, "Grid-Boxing for Spatial Simulation
//! Performance Optimisation", section V): keep boxes "ostensibly too small" for the largest
//! cluster, "construct halos on an individual basis", and "build in self-tuning of the
//! grid-boxing ... to adjust this at runtime".
//!
//! - Each cluster is a rigid `Shape` (origin plus sorted relative positions): a move changes
//!   its origin and its bounding `Region` in O(1).
//! - Its *halo* is its bounding region grown by one site: every site face-adjacent to it. The
//!   cluster is listed in every grid box its halo overlaps (`HaloBoxes`); a move re-lists it
//!   only in the slab of boxes its halo enters or leaves.
//! - The candidates of a move are the clusters listed in the mover's boxes: two clusters in
//!   contact have a site in both halos, so they share that site's box. A candidate whose
//!   bounding region misses the mover's halo is dropped at once; the others get the exact
//!   particle test (`touches`).
//! - The box side is the power of two with the least predicted cost (`predicted_cost`: boxes
//!   per cluster against clusters per box). It is re-tuned each time the number of clusters
//!   falls past a step of a geometric scale (about 16% apart), and the boxes are rebuilt when
//!   another side is predicted at most [`RETUNE_GAIN`] times as costly.
//!
//! Invariant: the contacts of a move are exactly the clusters touching the mover, in
//! increasing id, whatever the boxes and their side (so a model's trajectory cannot depend on
//! them); `tests/halo_props.rs` checks this against a brute-force scan.

mod boxes;
mod region;
mod shape;

use super::sets::LiveList;
use super::{ItemId, SiteSets};
use boxes::{HaloBoxes, box_count, predicted_cost};
use core_lattice::{Blocked, Direction, Lattice};
use region::Region;
use shape::{Shape, touches};

/// Rebuild the boxes when another side is predicted to cost at most this fraction of the
/// current one (hysteresis: re-tuning costs a rebuild).
pub const RETUNE_GAIN: f64 = 0.6;

/// Re-tune when `floor(RETUNE_STEPS * log2(clusters))` changes.
const RETUNE_STEPS: f64 = 4.0;

/// Boxes at most this many per particle, plus [`BOX_ALLOWANCE`]: on a large, dilute lattice
/// the box count follows the particles, not the sites.
const BOXES_PER_PARTICLE: u64 = 8;
const BOX_ALLOWANCE: u64 = 1 << 16;

/// A re-tuning of the box side during a merge, for the caller's log.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Retuned {
    /// Live clusters after the merge.
    pub clusters: usize,
    /// The box side before and after.
    pub from: u64,
    /// The new box side.
    pub to: u64,
    /// Predicted cost of a sweep (box-list entries) with the old side.
    pub cost_before: f64,
    /// Predicted cost of a sweep with the new side.
    pub cost_after: f64,
}

/// The clusters as rigid shapes, listed in grid boxes by their halos; see the module
/// documentation.
///
/// Clusters are numbered by [`ItemId`] as in the [`SiteSets`] it is built from; a merge keeps
/// the survivor's id and retires the others'. The caller keeps clusters apart: between two
/// calls no two clusters are face-adjacent (DLCA merges them as soon as they touch).
///
/// ```
/// use core_lattice::{Boundary, Direction, Lattice};
/// use spatial::lattice::{HaloGrid, SiteSets};
/// let lattice = Lattice::with_boundary(&[16, 16], Boundary::Periodic).unwrap();
/// let mut sets = SiteSets::new(lattice.clone());
/// sets.push(vec![lattice.encode(&[2, 2]).unwrap()]);
/// sets.push(vec![lattice.encode(&[4, 2]).unwrap()]);
/// let mut grid = HaloGrid::new(&sets, None);
/// let mut contacts = Vec::new();
/// // Cluster 0 steps towards cluster 1 and touches it.
/// grid.try_move(0, Direction::new(0, true), &mut contacts).unwrap();
/// assert_eq!(contacts, [1]);
/// let (size, _) = grid.merge(0, &[1]);
/// assert_eq!((size, grid.live()), (2, &[0][..]));
/// ```
#[derive(Debug, Clone)]
pub struct HaloGrid {
    lattice: Lattice,
    /// Every cluster id ever handed out: its shape (empty once retired) and bounding region.
    shapes: Vec<Shape>,
    regions: Vec<Region>,
    /// The live cluster ids (a copy of the sets' list at the start, then retired on merges).
    live: LiveList,
    particles: u64,
    boxes: HaloBoxes,
    /// The step of the cluster count's geometric scale at the last tuning.
    tuned_at: i64,
    candidates: Vec<ItemId>,
    scratch: Vec<u64>,
}

/// The step of `clusters` on the re-tuning scale.
fn tuning_step(clusters: usize) -> i64 {
    ((clusters.max(1) as f64).log2() * RETUNE_STEPS).floor() as i64
}

impl HaloGrid {
    /// The live clusters of `sets` (with their ids; none may be face-adjacent to another), in
    /// grid boxes of side `requested` (a power of two) or, by default, of the side with the
    /// least predicted cost. [`HaloGrid::side`] tells the side chosen.
    pub fn new(sets: &SiteSets, requested: Option<u64>) -> Self {
        let lattice = sets.lattice().clone();
        let mut shapes = vec![Shape::default(); sets.id_bound()];
        let mut regions = vec![Region::default(); sets.id_bound()];
        for &id in sets.live() {
            let sites = sets.sites(id);
            shapes[id as usize] = Shape::of(&lattice, sites);
            regions[id as usize] = Region::of(&lattice, sites);
        }
        let mut grid = HaloGrid {
            boxes: HaloBoxes::new(&lattice, 1 << 62),
            lattice,
            shapes,
            regions,
            live: sets.live_list().clone(),
            particles: sets.total_sites(),
            tuned_at: tuning_step(sets.len()),
            candidates: Vec::new(),
            scratch: Vec::new(),
        };
        let side = requested.unwrap_or_else(|| grid.best_side().0);
        grid.rebuild(side);
        grid
    }

    /// The lattice.
    pub fn lattice(&self) -> &Lattice {
        &self.lattice
    }

    /// The box side `A`.
    pub fn side(&self) -> u64 {
        self.boxes.side()
    }

    /// Live cluster ids, in no particular order.
    #[inline]
    pub fn live(&self) -> &[ItemId] {
        self.live.ids()
    }

    /// Whether cluster `id` is live.
    #[inline]
    pub fn contains(&self, id: ItemId) -> bool {
        self.live.contains(id)
    }

    /// Number of particles of live cluster `id`.
    #[inline]
    pub fn len_of(&self, id: ItemId) -> usize {
        self.shapes[id as usize].len()
    }

    /// The halo of cluster `id`.
    #[inline]
    fn halo(&self, id: ItemId) -> Region {
        self.regions[id as usize].halo(&self.lattice)
    }

    /// The power-of-two side with the least [`predicted_cost`] for the clusters now, among
    /// those giving at most [`BOXES_PER_PARTICLE`] boxes per particle (plus an allowance), and
    /// that cost.
    fn best_side(&self) -> (u64, f64) {
        let halos: Vec<Region> = self.live.ids().iter().map(|&id| self.halo(id)).collect();
        let longest = self.lattice.sizes().iter().copied().max().unwrap_or(1);
        let most_boxes = self.particles.saturating_mul(BOXES_PER_PARTICLE) + BOX_ALLOWANCE;
        let mut best = (longest.next_power_of_two(), f64::INFINITY);
        let mut side = 1;
        while side <= longest.next_power_of_two() {
            if box_count(&self.lattice, side) <= most_boxes {
                let cost = predicted_cost(&self.lattice, side, halos.iter());
                if cost < best.1 {
                    best = (side, cost);
                }
            }
            side *= 2;
        }
        best
    }

    /// Boxes of side `side`, listing every live cluster.
    fn rebuild(&mut self, side: u64) {
        self.boxes = HaloBoxes::new(&self.lattice, side);
        for i in 0..self.live.ids().len() {
            let id = self.live.ids()[i];
            let halo = self.halo(id);
            self.boxes.register(id, &halo);
        }
    }

    /// Re-tune the box side if the cluster count has passed a step of its scale since the last
    /// tuning and another side is predicted to be enough cheaper.
    fn maybe_retune(&mut self) -> Option<Retuned> {
        let step = tuning_step(self.live.ids().len());
        if step == self.tuned_at {
            return None;
        }
        self.tuned_at = step;
        let side = self.boxes.side();
        let halos: Vec<Region> = self.live.ids().iter().map(|&id| self.halo(id)).collect();
        let now = predicted_cost(&self.lattice, side, halos.iter());
        let (best, cost) = self.best_side();
        if best != side && cost <= RETUNE_GAIN * now {
            self.rebuild(best);
            return Some(Retuned {
                clusters: self.live.ids().len(),
                from: side,
                to: best,
                cost_before: now,
                cost_after: cost,
            });
        }
        None
    }

    /// The clusters as k-index arrays, with the same ids (retired ids removed). O(N).
    pub fn to_sets(&self) -> SiteSets {
        let mut sets = SiteSets::new(self.lattice.clone());
        for id in 0..self.shapes.len() as ItemId {
            sets.push(if self.contains(id) {
                self.shapes[id as usize].sites(&self.lattice)
            } else {
                Vec::new()
            });
        }
        for id in 0..self.shapes.len() as ItemId {
            if !self.contains(id) {
                sets.remove(id);
            }
        }
        sets
    }
}

impl HaloGrid {
    /// Moves cluster `id` by `dir`, all or nothing (a wall blocks the whole cluster), and
    /// writes the clusters then face-adjacent to it to `contacts`, in increasing id: moves the
    /// shape and its region, re-lists the halo's boxes where it crossed a box boundary, and
    /// tests the candidates sharing a box with it. Returns the number of candidates examined.
    pub fn try_move(
        &mut self,
        id: ItemId,
        dir: Direction,
        contacts: &mut Vec<ItemId>,
    ) -> Result<usize, Blocked> {
        contacts.clear();
        let i = id as usize;
        if self.regions[i].blocked(&self.lattice, dir) {
            return Err(Blocked);
        }
        let old_halo = self.halo(id);
        self.regions[i].shift(&self.lattice, dir);
        self.shapes[i].shift(&self.lattice, dir);
        let halo = self.halo(id);
        self.boxes.moved(id, dir.axis(), &old_halo, &halo);
        let mut candidates = std::mem::take(&mut self.candidates);
        candidates.clear();
        self.boxes.sharing(id, &halo, &mut candidates);
        let lattice = &self.lattice;
        let mine = (&self.shapes[i], &self.regions[i]);
        for &other in &candidates {
            let o = other as usize;
            if self.regions[o].meets(&halo, lattice)
                && touches(lattice, dir, mine, (&self.shapes[o], &self.regions[o]))
            {
                contacts.push(other);
            }
        }
        let examined = candidates.len();
        self.candidates = candidates;
        contacts.sort_unstable();
        Ok(examined)
    }

    /// Merges every cluster of `others` (live, distinct, other than `survivor`) into
    /// `survivor`, which keeps its id; the others' ids are retired. Returns the survivor's
    /// size and, when the cluster count passed a step of its scale and another box side was
    /// predicted to be enough cheaper, the re-tuning done.
    pub fn merge(&mut self, survivor: ItemId, others: &[ItemId]) -> (usize, Option<Retuned>) {
        let s = survivor as usize;
        let halo = self.halo(survivor);
        self.boxes.unregister(survivor, &halo);
        for &other in others {
            let o = other as usize;
            let halo = self.halo(other);
            self.boxes.unregister(other, &halo);
            // The larger shape keeps its frame and absorbs the smaller.
            let mut from = std::mem::take(&mut self.shapes[o]);
            if from.len() > self.shapes[s].len() {
                std::mem::swap(&mut from, &mut self.shapes[s]);
            }
            self.shapes[s].absorb(&self.lattice, &from, &mut self.scratch);
            self.regions[s] = self.regions[s].union(&self.regions[o], &self.lattice);
            self.live.unlink(other);
        }
        let halo = self.halo(survivor);
        self.boxes.register(survivor, &halo);
        let size = self.shapes[s].len();
        (size, self.maybe_retune())
    }

    /// Panics unless every shape is sorted and inside its region, and every box lists exactly
    /// the clusters whose halo overlaps it. For tests.
    pub fn check(&self) {
        let mut halos = Vec::with_capacity(self.live.ids().len());
        for &id in self.live.ids() {
            let shape = &self.shapes[id as usize];
            assert!(
                shape.is_consistent(),
                "cluster {id}: shape keys unsorted or not indexed"
            );
            for k in shape.sites(&self.lattice) {
                let x = self.lattice.coords_array(k);
                assert!(
                    self.regions[id as usize].contains(&self.lattice, &x),
                    "cluster {id}: site {k} outside its bounding region"
                );
            }
            halos.push((id, self.halo(id)));
        }
        self.boxes.check(&halos);
    }
}
