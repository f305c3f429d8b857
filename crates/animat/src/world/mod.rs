//! The animat world: the animats on the unbounded plane, their stored records, the structures
//! that index them by cell, and the public face of the model ([`World`]): construction (the
//! default start and hand-built scenes), accessors and the state hash.
//!
//! The model is the foxes-and-rabbits animat model of Hawick, James & Scogings (2006),
//! "Grid-Boxing for Spatial Simulation Performance Optimisation", section II.B, as
//! `docs/animat.md` states it. The rest of the world lives in child modules, each using only
//! this module and the ones listed after it:
//!
//! - `step`: one step (visiting order, turns, ageing and deaths, the id order listed again);
//! - `rules`: the fox and rabbit rule lists, the action each chooses and how actions apply;
//! - `perception`: the neighbour queries the rules ask, from the cell index
//!   ([`spatial::cells`], with its near cache and wide queries) or the grid boxes;
//! - `checkpoint`: the [`Snapshot`] of a world between steps and its exact restore;
//! - `tests`: hand-built scenes.
//!
//! Invariants between steps: `ranks` lists exactly the live animats in id order, each as the
//! index of its record in `recs` (with `flags` parallel to `recs`; records of the animats that
//! died in the last step may remain there, with their `DEAD` bit set, until the next step
//! drops them), and `ids` holds their ids in the same order (strictly increasing); every live
//! animat stands alone on its cell in `cells` and, with the cell search off, is in `grid` at
//! that cell (`pending` is empty; with the cell search on `grid` is empty); `foxes` and
//! `rabbits` count the live animats; every id is below `next_id` and none is reused. During a
//! step `grid` may lag behind `cells` by the changes logged in `pending` (see `step`).

mod checkpoint;
mod perception;
mod rules;
mod step;
#[cfg(test)]
mod tests;

use crate::params::{ANIMAT_BYTES, FoxRule, MAX_ANIMATS, Params, ParamsError, RabbitRule, Species};
use spatial::cells::near::{NEAR_ROWS, NEAR_WINDOW_MIN, disc_mask};
use spatial::cells::{CellIndex, KIND_A, KIND_B, WINDOW_MAX};

use core_lattice::rng::{RngExt, SimRng, stream, stream_id};
use run_io::StateHasher;
use serde::{Deserialize, Serialize};
pub use spatial::cells::{TILE, TILE_BYTES};
use spatial::plane::{BoxSize, PlaneError, PlaneGrid, Pos};

pub use checkpoint::Snapshot;

/// Random stream purposes of a run (each its own stream of the run seed).
const STREAM_PLACEMENT: u32 = 1;
/// The visiting order of each step.
const STREAM_ORDER: u32 = 2;
/// Breeding draws, birth cells and wander directions.
const STREAM_ACTION: u32 = 3;

/// Squared radius of "adjacent": Chebyshev distance 1 is squared Euclidean distance <= 2.
pub const ADJACENT_R2: u64 = 2;

/// The 8 unit steps, in a fixed order (wander directions, birth cells).
pub const DIRECTIONS: [[i64; 2]; 8] = [
    [1, 0],
    [1, 1],
    [0, 1],
    [-1, 1],
    [-1, 0],
    [-1, -1],
    [0, -1],
    [1, -1],
];

/// Largest cell-ring radius the cell-index searches scan before handing a query to the grid.
const RING_MAX: i64 = 8;
const _: () = assert!(RING_MAX <= WINDOW_MAX && RING_MAX >= NEAR_WINDOW_MIN);

/// One animat (a copy of its state, as [`World::animats`] and [`World::get`] return it, and
/// as a [`Snapshot`] keeps it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Animat {
    /// Unique id; ids increase with creation and are never reused.
    pub id: u64,
    /// Fox or rabbit.
    pub species: Species,
    /// Cell.
    pub pos: Pos,
    /// Steps lived.
    pub age: u32,
    /// Foxes: steps since the fox last ate. Always 0 for rabbits.
    pub hunger: u32,
}

/// The stored state of an animat apart from its species and liveness (kept in
/// `World::flags`): 32 bytes, half a cache line.
#[derive(Debug, Clone, Copy)]
struct Rec {
    pos: Pos,
    id: u64,
    age: u32,
    hunger: u32,
}

/// Flag bit: the animat is a rabbit (else a fox).
const RABBIT: u8 = 1;
/// Flag bit: the animat died in the current step (removed at its end).
const DEAD: u8 = 2;

