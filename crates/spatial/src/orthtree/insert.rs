//! Insertion: locating a point's leaf cell and fixed-point offsets, growing the root towards
//! it, creating the nodes and leaf on its path, and appending its record to the leaf's block.
//!
//! Invariants kept: an insert either succeeds or leaves the tree unchanged (every capacity and
//! coordinate check happens before the first change); leaf cells never move when the root
//! grows, so a point's stored position does not depend on insertion order; every node lies on
//! the path to at least one stored point.

use super::pool::{self, LeafPool};
use super::{CODE_SCALE, COORD_LIMIT_LEAVES, EMPTY, Leaf, Orthtree, OrthtreeError, decode};

impl<const D: usize> Orthtree<D> {
    /// Leaf cell of `p` in leaf sides and the fixed-point offsets inside it, after checking the
    /// point. Offsets are rounded to the nearest multiple of `s / 2^32`; one that rounds up to
    /// the cell's upper face is stored as offset 0 of the next cell (the same position), so the
    /// error stays within half a step on every axis.
    fn locate(&self, p: &[f64; D]) -> Result<([i64; D], [u32; D]), OrthtreeError> {
        let mut k = [0i64; D];
        let mut code = [0u32; D];
        let inv_step = CODE_SCALE / self.leaf_side;
        for (axis, &x) in p.iter().enumerate() {
            if !x.is_finite() {
                return Err(OrthtreeError::NonFinite { axis, value: x });
            }
            let u = x / self.leaf_side;
            if u.abs() >= COORD_LIMIT_LEAVES {
                return Err(OrthtreeError::OutOfRange {
                    axis,
                    value: x,
                    limit: COORD_LIMIT_LEAVES * self.leaf_side,
                });
            }
            let cell = u.floor();
            let t = ((x - cell * self.leaf_side) * inv_step).round();
            if t >= CODE_SCALE {
                k[axis] = cell as i64 + 1;
                code[axis] = 0;
            } else {
                k[axis] = cell as i64;
                // t is in [0, 2^32).
                code[axis] = t as u32;
            }
        }
        Ok((k, code))
    }

    /// Whether the leaf cell `k` lies inside the root.
    fn root_contains(&self, k: &[i64; D]) -> bool {
        let side = 1i64 << self.root_level;
        (0..D).all(|i| k[i] >= self.root_origin[i] && k[i] < self.root_origin[i] + side)
    }

    /// Length of the leaf for cell `k`, 0 if it does not exist yet (read-only).
    fn existing_leaf_len(&self, k: &[i64; D]) -> u32 {
        if self.root == EMPTY || !self.root_contains(k) {
            return 0;
        }
        let mut node = self.root;
        let mut level = self.root_level;
        loop {
            let child = self.children[node as usize * Self::FANOUT + self.child_index(k, level)];
            if child == EMPTY {
                return 0;
            }
            if level == 1 {
                return self.leaves[child as usize].len;
            }
            node = child;
            level -= 1;
        }
    }

    /// Appends an internal node with no children.
    fn new_node(&mut self) -> u32 {
        let n = self.node_count() as u32;
        pool::reserve_slowly(&mut self.children, Self::FANOUT);
        self.children
            .resize(self.children.len() + Self::FANOUT, EMPTY);
        n
    }

    /// Doubles the root towards leaf cell `k` (the variable-precision paper builds its tree over a
    /// fixed domain; here the domain grows, the old root becoming a child of the new one).
    fn grow_root(&mut self, k: &[i64; D]) {
        let side = 1i64 << self.root_level;
        let mut origin = self.root_origin;
        let mut slot = 0;
        for i in 0..D {
            let lo = self.root_origin[i];
            let down = if k[i] < lo {
                true
            } else if k[i] >= lo + side {
                false
            } else {
                lo + side / 2 > self.anchor[i]
            };
            if down {
                origin[i] = lo - side;
                slot |= 1 << i;
            }
        }
        let n = self.new_node();
        self.children[n as usize * Self::FANOUT + slot] = self.root;
        self.root = n;
        self.root_level += 1;
        self.root_origin = origin;
    }

    /// Inserts a particle centre (the variable-precision paper, section 3.3: the particle is stored
    /// in the leaf containing it, in relative coordinates) and returns its stored position, which
    /// is what every query sees: within `leaf_side / 2^33` of `p` per coordinate (plus `f64`
    /// rounding at the coordinate's magnitude).
    ///
    /// Duplicate points are allowed. On error the tree is unchanged.
    pub fn insert(&mut self, p: [f64; D]) -> Result<[f64; D], OrthtreeError> {
        let (k, code) = self.locate(&p)?;
        // Capacity checks before any change, so that an error leaves the tree as it was.
        // 128 nodes: the most one insert can add (root growth and a path down to a leaf).
        if self.node_count() as u64 + 128 > self.index_limit {
            return Err(OrthtreeError::CapacityExceeded("nodes"));
        }
        if self.leaves.len() as u64 + 1 > self.index_limit {
            return Err(OrthtreeError::CapacityExceeded("leaves"));
        }
        let leaf_len = self.existing_leaf_len(&k);
        if leaf_len == u32::MAX
            || self.pool.slots.len() as u64 + LeafPool::<D>::push_needs(leaf_len) > self.index_limit
        {
            return Err(OrthtreeError::CapacityExceeded("point slots"));
        }

        if self.root == EMPTY {
            // Root of 2 x 2 leaf cells centred on the leaf-cell corner nearest to p.
            for i in 0..D {
                let frac = p[i] / self.leaf_side - k[i] as f64;
                self.root_origin[i] = if frac < 0.5 { k[i] - 1 } else { k[i] };
                self.anchor[i] = self.root_origin[i] + 1;
            }
            self.root_level = 1;
            self.root = self.new_node();
        }
        while !self.root_contains(&k) {
            self.grow_root(&k);
        }

        let mut node = self.root;
        let mut level = self.root_level;
        let leaf = loop {
            let slot = node as usize * Self::FANOUT + self.child_index(&k, level);
            let child = self.children[slot];
            if level == 1 {
                break if child == EMPTY {
                    let l = self.leaves.len() as u32;
                    pool::reserve_slowly(&mut self.leaves, 1);
                    self.leaves.push(Leaf { start: 0, len: 0 });
                    self.children[slot] = l;
                    l
                } else {
                    child
                };
            }
            node = if child == EMPTY {
                let n = self.new_node();
                self.children[slot] = n;
                n
            } else {
                child
            };
            level -= 1;
        };

        let mut stored = [0.0; D];
        for i in 0..D {
            stored[i] = decode(k[i] as f64 * self.leaf_side, code[i], self.step);
        }
        let mut rec = self.leaves[leaf as usize];
        self.pool.push(&mut rec, code);
        self.leaves[leaf as usize] = rec;
        self.len += 1;
        if self.pool.wants_compaction() {
            self.pool.compact(&mut self.leaves);
        }
        Ok(stored)
    }

    /// The position [`insert`](Self::insert) would store for `p` (its fixed-point rounding),
    /// without inserting it: PDLA computes it outside the tree's writer (the variable-precision
    /// paper, section 3.4). Fails as `insert` would on a non-finite or out-of-range coordinate.
    pub fn stored_position(&self, p: &[f64; D]) -> Result<[f64; D], OrthtreeError> {
        let (k, code) = self.locate(p)?;
        let mut stored = [0.0; D];
        for i in 0..D {
            stored[i] = decode(k[i] as f64 * self.leaf_side, code[i], self.step);
        }
        Ok(stored)
    }
}
