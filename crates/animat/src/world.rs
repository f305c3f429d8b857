//! The animat world: animats on the unbounded plane, their rules, and one step of the model
//! (MODELS.md section 3; seed 000, section II.B).

use crate::cells::{CellIndex, FREE, SPECIES, WINDOW_MAX, Window, kind_byte};
use crate::params::{FoxRule, Params, ParamsError, RabbitRule, Species};
use core_lattice::io::StateHasher;
use core_lattice::rng::{RngExt, SimRng, shuffle, stream, stream_id, uniform01};
use rustc_hash::FxHashSet;
use spatial::plane::{PlaneError, PlaneGrid, Pos};
use std::time::Instant;

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
const _: () = assert!(RING_MAX <= WINDOW_MAX);

/// One animat (a copy of its state, as [`World::animats`] and [`World::get`] return it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
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
/// [`World::flags`]): 32 bytes, half a cache line.
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

/// What an animat decided to do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Action {
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

/// Errors building a hand-made scene.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WorldError {
    /// Bad parameters.
    #[error(transparent)]
    Params(#[from] ParamsError),
    /// The cell is already occupied (at most one animat per cell).
    #[error("cell [{}, {}] is already occupied", .0[0], .0[1])]
    Occupied(Pos),
    /// An error of the search structure.
    #[error(transparent)]
    Plane(#[from] PlaneError),
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
    fox_rules: Vec<FoxRule>,
    rabbit_rules: Vec<RabbitRule>,
    vision2: u64,
    crowd2: u64,
    grid: PlaneGrid<Species>,
    /// Grid changes not yet applied (see [`GridOp`]); empty between steps.
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
    /// The same offsets as bit 0 of byte `dx + 2` of row `dy + 2` (see [`Near::rows`]), when
    /// `crowd_radius <= 2`.
    crowd_masks: [u64; NEAR_ROWS],
    /// Live animats (and, during a step, the ones that died in it and the newborns), sorted
    /// by id. During a step the records of the animats alive at its start are stale: their
    /// current state is in `hot`, and is copied back at the end of the step.
    recs: Vec<Rec>,
    /// [`RABBIT`] and [`DEAD`] bits of each record of `recs` (same index).
    flags: Vec<u8>,
    /// Ids of the rabbits eaten in the current step (their records are dead, though their
    /// [`DEAD`] bits are not set: finding a record by id would cost a search).
    eaten: FxHashSet<u64>,
    /// During a step: the records of the animats alive at its start, in visiting order
    /// (`hot[j]` is `recs[order[j]]`).
    hot: Vec<Rec>,
    /// During a step: the flags of `hot` (`hot_flags[j]` is `flags[order[j]]` at the start).
    hot_flags: Vec<u8>,
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

/// Query and work counters of one decision (added to the world's afterwards).
#[derive(Debug, Default)]
struct Tally {
    adjacent: u64,
    nearest: u64,
    count: u64,
    evals: u64,
    /// A query needed the grid while it lagged behind the logged changes.
    stale: bool,
}

/// A change of the grid, logged during a step and applied in order before the grid is next
/// read (a loop of independent updates instead of one dependent cache miss per move).
#[derive(Debug, Clone, Copy)]
enum GridOp {
    Insert(u64, Pos, Species),
    Remove(u64),
    Move(u64, Pos),
}

/// Half-side of the square of cells [`Near::rows`] holds.
const NEAR_HALF: i64 = 2;
/// How many turns ahead a turn's cells are prefetched.
const PREFETCH_TURNS: usize = 8;
/// Rows of [`Near::rows`].
const NEAR_ROWS: usize = 2 * NEAR_HALF as usize + 1;
// Rows are read through a window of half-side RING_MAX, which must hold their cells
// (x - NEAR_HALF ..= x - NEAR_HALF + 7).
const _: () = assert!(RING_MAX >= NEAR_HALF && RING_MAX >= 7 - NEAR_HALF);

/// The cells around the acting animat (the cell-index fast path), located once per turn.
struct Near<'a> {
    /// Window of half-side [`RING_MAX`] around the animat; `None` when the fast path is off.
    w: Option<Window<'a>>,
    /// The kind bytes of the `NEAR_ROWS` rows around the animat, read on first use.
    rows: Option<[u64; NEAR_ROWS]>,
}

impl Near<'_> {
    /// Kind bytes of rows `y - 2 ..= y + 2` around `p = [x, y]`, each holding cells
    /// `x - 2 ..= x + 5` as bytes 0..8 (byte `dx + 2` is cell `x + dx`). The window must be
    /// present.
    #[inline]
    fn rows(&mut self, p: Pos) -> &[u64; NEAR_ROWS] {
        self.parts(p).expect("rows need the window").1
    }

    /// The window and the row words ([`Near::rows`]), if the window is present.
    #[inline]
    fn parts(&mut self, p: Pos) -> Option<(&Window<'_>, &[u64; NEAR_ROWS])> {
        let w = self.w.as_ref()?;
        let rows = self
            .rows
            .get_or_insert_with(|| w.rows::<NEAR_ROWS>(p[0] - NEAR_HALF, p[1] - NEAR_HALF));
        Some((w, rows))
    }
}