/// The cell index's kind byte of a species: foxes are [`KIND_A`], rabbits [`KIND_B`].
#[inline]
fn kind_byte(rabbit: bool) -> u8 {
    if rabbit { KIND_B } else { KIND_A }
}

fn species_of(flags: u8) -> Species {
    if flags & RABBIT != 0 {
        Species::Rabbit
    } else {
        Species::Fox
    }
}

/// Perception queries asked, by kind (for the lazy-perception tests and diagnostics).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct QueryCounts {
    /// "Is an animat of a kind adjacent" (including "which adjacent one is nearest").
    pub adjacent: u64,
    /// "Nearest animat of a kind within vision".
    pub nearest: u64,
    /// Counting queries (overcrowding, enough prey).
    pub count: u64,
}

impl QueryCounts {
    /// All queries.
    pub fn total(&self) -> u64 {
        self.adjacent + self.nearest + self.count
    }
}

/// Errors building a hand-made scene.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WorldError {
    /// Bad parameters.
    #[error(transparent)]
    Params(#[from] ParamsError),
    /// The cell is already occupied (at most one animat per cell).
    #[error("cell [{}, {}] is already occupied", .0[0], .0[1])]
    Occupied(Pos),
    /// A snapshot no world could have written (ids out of order, a rabbit with hunger).
    #[error("impossible snapshot: {0}")]
    BadSnapshot(String),
    /// An error of the search structure.
    #[error(transparent)]
    Plane(#[from] PlaneError),
    /// More animat records than a `u32` index can address.
    #[error("too many animats: at most {} records", u32::MAX)]
    TooMany,
}

/// Counters of one step.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepStats {
    /// Seconds spent in perception queries (only with [`World::set_timing`]; else 0).
    pub search_seconds: f64,
    /// Distance evaluations of the search structure during the step.
    pub distance_evals: u64,
}

/// The simulation: a pure function of `(Params, seed)`; every grid-box setting gives the same
/// trajectory.
#[derive(Debug, Clone)]
pub struct World {
    params: Params,
    /// The run seed (its random streams are derived from it).
    seed: u64,
    fox_rules: Vec<FoxRule>,
    rabbit_rules: Vec<RabbitRule>,
    vision2: u64,
    crowd2: u64,
    /// The grid boxes: kept up to date only with the cell search off (empty, holding the box
    /// size, with it on).
    grid: PlaneGrid<Species>,
    /// Grid changes not yet applied (see [`GridOp`]); empty between steps and with the cell
    /// search on.
    pending: Vec<GridOp>,
    /// Which animat stands on each cell (always maintained; read by perception when
    /// `cell_search` is on).
    cells: CellIndex,
    /// Answer small-radius perception from the cell index before the grid boxes.
    cell_search: bool,
    /// Distance evaluations made by cell-index searches since the last step boundary.
    cell_evals: u64,
    /// Reused visiting-order buffer.
    order: Vec<u32>,
    /// Cell offsets within `crowd_radius` (origin excluded), when `crowd_radius <= RING_MAX`.
    crowd_offsets: Vec<[i64; 2]>,
    /// The same offsets as bit 0 of byte `dx + 2` of row `dy + 2` (see
    /// [`Near::rows`](spatial::cells::near::Near::rows)), when `crowd_radius <= 2`.
    crowd_masks: [u64; NEAR_ROWS],
    /// The animats' records in the order of the last step's turns, then the animats born in
    /// it (in id order); during a step, in the order of its turns, then its newborns. Records
    /// of dead animats stay (with [`DEAD`] set) until the next step's gather drops them.
    recs: Vec<Rec>,
    /// [`RABBIT`] and [`DEAD`] bits of each record of `recs` (same index).
    flags: Vec<u8>,
    /// The live animats in id order, as indices into `recs` (during a step: the animats alive
    /// at its start, as indices into the previous step's `recs`, until the step's end).
    ranks: Vec<u32>,
    /// The ids of `ranks` (same order, so strictly increasing).
    ids: Vec<u64>,
    /// During a step: where each animat of `ranks` takes its turn (`inv[k]` is the index in
    /// `recs` of the animat of rank `k`).
    inv: Vec<u32>,
    /// During a step, when the ids alive at its start are dense enough: the rank of id
    /// `ids[0] + i` at index `i` (`u32::MAX` for an id not listed), so that finding a prey's
    /// record is two reads and not a binary search over `ids`; empty otherwise.
    rank_of: Vec<u32>,
    /// Reused buffers: the records and flags of the previous order while a step gathers them.
    spare_recs: Vec<Rec>,
    spare_flags: Vec<u8>,
    /// During a step: the number of animats alive at its start and the first id born in it
    /// (newborn `id` has record `born_at + (id - first_born)`).
    born_at: usize,
    first_born: u64,
    next_id: u64,
    steps: u64,
    order_rng: SimRng,
    action_rng: SimRng,
    queries: QueryCounts,
    timing: bool,
    search_seconds: f64,
    /// Seconds spent applying logged grid changes inside decisions (timing on), left out of
    /// `search_seconds`.
    flush_seconds: f64,
    total_distance_evals: u64,
    foxes: u64,
    rabbits: u64,
    /// Births that would make more records than this do not happen ([`MAX_ANIMATS`] unless
    /// lowered by [`World::set_animat_limit`]).
    animat_limit: u64,
}

