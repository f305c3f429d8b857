//! The dense distance map: one byte per cell over the whole covered cube (see the parent
//! module for what a cell stores and the bound it gives), and its inserts of boxes.

use super::grid::{Grid, WINDOW, WindowBox, merge_row};
use super::{CAPPED, Cells, DistanceMapError, PointMap, finite_max_norm, next_row};
use crate::round::{ceil, floor, whole_to_usize};
use std::fmt;
use std::sync::atomic::{AtomicU8, AtomicU64, Ordering};

/// Capped bytes after the last cell of `values`: a window insert merges 16 bytes from the box's
/// first column ([`Cells::lower_window`]), which may run past the last row's end.
const PAD: usize = 15;

/// The coarse distance map (see the [module docs](super)).
pub struct DistanceMap<const D: usize> {
    /// Cells, tables and points; the cube covers `|x_i| < grid.half * cell`.
    pub(super) grid: Grid,
    /// `2 * half`: cells per axis.
    pub(super) side: usize,
    /// `side` as a float (exact).
    pub(super) side_f: f64,
    /// One byte per cell, axis 0 fastest. Atomic so that PDLA threads can share one map
    /// ([`DistanceMap::insert_shared`]); relaxed loads and stores are plain moves.
    pub(super) values: Vec<AtomicU8>,
    /// Sub-boxes per axis of a cell for
    /// [`insert_box_by_sub_box`](DistanceMap::insert_box_by_sub_box) (0: none kept).
    sub: usize,
    /// With `sub > 0`, one word per cell (indexed as `values`): bit `j` set once the cell's
    /// sub-box `j` (`j = sum_i j_i sub^i`) has been inserted.
    seen: Vec<AtomicU64>,
}

impl<const D: usize> Clone for DistanceMap<D> {
    fn clone(&self) -> Self {
        DistanceMap {
            grid: self.grid.clone(),
            side: self.side,
            side_f: self.side_f,
            values: self
                .values
                .iter()
                .map(|v| AtomicU8::new(v.load(Ordering::Relaxed)))
                .collect(),
            sub: self.sub,
            seen: self
                .seen
                .iter()
                .map(|v| AtomicU64::new(v.load(Ordering::Relaxed)))
                .collect(),
        }
    }
}

impl<const D: usize> fmt::Debug for DistanceMap<D> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("DistanceMap")
            .field("cell", &self.grid.cell)
            .field("cap", &self.grid.cap)
            .field("cells_per_axis", &self.side)
            .field("points", &self.grid.points)
            .finish()
    }
}

impl<const D: usize> DistanceMap<D> {
    /// An empty map with cell side `cell` and cap distance `cap` (both in the units of the
    /// points). Nothing is allocated until the first insert.
    pub fn new(cell: f64, cap: f64) -> Result<Self, DistanceMapError> {
        Ok(DistanceMap {
            grid: Grid::new(cell, cap)?,
            side: 0,
            side_f: 0.0,
            values: Vec::new(),
            sub: 0,
            seen: Vec::new(),
        })
    }

    /// The same map, keeping track of which of the `sub^D` equal sub-boxes of each cell
    /// have been inserted by [`insert_box_by_sub_box`](Self::insert_box_by_sub_box) (8 bytes
    /// more per cell). `sub^D` must not exceed 64, and the map must be empty.
    pub fn with_sub_boxes(mut self, sub: usize) -> Result<Self, DistanceMapError> {
        let fits = sub >= 1 && sub.checked_pow(D as u32).is_some_and(|n| n <= 64);
        if !fits || self.side > 0 {
            return Err(DistanceMapError::SubBoxes(sub));
        }
        self.sub = sub;
        Ok(self)
    }

    /// Sub-boxes per axis of a cell kept by [`with_sub_boxes`](Self::with_sub_boxes) (0 when
    /// not kept).
    pub fn sub_boxes(&self) -> usize {
        self.sub
    }

