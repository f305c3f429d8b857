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
//!   per-cell test rejects.
//! - Growth: when a point comes within `cap + c` of the map's edge (max-norm), the map grows by a
//!   quarter (at least to cover the point) and the old cells are copied; no cell of the new rim
//!   can be within `cap` of a point inserted before, so the copy is exact. Amortised O(1) per
//!   cell.
//! - Memory: one byte per cell, `(2 H / c)^D` bytes for a map of half side `H`; for a 2D DLA
//!   cluster of 1e6 particles (radius about 3 000 diameters, `c = 8`) about 0.7 MB.

use crate::round::{ceil, floor};
use std::fmt;

mod beside;
mod sparse;
use beside::Beside;
use sealed::Cells;
pub use sparse::{SparseDistanceMap, UNKNOWN};

use std::sync::atomic::{AtomicU8, Ordering};

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
    fn cell_side(&self) -> f64;

    /// The cap distance: cells farther than this from every point only know "at least `cap`".
    fn cap(&self) -> f64;

    /// Points inserted through [`insert`](Self::insert) and
    /// [`insert_beside`](Self::insert_beside) (shared inserts are not counted).
    fn len(&self) -> u64;

    /// Whether no point has been counted by [`len`](Self::len).
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Half the side of the covered cube: positions with every `|x_i|` below this are inside.
    fn reach(&self) -> f64;

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
        let (m, e, v) = self.read(p)?;
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
        let (m, e, v) = self.read(p)?;
        let capped = v == CAPPED;
        let upper = if capped {
            f64::INFINITY
        } else {
            (m + self.quantum() + e) * (1.0 + SHRINK) + 1e-12
        };
        Some((lower_from(m, e), upper, capped))
    }

    /// Adds the point `q`: lowers every cell whose centre lies within `cap` of it, growing the
    /// map first if `q` comes within `cap + c` of its edge (the sparse map allocates the
    /// blocks it writes).
    fn insert(&mut self, q: &[f64; D]) -> Result<(), DistanceMapError> {
        self.insert_with(q, None)
    }

    /// [`insert`](Self::insert) of a point `q` that touches the point `p` inserted before it:
    /// the same map, visiting only the cells nearer `q` than `p` (about half), since no other
    /// cell can be lowered by `q`.
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

/// What [`PointMap`]'s provided methods are made of, private to this module.
mod sealed {
    use super::DistanceMapError;

    pub trait Cells<const D: usize> {
        /// The cell holding `p`: its stored distance `m` from the centre, `|p - centre|` and
        /// its distance byte; `None` where the map has no answer.
        fn read(&self, p: &[f64; D]) -> Option<(f64, f64, u8)>;

        /// `cap / 255`, the distance one step of a stored byte stands for.
        fn quantum(&self) -> f64;

        /// Inserts `q`, beside the point `touched` if given (see `PointMap::insert_beside`).
        fn insert_with(
            &mut self,
            q: &[f64; D],
            touched: Option<&[f64; D]>,
        ) -> Result<(), DistanceMapError>;

