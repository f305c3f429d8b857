//! What the dense and the sparse maps share: the cells' geometry, the quantum, the tables an
//! insert reads and the count of points ([`Grid`]), and the ranges of cells a point's ball
//! covers, row by row.

use super::beside::Beside;
use super::{CAPPED, DistanceMapError, SHRINK};
use crate::round::{ceil, floor};
use std::sync::atomic::AtomicU8;

/// Largest `(cap / cell)^2` for which a map tabulates its row widths.
const WIDTHS_MAX: f64 = 4096.0;

/// Most cells per axis over which an insert tabulates its rows' offsets ([`RowTables`]); an
/// insert spanning more computes every row in full.
const TABLE_ROWS: usize = 12;

/// Most entries of the table of widths ([`Grid::widths`]) for which an insert tabulates its
/// rows' ranges along axis 0 ([`RowTables`]). With [`TABLE_ROWS`], enough for a cap of up to
/// 5.5 cells (the tables stay small: an insert sets them to zero before filling them).
const TABLE_SPANS: usize = 32;

/// Cells along a row that an exclusive 2D or 3D insert computes at once
/// ([`Grid::window_row`]): a point's cells within the cap along a row fit whenever the cap is
/// at most 5.5 cells (`dla`'s sparse maps and first dense levels have 4).
pub(super) const WINDOW: usize = 12;

/// Merges the bytes `w` into the row `row` of a map held exclusively, byte by byte with
/// `keep` (the dense map's minimum, the sparse map's maximum): through plain copies, so that
/// the compiler does it as one vector load, operation and store.
#[inline(always)]
pub(super) fn merge_row<const N: usize>(
    row: &mut [AtomicU8; N],
    w: [u8; N],
    keep: impl Fn(u8, u8) -> u8,
) {
    let mut cur = [0u8; N];
    for (c, v) in cur.iter_mut().zip(row.iter_mut()) {
        *c = *v.get_mut();
    }
    for (c, w) in cur.iter_mut().zip(w) {
        *c = keep(*c, w);
    }
    for (v, c) in row.iter_mut().zip(cur) {
        *v.get_mut() = c;
    }
}

/// The cells of a map of side `cell` capped at `cap`, how far the map reaches, its points,
/// and the tables its inserts read (see [`Grid::new`]).
#[derive(Clone)]
pub struct Grid {
    pub(super) cell: f64,
    pub(super) inv_cell: f64,
    pub(super) cap: f64,
    /// `cap / 255`, the distance one step of a stored byte stands for.
    pub(super) quantum: f64,
    pub(super) inv_quantum: f64,
    /// The map covers cells `k` in `[-half, half)` per axis, i.e. `|x| < half * cell`.
    pub(super) half: i64,
    /// `half` as a float, for the reads' in-map test (set with `half`, by `set_half`).
    pub(super) half_f: f64,
    /// Points counted by `PointMap::len`.
    pub(super) points: u64,
    /// `below[v]`: a squared distance below which a cell holding `v` may be lowered,
    /// `(v u)^2` widened by a relative `2^-40` (so rounding never skips a lowering). The sparse
    /// map, which stores nearness `255 - v`, holds it reversed.
    pub(super) below: Box<[f64; 256]>,
    /// `widths[j]`: for a row of cells whose centres lie at a squared distance of at least
    /// `j` squared cell sides from the inserted point along the other axes, half the length,
    /// in cells, of the part of the row within `cap` of it, widened a little (so a row never
    /// misses a cell). Empty when `(cap / cell)^2` exceeds [`WIDTHS_MAX`]; rows then solve
    /// for their range exactly.
    pub(super) widths: Box<[f64]>,
    /// `cap^2 (1 + 1e-9)`: a row of cells at a squared distance of at least this from a point
    /// along the other axes has no cell within the cap, even after rounding (an exclusive
    /// window insert skips it, see [`window_row`](Self::window_row)).
    pub(super) window_skip: f64,
    /// Whether exclusive inserts may go by window rows (`Cells::lower_window`); always, but
    /// for the tests of the rows' inserts.
    pub(super) window_inserts: bool,
}

impl Grid {
    /// An empty grid (covering nothing) of cells of side `cell` capped at `cap`, both checked.
    pub(super) fn new(cell: f64, cap: f64) -> Result<Self, DistanceMapError> {
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
        Ok(Grid {
            cell,
            inv_cell: 1.0 / cell,
            cap,
            quantum,
            inv_quantum: 1.0 / quantum,
            half: 0,
            half_f: 0.0,
            points: 0,
            below,
            widths,
            window_skip: cap * cap * (1.0 + 1e-9),
            window_inserts: true,
        })
    }

