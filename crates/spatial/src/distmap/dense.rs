//! The dense distance map: one byte per cell over the whole covered cube (see the parent
//! module for what a cell stores and the bound it gives), and its inserts of boxes.

use super::grid::Grid;
use super::{CAPPED, Cells, DistanceMapError, PointMap, finite_max_norm, next_row};
use crate::round::{ceil, floor, whole_to_usize};
use std::fmt;
use std::sync::atomic::{AtomicU8, Ordering};

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
        })
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
        let mut base = 0usize;
        let mut stride = self.side;
        for i in 1..D {
            base += (k[i] + self.grid.half) as usize * stride;
            stride *= self.side;
        }
        base
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

impl<const D: usize> PointMap<D> for DistanceMap<D> {
    /// Heap bytes held (one byte per cell, counting the vector's capacity).
    fn memory_bytes(&self) -> usize {
        self.values.capacity()
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
    fn read(&self, p: &[f64; D]) -> Option<(f64, f64, u8)> {
        let (idx, z) = self.index(p)?;
        let v = self.values[idx].load(Ordering::Relaxed);
        let mut e2 = 0.0;
        for i in 0..D {
            let e = p[i] - z[i];
            e2 += e * e;
        }
        Some((f64::from(v) * self.grid.quantum, e2.sqrt(), v))
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
            .try_reserve_exact(total as usize)
            .map_err(|_| DistanceMapError::Alloc {
                bytes: total as u64,
            })?;
        values.extend((0..total as usize).map(|_| AtomicU8::new(CAPPED)));
        if self.side > 0 {
            let off = (half - self.grid.half) as usize;
            // Copy old rows (along axis 0) into the new array.
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
                for (new, old) in values[base..base + self.side]
                    .iter_mut()
                    .zip(&self.values[r * self.side..(r + 1) * self.side])
                {
                    *new.get_mut() = old.load(Ordering::Relaxed);
                }
            }
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

    type RowCache<'a> = ();

    /// Lowers the row's cells in `values`, contiguous along axis 0.
    #[inline(always)]
    fn lower_row(
        &self,
        q: &[f64; D],
        s: f64,
        k: &[i64; D],
        (a, b): (i64, i64),
        lower: &mut impl FnMut(&AtomicU8, u8),
        _: &mut (),
    ) {
        let g = &self.grid;
        let base = self.row_base(k);
        let row = &self.values[base + (a + g.half) as usize..=base + (b + g.half) as usize];
        let x0 = (a as f64 + 0.5) * g.cell - q[0];
        for (j, v) in row.iter().enumerate() {
            // Rows are far shorter than 2^31 cells; i32 converts in one instruction.
            let x = x0 + f64::from(j as i32) * g.cell;
            self.lower_cell(v, x * x + s, lower);
        }
    }
}