    /// Adds the box `[lo, hi]` as the sub-box of a cell ([`with_sub_boxes`](Self::with_sub_boxes))
    /// that contains it, unless that sub-box was inserted before; `true` when the map was
    /// lowered now. A caller that adds small boxes this way (DLA: the boxes of its tree's
    /// leaves) inserts each sub-box once, whatever number of boxes it holds: the map stays a
    /// lower bound, looser by at most a sub-box's diagonal. Sub-boxes are the closed boxes of
    /// side `cell / sub` aligned on the cells (`[k c, (k + 1) c)` along each axis); a box that
    /// does not lie inside one is inserted by itself, as [`insert_box`](Self::insert_box) does.
    /// Fails like [`insert_box`](Self::insert_box), and with [`DistanceMapError::SubBoxes`]
    /// on a map that keeps none.
    pub fn insert_box_by_sub_box(
        &mut self,
        lo: &[f64; D],
        hi: &[f64; D],
    ) -> Result<bool, DistanceMapError> {
        let Some((slo, shi)) = self.sub_box(lo, hi)? else {
            self.insert_box(lo, hi)?;
            return Ok(true);
        };
        let need =
            finite_max_norm(&slo)?.max(finite_max_norm(&shi)?) + self.grid.cap + self.grid.cell;
        if need >= self.reach() {
            self.grow(need)?;
        }
        let (word, bit) = self.sub_bit(&slo);
        let word = word.expect("the map covers the sub-box after growing");
        let seen = self.seen[word].get_mut();
        if *seen & bit != 0 {
            return Ok(false);
        }
        *seen |= bit;
        self.grid.points += 1;
        self.lower_box_rows(&slo, &shi, Self::keep_nearer);
        Ok(true)
    }

    /// [`insert_box_by_sub_box`](Self::insert_box_by_sub_box) through a shared reference, as
    /// [`insert_box_shared`](Self::insert_box_shared) is to [`insert_box`](Self::insert_box):
    /// the sub-box's bit is set with an atomic `fetch_or`, so that of several threads adding
    /// boxes of one sub-box exactly one inserts it; no growth. Returns `(lowered now,
    /// inside)`, `inside` as [`insert_box_shared`](Self::insert_box_shared) returns it; a
    /// sub-box whose cell lies outside the map is inserted every time (its bit cannot be
    /// kept).
    pub fn insert_box_by_sub_box_shared(
        &self,
        lo: &[f64; D],
        hi: &[f64; D],
    ) -> Result<(bool, bool), DistanceMapError> {
        let Some((slo, shi)) = self.sub_box(lo, hi)? else {
            return Ok((true, self.insert_box_shared(lo, hi)?));
        };
        if let (Some(word), bit) = self.sub_bit(&slo)
            && self.seen[word].fetch_or(bit, Ordering::Relaxed) & bit != 0
        {
            return Ok((false, true));
        }
        Ok((true, self.insert_box_shared(&slo, &shi)?))
    }

    /// The closed sub-box of a cell that holds the box `[lo, hi]` (found from its centre), as
    /// `(lo, hi)`, or `None` when the box does not lie inside one.
    #[allow(clippy::type_complexity)]
    fn sub_box(
        &self,
        lo: &[f64; D],
        hi: &[f64; D],
    ) -> Result<Option<([f64; D], [f64; D])>, DistanceMapError> {
        if self.sub == 0 {
            return Err(DistanceMapError::SubBoxes(0));
        }
        finite_max_norm(lo)?;
        finite_max_norm(hi)?;
        let g = &self.grid;
        let side = g.cell / self.sub as f64;
        let mut slo = [0.0; D];
        let mut shi = [0.0; D];
        for i in 0..D {
            let m = floor(0.5 * (lo[i] + hi[i]) / side);
            slo[i] = m * side;
            shi[i] = slo[i] + side;
            if !(slo[i] <= lo[i] && hi[i] <= shi[i]) {
                return Ok(None);
            }
        }
        Ok(Some((slo, shi)))
    }

    /// The word of `seen` for the cell holding the sub-box with lower corner `slo` (`None`
    /// outside the map) and the sub-box's bit.
    fn sub_bit(&self, slo: &[f64; D]) -> (Option<usize>, u64) {
        let side = self.grid.cell / self.sub as f64;
        // The sub-box's centre, half its side from the boundaries of the cell's sub-boxes, so
        // that rounding cannot place it in another.
        let c: [f64; D] = std::array::from_fn(|i| slo[i] + 0.5 * side);
        let mut j = 0usize;
        let mut stride = 1usize;
        for x in c {
            let k = floor(x * self.grid.inv_cell);
            let ji = floor((x - k * self.grid.cell) / side).clamp(0.0, (self.sub - 1) as f64);
            j += ji as usize * stride;
            stride *= self.sub;
        }
        (self.index(&c).map(|(i, _)| i), 1u64 << j)
    }

