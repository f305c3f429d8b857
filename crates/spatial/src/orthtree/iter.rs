//! Iteration over the stored positions: [`Points`], a depth-first walk with an explicit stack
//! of `O(depth)` frames that rebuilds each leaf's origin from the path (the variable-precision
//! paper, section 3.3: base coordinates are computed while traversing the tree), yielding exactly
//! the decoded positions the queries see.

use super::{EMPTY, Orthtree, decode};

impl<const D: usize> Orthtree<D> {
    /// Iterates over the stored positions of all points, leaf by leaf (the variable-precision
    /// paper, section 3.3: base coordinates are rebuilt while traversing the tree).
    pub fn iter(&self) -> Points<'_, D> {
        let mut stack = Vec::new();
        if self.root != EMPTY {
            stack.reserve(self.root_level as usize);
            stack.push(Frame {
                node: self.root,
                level: self.root_level,
                origin: self.root_origin,
                next: 0,
            });
        }
        Points {
            tree: self,
            stack,
            leaf: &[],
            leaf_origin: [0.0; D],
            pos: 0,
            remaining: self.len(),
        }
    }
}

/// A node on the iteration stack.
#[derive(Debug, Clone, Copy)]
struct Frame<const D: usize> {
    node: u32,
    level: u32,
    origin: [i64; D],
    next: usize,
}

/// Iterator over the stored positions of an [`Orthtree`], from [`Orthtree::iter`].
///
/// Its stack only holds reached nodes (the root, and children read from the slots of reached
/// nodes), with their levels, and `leaf` a reached leaf's points: the invariant its `unsafe`
/// calls rely on.
#[derive(Debug, Clone)]
pub struct Points<'a, const D: usize> {
    tree: &'a Orthtree<D>,
    stack: Vec<Frame<D>>,
    leaf: &'a [[u32; D]],
    leaf_origin: [f64; D],
    pos: usize,
    remaining: usize,
}

impl<const D: usize> Iterator for Points<'_, D> {
    type Item = [f64; D];

    fn next(&mut self) -> Option<[f64; D]> {
        let tree = self.tree;
        loop {
            if let Some(code) = self.leaf.get(self.pos) {
                self.pos += 1;
                // Saturating: a shared insert during the iteration can add points beyond the
                // count taken at its start.
                self.remaining = self.remaining.saturating_sub(1);
                let mut x = [0.0; D];
                for i in 0..D {
                    x[i] = decode(self.leaf_origin[i], code[i], tree.step);
                }
                return Some(x);
            }
            let top = self.stack.last_mut()?;
            if top.next == Orthtree::<D>::FANOUT {
                self.stack.pop();
                continue;
            }
            let ci = top.next;
            top.next += 1;
            // SAFETY: `top.node` is a reached node (the stack's invariant), `ci < FANOUT`.
            let child = unsafe { tree.child(top.node as usize * Orthtree::<D>::FANOUT + ci) };
            if child == EMPTY {
                continue;
            }
            let half = 1i64 << (top.level - 1);
            let mut origin = top.origin;
            for (i, o) in origin.iter_mut().enumerate() {
                if ci >> i & 1 == 1 {
                    *o += half;
                }
            }
            if top.level == 1 {
                // SAFETY: a non-empty slot of a reached level-1 node: a reached leaf. A reader
                // announces an epoch only while it holds no iterator (`insert_shared`'s
                // promise), so the block outlives this borrow.
                self.leaf = unsafe { tree.leaf_points(child) };
                self.leaf_origin = origin.map(|o| o as f64 * tree.leaf_side);
                self.pos = 0;
            } else {
                let level = top.level - 1;
                self.stack.push(Frame {
                    node: child,
                    level,
                    origin,
                    next: 0,
                });
            }
        }
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.remaining, Some(self.remaining))
    }
}

/// Exact when no [`insert_shared`](Orthtree::insert_shared) runs during the iteration (PDLA
/// never iterates while it shares the tree); points such an insert adds may be yielded beyond
/// the length taken at the start.
impl<const D: usize> ExactSizeIterator for Points<'_, D> {}

impl<'a, const D: usize> IntoIterator for &'a Orthtree<D> {
    type Item = [f64; D];
    type IntoIter = Points<'a, D>;

    fn into_iter(self) -> Points<'a, D> {
        self.iter()
    }
}
