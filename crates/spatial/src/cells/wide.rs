//! Wide queries over the cell index: the nearest item of a kind within a squared radius, and
//! whether at least `n` items lie within one, answered exactly with the grid-box search of
//! Hawick, James & Scogings (2006), "Grid-Boxing for Spatial Simulation Performance
//! Optimisation", section II.B: the boxes of side `A` in rings outward from the query's box,
//! stopping once no nearer item can exist. A box's items are read from the index
//! ([`CellIndex::scan_rect`]), which skips empty tiles and blocks, so no list per box has to
//! be kept up to date as the items move: the box side is a parameter of the query, not of the
//! index. The animat model asks these when the cells around an animat cannot settle a query
//! (a radius beyond its window, few animats of the wanted kind nearby, or an animat too near
//! the `i64` limits for a window).
//!
//! Invariants: every cell within the radius is examined unless the answer is already known
//! (a count reached, or every remaining cell farther than the best found), the query's own
//! cell is never counted, and the nearest is the minimum of `(squared distance, id)`, so the
//! answers equal the exhaustive scan's for every box side (`tests/cells_props.rs`).

use super::CellIndex;
use crate::plane::Pos;
use std::ops::ControlFlow;

/// The rings of grid boxes around a query point, as the search visits them.
struct Rings {
    /// Box side.
    a: i128,
    /// The query point and its box.
    p: [i128; 2],
    b: [i128; 2],
    /// Cells from the point to the nearest edge of its box, plus one: every cell of ring
    /// `k >= 1` is at least `(k - 1) a + edge` away along some axis.
    edge: i128,
}

impl Rings {
    #[inline]
    fn new(a: i64, p: Pos) -> Self {
        let a = i128::from(a);
        let p = [i128::from(p[0]), i128::from(p[1])];
        let b = [p[0].div_euclid(a), p[1].div_euclid(a)];
        let o = [p[0] - b[0] * a, p[1] - b[1] * a];
        Rings {
            a,
            p,
            b,
            edge: (o[0] + 1).min(a - o[0]).min(o[1] + 1).min(a - o[1]),
        }
    }

    /// Whether ring `k` can hold a cell within squared distance `limit`.
    #[inline]
    fn reaches(&self, k: i128, limit: u64) -> bool {
        if k == 0 {
            return true;
        }
        let d = (k - 1) * self.a + self.edge;
        d * d <= i128::from(limit)
    }

    /// The last ring that meets the square of half-side `r` around the point.
    #[inline]
    fn last(&self, r: i128) -> i128 {
        let lo = [
            (self.p[0] - r).div_euclid(self.a),
            (self.p[1] - r).div_euclid(self.a),
        ];
        let hi = [
            (self.p[0] + r).div_euclid(self.a),
            (self.p[1] + r).div_euclid(self.a),
        ];
        (self.b[0] - lo[0])
            .max(hi[0] - self.b[0])
            .max(self.b[1] - lo[1])
            .max(hi[1] - self.b[1])
    }

    /// The cells of box `(dx, dy)` (in boxes from the point's) within the square of half-side
    /// `r` around the point, as `i64` ranges, or `None` when they are none.
    #[inline]
    fn cells(&self, dx: i128, dy: i128, r: i128) -> Option<([i64; 2], [i64; 2])> {
        let axis = |b: i128, p: i128| -> Option<[i64; 2]> {
            let lo = (b * self.a).max(p - r).max(i128::from(i64::MIN));
            let hi = ((b + 1) * self.a - 1).min(p + r).min(i128::from(i64::MAX));
            (lo <= hi).then_some([lo as i64, hi as i64])
        };
        Some((
            axis(self.b[0] + dx, self.p[0])?,
            axis(self.b[1] + dy, self.p[1])?,
        ))
    }

    /// Visits the boxes of ring `k` (in a fixed order) until `visit` breaks.
    #[inline]
    fn ring(
        &self,
        k: i128,
        mut visit: impl FnMut(i128, i128) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if k == 0 {
            return visit(0, 0);
        }
        for dx in -k..=k {
            visit(dx, -k)?;
            visit(dx, k)?;
        }
        for dy in (-k + 1)..k {
            visit(-k, dy)?;
            visit(k, dy)?;
        }
        ControlFlow::Continue(())
    }
}

/// Squared distance from `p` to `(x, y)`, exact (it can exceed every `u64` limit).
#[inline]
fn dist2(p: Pos, x: i64, y: i64) -> u128 {
    let dx = u128::from(p[0].abs_diff(x));
    let dy = u128::from(p[1].abs_diff(y));
    dx * dx + dy * dy
}

impl CellIndex {
    /// Whether visiting the boxes ring by ring up to ring `last` would take more box visits
    /// than scanning the square once through the tiles in use.
    fn rings_too_many(&self, last: i128) -> bool {
        let boxes = (2 * last + 1).saturating_mul(2 * last + 1);
        boxes > 4 * (self.tiles_in_use() as i128 + 1)
    }