    /// The cell index of `p`, or `None` outside the map.
    #[inline]
    fn index(&self, p: &[f64; D]) -> Option<(usize, [f64; D])> {
        let g = &self.grid;
        let mut idx = 0.0;
        let mut stride = 1.0;
        let mut centre = [0.0; D];
        for i in 0..D {
            let k = floor(p[i] * g.inv_cell);
            // The cube is `side = 2 half` cells a side. NaN fails the test.
            let half = g.half_f;
            if !(k >= -half && k < half) {
                return None;
            }
            // `k + half` is a whole number in [0, side), and the index a whole number below
            // the map's cells, under 2^52 (`grow`): exact in `f64`, converted once.
            idx += (k + half) * stride;
            stride *= self.side_f;
            centre[i] = (k + 0.5) * g.cell;
        }
        Some((whole_to_usize(idx), centre))
    }

    /// Adds every point of the closed box `[lo, hi]` at once: lowers each cell to the
    /// quantised distance from its centre to the box, which is at most the distance to any
    /// point in it. A caller that has added a box need not add the points inside it later: the
    /// map stays a lower bound, looser by at most the box's diagonal near it. Grows the map
    /// first like [`insert`](Self::insert). `lo <= hi` on every axis.
    pub fn insert_box(&mut self, lo: &[f64; D], hi: &[f64; D]) -> Result<(), DistanceMapError> {
        let need = finite_max_norm(lo)?.max(finite_max_norm(hi)?) + self.grid.cap + self.grid.cell;
        if need >= self.reach() {
            self.grow(need)?;
        }
        self.grid.points += 1;
        self.lower_box_rows(lo, hi, Self::keep_nearer);
        Ok(())
    }

    /// [`insert_box`](Self::insert_box) through a shared reference, as
    /// [`insert_shared`](Self::insert_shared) is to [`insert`](Self::insert): atomic
    /// `fetch_min`, no growth (cells outside the map are skipped; `false` then).
    pub fn insert_box_shared(
        &self,
        lo: &[f64; D],
        hi: &[f64; D],
    ) -> Result<bool, DistanceMapError> {
        let inside =
            finite_max_norm(lo)?.max(finite_max_norm(hi)?) + self.grid.cap + self.grid.cell
                < self.reach();
        self.lower_box_rows(lo, hi, Self::keep_nearer_shared);
        Ok(inside)
    }

    /// Lowers cell `v` to the squared distance `d2` (in length units) if that is below its
    /// value, through `lower` (a plain or an atomic store); cells at or beyond the cap stay.
    #[inline(always)]
    fn lower_cell(&self, v: &AtomicU8, d2: f64, lower: &mut impl FnMut(&AtomicU8, u8)) {
        // Most cells are already nearer another point: one table read and a compare, no
        // square root.
        if d2 < self.grid.below[usize::from(v.load(Ordering::Relaxed))] {
            let d = d2.sqrt() * self.grid.inv_quantum;
            if d < f64::from(CAPPED) {
                lower(v, d as u8);
            }
        }
    }

    /// The offset in `values` of the first cell (`k_0 = -half`) of the row at `k[1..]`.
    #[inline(always)]
    fn row_base(&self, k: &[i64; D]) -> usize {
        (1..D).map(|i| self.row_key(i, k[i]) as usize).sum()
    }

