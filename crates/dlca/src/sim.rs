//! The DLCA simulation (MODELS.md section 1; seed 000 sections II.A, III, IV.A).

use crate::params::{ParamError, Params, Search};
use crate::record::Records;
use crate::rigid::RigidStore;
use core_lattice::io::StateHasher;
use core_lattice::rng::{DirectionSampler, SimRng, shuffle, stream, stream_id, uniform01};
use core_lattice::{Lattice, MAX_DIM};
use spatial::lattice::{AllPairs, ContactSearch, ItemId, LatticeGridBoxes, Occupancy, SiteSets};
use std::sync::OnceLock;
use std::time::Instant;

/// Random stream purposes of a DLCA run (see `core_lattice::rng::stream_id`).
const STREAM_PLACEMENT: u32 = 1;
const STREAM_DYNAMICS: u32 = 2;

/// The contact search in use. The `lattice` strategy keeps the clusters itself, as rigid
/// clusters over an occupancy lattice (see `rigid.rs`); the others search the k-index arrays
/// of [`SiteSets`].
enum Engine {
    AllPairs(AllPairs),
    Grid(Box<LatticeGridBoxes>),
    Lattice(Box<RigidStore>),
    /// The `lattice` strategy in 4 and 5 dimensions (see [`RIGID_MAX_DIM`]).
    Occupancy(Occupancy),
}

/// Highest dimension in which the `lattice` strategy uses rigid clusters. Beyond it a fractal
/// cluster has nearly every particle on every face and about `2d - 1` probes per particle and
/// direction, so the lists cost more than moving every particle: measured in 5D (L = 24, 1%
/// fill) 2.9 s and 470 MB with rigid clusters against 1.6 s and 47 MB with the plain
/// occupancy lattice (k-index arrays, leading-particle contact checks).
const RIGID_MAX_DIM: usize = 3;

impl Engine {
    fn search(&mut self) -> &mut dyn ContactSearch {
        match self {
            Engine::AllPairs(s) => s,
            Engine::Grid(s) => s.as_mut(),
            Engine::Lattice(_) => unreachable!("the lattice strategy keeps its own clusters"),
            Engine::Occupancy(s) => s,
        }
    }
    fn kind(&self) -> Search {
        match self {
            Engine::AllPairs(_) => Search::AllPairs,
            Engine::Grid(_) => Search::Grid,
            Engine::Lattice(_) | Engine::Occupancy(_) => Search::Lattice,
        }
    }
}

/// Bounding box of a cluster along each axis, relative to its anchor (its first site), in
/// minimum-image offsets. Kept only while grid boxes are in use, to decide when to double the
/// box side. Exact while the cluster spans less than half the lattice on every axis; beyond
/// that the grid has stopped paying anyway (`3A >= L`). Correctness never depends on it: the
/// grid-box search is exact for every box side.
#[derive(Debug, Clone, Copy, Default)]
struct BBox {
    lo: [i64; MAX_DIM],
    hi: [i64; MAX_DIM],
}

/// Something that happened to the search during the run, for logs and `run.json`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SearchEvent {
    /// Sweep during which it happened (0: at start).
    pub sweep: u64,
    /// What happened.
    pub what: String,
}

/// The state of a run between two sweeps, for checkpoints (`--checkpoint-every`, `--resume`):
/// [`Simulation::restore`] continues it to the same final state as an uninterrupted run.
/// Serialisable with serde (the `dlca` binary writes it in `core_lattice::io`'s checkpoint
/// envelope).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Snapshot {
    params: Params,
    seed: u64,
    sweep: u64,
    rng: SimRng,
    /// Live clusters in increasing id, with their sites (k-indices).
    clusters: Vec<(ItemId, Vec<u64>)>,
    /// One more than the largest cluster id.
    id_bound: u64,
    particles: u64,
    largest: u64,
    /// The search in use, and the grid box side if it is the grid.
    strategy: Search,
    grid_side: Option<u64>,
    strategy_reason: String,
    events: Vec<SearchEvent>,
    records: Records,
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

    /// Sweeps done when it was saved.
    pub fn sweeps(&self) -> u64 {
        self.sweep
    }

    /// Change where the resumed run stops (`--target-clusters`, `--max-sweeps`): the only
    /// parameters that may differ from the saved run's.
    pub fn set_stop(&mut self, target_clusters: u64, max_sweeps: Option<u64>) {
        self.params.target_clusters = target_clusters;
        self.params.max_sweeps = max_sweeps;
    }
}

