//! The DLCA simulation ([`Simulation`]): Hawick, James & Scogings 2006, "Grid-Boxing for
//! Spatial Simulation Performance Optimisation", section II.A; the model as this code defines it
//! is in docs/dlca.md, "The model".
//!
//! This module owns the run: parameters, the random stream, the sweep (every cluster in a fresh
//! random order tries one move and merges with what it then touches) and the records. The
//! clusters and the contact search live in the installed strategy (`crate::store`), chosen and
//! installed by `strategy`; the initial state comes from `placement`; `checkpoint` holds
//! the state saved between sweeps.
//!
//! Invariants (checked after every move by [`Simulation::with_invariant_checks`]): the particle
//! count is conserved, no site holds two particles, every cluster is connected, and no two
//! clusters are face-adjacent. The trajectory is a pure function of `(Params, seed)`, whatever
//! the strategy.

mod checkpoint;
mod placement;
mod strategy;

/// The contact search a run of `params` on `lattice` with `particles` uses (`auto` resolved).
pub(crate) fn chosen_search(params: &Params, lattice: &Lattice, particles: u64) -> Search {
    strategy::choose(params, lattice, particles).0
}

/// Memory a checkpoint of a run with `particles` particles needs while it is written, beside
/// the run itself: the snapshot (8 bytes a site and a little per cluster) and its encoding,
/// 50 bytes a particle for both, and 16 MiB for buffers. Front ends keep this free
/// (`run_io::guard::MemoryWatch::reserve`).
pub fn checkpoint_reserve_bytes(particles: u64) -> u64 {
    (16 << 20) + 50 * particles
}

/// Peak memory of a run of `params`, estimated before it starts, in bytes:
/// [`PEAK_FIXED_BYTES`], then per particle `(d + 1)` [`PEAK_BYTES_PER_PARTICLE_AXIS`] and per
/// site [`PEAK_BYTES_PER_SITE_LATTICE`] when the run uses the occupancy lattice (`--search
/// lattice`, or `auto` where it fits), else `(d + 1)` [`PEAK_BYTES_PER_PARTICLE_AXIS_GRID`] and
/// [`PEAK_BYTES_PER_SITE`] (the placement's bitset). An upper bound of the measured peak RSS
/// (docs/dlca.md, "Memory", has the calibration table). 0 for parameters that do not validate.
pub fn peak_memory_bytes(params: &Params) -> u64 {
    let (Ok(lattice), Ok(n)) = (params.lattice(), params.particles()) else {
        return 0;
    };
    let (per_particle, per_site) = match chosen_search(params, &lattice, n) {
        Search::Lattice => (PEAK_BYTES_PER_PARTICLE_AXIS, PEAK_BYTES_PER_SITE_LATTICE),
        _ => (PEAK_BYTES_PER_PARTICLE_AXIS_GRID, PEAK_BYTES_PER_SITE),
    };
    let sites = (lattice.volume() as f64 * per_site) as u64;
    PEAK_FIXED_BYTES
        .saturating_add(n.saturating_mul(per_particle * (params.dim() as u64 + 1)))
        .saturating_add(sites)
}

/// The name of the contact search a run of valid `params` uses (`auto` resolved), for
/// messages.
pub fn chosen_search_name(params: &Params) -> &'static str {
    match (params.lattice(), params.particles()) {
        (Ok(lattice), Ok(n)) => chosen_search(params, &lattice, n).name(),
        _ => params.search.name(),
    }
}

pub use checkpoint::Snapshot;
pub use strategy::SearchEvent;

use crate::params::{
    PEAK_BYTES_PER_PARTICLE_AXIS, PEAK_BYTES_PER_PARTICLE_AXIS_GRID, PEAK_BYTES_PER_SITE,
    PEAK_BYTES_PER_SITE_LATTICE, PEAK_FIXED_BYTES, ParamError, Params, Search,
};
use crate::record::Records;
use crate::store::{ClusterArrays, ClusterStore, Engine};
use core_lattice::Lattice;
use core_lattice::rng::{DirectionSampler, SimRng, shuffle, stream, stream_id, uniform01};
use placement::{initial_clusters, place_particles};
use run_io::StateHasher;
use spatial::lattice::{ItemId, SiteSets};
use std::time::Instant;

/// Random stream purposes of a DLCA run (see `core_lattice::rng::stream_id`).
const STREAM_PLACEMENT: u32 = 1;
const STREAM_DYNAMICS: u32 = 2;

