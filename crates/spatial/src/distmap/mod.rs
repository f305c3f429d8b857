//! A coarse distance map: for a growing set of points, a grid of cubic cells that stores, per
//! cell, a lower bound of the distance from the cell's centre to the nearest point, so that a
//! walker anywhere in the cell gets a lower bound of its distance to the set from one memory
//! read instead of a tree query.
//!
//! This is the device of Ball & Brady (*J. Phys. A* 18, L809, 1985) and of the fast lattice DLA
//! codes that followed (a "distance map" kept up to date as particles stick), applied here to
//! off-lattice DLA (the variable-precision paper, section 3.3) in front of the orthtree of
//! [`crate::orthtree`]: a walker a few diameters or more from the cluster jumps by the map's bound;
//! only near the cluster (or where the map knows nothing) does it pay for a tree query.
//!
//! # What is stored
//!
//! Space is cut into cells `[k c, (k + 1) c)^D` of side `c` (the *cell side*), integer `k`, over
//! a cube centred on the origin that the map enlarges as points arrive. Cell `C` with centre `z`
//! stores one byte `v(C) = min(255, floor(m(C) / u))`, where `m(C)` is the distance from `z` to
//! the nearest point inserted so far and `u = cap / 255` is the *quantum* (`cap` is the *cap
//! distance*: a cell farther than `cap` from every point stores 255, "at least `cap`").
//!
//! # The bound
//!
//! For a position `p` in cell `C` and any inserted point `q`, the triangle inequality gives
//! `|p - q| >= |z - q| - |p - z| >= m(C) - |p - z| >= v(C) u - |p - z|`.
//! [`DistanceMap::lower_bound`] returns that value, shrunk by a relative `2^-40` and an absolute
//! `1e-12` to cover floating-point rounding, so it is never larger than the exact distance to
//! the nearest point. It is at most `2 |p - z| + u` below the exact distance `d` when `d` is
//! below `cap` (the point nearest the centre is within `d + |p - z|` of it), so at most a cell
//! diagonal plus one quantum; for a capped cell it is still a valid bound (`cap - |p - z|`).
//!
//! # Cost
//!
//! - [`lower_bound`](DistanceMap::lower_bound): one byte read and one square root, O(1).
//! - [`insert`](DistanceMap::insert): O((cap / c)^D): every cell whose centre lies within `cap`
//!   of the point is lowered (about 200 cells in 2D for the defaults of `dla`, `cap = 64`,
//!   `c = 8`; the rows are contiguous in memory). A row's range comes from a table of
//!   widths indexed by its distance from the point in whole cells, integer arithmetic with no
//!   square root per row; it visits a few cells more than the exact range, which the
//!   per-cell test rejects. In 3D and above an insert first tabulates, per axis, what its rows
//!   need (offsets, distances, the map's address terms) and, per entry of the widths table,
//!   the range itself, so that each of its rows (64 for a cap of 4 cells) costs a few table
//!   reads.
//! - Growth: when a point comes within `cap + c` of the map's edge (max-norm), the map grows by a
//!   quarter (at least to cover the point) and the old cells are copied; no cell of the new rim
//!   can be within `cap` of a point inserted before, so the copy is exact. Amortised O(1) per
//!   cell.
//! - Memory: one byte per cell, `(2 H / c)^D` bytes for a map of half side `H`; for a 2D DLA
//!   cluster of 1e6 particles (radius about 3 000 diameters, `c = 8`) about 0.7 MB.
//!
//! # Where things are
//!
//! The dense map, [`DistanceMap`], is in `dense`; the sparse one, [`SparseDistanceMap`], in
//! `sparse`. What they share is written once: the cells' geometry, tables and row ranges in
//! `grid`, the half-space an insert beside a touched point keeps to in `beside`, and the bound
//! and the inserts as provided methods of [`PointMap`], over the storage each map supplies.

use std::sync::atomic::AtomicU8;

mod beside;
mod dense;
mod grid;
mod sparse;
use beside::Beside;
pub use dense::DistanceMap;
use grid::{Grid, RowTables};
use sealed::Cells;
pub use sparse::{SparseDistanceMap, UNKNOWN};