    /// The offset along axis 0 from `q_0` of the centre of cell `k + n`, given
    /// `kc = k + 1/2`: `(kc + n) c - q_0`, the sum exact (whole numbers and halves), so that
    /// every insert computes a cell's offset to the same bits, whichever cell its row or
    /// window starts at.
    #[inline(always)]
    pub(super) fn offset(&self, kc: f64, n: f64, q0: f64) -> f64 {
        (kc + n) * self.cell - q0
    }

    /// The squared offsets along a row ([`offset`](Self::offset)) of the first `cells` of
    /// the [`WINDOW`] cells from cell `k` (`kc = k + 1/2`) on, and infinity after them (their
    /// cells come out capped): the same for every row of an insert
    /// ([`window_row`](Self::window_row)).
    #[inline(always)]
    pub(super) fn window_offsets(&self, kc: f64, q0: f64, cells: i64) -> [f64; WINDOW] {
        std::array::from_fn(|n| {
            let x = self.offset(kc, f64::from(n as i32), q0);
            if (n as i64) < cells {
                x * x
            } else {
                f64::INFINITY
            }
        })
    }

    /// The distance bytes `min(255, floor(|c - q| / u))` of the [`WINDOW`] cells at squared
    /// offsets `x2` ([`window_offsets`](Self::window_offsets)) along a row at squared
    /// distance `s` from `q` along the other axes (255, capped, at an infinite offset), and
    /// 255 in the four lanes after them: a 16-byte row that an exclusive 2D or 3D insert
    /// merges into the map's ([`Cells::lower_window`]). Each lane is the value
    /// [`Cells::lower_row`] stores for its cell, computed without a test so that the lanes
    /// run in vector registers: a cell beyond the cap comes out capped, and a cell already
    /// nearer another point keeps its value when merged.
    ///
    /// Only the first `L` lanes are computed (the rest are capped): a box of at most `L`
    /// cells a row needs no more. A cap of 4 cells, `dla`'s, makes boxes of 8 cells a row for
    /// all but the points at exact cell boundaries, and 8 lanes are two 4-lane vectors of
    /// square roots where 12 are three.
    ///
    /// [`Cells::lower_window`]: super::sealed::Cells::lower_window
    /// [`Cells::lower_row`]: super::sealed::Cells::lower_row
    #[inline(always)]
    pub(super) fn window_row<const L: usize>(&self, x2: &[f64; WINDOW], s: f64) -> [u8; 16] {
        let mut w = [CAPPED; 16];
        for (w, x2) in w[..L].iter_mut().zip(&x2[..L]) {
            let d = ((x2 + s).sqrt() * self.inv_quantum).min(f64::from(CAPPED));
            // `floor(d)` (a whole number in [0, 255]) plus 2^52 is exact and holds it in the
            // mantissa's low byte: a conversion without the saturating cast's tests, which
            // keeps the lanes in vector registers.
            *w = (d.floor() + 4_503_599_627_370_496.0).to_bits() as u8;
        }
        w
    }

    /// Sets the half side in cells (`half` and `half_f`).
    #[inline]
    pub(super) fn set_half(&mut self, half: i64) {
        self.half = half;
        self.half_f = half as f64;
    }

    /// Half the side of the covered cube.
    #[inline(always)]
    pub(super) fn reach(&self) -> f64 {
        self.half as f64 * self.cell
    }

    /// Per axis, the cells whose centres `(k + 1/2) c` lie within `cap` of the box
    /// `[blo, bhi]` (a point when `blo == bhi`), clipped to the map; `None` if none do.
    #[inline(always)]
    pub(super) fn cells_near<const D: usize>(
        &self,
        blo: &[f64; D],
        bhi: &[f64; D],
    ) -> Option<([i64; D], [i64; D])> {
        let mut lo = [0i64; D];
        let mut hi = [0i64; D];
        for i in 0..D {
            lo[i] = (ceil((blo[i] - self.cap) * self.inv_cell - 0.5) as i64).max(-self.half);
            hi[i] = (floor((bhi[i] + self.cap) * self.inv_cell - 0.5) as i64).min(self.half - 1);
            if lo[i] > hi[i] {
                return None;
            }
        }
        Some((lo, hi))
    }

    /// Where the point `q` sits among the cells, for [`row_offset`](Self::row_offset) and
    /// [`row_range`](Self::row_range): `q_0` in units of cells with the cells' centres
    /// at whole numbers, and per axis the lower of the two centre indices around `q`.
    #[inline(always)]
    pub(super) fn row_origin<const D: usize>(&self, q: &[f64; D]) -> (f64, [i64; D]) {
        let t0 = q[0] * self.inv_cell - 0.5;
        let kq: [i64; D] = std::array::from_fn(|i| floor(q[i] * self.inv_cell - 0.5) as i64);
        (t0, kq)
    }