/// A DLCA run: the lattice, the clusters, the search, the random stream and the records.
///
/// Built from `(Params, seed)`; the trajectory is a pure function of them, whatever the search
/// strategy (tests check bit-identical state hashes across strategies).
pub struct Simulation {
    params: Params,
    seed: u64,
    lattice: Lattice,
    /// The clusters as k-index arrays, for the all-pairs and grid searches. Empty while the
    /// `lattice` strategy, which keeps the clusters itself, is in use.
    sets: SiteSets,
    /// With the `lattice` strategy: the clusters as k-index arrays, built on demand by
    /// [`Simulation::sets`] and dropped at every change.
    materialized: OnceLock<SiteSets>,
    engine: Engine,
    strategy_reason: String,
    bbox: Vec<BBox>,
    rng: SimRng,
    directions: DirectionSampler,
    particles: u64,
    sweep: u64,
    largest: u64,
    events: Vec<SearchEvent>,
    records: Records,
    check_invariants: bool,
    /// Size of each cluster when its sites were last sorted.
    sorted_size: Vec<usize>,
    // Scratch buffers reused by every move.
    old: Vec<u64>,
    contacts: Vec<ItemId>,
    order: Vec<ItemId>,
}

/// The state [`Simulation::new`] and [`Simulation::restore`] build differently; everything
/// else starts out the same ([`Simulation::assemble`]).
struct Assembly {
    params: Params,
    seed: u64,
    lattice: Lattice,
    sets: SiteSets,
    records: Records,
    strategy_reason: String,
    rng: SimRng,
    directions: DirectionSampler,
    particles: u64,
    sweep: u64,
    largest: u64,
}

impl Simulation {
    /// A simulation from `a`, with the all-pairs engine (the caller installs the chosen
    /// search) and empty scratch buffers.
    fn assemble(a: Assembly) -> Self {
        let sorted_size = vec![0; a.sets.id_bound()];
        Simulation {
            records: a.records,
            params: a.params,
            seed: a.seed,
            lattice: a.lattice,
            sets: a.sets,
            materialized: OnceLock::new(),
            engine: Engine::AllPairs(AllPairs::new()),
            strategy_reason: a.strategy_reason,
            bbox: Vec::new(),
            rng: a.rng,
            directions: a.directions,
            particles: a.particles,
            sweep: a.sweep,
            largest: a.largest,
            events: Vec::new(),
            check_invariants: false,
            sorted_size,
            old: Vec::new(),
            contacts: Vec::new(),
            order: Vec::new(),
        }
    }

    /// Validate `params`, place the particles, form the initial clusters (face-adjacent
    /// particles belong to one cluster from the start) and set up the search.
    pub fn new(params: Params, seed: u64) -> Result<Self, ParamError> {
        params.validate()?;
        let lattice = params.lattice()?;
        let n = params.particles()?;
        let directions =
            DirectionSampler::gravity(lattice.dim(), params.gravity).expect("gravity validated");
        let sites = place_particles(
            &lattice,
            n,
            &mut stream(seed, stream_id(STREAM_PLACEMENT, 0)),
        );
        let mut sets = SiteSets::new(lattice.clone());
        for cluster in initial_clusters(&lattice, &sites) {
            sets.push(cluster);
        }
        let largest = sets
            .live()
            .iter()
            .map(|&id| sets.sites(id).len() as u64)
            .max()
            .unwrap_or(0);
        let (kind, reason) = choose_strategy(&params, &lattice, n);
        let mut sim = Simulation::assemble(Assembly {
            records: Records::new(&params),
            params,
            seed,
            lattice,
            sets,
            strategy_reason: reason,
            rng: stream(seed, stream_id(STREAM_DYNAMICS, 0)),
            directions,
            particles: n,
            sweep: 0,
            largest,
        });
        sim.install(kind)?;
        sim.records.record_sweep(0, sim.clusters(), largest, None);
        Ok(sim)
    }

