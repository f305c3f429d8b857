//! Grid boxes holding every cluster whose halo overlaps them ([`HaloBoxes`]), and the cost model
//! that tunes their side ([`predicted_cost`]).
//!
//! Invariant: box `b` lists cluster `c` exactly once if the halo of `c` (its bounding region
//! grown by one site) overlaps `b`, and not at all otherwise.

use super::region::{Region, Span};
use crate::lattice::{ItemId, StampSet};
use core_lattice::{Lattice, MAX_DIM};

/// The boxes a span of coordinates overlaps along one axis: `first, first + 1, ...` (`n` of
/// them), modulo the number of boxes on the axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct BoxSpan {
    first: u64,
    n: u64,
}

impl BoxSpan {
    #[inline]
    fn contains(&self, i: u64, count: u64) -> bool {
        (i + count - self.first) % count < self.n
    }
}

/// Grid boxes of side `A` (a power of two) over the lattice, each listing the clusters whose
/// halo overlaps it.
#[derive(Debug, Clone)]
pub(super) struct HaloBoxes {
    lattice: Lattice,
    side: u64,
    shift: u32,
    /// Boxes along each axis, `ceil(L_a / A)`.
    counts: [u64; MAX_DIM],
    /// Strides of box indices, like k-index strides.
    strides: [u64; MAX_DIM],
    boxes: Vec<Vec<ItemId>>,
    seen: StampSet,
}

impl HaloBoxes {
    /// Empty boxes of side `side` (a power of two) over `lattice`.
    pub(super) fn new(lattice: &Lattice, side: u64) -> Self {
        assert!(side.is_power_of_two());
        let (counts, total) = layout(lattice, side);
        let mut strides = [0; MAX_DIM];
        let mut stride = 1;
        for axis in 0..lattice.dim() {
            strides[axis] = stride;
            stride *= counts[axis];
        }
        HaloBoxes {
            lattice: lattice.clone(),
            side,
            shift: side.trailing_zeros(),
            counts,
            strides,
            boxes: vec![Vec::new(); total as usize],
            seen: StampSet::default(),
        }
    }

    /// The box side `A`.
    pub(super) fn side(&self) -> u64 {
        self.side
    }

    /// The boxes span `s` overlaps along `axis`.
    #[inline]
    fn box_span(&self, axis: usize, s: Span) -> BoxSpan {
        let (size, count) = (self.lattice.size(axis), self.counts[axis]);
        if s.len >= size {
            return BoxSpan { first: 0, n: count };
        }
        let first = s.lo >> self.shift;
        let end = s.lo + s.len - 1;
        let n = if end < size {
            (end >> self.shift) - first + 1
        } else {
            (count - first) + ((end - size) >> self.shift) + 1
        };
        if n >= count {
            BoxSpan { first: 0, n: count }
        } else {
            BoxSpan { first, n }
        }
    }

    /// The box spans of `halo` on every axis.
    #[inline]
    fn box_spans(&self, halo: &Region) -> [BoxSpan; MAX_DIM] {
        let mut spans = [BoxSpan { first: 0, n: 1 }; MAX_DIM];
        for (axis, span) in spans.iter_mut().enumerate().take(self.lattice.dim()) {
            *span = self.box_span(axis, halo.spans[axis]);
        }
        spans
    }

