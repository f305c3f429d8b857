//! A cluster as a rigid shape ([`Shape`]): an origin plus its particles' positions relative to
//! it, sorted, so that a move changes the origin alone and membership is a binary search; and
//! the exact contact test between two shapes ([`touches`]).
//!
//! Coordinates: a relative position is the absolute one minus the origin, modulo `L` on every
//! axis, encoded like a k-index (`key`); on a wall axis the cluster never wraps, so the modulo
//! is only a bijection there. Invariant: `keys` is sorted and without repeats, and
//! `origin + key` (axis by axis, modulo `L`) is exactly the set of the cluster's sites.

use super::region::Region;
use core_lattice::{Boundary, Direction, Lattice, MAX_DIM};

/// Clusters up to this size absorb another cluster by binary insertion; larger ones by a merge
/// of the two sorted key lists.
const INSERT_MAX: usize = 16;

/// Shapes of at least this many particles also keep their keys in a hash table, so that a
/// membership test is one or two probes instead of a binary search.
const HASHED_MIN: usize = 64;

/// A cluster: an origin and the sorted relative positions of its particles.
#[derive(Debug, Clone, Default)]
pub(super) struct Shape {
    origin: [u64; MAX_DIM],
    keys: Vec<u64>,
    /// The keys again, for shapes of at least [`HASHED_MIN`] particles.
    table: KeyTable,
}

/// A set of keys by open addressing with linear probing, at most half full.
#[derive(Debug, Clone, Default)]
struct KeyTable {
    slots: Vec<u64>,
    len: usize,
    /// `64 - log2(slots)`.
    shift: u32,
}

/// An empty slot (no key reaches it: keys are below the lattice volume).
const EMPTY: u64 = u64::MAX;

impl KeyTable {
    #[inline]
    fn slot(&self, key: u64) -> usize {
        (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> self.shift) as usize
    }

    fn insert(&mut self, key: u64) {
        if 2 * (self.len + 1) > self.slots.len() {
            self.grow();
        }
        let mask = self.slots.len() - 1;
        let mut i = self.slot(key);
        while self.slots[i] != EMPTY {
            i = (i + 1) & mask;
        }
        self.slots[i] = key;
        self.len += 1;
    }

    fn grow(&mut self) {
        let n = (2 * self.slots.len()).max(2 * HASHED_MIN);
        let old = std::mem::replace(&mut self.slots, vec![EMPTY; n]);
        self.shift = 64 - n.trailing_zeros();
        self.len = 0;
        for key in old.into_iter().filter(|&k| k != EMPTY) {
            self.insert(key);
        }
    }

    #[inline]
    fn contains(&self, key: u64) -> bool {
        let mask = self.slots.len() - 1;
        let mut i = self.slot(key);
        loop {
            let s = self.slots[i];
            if s == key {
                return true;
            }
            if s == EMPTY {
                return false;
            }
            i = (i + 1) & mask;
        }
    }
}

/// The relative key of absolute coordinates `x` in the frame of `origin`.
#[inline]
fn key_of(lattice: &Lattice, origin: &[u64; MAX_DIM], x: &[u64; MAX_DIM]) -> u64 {
    let mut key = 0;
    for axis in 0..lattice.dim() {
        let size = lattice.size(axis);
        let rel = if x[axis] >= origin[axis] {
            x[axis] - origin[axis]
        } else {
            x[axis] + size - origin[axis]
        };
        key += rel * lattice.stride(axis);
    }
    key
}

/// The absolute coordinates of relative key `key` in the frame of `origin`.
#[inline]
fn coords_of_key(lattice: &Lattice, origin: &[u64; MAX_DIM], key: u64) -> [u64; MAX_DIM] {
    let mut x = lattice.coords_array(key);
    for axis in 0..lattice.dim() {
        let size = lattice.size(axis);
        x[axis] += origin[axis];
        if x[axis] >= size {
            x[axis] -= size;
        }
    }
    x
}

