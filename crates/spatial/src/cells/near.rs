//! The near cache: the cells around a query point, located once ([`Near`]), and the
//! word-wide bit tricks on its rows of cell bytes (kind bits, squared-distance classes,
//! counting, the lowest id among equally near cells). The animat model makes one per turn for
//! the acting animat; every query of the turn about its 5 x 5 neighbourhood is then a few
//! word operations.
//!
//! Invariants: [`Near::rows`] holds the cell bytes of the `NEAR_ROWS` x 8 cells from
//! `(x - NEAR_HALF, y - NEAR_HALF)` as they were when read, so a `Near` must be dropped (or
//! made again) once the index changes; it borrows the index, so the borrow checker enforces
//! that.

use super::{KIND_MASK, Window};
use crate::plane::Pos;

/// Half-side of the square of cells [`Near::rows`] holds.
pub const NEAR_HALF: i64 = 2;

/// Rows of [`Near::rows`].
pub const NEAR_ROWS: usize = 2 * NEAR_HALF as usize + 1;

/// The least half-side of the window a [`Near`] is made from: its rows read cells
/// `x - NEAR_HALF ..= x - NEAR_HALF + 7`, which the window must hold.
pub const NEAR_WINDOW_MIN: i64 = if NEAR_HALF > 7 - NEAR_HALF {
    NEAR_HALF
} else {
    7 - NEAR_HALF
};

/// The cells around a query point: a window and, read on first use, the row words of its
/// `NEAR_ROWS` x `NEAR_ROWS` neighbourhood.
pub struct Near<'a> {
    /// Window of half-side at least [`NEAR_WINDOW_MIN`] around the point; `None` when the
    /// caller does not use the index here (then every query goes elsewhere).
    w: Option<Window<'a>>,
    /// The cell bytes of the `NEAR_ROWS` rows around the point, read on first use.
    rows: Option<[u64; NEAR_ROWS]>,
}

impl<'a> Near<'a> {
    /// The near cache over `w`, a window of half-side at least [`NEAR_WINDOW_MIN`] (from
    /// [`CellIndex::window`](super::CellIndex::window)), or an empty one for `None`.
    #[inline]
    pub fn new(w: Option<Window<'a>>) -> Self {
        Near { w, rows: None }
    }

    /// The window, if present.
    #[inline]
    pub fn window(&self) -> Option<&Window<'a>> {
        self.w.as_ref()
    }

    /// Kind bytes of rows `y - 2 ..= y + 2` around `p = [x, y]`, each holding cells
    /// `x - 2 ..= x + 5` as bytes 0..8 (byte `dx + 2` is cell `x + dx`). The window must be
    /// present.
    #[inline]
    pub fn rows(&mut self, p: Pos) -> &[u64; NEAR_ROWS] {
        self.parts(p).expect("rows need the window").1
    }

    /// The window and the row words ([`Near::rows`]), if the window is present.
    #[inline]
    pub fn parts(&mut self, p: Pos) -> Option<(&Window<'_>, &[u64; NEAR_ROWS])> {
        let w = self.w.as_ref()?;
        let rows = self
            .rows
            .get_or_insert_with(|| w.rows::<NEAR_ROWS>(p[0] - NEAR_HALF, p[1] - NEAR_HALF));
        Some((w, rows))
    }
}

/// The kind byte of cell `(x + dx, y + dy)` from [`Near::rows`] (`|dx|, |dy| <= 2`).
#[inline(always)]
pub fn row_cell(rows: &[u64; NEAR_ROWS], dx: i64, dy: i64) -> u8 {
    row_byte(rows, dx, dy) & KIND_MASK
}

/// The whole cell byte (kind and id bucket) of cell `(x + dx, y + dy)` from [`Near::rows`].
#[inline(always)]
pub fn row_byte(rows: &[u64; NEAR_ROWS], dx: i64, dy: i64) -> u8 {
    (rows[(dy + NEAR_HALF) as usize] >> (8 * (dx + NEAR_HALF))) as u8
}

