//! Perception: the neighbour queries the rules ask ("a fox adjacent?", "the nearest rabbit
//! within vision", "overcrowded?", "enough prey?"). Each is answered from the cell index first
//! (the cells around the animat through [`spatial::cells::near`], then rings of cells up to
//! `RING_MAX` through [`spatial::cells::rings`]) and handed to the index's wide search over grid boxes
//! ([`spatial::cells::wide`]) when the rings cannot settle it; with the cell search off, every
//! query goes to the paper's grid boxes ([`spatial::plane::PlaneGrid`]).
//!
//! Stays in the model: this is the dispatch of the rules' queries (which path answers which
//! rule, with the model's radii, counters and grid staleness); the searches it calls are
//! `spatial`'s.
//!
//! Invariants: every path gives the exact answer, ties going to the lower id, so the trajectory
//! does not depend on the path or on the grid-box size; a query that needs the grid while
//! changes are still logged does not read it but marks the decision stale ([`Tally::stale`]),
//! and the decision is made again once the grid is up to date.

use super::{ADJACENT_R2, Animat, DIRECTIONS, RING_MAX, World, kind_byte};
use crate::params::Species;
use spatial::cells::near::{
    NEAR_HALF, Near, RING_CLASSES, byte_sum, count_in, kind_bits, lowest_in, row_cell,
};
use spatial::cells::{FREE, KIND_MASK};
use spatial::plane::Pos;

/// Query and work counters of one decision (added to the world's afterwards).
#[derive(Debug, Default)]
pub(super) struct Tally {
    pub(super) adjacent: u64,
    pub(super) nearest: u64,
    pub(super) count: u64,
    pub(super) evals: u64,
    /// A query needed the grid while it lagged behind the logged changes.
    pub(super) stale: bool,
}

