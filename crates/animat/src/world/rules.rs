//! The rules: each animat runs its species' rule list in priority order and executes the
//! first rule whose condition holds (Hawick, James & Scogings 2006, section II.B); this module
//! evaluates the fox and rabbit rules into an [`Action`] and applies it (moves, eating,
//! breeding).
//!
//! Invariants: a condition asks only the queries it needs, in the order of its terms, so
//! perception stays lazy; a decision changes nothing (it may be made again after the grid is
//! brought up to date); applying an action keeps one animat per cell and logs every grid
//! change in `pending`.

use super::perception::Tally;
use super::{Animat, DIRECTIONS, GridOp, World};
use crate::params::{FoxRule, RabbitRule, Species};
use core_lattice::rng::{RngExt, uniform01};
use spatial::cells::FREE;
use spatial::cells::near::{NEAR_ROWS, Near, row_cell};
use spatial::plane::Pos;
use std::time::Instant;

/// What an animat decided to do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Action {
    /// Eat the rabbit on this cell.
    Eat(Pos),
    /// Breed (the probability is drawn when applied).
    Breed,
    /// Step by this unit vector (blocked steps stay put).
    Step([i64; 2]),
    /// Random step.
    Wander,
    /// No rule fired.
    Stay,
}

/// Sign of `b - a` without overflow.
fn sign_towards(a: i64, b: i64) -> i64 {
    match b.cmp(&a) {
        std::cmp::Ordering::Greater => 1,
        std::cmp::Ordering::Less => -1,
        std::cmp::Ordering::Equal => 0,
    }
}

/// The unit step from `from` towards `to` (the sign of each coordinate difference).
fn towards(from: Pos, to: Pos) -> [i64; 2] {
    [sign_towards(from[0], to[0]), sign_towards(from[1], to[1])]
}

/// `p + d`, or `None` on overflow.
fn offset(p: Pos, d: [i64; 2]) -> Option<Pos> {
    Some([p[0].checked_add(d[0])?, p[1].checked_add(d[1])?])
}

impl World {
    /// Chooses the action of animat `a`: the first rule whose condition holds. Asks only the
    /// queries each condition needs, in priority order.
    #[cfg(test)]
    pub(super) fn decide(&mut self, a: &Animat) -> Action {
        self.decide_near(a).0
    }

    /// `World::decide`, with the kind bytes around `a` ([`Near::rows`]) when the action
    /// moves or breeds and the cell-index fast path is on: applying it reads its free
    /// neighbours from them.
    pub(super) fn decide_near(&mut self, a: &Animat) -> (Action, Option<[u64; NEAR_ROWS]>) {
        let (act, t) = loop {
            let mut t = Tally::default();
            let mut near = self.near(a);
            let act = self.decide_in(a, &mut near, &mut t);
            if t.stale {
                // A query needed the grid while changes were still logged: bring it up to
                // date and decide again (the first attempt changed nothing). Applying the
                // logged changes is grid maintenance, not search: with timing on it is
                // clocked apart and left out of the search time.
                if self.timing {
                    let f = Instant::now();
                    self.flush_grid();
                    self.flush_seconds += f.elapsed().as_secs_f64();
                } else {
                    self.flush_grid();
                }
                continue;
            }
            let rows = match act {
                Action::Step(_) | Action::Wander | Action::Breed if near.window().is_some() => {
                    Some(*near.rows(a.pos))
                }
                _ => None,
            };
            break ((act, rows), t);
        };
        self.queries.adjacent += t.adjacent;
        self.queries.nearest += t.nearest;
        self.queries.count += t.count;
        self.cell_evals += t.evals;
        act
    }

    fn decide_in(&self, a: &Animat, near: &mut Near<'_>, t: &mut Tally) -> Action {
        match a.species {
            Species::Fox => {
                let hungry = a.hunger >= self.params.hungry_at;
                for &rule in &self.fox_rules {
                    if let Some(act) = self.fox_rule(rule, a, hungry, near, t) {
                        return act;
                    }
                }
                Action::Stay
            }
            Species::Rabbit => {
                for &rule in &self.rabbit_rules {
                    if let Some(act) = self.rabbit_rule(rule, a, near, t) {
                        return act;
                    }
                }
                Action::Stay
            }
        }
    }

