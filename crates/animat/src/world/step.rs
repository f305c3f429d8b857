//! One step of the world ([`World::step`]): the visiting order, each turn (decide, apply, age,
//! die), and the end of the step (the live animats listed in id order again, the grid brought
//! up to date), plus the re-spreading of the cell index's id buckets between steps.
//!
//! Invariants: every animat alive at the start of a step acts exactly once unless eaten before
//! its turn, in the order drawn from the order stream; newborns do not act in their birth
//! step; an animat's `DEAD` bit is set in its own turn or when it is eaten; at the end of the
//! step the world's between-steps invariants (see the parent module) hold again.

use super::{Animat, DEAD, GridOp, Rec, StepStats, World, species_of};
use crate::params::Species;
use core_lattice::rng::shuffle;
use spatial::plane::Pos;
use std::time::Instant;

/// How many turns ahead a turn's cells are prefetched.
const PREFETCH_TURNS: usize = 8;

/// A `rank_of` entry for an id not alive at the step's start.
const NO_RANK: u32 = u32::MAX;

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
        let n = self.ranks.len();
        self.maybe_rebucket(n);
        let mut order = std::mem::take(&mut self.order);
        order.clear();
        order.extend(0..n as u32);
        shuffle(&mut self.order_rng, &mut order);
        self.gather(&mut order);
        self.order = order;
        self.index_ranks();
        self.born_at = n;
        self.first_born = self.next_id;
        for j in 0..n {
            let f = self.flags[j];
            // Eaten before its turn.
            if f & DEAD != 0 {
                continue;
            }
            let r = self.recs[j];
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
            let ahead = self
                .recs
                .get(j + PREFETCH_TURNS)
                .filter(|_| self.cell_search)
                .map(|r| r.pos);
            let (action, rows) = if self.timing {
                let flushed = self.flush_seconds;
                let t = Instant::now();
                if let Some(p) = ahead {
                    self.cells.near_lines(p, core_lattice::hint::prefetch);
                }
                let act = self.decide_near(&a);
                self.search_seconds += t.elapsed().as_secs_f64() - (self.flush_seconds - flushed);
                act
            } else {
                if let Some(p) = ahead {
                    self.cells.near_lines(p, core_lattice::hint::prefetch);
                }
                self.decide_near(&a)
            };
            self.apply(&mut a, action, rows.as_ref());
            self.age_and_die(j, &mut a);
            self.recs[j] = Rec {
                pos: a.pos,
                id: a.id,
                age: a.age,
                hunger: a.hunger,
            };
        }
        self.relist(n);
        self.steps += 1;
        self.flush_grid();
        let evals = self.grid.take_distance_evals() + std::mem::take(&mut self.cell_evals);
        self.total_distance_evals += evals;
        StepStats {
            search_seconds: self.search_seconds,
            distance_evals: evals,
        }
    }

    /// Puts the records and flags of the live animats into visiting order (`recs[j]` is the
    /// animat of rank `order[j]`) and notes where each rank went (`inv`); `order` is left
    /// holding the records' previous indices. The visiting order is random, so reading each
    /// turn's record where it was stored would start every turn with a cache miss that
    /// nothing overlaps; the gathering loops' loads are independent, and the CPU overlaps
    /// them. Records of animats that died in the last step are left behind.
    fn gather(&mut self, order: &mut [u32]) {
        let n = order.len();
        self.inv.clear();
        self.inv.resize(n, 0);
        for (j, k) in order.iter_mut().enumerate() {
            self.inv[*k as usize] = j as u32;
            *k = self.ranks[*k as usize];
        }
        // Room for the newborns of a step without reallocating in it, as a rule.
        let room = n + n / 8 + 16;
        let mut recs = std::mem::take(&mut self.spare_recs);
        recs.clear();
        recs.reserve(room);
        recs.extend(order.iter().map(|&i| self.recs[i as usize]));
        let mut flags = std::mem::take(&mut self.spare_flags);
        flags.clear();
        flags.reserve(room);
        flags.extend(order.iter().map(|&i| self.flags[i as usize]));
        self.spare_recs = std::mem::replace(&mut self.recs, recs);
        self.spare_flags = std::mem::replace(&mut self.flags, flags);
    }

    /// At the end of a step: lists the live animats in id order again, those alive at the
    /// start (`n` of them, still in `ranks` and `ids`) and then the newborns.
    fn relist(&mut self, n: usize) {
        let mut w = 0;
        for k in 0..n {
            let j = self.inv[k];
            if self.flags[j as usize] & DEAD == 0 {
                self.ranks[w] = j;
                self.ids[w] = self.ids[k];
                w += 1;
            }
        }
        self.ranks.truncate(w);
        self.ids.truncate(w);
        for j in n..self.recs.len() {
            if self.flags[j] & DEAD == 0 {
                // `add_deferred` keeps the record count within u32.
                self.ranks.push(j as u32);
                self.ids.push(self.recs[j].id);
            }
        }
    }

    /// At the start of a step: `rank_of` over the ids alive, where they span at most twice
    /// as many ids as there are animats (a table of at most 8 bytes an animat, written in
    /// order); else empty.
    fn index_ranks(&mut self) {
        self.rank_of.clear();
        let (Some(&lo), Some(&hi)) = (self.ids.first(), self.ids.last()) else {
            return;
        };
        let span = (hi - lo) as usize + 1;
        if span > 2 * self.ids.len() + 16 {
            return;
        }
        self.rank_of.resize(span, NO_RANK);
        for (k, &id) in self.ids.iter().enumerate() {
            self.rank_of[(id - lo) as usize] = k as u32;
        }
    }

    /// During a step: the record of the live animat `id` (alive at the step's start or born
    /// in it).
    pub(super) fn record_of(&self, id: u64) -> usize {
        if id >= self.first_born {
            return self.born_at + (id - self.first_born) as usize;
        }
        let k = if self.rank_of.is_empty() {
            self.ids
                .binary_search(&id)
                .expect("a live animat is listed")
        } else {
            let k = self.rank_of[(id - self.ids[0]) as usize];
            assert!(k != NO_RANK, "a live animat is listed");
            debug_assert_eq!(self.ids.binary_search(&id), Ok(k as usize));
            k as usize
        };
        self.inv[k] as usize
    }

    /// Spreads the id buckets of the cell bytes
    /// ([`CellIndex::bucket`](spatial::cells::CellIndex::bucket)) over the ids that can be alive
    /// during the next step (the live ones, sorted in `ids`, and at most `n` newborns) when the
    /// top bucket could overflow or the lower half of the buckets has gone unused. Buckets only
    /// speed up tie-breaks; any non-decreasing map gives the same answers.
    fn maybe_rebucket(&mut self, n: usize) {
        let Some(&lo) = self.ids.first() else {
            return;
        };
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
        let recs = &self.recs;
        self.cells.rebucket(
            lo,
            s,
            self.ranks.iter().map(|&i| {
                let r = &recs[i as usize];
                (r.pos, r.id)
            }),
        );
    }

    /// Marks record `k` (animat `id` on cell `pos`) dead and takes it off the plane.
    pub(super) fn kill(&mut self, k: usize, id: u64, pos: Pos) {
        let f = self.flags[k];
        if f & DEAD != 0 {
            return;
        }
        self.flags[k] = f | DEAD;
        match species_of(f) {
            Species::Fox => self.foxes -= 1,
            Species::Rabbit => self.rabbits -= 1,
        }
        self.log(GridOp::Remove(id));
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