/// One read of a map at a position `p` ([`PointMap::reading`]): the bounds of
/// [`PointMap::bounds`] and the empty ball they come from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reading<const D: usize> {
    /// A lower bound of the distance from `p` to the nearest point: `clear - |p - centre|`
    /// (shrunk for rounding).
    pub lower: f64,
    /// An upper bound of that distance (`+inf` for a capped cell).
    pub upper: f64,
    /// Whether the cell is capped (at least `cap` from every point).
    pub capped: bool,
    /// The centre of the cell holding `p`.
    pub centre: [f64; D],
    /// A lower bound of the distance from `centre` to the nearest point (`cap` and above for a
    /// capped cell), shrunk for rounding as `lower` is: no point lies within it of the centre.
    pub clear: f64,
}

/// Largest stored value: the cell is at least `cap` from every point.
const CAPPED: u8 = u8::MAX;

/// Relative shrink of the returned bound (rounding of the distances and the quantisation).
const SHRINK: f64 = 1.0 / 1_099_511_627_776.0;

/// Errors of the distance map's parameters and points.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DistanceMapError {
    /// The cell side is not finite and positive.
    #[error("cell side {0} is invalid; expected a finite number > 0")]
    CellSide(f64),
    /// The cap distance is not finite and positive.
    #[error("cap distance {0} is invalid; expected a finite number > 0")]
    Cap(f64),
    /// A coordinate of an inserted point is not finite.
    #[error("coordinate {axis} of the point is {value}; expected a finite number")]
    NonFinite {
        /// Axis of the offending coordinate.
        axis: usize,
        /// The offending value.
        value: f64,
    },
    /// The map would need more cells than fit in memory (`u32` cell indices per axis and
    /// `usize` in all).
    #[error("the distance map would need {cells_per_axis} cells per axis; too many")]
    TooLarge {
        /// Cells per axis that were needed.
        cells_per_axis: f64,
    },
    /// Sub-boxes per axis that a map cannot keep: 0, more than 64 per cell in all, or asked
    /// of a map that already holds cells.
    #[error(
        "{0} sub-boxes per axis cannot be kept; expected at least 1, at most 64 per cell, on an empty map"
    )]
    SubBoxes(usize),
    /// The system refused the memory of the map's cells.
    #[error("cannot allocate {bytes} bytes for the distance map")]
    Alloc {
        /// Bytes asked for.
        bytes: u64,
    },
}

/// The interface the dense [`DistanceMap`] and the [`SparseDistanceMap`] share: the same cells,
/// bound and inserts, stored densely or in blocks. Callers that hold either kind (the DLA
/// cluster holds both) write one generic function; it dispatches statically, so it costs what
/// the map's own methods cost. Sealed: only the maps of this module implement it.
pub trait PointMap<const D: usize>: Cells<D> {
    /// The cell side.
    fn cell_side(&self) -> f64 {
        self.grid().cell
    }

    /// The cap distance: cells farther than this from every point only know "at least `cap`".
    fn cap(&self) -> f64 {
        self.grid().cap
    }

    /// Points inserted through [`insert`](Self::insert) and
    /// [`insert_beside`](Self::insert_beside) (shared inserts are not counted).
    fn len(&self) -> u64 {
        self.grid().points
    }

    /// Whether no point has been counted by [`len`](Self::len).
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Half the side of the covered cube: positions with every `|x_i|` below this are inside.
    fn reach(&self) -> f64 {
        self.grid().reach()
    }

    /// Heap bytes held.
    fn memory_bytes(&self) -> usize;

    /// The stored distance byte of the cell holding `p` (for tests and diagnostics).
    fn value(&self, p: &[f64; D]) -> Option<u8>;

    /// Grows the map (if needed) so that it covers `|x_i| < reach`.
    fn reserve(&mut self, reach: f64) -> Result<(), DistanceMapError>;

    /// A lower bound of the distance from `p` to the nearest inserted point, with `true` when
    /// the cell is capped (farther than `cap` from every point: a tree query may do better), or
    /// `None` when `p` lies outside the map (or nothing was inserted). The bound may be
    /// negative (no information).
    #[inline]
    fn lower_bound(&self, p: &[f64; D]) -> Option<(f64, bool)> {
        let (m, e, v, _) = self.read(p)?;
        Some((lower_from(m, e), v == CAPPED))
    }