    fn fox_rule(
        &self,
        rule: FoxRule,
        a: &Animat,
        hungry: bool,
        near: &mut Near<'_>,
        t: &mut Tally,
    ) -> Option<Action> {
        match rule {
            FoxRule::Eat => {
                if !hungry {
                    return None;
                }
                self.nearest_adjacent(a, Species::Rabbit, near, t)
                    .map(Action::Eat)
            }
            FoxRule::Breed => (!hungry
                && self.adjacent(a, Species::Fox, near, t)
                && !self.overcrowded_in(a, near, t)
                && self.enough_prey_in(a, near, t))
            .then_some(Action::Breed),
            FoxRule::Hunt => {
                if !hungry {
                    return None;
                }
                self.nearest_seen(a, Species::Rabbit, near, t)
                    .map(|p| Action::Step(towards(a.pos, p)))
            }
            FoxRule::SeekMate => {
                if hungry {
                    return None;
                }
                self.nearest_seen(a, Species::Fox, near, t)
                    .map(|p| Action::Step(towards(a.pos, p)))
            }
            FoxRule::Wander => Some(Action::Wander),
        }
    }

    fn rabbit_rule(
        &self,
        rule: RabbitRule,
        a: &Animat,
        near: &mut Near<'_>,
        t: &mut Tally,
    ) -> Option<Action> {
        match rule {
            RabbitRule::Flee => self.nearest_adjacent(a, Species::Fox, near, t).map(|f| {
                let d = towards(a.pos, f);
                Action::Step([-d[0], -d[1]])
            }),
            RabbitRule::Breed => (self.adjacent(a, Species::Rabbit, near, t)
                && !self.overcrowded_in(a, near, t))
            .then_some(Action::Breed),
            RabbitRule::Herd => self
                .nearest_seen(a, Species::Rabbit, near, t)
                .map(|p| Action::Step(towards(a.pos, p))),
            RabbitRule::Wander => Some(Action::Wander),
        }
    }

    /// Whether the neighbour `c = a.pos + d` of `a` is free, from `rows` (the kind bytes
    /// around `a`) when given.
    fn is_free(&self, c: Pos, d: [i64; 2], rows: Option<&[u64; NEAR_ROWS]>) -> bool {
        match rows {
            Some(r) => row_cell(r, d[0], d[1]) == FREE,
            None => !self.cells.occupied(c),
        }
    }

    /// Moves animat `a` one step by `d` unless the target cell is occupied.
    fn try_step(&mut self, a: &mut Animat, d: [i64; 2], rows: Option<&[u64; NEAR_ROWS]>) {
        if d == [0, 0] {
            return;
        }
        let Some(to) = offset(a.pos, d) else { return };
        if !self.is_free(to, d, rows) {
            return;
        }
        self.log(GridOp::Move(a.id, to));
        self.cells.relocate(a.pos, to);
        a.pos = to;
    }

    pub(super) fn apply(
        &mut self,
        a: &mut Animat,
        action: Action,
        rows: Option<&[u64; NEAR_ROWS]>,
    ) {
        match action {
            Action::Stay => {}
            Action::Step(d) => self.try_step(a, d, rows),
            Action::Wander => {
                let d = DIRECTIONS[self.action_rng.random_range(0..8usize)];
                self.try_step(a, d, rows);
            }
            Action::Eat(pos) => {
                // Marked dead, the rabbit does not act if its turn is still to come.
                let rabbit = self.cells.id(pos);
                let k = self.record_of(rabbit);
                self.kill(k, rabbit, pos);
                a.hunger = 0;
            }
            Action::Breed => {
                let p = match a.species {
                    Species::Fox => self.params.fox_breed_p,
                    Species::Rabbit => self.params.rabbit_breed_p,
                };
                if uniform01(&mut self.action_rng) >= p {
                    return;
                }
                let mut free = [[0i64; 2]; 8];
                let mut n = 0;
                for d in DIRECTIONS {
                    if let Some(c) = offset(a.pos, d) {
                        if self.is_free(c, d, rows) {
                            free[n] = c;
                            n += 1;
                        }
                    }
                }
                if n > 0 && self.may_give_birth() {
                    let child = Animat {
                        id: self.next_id,
                        species: a.species,
                        pos: free[self.action_rng.random_range(0..n)],
                        age: 0,
                        hunger: 0,
                    };
                    self.add_deferred(child)
                        .expect("a birth on a free cell, within the record limit");
                }
            }
        }
    }
}