    /// The state of the run now, to continue later with [`Simulation::restore`].
    pub fn snapshot(&self) -> Snapshot {
        let sets = self.sets();
        let mut ids = sets.live().to_vec();
        ids.sort_unstable();
        Snapshot {
            params: self.params.clone(),
            seed: self.seed,
            sweep: self.sweep,
            rng: self.rng.clone(),
            clusters: ids
                .into_iter()
                .map(|id| (id, sets.sites(id).to_vec()))
                .collect(),
            id_bound: sets.id_bound() as u64,
            particles: self.particles,
            largest: self.largest,
            strategy: self.strategy(),
            grid_side: match &self.engine {
                Engine::Grid(g) => Some(g.side()),
                _ => None,
            },
            strategy_reason: self.strategy_reason.clone(),
            events: self.events.clone(),
            records: self.records.clone(),
        }
    }

    /// Continue the run saved in `snapshot`: it reaches the same final state (the same
    /// `state_hash` and per-sweep records) as the run that was never interrupted.
    pub fn restore(snapshot: Snapshot) -> Result<Self, ParamError> {
        let s = snapshot;
        s.params.validate()?;
        let lattice = s.params.lattice()?;
        let directions =
            DirectionSampler::gravity(lattice.dim(), s.params.gravity).expect("gravity validated");
        let mut sets = SiteSets::new(lattice.clone());
        let mut clusters = s.clusters.into_iter().peekable();
        let mut dead = Vec::new();
        for id in 0..s.id_bound {
            match clusters.next_if(|(c, _)| u64::from(*c) == id) {
                Some((_, sites)) => sets.push(sites),
                None => {
                    dead.push(sets.push(Vec::new()));
                    0
                }
            };
        }
        for id in dead {
            sets.remove(id);
        }
        let mut sim = Simulation::assemble(Assembly {
            records: s.records,
            params: s.params,
            seed: s.seed,
            lattice,
            sets,
            strategy_reason: s.strategy_reason,
            rng: s.rng,
            directions,
            particles: s.particles,
            sweep: s.sweep,
            largest: s.largest,
        });
        // The grid resumes with the box side it had (the parameters stay as given).
        let grid_box = sim.params.grid_box;
        if s.strategy == Search::Grid {
            sim.params.grid_box = s.grid_side;
        }
        sim.install(s.strategy)?;
        sim.params.grid_box = grid_box;
        sim.events = s.events;
        Ok(sim)
    }

