//! The queries of a [`PlaneGrid`]: nearest of a kind, counts (capped), existence and the
//! whole neighbourhood within a radius, and the accessors of their work counters.
//!
//! Every query is a visitor driven over the boxes by one search: the exhaustive scan of the
//! single list in [`BoxSize::None`](super::BoxSize::None) mode, the ring search outward from
//! the query's box otherwise (with a one-pass fallback over the occupied boxes). Invariant:
//! every box that can hold an item within the current limit is visited, and every item is
//! judged by the same exact integer test (`Probe::test`), so the answers equal the exhaustive
//! scan's for every box size (see the [module documentation](super) for the proof).

use std::ops::ControlFlow;
use std::sync::atomic::Ordering;

use super::grid::{Entry, PlaneGrid};
use super::{Pos, SearchStats};

/// The per-item test shared by every query and both modes: per-axis early exit against
/// `lim_r = isqrt(limit)`, then (counted) the full squared distance. Returns `None` when the
/// item is certainly farther than `limit`; otherwise the exact squared distance (which the
/// caller still compares with `limit`).
#[inline(always)]
fn item_dist2(p: Pos, q: Pos, lim_r: u64, evals: &mut u64) -> Option<u64> {
    let dx = p[0].abs_diff(q[0]);
    if dx > lim_r {
        return None;
    }
    let dy = p[1].abs_diff(q[1]);
    if dy > lim_r {
        return None;
    }
    *evals += 1;
    // dx, dy <= isqrt(u64::MAX) = 2^32 - 1, so each square fits in u64; the sum may not, and
    // then it is larger than any u64 limit.
    (dx * dx).checked_add(dy * dy)
}

/// What every query carries: the query point, the filter, the current inclusive limit on the
/// squared distance (with its integer square root for the per-axis test) and the work tally.
struct Probe<K> {
    p: Pos,
    kind: Option<K>,
    exclude: Option<u64>,
    limit: u64,
    lim_r: u64,
    evals: u64,
    scanned: u64,
}

impl<K: Copy + Eq> Probe<K> {
    fn new(p: Pos, kind: Option<K>, r2: u64, exclude: Option<u64>) -> Self {
        Probe {
            p,
            kind,
            exclude,
            limit: r2,
            lim_r: r2.isqrt(),
            evals: 0,
            scanned: 0,
        }
    }

    /// The per-item test: kind filter, exclusion, per-axis early exit, then the counted full
    /// squared distance. `Some(d2)` exactly when the item qualifies, `d2 <= limit`.
    #[inline(always)]
    fn test(&mut self, e: &Entry<K>) -> Option<u64> {
        self.scanned += 1;
        if !self.kind.is_none_or(|k| e.kind == k) || self.exclude == Some(e.id) {
            return None;
        }
        item_dist2(self.p, e.pos, self.lim_r, &mut self.evals).filter(|&d2| d2 <= self.limit)
    }
}

/// A query as the search driver sees it: its [`Probe`] (whose limit says which boxes and rings
/// can still matter) and what to do with a box's items.
trait Visitor<K> {
    /// The query's probe (current limit and work tally).
    fn probe(&self) -> &Probe<K>;
    /// Examines the items of one box; `Break` ends the search (answer known).
    fn visit(&mut self, entries: &[Entry<K>]) -> ControlFlow<()>;
}

/// Nearest item by the total order `(dist2, id)` among those with `dist2 <= r2`; the limit
/// shrinks to the best distance found (never below it, so equally near items are still seen).
struct NearestVisitor<K> {
    probe: Probe<K>,
    best: Option<(u64, u64)>,
}

impl<K: Copy + Eq> Visitor<K> for NearestVisitor<K> {
    fn probe(&self) -> &Probe<K> {
        &self.probe
    }

    fn visit(&mut self, entries: &[Entry<K>]) -> ControlFlow<()> {
        for e in entries {
            let Some(d2) = self.probe.test(e) else {
                continue;
            };
            let better = match self.best {
                None => true,
                Some((bid, bd2)) => d2 < bd2 || (d2 == bd2 && e.id < bid),
            };
            if better {
                self.best = Some((e.id, d2));
                if d2 < self.probe.limit {
                    self.probe.limit = d2;
                    self.probe.lim_r = d2.isqrt();
                }
            }
        }
        ControlFlow::Continue(())
    }
}

/// Counts items with `dist2 <= r2`, stopping once the count reaches `cap`.
struct CountVisitor<K> {
    probe: Probe<K>,
    count: usize,
    cap: usize,
}