    /// [`lower_bound`](Self::lower_bound) and, for a cell that is not capped, an upper bound
    /// of the same distance: the nearest point is less than one quantum above the stored
    /// value from the cell's centre `z`, so less than that plus `|p - z|` from `p` (widened by
    /// a relative `2^-40` for rounding); `+inf` for a capped cell. As `(lower, upper,
    /// capped)`. After [`DistanceMap::insert_box`] the upper bound is one to the nearest box:
    /// add the boxes' diagonal for one to the points in them.
    #[inline(always)]
    fn bounds(&self, p: &[f64; D]) -> Option<(f64, f64, bool)> {
        self.reading(p).map(|r| (r.lower, r.upper, r.capped))
    }

    /// [`bounds`](Self::bounds) with what they come from: the cell's centre and a lower bound
    /// of its distance to the nearest point (see [`Reading`]).
    #[inline(always)]
    fn reading(&self, p: &[f64; D]) -> Option<Reading<D>> {
        let (m, e, v, centre) = self.read(p)?;
        let capped = v == CAPPED;
        let upper = if capped {
            f64::INFINITY
        } else {
            (m + self.grid().quantum + e) * (1.0 + SHRINK) + 1e-12
        };
        Some(Reading {
            lower: lower_from(m, e),
            upper,
            capped,
            centre,
            clear: m * (1.0 - SHRINK) - 1e-12,
        })
    }

    /// Adds the point `q`: lowers every cell whose centre lies within `cap` of it, growing the
    /// map first if `q` comes within `cap + c` of its edge (the sparse map allocates the
    /// blocks it writes).
    fn insert(&mut self, q: &[f64; D]) -> Result<(), DistanceMapError> {
        self.insert_with(q, None)
    }

    /// [`insert`](Self::insert) of a point `q` that touches the point `p` inserted before it:
    /// the same map, visiting only the cells nearer `q` than `p` (about half), since no other
    /// cell can be lowered by `q`. A 2D or 3D map whose cap spans at most 5.5 cells (a sparse
    /// map's blocks 8 or 16 cells a side) goes by whole rows of the ball's box instead,
    /// branch-free, which costs less than finding that half.
    fn insert_beside(&mut self, q: &[f64; D], p: &[f64; D]) -> Result<(), DistanceMapError> {
        self.insert_with(q, Some(p))
    }

    /// Adds the point `q` through a shared reference, for several threads adding points to one
    /// map while others read it (PDLA): every cell is lowered atomically (the dense map's
    /// `fetch_min` of the distance, the sparse map's `fetch_max` of the nearness), so
    /// concurrent inserts never undo each other. The map does not grow: cells outside it are
    /// skipped (every stored cell stays a valid bound; positions outside simply get no bound).
    /// Returns `false` when part of `q`'s ball fell outside the map. [`len`](Self::len) does
    /// not count these points.
    fn insert_shared(&self, q: &[f64; D]) -> Result<bool, DistanceMapError> {
        self.insert_shared_with(q, None)
    }

    /// [`insert_shared`](Self::insert_shared) of a point `q` that touches `p`, visiting the cells
    /// [`insert_beside`](Self::insert_beside) visits. If `p`'s own insert is still under way
    /// in another thread, the cells skipped here are lowered by it when it completes.
    fn insert_shared_beside(&self, q: &[f64; D], p: &[f64; D]) -> Result<bool, DistanceMapError> {
        self.insert_shared_with(q, Some(p))
    }
}

/// What [`PointMap`]'s provided methods are made of, private to this module: each map
/// supplies its storage (reads, growth, the rows of cells an insert visits, how a cell is
/// lowered); the inserts built on them are written once here.
mod sealed {
    use super::{
        AtomicU8, Beside, DistanceMapError, Grid, RowTables, finite_max_norm, finite_reach,
        next_row,
    };

    pub trait Cells<const D: usize> {
        /// The cells' geometry, tables and point count.
        fn grid(&self) -> &Grid;