    /// For the row of cells at indices `k[1..]` (axis 0 runs along it): the squared distance
    /// `s` from `q` to the row's centres along the other axes, and `j2`, a whole number of
    /// squared cell sides at most that distance (the centres of a row `j_i` whole cells beyond
    /// the pair `kq_i, kq_i + 1` around `q` are at least `j_i` cells from `q` along axis `i`).
    #[inline(always)]
    pub(super) fn row_offset<const D: usize>(
        &self,
        q: &[f64; D],
        k: &[i64; D],
        kq: &[i64; D],
    ) -> (f64, usize) {
        let mut s = 0.0;
        let mut j2 = 0usize;
        for i in 1..D {
            let e = q[i] - (k[i] as f64 + 0.5) * self.cell;
            s += e * e;
            let j = if k[i] <= kq[i] {
                kq[i] - k[i]
            } else {
                k[i] - kq[i] - 1
            };
            j2 += (j * j) as usize;
        }
        (s, j2)
    }

    /// The range along axis 0 (in cells, as floats) of the cells within `cap` of the point
    /// (`q_0` its first coordinate, `t0` from [`row_origin`](Self::row_origin)) in a row at
    /// squared distance `s` from it along the other axes, `j2` squared cell sides at most (see
    /// [`row_offset`](Self::row_offset)); `None` when no cell of the row is that near.
    ///
    /// From the table of widths when there is one: integer arithmetic, so the row's range does
    /// not wait for the floating-point distance (which only the per-cell test uses) and the
    /// rows' set-up overlaps; no square root per row; a few cells more than the exact range,
    /// which the per-cell test rejects. Without a table, solved exactly.
    #[inline(always)]
    pub(super) fn row_range(&self, q0: f64, s: f64, t0: f64, j2: usize) -> Option<(f64, f64)> {
        if self.widths.is_empty() {
            let cap2 = self.cap * self.cap;
            (s < cap2).then(|| {
                let w = (cap2 - s).sqrt();
                (
                    ceil((q0 - w) * self.inv_cell - 0.5),
                    floor((q0 + w) * self.inv_cell - 0.5),
                )
            })
        } else {
            // `j2` is at most the row's squared distance from q in cells, so its width in the
            // table is at least the exact one.
            self.widths.get(j2).map(|&h| (ceil(t0 - h), floor(t0 + h)))
        }
    }

    /// The cells `a..=b` of a row's range (as floats from the range computation) clipped to
    /// `lo_0..=hi_0` and, for an insert beside a touched point, to its half-space.
    #[inline(always)]
    pub(super) fn clip_row<const D: usize>(
        &self,
        (a, b): (f64, f64),
        lo0: i64,
        hi0: i64,
        k: &[i64; D],
        side: Option<&Beside<D>>,
    ) -> (i64, i64) {
        let a = (a as i64).max(lo0);
        let b = (b as i64).min(hi0);
        match side {
            Some(side) => side.clip(k, self.cell, a, b),
            None => (a, b),
        }
    }
}

/// The box of cells an exclusive window insert of a point visits ([`Grid::window_box`]).
pub(super) struct WindowBox<const D: usize> {
    /// The point.
    q: [f64; D],
    /// Per axis, the cells `lo..=hi` whose centres lie within the cap of the point.
    lo: [i64; D],
    hi: [i64; D],
    /// The squared offsets of the box's columns ([`Grid::window_offsets`]).
    pub(super) x2: [f64; WINDOW],
    /// The box's first column in the map's rows, `lo_0 + half`.
    pub(super) start: usize,
    /// Cells in a row of the box.
    pub(super) cells: usize,
    cell: f64,
    /// [`Grid::window_skip`].
    skip: f64,
}

impl Grid {
    /// The box of an exclusive window insert of `q` (`Some(None)` when no cell of the map lies
    /// within the cap of it), or `None` when the map goes by rows instead: window inserts off,
    /// 4D and more, or a box wider than [`WINDOW`] cells along some axis.
    #[inline(always)]
    pub(super) fn window_box<const D: usize>(&self, q: &[f64; D]) -> Option<Option<WindowBox<D>>> {
        if !self.window_inserts || !(D == 2 || D == 3) {
            return None;
        }
        let Some((lo, hi)) = self.cells_near(q, q) else {
            return Some(None);
        };
        if (0..D).any(|i| hi[i] - lo[i] >= WINDOW as i64) {
            return None;
        }
        let cells = hi[0] - lo[0] + 1;
        Some(Some(WindowBox {
            q: *q,
            lo,
            hi,
            x2: self.window_offsets(lo[0] as f64 + 0.5, q[0], cells),
            start: (lo[0] + self.half) as usize,
            cells: cells as usize,
            cell: self.cell,
            skip: self.window_skip,
        }))
    }
}