    /// Calls `lower(cell, w)` for every cell of the map whose centre lies within `cap` of the
    /// box `[blo, bhi]`, with `w` the quantised distance from the centre to the box, whenever
    /// `w` could be below the stored value.
    fn lower_box_rows(&self, blo: &[f64; D], bhi: &[f64; D], mut lower: impl FnMut(&AtomicU8, u8)) {
        let g = &self.grid;
        let Some((lo, hi)) = g.cells_near(blo, bhi) else {
            return;
        };
        let cap2 = g.cap * g.cap;
        // Distance along axis i from the centre of cell k to the box.
        let gap = |i: usize, k: i64| {
            let z = (k as f64 + 0.5) * g.cell;
            (blo[i] - z).max(z - bhi[i]).max(0.0)
        };
        let mut k = lo;
        loop {
            let mut s = 0.0;
            for i in 1..D {
                let e = gap(i, k[i]);
                s += e * e;
            }
            let base = self.row_base(&k);
            if s < cap2 {
                // Centres within sqrt(cap^2 - s) of the box along axis 0.
                let w = (cap2 - s).sqrt();
                let a = (ceil((blo[0] - w) * g.inv_cell - 0.5) as i64).max(lo[0]);
                let b = (floor((bhi[0] + w) * g.inv_cell - 0.5) as i64).min(hi[0]);
                if a <= b {
                    let row =
                        &self.values[base + (a + g.half) as usize..=base + (b + g.half) as usize];
                    for (j, v) in row.iter().enumerate() {
                        let e = gap(0, a + j as i64);
                        self.lower_cell(v, e * e + s, &mut lower);
                    }
                }
            }
            if !next_row(&mut k, &lo, &hi) {
                return;
            }
        }
    }
}

impl<const D: usize> DistanceMap<D> {
    /// Calls `copy(new, old)` for every cell of the map with its index `old` here and `new`
    /// in a grown array of `side` cells per axis centred the same way (`half` its half side),
    /// the old cells in its middle.
    fn copy_rows(&self, side: usize, half: i64, mut copy: impl FnMut(usize, usize)) {
        let off = (half - self.grid.half) as usize;
        // Old rows (along axis 0) in order.
        let rows = self.side.pow(D as u32 - 1);
        for r in 0..rows {
            let mut rem = r;
            let mut base = off;
            let mut stride = side;
            for _ in 1..D {
                base += (rem % self.side + off) * stride;
                rem /= self.side;
                stride *= side;
            }
            for j in 0..self.side {
                copy(base + j, r * self.side + j);
            }
        }
    }
}

impl<const D: usize> DistanceMap<D> {
    /// [`Cells::lower_window`]'s rows, `L` lanes of each computed ([`Grid::window_row`]).
    #[inline(always)]
    fn window_rows<const L: usize>(&mut self, b: &WindowBox<D>) {
        b.rows(
            self,
            |m, i, k| m.row_key(i, k),
            |m, s, key| {
                let w = m.grid.window_row::<L>(&b.x2, s);
                let base = key as usize + b.start;
                // Past the box the lanes are capped, which the minimum leaves as they are: 16
                // bytes may run into the next row, or into the [`PAD`] after the last one.
                let row: &mut [AtomicU8; 16] = (&mut m.values[base..base + 16])
                    .try_into()
                    .expect("16 bytes");
                merge_row(row, w, u8::min);
            },
        );
    }
}

impl<const D: usize> PointMap<D> for DistanceMap<D> {
    /// Heap bytes held (one byte per cell, counting the vector's capacity).
    fn memory_bytes(&self) -> usize {
        self.values.capacity() + self.seen.capacity() * size_of::<AtomicU64>()
    }

    fn value(&self, p: &[f64; D]) -> Option<u8> {
        self.index(p)
            .map(|(i, _)| self.values[i].load(Ordering::Relaxed))
    }

    fn reserve(&mut self, reach: f64) -> Result<(), DistanceMapError> {
        self.cover(reach)
    }
}

impl<const D: usize> Cells<D> for DistanceMap<D> {
    #[inline(always)]
    fn grid(&self) -> &Grid {
        &self.grid
    }

    #[inline(always)]
    fn grid_mut(&mut self) -> &mut Grid {
        &mut self.grid
    }

    /// The cell holding `p`: its stored distance `m` from the centre, `|p - centre|` and the
    /// stored byte.
    #[inline(always)]
    fn read(&self, p: &[f64; D]) -> Option<(f64, f64, u8, [f64; D])> {
        let (idx, z) = self.index(p)?;
        let v = self.values[idx].load(Ordering::Relaxed);
        let mut e2 = 0.0;
        for i in 0..D {
            let e = p[i] - z[i];
            e2 += e * e;
        }
        Some((f64::from(v) * self.grid.quantum, e2.sqrt(), v, z))
    }

