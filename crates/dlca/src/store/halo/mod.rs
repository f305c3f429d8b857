//! The `grid` strategy: small grid boxes with a halo per cluster, and a box side tuned at run
//! time (Hawick, James & Scogings 2006, section V: keep boxes "ostensibly too small" for the
//! largest cluster, "construct halos on an individual basis", and "build in self-tuning of the
//! grid-boxing ... to adjust this at runtime").
//!
//! - Each cluster is a rigid [`Shape`] (origin plus sorted relative positions): a move changes
//!   its origin and its bounding [`Region`] in O(1).
//! - Its *halo* is its bounding region grown by one site: every site face-adjacent to it. The
//!   cluster is listed in every grid box its halo overlaps ([`HaloBoxes`]); a move re-lists it
//!   only in the slab of boxes its halo enters or leaves.
//! - The candidates of a move are the clusters listed in the mover's boxes: two clusters in
//!   contact have a site in both halos, so they share that site's box. A candidate whose
//!   bounding region misses the mover's halo is dropped at once; the others get the exact
//!   particle test ([`touches`]).
//! - The box side is the power of two with the least [`predicted_cost`] (boxes per cluster
//!   against clusters per box). It is re-tuned each time the number of clusters falls past a
//!   step of a geometric scale (about 16% apart), and the boxes are rebuilt when another side
//!   is predicted at most [`RETUNE_GAIN`] times as costly.
//!
//! Invariant: as every strategy, the contacts of a move are exactly the clusters touching the
//! mover, in increasing id, so the trajectory does not depend on the boxes or their side.

mod boxes;
mod region;
mod shape;

use super::arrays::ClusterArrays;
use super::strategy::{ClusterStore, Merged};
use crate::params::Search;
use boxes::{HaloBoxes, box_count, predicted_cost};
use core_lattice::{Blocked, Direction, Lattice};
use region::Region;
use shape::{Shape, touches};
use spatial::lattice::{ItemId, SiteSets};
use std::sync::OnceLock;

/// Rebuild the boxes when another side is predicted to cost at most this fraction of the
/// current one (hysteresis: re-tuning costs a rebuild).
const RETUNE_GAIN: f64 = 0.6;

/// Re-tune when `floor(RETUNE_STEPS * log2(clusters))` changes.
const RETUNE_STEPS: f64 = 4.0;

/// Boxes at most this many per particle, plus [`BOX_ALLOWANCE`]: on a large, dilute lattice
/// the box count follows the particles, not the sites.
const BOXES_PER_PARTICLE: u64 = 8;
const BOX_ALLOWANCE: u64 = 1 << 16;

/// Position of a cluster id in the live list, or this for a retired id.
const DEAD: u32 = u32::MAX;

/// The clusters as rigid shapes, listed in grid boxes by their halos.
#[derive(Debug)]
pub(crate) struct HaloGrid {
    lattice: Lattice,
    /// Every cluster id ever handed out: its shape (empty once retired) and bounding region.
    shapes: Vec<Shape>,
    regions: Vec<Region>,
    live: Vec<ItemId>,
    position: Vec<u32>,
    particles: u64,
    boxes: HaloBoxes,
    /// The step of the cluster count's geometric scale at the last tuning.
    tuned_at: i64,
    /// The clusters as k-index arrays, built by [`ClusterStore::sets`] and dropped by
    /// [`ClusterStore::forget_views`].
    materialized: OnceLock<SiteSets>,
    candidates: Vec<ItemId>,
    scratch: Vec<u64>,
}

/// The step of `clusters` on the re-tuning scale.
fn tuning_step(clusters: usize) -> i64 {
    ((clusters.max(1) as f64).log2() * RETUNE_STEPS).floor() as i64
}

