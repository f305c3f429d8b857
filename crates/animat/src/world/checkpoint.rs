//! Saving a world between steps and restoring it exactly ([`Snapshot`], [`World::snapshot`],
//! [`World::restore`]), behind the binary's `--checkpoint-every` and `--resume`.
//!
//! A snapshot holds what the future of the run depends on: the parameters and seed, the step
//! count, the next id, every live animat (id, species, cell, age, hunger) in id order and the
//! two random streams a step draws from (visiting order and actions). Everything else of a
//! [`World`] (the grid boxes, the cell index, the step buffers) is rebuilt from the animats:
//! every query answers by distance with ties broken by id, never by storage order, so a
//! restored world continues bit-identically. The counters (queries asked, distance
//! evaluations) are carried over so they keep counting from where they were.

use super::{Animat, QueryCounts, World, WorldError};
use crate::params::{Params, Species};
use core_lattice::rng::SimRng;
use serde::{Deserialize, Serialize};

/// A world between steps, as a checkpoint stores it (serde; see the module doc).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    params: Params,
    seed: u64,
    steps: u64,
    next_id: u64,
    /// Live animats in id order.
    animats: Vec<Animat>,
    order_rng: SimRng,
    action_rng: SimRng,
    /// Queries asked so far: adjacent, nearest, count.
    queries: [u64; 3],
    distance_evals: u64,
    cell_search: bool,
}

impl Snapshot {
    /// The parameters of the saved run.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The seed of the saved run.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Steps the saved run had done.
    pub fn steps(&self) -> u64 {
        self.steps
    }
}

impl World {
    /// The world as a [`Snapshot`] (between steps, the only time a caller holds it).
    pub fn snapshot(&self) -> Snapshot {
        let q = self.queries;
        Snapshot {
            params: self.params.clone(),
            seed: self.seed,
            steps: self.steps,
            next_id: self.next_id,
            animats: self.animats().collect(),
            order_rng: self.order_rng.clone(),
            action_rng: self.action_rng.clone(),
            queries: [q.adjacent, q.nearest, q.count],
            distance_evals: self.distance_evals(),
            cell_search: self.cell_search,
        }
    }

    /// The world a [`Snapshot`] saved, continuing exactly as the saved world would have.
    ///
    /// # Errors
    /// [`WorldError::Params`] for invalid parameters, [`WorldError::Occupied`] for two animats
    /// on one cell, [`WorldError::BadSnapshot`] for ids out of order or not below the next id,
    /// or a rabbit with hunger: a snapshot no world could have written.
    pub fn restore(s: Snapshot) -> Result<World, WorldError> {
        let mut w = World::empty(s.params, s.seed)?;
        let mut last: Option<u64> = None;
        for &a in &s.animats {
            if last.is_some_and(|l| a.id <= l) || a.id >= s.next_id {
                return Err(WorldError::BadSnapshot(format!(
                    "animat id {} is out of order or not below the next id {}",
                    a.id, s.next_id
                )));
            }
            if a.species == Species::Rabbit && a.hunger != 0 {
                return Err(WorldError::BadSnapshot(format!(
                    "rabbit {} has hunger {}; rabbits never hunger",
                    a.id, a.hunger
                )));
            }
            w.insert(a)?;
            last = Some(a.id);
        }
        w.next_id = s.next_id;
        w.steps = s.steps;
        w.order_rng = s.order_rng;
        w.action_rng = s.action_rng;
        let [adjacent, nearest, count] = s.queries;
        w.queries = QueryCounts {
            adjacent,
            nearest,
            count,
        };
        // Restoring the animats counted no distance evaluations worth keeping.
        w.grid.take_distance_evals();
        w.cell_evals = 0;
        w.total_distance_evals = s.distance_evals;
        w.set_cell_search(s.cell_search);
        Ok(w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::GridBox;
    use run_io::checkpoint::{decode_checkpoint, encode_checkpoint};

    fn params(grid_box: GridBox) -> Params {
        Params {
            foxes: 40,
            rabbits: 400,
            start_radius: 30,
            grid_box,
            ..Params::default()
        }
    }

    fn through_bytes(s: &Snapshot) -> Snapshot {
        let bytes = encode_checkpoint("animat", s).unwrap();
        decode_checkpoint(&bytes, "animat").unwrap()
    }

    #[test]
    fn a_restored_world_continues_step_for_step_as_the_saved_one() {
        for grid_box in [GridBox::Vision, GridBox::None, GridBox::Side(3)] {
            for cell_search in [true, false] {
                for seed in [1, 7] {
                    let mut a = World::new(params(grid_box), seed).unwrap();
                    a.set_cell_search(cell_search);
                    a.run(12);
                    let start = (a.foxes(), a.rabbits());
                    let mut b = World::restore(through_bytes(&a.snapshot())).unwrap();
                    assert_eq!(b.state_hash(), a.state_hash());
                    assert_eq!(b.seed(), seed);
                    for _ in 0..25 {
                        a.step();
                        b.step();
                        assert_eq!(b.state_hash(), a.state_hash(), "{grid_box:?} seed {seed}");
                        assert_eq!(b.steps(), a.steps());
                    }
                    assert_eq!(b.queries(), a.queries());
                    assert_ne!((a.foxes(), a.rabbits()), start, "nothing happened");
                }
            }
        }
    }

    #[test]
    fn an_extinct_world_restores() {
        let w = World::empty(params(GridBox::Vision), 3).unwrap();
        let r = World::restore(through_bytes(&w.snapshot())).unwrap();
        assert_eq!(r.foxes() + r.rabbits(), 0);
        assert_eq!(r.state_hash(), w.state_hash());
    }

    #[test]
    fn impossible_snapshots_are_typed_errors() {
        let mut w = World::new(params(GridBox::Vision), 2).unwrap();
        w.run(3);
        let good = w.snapshot();
        let bad = |f: &dyn Fn(&mut Snapshot)| {
            let mut s = good.clone();
            f(&mut s);
            World::restore(s).map(|_| ()).unwrap_err()
        };
        assert!(matches!(
            bad(&|s| s.animats.swap(0, 1)),
            WorldError::BadSnapshot(_)
        ));
        assert!(matches!(
            bad(&|s| s.next_id = s.animats.last().unwrap().id),
            WorldError::BadSnapshot(_)
        ));
        assert!(matches!(
            bad(&|s| {
                let p = s.animats[0].pos;
                s.animats[1].pos = p;
            }),
            WorldError::Occupied(_)
        ));
        assert!(matches!(
            bad(&|s| {
                let r = s
                    .animats
                    .iter_mut()
                    .find(|a| a.species == Species::Rabbit)
                    .unwrap();
                r.hunger = 3;
            }),
            WorldError::BadSnapshot(_)
        ));
        assert!(matches!(
            bad(&|s| s.params.vision = 0),
            WorldError::Params(_)
        ));
    }
}