impl<K: Copy + Eq> Visitor<K> for CountVisitor<K> {
    fn probe(&self) -> &Probe<K> {
        &self.probe
    }

    fn visit(&mut self, entries: &[Entry<K>]) -> ControlFlow<()> {
        for e in entries {
            if self.probe.test(e).is_some() {
                self.count += 1;
                if self.count >= self.cap {
                    return ControlFlow::Break(());
                }
            }
        }
        ControlFlow::Continue(())
    }
}

/// Collects `(id, dist2)` of every item with `dist2 <= r2`.
struct CollectVisitor<K> {
    probe: Probe<K>,
    found: Vec<(u64, u64)>,
}

impl<K: Copy + Eq> Visitor<K> for CollectVisitor<K> {
    fn probe(&self) -> &Probe<K> {
        &self.probe
    }

    fn visit(&mut self, entries: &[Entry<K>]) -> ControlFlow<()> {
        for e in entries {
            if let Some(d2) = self.probe.test(e) {
                self.found.push((e.id, d2));
            }
        }
        ControlFlow::Continue(())
    }
}

/// Geometry of a query point relative to its own box, in `i128` so that no box arithmetic can
/// overflow anywhere on the `i64` plane.
#[derive(Clone, Copy)]
struct QueryBox {
    a: i128,
    bx: i128,
    by: i128,
    ox: i128,
    oy: i128,
}

impl QueryBox {
    fn new(a: i64, p: Pos) -> Self {
        let a = i128::from(a);
        let (px, py) = (i128::from(p[0]), i128::from(p[1]));
        let bx = px.div_euclid(a);
        let by = py.div_euclid(a);
        QueryBox {
            a,
            bx,
            by,
            ox: px - bx * a,
            oy: py - by * a,
        }
    }

    /// Cells between the query point and the nearest cell of a box `d` boxes away along one
    /// axis (`o` = the point's offset inside its own box on that axis).
    #[inline]
    fn gap(&self, d: i128, o: i128) -> i128 {
        if d > 0 {
            d * self.a - o
        } else if d < 0 {
            (-d - 1) * self.a + o + 1
        } else {
            0
        }
    }

    /// The smallest distance, along its nearest axis, from the point to any cell of ring 1:
    /// ring `k >= 1` is at least `(k - 1) A + edge` away.
    fn edge(&self) -> i128 {
        (self.ox + 1)
            .min(self.a - self.ox)
            .min(self.oy + 1)
            .min(self.a - self.oy)
    }

    /// Whether the box at offset `(dx, dy)` (in boxes) can hold an item within `limit`
    /// (`lim_r = isqrt(limit)`): its exact minimum squared distance is `<= limit`.
    #[inline]
    fn box_within(&self, dx: i128, dy: i128, limit: u64, lim_r: u64) -> bool {
        let gx = self.gap(dx, self.ox);
        let gy = self.gap(dy, self.oy);
        let lr = i128::from(lim_r);
        if gx > lr || gy > lr {
            return false;
        }
        // Both gaps are at most 2^32 - 1 here, so this cannot overflow.
        gx * gx + gy * gy <= i128::from(limit)
    }

    /// The map key of the box at offset `(dx, dy)`, if it is a box some `i64` cell can be in.
    #[inline]
    fn key(&self, dx: i128, dy: i128) -> Option<[i64; 2]> {
        Some([
            i64::try_from(self.bx + dx).ok()?,
            i64::try_from(self.by + dy).ok()?,
        ])
    }
}

impl<K: Copy + Eq> PlaneGrid<K> {
    /// Nearest item of `kind` to `p` with squared distance `<= r2`, excluding `exclude`, as
    /// `(id, dist2)`; equally near items are resolved by the lower id.
    ///
    /// Serves the "move towards the nearest rabbit / fox" rules (the grid-boxing paper, section
    /// II.B) and is the query timed in Fig. 9 and Table I (section IV.B). With boxes, it searches
    /// box rings outward from `p`'s box and stops as soon as no closer item can exist; in
    /// [`BoxSize::None`](super::BoxSize::None) mode it scans every item.
    pub fn nearest(&self, p: Pos, kind: K, r2: u64, exclude: Option<u64>) -> Option<(u64, u64)> {
        self.nearest_filtered(p, Some(kind), r2, exclude)
    }

    /// Nearest item of any kind, as [`nearest`](Self::nearest) (the grid-boxing paper, section
    /// II.B).
    pub fn nearest_any(&self, p: Pos, r2: u64, exclude: Option<u64>) -> Option<(u64, u64)> {
        self.nearest_filtered(p, None, r2, exclude)
    }