impl<const D: usize> WindowBox<D> {
    /// The box's first cell index along axis `i`.
    #[inline(always)]
    pub(super) fn lo(&self, i: usize) -> i64 {
        self.lo[i]
    }

    /// Calls `f(map, s, key)` for the rows of the box with a cell within the cap, each given
    /// by its squared offset `s` from the point along axes 1 and 2 (below
    /// [`Grid::window_skip`]) and its key, the sum of `key(map, i, k_i)` over those axes; axis
    /// 1 fastest ([`Grid::window_row`] gives a row's values). In 3D both are sums of per-axis
    /// terms tabulated once.
    #[inline(always)]
    pub(super) fn rows<M>(
        &self,
        map: &mut M,
        key: impl Fn(&M, usize, i64) -> u64,
        mut f: impl FnMut(&mut M, f64, u64),
    ) {
        let (q, lo, hi, cell, skip) = (&self.q, &self.lo, &self.hi, self.cell, self.skip);
        // As `RowTables` and `Grid::row_offset`: a row's squared offset is then the same sum, to
        // the bits.
        let e2 = |i: usize, k: i64| {
            let e = q[i] - (k as f64 + 0.5) * cell;
            e * e
        };
        if D == 2 {
            // A 2D box's rows all come within about a cell of the cap: none is worth a test.
            for k in lo[1]..=hi[1] {
                let key = key(map, 1, k);
                f(map, e2(1, k), key);
            }
            return;
        }
        let mut t1 = [(0.0, 0); WINDOW];
        for (t, k) in t1.iter_mut().zip(lo[1]..=hi[1]) {
            *t = (e2(1, k), key(map, 1, k));
        }
        let n1 = (hi[1] - lo[1]) as usize + 1;
        for k2 in lo[2]..=hi[2] {
            let (s2, key2) = (e2(2, k2), key(map, 2, k2));
            for &(s1, key1) in &t1[..n1] {
                let s = s1 + s2;
                if s < skip {
                    f(map, s, key1 + key2);
                }
            }
        }
    }
}

/// What the rows of one insert need from each axis `1..D`, tabulated once per cell index along
/// that axis instead of once per row: the squared distance from the point to the cells'
/// centres along the axis and its whole-cell lower bound ([`Grid::row_offset`] sums these over
/// the axes, in the same order, so a row gets the same values bit for bit), and the axis's
/// term of the half-space offset of an insert beside a touched point ([`Beside::clip`]) and of
/// the map's key of the row; and for each entry `j2` of the table of widths, the range along
/// axis 0 a row with that lower bound covers ([`Grid::row_range`] and [`Grid::clip_row`]'s
/// clamp to the box, the same integers). A row then costs a few table reads and additions,
/// with no rounding of its own (the point's ball has far fewer distinct `j2` than rows).
pub(super) struct RowTables<const D: usize> {
    e2: [[f64; TABLE_ROWS]; D],
    j2: [[usize; TABLE_ROWS]; D],
    off: [[f64; TABLE_ROWS]; D],
    key: [[u64; TABLE_ROWS]; D],
    spans: [(i64, i64); TABLE_SPANS],
    /// Entries of `spans` filled: rows with a larger `j2` hold no cell within the cap.
    nspans: usize,
}

impl<const D: usize> RowTables<D> {
    /// Empty tables, to be [`fill`](Self::fill)ed.
    #[inline(always)]
    pub(super) fn new() -> Self {
        RowTables {
            e2: [[0.0; TABLE_ROWS]; D],
            j2: [[0; TABLE_ROWS]; D],
            off: [[0.0; TABLE_ROWS]; D],
            key: [[0; TABLE_ROWS]; D],
            spans: [(0, 0); TABLE_SPANS],
            nspans: 0,
        }
    }

