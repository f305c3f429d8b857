//! Exact searches over the rings of cells around a point inside a [`Window`]: the nearest item
//! of a kind ([`Window::nearest_in_rings`]) and whether enough items of a kind lie within a
//! radius ([`Window::count_in_rings`]). Ring `k` is the cells at Chebyshev distance `k`; the
//! animat model scans rings 1 to 8 (its window's half-side) before it asks the wide queries.
//!
//! Invariants: rings are visited outward in a fixed order, the nearest is the minimum of
//! `(squared distance, id)` (the id bucket of the cell byte first, the ids only when buckets
//! tie), and a search reports itself settled only when no cell beyond its last ring could
//! change the answer.

use super::{KIND_MASK, Window};
use crate::plane::Pos;

/// Visits the cells of ring `k >= 1` (Chebyshev distance `k`) as offsets `(dx, dy)` in a fixed
/// order (the bottom and top rows pairwise by `dx`, then the left and right columns pairwise by
/// `dy`) until `visit` returns `true`; returns whether it did.
#[inline(always)]
pub fn ring_until(k: i64, mut visit: impl FnMut(i64, i64) -> bool) -> bool {
    for dx in -k..=k {
        if visit(dx, -k) || visit(dx, k) {
            return true;
        }
    }
    for dy in (-k + 1)..k {
        if visit(-k, dy) || visit(k, dy) {
            return true;
        }
    }
    false
}

/// The answer of [`Window::nearest_in_rings`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RingNearest {
    /// The nearest item found in the rings scanned (ties: lower id).
    pub found: Option<Pos>,
    /// Whether `found` is the answer for the whole radius: no cell beyond the last ring
    /// scanned can be nearer, or lie within the radius at all.
    pub settled: bool,
    /// Cells of the wanted kind examined (a work counter).
    pub evals: u64,
}

impl Window<'_> {
    /// The nearest item of kind byte `kb` within squared distance `r2` of `p` among rings
    /// `k_first ..= k_max` (`1 <= k_first`, `k_max` at most the window's half-side around `p`),
    /// the minimum of `(squared distance, id)`. Stops after the first ring beyond which no cell
    /// can be strictly nearer than the best found, or within `r2`; `settled` then tells
    /// that the answer holds for the whole plane. The rings below `k_first` are the caller's
    /// (the animat model settles rings 1 and 2 from the near cache's row words first).
    #[inline]
    pub fn nearest_in_rings(
        &self,
        p: Pos,
        kb: u8,
        r2: u64,
        k_first: i64,
        k_max: i64,
    ) -> RingNearest {
        let [x, y] = p;
        let mut evals = 0;
        // Best as (d2, position, id bucket, id once read): a tie of distances goes to the
        // lower bucket, and ids (in a larger array that is rarely in cache) are read only when
        // the buckets are equal too.
        type Best = Option<(u64, Pos, u8, Option<u64>)>;
        let mut best: Best = None;
        let mut look = |dx: i64, dy: i64, best: &mut Best| {
            let byte = self.byte(x + dx, y + dy);
            if byte & KIND_MASK == kb {
                evals += 1;
                let d2 = (dx * dx + dy * dy) as u64;
                let c = [x + dx, y + dy];
                let cb = byte >> 2;
                match best {
                    _ if d2 > r2 => {}
                    None => *best = Some((d2, c, cb, None)),
                    Some((bd, bp, bb, bid)) => {
                        if d2 < *bd || (d2 == *bd && cb < *bb) {
                            *best = Some((d2, c, cb, None));
                        } else if d2 == *bd && cb == *bb {
                            let bi = *bid.get_or_insert_with(|| self.id(bp[0], bp[1]));
                            let id = self.id(c[0], c[1]);
                            if id < bi {
                                *best = Some((d2, c, cb, Some(id)));
                            }
                        }
                    }
                }
            }
        };
        for k in k_first..=k_max {
            ring_until(k, |dx, dy| {
                look(dx, dy, &mut best);
                false
            });
            // Every cell beyond ring k is at least k + 1 away: a best strictly nearer than
            // that is final (an equally near one could still win on id).
            let next = ((k + 1) * (k + 1)) as u64;
            if best.is_some_and(|(bd, _, _, _)| bd < next) || next > r2 {
                return RingNearest {
                    found: best.map(|(_, p, _, _)| p),
                    settled: true,
                    evals,
                };
            }
        }
        RingNearest {
            found: best.map(|(_, p, _, _)| p),
            settled: false,
            evals,
        }
    }

    /// Counts the items of kind byte `kb` within squared distance `r2` of `p` in rings
    /// `1 ..= k_max` (`k_max` at most the window's half-side around `p`), stopping as soon as
    /// there are `n`. Returns whether `n` were found and the count reached.
    #[inline]
    pub fn count_in_rings(&self, p: Pos, kb: u8, r2: u64, n: usize, k_max: i64) -> (bool, usize) {
        let [x, y] = p;
        let mut count = 0usize;
        let mut look = |dx: i64, dy: i64| -> bool {
            if self.at(x + dx, y + dy) == kb && (dx * dx + dy * dy) as u64 <= r2 {
                count += 1;
            }
            count >= n
        };
        let mut found = false;
        for k in 1..=k_max {
            if ring_until(k, &mut look) {
                found = true;
                break;
            }
        }
        (found, count)
    }
}