        /// Inserts `q` through a shared reference (see `PointMap::insert_shared_beside`).
        fn insert_shared_with(
            &self,
            q: &[f64; D],
            touched: Option<&[f64; D]>,
        ) -> Result<bool, DistanceMapError>;
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

/// The coarse distance map (see the module docs).
pub struct DistanceMap<const D: usize> {
    cell: f64,
    inv_cell: f64,
    cap: f64,
    quantum: f64,
    inv_quantum: f64,
    /// The map covers cells `k` in `[-half, half)` per axis, i.e. `|x| < half * cell`.
    half: i64,
    /// `2 * half`: cells per axis.
    side: usize,
    /// One byte per cell, axis 0 fastest. Atomic so that PDLA threads can share one map
    /// ([`DistanceMap::insert_shared`]); relaxed loads and stores are plain moves.
    values: Vec<AtomicU8>,
    points: u64,
    /// `below[v]`: a squared distance below which a cell holding `v` may be lowered,
    /// `(v u)^2` widened by a relative `2^-40` (so rounding never skips a lowering).
    below: Box<[f64; 256]>,
    /// `widths[j]`: for a row of cells whose centres lie at a squared distance of at least
    /// `j` squared cell sides from the inserted point along the other axes, half the length,
    /// in cells, of the part of the row within `cap` of it, widened a little (so a row never
    /// misses a cell). Empty when `(cap / cell)^2` exceeds [`WIDTHS_MAX`]; rows then solve
    /// for their range exactly.
    widths: Box<[f64]>,
}

/// Largest `(cap / cell)^2` for which [`DistanceMap`] tabulates its row widths.
const WIDTHS_MAX: f64 = 4096.0;

/// What a map with cells of side `cell` capped at `cap` derives from them (see [`tables`]).
struct Tables {
    /// `cap / 255`.
    quantum: f64,
    /// `below[v]`: the squared distance below which a cell holding `v` may be lowered,
    /// `(v u)^2` widened by a relative [`SHRINK`].
    below: Box<[f64; 256]>,
    /// Row half-widths by squared distance in whole cells; empty when `(cap / cell)^2` exceeds
    /// [`WIDTHS_MAX`].
    widths: Box<[f64]>,
}

/// The [`Tables`] of a map with cells of side `cell` capped at `cap`, both checked.
fn tables(cell: f64, cap: f64) -> Result<Tables, DistanceMapError> {
    if !(cell.is_finite() && cell > 0.0) {
        return Err(DistanceMapError::CellSide(cell));
    }
    if !(cap.is_finite() && cap > 0.0) {
        return Err(DistanceMapError::Cap(cap));
    }
    let quantum = cap / f64::from(CAPPED);
    let mut below = Box::new([0.0; 256]);
    for (v, b) in below.iter_mut().enumerate() {
        let d = v as f64 * quantum;
        *b = d * d * (1.0 + SHRINK);
    }
    let r2 = (cap / cell) * (cap / cell);
    let widths = if r2 <= WIDTHS_MAX {
        (0..=r2 as usize)
            .map(|j| (r2 - j as f64).max(0.0).sqrt() * (1.0 + 1e-9) + 1e-9)
            .collect()
    } else {
        Box::default()
    };
    Ok(Tables {
        quantum,
        below,
        widths,
    })
}

impl<const D: usize> Clone for DistanceMap<D> {
    fn clone(&self) -> Self {
        DistanceMap {
            cell: self.cell,
            inv_cell: self.inv_cell,
            cap: self.cap,
            quantum: self.quantum,
            inv_quantum: self.inv_quantum,
            half: self.half,
            side: self.side,
            values: self
                .values
                .iter()
                .map(|v| AtomicU8::new(v.load(Ordering::Relaxed)))
                .collect(),
            points: self.points,
            below: self.below.clone(),
            widths: self.widths.clone(),
        }
    }
}

impl<const D: usize> fmt::Debug for DistanceMap<D> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("DistanceMap")
            .field("cell", &self.cell)
            .field("cap", &self.cap)
            .field("cells_per_axis", &self.side)
            .field("points", &self.points)
            .finish()
    }
}

impl<const D: usize> DistanceMap<D> {
    /// An empty map with cell side `cell` and cap distance `cap` (both in the units of the
    /// points). Nothing is allocated until the first insert.
    pub fn new(cell: f64, cap: f64) -> Result<Self, DistanceMapError> {
        let Tables {
            quantum,
            below,
            widths,
        } = tables(cell, cap)?;
        Ok(DistanceMap {
            below,
            widths,
            cell,
            inv_cell: 1.0 / cell,
            cap,
            quantum,
            inv_quantum: 1.0 / quantum,
            half: 0,
            side: 0,
            values: Vec::new(),
            points: 0,
        })
    }

    /// The cell index of `p`, or `None` outside the map.
    #[inline]
    fn index(&self, p: &[f64; D]) -> Option<(usize, [f64; D])> {
        let mut idx = 0usize;
        let mut stride = 1usize;
        let mut centre = [0.0; D];
        for i in 0..D {
            let k = floor(p[i] * self.inv_cell);
            // The cube is `side = 2 half` cells a side; a signed integer converts to `f64` in
            // one instruction, an unsigned one in several. NaN fails the test.
            let half = self.half as f64;
            if !(k >= -half && k < half) {
                return None;
            }
            let j = k + half;
            // j is a whole number in [0, side): through i64 the conversion is one instruction
            // and a check, where a direct f64 -> usize conversion is a longer sequence.
            idx += j as i64 as usize * stride;
            stride *= self.side;
            centre[i] = (k + 0.5) * self.cell;
        }
        Some((idx, centre))
    }

    /// Adds every point of the closed box `[lo, hi]` at once: lowers each cell to the
    /// quantised distance from its centre to the box, which is at most the distance to any
    /// point in it. A caller that has added a box need not add the points inside it later: the
    /// map stays a lower bound, looser by at most the box's diagonal near it. Grows the map
    /// first like [`insert`](Self::insert). `lo <= hi` on every axis.
    pub fn insert_box(&mut self, lo: &[f64; D], hi: &[f64; D]) -> Result<(), DistanceMapError> {
        let need = finite_max_norm(lo)?.max(finite_max_norm(hi)?) + self.cap + self.cell;
        if need >= self.reach() {
            self.grow(need)?;
        }
        self.points += 1;
        self.lower_box_rows(lo, hi, |v, w| {
            if w < v.load(Ordering::Relaxed) {
                v.store(w, Ordering::Relaxed);
            }
        });
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
            finite_max_norm(lo)?.max(finite_max_norm(hi)?) + self.cap + self.cell < self.reach();
        self.lower_box_rows(lo, hi, |v, w| {
            if w < v.load(Ordering::Relaxed) {
                v.fetch_min(w, Ordering::Relaxed);
            }
        });
        Ok(inside)
    }