    fn nearest_filtered(
        &self,
        p: Pos,
        kind: Option<K>,
        r2: u64,
        exclude: Option<u64>,
    ) -> Option<(u64, u64)> {
        let mut v = NearestVisitor {
            probe: Probe::new(p, kind, r2, exclude),
            best: None,
        };
        self.search(p, &mut v);
        v.best
    }

    /// Number of items of any kind with squared distance `<= r2` from `p`, excluding
    /// `exclude` (the grid-boxing paper, section II.B: counting the animats in the local area).
    pub fn count_within(&self, p: Pos, r2: u64, exclude: Option<u64>) -> usize {
        self.count_within_capped(p, None, r2, exclude, usize::MAX)
    }

    /// Number of items of `kind` with squared distance `<= r2` from `p`, excluding `exclude`
    /// (the grid-boxing paper, section II.B: "predators will not breed unless there is sufficient
    /// prey nearby").
    pub fn count_within_kind(&self, p: Pos, kind: K, r2: u64, exclude: Option<u64>) -> usize {
        self.count_within_capped(p, Some(kind), r2, exclude, usize::MAX)
    }

    /// `min(count, cap)`, where `count` is the number of items (of `kind`, or of any kind when
    /// `None`) with squared distance `<= r2` from `p`, excluding `exclude`. Stops as soon as
    /// `cap` items are found, so an overcrowding test `count > crowd_max` costs only what it
    /// needs: `count_within_capped(p, None, r2, Some(me), crowd_max + 1) > crowd_max`
    /// (the grid-boxing paper, section II.B).
    pub fn count_within_capped(
        &self,
        p: Pos,
        kind: Option<K>,
        r2: u64,
        exclude: Option<u64>,
        cap: usize,
    ) -> usize {
        if cap == 0 {
            return 0;
        }
        let mut v = CountVisitor {
            probe: Probe::new(p, kind, r2, exclude),
            count: 0,
            cap,
        };
        self.search(p, &mut v);
        v.count
    }

    /// Whether at least `n` items (of `kind`, or of any kind when `None`) lie within squared
    /// distance `r2` of `p`, excluding `exclude`; stops at the `n`-th. `at_least(.., 0)` is
    /// `true`. Overcrowding is `at_least(p, None, r2, Some(me), crowd_max + 1)`; "enough prey"
    /// is `at_least(p, Some(rabbit), v2, None, prey_needed)` (the grid-boxing paper, section II.B).
    pub fn at_least(
        &self,
        p: Pos,
        kind: Option<K>,
        r2: u64,
        exclude: Option<u64>,
        n: usize,
    ) -> bool {
        self.count_within_capped(p, kind, r2, exclude, n) >= n
    }

    /// Whether any item of `kind` lies within squared distance `r2` of `p`, excluding
    /// `exclude`; stops at the first hit. With `r2 = 2` this is "a rabbit / fox adjacent" (the 8
    /// surrounding cells; the grid-boxing paper, section II.B).
    pub fn any_within(&self, p: Pos, kind: K, r2: u64, exclude: Option<u64>) -> bool {
        self.count_within_capped(p, Some(kind), r2, exclude, 1) >= 1
    }

    /// Every item (of `kind`, or of any kind when `None`) within squared distance `r2` of `p`,
    /// excluding `exclude`, as `(id, dist2)` sorted by `(dist2, id)`. For diagnostics and for
    /// rules that need the whole neighbourhood.
    pub fn within(
        &self,
        p: Pos,
        kind: Option<K>,
        r2: u64,
        exclude: Option<u64>,
    ) -> Vec<(u64, u64)> {
        let mut v = CollectVisitor {
            probe: Probe::new(p, kind, r2, exclude),
            found: Vec::new(),
        };
        self.search(p, &mut v);
        let mut found = v.found;
        found.sort_unstable_by_key(|&(id, d2)| (d2, id));
        found
    }

    /// Distance evaluations (full squared-distance computations against candidate items) made
    /// by queries since creation or the last reset: the work measure behind the grid-boxing paper,
    /// Fig. 9 and Table I. Shorthand for `self.stats().distance_evals`.
    pub fn distance_evals(&self) -> u64 {
        self.stats.distance_evals.load(Ordering::Relaxed)
    }

    /// Resets the distance-evaluation counter to zero (the other [`SearchStats`] counters are
    /// kept).
    pub fn reset_distance_evals(&self) {
        self.stats.distance_evals.store(0, Ordering::Relaxed);
    }

