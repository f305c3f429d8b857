//! The half-space of cells a DLA particle's insert can lower, given the particle it touched
//! (see [`Beside`]).

use crate::round::{ceil, floor};

/// The cells a new point `q` can lower when it touches a point `p` inserted before it (DLA's
/// stuck particle and the one it stuck to): those nearer `q` than `p`, the half-space
/// `(c - m) . w < MARGIN` with `m` the midpoint and `w = p - q`. Every other cell already holds
/// at most its distance to `p` (quantised down), which is at most its distance to `q`, so an
/// insert that skips them leaves the map, and a sparse map's blocks, exactly as a full insert
/// would: about half the cells and rows of the ball for the same result. The argument holds
/// whatever `|p - q|` is (DLA's noise reduction stores `q` closer than 1 to `p`); the half-space
/// is used between half a diameter and two, where the bound `slack` holds.
///
/// `MARGIN` (1e-6 squared diameters, far above the rounding of the centres' coordinates) keeps
/// every skipped cell strictly nearer `p`, so the rounding of the distances cannot make `q`'s
/// quantised value the lower one.
#[derive(Debug, Clone, Copy)]
pub struct Beside<const D: usize> {
    mid: [f64; D],
    w: [f64; D],
    /// A bound of `|c_0 - m_0|` over the cells an insert visits.
    slack: f64,
    /// The boundary along axis 0 as a linear function of a row's offset `off` (in cells,
    /// centres at whole numbers): `at - off * slope`, when `|w_0| > 1e-3` (see `clip_at`).
    at: f64,
    slope: f64,
}

impl<const D: usize> Beside<D> {
    const MARGIN: f64 = 1e-6;

    /// The half-space for `q` touching `p`; `None` (insert every cell) unless the two are
    /// finite and between half a diameter and two apart.
    pub(super) fn new(q: &[f64; D], p: &[f64; D], cap: f64, cell: f64) -> Option<Self> {
        let w: [f64; D] = std::array::from_fn(|i| p[i] - q[i]);
        let w2: f64 = w.iter().map(|x| x * x).sum();
        (0.25..=4.0).contains(&w2).then(|| {
            let mid: [f64; D] = std::array::from_fn(|i| 0.5 * (p[i] + q[i]));
            let inv_cell = 1.0 / cell;
            Beside {
                mid,
                w,
                slack: cap + 2.0 * cell + 2.0,
                at: (mid[0] + Self::MARGIN / w[0]) * inv_cell - 0.5,
                slope: inv_cell / w[0],
            }
        })
    }

    /// Narrows the cell range `a..=b` along axis 0 of the row at cell indices `k[1..]` to the
    /// half-space (an empty range when none of it is inside).
    #[inline(always)]
    pub(super) fn clip(&self, k: &[i64; D], cell: f64, a: i64, b: i64) -> (i64, i64) {
        let mut off = 0.0;
        for (i, &k) in k.iter().enumerate().skip(1) {
            off += self.term(i, k, cell);
        }
        self.clip_at(off, a, b)
    }

    /// The term of axis `i >= 1` in the offset of the rows at cell index `k` along it: what
    /// [`clip`](Self::clip) sums over the axes, for an insert that tabulates it per axis.
    #[inline(always)]
    pub(super) fn term(&self, i: usize, k: i64, cell: f64) -> f64 {
        ((k as f64 + 0.5) * cell - self.mid[i]) * self.w[i]
    }

    /// [`clip`](Self::clip) given the row's offset `off`, the sum of its [`term`](Self::term)s
    /// over axes `1..D` in order.
    #[inline(always)]
    pub(super) fn clip_at(&self, off: f64, a: i64, b: i64) -> (i64, i64) {
        // Keep the cells with (c_0 - m_0) w_0 < MARGIN - off; a cell on the boundary is kept.
        let w0 = self.w[0];
        if w0.abs() > 1e-3 {
            // `(m_0 + (MARGIN - off) / w_0) / c - 1/2`, expanded so that a row costs a
            // multiplication, not a division: it differs from that by a few ulps of the cell
            // index, far inside `MARGIN`, so every cell it drops is still strictly nearer `p`.
            let x = self.at - off * self.slope;
            if w0 > 0.0 {
                (a, b.min(floor(x) as i64))
            } else {
                (a.max(ceil(x) as i64), b)
            }
        } else if Self::MARGIN - off + 1e-3 * self.slack > 0.0 {
            (a, b)
        } else {
            (a, a - 1)
        }
    }
}