/// The cells of [`Near::rows`] at squared distance `lo ..= hi` from the centre (the
/// `NEAR_ROWS` x `NEAR_ROWS` square around it), as bit 0 of their bytes.
pub const fn disc_mask(lo: i64, hi: i64) -> [u64; NEAR_ROWS] {
    let mut m = [0u64; NEAR_ROWS];
    let mut dy = -NEAR_HALF;
    while dy <= NEAR_HALF {
        let mut dx = -NEAR_HALF;
        while dx <= NEAR_HALF {
            let d2 = dx * dx + dy * dy;
            if lo <= d2 && d2 <= hi {
                m[(dy + NEAR_HALF) as usize] |= 1 << (8 * (dx + NEAR_HALF));
            }
            dx += 1;
        }
        dy += 1;
    }
    m
}

/// The cells of rings 1 and 2 by squared distance, nearest first: ring 1 is `d2` 1 and 2,
/// ring 2 is `d2` 4, 5 and 8.
pub const RING_CLASSES: [[u64; NEAR_ROWS]; 5] = [
    disc_mask(1, 1),
    disc_mask(2, 2),
    disc_mask(4, 4),
    disc_mask(5, 5),
    disc_mask(8, 8),
];

/// Bit 0 of each byte of [`Near::rows`] whose cell holds kind byte `kb` ([`KIND_A`](super::KIND_A):
/// bit 0 of the byte; [`KIND_B`](super::KIND_B): bit 1).
#[inline(always)]
pub fn kind_bits(rows: &[u64; NEAR_ROWS], kb: u8) -> [u64; NEAR_ROWS] {
    let shift = u32::from(kb - 1);
    rows.map(|r| (r >> shift) & 0x0101_0101_0101_0101)
}

/// How many cells of `bits` (from [`kind_bits`]) lie in `class` (at most one bit per byte and
/// `NEAR_ROWS` rows: see [`byte_sum`]).
#[inline(always)]
pub fn count_in(bits: &[u64; NEAR_ROWS], class: &[u64; NEAR_ROWS]) -> u64 {
    let sum = bits
        .iter()
        .zip(class)
        .fold(0u64, |acc, (&b, &m)| acc + (b & m));
    byte_sum(sum)
}

/// The sum of the 8 bytes of `x`, when it is below 256 (true of a sum of at most `NEAR_ROWS`
/// row words with at most one bit per byte): the multiplication adds every byte into the top
/// byte.
#[inline(always)]
pub fn byte_sum(x: u64) -> u64 {
    x.wrapping_mul(0x0101_0101_0101_0101) >> 56
}

/// The cell of `bits` in `class` with the lowest id (`n` of them, `n >= 1`), around `p`:
/// the lowest id bucket of the cell bytes in `rows` decides, and ids are read only when
/// several cells share it.
#[inline]
pub fn lowest_in(
    bits: &[u64; NEAR_ROWS],
    class: &[u64; NEAR_ROWS],
    n: u64,
    p: Pos,
    rows: &[u64; NEAR_ROWS],
    w: &Window<'_>,
) -> Pos {
    // (dx, dy, bucket) of each candidate; a class has at most 8 cells.
    let mut cand = [(0i64, 0i64, 0u8); 8];
    let mut m = 0;
    for (r, (&b, &c)) in bits.iter().zip(class).enumerate() {
        let mut hits = b & c;
        while hits != 0 {
            let dx = i64::from(hits.trailing_zeros() / 8) - NEAR_HALF;
            let dy = r as i64 - NEAR_HALF;
            hits &= hits - 1;
            cand[m] = (dx, dy, row_byte(rows, dx, dy) >> 2);
            m += 1;
        }
    }
    debug_assert_eq!(m as u64, n);
    let cand = &cand[..m];
    let low = cand.iter().map(|c| c.2).min().unwrap_or(0);
    let mut best: Option<(Pos, Option<u64>)> = None;
    for &(dx, dy, b) in cand {
        if b != low {
            continue;
        }
        let c = [p[0] + dx, p[1] + dy];
        best = match best {
            None => Some((c, None)),
            Some((bc, bid)) => {
                let bi = bid.unwrap_or_else(|| w.id(bc[0], bc[1]));
                let id = w.id(c[0], c[1]);
                Some(if id < bi {
                    (c, Some(id))
                } else {
                    (bc, Some(bi))
                })
            }
        };
    }
    best.map_or(p, |(c, _)| c)
}