/// How many turns ahead a sweep asks for a cluster's record ([`ClusterStore::prefetch_record`]).
const RECORD_AHEAD: usize = 8;

/// How many turns ahead a sweep asks for a cluster's lists ([`ClusterStore::prefetch_lists`]).
const LISTS_AHEAD: usize = 3;

/// A DLCA run: the lattice, the clusters, the search, the random stream and the records.
///
/// Built from `(Params, seed)`; the trajectory is a pure function of them, whatever the search
/// strategy (tests check bit-identical state hashes across strategies).
pub struct Simulation {
    /// What [`Simulation::new`] and [`Simulation::restore`] build differently.
    run: RunState,
    /// The clusters and the contact search over them.
    engine: Engine,
    events: Vec<SearchEvent>,
    check_invariants: bool,
    /// No cluster can move any more: see [`Simulation::is_frozen`].
    frozen: bool,
    // Scratch buffers reused by every move.
    contacts: Vec<ItemId>,
    order: Vec<ItemId>,
}

/// The part of a [`Simulation`] that [`Simulation::new`] and [`Simulation::restore`] build
/// differently (fresh, or from a snapshot); everything else starts out the same
/// ([`Simulation::assemble`]).
struct RunState {
    params: Params,
    seed: u64,
    lattice: Lattice,
    records: Records,
    strategy_reason: String,
    rng: SimRng,
    directions: DirectionSampler,
    particles: u64,
    sweep: u64,
    largest: u64,
}