    /// Call `f` on the index of every box of the product of `spans`.
    #[inline]
    fn for_each_box(&self, spans: &[BoxSpan; MAX_DIM], mut f: impl FnMut(usize)) {
        let dim = self.lattice.dim();
        let mut step = [0u64; MAX_DIM];
        'outer: loop {
            let mut index = 0;
            for axis in 0..dim {
                let i = (spans[axis].first + step[axis]) % self.counts[axis];
                index += i * self.strides[axis];
            }
            f(index as usize);
            for axis in 0..dim {
                step[axis] += 1;
                if step[axis] < spans[axis].n {
                    continue 'outer;
                }
                step[axis] = 0;
            }
            break;
        }
    }

    /// List cluster `id` in every box its halo `halo` overlaps.
    pub(super) fn register(&mut self, id: ItemId, halo: &Region) {
        let spans = self.box_spans(halo);
        let mut boxes = std::mem::take(&mut self.boxes);
        self.for_each_box(&spans, |b| boxes[b].push(id));
        self.boxes = boxes;
    }

    /// Take cluster `id` out of every box its halo `halo` overlaps.
    pub(super) fn unregister(&mut self, id: ItemId, halo: &Region) {
        let spans = self.box_spans(halo);
        let mut boxes = std::mem::take(&mut self.boxes);
        self.for_each_box(&spans, |b| take(&mut boxes[b], id));
        self.boxes = boxes;
    }

    /// Cluster `id`'s halo moved from `old` to `new` along `axis` (one site): list it in the
    /// boxes it entered and take it out of those it left (slabs of boxes across the axis).
    pub(super) fn moved(&mut self, id: ItemId, axis: usize, old: &Region, new: &Region) {
        let (was, now) = (
            self.box_span(axis, old.spans[axis]),
            self.box_span(axis, new.spans[axis]),
        );
        if was == now {
            return;
        }
        let count = self.counts[axis];
        let mut slab = self.box_spans(new);
        let mut boxes = std::mem::take(&mut self.boxes);
        for step in 0..was.n {
            let i = (was.first + step) % count;
            if !now.contains(i, count) {
                slab[axis] = BoxSpan { first: i, n: 1 };
                self.for_each_box(&slab, |b| take(&mut boxes[b], id));
            }
        }
        for step in 0..now.n {
            let i = (now.first + step) % count;
            if !was.contains(i, count) {
                slab[axis] = BoxSpan { first: i, n: 1 };
                self.for_each_box(&slab, |b| boxes[b].push(id));
            }
        }
        self.boxes = boxes;
    }

    /// The clusters other than `id` listed in a box its halo `halo` overlaps, each once, in
    /// discovery order, appended to `out`. Returns the number of list entries scanned.
    pub(super) fn sharing(&mut self, id: ItemId, halo: &Region, out: &mut Vec<ItemId>) -> usize {
        let spans = self.box_spans(halo);
        let mut seen = std::mem::take(&mut self.seen);
        seen.clear();
        let mut scanned = 0;
        self.for_each_box(&spans, |b| {
            scanned += self.boxes[b].len();
            for &other in &self.boxes[b] {
                if other != id && seen.insert(other as usize) {
                    out.push(other);
                }
            }
        });
        self.seen = seen;
        scanned
    }

    /// Panic unless every box lists exactly the clusters whose halo overlaps it, each once.
    /// `halos` gives the halo of every live cluster. For tests.
    pub(super) fn check(&self, halos: &[(ItemId, Region)]) {
        let mut expected: Vec<Vec<ItemId>> = vec![Vec::new(); self.boxes.len()];
        for (id, halo) in halos {
            let spans = self.box_spans(halo);
            self.for_each_box(&spans, |b| expected[b].push(*id));
        }
        for (b, (have, want)) in self.boxes.iter().zip(&mut expected).enumerate() {
            let mut have = have.clone();
            have.sort_unstable();
            want.sort_unstable();
            assert_eq!(&have, want, "box {b} of side {}", self.side);
        }
    }
}

/// Take `id` out of box list `list`, where it is listed.
#[inline]
fn take(list: &mut Vec<ItemId>, id: ItemId) {
    let at = list
        .iter()
        .position(|&x| x == id)
        .expect("cluster listed in the boxes its halo overlaps");
    list.swap_remove(at);
}

/// Boxes along each axis and in all, for boxes of side `side`.
fn layout(lattice: &Lattice, side: u64) -> ([u64; MAX_DIM], u64) {
    let mut counts = [1; MAX_DIM];
    let mut total: u64 = 1;
    for (axis, count) in counts.iter_mut().enumerate().take(lattice.dim()) {
        *count = lattice.size(axis).div_ceil(side);
        total = total.saturating_mul(*count);
    }
    (counts, total)
}

/// The number of boxes of side `side` over `lattice`.
pub(super) fn box_count(lattice: &Lattice, side: u64) -> u64 {
    layout(lattice, side).1
}

/// Predicted work of one sweep with boxes of side `side`, in box-list entries, when every
/// cluster of `halos` moves once: registering and querying each cluster costs the boxes its
/// halo overlaps, `B = prod_a min(n_a, 1 + (l_a - 1) / A)` (the expected number for a span of
/// `l_a` sites at a random offset, `n_a` boxes on axis `a`), and each box visited holds on
/// average `R / n` entries (`R`: all clusters' `B` summed, `n`: number of boxes); a move along
/// axis `a` re-registers a slab of `B / b_a` boxes with probability about `2 / A`. So a sweep
/// costs `R (1 + R / n) + sum_C (2 / A) mean_a(B / b_a)`: large boxes crowd each list (the
/// second factor), small ones multiply the boxes per cluster (the first).
pub(super) fn predicted_cost<'a>(
    lattice: &Lattice,
    side: u64,
    halos: impl Iterator<Item = &'a Region>,
) -> f64 {
    let (counts, total) = layout(lattice, side);
    let dim = lattice.dim();
    let a = side as f64;
    let (mut registrations, mut upkeep) = (0.0, 0.0);
    for halo in halos {
        let mut per_axis = [1.0f64; MAX_DIM];
        let mut b = 1.0;
        for axis in 0..dim {
            let len = halo.spans[axis].len as f64;
            per_axis[axis] = (1.0 + (len - 1.0) / a).min(counts[axis] as f64);
            b *= per_axis[axis];
        }
        registrations += b;
        upkeep += (0..dim).map(|ax| b / per_axis[ax]).sum::<f64>() * 2.0 / (a * dim as f64);
    }
    registrations * (1.0 + registrations / total as f64) + upkeep
}