    /// Lowers cell `v` to the squared distance `d2` (in length units) if that is below its
    /// value, through `lower` (a plain or an atomic store); cells at or beyond the cap stay.
    #[inline(always)]
    fn lower_cell(&self, v: &AtomicU8, d2: f64, lower: &mut impl FnMut(&AtomicU8, u8)) {
        // Most cells are already nearer another point: one table read and a compare, no
        // square root.
        if d2 < self.below[usize::from(v.load(Ordering::Relaxed))] {
            let d = d2.sqrt() * self.inv_quantum;
            if d < f64::from(CAPPED) {
                lower(v, d as u8);
            }
        }
    }

    /// Calls `lower(cell, w)` for every cell of the map whose centre lies within `cap` of the
    /// box `[blo, bhi]`, with `w` the quantised distance from the centre to the box, whenever
    /// `w` could be below the stored value.
    fn lower_box_rows(&self, blo: &[f64; D], bhi: &[f64; D], mut lower: impl FnMut(&AtomicU8, u8)) {
        let mut lo = [0i64; D];
        let mut hi = [0i64; D];
        for i in 0..D {
            lo[i] = (ceil((blo[i] - self.cap) * self.inv_cell - 0.5) as i64).max(-self.half);
            hi[i] = (floor((bhi[i] + self.cap) * self.inv_cell - 0.5) as i64).min(self.half - 1);
            if lo[i] > hi[i] {
                return;
            }
        }
        let cap2 = self.cap * self.cap;
        // Distance along axis i from the centre of cell k to the box.
        let gap = |i: usize, k: i64| {
            let z = (k as f64 + 0.5) * self.cell;
            (blo[i] - z).max(z - bhi[i]).max(0.0)
        };
        let mut k = lo;
        loop {
            let mut s = 0.0;
            let mut base = 0usize;
            let mut stride = self.side;
            for i in 1..D {
                let e = gap(i, k[i]);
                s += e * e;
                base += (k[i] + self.half) as usize * stride;
                stride *= self.side;
            }
            if s < cap2 {
                // Centres within sqrt(cap^2 - s) of the box along axis 0.
                let w = (cap2 - s).sqrt();
                let a = (ceil((blo[0] - w) * self.inv_cell - 0.5) as i64).max(lo[0]);
                let b = (floor((bhi[0] + w) * self.inv_cell - 0.5) as i64).min(hi[0]);
                if a <= b {
                    let row = &self.values
                        [base + (a + self.half) as usize..=base + (b + self.half) as usize];
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

    /// Calls `lower(cell, w)` for every cell of the map whose centre lies within `cap` of `q`,
    /// with `w` the quantised distance from the centre to `q`, whenever `w` could be below the
    /// stored value (`(w u)^2` under the table's threshold for that value).
    #[inline]
    fn lower_rows(
        &self,
        q: &[f64; D],
        side: Option<&Beside<D>>,
        mut lower: impl FnMut(&AtomicU8, u8),
    ) {
        // Cell ranges per axis: centres (k + 1/2) c within cap of q, clipped to the map.
        let mut lo = [0i64; D];
        let mut hi = [0i64; D];
        for i in 0..D {
            lo[i] = (ceil((q[i] - self.cap) * self.inv_cell - 0.5) as i64).max(-self.half);
            hi[i] = (floor((q[i] + self.cap) * self.inv_cell - 0.5) as i64).min(self.half - 1);
            if lo[i] > hi[i] {
                return;
            }
        }
        // Odometer over axes 1..D; axis 0 is a contiguous row whose range is solved for.
        let mut k = lo;
        let cap2 = self.cap * self.cap;
        // q in units of cells, with the cells' centres at whole numbers, and the lower of the
        // two centre indices around it on each axis: the centres of a row `j_i` whole cells
        // beyond that pair on axis i are at least `j_i` cells from q along that axis.
        let t0 = q[0] * self.inv_cell - 0.5;
        let kq: [i64; D] = std::array::from_fn(|i| floor(q[i] * self.inv_cell - 0.5) as i64);
        loop {
            let mut s = 0.0;
            let mut j2 = 0usize;
            let mut base = 0usize;
            let mut stride = self.side;
            for i in 1..D {
                let e = q[i] - (k[i] as f64 + 0.5) * self.cell;
                s += e * e;
                let j = if k[i] <= kq[i] {
                    kq[i] - k[i]
                } else {
                    k[i] - kq[i] - 1
                };
                j2 += (j * j) as usize;
                base += (k[i] + self.half) as usize * stride;
                stride *= self.side;
            }
            // The row's range along axis 0: from the table of widths (no square root per
            // row; a few cells more than the exact range, which the per-cell test rejects),
            // or solved exactly when there is no table.
            let range = if self.widths.is_empty() {
                (s < cap2).then(|| {
                    let w = (cap2 - s).sqrt();
                    (
                        ceil((q[0] - w) * self.inv_cell - 0.5),
                        floor((q[0] + w) * self.inv_cell - 0.5),
                    )
                })
            } else {
                // `j2` is at most the row's squared distance from q in cells, so its width in
                // the table is at least the exact one. It is integer arithmetic: the row's
                // range does not wait for the floating-point distance (which only the
                // per-cell test below uses), and the rows' set-up overlaps.
                self.widths.get(j2).map(|&h| (ceil(t0 - h), floor(t0 + h)))
            };
            if let Some((a, b)) = range {
                let a = (a as i64).max(lo[0]);
                let b = (b as i64).min(hi[0]);
                let (a, b) = match side {
                    Some(side) => side.clip(&k, self.cell, self.inv_cell, a, b),
                    None => (a, b),
                };
                if a <= b {
                    let row = &self.values
                        [base + (a + self.half) as usize..=base + (b + self.half) as usize];
                    let x0 = (a as f64 + 0.5) * self.cell - q[0];
                    for (j, v) in row.iter().enumerate() {
                        // Rows are far shorter than 2^31 cells; i32 converts in one instruction.
                        let x = x0 + f64::from(j as i32) * self.cell;
                        self.lower_cell(v, x * x + s, &mut lower);
                    }
                }
            }
            // Next row.
            if !next_row(&mut k, &lo, &hi) {
                return;
            }
        }
    }

    /// Enlarges the map so that it covers `|x_i| < need` (by at least a quarter of its half
    /// side), copying the old cells into the middle of the new ones. The caller guarantees
    /// that every point inserted so far lies farther than `cap` from the new cells.
    fn grow(&mut self, need: f64) -> Result<(), DistanceMapError> {
        let cells = (need * self.inv_cell)
            .ceil()
            .max(self.half as f64 * 1.25)
            .ceil();
        let side = 2.0 * cells;
        let total = side.powi(D as i32);
        if !(side < f64::from(u32::MAX) && total < (isize::MAX as f64) / 2.0) {
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
            let off = (half - self.half) as usize;
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
        self.half = half;
        self.side = side;
        Ok(())
    }
}

impl<const D: usize> PointMap<D> for DistanceMap<D> {
    fn cell_side(&self) -> f64 {
        self.cell
    }

    fn cap(&self) -> f64 {
        self.cap
    }

    fn len(&self) -> u64 {
        self.points
    }

    fn reach(&self) -> f64 {
        self.half as f64 * self.cell
    }

    /// Heap bytes held (one byte per cell, counting the vector's capacity).
    fn memory_bytes(&self) -> usize {
        self.values.capacity()
    }

    fn value(&self, p: &[f64; D]) -> Option<u8> {
        self.index(p)
            .map(|(i, _)| self.values[i].load(Ordering::Relaxed))
    }

    fn reserve(&mut self, reach: f64) -> Result<(), DistanceMapError> {
        if finite_reach(reach)? >= self.reach() {
            self.grow(reach)?;
        }
        Ok(())
    }
}

impl<const D: usize> Cells<D> for DistanceMap<D> {
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
        Some((f64::from(v) * self.quantum, e2.sqrt(), v))
    }

    #[inline(always)]
    fn quantum(&self) -> f64 {
        self.quantum
    }

    fn insert_with(
        &mut self,
        q: &[f64; D],
        touched: Option<&[f64; D]>,
    ) -> Result<(), DistanceMapError> {
        let side = touched.and_then(|p| Beside::new(q, p, self.cap, self.cell));
        let need = finite_max_norm(q)? + self.cap + self.cell;
        if need >= self.reach() {
            self.grow(need)?;
        }
        self.points += 1;
        // Exclusive access: plain loads and stores (relaxed atomics compile to plain moves).
        self.lower_rows(q, side.as_ref(), |v, w| {
            if w < v.load(Ordering::Relaxed) {
                v.store(w, Ordering::Relaxed);
            }
        });
        Ok(())
    }

    fn insert_shared_with(
        &self,
        q: &[f64; D],
        touched: Option<&[f64; D]>,
    ) -> Result<bool, DistanceMapError> {
        let side = touched.and_then(|p| Beside::new(q, p, self.cap, self.cell));
        let inside = finite_max_norm(q)? + self.cap + self.cell < self.reach();
        self.lower_rows(q, side.as_ref(), |v, w| {
            if w < v.load(Ordering::Relaxed) {
                v.fetch_min(w, Ordering::Relaxed);
            }
        });
        Ok(inside)
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