impl Simulation {
    /// A simulation from `a` with strategy `kind` (grid box side `grid_box` for the grid)
    /// installed over `clusters`, and empty scratch buffers.
    fn assemble(
        a: RunState,
        clusters: SiteSets,
        kind: Search,
        grid_box: Option<u64>,
    ) -> Result<Self, ParamError> {
        let mut notes = Vec::new();
        let engine = strategy::install(
            kind,
            ClusterArrays::new(clusters),
            &a.params,
            grid_box,
            &mut notes,
        )?;
        let mut sim = Simulation {
            run: a,
            engine,
            events: Vec::new(),
            check_invariants: false,
            frozen: false,
            contacts: Vec::new(),
            order: Vec::new(),
        };
        sim.note_all(notes);
        sim.update_frozen();
        Ok(sim)
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
        )?;
        let mut sets = SiteSets::new(lattice.clone());
        for cluster in initial_clusters(&lattice, &sites)? {
            sets.push(cluster);
        }
        let largest = sets
            .live()
            .iter()
            .map(|&id| sets.sites(id).len() as u64)
            .max()
            .unwrap_or(0);
        let (kind, reason) = strategy::choose(&params, &lattice, n);
        let grid_box = params.grid_box;
        let mut sim = Simulation::assemble(
            RunState {
                records: Records::new(&params),
                params,
                seed,
                lattice,
                strategy_reason: reason,
                rng: stream(seed, stream_id(STREAM_DYNAMICS, 0)),
                directions,
                particles: n,
                sweep: 0,
                largest,
            },
            sets,
            kind,
            grid_box,
        )?;
        sim.run
            .records
            .record_sweep(0, sim.clusters(), largest, None);
        Ok(sim)
    }

    /// The state of the run now, to continue later with [`Simulation::restore`].
    pub fn snapshot(&self) -> Snapshot {
        let sets = self.sets();
        let mut ids = sets.live().to_vec();
        ids.sort_unstable();
        Snapshot {
            params: self.run.params.clone(),
            seed: self.run.seed,
            sweep: self.run.sweep,
            rng: self.run.rng.clone(),
            clusters: ids
                .into_iter()
                .map(|id| (id, sets.sites(id).to_vec()))
                .collect(),
            id_bound: sets.id_bound() as u64,
            particles: self.run.particles,
            largest: self.run.largest,
            strategy: self.strategy(),
            grid_side: self.engine.grid_side(),
            strategy_reason: self.run.strategy_reason.clone(),
            events: self.events.clone(),
            records: self.run.records.clone(),
        }
    }

    /// Continue the run saved in `snapshot`: it reaches the same final state (the same
    /// `state_hash` and per-sweep records) as the run that was never interrupted.
    pub fn restore(snapshot: Snapshot) -> Result<Self, ParamError> {
        let s = snapshot;
        s.params.validate()?;
        let lattice = s.params.lattice()?;
        s.check(&lattice).map_err(ParamError::Checkpoint)?;
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
        // A grid resumes with the box side it had (the parameters stay as given).
        let grid_box = match s.strategy {
            Search::Grid | Search::GridDoubling => s.grid_side,
            _ => s.params.grid_box,
        };
        let mut sim = Simulation::assemble(
            RunState {
                records: s.records,
                params: s.params,
                seed: s.seed,
                lattice,
                strategy_reason: s.strategy_reason,
                rng: s.rng,
                directions,
                particles: s.particles,
                sweep: s.sweep,
                largest: s.largest,
            },
            sets,
            s.strategy,
            grid_box,
        )?;
        sim.events = s.events;
        Ok(sim)
    }

    /// Log `what` and record it as an event of the search.
    fn note(&mut self, what: String) {
        #[cfg(feature = "log")]
        tracing::info!(sweep = self.run.sweep, "{what}");
        self.events.push(SearchEvent {
            sweep: self.run.sweep,
            what,
        });
    }

    /// [`Simulation::note`] each of `notes`, in order.
    fn note_all(&mut self, notes: Vec<String>) {
        for what in notes {
            self.note(what);
        }
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

    /// Whether the run has reached `--target-clusters` or `--max-sweeps`, or no cluster can
    /// move any more ([`Simulation::is_frozen`]).
    pub fn is_done(&self) -> bool {
        self.clusters() <= self.run.params.target_clusters
            || self
                .run
                .params
                .max_sweeps
                .is_some_and(|m| self.run.sweep >= m)
            || self.frozen
    }

    /// Whether no cluster can ever move again: the move probability `temperature * s^-gamma`
    /// of the smallest cluster, the most mobile one, is exactly 0 in floating point (a large
    /// `--mobility-exponent`: `2^-1100` is 0). Clusters only grow, so the state would never
    /// change again, and a run to `--target-clusters` would sweep forever; it stops instead.
    pub fn is_frozen(&self) -> bool {
        self.frozen
    }

    /// The move probability of a cluster of `size` particles (docs/dlca.md, "The model", step 1).
    fn move_probability(&self, size: usize) -> f64 {
        if self.run.params.mobility_exponent == 0.0 {
            self.run.params.temperature
        } else {
            self.run.params.temperature * (size as f64).powf(-self.run.params.mobility_exponent)
        }
    }

    /// Recomputes [`Simulation::is_frozen`] (after a sweep: sizes only grow).
    fn update_frozen(&mut self) {
        let smallest = self
            .engine
            .live()
            .iter()
            .map(|&id| self.engine.len_of(id))
            .min();
        self.frozen = smallest.is_some_and(|s| self.move_probability(s) == 0.0);
    }

    /// One sweep: every cluster existing at its start, in a fresh random order, tries one move
    /// (skipping clusters merged away earlier in the sweep).
    pub fn sweep(&mut self) {
        let start = self.run.params.timing.then(Instant::now);
        self.engine.forget_views();
        self.run.sweep += 1;
        self.run.records.begin_sweep(self.run.sweep);
        let mut order = std::mem::take(&mut self.order);
        order.clear();
        order.extend_from_slice(self.engine.live());
        order.sort_unstable();
        shuffle(&mut self.run.rng, &mut order);
        for (i, &id) in order.iter().enumerate() {
            // The turns' order is known: the clusters' records are asked for a few turns
            // ahead and their lists (found from the record) a turn or two ahead, so that the
            // cache misses of a turn's start overlap earlier turns.
            if let Some(&next) = order.get(i + RECORD_AHEAD) {
                self.engine.prefetch_record(next);
            }
            if let Some(&next) = order.get(i + LISTS_AHEAD) {
                self.engine.prefetch_lists(next);
            }
            if self.engine.contains(id) {
                self.visit(id);
            }
        }
        self.order = order;
        if self.run.params.mobility_exponent > 0.0 {
            self.update_frozen();
        }
        let seconds = start.map(|t| t.elapsed().as_secs_f64());
        self.run
            .records
            .record_sweep(self.run.sweep, self.clusters(), self.run.largest, seconds);
    }

    /// One cluster's turn (docs/dlca.md, "The model", steps 1-4).
    fn visit(&mut self, id: ItemId) {
        // 1. Move with probability temperature * size^-gamma (no draw when that is 1).
        let p = self.move_probability(self.engine.len_of(id));
        if p < 1.0 && uniform01(&mut self.run.rng) >= p {
            return;
        }
        // 2. A direction, weighted by gravity.
        let dir = self.run.directions.sample(&mut self.run.rng);
        // 3. Translate (a wall blocks the whole cluster) and find the clusters now in contact.
        let Ok(examined) = self.engine.try_move(id, dir, &mut self.contacts) else {
            return;
        };
        self.run.records.record_move(examined);
        // 4. Merge with every cluster now in contact; the lowest id survives.
        if !self.contacts.is_empty() {
            self.merge_contacts(id);
        }
        if self.check_invariants {
            self.engine.forget_views();
            self.assert_invariants();
        }
    }

    /// Merge `mover` and the clusters in `self.contacts` into the one with the lowest id.
    fn merge_contacts(&mut self, mover: ItemId) {
        let mut group = std::mem::take(&mut self.contacts);
        group.push(mover);
        group.sort_unstable();
        let mut notes = Vec::new();
        let merged = self.engine.merge(group[0], &group[1..], &mut notes);
        self.run.largest = self.run.largest.max(merged.size as u64);
        group.clear();
        self.contacts = group;
        self.note_all(notes);
    }

    /// Panic unless: the particle count is conserved, no site holds two particles, every
    /// cluster is connected, and no two clusters are face-adjacent; and the store's own
    /// bookkeeping is consistent.
    pub fn assert_invariants(&self) {
        use std::collections::{HashMap, HashSet, VecDeque};
        self.engine.check();
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
            self.run.particles,
            "particles not conserved"
        );
        for &id in sets.live() {
            let sites = sets.sites(id);
            let mut seen = HashSet::from([sites[0]]);
            let mut queue = VecDeque::from([sites[0]]);
            while let Some(k) = queue.pop_front() {
                for n in self.run.lattice.neighbours(k) {
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
        &self.run.params
    }

    /// The seed the run was built from.
    pub fn seed(&self) -> u64 {
        self.run.seed
    }

    /// The lattice.
    pub fn lattice(&self) -> &Lattice {
        &self.run.lattice
    }

    /// The clusters as k-index arrays (absolute sites). With the `lattice` strategy, which
    /// stores clusters as an origin plus relative sites, the arrays are built on the first call
    /// after a change (O(N)) and cached until the next sweep.
    pub fn sets(&self) -> &SiteSets {
        self.engine.sets()
    }

    /// Number of particles.
    pub fn particles(&self) -> u64 {
        self.run.particles
    }

    /// Sweeps done.
    pub fn sweeps(&self) -> u64 {
        self.run.sweep
    }

    /// Number of clusters.
    pub fn clusters(&self) -> u64 {
        self.engine.live().len() as u64
    }

    /// Size of the largest cluster.
    pub fn largest(&self) -> u64 {
        self.run.largest
    }

    /// The search in use now.
    pub fn strategy(&self) -> Search {
        self.engine.kind()
    }

    /// Why the strategy was chosen (for `auto`: the regime it found).
    pub fn strategy_reason(&self) -> &str {
        &self.run.strategy_reason
    }

    /// Changes of the search during the run (box doublings, fall-back to all-pairs).
    pub fn events(&self) -> &[SearchEvent] {
        &self.events
    }

    /// What was recorded.
    pub fn records(&self) -> &Records {
        &self.run.records
    }

    /// Calls `f(cluster id, site k-index)` for every particle in a canonical order: clusters
    /// in increasing id, each cluster's sites in increasing k-index (the order of
    /// `particles.csv` and of the state hash).
    ///
    /// # Errors
    /// The first error of `f`.
    pub fn try_for_each_particle<E>(
        &self,
        mut f: impl FnMut(ItemId, u64) -> Result<(), E>,
    ) -> Result<(), E> {
        let sets = self.sets();
        let mut ids: Vec<ItemId> = sets.live().to_vec();
        ids.sort_unstable();
        let mut sites = Vec::new();
        for id in ids {
            sites.clear();
            sites.extend_from_slice(sets.sites(id));
            sites.sort_unstable();
            for &k in &sites {
                f(id, k)?;
            }
        }
        Ok(())
    }

    /// Hash of every particle's site and cluster id: clusters in increasing id, each cluster's
    /// sites in increasing k-index, fed as `(id, k)` little-endian `u64` pairs into XXH3-64.
    pub fn state_hash(&self) -> String {
        let mut h = StateHasher::new();
        let _ = self.try_for_each_particle(|id, k| {
            h.u64(u64::from(id)).u64(k);
            Ok::<(), std::convert::Infallible>(())
        });
        h.finish_hex()
    }
}
