//! The fixed-radius range query: every stored point within a distance of a position.

use super::super::{EMPTY, Orthtree, decode};
use super::box_dist_sq;

/// Points a leaf scan handles at once.
const LANES: usize = 4;

/// Where [`Orthtree::range_into`] puts what it finds, a leaf (or a piece of one) at a time: the
/// query asks the sink for room, writes each point it scans after the last one found inside
/// (a point outside is overwritten by the next), then tells the sink how many it kept. So the
/// points are kept without a branch per point (whether a point of a leaf lies inside is close
/// to a coin toss, and a mispredicted branch costs more than the store it would skip), and the
/// scan keeps its count in a register.
pub trait RangeSink<const D: usize> {
    /// Room for up to `n` points, the rest of the leaf being scanned: a non-empty slice; the
    /// query scans as many of the leaf's points as it has slots (all `n` if it has that many),
    /// then asks again for the rest.
    fn room(&mut self, n: usize) -> &mut [[f64; D]];
    /// The first `kept` slots of the last [`room`](Self::room) hold the points just scanned
    /// that lie inside the ball (as the tree decodes them, their squared distance from the
    /// query position summed axis by axis at most the squared radius), in the leaf's order.
    fn keep(&mut self, kept: usize);

    /// Whether [`room`](Self::room) always lends at least the `n` slots asked for, so that a
    /// leaf is scanned in one piece (a little less work per leaf).
    const WHOLE_LEAF: bool = false;
}

/// Slots of [`for_each_within`](Orthtree::for_each_within)'s sink: a leaf with more points is
/// scanned in pieces of this many.
const CALL_SLOTS: usize = 16;

/// The sink of [`Orthtree::for_each_within`]: the closure, called for the points kept, from a
/// few slots on the stack (the query allocates nothing).
struct Calls<const D: usize, F> {
    f: F,
    slots: [[f64; D]; CALL_SLOTS],
}

impl<const D: usize, F: FnMut([f64; D])> RangeSink<D> for Calls<D, F> {
    #[inline(always)]
    fn room(&mut self, _: usize) -> &mut [[f64; D]] {
        &mut self.slots
    }

    #[inline(always)]
    fn keep(&mut self, kept: usize) {
        for &x in &self.slots[..kept] {
            (self.f)(x);
        }
    }
}

impl<const D: usize> Orthtree<D> {
    /// Calls `f` with the stored position of every point at distance `<= r` from `p` (inclusive,
    /// comparing squared distances summed axis by axis, as
    /// [`nearest_distance`](Self::nearest_distance) does). Order unspecified. Nothing is called if
    /// `r` is negative or NaN. Used by DLA to find the first contact along a step (the
    /// variable-precision paper, section 3.2, Fig. 6).
    pub fn for_each_within<F: FnMut([f64; D])>(&self, p: &[f64; D], r: f64, f: F) {
        self.range_into(
            p,
            r,
            &mut Calls {
                f,
                slots: [[0.0; D]; CALL_SLOTS],
            },
        );
    }

    /// The range query of [`for_each_within`](Self::for_each_within), handing `sink` the
    /// points of each leaf that meets the ball (see [`RangeSink`]): the points kept are exactly
    /// those `for_each_within` lists, in the same order.
    pub fn range_into<S: RangeSink<D>>(&self, p: &[f64; D], r: f64, sink: &mut S) {
        if self.root == EMPTY || r.is_nan() || r < 0.0 {
            return;
        }
        let r_sq = r * r;
        let cell = |tree: &Self, node, level, c, half| {
            if box_dist_sq(p, &c, half) > r_sq {
                return;
            }
            // SAFETY: `for_each_cover_cell` passes reached nodes (leaves at level 0) with
            // their levels.
            unsafe {
                if level == 0 {
                    tree.range_leaf(p, r_sq, node, c, half, sink);
                } else {
                    tree.range_node(p, r_sq, node, level, c, half, sink);
                }
            }
        };
        // SAFETY: the tree is not empty (checked above).
        unsafe { self.for_each_cover_cell(p, r, cell) };
    }

