//! Contact search for items made of lattice sites: the DLCA clusters of the grid-boxing paper.
//!
//! Hawick, James & Scogings (2006), sections II.A, III and IV.A: after a cluster moves one
//! lattice step, the model must find every other cluster with a particle face-adjacent to one of
//! its particles, and merge with them. This module holds the clusters and three interchangeable
//! ways to answer that question, all giving exactly the same answer:
//!
//! - [`AllPairs`]: the paper's "no grid" baseline: every other cluster, particle by particle,
//!   comparing one axis at a time and leaving as soon as one axis is too far apart.
//! - [`LatticeGridBoxes`]: the paper's grid boxes (Fig. 1): boxes of side `A` (a power of two);
//!   each cluster is registered in every box holding one of its particles; a move examines only
//!   the clusters registered in the mover's boxes and their `3^d` halo.
//! - [`Occupancy`]: a lattice holding the cluster id of every site; contact is `2d` lookups per
//!   moved particle.
//!
//! [`SiteSets`] stores the clusters themselves as arrays of k-indices with an indirect list of
//! live clusters, the data structure of the paper's Fig. 2.
//!
//! Every strategy implements [`ContactSearch`]; a model keeps one [`SiteSets`] and one
//! strategy and calls the strategy's `insert`, `moved`, `merge`, `remove` alongside its own
//! updates. Contacts come back sorted by id, so a model's trajectory never depends on the
//! strategy. These three are the paper's settings, the baseline its measurements use (DLCA's
//! `all-pairs` and `grid-doubling` strategies, and `lattice` in 4 and 5 dimensions).
//!
//! [`HaloGrid`] ([`halo`]) is the structure DLCA runs by default (its `grid` strategy): it
//! keeps the clusters itself, as rigid shapes listed in small grid boxes by their halos, with
//! a self-tuned box side, and gives the same contacts.

mod all_pairs;
mod grid;
pub mod halo;
mod occupancy;
mod sets;

pub use all_pairs::AllPairs;
pub use grid::{GridError, LatticeGridBoxes};
pub use halo::HaloGrid;
pub use occupancy::{Occupancy, OccupancyError};
pub use sets::SiteSets;

use core_lattice::{Direction, Lattice, MAX_DIM};

/// Identifier of an item (a cluster). Ids index dense arrays, so keep them small: models number
/// clusters `0..N`.
pub type ItemId = u32;

/// The contact query shared by the three strategies (the grid-boxing paper, section IV.A).
///
/// The caller keeps the [`SiteSets`] and the strategy in step: every change to the sets is
/// reported to the strategy with the same arguments. Items must not share sites (in DLCA they
/// merge as soon as they touch, so they never overlap).
pub trait ContactSearch {
    /// A short name for logs and result files: `all-pairs`, `grid`, `lattice`.
    fn name(&self) -> &'static str;

    /// A new item `id` occupying `sites` (already stored in the sets).
    fn insert(&mut self, sets: &SiteSets, id: ItemId);

    /// Item `id`, occupying `sites`, is about to be removed from the sets.
    fn remove(&mut self, sets: &SiteSets, id: ItemId);

    /// Item `id` moved by the unit vector `dir`: site `i` went from `old[i]` to `new[i]` (the
    /// sets already hold `new`).
    fn moved(&mut self, sets: &SiteSets, id: ItemId, old: &[u64], new: &[u64], dir: Direction);

    /// Item `from` was merged into item `into` by [`SiteSets::merge`], which returned
    /// `from_len`: the sets already hold the union under `into` and `from` is gone
    /// ([`SiteSets::merged_parts`] recovers which sites were whose).
    fn merge(&mut self, sets: &SiteSets, into: ItemId, from: ItemId, from_len: usize);

    /// The items other than `id` with a site face-adjacent to a site of `id`, in increasing
    /// id, without repeats, written to `out` (which is cleared first). Returns the number of
    /// candidate items examined (the quantity histogrammed in the grid-boxing paper, Figs. 4, 7,
    /// 8).
    fn contacts(&mut self, sets: &SiteSets, id: ItemId, out: &mut Vec<ItemId>) -> usize;
}

/// Coordinates of a site as a fixed array (axes beyond the dimension are 0).
#[inline]
fn coords_of(lattice: &Lattice, k: u64) -> [u64; MAX_DIM] {
    lattice.coords_array(k)
}

/// Whether site coordinates `p` and `q` are face-adjacent, comparing one axis at a time and
/// leaving at the first axis on which they are more than one step apart (the per-axis early
/// exit of the grid-boxing paper's all-pairs search).
#[inline]
fn adjacent_coords(lattice: &Lattice, p: &[u64; MAX_DIM], q: &[u64; MAX_DIM]) -> bool {
    let mut unit_axes = 0;
    for axis in 0..lattice.dim() {
        let (a, b) = (p[axis], q[axis]);
        let diff = a.abs_diff(b);
        if diff == 0 {
            continue;
        }
        let near = diff == 1
            || (diff + 1 == lattice.size(axis)
                && lattice.boundary(axis) == core_lattice::Boundary::Periodic);
        if !near {
            return false;
        }
        unit_axes += 1;
        if unit_axes > 1 {
            return false;
        }
    }
    unit_axes == 1
}

/// Whether any site of `a` is face-adjacent to any site of `b`, by the all-pairs test with the
/// per-axis early exit. `a_coords` are the decoded coordinates of `a`.
fn touches(lattice: &Lattice, a_coords: &[[u64; MAX_DIM]], b: &[u64]) -> bool {
    b.iter().any(|&k| {
        let q = coords_of(lattice, k);
        a_coords.iter().any(|p| adjacent_coords(lattice, p, &q))
    })
}

/// A generation-stamped set of small integers: `insert` is O(1), clearing is O(1) amortised.
/// Used to report each candidate item and each halo box once.
/// Public for the other contact indexes built on this module's types (dlca's halo grid).
#[derive(Debug, Clone, Default)]
pub struct StampSet {
    stamps: Vec<u32>,
    generation: u32,
}

impl StampSet {
    /// Empties the set.
    pub fn clear(&mut self) {
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.stamps.iter_mut().for_each(|s| *s = 0);
            self.generation = 1;
        }
    }

    /// Insert `i`; true if it was not yet in the set.
    #[inline]
    pub fn insert(&mut self, i: usize) -> bool {
        if i >= self.stamps.len() {
            self.stamps.resize((i + 1).max(2 * self.stamps.len()), 0);
        }
        if self.stamps[i] == self.generation {
            false
        } else {
            self.stamps[i] = self.generation;
            true
        }
    }
}