    /// The cell of the nearest item whose kind meets `kinds` (bit 0 [`KIND_A`](super::KIND_A),
    /// bit 1 [`KIND_B`](super::KIND_B)) within squared distance `r2` of `p`, other than the
    /// one on `p`: the minimum of `(squared distance, id)`. The search visits grid boxes of
    /// side `side` (`>= 1`; `i64::MAX` for one box holding the plane), which changes its
    /// speed only. Also returns the number of cells examined (a work counter).
    #[inline]
    pub fn nearest_within(&self, p: Pos, kinds: u8, r2: u64, side: i64) -> (Option<Pos>, u64) {
        let rings = Rings::new(side, p);
        // Best as (d2, cell, id bucket, id once read); buckets settle most ties without ids.
        let mut best: Option<(u64, Pos, u8, Option<u64>)> = None;
        let mut limit = r2;
        let mut evals = 0;
        let cells = self;
        let mut look = |x: i64, y: i64, byte: u8, limit: &mut u64| {
            if [x, y] == p {
                return;
            }
            evals += 1;
            // Within the limit, so below 2^64.
            let Some(d2) = u64::try_from(dist2(p, x, y)).ok().filter(|&d| d <= *limit) else {
                return;
            };
            let bucket = byte >> 2;
            let better = match &mut best {
                None => true,
                Some((bd, bp, bb, bid)) => {
                    d2 < *bd
                        || (d2 == *bd && bucket < *bb)
                        || (d2 == *bd && bucket == *bb && {
                            let bi = *bid.get_or_insert_with(|| cells.id(*bp));
                            cells.id([x, y]) < bi
                        })
                }
            };
            if better {
                best = Some((d2, [x, y], bucket, None));
                *limit = d2;
            }
        };
        let mut k = 0;
        loop {
            let r = i128::from(limit.isqrt());
            let last = rings.last(r);
            if k > last || !rings.reaches(k, limit) {
                break;
            }
            if self.rings_too_many(last) {
                // One pass over the whole square; boxes already visited are seen again, which
                // cannot change a minimum.
                let (xs, ys) = square(p, r);
                let _ = cells.scan_rect(xs, ys, kinds, |x, y, b| {
                    look(x, y, b, &mut limit);
                    ControlFlow::Continue(())
                });
                break;
            }
            let _ = rings.ring(k, |dx, dy| {
                // The square shrinks as better items are found.
                let r = i128::from(limit.isqrt());
                if let Some((xs, ys)) = rings.cells(dx, dy, r) {
                    let _ = cells.scan_rect(xs, ys, kinds, |x, y, b| {
                        look(x, y, b, &mut limit);
                        ControlFlow::Continue(())
                    });
                }
                ControlFlow::Continue(())
            });
            k += 1;
        }
        (best.map(|(_, c, _, _)| c), evals)
    }

    /// Whether at least `n` items whose kind meets `kinds` lie within squared distance `r2` of
    /// `p`, the one on `p` not counted; grid boxes of side `side` as for
    /// [`CellIndex::nearest_within`]. Stops as soon as `n` are found. Also returns the number
    /// of cells examined.
    #[inline]
    pub fn at_least_within(&self, p: Pos, kinds: u8, r2: u64, n: usize, side: i64) -> (bool, u64) {
        if n == 0 {
            return (true, 0);
        }
        let rings = Rings::new(side, p);
        let r = i128::from(r2.isqrt());
        let last = rings.last(r);
        let mut count = 0;
        let mut evals = 0;
        let mut look = |x: i64, y: i64, _: u8| {
            if [x, y] != p {
                evals += 1;
                if dist2(p, x, y) <= u128::from(r2) {
                    count += 1;
                    if count >= n {
                        return ControlFlow::Break(());
                    }
                }
            }
            ControlFlow::Continue(())
        };
        let _ = if self.rings_too_many(last) {
            let (xs, ys) = square(p, r);
            self.scan_rect(xs, ys, kinds, &mut look)
        } else {
            let mut k = 0;
            loop {
                if k > last || !rings.reaches(k, r2) {
                    break ControlFlow::Continue(());
                }
                let done = rings.ring(k, |dx, dy| match rings.cells(dx, dy, r) {
                    Some((xs, ys)) => self.scan_rect(xs, ys, kinds, &mut look),
                    None => ControlFlow::Continue(()),
                });
                if done.is_break() {
                    break done;
                }
                k += 1;
            }
        };
        (count >= n, evals)
    }
}

/// The square of half-side `r` around `p`, clamped to the `i64` plane.
#[inline]
fn square(p: Pos, r: i128) -> ([i64; 2], [i64; 2]) {
    let axis = |c: i64| {
        let c = i128::from(c);
        [
            (c - r).max(i128::from(i64::MIN)) as i64,
            (c + r).min(i128::from(i64::MAX)) as i64,
        ]
    };
    (axis(p[0]), axis(p[1]))
}