    /// Range query below a node (centre `c`, half side `half`) already known to meet the ball.
    ///
    /// # Safety
    ///
    /// `node` is a reached node of level `level`, as for [`visit`](Self::visit).
    #[allow(clippy::too_many_arguments)]
    unsafe fn range_node<S: RangeSink<D>>(
        &self,
        p: &[f64; D],
        r_sq: f64,
        node: u32,
        level: u32,
        c: [f64; D],
        half: f64,
        sink: &mut S,
    ) {
        let q = half * 0.5;
        // Per axis, the squared distance from p to the lower and the upper half of the node,
        // summed into each child's `box_dist_sq` bit for bit (as in `visit`).
        let mut slab = [[0.0f64; 2]; D];
        for i in 0..D {
            let x = p[i];
            let lo = (c[i] - half - x).max(x - c[i]).max(0.0);
            let hi = (c[i] - x).max(x - (c[i] + half)).max(0.0);
            slab[i] = [lo * lo, hi * hi];
        }
        let base = node as usize * Self::FANOUT;
        for ci in 0..Self::FANOUT {
            // SAFETY: `node` is a reached node (the caller's contract), `ci < FANOUT`.
            let child = unsafe { self.child(base + ci) };
            if child == EMPTY {
                continue;
            }
            let mut d2 = 0.0;
            for (i, sl) in slab.iter().enumerate() {
                d2 += sl[ci >> i & 1];
            }
            if d2 > r_sq {
                continue;
            }
            child_centre!(cc = c, ci, q);
            // SAFETY: a non-empty slot of a reached node of level `level`: a reached leaf
            // if `level == 1`, else a reached node of level `level - 1`.
            unsafe {
                if level == 1 {
                    self.range_leaf(p, r_sq, child, cc, q, sink);
                } else {
                    self.range_node(p, r_sq, child, level - 1, cc, q, sink);
                }
            }
        }
    }

    /// Range query inside a leaf (centre `c`, half side `half`).
    ///
    /// # Safety
    ///
    /// `leaf` is a reached leaf, as for [`visit_leaf`](Self::visit_leaf).
    #[inline]
    unsafe fn range_leaf<S: RangeSink<D>>(
        &self,
        p: &[f64; D],
        r_sq: f64,
        leaf: u32,
        c: [f64; D],
        half: f64,
        sink: &mut S,
    ) {
        let origin = c.map(|x| x - half);
        // SAFETY: a reached leaf (the caller's contract); the slice lives for this call only.
        let mut codes = unsafe { self.leaf_points(leaf) };
        if S::WHOLE_LEAF {
            let slots = &mut sink.room(codes.len())[..codes.len()];
            let kept = self.scan_leaf(p, r_sq, &origin, codes, slots);
            sink.keep(kept);
            return;
        }
        while !codes.is_empty() {
            let room = sink.room(codes.len());
            assert!(!room.is_empty(), "a range sink lent no room");
            let (now, rest) = codes.split_at(room.len().min(codes.len()));
            codes = rest;
            let kept = self.scan_leaf(p, r_sq, &origin, now, &mut room[..now.len()]);
            sink.keep(kept);
        }
    }

    /// Decodes the points `codes` of a leaf whose lower corner is `origin`, writes each into
    /// `slots` after the last one within the squared radius `r_sq` of `p`, and returns how
    /// many those are (`slots` and `codes` have the same length).
    #[inline(always)]
    fn scan_leaf(
        &self,
        p: &[f64; D],
        r_sq: f64,
        origin: &[f64; D],
        codes: &[[u32; D]],
        slots: &mut [[f64; D]],
    ) -> usize {
        assert_eq!(codes.len(), slots.len());
        let mut kept = 0;
        // Four points at a time, axis by axis (the vectorizer's shape), then the rest; each
        // point's squared distance is summed over the axes in order either way.
        let mut chunks = codes.chunks_exact(LANES);
        for chunk in &mut chunks {
            let mut xs = [[0.0; LANES]; D];
            let mut d2 = [0.0; LANES];
            for i in 0..D {
                for k in 0..LANES {
                    xs[i][k] = decode(origin[i], chunk[k][i], self.step);
                    let e = p[i] - xs[i][k];
                    d2[k] += e * e;
                }
            }
            for k in 0..LANES {
                debug_assert!(kept < slots.len());
                // SAFETY: `kept` is at most the number of points scanned before this one, so
                // below `codes.len()`, which is `slots.len()`.
                unsafe { *slots.get_unchecked_mut(kept) = std::array::from_fn(|i| xs[i][k]) };
                kept += usize::from(d2[k] <= r_sq);
            }
        }
        for code in chunks.remainder() {
            let mut x = [0.0; D];
            let mut d2 = 0.0;
            for i in 0..D {
                x[i] = decode(origin[i], code[i], self.step);
                let e = p[i] - x[i];
                d2 += e * e;
            }
            debug_assert!(kept < slots.len());
            // SAFETY: as in the loop above.
            unsafe { *slots.get_unchecked_mut(kept) = x };
            kept += usize::from(d2 <= r_sq);
        }
        kept
    }
}