    /// Build the engine `kind` and register every cluster in it.
    fn install(&mut self, kind: Search) -> Result<(), ParamError> {
        self.engine = match kind {
            Search::Lattice => {
                let too_large = ParamError::TooLarge {
                    bytes: Occupancy::bytes_needed(&self.lattice),
                    sites: self.lattice.volume(),
                    budget: self.params.max_memory,
                };
                if too_large_for(&self.lattice, self.params.max_memory) {
                    return Err(too_large);
                }
                if self.lattice.dim() <= RIGID_MAX_DIM {
                    let store = RigidStore::new(&self.sets).ok_or(too_large)?;
                    self.sets = SiteSets::new(self.lattice.clone());
                    Engine::Lattice(Box::new(store))
                } else {
                    // Clusters merge as soon as they touch, so they are separated before every
                    // move.
                    Engine::Occupancy(
                        Occupancy::new(&self.lattice, self.params.max_memory)
                            .map_err(|_| too_large)?
                            .with_separated_items(true),
                    )
                }
            }
            Search::AllPairs | Search::Auto => Engine::AllPairs(AllPairs::new()),
            Search::Grid => {
                self.bbox = vec![BBox::default(); self.sets.id_bound()];
                let mut max_extent = 1;
                for i in 0..self.sets.live().len() {
                    let id = self.sets.live()[i];
                    self.bbox[id as usize] = self.measure_bbox(id);
                    max_extent = max_extent.max(self.extent(id));
                }
                let side = match self.params.grid_box {
                    Some(a) => a.max(max_extent.next_power_of_two()),
                    None => {
                        // Seed 000 section V: in the dilute regime a box about the spacing of
                        // the clusters keeps each halo to a few clusters.
                        let spacing = (self.lattice.volume() as f64
                            / self.sets.len().max(1) as f64)
                            .powf(1.0 / self.lattice.dim() as f64);
                        (spacing.ceil() as u64).max(max_extent).next_power_of_two()
                    }
                };
                let mut grid = LatticeGridBoxes::new(&self.lattice, side).expect("power of two");
                if grid.stops_paying() {
                    self.note(format!(
                        "grid box {side} has 3A >= L on some axis: grid-boxing does not pay, using all-pairs"
                    ));
                    self.bbox.clear();
                    Engine::AllPairs(AllPairs::new())
                } else {
                    grid.set_side(side, &self.sets).expect("power of two");
                    self.note(format!("grid box side {side}"));
                    Engine::Grid(Box::new(grid))
                }
            }
        };
        if matches!(self.engine, Engine::AllPairs(_) | Engine::Occupancy(_)) {
            let ids: Vec<ItemId> = self.sets.live().to_vec();
            for id in ids {
                self.engine.search().insert(&self.sets, id);
            }
        }
        Ok(())
    }

    fn note(&mut self, what: String) {
        tracing::info!(sweep = self.sweep, "{what}");
        self.events.push(SearchEvent {
            sweep: self.sweep,
            what,
        });
    }

    /// Turn on a full check of the model's invariants after every move: particles conserved,
    /// every cluster connected, no two clusters face-adjacent. O(N) per move: for tests.
    pub fn with_invariant_checks(mut self, on: bool) -> Self {
        self.check_invariants = on;
        if on {
            self.assert_invariants();
        }
        self
    }

    /// Run sweeps until [`Simulation::is_done`].
    pub fn run(&mut self) {
        self.run_with(|_| {});
    }

    /// Run sweeps until [`Simulation::is_done`], calling `after_sweep` after each.
    pub fn run_with(&mut self, mut after_sweep: impl FnMut(&Simulation)) {
        while !self.is_done() {
            self.sweep();
            after_sweep(self);
        }
    }

    /// Whether the run has reached `--target-clusters` or `--max-sweeps`.
    pub fn is_done(&self) -> bool {
        self.clusters() <= self.params.target_clusters
            || self.params.max_sweeps.is_some_and(|m| self.sweep >= m)
    }

    /// One sweep: every cluster existing at its start, in a fresh random order, tries one move
    /// (skipping clusters merged away earlier in the sweep).
    pub fn sweep(&mut self) {
        let start = self.params.timing.then(Instant::now);
        self.materialized.take();
        self.sweep += 1;
        self.records.begin_sweep(self.sweep);
        let mut order = std::mem::take(&mut self.order);
        order.clear();
        order.extend_from_slice(self.live());
        order.sort_unstable();
        shuffle(&mut self.rng, &mut order);
        for &id in &order {
            let live = match &self.engine {
                Engine::Lattice(store) => store.contains(id),
                _ => self.sets.contains(id),
            };
            if live {
                self.visit(id);
            }
        }
        self.order = order;
        let seconds = start.map(|t| t.elapsed().as_secs_f64());
        self.records
            .record_sweep(self.sweep, self.clusters(), self.largest, seconds);
    }

