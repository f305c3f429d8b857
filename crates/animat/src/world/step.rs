//! One step of the world ([`World::step`]): the visiting order, each turn (decide, apply, age,
//! die), and the end of the step (records copied back, dead and eaten animats dropped, grid
//! brought up to date), plus the re-spreading of the cell index's id buckets between steps.
//!
//! Invariants: every animat alive at the start of a step acts exactly once unless eaten before
//! its turn, in the order drawn from the order stream; newborns do not act in their birth
//! step; an animat's `DEAD` bit is set only in its own turn; at the end of the step the
//! world's between-steps invariants (see the parent module) hold again.

use super::{Animat, DEAD, GridOp, RABBIT, Rec, StepStats, World, species_of};
use crate::params::Species;
use core_lattice::rng::shuffle;
use spatial::plane::Pos;
use std::time::Instant;

/// How many turns ahead a turn's cells are prefetched.
const PREFETCH_TURNS: usize = 8;

impl World {
    /// One step: every animat alive at its start acts once, in a fresh uniformly random order
    /// (ids sorted, then shuffled with the order stream); an animat eaten earlier in the step
    /// does not act; newborns first act in the next step. Each runs its species' rules in
    /// priority order and executes the first whose condition holds; then its age (and a fox's
    /// hunger) grow by one and it dies if a fox's hunger exceeds `starve` or its age exceeds
    /// its species' `max_age`.
    pub fn step(&mut self) -> StepStats {
        let evals_before = self.grid.take_distance_evals() + std::mem::take(&mut self.cell_evals);
        self.total_distance_evals += evals_before;
        self.search_seconds = 0.0;
        let n = self.recs.len();
        self.maybe_rebucket(n);
        let mut order = std::mem::take(&mut self.order);
        order.clear();
        order.extend(0..n as u32);
        shuffle(&mut self.order_rng, &mut order);
        // The visiting order is random, so reading each turn's record where it is stored (id
        // order) would start every turn with a cache miss that nothing overlaps. Copying the
        // records into visiting order first is a loop of independent loads that the CPU
        // overlaps; the turns then read their records in sequence.
        let mut hot = std::mem::take(&mut self.hot);
        hot.clear();
        hot.extend(order.iter().map(|&k| self.recs[k as usize]));
        let mut hot_flags = std::mem::take(&mut self.hot_flags);
        hot_flags.clear();
        hot_flags.extend(order.iter().map(|&k| self.flags[k as usize]));
        for j in 0..n {
            let f = hot_flags[j];
            let r = hot[j];
            // An animat dies in its own turn or is eaten (listed in `eaten`): the DEAD bit of
            // one that has not acted yet is never set.
            debug_assert_eq!(self.flags[order[j] as usize] & DEAD, 0);
            if f & RABBIT != 0 && !self.eaten.is_empty() && self.eaten.contains(&r.id) {
                continue;
            }
            let mut a = Animat {
                id: r.id,
                species: species_of(f),
                pos: r.pos,
                age: r.age,
                hunger: r.hunger,
            };
            // The turns' positions are known ahead (an animat moves only in its own turn), so
            // the cells a later turn reads first are asked for now: their misses overlap this
            // turn's work instead of stalling that one's. Part of the search, so timed with it.
            let ahead = hot
                .get(j + PREFETCH_TURNS)
                .filter(|_| self.cell_search)
                .map(|r| r.pos);
            let (action, rows) = if self.timing {
                let flushed = self.flush_seconds;
                let t = Instant::now();
                if let Some(p) = ahead {
                    self.cells.prefetch_near(p);
                }
                let act = self.decide_near(&a);
                self.search_seconds += t.elapsed().as_secs_f64() - (self.flush_seconds - flushed);
                act
            } else {
                if let Some(p) = ahead {
                    self.cells.prefetch_near(p);
                }
                self.decide_near(&a)
            };
            self.apply(&mut a, action, rows.as_ref());
            self.age_and_die(order[j] as usize, &mut a);
            hot[j] = Rec {
                pos: a.pos,
                id: a.id,
                age: a.age,
                hunger: a.hunger,
            };
        }
        self.hot_flags = hot_flags;
        for (&k, r) in order.iter().zip(&hot) {
            self.recs[k as usize] = *r;
        }
        self.order = order;
        self.hot = hot;
        let mut w = 0;
        for i in 0..self.recs.len() {
            let f = self.flags[i];
            let eaten =
                f & RABBIT != 0 && !self.eaten.is_empty() && self.eaten.contains(&self.recs[i].id);
            if f & DEAD == 0 && !eaten {
                self.recs[w] = self.recs[i];
                self.flags[w] = f;
                w += 1;
            }
        }
        self.recs.truncate(w);
        self.flags.truncate(w);
        self.eaten.clear();
        self.steps += 1;
        self.flush_grid();
        let evals = self.grid.take_distance_evals() + std::mem::take(&mut self.cell_evals);
        self.total_distance_evals += evals;
        StepStats {
            search_seconds: self.search_seconds,
            distance_evals: evals,
        }
    }

    /// Spreads the id buckets of the cell bytes
    /// ([`CellIndex::bucket`](crate::cells::CellIndex::bucket)) over the ids that can be alive
    /// during the next step (the live ones, sorted in `recs`, and at most `n` newborns) when the
    /// top bucket could overflow or the lower half of the buckets has gone unused. Buckets only
    /// speed up tie-breaks; any non-decreasing map gives the same answers.
    fn maybe_rebucket(&mut self, n: usize) {
        let Some(first) = self.recs.first() else {
            return;
        };
        let lo = first.id;
        let hi = self.next_id.saturating_add(n as u64);
        let (base, shift) = self.cells.bucket_range();
        let wasted = lo.saturating_sub(base) >> shift >= 32;
        if !self.cells.bucket_capped(hi) && !wasted {
            return;
        }
        // The smallest width that keeps `hi` within bucket 47 (room for later births).
        let span = hi - lo;
        let mut s = 0;
        while span >> s > 47 {
            s += 1;
        }
        self.cells
            .rebucket(lo, s, self.recs.iter().map(|r| (r.pos, r.id)));
    }

    /// Marks record `k` (animat `id` on cell `pos`) dead and takes it off the plane.
    fn kill(&mut self, k: usize, id: u64, pos: Pos) {
        let f = self.flags[k];
        if f & DEAD != 0 {
            return;
        }
        self.flags[k] = f | DEAD;
        match species_of(f) {
            Species::Fox => self.foxes -= 1,
            Species::Rabbit => self.rabbits -= 1,
        }
        self.pending.push(GridOp::Remove(id));
        self.cells.clear(pos);
    }

    /// Ages the animat `a` of record `k` and kills it if it is too old or has starved.
    fn age_and_die(&mut self, k: usize, a: &mut Animat) {
        a.age = a.age.saturating_add(1);
        let dies = match a.species {
            Species::Fox => {
                a.hunger = a.hunger.saturating_add(1);
                a.hunger > self.params.starve || a.age > self.params.fox_max_age
            }
            Species::Rabbit => a.age > self.params.rabbit_max_age,
        };
        if dies {
            self.kill(k, a.id, a.pos);
        }
    }
}