    /// Fills the tables for an insert of `q` over the cells `lo..=hi` (`t0` and `kq` from
    /// [`Grid::row_origin`], `key` the map's term of a row's key per axis and cell index);
    /// `false` (tables unusable) when an axis spans more than [`TABLE_ROWS`] cells or the map's
    /// table of widths is empty or longer than [`TABLE_SPANS`].
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn fill(
        &mut self,
        g: &Grid,
        q: &[f64; D],
        lo: &[i64; D],
        hi: &[i64; D],
        (t0, kq): (f64, &[i64; D]),
        side: Option<&Beside<D>>,
        key: impl Fn(usize, i64) -> u64,
    ) -> bool {
        let n = g.widths.len();
        if n == 0 || n > TABLE_SPANS || (1..D).any(|i| hi[i] - lo[i] >= TABLE_ROWS as i64) {
            return false;
        }
        for (span, &h) in self.spans.iter_mut().zip(g.widths.iter()) {
            // `Grid::row_range`, then `Grid::clip_row`'s clamp.
            *span = (
                (ceil(t0 - h) as i64).max(lo[0]),
                (floor(t0 + h) as i64).min(hi[0]),
            );
        }
        self.nspans = n;
        for i in 1..D {
            for (m, k) in (lo[i]..=hi[i]).enumerate() {
                let e = q[i] - (k as f64 + 0.5) * g.cell;
                self.e2[i][m] = e * e;
                let j = if k <= kq[i] { kq[i] - k } else { k - kq[i] - 1 };
                self.j2[i][m] = (j * j) as usize;
                self.key[i][m] = key(i, k);
                if let Some(side) = side {
                    self.off[i][m] = side.term(i, k, g.cell);
                }
            }
        }
        true
    }

    /// Calls `row(s, key, (a, b))` for every row of a 3D insert over the cells `lo..=hi` that
    /// holds a cell within the cap (in the half-space `side` if given), in the odometer's
    /// order (axis 1 fastest), with the values [`row_offset`](Self::row_offset) and
    /// [`row_span`](Self::row_span) give it. As two nested loops, the outer axis's terms are
    /// read once per plane of rows; in 3D a row's sums have two terms, so adding the outer
    /// one second is the odometer's sum bit for bit.
    #[inline(always)]
    pub(super) fn each_row_3d(
        &self,
        lo: &[i64; D],
        hi: &[i64; D],
        side: Option<&Beside<D>>,
        mut row: impl FnMut(f64, u64, (i64, i64)),
    ) {
        debug_assert_eq!(D, 3);
        // `fill` checked both spans against the tables; the `min`s let the compiler see it.
        let n1 = ((hi[1] - lo[1] + 1) as usize).min(TABLE_ROWS);
        let n2 = ((hi[2] - lo[2] + 1) as usize).min(TABLE_ROWS);
        let nspans = self.nspans.min(TABLE_SPANS);
        for m2 in 0..n2 {
            let j2_out = self.j2[2][m2];
            if j2_out >= nspans {
                continue;
            }
            let (e2_out, key_out, off_out) = (self.e2[2][m2], self.key[2][m2], self.off[2][m2]);
            for m1 in 0..n1 {
                let j2 = self.j2[1][m1] + j2_out;
                if j2 >= nspans {
                    continue;
                }
                let (a, b) = self.spans[j2];
                let (a, b) = match side {
                    Some(side) => side.clip_at(self.off[1][m1] + off_out, a, b),
                    None => (a, b),
                };
                if a <= b {
                    row(self.e2[1][m1] + e2_out, self.key[1][m1] + key_out, (a, b));
                }
            }
        }
    }

    /// [`Grid::row_offset`] of the row at cell indices `k[1..]` (the cells from `lo`), and the
    /// map's key of the row.
    #[inline(always)]
    pub(super) fn row_offset(&self, k: &[i64; D], lo: &[i64; D]) -> (f64, usize, u64) {
        let mut s = 0.0;
        let mut j2 = 0usize;
        let mut key = 0u64;
        for i in 1..D {
            let m = (k[i] - lo[i]) as usize;
            s += self.e2[i][m];
            j2 += self.j2[i][m];
            key += self.key[i][m];
        }
        (s, j2, key)
    }

    /// The cells `a..=b` along axis 0 of the row at cell indices `k[1..]` (the cells from
    /// `lo`) with offset lower bound `j2` ([`row_offset`](Self::row_offset)): [`Grid::row_range`]
    /// and [`Grid::clip_row`] from the tables; `None` when no cell of the row is within the cap.
    #[inline(always)]
    pub(super) fn row_span(
        &self,
        j2: usize,
        k: &[i64; D],
        lo: &[i64; D],
        side: Option<&Beside<D>>,
    ) -> Option<(i64, i64)> {
        if j2 >= self.nspans {
            return None;
        }
        let (a, b) = self.spans[j2];
        Some(match side {
            Some(side) => {
                let mut off = 0.0;
                for i in 1..D {
                    off += self.off[i][(k[i] - lo[i]) as usize];
                }
                side.clip_at(off, a, b)
            }
            None => (a, b),
        })
    }
}