    /// Live cluster ids.
    fn live(&self) -> &[ItemId] {
        match &self.engine {
            Engine::Lattice(store) => store.live(),
            _ => self.sets.live(),
        }
    }

    /// Steps 1-4 of MODELS.md section 1 for cluster `id`.
    fn visit(&mut self, id: ItemId) {
        let size = match &self.engine {
            Engine::Lattice(store) => store.len_of(id),
            _ => self.sets.sites(id).len(),
        };
        // 1. Move with probability temperature * size^-gamma (no draw when that is 1).
        let p = if self.params.mobility_exponent == 0.0 {
            self.params.temperature
        } else {
            self.params.temperature * (size as f64).powf(-self.params.mobility_exponent)
        };
        if p < 1.0 && uniform01(&mut self.rng) >= p {
            return;
        }
        // 2. A direction, weighted by gravity.
        let dir = self.directions.sample(&mut self.rng);
        if let Engine::Lattice(store) = &mut self.engine {
            // 3.-4. Translate and find the contacts in one go.
            if store.try_move(id, dir, &mut self.contacts).is_err() {
                return;
            }
            self.records.record_move(self.contacts.len());
            if !self.contacts.is_empty() {
                self.merge_contacts(id);
            }
            if self.check_invariants {
                self.materialized.take();
                self.assert_invariants();
            }
            return;
        }
        // 3. Translate; a wall blocks the whole cluster.
        if self.sets.translate(id, dir, &mut self.old).is_err() {
            return;
        }
        self.engine
            .search()
            .moved(&self.sets, id, &self.old, self.sets.sites(id), dir);
        // 4. Merge with every cluster now in contact; the lowest id survives.
        let examined = self
            .engine
            .search()
            .contacts(&self.sets, id, &mut self.contacts);
        self.records.record_move(examined);
        if !self.contacts.is_empty() {
            self.merge_contacts(id);
        }
        if self.check_invariants {
            self.assert_invariants();
        }
    }

    fn merge_contacts(&mut self, mover: ItemId) {
        let mut group = std::mem::take(&mut self.contacts);
        group.push(mover);
        group.sort_unstable();
        let survivor = group[0];
        if let Engine::Lattice(store) = &mut self.engine {
            for &other in &group[1..] {
                store.merge(survivor, other);
            }
            store.finish(survivor);
            self.largest = self.largest.max(store.len_of(survivor) as u64);
            group.clear();
            self.contacts = group;
            return;
        }
        for &other in &group[1..] {
            let anchors = (self.sets.sites(survivor)[0], self.sets.sites(other)[0]);
            let from_len = self.sets.merge(survivor, other);
            self.engine
                .search()
                .merge(&self.sets, survivor, other, from_len);
            if matches!(self.engine, Engine::Grid(_)) {
                self.merge_bbox(survivor, other, anchors);
            }
        }
        let size = self.sets.sites(survivor).len();
        self.largest = self.largest.max(size as u64);
        // Keep large clusters' sites in k-index order (re-sorted each time they double), so
        // moves walk the occupancy lattice in memory order. Amortised O(log s) per particle.
        if size >= 64 && size >= 2 * self.sorted_size[survivor as usize] {
            self.sets.sort_sites(survivor);
            self.sorted_size[survivor as usize] = size;
        }
        group.clear();
        self.contacts = group;
        if matches!(self.engine, Engine::Grid(_)) {
            self.maybe_double(survivor);
        }
    }