/// A change of the grid, logged during a step and applied in order before the grid is next
/// read (a loop of independent updates instead of one dependent cache miss per move).
#[derive(Debug, Clone, Copy)]
enum GridOp {
    Insert(u64, Pos, Species),
    Remove(u64),
    Move(u64, Pos),
}

impl World {
    /// An empty world (no animats) with validated parameters: for hand-built scenes.
    ///
    /// # Errors
    /// [`WorldError::Params`] if the parameters are invalid.
    pub fn empty(params: Params, seed: u64) -> Result<Self, WorldError> {
        params.validate()?;
        let fox_rules = params.fox_rule_list()?;
        let rabbit_rules = params.rabbit_rule_list()?;
        // The cell index answers "is this cell free", so the grid need not count cells.
        let grid = PlaneGrid::without_cell_counts(params.grid_box.box_size(params.vision))?;
        let v = params.vision as u64;
        let c = params.crowd_radius as u64;
        Ok(World {
            fox_rules,
            rabbit_rules,
            vision2: v * v,
            crowd2: c * c,
            cell_search: grid.box_size() != BoxSize::None,
            grid,
            pending: Vec::new(),
            cells: CellIndex::default(),
            cell_evals: 0,
            order: Vec::new(),
            crowd_offsets: if params.crowd_radius <= RING_MAX {
                let r = params.crowd_radius;
                (-r..=r)
                    .flat_map(|dy| (-r..=r).map(move |dx| [dx, dy]))
                    .filter(|&[dx, dy]| (dx, dy) != (0, 0) && (dx * dx + dy * dy) as u64 <= c * c)
                    .collect()
            } else {
                Vec::new()
            },
            // `c <= MAX_RADIUS = 2^30`: `c * c` fits in i64.
            crowd_masks: disc_mask(1, (c * c) as i64),
            recs: Vec::new(),
            flags: Vec::new(),
            ranks: Vec::new(),
            ids: Vec::new(),
            inv: Vec::new(),
            rank_of: Vec::new(),
            spare_recs: Vec::new(),
            spare_flags: Vec::new(),
            born_at: 0,
            first_born: 0,
            next_id: 0,
            steps: 0,
            order_rng: stream(seed, stream_id(STREAM_ORDER, 0)),
            action_rng: stream(seed, stream_id(STREAM_ACTION, 0)),
            queries: QueryCounts::default(),
            timing: false,
            search_seconds: 0.0,
            flush_seconds: 0.0,
            total_distance_evals: 0,
            foxes: 0,
            rabbits: 0,
            animat_limit: MAX_ANIMATS,
            seed,
            params,
        })
    }

    /// The default start: `foxes + rabbits` animats on distinct cells drawn uniformly in the
    /// disc of radius `start_radius` around the origin (foxes first, so foxes have the lower
    /// ids), with ages uniform in `[0, max_age / 2]` and fox hunger uniform in
    /// `[0, hungry_at]`, all from the placement stream of `seed`.
    ///
    /// # Errors
    /// [`WorldError::Params`] if the parameters are invalid.
    pub fn new(params: Params, seed: u64) -> Result<Self, WorldError> {
        let mut w = World::empty(params, seed)?;
        let mut rng = stream(seed, stream_id(STREAM_PLACEMENT, 0));
        let r = w.params.start_radius;
        let r2 = (r as i128) * (r as i128);
        let counts = [
            (Species::Fox, w.params.foxes),
            (Species::Rabbit, w.params.rabbits),
        ];
        for (species, n) in counts {
            let max_age = match species {
                Species::Fox => w.params.fox_max_age,
                Species::Rabbit => w.params.rabbit_max_age,
            };
            let mut placed = 0;
            while placed < n {
                let x = rng.random_range(-r..=r);
                let y = rng.random_range(-r..=r);
                if (x as i128) * (x as i128) + (y as i128) * (y as i128) > r2
                    || w.cells.occupied([x, y])
                {
                    continue;
                }
                let age = rng.random_range(0..=max_age / 2);
                let hunger = match species {
                    Species::Fox => rng.random_range(0..=w.params.hungry_at),
                    Species::Rabbit => 0,
                };
                w.add(species, [x, y], age, hunger)?;
                placed += 1;
            }
        }
        Ok(w)
    }