impl Shape {
    /// The shape of `sites` (not empty), with its first site as origin.
    pub(super) fn of(lattice: &Lattice, sites: &[u64]) -> Self {
        let origin = lattice.coords_array(sites[0]);
        let mut keys: Vec<u64> = sites
            .iter()
            .map(|&k| key_of(lattice, &origin, &lattice.coords_array(k)))
            .collect();
        keys.sort_unstable();
        let mut shape = Shape {
            origin,
            keys,
            table: KeyTable::default(),
        };
        shape.index_keys(&[]);
        shape
    }

    /// Keep the hash table in step with the keys, after `added` were added to them: all of
    /// them once the shape reaches [`HASHED_MIN`] particles, then those added.
    fn index_keys(&mut self, added: &[u64]) {
        if self.keys.len() < HASHED_MIN {
            return;
        }
        if self.table.len == 0 {
            for &k in &self.keys {
                self.table.insert(k);
            }
        } else {
            for &k in added {
                self.table.insert(k);
            }
        }
    }

    /// Number of particles.
    #[inline]
    pub(super) fn len(&self) -> usize {
        self.keys.len()
    }

    /// Translate by `dir` (the move is allowed).
    #[inline]
    pub(super) fn shift(&mut self, lattice: &Lattice, dir: Direction) {
        let axis = dir.axis();
        let size = lattice.size(axis);
        let o = &mut self.origin[axis];
        *o = if dir.is_positive() {
            (*o + 1) % size
        } else {
            (*o + size - 1) % size
        };
    }

    /// Whether relative key `key` is a particle of the shape.
    #[inline]
    fn holds_key(&self, key: u64) -> bool {
        if self.table.len > 0 {
            self.table.contains(key)
        } else {
            self.keys.binary_search(&key).is_ok()
        }
    }

    /// Add the particles of `other` (no site in common), in this shape's frame. `scratch` is
    /// reused between calls.
    pub(super) fn absorb(&mut self, lattice: &Lattice, other: &Shape, scratch: &mut Vec<u64>) {
        scratch.clear();
        scratch.extend(other.keys.iter().map(|&k| {
            let x = coords_of_key(lattice, &other.origin, k);
            key_of(lattice, &self.origin, &x)
        }));
        scratch.sort_unstable();
        if scratch.len() <= INSERT_MAX {
            for &k in scratch.iter() {
                let at = self.keys.partition_point(|&s| s < k);
                self.keys.insert(at, k);
            }
            self.index_keys(scratch);
            return;
        }
        let mut merged = Vec::with_capacity(self.keys.len() + scratch.len());
        let (mut i, mut j) = (0, 0);
        while i < self.keys.len() && j < scratch.len() {
            if self.keys[i] < scratch[j] {
                merged.push(self.keys[i]);
                i += 1;
            } else {
                merged.push(scratch[j]);
                j += 1;
            }
        }
        merged.extend_from_slice(&self.keys[i..]);
        merged.extend_from_slice(&scratch[j..]);
        self.keys = merged;
        self.index_keys(scratch);
    }

    /// The particles' sites (k-indices), in relative-key order.
    pub(super) fn sites(&self, lattice: &Lattice) -> Vec<u64> {
        self.keys
            .iter()
            .map(|&k| {
                let x = coords_of_key(lattice, &self.origin, k);
                (0..lattice.dim())
                    .map(|a| x[a] * lattice.stride(a))
                    .sum::<u64>()
            })
            .collect()
    }

    /// Whether the keys are sorted without repeats and the hash table, if any, holds exactly
    /// them (the invariant). For tests.
    pub(super) fn is_consistent(&self) -> bool {
        self.keys.windows(2).all(|w| w[0] < w[1])
            && (self.keys.len() < HASHED_MIN
                || (self.table.len == self.keys.len()
                    && self.keys.iter().all(|&k| self.table.contains(k))))
    }