    /// Union of the bounding boxes of `into` and `from` in the frame of the union's anchor.
    fn merge_bbox(&mut self, into: ItemId, from: ItemId, (anchor_into, anchor_from): (u64, u64)) {
        let delta = self.lattice.displacement(anchor_into, anchor_from);
        let (a, b) = (self.bbox[into as usize], self.bbox[from as usize]);
        let mut u = a;
        for axis in 0..self.lattice.dim() {
            u.lo[axis] = a.lo[axis].min(delta[axis] + b.lo[axis]);
            u.hi[axis] = a.hi[axis].max(delta[axis] + b.hi[axis]);
        }
        // The union's array starts with the larger part: its anchor may be `from`'s.
        if self.sets.sites(into)[0] != anchor_into {
            for axis in 0..self.lattice.dim() {
                u.lo[axis] -= delta[axis];
                u.hi[axis] -= delta[axis];
            }
        }
        self.bbox[into as usize] = u;
    }

    /// Bounding box of cluster `id` from its sites (minimum image relative to its anchor).
    fn measure_bbox(&self, id: ItemId) -> BBox {
        let sites = self.sets.sites(id);
        let mut b = BBox::default();
        for &k in sites {
            let d = self.lattice.displacement(sites[0], k);
            for axis in 0..self.lattice.dim() {
                b.lo[axis] = b.lo[axis].min(d[axis]);
                b.hi[axis] = b.hi[axis].max(d[axis]);
            }
        }
        b
    }

    /// Largest extent (sites spanned) of cluster `id` over the axes.
    fn extent(&self, id: ItemId) -> u64 {
        let b = &self.bbox[id as usize];
        (0..self.lattice.dim())
            .map(|a| (b.hi[a] - b.lo[a] + 1) as u64)
            .max()
            .unwrap_or(1)
    }

    /// Seed 000 section II.A: double the box side until it holds the largest cluster; once
    /// `3A >= L` on some axis, abandon grid-boxing for all-pairs.
    fn maybe_double(&mut self, id: ItemId) {
        let extent = self.extent(id);
        let Engine::Grid(grid) = &self.engine else {
            return;
        };
        let mut side = grid.side();
        if extent <= side {
            return;
        }
        while side < extent {
            side *= 2;
        }
        let probe = LatticeGridBoxes::new(&self.lattice, side).expect("power of two");
        if probe.stops_paying() {
            self.note(format!(
                "largest cluster spans {extent} sites: grid box {side} has 3A >= L, continuing as all-pairs"
            ));
            self.bbox = Vec::new();
            self.engine = Engine::AllPairs(AllPairs::new());
        } else {
            if let Engine::Grid(grid) = &mut self.engine {
                grid.set_side(side, &self.sets).expect("power of two");
            }
            self.note(format!(
                "largest cluster spans {extent} sites: grid box doubled to {side}"
            ));
        }
    }

    /// Panic unless: the particle count is conserved, no site holds two particles, every
    /// cluster is connected, and no two clusters are face-adjacent.
    pub fn assert_invariants(&self) {
        use std::collections::{HashMap, VecDeque};
        if let Engine::Lattice(store) = &self.engine {
            // The store's own bookkeeping: occupancy, labels, face and probe lists.
            let mut copy = store.as_ref().clone();
            copy.check();
        }
        let sets = self.sets();
        let mut owner: HashMap<u64, ItemId> = HashMap::new();
        for &id in sets.live() {
            for &k in sets.sites(id) {
                assert!(
                    owner.insert(k, id).is_none(),
                    "site {k} holds two particles"
                );
            }
        }
        assert_eq!(
            owner.len() as u64,
            self.particles,
            "particles not conserved"
        );
        for &id in sets.live() {
            let sites = sets.sites(id);
            let mut seen = std::collections::HashSet::from([sites[0]]);
            let mut queue = VecDeque::from([sites[0]]);
            while let Some(k) = queue.pop_front() {
                for n in self.lattice.neighbours(k) {
                    match owner.get(&n) {
                        Some(&o) if o == id && seen.insert(n) => queue.push_back(n),
                        Some(&o) if o == id => {}
                        Some(&o) => panic!("clusters {id} and {o} are face-adjacent at {k}-{n}"),
                        None => {}
                    }
                }
            }
            assert_eq!(seen.len(), sites.len(), "cluster {id} is not connected");
        }
    }