        /// [`grid`](Self::grid), to count a point or record growth.
        fn grid_mut(&mut self) -> &mut Grid;

        /// The cell holding `p`: its stored distance `m` from the centre, `|p - centre|` and
        /// its distance byte; `None` where the map has no answer.
        fn read(&self, p: &[f64; D]) -> Option<(f64, f64, u8, [f64; D])>;

        /// Enlarges the map to cover `|x_i| < need` (by at least a quarter), keeping what
        /// it holds.
        fn grow(&mut self, need: f64) -> Result<(), DistanceMapError>;

        /// What the map keeps from one row of an insert to the next (the sparse map's two
        /// recent blocks).
        type RowCache<'a>: Default
        where
            Self: 'a;

        /// The term of axis `i` (`1..D`) at cell index `k` in the key of a row: the row at cell
        /// indices `k[1..]` is the sum of its axes' terms, where the map finds its cells
        /// (`lower_row`). A sum, so that an insert tabulates the terms once per axis.
        fn row_key(&self, i: usize, k: i64) -> u64;

        /// Calls `lower(cell, w)` for the cells `a..=b` (along axis 0) of the row with key
        /// `key` (see [`row_key`](Self::row_key)), at squared distance `s` from `q` along the
        /// other axes, with `w` the value the map stores for the cell's quantised distance to
        /// `q`, whenever `w` could improve on the stored value.
        fn lower_row<'a>(
            &'a self,
            q: &[f64; D],
            s: f64,
            key: u64,
            ab: (i64, i64),
            lower: &mut impl FnMut(&AtomicU8, u8),
            cache: &mut Self::RowCache<'a>,
        );

        /// An exclusive insert of `q` in 2D or 3D by whole rows of
        /// [`WINDOW`](super::grid::WINDOW) cells ([`Grid::window_row`]) from the first column
        /// of the ball's box ([`Grid::window_box`]): every cell of the
        /// box gets the value [`lower_row`](Self::lower_row) would store, branch-free and a
        /// row at a time, where the rows of [`lower_rows`](Self::lower_rows) spend most of
        /// their work on finding the few cells of the ball's half beside the touched point.
        /// The map ends exactly as those rows leave it: a cell they skip keeps its value
        /// either way. `false` when the map does not go this way (the caller then goes by
        /// rows).
        fn lower_window(&mut self, _q: &[f64; D]) -> bool {
            false
        }

        /// The `lower` of an exclusive insert: stores `w` if it is nearer than the cell's
        /// value (plain loads and stores, which relaxed atomics compile to).
        fn keep_nearer(v: &AtomicU8, w: u8);

        /// The `lower` of a shared insert: the same through an atomic read-modify-write, so
        /// that concurrent inserts never undo each other.
        fn keep_nearer_shared(v: &AtomicU8, w: u8);

        /// Makes room for the cells one insert may write (the sparse map's chunk slots);
        /// nothing for a map whose cells all exist.
        fn make_room(&mut self) {}

        /// Grows the map (if needed) so that it covers `|x_i| < reach`.
        fn cover(&mut self, reach: f64) -> Result<(), DistanceMapError> {
            if finite_reach(reach)? >= self.grid().reach() {
                self.grow(reach)?;
            }
            Ok(())
        }