    /// Enlarges the map so that it covers `|x_i| < need` (by at least a quarter of its half
    /// side), copying the old cells into the middle of the new ones. The caller guarantees
    /// that every point inserted so far lies farther than `cap` from the new cells.
    fn grow(&mut self, need: f64) -> Result<(), DistanceMapError> {
        let cells = (need * self.grid.inv_cell)
            .ceil()
            .max(self.grid.half as f64 * 1.25)
            .ceil();
        let side = 2.0 * cells;
        let total = side.powi(D as i32);
        // Under 2^52 cells in all, so that a read's index is exact in `f64` and converts by
        // its bits (`whole_to_usize`).
        if !(side < f64::from(u32::MAX)
            && total < (isize::MAX as f64) / 2.0
            && total < 2f64.powi(52))
        {
            return Err(DistanceMapError::TooLarge {
                cells_per_axis: side,
            });
        }
        let half = cells as i64;
        let side = side as usize;
        // Fallible, so a map that does not fit is an error rather than an abort.
        let mut values: Vec<AtomicU8> = Vec::new();
        values
            .try_reserve_exact(total as usize + PAD)
            .map_err(|_| DistanceMapError::Alloc {
                bytes: total as u64 + PAD as u64,
            })?;
        values.extend((0..total as usize + PAD).map(|_| AtomicU8::new(CAPPED)));
        if self.side > 0 {
            self.copy_rows(side, half, |new, old| {
                *values[new].get_mut() = self.values[old].load(Ordering::Relaxed);
            });
        }
        if self.sub > 0 {
            let mut seen: Vec<AtomicU64> = Vec::new();
            seen.try_reserve_exact(total as usize)
                .map_err(|_| DistanceMapError::Alloc {
                    bytes: total as u64 * 8,
                })?;
            seen.extend((0..total as usize).map(|_| AtomicU64::new(0)));
            if self.side > 0 {
                self.copy_rows(side, half, |new, old| {
                    *seen[new].get_mut() = self.seen[old].load(Ordering::Relaxed);
                });
            }
            self.seen = seen;
        }
        self.values = values;
        self.grid.set_half(half);
        self.side = side;
        self.side_f = side as f64;
        Ok(())
    }

    /// Stores the distance byte `w` if it is below the cell's (exclusive access: plain loads
    /// and stores, which relaxed atomics compile to).
    #[inline(always)]
    fn keep_nearer(v: &AtomicU8, w: u8) {
        if w < v.load(Ordering::Relaxed) {
            v.store(w, Ordering::Relaxed);
        }
    }

    /// Lowers the cell to the distance byte `w` with an atomic `fetch_min`.
    #[inline(always)]
    fn keep_nearer_shared(v: &AtomicU8, w: u8) {
        if w < v.load(Ordering::Relaxed) {
            v.fetch_min(w, Ordering::Relaxed);
        }
    }

    /// Row by row of the ball's box (in 2D and 3D, [`Grid::window_box`]), 16 bytes of `values`
    /// from its first column merged with [`Grid::window_row`] by a byte minimum (plain bytes:
    /// the access is exclusive).
    fn lower_window(&mut self, q: &[f64; D]) -> bool {
        let Some(b) = self.grid.window_box(q) else {
            return false;
        };
        let Some(b) = b else {
            return true;
        };
        if b.cells <= 8 {
            self.window_rows::<8>(&b);
        } else {
            self.window_rows::<WINDOW>(&b);
        }
        true
    }

    type RowCache<'a> = ();

    /// The row's offset in `values` along axis `i`: `(k + half) side^i`.
    #[inline(always)]
    fn row_key(&self, i: usize, k: i64) -> u64 {
        ((k + self.grid.half) as usize * self.side.pow(i as u32)) as u64
    }

    /// Lowers the row's cells in `values`, contiguous along axis 0; the row's key is the
    /// offset of its first cell (`k_0 = -half`).
    #[inline(always)]
    fn lower_row(
        &self,
        q: &[f64; D],
        s: f64,
        key: u64,
        (a, b): (i64, i64),
        lower: &mut impl FnMut(&AtomicU8, u8),
        _: &mut (),
    ) {
        let g = &self.grid;
        let base = key as usize;
        let row = &self.values[base + (a + g.half) as usize..=base + (b + g.half) as usize];
        let kc = a as f64 + 0.5;
        // The cell's index along the row, counted in a float (whole numbers: exact), so no
        // cell waits for an integer's conversion.
        let mut j = 0.0;
        for v in row {
            let x = g.offset(kc, j, q[0]);
            self.lower_cell(v, x * x + s, lower);
            j += 1.0;
        }
    }
}