impl World {
    /// The cells around `a` for the cell-index fast path (no window when the fast path is
    /// off or `a` is too near the `i64` limits).
    pub(super) fn near(&self, a: &Animat) -> Near<'_> {
        Near::new(if self.cell_search {
            self.cells.window(a.pos, RING_MAX)
        } else {
            None
        })
    }

    /// The box side of the wide search: the grid-box setting, or (for `none`) one box holding
    /// the whole plane.
    fn wide_side(&self) -> i64 {
        self.grid.box_size().side().unwrap_or(i64::MAX)
    }

    /// The nearest animat of `kind` within squared distance `r2` of `p`, other than the one
    /// on `p`, from the cell index's wide search.
    #[inline]
    pub(super) fn wide_nearest(
        &self,
        p: Pos,
        kind: Species,
        r2: u64,
        t: &mut Tally,
    ) -> Option<Pos> {
        let kinds = kind_byte(kind == Species::Rabbit);
        let (found, evals) = self.cells.nearest_within(p, kinds, r2, self.wide_side());
        t.evals += evals;
        found
    }

    /// Whether at least `n` animats (of `kind`, or of either species) lie within squared
    /// distance `r2` of `p`, the one on `p` not counted, from the cell index's wide search.
    #[inline]
    pub(super) fn wide_at_least(
        &self,
        p: Pos,
        kind: Option<Species>,
        r2: u64,
        n: usize,
        t: &mut Tally,
    ) -> bool {
        let kinds = kind.map_or(KIND_MASK, |k| kind_byte(k == Species::Rabbit));
        let (enough, evals) = self
            .cells
            .at_least_within(p, kinds, r2, n, self.wide_side());
        t.evals += evals;
        enough
    }

    /// Whether the grid lags behind the logged changes; if so, notes in `t` that the
    /// decision must be made again after [`World::flush_grid`].
    #[inline]
    pub(super) fn stale(&self, t: &mut Tally) -> bool {
        t.stale = !self.pending.is_empty();
        t.stale
    }

    /// The position of the nearest adjacent animat of `kind` (ties: lower id).
    ///
    /// This and the other queries the rules ask are inlined into the decision: each is asked
    /// from a few places at most, and inlined they keep the near cache and the tally in
    /// registers instead of passing them through memory on every call.
    #[inline(always)]
    pub(super) fn nearest_adjacent(
        &self,
        a: &Animat,
        kind: Species,
        near: &mut Near<'_>,
        t: &mut Tally,
    ) -> Option<Pos> {
        t.adjacent += 1;
        if let Some((w, rows)) = near.parts(a.pos) {
            let kb = kind_byte(kind == Species::Rabbit);
            // Orthogonal cells (d2 = 1) before diagonal ones (d2 = 2); lower id wins ties.
            // Ids are read only to break a tie (they live in a larger array that is rarely in
            // cache).
            let bits = kind_bits(rows, kb);
            for class in &RING_CLASSES[..2] {
                let n = count_in(&bits, class);
                if n > 0 {
                    t.evals += n;
                    return Some(lowest_in(&bits, class, n, a.pos, rows, w));
                }
            }
            return None;
        }
        if self.cell_search {
            return self.wide_nearest(a.pos, kind, ADJACENT_R2, t);
        }
        if self.stale(t) {
            return None;
        }
        let (id, _) = self.grid.nearest(a.pos, kind, ADJACENT_R2, Some(a.id))?;
        self.grid.get(id).map(|(p, _)| p)
    }

    #[inline(always)]
    pub(super) fn adjacent(
        &self,
        a: &Animat,
        kind: Species,
        near: &mut Near<'_>,
        t: &mut Tally,
    ) -> bool {
        t.adjacent += 1;
        if let Some((_, rows)) = near.parts(a.pos) {
            let kb = kind_byte(kind == Species::Rabbit);
            let found = DIRECTIONS.iter().any(|d| row_cell(rows, d[0], d[1]) == kb);
            t.evals += u64::from(found);
            return found;
        }
        if self.cell_search {
            return self.wide_at_least(a.pos, Some(kind), ADJACENT_R2, 1, t);
        }
        if self.stale(t) {
            return false;
        }
        self.grid.any_within(a.pos, kind, ADJACENT_R2, Some(a.id))
    }

    /// Position of the nearest animat of `kind` within vision (ties: lower id).
    #[inline(always)]
    pub(super) fn nearest_seen(
        &self,
        a: &Animat,
        kind: Species,
        near: &mut Near<'_>,
        t: &mut Tally,
    ) -> Option<Pos> {
        t.nearest += 1;
        if near.window().is_some() {
            let k_max = RING_MAX.min(self.params.vision);
            let kb = kind_byte(kind == Species::Rabbit);
            // Rings 1 and 2 from the row words when they lie within vision.
            let mut k_first = 1;
            if self.params.vision >= 3 {
                let (w, rows) = near.parts(a.pos).expect("the window is present");
                let mut bits = kind_bits(rows, kb);
                // Not the animat itself.
                bits[NEAR_HALF as usize] &= !(1 << (8 * NEAR_HALF));
                for ring in [&RING_CLASSES[..2], &RING_CLASSES[2..]] {
                    let counts = ring.iter().map(|c| count_in(&bits, c));
                    let total: u64 = counts.clone().sum();
                    if total > 0 {
                        t.evals += total;
                        for (class, n) in ring.iter().zip(counts) {
                            if n > 0 {
                                return Some(lowest_in(&bits, class, n, a.pos, rows, w));
                            }
                        }
                    }
                }
                k_first = 3;
            }
            let w = near.window().expect("the window is present");
            let rings = w.nearest_in_rings(a.pos, kb, self.vision2, k_first, k_max);
            t.evals += rings.evals;
            if rings.settled {
                return rings.found;
            }
        }
        if self.cell_search {
            return self.wide_nearest(a.pos, kind, self.vision2, t);
        }
        if self.stale(t) {
            return None;
        }
        let (id, _) = self.grid.nearest(a.pos, kind, self.vision2, Some(a.id))?;
        self.grid.get(id).map(|(p, _)| p)
    }

    /// More than `crowd_max` animats (either species, `a` excluded) within `crowd_radius`.
    #[cfg(test)]
    pub(super) fn overcrowded(&self, a: &Animat) -> bool {
        self.overcrowded_in(a, &mut self.near(a), &mut Tally::default())
    }

    #[inline(always)]
    pub(super) fn overcrowded_in(&self, a: &Animat, near: &mut Near<'_>, t: &mut Tally) -> bool {
        t.count += 1;
        let n = self.params.crowd_max as usize + 1;
        let r = self.params.crowd_radius;
        if near.window().is_some() {
            if r <= NEAR_HALF {
                // Kind bytes are 0, 1 or 2: bit 0 or'ed with bit 1 marks an occupied cell;
                // the masks keep the cells within the radius.
                let rows = near.rows(a.pos);
                // At most one bit per byte and NEAR_ROWS rows: [`byte_sum`] applies.
                let bits = rows
                    .iter()
                    .zip(&self.crowd_masks)
                    .fold(0u64, |acc, (&row, &m)| acc + ((row | row >> 1) & m));
                let count = byte_sum(bits) as usize;
                t.evals += count.min(n) as u64;
                return count >= n;
            }
            if r <= RING_MAX {
                let w = near.window().expect("the window is present");
                let [x, y] = a.pos;
                let mut count = 0;
                for d in &self.crowd_offsets {
                    if w.at(x + d[0], y + d[1]) != FREE {
                        count += 1;
                        if count >= n {
                            break;
                        }
                    }
                }
                t.evals += count as u64;
                return count >= n;
            }
        }
        if self.cell_search {
            return self.wide_at_least(a.pos, None, self.crowd2, n, t);
        }
        if self.stale(t) {
            return false;
        }
        self.grid.at_least(a.pos, None, self.crowd2, Some(a.id), n)
    }

    /// At least `prey_needed` rabbits within vision.
    #[cfg(test)]
    pub(super) fn enough_prey(&self, a: &Animat) -> bool {
        self.enough_prey_in(a, &mut self.near(a), &mut Tally::default())
    }

    #[inline(always)]
    pub(super) fn enough_prey_in(&self, a: &Animat, near: &mut Near<'_>, t: &mut Tally) -> bool {
        t.count += 1;
        let n = self.params.prey_needed as usize;
        if let (Some(w), true) = (near.window(), n > 0) {
            let k_max = RING_MAX.min(self.params.vision);
            let (found, count) = w.count_in_rings(a.pos, kind_byte(true), self.vision2, n, k_max);
            t.evals += count as u64;
            // Rings 1..=k_max cover the whole vision disc when k_max = vision.
            if found || k_max == self.params.vision {
                return found;
            }
        }
        if self.cell_search {
            return self.wide_at_least(a.pos, Some(Species::Rabbit), self.vision2, n, t);
        }
        if self.stale(t) {
            return false;
        }
        self.grid
            .at_least(a.pos, Some(Species::Rabbit), self.vision2, Some(a.id), n)
    }
}