        /// Calls `lower(cell, w)` (see [`lower_row`](Self::lower_row)) for every cell of the
        /// map whose centre lies within `cap` of `q`, and only in the half-space `side` if
        /// given: an odometer over the rows (axes `1..D`), each row's range along axis 0
        /// solved for.
        #[inline]
        fn lower_rows(
            &self,
            q: &[f64; D],
            side: Option<&Beside<D>>,
            mut lower: impl FnMut(&AtomicU8, u8),
        ) {
            let g = self.grid();
            let Some((lo, hi)) = g.cells_near(q, q) else {
                return;
            };
            let mut k = lo;
            let (t0, kq) = g.row_origin(q);
            let mut cache = Self::RowCache::default();
            // In 2D a row is one cell index along axis 1: nothing to share between rows.
            let mut t = RowTables::new();
            let key = |i, k| self.row_key(i, k);
            if D >= 3 && t.fill(g, q, &lo, &hi, (t0, &kq), side, key) {
                if D == 3 {
                    t.each_row_3d(&lo, &hi, side, |s, key, ab| {
                        self.lower_row(q, s, key, ab, &mut lower, &mut cache)
                    });
                    return;
                }
                loop {
                    let (s, j2, key) = t.row_offset(&k, &lo);
                    if let Some((a, b)) = t.row_span(j2, &k, &lo, side) {
                        if a <= b {
                            self.lower_row(q, s, key, (a, b), &mut lower, &mut cache);
                        }
                    }
                    if !next_row(&mut k, &lo, &hi) {
                        return;
                    }
                }
            }
            loop {
                let (s, j2) = g.row_offset(q, &k, &kq);
                if let Some(range) = g.row_range(q[0], s, t0, j2) {
                    let (a, b) = g.clip_row(range, lo[0], hi[0], &k, side);
                    if a <= b {
                        let key = (1..D).map(|i| self.row_key(i, k[i])).sum();
                        self.lower_row(q, s, key, (a, b), &mut lower, &mut cache);
                    }
                }
                if !next_row(&mut k, &lo, &hi) {
                    return;
                }
            }
        }

        /// Inserts `q`, beside the point `touched` if given (see `PointMap::insert_beside`),
        /// growing the map first if `q` comes within `cap + c` of its edge.
        fn insert_with(
            &mut self,
            q: &[f64; D],
            touched: Option<&[f64; D]>,
        ) -> Result<(), DistanceMapError> {
            let g = self.grid();
            let need = finite_max_norm(q)? + g.cap + g.cell;
            if need >= g.reach() {
                self.grow(need)?;
            }
            self.make_room();
            self.grid_mut().points += 1;
            if !self.lower_window(q) {
                let g = self.grid();
                let side = touched.and_then(|p| Beside::new(q, p, g.cap, g.cell));
                self.lower_rows(q, side.as_ref(), Self::keep_nearer);
            }
            Ok(())
        }

        /// Inserts `q` through a shared reference (see `PointMap::insert_shared_beside`);
        /// `false` when part of its ball fell outside the map.
        fn insert_shared_with(
            &self,
            q: &[f64; D],
            touched: Option<&[f64; D]>,
        ) -> Result<bool, DistanceMapError> {
            let g = self.grid();
            let side = touched.and_then(|p| Beside::new(q, p, g.cap, g.cell));
            let inside = finite_max_norm(q)? + g.cap + g.cell < g.reach();
            self.lower_rows(q, side.as_ref(), Self::keep_nearer_shared);
            Ok(inside)
        }
    }
}

/// The lower bound from a cell's stored distance `m` and `|p - centre|` `e`, shrunk for
/// rounding.
#[inline(always)]
fn lower_from(m: f64, e: f64) -> f64 {
    m * (1.0 - SHRINK) - e * (1.0 + SHRINK) - 1e-12
}

/// `reach` if it is finite, else the error [`PointMap::reserve`] returns.
fn finite_reach(reach: f64) -> Result<f64, DistanceMapError> {
    if reach.is_finite() {
        Ok(reach)
    } else {
        Err(DistanceMapError::NonFinite {
            axis: 0,
            value: reach,
        })
    }
}

/// The largest `|x_i|`, or the first non-finite coordinate as an error.
fn finite_max_norm<const D: usize>(q: &[f64; D]) -> Result<f64, DistanceMapError> {
    let mut m = 0.0f64;
    for (axis, &x) in q.iter().enumerate() {
        if !x.is_finite() {
            return Err(DistanceMapError::NonFinite { axis, value: x });
        }
        m = m.max(x.abs());
    }
    Ok(m)
}

/// Advances the row index `k[1..]` through the box of cells `lo..=hi` (axis 0 runs along a
/// row), odometer fashion; `false` once the last row is done.
#[inline(always)]
fn next_row<const D: usize>(k: &mut [i64; D], lo: &[i64; D], hi: &[i64; D]) -> bool {
    for axis in 1..D {
        if k[axis] < hi[axis] {
            k[axis] += 1;
            return true;
        }
        k[axis] = lo[axis];
    }
    false
}

#[cfg(test)]
mod tests;