    /// The parameters.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The seed the run was built from.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The lattice.
    pub fn lattice(&self) -> &Lattice {
        &self.lattice
    }

    /// The clusters as k-index arrays (absolute sites). With the `lattice` strategy, which
    /// stores clusters as an origin plus relative sites, the arrays are built on the first call
    /// after a change (O(N)) and cached until the next sweep.
    pub fn sets(&self) -> &SiteSets {
        match &self.engine {
            Engine::Lattice(store) => self.materialized.get_or_init(|| store.to_sets()),
            _ => &self.sets,
        }
    }

    /// Number of particles.
    pub fn particles(&self) -> u64 {
        self.particles
    }

    /// Sweeps done.
    pub fn sweeps(&self) -> u64 {
        self.sweep
    }

    /// Number of clusters.
    pub fn clusters(&self) -> u64 {
        self.live().len() as u64
    }

    /// Size of the largest cluster.
    pub fn largest(&self) -> u64 {
        self.largest
    }

    /// The search in use now.
    pub fn strategy(&self) -> Search {
        self.engine.kind()
    }

    /// Why the strategy was chosen (for `auto`: the regime it found).
    pub fn strategy_reason(&self) -> &str {
        &self.strategy_reason
    }

    /// Changes of the search during the run (box doublings, fall-back to all-pairs).
    pub fn events(&self) -> &[SearchEvent] {
        &self.events
    }

    /// What was recorded.
    pub fn records(&self) -> &Records {
        &self.records
    }

    /// Hash of every particle's site and cluster id: clusters in increasing id, each cluster's
    /// sites in increasing k-index, fed as `(id, k)` little-endian `u64` pairs into XXH3-64.
    pub fn state_hash(&self) -> String {
        let sets = self.sets();
        let mut ids: Vec<ItemId> = sets.live().to_vec();
        ids.sort_unstable();
        let mut h = StateHasher::new();
        let mut sites = Vec::new();
        for id in ids {
            sites.clear();
            sites.extend_from_slice(sets.sites(id));
            sites.sort_unstable();
            for &k in &sites {
                h.u64(u64::from(id)).u64(k);
            }
        }
        h.finish_hex()
    }
}

/// Whether the occupancy lattice of `lattice` needs more than `budget` bytes.
fn too_large_for(lattice: &Lattice, budget: u64) -> bool {
    Occupancy::bytes_needed(lattice) > budget
}

/// Which strategy to use, and why (MODELS.md section 1, `auto`; seed 000 section V).
fn choose_strategy(params: &Params, lattice: &Lattice, particles: u64) -> (Search, String) {
    let bytes = Occupancy::bytes_needed(lattice);
    let density = particles as f64 / lattice.volume() as f64;
    match params.search {
        Search::Auto => {
            if bytes > params.max_memory {
                (
                    Search::Grid,
                    format!(
                        "auto: occupancy lattice needs {bytes} bytes, over --max-memory {}: grid boxes",
                        params.max_memory
                    ),
                )
            } else if density < 1e-4 && lattice.volume() > 1 << 26 {
                (
                    Search::Grid,
                    format!(
                        "auto: dilute limit (density {density:.2e} on {} sites): grid boxes, whose cost follows the particles rather than the lattice",
                        lattice.volume()
                    ),
                )
            } else {
                (
                    Search::Lattice,
                    format!(
                        "auto: occupancy lattice fits ({bytes} bytes, density {density:.3}): lattice lookups, O(2d) per moved particle"
                    ),
                )
            }
        }
        other => (other, format!("{} requested", other.name())),
    }
}