impl HaloGrid {
    /// The clusters of `arrays`, in grid boxes of side `requested` (a power of two) or, by
    /// default, of the side with the least predicted cost. Pushes the side chosen to `notes`.
    pub(crate) fn new(
        arrays: ClusterArrays,
        requested: Option<u64>,
        notes: &mut Vec<String>,
    ) -> Self {
        let sets = arrays.sets();
        let lattice = sets.lattice().clone();
        let mut shapes = vec![Shape::default(); sets.id_bound()];
        let mut regions = vec![Region::default(); sets.id_bound()];
        let mut position = vec![DEAD; sets.id_bound()];
        let mut live = Vec::with_capacity(sets.len());
        for &id in sets.live() {
            let sites = sets.sites(id);
            shapes[id as usize] = Shape::of(&lattice, sites);
            regions[id as usize] = Region::of(&lattice, sites);
            position[id as usize] = live.len() as u32;
            live.push(id);
        }
        let mut grid = HaloGrid {
            boxes: HaloBoxes::new(&lattice, 1 << 62),
            lattice,
            shapes,
            regions,
            live,
            position,
            particles: sets.total_sites(),
            tuned_at: tuning_step(sets.len()),
            materialized: OnceLock::new(),
            candidates: Vec::new(),
            scratch: Vec::new(),
        };
        let side = requested.unwrap_or_else(|| grid.best_side().0);
        grid.rebuild(side);
        notes.push(match requested {
            Some(_) => format!("grid box side {side} (halo per cluster, re-tuned as clusters grow)"),
            None => format!(
                "grid box side {side} (halo per cluster, least predicted cost; re-tuned as clusters grow)"
            ),
        });
        grid
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
        let halos: Vec<Region> = self.live.iter().map(|&id| self.halo(id)).collect();
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
        for i in 0..self.live.len() {
            let id = self.live[i];
            let halo = self.halo(id);
            self.boxes.register(id, &halo);
        }
    }

    /// Re-tune the box side if the cluster count has passed a step of its scale since the last
    /// tuning and another side is predicted to be enough cheaper.
    fn maybe_retune(&mut self, notes: &mut Vec<String>) {
        let step = tuning_step(self.live.len());
        if step == self.tuned_at {
            return;
        }
        self.tuned_at = step;
        let side = self.boxes.side();
        let halos: Vec<Region> = self.live.iter().map(|&id| self.halo(id)).collect();
        let now = predicted_cost(&self.lattice, side, halos.iter());
        let (best, cost) = self.best_side();
        if best != side && cost <= RETUNE_GAIN * now {
            self.rebuild(best);
            notes.push(format!(
                "{} clusters: grid box side re-tuned from {side} to {best} (predicted cost per sweep {now:.0} -> {cost:.0})",
                self.live.len()
            ));
        }
    }

    /// Retire cluster `id` from the live list.
    fn unlink(&mut self, id: ItemId) {
        let p = self.position[id as usize] as usize;
        self.live.swap_remove(p);
        if let Some(&moved) = self.live.get(p) {
            self.position[moved as usize] = p as u32;
        }
        self.position[id as usize] = DEAD;
    }

    /// The clusters as k-index arrays, with the same ids.
    fn to_sets(&self) -> SiteSets {
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

impl ClusterStore for HaloGrid {
    fn kind(&self) -> Search {
        Search::Grid
    }

    fn grid_side(&self) -> Option<u64> {
        Some(self.boxes.side())
    }

    #[inline]
    fn live(&self) -> &[ItemId] {
        &self.live
    }

    #[inline]
    fn contains(&self, id: ItemId) -> bool {
        self.position.get(id as usize).is_some_and(|&p| p != DEAD)
    }

    #[inline]
    fn len_of(&self, id: ItemId) -> usize {
        self.shapes[id as usize].len()
    }

    /// Moves the shape and its region, re-lists the halo's boxes where it crossed a box
    /// boundary, and tests the candidates sharing a box with it. Returns the number of
    /// candidates.
    fn try_move(
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

    fn merge(&mut self, survivor: ItemId, others: &[ItemId], notes: &mut Vec<String>) -> Merged {
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
            self.unlink(other);
        }
        let halo = self.halo(survivor);
        self.boxes.register(survivor, &halo);
        let size = self.shapes[s].len();
        self.maybe_retune(notes);
        Merged {
            size,
            to_all_pairs: false,
        }
    }

    fn sets(&self) -> &SiteSets {
        self.materialized.get_or_init(|| self.to_sets())
    }

    fn forget_views(&mut self) {
        self.materialized.take();
    }

    /// Every shape sorted and inside its region, and every box listing exactly the clusters
    /// whose halo overlaps it.
    fn check(&self) {
        let mut halos = Vec::with_capacity(self.live.len());
        for &id in &self.live {
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

    fn take_arrays(&mut self) -> ClusterArrays {
        ClusterArrays::new(self.to_sets())
    }
}