    /// Adds an animat (a newborn, or part of a hand-built scene) and returns its id.
    ///
    /// # Errors
    /// [`WorldError::Occupied`] if the cell holds an animat.
    pub fn add(
        &mut self,
        species: Species,
        pos: Pos,
        age: u32,
        hunger: u32,
    ) -> Result<u64, WorldError> {
        let id = self.next_id;
        self.insert(Animat {
            id,
            species,
            pos,
            age,
            hunger,
        })?;
        Ok(id)
    }

    /// Adds animat `a`, whose id is above every id so far (the next one, or a restored
    /// animat's), listed in `ranks` and in the grid.
    fn insert(&mut self, a: Animat) -> Result<(), WorldError> {
        self.add_deferred(a)?;
        // `add_deferred` keeps the record count within u32.
        self.ranks.push((self.recs.len() - 1) as u32);
        self.ids.push(a.id);
        self.flush_grid();
        Ok(())
    }

    /// Logs a change for the grid, which is kept only while the cell search is off (with it
    /// on, every query is answered from the cell index).
    #[inline]
    fn log(&mut self, op: GridOp) {
        if !self.cell_search {
            self.pending.push(op);
        }
    }

    /// Brings the grid up to date with the changes logged in `pending`, in order.
    fn flush_grid(&mut self) {
        for op in self.pending.drain(..) {
            match op {
                GridOp::Insert(id, pos, species) => self
                    .grid
                    .insert(id, pos, species)
                    .expect("ids are never reused"),
                GridOp::Remove(id) => {
                    self.grid.remove(id).expect("a live animat is in the grid");
                }
                GridOp::Move(id, to) => {
                    self.grid
                        .move_to(id, to)
                        .expect("a live animat is in the grid");
                }
            }
        }
    }

    /// [`World::insert`], with the grid's insertion logged in `pending` and without listing the
    /// animat in `ranks` (a newborn is listed at the end of its birth step). The next id is
    /// then the one after `a`'s.
    fn add_deferred(&mut self, a: Animat) -> Result<(), WorldError> {
        if self.cells.occupied(a.pos) {
            return Err(WorldError::Occupied(a.pos));
        }
        if self.recs.len() >= u32::MAX as usize {
            return Err(WorldError::TooMany);
        }
        debug_assert!(a.id >= self.next_id, "ids increase");
        let rabbit = a.species == Species::Rabbit;
        self.log(GridOp::Insert(a.id, a.pos, a.species));
        self.cells.set(a.pos, kind_byte(rabbit), a.id);
        self.next_id = a.id + 1;
        self.recs.push(Rec {
            pos: a.pos,
            id: a.id,
            age: a.age,
            hunger: if rabbit { 0 } else { a.hunger },
        });
        self.flags.push(if rabbit { RABBIT } else { 0 });
        match a.species {
            Species::Fox => self.foxes += 1,
            Species::Rabbit => self.rabbits += 1,
        }
        Ok(())
    }

    /// The parameters.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The run seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Steps done.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Live foxes.
    pub fn foxes(&self) -> u64 {
        self.foxes
    }

    /// Live rabbits.
    pub fn rabbits(&self) -> u64 {
        self.rabbits
    }