/// `n` distinct sites drawn uniformly (rejection sampling), in draw order. Taken sites are
/// tracked in a bitset (one bit per site) when the lattice has at most 64 sites per particle,
/// else in a hash set; both give the same draws.
fn place_particles(lattice: &Lattice, n: u64, rng: &mut SimRng) -> Vec<u64> {
    let volume = lattice.volume();
    let mut sites = Vec::with_capacity(n as usize);
    let mut draw = |taken: &mut dyn FnMut(u64) -> bool| {
        while (sites.len() as u64) < n {
            let k = ((uniform01(rng) * volume as f64) as u64).min(volume - 1);
            if taken(k) {
                sites.push(k);
            }
        }
    };
    if volume <= n.saturating_mul(64) {
        let mut bits = vec![0u64; volume.div_ceil(64) as usize];
        draw(&mut |k| {
            let (w, b) = ((k / 64) as usize, 1u64 << (k % 64));
            let fresh = bits[w] & b == 0;
            bits[w] |= b;
            fresh
        });
    } else {
        let mut taken = std::collections::HashSet::with_capacity(n as usize);
        draw(&mut |k| taken.insert(k));
    }
    sites
}

/// Group face-adjacent particles into clusters (union-find), numbered in order of their first
/// particle in `sites`; each cluster's sites in `sites` order.
fn initial_clusters(lattice: &Lattice, sites: &[u64]) -> Vec<Vec<u64>> {
    let index: std::collections::HashMap<u64, usize> =
        sites.iter().enumerate().map(|(i, &k)| (k, i)).collect();
    let mut parent: Vec<usize> = (0..sites.len()).collect();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for (i, &k) in sites.iter().enumerate() {
        for n in lattice.neighbours(k) {
            if let Some(&j) = index.get(&n) {
                let (a, b) = (find(&mut parent, i), find(&mut parent, j));
                if a != b {
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
    }
    let mut cluster_of_root = std::collections::HashMap::new();
    let mut clusters: Vec<Vec<u64>> = Vec::new();
    for (i, &k) in sites.iter().enumerate() {
        let root = find(&mut parent, i);
        let c = *cluster_of_root.entry(root).or_insert_with(|| {
            clusters.push(Vec::new());
            clusters.len() - 1
        });
        clusters[c].push(k);
    }
    clusters
}

#[cfg(test)]
mod tests {
    use super::*;
    use core_lattice::Boundary;

    #[test]
    fn adjacent_particles_start_as_one_cluster() {
        let l = Lattice::new(&[5, 4], &[Boundary::Periodic, Boundary::Wall]).unwrap();
        let at = |x, y| l.encode(&[x, y]).unwrap();
        // (0,0)-(4,0) touch across the periodic x axis; (2,0)-(2,3) do not touch (wall in y).
        let sites = vec![
            at(0, 0),
            at(2, 2),
            at(4, 0),
            at(2, 0),
            at(2, 3),
            at(3, 3),
            at(1, 1),
        ];
        let c = initial_clusters(&l, &sites);
        assert_eq!(
            c,
            vec![
                vec![at(0, 0), at(4, 0)],
                vec![at(2, 2), at(2, 3), at(3, 3)],
                vec![at(2, 0)],
                vec![at(1, 1)]
            ]
        );
    }

    #[test]
    fn placement_is_distinct_and_seeded() {
        let l = Lattice::periodic(&[10, 10]).unwrap();
        let a = place_particles(&l, 90, &mut stream(1, 1));
        let b = place_particles(&l, 90, &mut stream(1, 1));
        assert_eq!(a, b);
        // Sparse (hash set) and dense (bitset) tracking draw the same sites.
        let big = Lattice::periodic(&[1000, 1000]).unwrap();
        let sparse = place_particles(&big, 1000, &mut stream(2, 1));
        let dense = place_particles(&big, 20_000, &mut stream(2, 1));
        assert_eq!(&dense[..1000], &sparse[..]);
        let mut s = a.clone();
        s.sort_unstable();
        s.dedup();
        assert_eq!(s.len(), 90);
        assert!(s.iter().all(|&k| k < 100));
    }
}