    /// Call `f` with the absolute coordinates of every particle whose coordinate on the last
    /// axis lies in `span` (a [`Region`] span in absolute coordinates): the particles in that
    /// slab are one or two contiguous runs of keys, found by binary search. Stops when `f`
    /// returns true, and returns whether it did.
    fn any_in_slab(
        &self,
        lattice: &Lattice,
        lo: u64,
        len: u64,
        mut f: impl FnMut(&[u64; MAX_DIM]) -> bool,
    ) -> bool {
        let last = lattice.dim() - 1;
        let (size, stride) = (lattice.size(last), lattice.stride(last));
        let mut run = |from: u64, to: u64| {
            // Relative coordinates from..to (exclusive) on the last axis.
            let a = self.keys.partition_point(|&k| k < from * stride);
            let b = self.keys.partition_point(|&k| k < to * stride);
            self.keys[a..b]
                .iter()
                .any(|&k| f(&coords_of_key(lattice, &self.origin, k)))
        };
        if len >= size {
            return run(0, size);
        }
        let rel = (lo + size - self.origin[last]) % size;
        if rel + len <= size {
            run(rel, rel + len)
        } else {
            run(rel, size) || run(0, rel + len - size)
        }
    }
}

/// Whether any particle of `mover`, which has just moved by `dir`, is face-adjacent to a
/// particle of `other`, given their bounding regions. Walks the smaller shape's particles
/// inside the other's halo (first narrowed to a slab of the last axis by binary search, then
/// axis by axis) and looks their neighbours up in the larger: exact, O(s' d) for the s'
/// particles of the smaller in the larger's halo slab.
///
/// One neighbour per particle is skipped, as no contact can be there: the clusters did not
/// touch before the move, so a particle `b` of `other` never has `b + dir` in `mover` (that
/// site was `b` before the move), and a particle `a` of `mover` never has `a - dir` in `other`
/// (that site was `mover`'s before the move).
pub(super) fn touches(
    lattice: &Lattice,
    dir: Direction,
    (mover, mover_region): (&Shape, &Region),
    (other, other_region): (&Shape, &Region),
) -> bool {
    let (small, large, large_region, skip) = if mover.len() <= other.len() {
        (mover, other, other_region, dir.opposite())
    } else {
        (other, mover, mover_region, dir)
    };
    let halo = large_region.halo(lattice);
    let last = lattice.dim() - 1;
    let slab = halo.spans[last];
    small.any_in_slab(lattice, slab.lo, slab.len, |x| {
        halo.contains(lattice, x) && neighbour_held(lattice, x, large, skip)
    })
}

/// Whether a face neighbour of the site with coordinates `x`, other than the one in direction
/// `skip`, is a particle of `shape`.
#[inline]
fn neighbour_held(lattice: &Lattice, x: &[u64; MAX_DIM], shape: &Shape, skip: Direction) -> bool {
    // The site's relative coordinates and key in the shape's frame; each neighbour's key
    // differs by one stride, wrapped at the frame's edges.
    let mut rel = [0u64; MAX_DIM];
    let mut key = 0;
    for axis in 0..lattice.dim() {
        let (o, size) = (shape.origin[axis], lattice.size(axis));
        rel[axis] = if x[axis] >= o {
            x[axis] - o
        } else {
            x[axis] + size - o
        };
        key += rel[axis] * lattice.stride(axis);
    }
    for axis in 0..lattice.dim() {
        let size = lattice.size(axis);
        if size == 1 {
            continue;
        }
        let stride = lattice.stride(axis);
        let periodic = lattice.boundary(axis) == Boundary::Periodic;
        let (c, r) = (x[axis], rel[axis]);
        if (c + 1 < size || periodic) && skip != Direction::new(axis, true) {
            let n = if r + 1 < size {
                key + stride
            } else {
                key - r * stride
            };
            if shape.holds_key(n) {
                return true;
            }
        }
        if (c > 0 || periodic) && skip != Direction::new(axis, false) {
            let n = if r > 0 {
                key - stride
            } else {
                key + (size - 1) * stride
            };
            if shape.holds_key(n) {
                return true;
            }
        }
    }
    false
}