    /// Live animats, sorted by id (between steps).
    pub fn animats(&self) -> impl Iterator<Item = Animat> + '_ {
        self.ranks.iter().map(|&i| self.animat_at(i as usize))
    }

    /// A live animat by id.
    pub fn get(&self, id: u64) -> Option<Animat> {
        let k = self.ids.binary_search(&id).ok()?;
        Some(self.animat_at(self.ranks[k] as usize))
    }

    /// The animat of record `i`.
    fn animat_at(&self, i: usize) -> Animat {
        let f = self.flags[i];
        let r = self.recs[i];
        debug_assert_eq!(f & DEAD, 0);
        Animat {
            id: r.id,
            species: species_of(f),
            pos: r.pos,
            age: r.age,
            hunger: r.hunger,
        }
    }

    /// Perception queries asked so far.
    pub fn queries(&self) -> QueryCounts {
        self.queries
    }

    /// The grid boxes, while they are kept: with the cell search off (the grid-boxing paper's
    /// structure, and the exhaustive `none` mode). With the cell search on every query is
    /// answered from the cell index and there is no grid to maintain. The grid is built with
    /// [`PlaneGrid::without_cell_counts`] (the world's own cell index answers "is this cell
    /// free"), so its `is_occupied` scans a box rather than doing one lookup.
    pub fn grid(&self) -> Option<&PlaneGrid<Species>> {
        (!self.cell_search).then_some(&self.grid)
    }

    /// The grid-box size: of the grid boxes with the cell search off, and of the boxes the
    /// wide cell-index queries visit with it on.
    pub fn box_size(&self) -> BoxSize {
        self.grid.box_size()
    }

    /// Distance evaluations of the search structure since the start.
    pub fn distance_evals(&self) -> u64 {
        self.total_distance_evals + self.grid.distance_evals() + self.cell_evals
    }

    /// Whether small-radius perception reads the cell index first (see
    /// [`World::set_cell_search`]).
    pub fn cell_search(&self) -> bool {
        self.cell_search
    }

    /// Turns the cell-index search on or off. On by default with grid boxes, off (and ignored)
    /// in the exhaustive `none` mode, which stays the paper's "no grid" baseline. With it on,
    /// adjacency and overcrowding tests read the cells around the animat directly, and nearest
    /// and counting queries scan cell rings outward up to radius 8 before a wide search over
    /// the grid boxes that reads their animats from the cell index too; every path gives the
    /// exact answers, so the trajectory does not change. Turning it off measures the grid boxes
    /// alone (the paper's structure: Hawick, James & Scogings 2006, section III), which are then
    /// built from the animats and kept up to date on every change (turning it on drops them).
    pub fn set_cell_search(&mut self, on: bool) {
        let on = on && self.grid.box_size() != BoxSize::None;
        if on == self.cell_search {
            return;
        }
        self.flush_grid();
        self.total_distance_evals += self.grid.take_distance_evals();
        self.cell_search = on;
        self.grid = PlaneGrid::without_cell_counts(self.grid.box_size())
            .expect("the box size of an existing grid");
        if !on {
            for i in 0..self.ranks.len() {
                let a = self.animat_at(self.ranks[i] as usize);
                self.grid
                    .insert(a.id, a.pos, a.species)
                    .expect("ids are unique");
            }
        }
    }

    /// Measure the wall time of perception queries (`--timing`); off by default because the
    /// clock reads cost time themselves. Does not change the trajectory.
    pub fn set_timing(&mut self, on: bool) {
        self.timing = on;
    }

    /// Hash of every live animat's id, species, position, age and hunger, in id order, as 16
    /// hex digits.
    pub fn state_hash(&self) -> String {
        // The bytes go to the hasher a few kilobytes at a time: the same stream (and hash) as
        // six 8-byte updates an animat, for a fraction of the calls.
        let mut h = StateHasher::new();
        let mut buf = Vec::with_capacity(4096);
        for a in self.animats() {
            for v in [
                a.id,
                a.species.code(),
                a.pos[0] as u64,
                a.pos[1] as u64,
                a.age.into(),
                a.hunger.into(),
            ] {
                buf.extend_from_slice(&v.to_le_bytes());
            }
            if buf.len() > 4096 - 48 {
                h.bytes(&buf);
                buf.clear();
            }
        }
        h.bytes(&buf).finish_hex()
    }

    /// Memory the world takes, estimated: the cell index's tiles (36 KiB for each 64 x 64
    /// square holding an animat, or holding one earlier and kept for reuse) plus
    /// [`ANIMAT_BYTES`] per animat. The `animat` binary stops a run that outgrows its
    /// `--max-memory` with this.
    pub fn memory_bytes(&self) -> u64 {
        self.cells.memory_bytes() + self.recs.len() as u64 * ANIMAT_BYTES
    }

    /// Lowers the number of animats a world may hold (at most [`MAX_ANIMATS`], the default): a
    /// birth that would make more records than this does not happen. For tests of the cap
    /// without billions of animats.
    pub fn set_animat_limit(&mut self, limit: u64) {
        self.animat_limit = limit.min(MAX_ANIMATS);
    }

    /// Whether a birth may happen now (see [`World::set_animat_limit`]).
    fn may_give_birth(&self) -> bool {
        (self.recs.len() as u64) < self.animat_limit
    }

    /// Runs `n` steps (stopping early if every animat has died).
    pub fn run(&mut self, n: u64) {
        for _ in 0..n {
            if self.ranks.is_empty() {
                break;
            }
            self.step();
        }
    }
}