    /// Returns the distance-evaluation counter and resets it to zero in one step (per-step
    /// accounting of the grid-boxing paper, Fig. 9).
    pub fn take_distance_evals(&self) -> u64 {
        self.stats.distance_evals.swap(0, Ordering::Relaxed)
    }

    /// All work counters of the queries since creation or the last reset (the grid-boxing paper,
    /// Fig. 9 and Table I; see [`SearchStats`]).
    pub fn stats(&self) -> SearchStats {
        self.stats.load()
    }

    /// Returns all work counters and resets them to zero.
    pub fn take_stats(&self) -> SearchStats {
        self.stats.take()
    }

    /// Resets all work counters to zero.
    pub fn reset_stats(&self) {
        self.stats.take();
    }

    /// Runs a query: exhaustive scan in `None` mode, ring search otherwise; then adds the
    /// query's work to the counters (one atomic add per counter).
    fn search<V: Visitor<K>>(&self, p: Pos, v: &mut V) {
        let probed = match self.side {
            None => {
                let mut probed = 0;
                for list in self.boxes.values() {
                    probed += 1;
                    if v.visit(list).is_break() {
                        break;
                    }
                }
                probed
            }
            Some(a) => self.ring_search(a, p, v),
        };
        let probe = v.probe();
        self.stats.add(probe.evals, probe.scanned, probed);
    }

    /// Box rings outward from `p`'s box; see the module documentation for the stop rule and
    /// why it is exact. Returns the number of boxes probed.
    fn ring_search<V: Visitor<K>>(&self, a: i64, p: Pos, v: &mut V) -> u64 {
        let total = self.slots.len();
        if total == 0 {
            return 0;
        }
        let q = QueryBox::new(a, p);
        let mut seen = 0usize;
        let mut probed = 1u64;

        // Ring 0: p's own box (minimum distance 0, always within the limit).
        if let Some(list) = q.key(0, 0).and_then(|key| self.boxes.get(&key)) {
            seen += list.len();
            if v.visit(list).is_break() {
                return probed;
            }
        }

        let edge = q.edge();
        let nboxes = self.boxes.len() as i128;
        let mut k: i128 = 1;
        loop {
            if seen >= total {
                return probed;
            }
            let lr = i128::from(v.probe().lim_r);
            // Every item in ring k is at least (k - 1) A + edge away: stop when that exceeds
            // the limit (strictly: an item exactly at the limit may still win a tie).
            if (k - 1) * q.a + edge > lr {
                return probed;
            }
            // Last ring that can matter under the current limit, and the lookups left.
            let k_max = (lr - edge) / q.a + 1;
            let left = (2 * k_max + 1) * (2 * k_max + 1) - (2 * k - 1) * (2 * k - 1);
            if left > nboxes {
                return probed + self.scan_boxes_from(q, k, v);
            }
            let mut visit = |dx: i128, dy: i128, v: &mut V| -> ControlFlow<()> {
                let pr = v.probe();
                if !q.box_within(dx, dy, pr.limit, pr.lim_r) {
                    return ControlFlow::Continue(());
                }
                probed += 1;
                match q.key(dx, dy).and_then(|key| self.boxes.get(&key)) {
                    Some(list) => {
                        seen += list.len();
                        v.visit(list)
                    }
                    None => ControlFlow::Continue(()),
                }
            };
            for dx in -k..=k {
                if visit(dx, -k, v).is_break() || visit(dx, k, v).is_break() {
                    return probed;
                }
            }
            for dy in (-k + 1)..k {
                if visit(-k, dy, v).is_break() || visit(k, dy, v).is_break() {
                    return probed;
                }
            }
            k += 1;
        }
    }

    /// Finishes a ring search in one pass over the occupied boxes, visiting those at ring
    /// `k_from` or beyond that can hold an item within the limit. Used when the rings left
    /// would cost more lookups than there are boxes. Returns the number of boxes examined.
    fn scan_boxes_from<V: Visitor<K>>(&self, q: QueryBox, k_from: i128, v: &mut V) -> u64 {
        let mut probed = 0;
        for (key, list) in &self.boxes {
            probed += 1;
            let dx = i128::from(key[0]) - q.bx;
            let dy = i128::from(key[1]) - q.by;
            if dx.abs().max(dy.abs()) < k_from {
                continue; // already visited as part of an inner ring
            }
            let pr = v.probe();
            if q.box_within(dx, dy, pr.limit, pr.lim_r) && v.visit(list).is_break() {
                break;
            }
        }
        probed
    }
}