/// The kind byte of cell `(x + dx, y + dy)` from [`Near::rows`] (`|dx|, |dy| <= 2`).
#[inline(always)]
fn row_cell(rows: &[u64; NEAR_ROWS], dx: i64, dy: i64) -> u8 {
    row_byte(rows, dx, dy) & SPECIES
}

/// The whole cell byte (kind and id bucket) of cell `(x + dx, y + dy)` from [`Near::rows`].
#[inline(always)]
fn row_byte(rows: &[u64; NEAR_ROWS], dx: i64, dy: i64) -> u8 {
    (rows[(dy + NEAR_HALF) as usize] >> (8 * (dx + NEAR_HALF))) as u8
}

/// The cells of [`Near::rows`] at squared distance exactly `d2` from the centre, as bit 0 of
/// their bytes.
const fn class_mask(d2: i64) -> [u64; NEAR_ROWS] {
    let mut m = [0u64; NEAR_ROWS];
    let mut dy = -NEAR_HALF;
    while dy <= NEAR_HALF {
        let mut dx = -NEAR_HALF;
        while dx <= NEAR_HALF {
            if dx * dx + dy * dy == d2 {
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
const RING_CLASSES: [[u64; NEAR_ROWS]; 5] = [
    class_mask(1),
    class_mask(2),
    class_mask(4),
    class_mask(5),
    class_mask(8),
];

/// Bit 0 of each byte of [`Near::rows`] whose cell holds kind byte `kb` (1 fox: bit 0 of the
/// byte; 2 rabbit: bit 1).
#[inline(always)]
fn kind_bits(rows: &[u64; NEAR_ROWS], kb: u8) -> [u64; NEAR_ROWS] {
    let shift = u32::from(kb - 1);
    rows.map(|r| (r >> shift) & 0x0101_0101_0101_0101)
}

/// How many cells of `bits` (from [`kind_bits`]) lie in `class` (at most one bit per byte and
/// `NEAR_ROWS` rows: byte sums stay below 256, and the multiplication adds them up into the
/// top byte).
#[inline(always)]
fn count_in(bits: &[u64; NEAR_ROWS], class: &[u64; NEAR_ROWS]) -> u64 {
    let sum = bits
        .iter()
        .zip(class)
        .fold(0u64, |acc, (&b, &m)| acc + (b & m));
    sum.wrapping_mul(0x0101_0101_0101_0101) >> 56
}

/// The cell of `bits` in `class` with the lowest id (`n` of them, `n >= 1`), around `p`:
/// the lowest id bucket of the cell bytes in `rows` decides, and ids are read only when
/// several cells share it.
fn lowest_in(
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

/// `p + d`, or `None` on overflow.
fn offset(p: Pos, d: [i64; 2]) -> Option<Pos> {
    Some([p[0].checked_add(d[0])?, p[1].checked_add(d[1])?])
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
            cell_search: grid.box_size() != spatial::plane::BoxSize::None,
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
            crowd_masks: {
                let r = params.crowd_radius.min(NEAR_HALF);
                let mut m = [0u64; NEAR_ROWS];
                for dy in -r..=r {
                    for dx in -r..=r {
                        if (dx, dy) != (0, 0) && (dx * dx + dy * dy) as u64 <= c * c {
                            m[(dy + NEAR_HALF) as usize] |= 1 << (8 * (dx + NEAR_HALF));
                        }
                    }
                }
                m
            },
            recs: Vec::new(),
            flags: Vec::new(),
            eaten: FxHashSet::default(),
            hot: Vec::new(),
            hot_flags: Vec::new(),
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
        let id = self.add_deferred(species, pos, age, hunger)?;
        self.flush_grid();
        Ok(id)
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

    /// [`World::add`], with the grid's insertion logged in `pending`.
    fn add_deferred(
        &mut self,
        species: Species,
        pos: Pos,
        age: u32,
        hunger: u32,
    ) -> Result<u64, WorldError> {
        if self.cells.occupied(pos) {
            return Err(WorldError::Occupied(pos));
        }
        let id = self.next_id;
        self.pending.push(GridOp::Insert(id, pos, species));
        self.cells
            .set(pos, kind_byte(species == Species::Rabbit), id);
        self.next_id += 1;
        self.recs.push(Rec {
            pos,
            id,
            age,
            hunger: if species == Species::Fox { hunger } else { 0 },
        });
        self.flags.push(if species == Species::Rabbit {
            RABBIT
        } else {
            0
        });
        match species {
            Species::Fox => self.foxes += 1,
            Species::Rabbit => self.rabbits += 1,
        }
        Ok(id)
    }

    /// The parameters.
    pub fn params(&self) -> &Params {
        &self.params
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
        (0..self.recs.len()).filter_map(|i| self.animat_at(i))
    }

    /// A live animat by id.
    pub fn get(&self, id: u64) -> Option<Animat> {
        self.index_of(id).and_then(|i| self.animat_at(i))
    }

    /// The animat of record `i`, if alive (between steps).
    fn animat_at(&self, i: usize) -> Option<Animat> {
        let f = self.flags[i];
        let r = self.recs[i];
        (f & DEAD == 0).then_some(Animat {
            id: r.id,
            species: species_of(f),
            pos: r.pos,
            age: r.age,
            hunger: r.hunger,
        })
    }

    /// Perception queries asked so far.
    pub fn queries(&self) -> QueryCounts {
        self.queries
    }

    /// The search structure (for work counters and diagnostics). It is built with
    /// [`PlaneGrid::without_cell_counts`] (the world's own cell index answers "is this cell
    /// free"), so its `is_occupied` scans a box rather than doing one lookup.
    pub fn grid(&self) -> &PlaneGrid<Species> {
        &self.grid
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
    /// and counting queries scan cell rings outward up to radius 8 before falling back to the
    /// grid boxes; both give the exact answers, so the trajectory does not change. Turning it
    /// off measures the grid boxes alone (seed 000's structure).
    pub fn set_cell_search(&mut self, on: bool) {
        self.cell_search = on && self.grid.box_size() != spatial::plane::BoxSize::None;
    }

    /// Measure the wall time of perception queries (`--timing`); off by default because the
    /// clock reads cost time themselves. Does not change the trajectory.
    pub fn set_timing(&mut self, on: bool) {
        self.timing = on;
    }

    /// Hash of every live animat's id, species, position, age and hunger, in id order, as 16
    /// hex digits.
    pub fn state_hash(&self) -> String {
        let mut h = StateHasher::new();
        for a in self.animats() {
            h.u64(a.id)
                .u64(a.species.code())
                .i64(a.pos[0])
                .i64(a.pos[1])
                .u64(a.age.into())
                .u64(a.hunger.into());
        }
        h.finish_hex()
    }

    fn index_of(&self, id: u64) -> Option<usize> {
        self.recs.binary_search_by_key(&id, |a| a.id).ok()
    }

    /// Runs `n` steps (stopping early if every animat has died).
    pub fn run(&mut self, n: u64) {
        for _ in 0..n {
            if self.recs.is_empty() {
                break;
            }
            self.step();
        }
    }

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

    /// Spreads the id buckets of the cell bytes ([`CellIndex::bucket`]) over the ids that can
    /// be alive during the next step (the live ones, sorted in `recs`, and at most `n`
    /// newborns) when the top bucket could overflow or the lower half of the buckets has
    /// gone unused. Buckets only speed up tie-breaks; any non-decreasing map gives the same
    /// answers.
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

    /// Chooses the action of animat `a`: the first rule whose condition holds. Asks only the
    /// queries each condition needs, in priority order.
    #[cfg(test)]
    fn decide(&mut self, a: &Animat) -> Action {
        self.decide_near(a).0
    }

    /// [`World::decide`], with the kind bytes around `a` ([`Near::rows`]) when the action
    /// moves or breeds and the cell-index fast path is on: applying it reads its free
    /// neighbours from them.
    fn decide_near(&mut self, a: &Animat) -> (Action, Option<[u64; NEAR_ROWS]>) {
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
                Action::Step(_) | Action::Wander | Action::Breed if near.w.is_some() => {
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

    /// The cells around `a` for the cell-index fast path (no window when the fast path is
    /// off or `a` is too near the `i64` limits).
    fn near(&self, a: &Animat) -> Near<'_> {
        Near {
            w: if self.cell_search {
                self.cells.window(a.pos, RING_MAX)
            } else {
                None
            },
            rows: None,
        }
    }

    /// Whether the grid lags behind the logged changes; if so, notes in `t` that the
    /// decision must be made again after [`World::flush_grid`].
    #[inline]
    fn stale(&self, t: &mut Tally) -> bool {
        t.stale = !self.pending.is_empty();
        t.stale
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

    /// The position of the nearest adjacent animat of `kind` (ties: lower id).
    fn nearest_adjacent(
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
        if self.stale(t) {
            return None;
        }
        let (id, _) = self.grid.nearest(a.pos, kind, ADJACENT_R2, Some(a.id))?;
        self.grid.get(id).map(|(p, _)| p)
    }

    fn adjacent(&self, a: &Animat, kind: Species, near: &mut Near<'_>, t: &mut Tally) -> bool {
        t.adjacent += 1;
        if let Some((_, rows)) = near.parts(a.pos) {
            let kb = kind_byte(kind == Species::Rabbit);
            let found = DIRECTIONS.iter().any(|d| row_cell(rows, d[0], d[1]) == kb);
            t.evals += u64::from(found);
            return found;
        }
        if self.stale(t) {
            return false;
        }
        self.grid.any_within(a.pos, kind, ADJACENT_R2, Some(a.id))
    }

    /// Position of the nearest animat of `kind` within vision (ties: lower id).
    fn nearest_seen(
        &self,
        a: &Animat,
        kind: Species,
        near: &mut Near<'_>,
        t: &mut Tally,
    ) -> Option<Pos> {
        t.nearest += 1;
        if near.w.is_some() {
            let k_max = RING_MAX.min(self.params.vision);
            let kb = kind_byte(kind == Species::Rabbit);
            let [x, y] = a.pos;
            let v2 = self.vision2;
            let mut evals = 0;
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
            let w = near.w.as_ref().expect("the window is present");
            // Best as (d2, position, id bucket, id once read): a tie of distances goes to
            // the lower bucket, and ids (in a larger array that is rarely in cache) are read
            // only when the buckets are equal too.
            type Best = Option<(u64, Pos, u8, Option<u64>)>;
            let mut best: Best = None;
            let mut look = |dx: i64, dy: i64, best: &mut Best| {
                let byte = w.byte(x + dx, y + dy);
                if byte & SPECIES == kb {
                    evals += 1;
                    let d2 = (dx * dx + dy * dy) as u64;
                    let c = [x + dx, y + dy];
                    let cb = byte >> 2;
                    match best {
                        _ if d2 > v2 => {}
                        None => *best = Some((d2, c, cb, None)),
                        Some((bd, bp, bb, bid)) => {
                            if d2 < *bd || (d2 == *bd && cb < *bb) {
                                *best = Some((d2, c, cb, None));
                            } else if d2 == *bd && cb == *bb {
                                let bi = *bid.get_or_insert_with(|| w.id(bp[0], bp[1]));
                                let id = w.id(c[0], c[1]);
                                if id < bi {
                                    *best = Some((d2, c, cb, Some(id)));
                                }
                            }
                        }
                    }
                }
            };
            for k in k_first..=k_max {
                for dx in -k..=k {
                    look(dx, -k, &mut best);
                    look(dx, k, &mut best);
                }
                for dy in (-k + 1)..k {
                    look(-k, dy, &mut best);
                    look(k, dy, &mut best);
                }
                // Every cell beyond ring k is at least k + 1 away: a best strictly nearer
                // than that is final (an equally near one could still win on id).
                let next = ((k + 1) * (k + 1)) as u64;
                if best.is_some_and(|(bd, _, _, _)| bd < next) || next > v2 {
                    t.evals += evals;
                    return best.map(|(_, p, _, _)| p);
                }
            }
            t.evals += evals;
        }
        if self.stale(t) {
            return None;
        }
        let (id, _) = self.grid.nearest(a.pos, kind, self.vision2, Some(a.id))?;
        self.grid.get(id).map(|(p, _)| p)
    }

    /// More than `crowd_max` animats (either species, `a` excluded) within `crowd_radius`.
    #[cfg(test)]
    fn overcrowded(&self, a: &Animat) -> bool {
        self.overcrowded_in(a, &mut self.near(a), &mut Tally::default())
    }

    fn overcrowded_in(&self, a: &Animat, near: &mut Near<'_>, t: &mut Tally) -> bool {
        t.count += 1;
        let n = self.params.crowd_max as usize + 1;
        let r = self.params.crowd_radius;
        if near.w.is_some() {
            if r <= NEAR_HALF {
                // Kind bytes are 0, 1 or 2: bit 0 or'ed with bit 1 marks an occupied cell;
                // the masks keep the cells within the radius.
                let rows = near.rows(a.pos);
                // At most one bit per byte and NEAR_ROWS rows: the byte sums stay below 256,
                // and the multiplication adds the bytes up into the top byte.
                let bits = rows
                    .iter()
                    .zip(&self.crowd_masks)
                    .fold(0u64, |acc, (&row, &m)| acc + ((row | row >> 1) & m));
                let count = (bits.wrapping_mul(0x0101_0101_0101_0101) >> 56) as usize;
                t.evals += count.min(n) as u64;
                return count >= n;
            }
            if r <= RING_MAX {
                let w = near.w.as_ref().expect("the window is present");
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
        if self.stale(t) {
            return false;
        }
        self.grid.at_least(a.pos, None, self.crowd2, Some(a.id), n)
    }

    /// At least `prey_needed` rabbits within vision.
    #[cfg(test)]
    fn enough_prey(&self, a: &Animat) -> bool {
        self.enough_prey_in(a, &mut self.near(a), &mut Tally::default())
    }

    fn enough_prey_in(&self, a: &Animat, near: &mut Near<'_>, t: &mut Tally) -> bool {
        t.count += 1;
        let n = self.params.prey_needed as usize;
        if let (Some(w), true) = (near.w.as_ref(), n > 0) {
            let k_max = RING_MAX.min(self.params.vision);
            let [x, y] = a.pos;
            let v2 = self.vision2;
            let kb = kind_byte(true);
            let mut count = 0usize;
            let mut look = |dx: i64, dy: i64| -> bool {
                if w.at(x + dx, y + dy) == kb && (dx * dx + dy * dy) as u64 <= v2 {
                    count += 1;
                }
                count >= n
            };
            let mut found = false;
            'rings: for k in 1..=k_max {
                for dx in -k..=k {
                    if look(dx, -k) || look(dx, k) {
                        found = true;
                        break 'rings;
                    }
                }
                for dy in (-k + 1)..k {
                    if look(-k, dy) || look(k, dy) {
                        found = true;
                        break 'rings;
                    }
                }
            }
            t.evals += count as u64;
            // Rings 1..=k_max cover the whole vision disc when k_max = vision.
            if found || k_max == self.params.vision {
                return found;
            }
        }
        if self.stale(t) {
            return false;
        }
        self.grid
            .at_least(a.pos, Some(Species::Rabbit), self.vision2, Some(a.id), n)
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
        self.pending.push(GridOp::Move(a.id, to));
        self.cells.relocate(a.pos, to);
        a.pos = to;
    }

    fn apply(&mut self, a: &mut Animat, action: Action, rows: Option<&[u64; NEAR_ROWS]>) {
        match action {
            Action::Stay => {}
            Action::Step(d) => self.try_step(a, d, rows),
            Action::Wander => {
                let d = DIRECTIONS[self.action_rng.random_range(0..8usize)];
                self.try_step(a, d, rows);
            }
            Action::Eat(pos) => {
                // The rabbit's record is found (and dropped) at the end of the step; until
                // then the set of eaten ids marks it dead.
                let rabbit = self.cells.id(pos);
                self.eaten.insert(rabbit);
                self.rabbits -= 1;
                self.pending.push(GridOp::Remove(rabbit));
                self.cells.clear(pos);
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
                if n > 0 {
                    let c = free[self.action_rng.random_range(0..n)];
                    self.add_deferred(a.species, c, 0, 0)
                        .expect("the birth cell was free");
                }
            }
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::GridBox;
    use Species::{Fox, Rabbit};

    /// Parameters for hand-built scenes: breeding always succeeds, nobody dies of age or
    /// hunger within a step.
    fn scene_params() -> Params {
        Params {
            foxes: 0,
            rabbits: 0,
            fox_breed_p: 1.0,
            rabbit_breed_p: 1.0,
            hungry_at: 5,
            starve: 100,
            fox_max_age: 1000,
            rabbit_max_age: 1000,
            prey_needed: 2,
            crowd_max: 3,
            crowd_radius: 2,
            ..Params::default()
        }
    }

    fn world(p: Params) -> World {
        World::empty(p, 1).unwrap()
    }

    fn only(rules_f: &[&str], rules_r: &[&str]) -> Params {
        Params {
            fox_rules: rules_f.iter().map(|s| s.to_string()).collect(),
            rabbit_rules: rules_r.iter().map(|s| s.to_string()).collect(),
            ..scene_params()
        }
    }

    #[test]
    fn flee_steps_directly_away_from_the_nearest_adjacent_fox() {
        let mut w = world(only(&[], &["flee"]));
        let r = w.add(Rabbit, [0, 0], 0, 0).unwrap();
        w.add(Fox, [1, 1], 0, 0).unwrap();
        w.step();
        assert_eq!(w.get(r).unwrap().pos, [-1, -1]);
        // Orthogonal fox (d2 = 1) is nearer than a diagonal one (d2 = 2).
        let mut w = world(only(&[], &["flee"]));
        let r = w.add(Rabbit, [0, 0], 0, 0).unwrap();
        w.add(Fox, [1, 1], 0, 0).unwrap();
        w.add(Fox, [0, -1], 0, 0).unwrap();
        w.step();
        assert_eq!(w.get(r).unwrap().pos, [0, 1]);
    }

    #[test]
    fn eat_removes_the_rabbit_and_resets_hunger() {
        let mut w = world(only(&["eat"], &[]));
        let f = w.add(Fox, [0, 0], 0, 7).unwrap();
        let r = w.add(Rabbit, [1, 0], 0, 0).unwrap();
        w.step();
        assert!(w.get(r).is_none());
        assert_eq!(w.rabbits(), 0);
        // Hunger reset to 0 by eating, then +1 at the end of the turn.
        assert_eq!(w.get(f).unwrap().hunger, 1);
        assert!(!w.grid().is_occupied([1, 0]));
        // A fox that is not hungry does not eat.
        let mut w = world(only(&["eat"], &[]));
        w.add(Fox, [0, 0], 0, 4).unwrap();
        let r = w.add(Rabbit, [1, 0], 0, 0).unwrap();
        w.step();
        assert!(w.get(r).is_some());
    }

    #[test]
    fn an_eaten_rabbit_does_not_act() {
        // Whatever the order, the rabbit acts only if it moves before the fox; with flee it
        // would step away. Run several seeds: when the fox goes first, the rabbit is gone and
        // has not moved; the world never holds a dead rabbit.
        for seed in 0..20 {
            let mut w = World::empty(only(&["eat"], &["flee"]), seed).unwrap();
            w.add(Fox, [0, 0], 0, 7).unwrap();
            let r = w.add(Rabbit, [1, 0], 0, 0).unwrap();
            w.step();
            match w.get(r) {
                Some(a) => assert_eq!(a.pos, [2, 0]),
                None => assert_eq!(w.rabbits(), 0),
            }
        }
    }

    #[test]
    fn fox_breeding_needs_prey_and_room() {
        // Two foxes side by side, not hungry, two rabbits within vision: breeds.
        let scene = |rabbits: &[Pos], crowd: &[Pos]| {
            let mut w = world(only(&["breed"], &[]));
            let f = w.add(Fox, [0, 0], 0, 0).unwrap();
            w.add(Fox, [10, 10], 0, 0).unwrap(); // far fox: no partner
            for &p in rabbits {
                w.add(Rabbit, p, 0, 0).unwrap();
            }
            for &p in crowd {
                w.add(Rabbit, p, 0, 0).unwrap();
            }
            (w, f)
        };
        // No adjacent fox: no breeding.
        let (mut w, _) = scene(&[[30, 0], [0, 30]], &[]);
        w.step();
        assert_eq!(w.foxes(), 2);
        // Adjacent partner, enough prey.
        let (mut w, _) = scene(&[[30, 0], [0, 30]], &[]);
        w.add(Fox, [1, 0], 0, 0).unwrap();
        w.step();
        assert!(w.foxes() > 3, "breeding refused with prey and room");
        // Prey short: only one rabbit within vision (prey_needed = 2).
        let (mut w, _) = scene(&[[30, 0], [100, 100]], &[]);
        w.add(Fox, [1, 0], 0, 0).unwrap();
        w.step();
        assert_eq!(w.foxes(), 3, "breeding allowed with prey short");
        // Overcrowded for both foxes: within radius 2 of [0, 0] the partner and 4 rabbits
        // (5 > crowd_max 3); of [1, 0] the fox and 3 rabbits (4 > 3).
        let (mut w, _) = scene(&[[30, 0], [0, 30]], &[[-1, 0], [0, -1], [-1, -1], [1, -1]]);
        w.add(Fox, [1, 0], 0, 0).unwrap();
        w.step();
        assert_eq!(w.foxes(), 3, "breeding allowed when overcrowded");
    }

    #[test]
    fn rabbit_breeding_refused_when_overcrowded() {
        let mut w = world(only(&[], &["breed"]));
        w.add(Rabbit, [0, 0], 0, 0).unwrap();
        w.add(Rabbit, [1, 0], 0, 0).unwrap();
        w.step();
        assert!(w.rabbits() >= 3);
        let mut w = world(only(&[], &["breed"]));
        // A dense 3x3 block: every rabbit has more than 3 others within radius 2.
        for x in 0..3 {
            for y in 0..3 {
                w.add(Rabbit, [x, y], 0, 0).unwrap();
            }
        }
        w.step();
        assert_eq!(w.rabbits(), 9);
    }

    #[test]
    fn crowding_and_prey_thresholds_are_exact() {
        // crowd_max = 3, crowd_radius = 2: exactly 3 others within radius 2 (one exactly at
        // distance 2) is not overcrowded, 4 is; [2, 1] at d2 = 5 never counts.
        let mut w = world(scene_params());
        let me = w.add(Rabbit, [0, 0], 0, 0).unwrap();
        w.add(Fox, [2, 0], 0, 0).unwrap();
        w.add(Rabbit, [1, 1], 0, 0).unwrap();
        w.add(Rabbit, [2, 1], 0, 0).unwrap();
        w.add(Rabbit, [0, -2], 0, 0).unwrap();
        let a = w.get(me).unwrap();
        assert!(!w.overcrowded(&a));
        w.add(Fox, [-1, 0], 0, 0).unwrap();
        assert!(w.overcrowded(&a));
        // prey_needed = 2: rabbits within vision 60, the one at [60, 0] exactly on the edge.
        let mut w = world(scene_params());
        let f = w.add(Fox, [0, 0], 0, 0).unwrap();
        w.add(Rabbit, [60, 0], 0, 0).unwrap();
        w.add(Rabbit, [43, 43], 0, 0).unwrap(); // d2 = 3698 > 3600: unseen
        let a = w.get(f).unwrap();
        assert!(!w.enough_prey(&a));
        w.add(Rabbit, [0, -60], 0, 0).unwrap();
        assert!(w.enough_prey(&a));
    }

    #[test]
    fn newborns_act_next_step_and_ids_increase() {
        let mut w = world(only(&[], &["breed"]));
        w.add(Rabbit, [0, 0], 0, 0).unwrap();
        w.add(Rabbit, [1, 0], 0, 0).unwrap();
        w.step();
        let ages: Vec<(u64, u32)> = w.animats().map(|a| (a.id, a.age)).collect();
        assert_eq!(&ages[..2], &[(0, 1), (1, 1)]);
        for &(id, age) in &ages[2..] {
            assert!(id >= 2);
            assert_eq!(age, 0, "newborn acted in its birth step");
        }
    }

    #[test]
    fn blocked_steps_stay_put() {
        // Hunting fox whose step towards the rabbit is blocked by another rabbit.
        let mut w = world(only(&["hunt"], &[]));
        let f = w.add(Fox, [0, 0], 0, 9).unwrap();
        w.add(Rabbit, [1, 1], 0, 0).unwrap();
        w.add(Rabbit, [5, 5], 0, 0).unwrap();
        w.step();
        assert_eq!(w.get(f).unwrap().pos, [0, 0]);
        // Unblocked: it moves diagonally towards the rabbit.
        let mut w = world(only(&["hunt"], &[]));
        let f = w.add(Fox, [0, 0], 0, 9).unwrap();
        w.add(Rabbit, [5, 3], 0, 0).unwrap();
        w.step();
        assert_eq!(w.get(f).unwrap().pos, [1, 1]);
        // A fleeing rabbit with its escape cell taken stays.
        let mut w = world(only(&[], &["flee"]));
        let r = w.add(Rabbit, [0, 0], 0, 0).unwrap();
        w.add(Fox, [1, 0], 0, 0).unwrap();
        w.add(Fox, [-1, 0], 0, 0).unwrap();
        w.step();
        // Nearest adjacent fox: both at d2 = 1, lower id (the one at [1, 0]); away is [-1, 0],
        // occupied.
        assert_eq!(w.get(r).unwrap().pos, [0, 0]);
    }

    #[test]
    fn ties_go_to_the_lower_id() {
        // Two rabbits equally near the fox, on opposite sides; the lower id wins.
        for (first, second, want) in [([3, 0], [-3, 0], [1, 0]), ([-3, 0], [3, 0], [-1, 0])] {
            let mut w = world(only(&["hunt"], &[]));
            w.add(Rabbit, first, 0, 0).unwrap();
            w.add(Rabbit, second, 0, 0).unwrap();
            let f = w.add(Fox, [0, 0], 0, 9).unwrap();
            w.step();
            assert_eq!(w.get(f).unwrap().pos, want);
        }
    }

    #[test]
    fn seek_mate_and_herd_step_towards_the_nearest() {
        let mut w = world(only(&["seek_mate"], &["herd"]));
        let f = w.add(Fox, [0, 0], 0, 0).unwrap();
        w.add(Fox, [0, 20], 0, 0).unwrap();
        let r = w.add(Rabbit, [40, 0], 0, 0).unwrap();
        w.add(Rabbit, [40, -10], 0, 0).unwrap();
        w.step();
        let fp = w.get(f).unwrap().pos;
        assert!(fp == [0, 1] || fp == [0, 0], "{fp:?}");
        let rp = w.get(r).unwrap().pos;
        assert_eq!(rp, [40, -1]);
        // Hungry foxes do not seek mates; out of vision nothing is seen.
        let mut w = world(only(&["seek_mate"], &["herd"]));
        let f = w.add(Fox, [0, 0], 0, 9).unwrap();
        w.add(Fox, [0, 20], 0, 0).unwrap();
        let r = w.add(Rabbit, [1000, 0], 0, 0).unwrap();
        w.step();
        assert_eq!(w.get(f).unwrap().pos, [0, 0]);
        assert_eq!(w.get(r).unwrap().pos, [1000, 0]);
    }

    #[test]
    fn cell_search_and_grid_boxes_agree_on_hand_built_ties() {
        // Orthogonal before diagonal, then lower id, through both paths.
        for cells in [true, false] {
            let mut w = world(only(&[], &["flee"]));
            w.set_cell_search(cells);
            let r = w.add(Rabbit, [0, 0], 0, 0).unwrap();
            w.add(Fox, [1, 1], 0, 0).unwrap();
            w.add(Fox, [0, -1], 0, 0).unwrap();
            w.add(Fox, [-1, 0], 0, 0).unwrap();
            w.step();
            // [0, -1] (id 2) and [-1, 0] (id 3) both at d2 = 1: id 2 wins, flee to [0, 1].
            assert_eq!(w.get(r).unwrap().pos, [0, 1], "cells {cells}");
            // Nearest within vision: equal distance 9 + 16 = 25 on both sides, lower id wins;
            // the one at d2 = 25 on ring 5 against one at d2 = 26 on ring 5 too.
            let mut w = world(only(&["hunt"], &[]));
            w.set_cell_search(cells);
            w.add(Rabbit, [-5, 1], 0, 0).unwrap(); // d2 = 26
            w.add(Rabbit, [4, -3], 0, 0).unwrap(); // d2 = 25, id 1
            w.add(Rabbit, [-3, 4], 0, 0).unwrap(); // d2 = 25, id 2
            let f = w.add(Fox, [0, 0], 0, 9).unwrap();
            w.step();
            assert_eq!(w.get(f).unwrap().pos, [1, -1], "cells {cells}");
            // Beyond the 8 rings: a rabbit at distance 20 is found through the grid.
            let mut w = world(only(&["hunt"], &[]));
            w.set_cell_search(cells);
            w.add(Rabbit, [0, -20], 0, 0).unwrap();
            let f = w.add(Fox, [0, 0], 0, 9).unwrap();
            w.step();
            assert_eq!(w.get(f).unwrap().pos, [0, -1], "cells {cells}");
        }
    }

    #[test]
    fn starvation_and_old_age() {
        let p = Params {
            starve: 3,
            fox_max_age: 10,
            rabbit_max_age: 2,
            ..only(&[], &[])
        };
        let mut w = world(p);
        w.add(Fox, [0, 0], 0, 2).unwrap();
        w.add(Fox, [10, 0], 10, 0).unwrap();
        w.add(Rabbit, [20, 0], 1, 0).unwrap();
        w.step();
        // hunger 3 (not > 3), age 11 > 10, age 2 (not > 2).
        assert_eq!((w.foxes(), w.rabbits()), (1, 1));
        w.step();
        assert_eq!((w.foxes(), w.rabbits()), (0, 0));
    }

    #[test]
    fn perception_is_lazy() {
        // A hungry fox with a rabbit adjacent eats after exactly one query, even with foxes
        // and rabbits all around.
        let mut w = world(scene_params());
        w.add(Fox, [0, 0], 0, 9).unwrap();
        w.add(Rabbit, [1, 0], 0, 0).unwrap();
        let q0 = w.queries();
        let a = w.get(0).unwrap();
        assert_eq!(w.decide(&a), Action::Eat([1, 0]));
        let q = w.queries();
        assert_eq!(q.total() - q0.total(), 1);
        assert_eq!(q.adjacent, 1);
        assert_eq!(a.id, 0);

        // A sated fox with no fox adjacent: breed asks one adjacency query and stops; hunt is
        // skipped without a query (not hungry); seek_mate asks one nearest query and fires.
        let mut w = world(scene_params());
        w.add(Fox, [0, 0], 0, 0).unwrap();
        w.add(Fox, [0, 10], 0, 0).unwrap();
        for x in 0..5 {
            w.add(Rabbit, [20 + x, 0], 0, 0).unwrap();
        }
        assert_eq!(w.decide(&w.get(0).unwrap()), Action::Step([0, 1]));
        assert_eq!(
            w.queries(),
            QueryCounts {
                adjacent: 1,
                nearest: 1,
                count: 0
            }
        );

        // A rabbit with a fox adjacent flees after one query.
        let mut w = world(scene_params());
        w.add(Rabbit, [0, 0], 0, 0).unwrap();
        w.add(Fox, [1, 0], 0, 0).unwrap();
        w.add(Rabbit, [-1, 0], 0, 0).unwrap();
        assert_eq!(w.decide(&w.get(0).unwrap()), Action::Step([-1, 0]));
        assert_eq!(w.queries().total(), 1);

        // Over a whole step of a real run, fewer queries than the eager "ask everything"
        // (5 per animat) would need.
        let mut w = World::new(Params::default(), 3).unwrap();
        let n = w.foxes() + w.rabbits();
        w.step();
        assert!(w.queries().total() < 5 * n);
    }

    #[test]
    fn same_seed_same_run_and_seeds_differ() {
        let p = Params {
            foxes: 50,
            rabbits: 300,
            start_radius: 40,
            ..Params::default()
        };
        let mut a = World::new(p.clone(), 5).unwrap();
        let mut b = World::new(p.clone(), 5).unwrap();
        let mut c = World::new(p, 6).unwrap();
        a.run(50);
        b.run(50);
        c.run(50);
        assert_eq!(a.state_hash(), b.state_hash());
        assert_ne!(a.state_hash(), c.state_hash());
    }

    #[test]
    fn start_is_on_distinct_cells_in_the_disc() {
        let p = Params {
            grid_box: GridBox::Side(7),
            ..Params::default()
        };
        let w = World::new(p.clone(), 9).unwrap();
        assert_eq!(w.foxes(), p.foxes);
        assert_eq!(w.rabbits(), p.rabbits);
        let mut cells: Vec<Pos> = w.animats().map(|a| a.pos).collect();
        let r = p.start_radius;
        assert!(cells.iter().all(|c| c[0] * c[0] + c[1] * c[1] <= r * r));
        cells.sort();
        cells.dedup();
        assert_eq!(cells.len() as u64, p.foxes + p.rabbits);
        w.grid().validate().unwrap();
    }
}
