//! The nodes a bounded query starts from: at most `2^D` nodes of one level whose cells cover
//! a ball, found by descending along their cells' paths with no distance tests.

use super::super::{EMPTY, Orthtree};
use super::CHILD_ORDER;
use crate::round::{ceil, floor};

impl<const D: usize> Orthtree<D> {
    /// Calls `f(tree, node, level, centre, half side)` for each existing node of a set of at
    /// most `2^D` nodes, all at one level, whose cells cover the ball of radius `r` around `p`
    /// (with a relative margin against rounding): the nodes of the smallest level whose side
    /// is at least `2 r`, or the root if that level is not below the root. `level == 0` means
    /// `node` is a leaf index. Finding the nodes costs one descent per node with no distance
    /// computation (the range and bounded queries then start there, not at the root).
    ///
    /// Every `node` passed to `f` is a reached node of level `level` (a reached leaf for
    /// `level == 0`): the root, or read from the slots of reached nodes.
    ///
    /// # Safety
    ///
    /// The tree is not empty.
    #[inline]
    pub(super) unsafe fn for_each_cover_cell<F: FnMut(&Self, u32, u32, [f64; D], f64)>(
        &self,
        p: &[f64; D],
        r: f64,
        mut f: F,
    ) {
        let mut pmax: f64 = 0.0;
        for x in p {
            pmax = pmax.max(x.abs());
        }
        let mut omax: f64 = 0.0;
        for o in &self.root_origin {
            omax = omax.max((*o as f64).abs());
        }
        // Rounding of p +- r and of the divisions below is far below this margin. `u` below is
        // rounded at the magnitude of the root's corner, which may be far larger than p's (a
        // point a few ulps below a cell boundary near the origin of a wide tree rounds onto the
        // boundary): the margin covers that too.
        let r = r + (1.0 + r + pmax) * 1e-9 + (omax * self.leaf_side + pmax) * 1e-12;
        let side_leaves = (r + r) / self.leaf_side;
        // Smallest level whose side (2^level leaf sides) is >= 2 r.
        let level = if side_leaves <= 1.0 {
            0
        } else if side_leaves.is_finite() && side_leaves < (1u64 << 62) as f64 {
            64 - ((ceil(side_leaves) as u64) - 1).leading_zeros()
        } else {
            u32::MAX
        };
        if level >= self.root_level || !p.iter().all(|x| x.is_finite()) {
            let (c, half) = self.root_geometry();
            f(self, self.root, self.root_level, c, half);
            return;
        }
        // Cells of this level are aligned on the root's corner: index them from it.
        let cells = (1u64 << level) as f64;
        let r_leaves = r / self.leaf_side;
        let last = (1u64 << (self.root_level - level)) as f64 - 1.0;
        let mut lo = [0i64; D];
        let mut two = [false; D];
        let mut home = 0usize;
        for i in 0..D {
            let u = p[i] / self.leaf_side - self.root_origin[i] as f64;
            let a = floor((u - r_leaves) / cells);
            let b = floor((u + r_leaves) / cells);
            if b < 0.0 || a > last {
                return;
            }
            let a = a.max(0.0);
            let b = b.min(last);
            lo[i] = a as i64;
            two[i] = b > a;
            if two[i] && u >= b * cells {
                // p lies in the upper of the two cells.
                home |= 1 << i;
            }
        }
        let half = self.leaf_side * cells * 0.5;
        // The cells' paths from the root are one path down to the first level whose child
        // index differs between them (the bit of `k - root_origin` it reads, `l - 1`, lies
        // above every bit in which an axis's two cell indices differ): walk it once.
        let mut split = level;
        for i in 0..D {
            if two[i] {
                let diff = ((lo[i] ^ (lo[i] + 1)) as u64) << level;
                split = split.max(64 - diff.leading_zeros());
            }
        }
        let k0: [i64; D] = std::array::from_fn(|i| self.root_origin[i] + (lo[i] << level));
        let mut top = self.root;
        let mut top_level = self.root_level;
        while top_level > split {
            // SAFETY: `top` is the root (the tree is not empty: the caller's contract) or was
            // read from its parent's slot at level top_level + 1 >= 2.
            let child = unsafe {
                self.child(top as usize * Self::FANOUT + self.child_index(&k0, top_level))
            };
            if child == EMPTY {
                return;
            }
            top = child;
            top_level -= 1;
        }
        // p's own cell first, then by number of flipped axes (good bounds early).
        'cells: for &m in &CHILD_ORDER[D][..Self::FANOUT] {
            let combo = home ^ m as usize;
            let mut k = [0i64; D];
            for i in 0..D {
                let bit = (combo >> i) & 1;
                if bit == 1 && !two[i] {
                    continue 'cells;
                }
                k[i] = self.root_origin[i] + ((lo[i] + bit as i64) << level);
            }
            let mut node = top;
            let mut l = top_level;
            while l > level {
                // SAFETY: `node` is `top` (reached) or was read from its parent's slot at
                // level l + 1 >= 2.
                let child =
                    unsafe { self.child(node as usize * Self::FANOUT + self.child_index(&k, l)) };
                if child == EMPTY {
                    continue 'cells;
                }
                node = child;
                l -= 1;
            }
            let c = k.map(|x| x as f64 * self.leaf_side + half);
            f(self, node, level, c, half);
        }
    }
}
