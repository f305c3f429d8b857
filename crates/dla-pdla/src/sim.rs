//! The growth of one cluster: walkers, sticking, observables (MODELS.md section 2; seed 002,
//! sections 3.2 to 3.4).

use crate::cluster::Cluster;
use crate::farfield::{norm, return_to_sphere};
use crate::near::{NEAR_RADIUS, NearCache, REBUILD_UPPER};
use crate::params::{FarField, Params, ParamsError};
use core_lattice::io::StateHasher;
use core_lattice::rng::{Rng, SimRng, stream, stream_id, uniform01, unit_vector};
use core_lattice::{Gyration, LogLogFit};
use parking_lot::Mutex;
use serde::{Deserialize, Serialize};
use spatial::distmap::DistanceMapError;
use spatial::orthtree::{Orthtree, OrthtreeError, VpEstimate, dist_sq};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::time::Instant;

/// Stream purpose of the serial walker (`stream_id(PURPOSE_WALK, 0)`).
pub const PURPOSE_WALK: u32 = 1;
/// Stream purpose of PDLA walker threads (`stream_id(PURPOSE_PDLA, thread)`).
pub const PURPOSE_PDLA: u32 = 2;
/// PDLA re-check: a new particle closer than this to a stored one is discarded (MODELS.md).
pub const OVERLAP_DISTANCE: f64 = 1.0 - 1e-6;
/// A walker jumps by the distance map's bound `lb` when `lb - 1` exceeds this (diameters);
/// closer to the cluster the tree's sharper bound pays for its cost.
pub const MAP_JUMP_MIN: f64 = 2.0;
/// The far field starts at `|p| > r_b * FAR_FIELD_MARGIN`.
pub const FAR_FIELD_MARGIN: f64 = 1.0 + 1e-9;
/// Number of log-spaced growth samples aimed at.
pub const GROWTH_SAMPLES: f64 = 1000.0;

/// Errors of a run.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// Invalid parameters.
    #[error(transparent)]
    Params(#[from] ParamsError),
    /// `D` does not match `params.dim`.
    #[error("Simulation<{0}> built with --dim {1}")]
    DimMismatch(usize, usize),
    /// The orthtree refused a particle (coordinate range or capacity).
    #[error("storing a particle: {0}")]
    Tree(#[from] OrthtreeError),
    /// The distance map refused a particle (too large a cluster for its memory).
    #[error("distance map: {0}")]
    Map(#[from] DistanceMapError),
    /// A checkpoint could not be written or read.
    #[error("checkpoint: {0}")]
    Checkpoint(#[from] core_lattice::io::CheckpointError),
    /// Checkpoints need one thread and the positions kept in memory; or a checkpoint does not
    /// match the run it should continue.
    #[error("checkpoint: {0}")]
    CheckpointUsage(String),
    /// PDLA discarded [`MAX_CONSECUTIVE_DISCARDS`] walkers in a row without storing one.
    #[error(
        "PDLA livelock: {consecutive} walkers in a row discarded at the re-check ({total} in all); \
         the contact or re-check is broken"
    )]
    DiscardLivelock {
        /// Discarded in a row.
        consecutive: u64,
        /// Discarded in all.
        total: u64,
    },
}

/// One row of `growth.csv`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// Particles in the cluster.
    pub n: u64,
    /// Radius of gyration.
    pub radius_of_gyration: f64,
    /// Largest centre distance from the origin.
    pub r_ext: f64,
    /// Wall seconds since the start of growth.
    pub seconds: f64,
}

/// Everything that changes when a particle sticks (kept together under PDLA's write lock).
#[derive(Debug)]
struct Growth<const D: usize> {
    n: u64,
    r_ext: f64,
    gyration: Gyration<D>,
    hasher: StateHasher,
    positions: Option<Vec<[f64; D]>>,
    samples: Vec<Sample>,
    next_sample: u64,
    ratio: f64,
    started: Instant,
}

impl<const D: usize> Growth<D> {
    fn new(params: &Params) -> Self {
        Growth {
            n: 0,
            r_ext: 0.0,
            gyration: Gyration::new(),
            hasher: StateHasher::new(),
            positions: params.keep_positions.then(Vec::new),
            samples: Vec::new(),
            next_sample: 1,
            ratio: (params.particles as f64).powf(1.0 / GROWTH_SAMPLES),
            started: Instant::now(),
        }
    }

    /// Store `p` in the cluster and account for it; returns the stored position.
    fn add(
        &mut self,
        cluster: &mut Cluster<D>,
        p: [f64; D],
        target: u64,
    ) -> Result<[f64; D], SimError> {
        let q = cluster.insert(p)?;
        self.account(q, target);
        Ok(q)
    }

    /// Accounts for a particle already stored at `q`.
    fn account(&mut self, q: [f64; D], target: u64) {
        self.n += 1;
        self.r_ext = self.r_ext.max(norm(&q));
        self.gyration.push(&q);
        for x in q {
            self.hasher.f64(x);
        }
        if let Some(v) = &mut self.positions {
            v.push(q);
        }
        if self.n >= self.next_sample || self.n == target {
            self.samples.push(Sample {
                n: self.n,
                radius_of_gyration: self.gyration.radius(),
                r_ext: self.r_ext,
                seconds: self.started.elapsed().as_secs_f64(),
            });
            self.next_sample = (self.n + 1).max((self.n as f64 * self.ratio).ceil() as u64);
        }
    }
}

/// A random walker (seed 002, section 3.2).
#[derive(Debug, Clone, Copy)]
pub struct Walker<const D: usize> {
    /// Current centre.
    pub p: [f64; D],
}

impl<const D: usize> Walker<D> {
    /// A walker born uniformly on the sphere of radius `r_b`.
    pub fn born<R: Rng + ?Sized>(r_b: f64, rng: &mut R) -> Self {
        let mut p = direction::<D, _>(rng);
        p.iter_mut().for_each(|x| *x *= r_b);
        Walker { p }
    }

    /// One move on a non-empty cluster whose particles all lie within `r_ext` of the origin.
    /// Returns the sticking position (centre distance 1 to the particle first touched) when
    /// the move ends in contact.
    pub fn step<R: Rng + ?Sized>(
        &mut self,
        cluster: &Cluster<D>,
        r_ext: f64,
        params: &Params,
        rng: &mut R,
    ) -> Option<[f64; D]> {
        self.advance(&mut WalkState::new(params), cluster, r_ext, params, rng)
    }

    /// [`step`](Self::step) with the walker's memory `state` (reset it for each new walker):
    /// an upper bound of its distance to the cluster, so the tree query starts from the few
    /// nodes covering that ball ([`Orthtree::vpdist_bounded`]) rather than from the root.
    pub(crate) fn advance<R: Rng + ?Sized>(
        &mut self,
        state: &mut WalkState<D>,
        cluster: &Cluster<D>,
        r_ext: f64,
        params: &Params,
        rng: &mut R,
    ) -> Option<[f64; D]> {
        let r_b = r_ext + params.birth_gap;
        let r = norm(&self.p);
        // Far field. The margin keeps a walker just returned to the birth sphere (whose norm
        // may round to slightly above r_b) in the near field, which is valid everywhere;
        // without it a walker at r_b (1 + 1e-16) would be "returned" to itself forever.
        if r > r_b * FAR_FIELD_MARGIN {
            state.reset();
            match params.far_field {
                FarField::Return => self.p = return_to_sphere(&self.p, r_b, rng),
                FarField::Jump => {
                    if r > params.death_ratio * r_b {
                        *self = Walker::born(r_b, rng);
                    } else {
                        // Every particle is within r_ext of the origin, so within distance
                        // r - r_ext - 1 the walker cannot touch one.
                        self.jump(r - r_ext - 1.0, rng);
                    }
                }
            }
            return None;
        }
        // Near field. First the distance map: one byte read bounds the distance to the
        // cluster from below; a walker at least a few diameters out jumps by it.
        if let Some(lb) = cluster.map_bound(&self.p) {
            if lb - 1.0 > MAP_JUMP_MIN {
                self.jump(lb - 1.0, rng);
                state.upper += (lb - 1.0) * (1.0 + 1e-9);
                return None;
            }
        }
        // Then the tree: a lower bound on the distance to the nearest centre.
        // Near the cluster the walker's near cache gives the same exact answer as the tree.
        let tree = cluster.tree();
        let (est, nearest) = match state.near_query(&self.p, tree) {
            Some((distance, x)) => (
                VpEstimate {
                    distance,
                    half_diagonal: None,
                },
                Some(x),
            ),
            None => tree
                .vpdist_bounded_nearest(&self.p, params.precision, state.upper(&self.p))
                .expect("the cluster is never empty"),
        };
        state.anchor = nearest;
        let delta = est.distance;
        // The exact distance is at most delta + 2 r (the gap of a far node's bound), with a
        // relative margin for the rounding of that bound.
        state.upper = (delta + 2.0 * est.half_diagonal.unwrap_or(0.0)) * (1.0 + 1e-9) + 1e-9;
        if delta - 1.0 > params.step_min {
            self.jump(delta - 1.0, rng);
            state.upper += (delta - 1.0) * (1.0 + 1e-9);
            return None;
        }
        state.upper += params.step_min * (1.0 + 1e-9);
        let u = direction::<D, _>(rng);
        let r = params.step_min + 1.0;
        // `covers` is false unless the cache was built, which only `near_query` does, and only
        // when the cache is on.
        let t = if state.near.covers(&self.p, r) {
            // The same particles as the tree's range query (see `near`), so the same contact.
            let mut best = f64::INFINITY;
            state
                .near
                .for_each_within(&self.p, r, |q| contact(&self.p, &u, &q, &mut best));
            (best <= params.step_min).then_some(best)
        } else {
            first_contact(tree, &self.p, &u, params.step_min)
        };
        if let Some(t) = t {
            let mut q = self.p;
            for i in 0..D {
                q[i] += t * u[i];
            }
            return Some(q);
        }
        for i in 0..D {
            self.p[i] += params.step_min * u[i];
        }
        None
    }

    fn jump<R: Rng + ?Sized>(&mut self, len: f64, rng: &mut R) {
        let u = direction::<D, _>(rng);
        for i in 0..D {
            self.p[i] += len * u[i];
        }
    }
}

/// A uniformly random unit vector in `D = 2` or 3 dimensions, without trigonometric functions:
/// a point uniform in the unit disk by rejection from the square (two 32-bit uniforms from one
/// 64-bit draw, accepted with probability pi/4), normalised; in 3D, `z` uniform in `[-1, 1]`
/// (Archimedes) and the azimuth from such a disk point. Isotropic exactly up to the 2^-31
/// granularity of the disk point.
#[inline]
pub fn direction<const D: usize, R: Rng + ?Sized>(rng: &mut R) -> [f64; D] {
    const SCALE: f64 = 1.0 / 2_147_483_648.0;
    let disk = |rng: &mut R| loop {
        let b = rng.next_u64();
        let x = ((b >> 32) as u32 as i32) as f64 * SCALE;
        let y = (b as u32 as i32) as f64 * SCALE;
        let s = x * x + y * y;
        if s <= 1.0 && s > 1e-12 {
            let inv = 1.0 / s.sqrt();
            return (x * inv, y * inv);
        }
    };
    let mut v = [0.0; D];
    match D {
        2 => {
            let (c, s) = disk(rng);
            v[0] = c;
            v[1] = s;
        }
        3 => {
            let z = 2.0 * uniform01(rng) - 1.0;
            let rho = (1.0 - z * z).max(0.0).sqrt();
            let (c, s) = disk(rng);
            v[0] = rho * c;
            v[1] = rho * s;
            v[2] = z;
        }
        _ => v = unit_vector::<D, _>(rng),
    }
    v
}

/// Smallest `t` in `[0, len]` with `|p + t u - q| = 1` over every stored centre `q` (`u` a unit
/// vector): the first contact along the step (seed 002, section 3.2, Fig. 6). A centre already
/// at distance <= 1 gives `t = 0`.
pub fn first_contact<const D: usize>(
    tree: &Orthtree<D>,
    p: &[f64; D],
    u: &[f64; D],
    len: f64,
) -> Option<f64> {
    let mut best = f64::INFINITY;
    tree.for_each_within(p, len + 1.0, |q| contact(p, u, &q, &mut best));
    (best <= len).then_some(best)
}

/// Lowers `best` to the contact time with centre `q` along `p + t u`, if there is one.
#[inline(always)]
fn contact<const D: usize>(p: &[f64; D], u: &[f64; D], q: &[f64; D], best: &mut f64) {
    let mut b = 0.0;
    let mut w2 = 0.0;
    for i in 0..D {
        let w = p[i] - q[i];
        b += w * u[i];
        w2 += w * w;
    }
    let c = w2 - 1.0;
    let t = if c <= 0.0 {
        0.0
    } else {
        let disc = b * b - c;
        if disc < 0.0 || b >= 0.0 {
            return;
        }
        // Stable form of -b - sqrt(disc) (b < 0): c / (-b + sqrt(disc)).
        c / (-b + disc.sqrt())
    };
    if t < *best {
        *best = t;
    }
}

/// What a walker remembers between moves: an upper bound of its exact distance to the
/// nearest centre (`+inf` when unknown), and the stored particle found nearest at the last
/// exact tree query (`anchor`). Both stay valid while particles are only added, so PDLA
/// threads keep them when other threads store particles.
#[derive(Debug, Clone)]
pub(crate) struct WalkState<const D: usize> {
    upper: f64,
    anchor: Option<[f64; D]>,
    /// Whether the near cache is used: `params.near_cache`, and the tree's answers are exact
    /// wherever the cache answers (`(kappa - 1/2)` leaf diagonals cover [`NEAR_RADIUS`]).
    near_on: bool,
    near: NearCache<D>,
}

impl<const D: usize> WalkState<D> {
    pub(crate) fn new(params: &Params) -> Self {
        let kappa = params.precision;
        let exact_within = if kappa.is_nan() {
            f64::INFINITY
        } else {
            (kappa - 0.5) * params.leaf_side * (D as f64).sqrt()
        };
        WalkState {
            upper: f64::INFINITY,
            anchor: None,
            near_on: params.near_cache && exact_within >= NEAR_RADIUS,
            near: NearCache::new(),
        }
    }

    /// A new walker: nothing known.
    pub(crate) fn reset(&mut self) {
        self.upper = f64::INFINITY;
        self.anchor = None;
        self.near.reset();
    }

    /// The exact nearest distance and a particle at it from the near cache, rebuilding the
    /// cache around `p` when it cannot answer and `p` is known to be close to the cluster;
    /// `None` when the tree must answer.
    #[inline]
    fn near_query(&mut self, p: &[f64; D], tree: &Orthtree<D>) -> Option<(f64, [f64; D])> {
        if !self.near_on {
            return None;
        }
        if let Some(hit) = self.near.nearest(p) {
            return Some(hit);
        }
        if self.upper(p) <= REBUILD_UPPER {
            self.near.rebuild(tree, p);
            return self.near.nearest(p);
        }
        None
    }

    /// An upper bound of the nearest distance from `p`: the smaller of `upper` (the last
    /// answer plus every distance moved since) and the distance to the anchor particle (the
    /// walker jumped in a random direction, so the anchor is typically about `sqrt 2` times
    /// the last answer away rather than twice), with a relative margin for rounding.
    #[inline]
    fn upper(&self, p: &[f64; D]) -> f64 {
        match self.anchor {
            Some(a) => self.upper.min(dist_sq(p, &a).sqrt() * (1.0 + 1e-9) + 1e-9),
            None => self.upper,
        }
    }
}

/// Consecutive discarded walkers (with no particle stored in between) after which a PDLA run
/// stops with [`SimError::DiscardLivelock`]. With exact contact a discard needs another thread
/// to have stored a particle within one diameter of the sticking point during the walker's
/// last move, so a handful in a row is already rare; this many means a bug, not bad luck.
pub const MAX_CONSECUTIVE_DISCARDS: u64 = 100_000;

/// Counts discarded PDLA walkers and stops a run that only discards (a livelock).
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct DiscardGuard {
    /// All discarded walkers.
    pub total: u64,
    /// Discarded since the last stored particle.
    pub consecutive: u64,
}

impl DiscardGuard {
    /// Records one walker at the re-check: discarded or stored.
    pub fn record(&mut self, discarded: bool) -> Result<(), SimError> {
        if discarded {
            self.total += 1;
            self.consecutive += 1;
            if self.consecutive >= MAX_CONSECUTIVE_DISCARDS {
                return Err(SimError::DiscardLivelock {
                    consecutive: self.consecutive,
                    total: self.total,
                });
            }
        } else {
            self.consecutive = 0;
        }
        Ok(())
    }
}

/// The shared side of PDLA: stored particles in order, and everything a stored particle changes.
struct Log<const D: usize> {
    /// Stored positions from absolute index `base` on (older ones every thread has applied are
    /// dropped).
    points: Vec<[f64; D]>,
    base: usize,
    growth: Growth<D>,
    guard: DiscardGuard,
    error: Option<SimError>,
}

/// One thread's copy of the cluster.
struct Replica<const D: usize> {
    cluster: Cluster<D>,
    /// Largest centre distance over the applied particles.
    r_ext: f64,
    /// Particles taken from the log (an absolute log index).
    applied: usize,
    /// Taken from the log but not yet inserted (filled under the lock, inserted after it).
    pending: Vec<[f64; D]>,
    index: usize,
    /// The memory of the thread's current walker.
    walk: WalkState<D>,
}

/// References shared by the PDLA threads.
#[derive(Clone, Copy)]
struct Ctx<'a, const D: usize> {
    log: &'a Mutex<Log<D>>,
    published: &'a AtomicUsize,
    applied: &'a [AtomicUsize],
    stop: &'a AtomicBool,
    target: u64,
    /// Nanoseconds threads spent waiting for the log's mutex (summed over threads).
    wait_nanos: &'a AtomicU64,
}

/// Log entries are dropped once every thread has applied them and this many have piled up.
const LOG_TRIM: usize = 4096;

impl<const D: usize> Ctx<'_, D> {
    /// Takes the log's mutex, timing the wait when it is contended.
    #[inline]
    fn lock(&self) -> parking_lot::MutexGuard<'_, Log<D>> {
        if let Some(g) = self.log.try_lock() {
            return g;
        }
        let t = Instant::now();
        let g = self.log.lock();
        self.wait_nanos
            .fetch_add(t.elapsed().as_nanos() as u64, Ordering::Relaxed);
        g
    }

    /// Copies the log entries `rep` has not seen into `rep.pending` (the caller holds the
    /// lock; inserting them into the replica happens after it is released).
    fn take_pending(&self, log: &Log<D>, rep: &mut Replica<D>) {
        rep.pending
            .extend_from_slice(&log.points[rep.applied - log.base..]);
        rep.applied = log.base + log.points.len();
        self.applied[rep.index].store(rep.applied, Ordering::Relaxed);
    }

    /// Inserts `rep.pending` into the replica, in log order (no lock held).
    fn insert_pending(&self, rep: &mut Replica<D>) -> bool {
        for q in rep.pending.drain(..) {
            if let Err(e) = rep.cluster.insert_tree(q) {
                self.fail(&mut self.lock(), e);
                return false;
            }
            rep.walk.near.added(&q);
            rep.r_ext = rep.r_ext.max(norm(&q));
        }
        true
    }

    /// Brings `rep` up to date if another thread stored particles; `false` to stop.
    #[inline]
    fn sync(&self, rep: &mut Replica<D>) -> bool {
        if self.stop.load(Ordering::Relaxed) {
            return false;
        }
        if self.published.load(Ordering::Acquire) == rep.applied {
            return true;
        }
        let done = {
            let log = self.lock();
            self.take_pending(&log, rep);
            log.growth.n >= self.target
        };
        self.insert_pending(rep) && !done
    }

    fn fail(&self, log: &mut Log<D>, e: SimError) {
        log.error.get_or_insert(e);
        self.stop.store(true, Ordering::Relaxed);
    }

    /// One thread's walkers until the cluster is complete or the run fails.
    fn walk<R: Rng + ?Sized>(
        &self,
        rep: &mut Replica<D>,
        params: &Params,
        rng: &mut R,
        progress: &(dyn Fn(u64) + Sync),
    ) {
        loop {
            if !self.sync(rep) {
                return;
            }
            let mut w = Walker::born(rep.r_ext + params.birth_gap, rng);
            rep.walk.reset();
            let stick = loop {
                if let Some(p) = w.advance(&mut rep.walk, &rep.cluster, rep.r_ext, params, rng) {
                    break p;
                }
                if !self.sync(rep) {
                    return;
                }
            };
            let q = match rep.cluster.tree().stored_position(&stick) {
                Ok(q) => q,
                Err(e) => return self.fail(&mut self.lock(), e.into()),
            };
            // A jump or step made on the replica can end inside a particle another thread
            // stored meanwhile; once that particle is applied the next move sticks at once,
            // overlapping it. So the sticking point is checked against the replica (private,
            // no lock needed) and, under the lock, against the particles stored since.
            let mut overlap = false;
            rep.cluster
                .tree()
                .for_each_within(&stick, OVERLAP_DISTANCE, |_| overlap = true);
            let mut guard = self.lock();
            if guard.growth.n >= self.target || self.stop.load(Ordering::Relaxed) {
                return;
            }
            self.take_pending(&guard, rep);
            // Re-check under the lock (seed 002, section 3.4) against the particles other
            // threads stored since the walker's last move (now in `pending`, a handful at most).
            let r_sq = OVERLAP_DISTANCE * OVERLAP_DISTANCE;
            overlap |= rep.pending.iter().any(|x| dist_sq(&stick, x) <= r_sq);
            if let Err(e) = guard.guard.record(overlap) {
                return self.fail(&mut guard, e);
            }
            if overlap {
                drop(guard);
                if !self.insert_pending(rep) {
                    return;
                }
                continue;
            }
            let log = &mut *guard;
            log.growth.account(q, self.target);
            log.points.push(q);
            rep.pending.push(q);
            rep.applied += 1;
            self.applied[rep.index].store(rep.applied, Ordering::Relaxed);
            self.published.store(rep.applied, Ordering::Release);
            if log.growth.n % 1024 == 0 {
                progress(log.growth.n);
            }
            if log.points.len() >= 2 * LOG_TRIM {
                let oldest = self
                    .applied
                    .iter()
                    .map(|a| a.load(Ordering::Relaxed))
                    .min()
                    .unwrap_or(log.base);
                let drop = oldest - log.base;
                if drop >= LOG_TRIM {
                    log.points.drain(..drop);
                    log.base = oldest;
                }
            }
            drop(guard);
            // The stuck particle lowers the shared distance maps once, atomically; until it
            // has, another thread's walker may jump by a stale bound, which the re-check at
            // its sticking catches like any move made before a particle was applied.
            if let Err(e) = rep.cluster.update_maps(&q) {
                return self.fail(&mut self.lock(), e);
            }
            if !self.insert_pending(rep) {
                return;
            }
        }
    }
}

/// Model name in the checkpoint envelope.
pub const CHECKPOINT_MODEL: &str = "dla";

/// The state a checkpoint holds (bincode 2 in the `AGGSIMCK` envelope).
#[derive(Serialize, Deserialize)]
struct Snapshot {
    params: Params,
    seed: u64,
    rng: SimRng,
    /// Positions in arrival order, `D` coordinates each.
    positions: Vec<f64>,
    samples: Vec<Sample>,
    next_sample: u64,
    /// Wall seconds of growth so far (the `seconds` column of `growth.csv` continues).
    seconds: f64,
}

/// A DLA/PDLA run in `D` dimensions (2 or 3), a pure function of `(Params, seed)` for one
/// thread.
#[derive(Debug)]
pub struct Simulation<const D: usize> {
    params: Params,
    seed: u64,
    cluster: Cluster<D>,
    growth: Growth<D>,
    rng: SimRng,
    discarded: u64,
    walk: WalkState<D>,
    parallel_seconds: f64,
    lock_wait_seconds: f64,
}

/// The fitted fractal dimension (`log N = D log R_g + c`).
pub type FractalFit = LogLogFit;

impl<const D: usize> Simulation<D> {
    /// A cluster holding the seed particle at the origin.
    pub fn new(params: Params, seed: u64) -> Result<Self, SimError> {
        params.validate()?;
        if params.dim != D {
            return Err(SimError::DimMismatch(D, params.dim));
        }
        let mut cluster = Cluster::new(&params)?;
        let mut growth = Growth::new(&params);
        growth.add(&mut cluster, [0.0; D], params.particles)?;
        Ok(Simulation {
            rng: stream(seed, stream_id(PURPOSE_WALK, 0)),
            walk: WalkState::new(&params),
            params,
            seed,
            cluster,
            growth,
            discarded: 0,
            parallel_seconds: 0.0,
            lock_wait_seconds: 0.0,
        })
    }

    /// Grow the cluster to `params.particles`, calling `progress(n)` about every 1024
    /// particles.
    pub fn run_with(&mut self, progress: &(dyn Fn(u64) + Sync)) -> Result<(), SimError> {
        let target = self.params.particles;
        let serial_to = if self.params.threads == 1 {
            target
        } else {
            self.params.serial_until.clamp(1, target)
        };
        while self.growth.n < serial_to {
            self.add_one()?;
            if self.growth.n % 1024 == 0 {
                progress(self.growth.n);
            }
        }
        if self.growth.n < target {
            self.run_parallel(progress)?;
        }
        progress(self.growth.n);
        Ok(())
    }

    /// Serial DLA with a checkpoint written to `path` every `every` particles (and at the
    /// end), atomically, in the `AGGSIMCK` envelope (model `dla`). Needs `threads == 1` and
    /// `keep_positions` (the checkpoint holds every position in arrival order, from which
    /// [`resume`](Self::resume) rebuilds the tree, `R_g`, `R_ext` and the state hash exactly).
    /// A resumed run ends with the same `state_hash` as an uninterrupted one.
    pub fn run_checkpointed(
        &mut self,
        every: u64,
        path: &std::path::Path,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<(), SimError> {
        if self.params.threads != 1 || self.growth.positions.is_none() || every == 0 {
            return Err(SimError::CheckpointUsage(format!(
                "checkpoints need --threads 1, kept positions and every >= 1 (got threads {}, every {every})",
                self.params.threads
            )));
        }
        let target = self.params.particles;
        while self.growth.n < target {
            self.add_one()?;
            if self.growth.n % 1024 == 0 {
                progress(self.growth.n);
            }
            if self.growth.n % every == 0 && self.growth.n < target {
                self.write_checkpoint(path)?;
            }
        }
        self.write_checkpoint(path)?;
        progress(self.growth.n);
        Ok(())
    }

    /// Writes the run's state to `path` (see [`run_checkpointed`](Self::run_checkpointed)).
    pub fn write_checkpoint(&self, path: &std::path::Path) -> Result<(), SimError> {
        let positions = self.growth.positions.as_ref().ok_or_else(|| {
            SimError::CheckpointUsage("a checkpoint needs the positions kept in memory".into())
        })?;
        if self.params.threads != 1 {
            return Err(SimError::CheckpointUsage(
                "checkpoints are for one thread (PDLA is not deterministic)".into(),
            ));
        }
        let snap = Snapshot {
            params: self.params.clone(),
            seed: self.seed,
            rng: self.rng.clone(),
            positions: positions.iter().flatten().copied().collect(),
            samples: self.growth.samples.clone(),
            next_sample: self.growth.next_sample,
            seconds: self.growth.started.elapsed().as_secs_f64(),
        };
        core_lattice::io::write_checkpoint(path, CHECKPOINT_MODEL, &snap)?;
        Ok(())
    }

    /// Continues a run from a checkpoint written by
    /// [`run_checkpointed`](Self::run_checkpointed): the tree, `R_g`, `R_ext` and the state
    /// hash are rebuilt by storing the checkpointed positions again in arrival order, so they
    /// are bit-identical to those of the run that wrote it.
    pub fn resume(path: &std::path::Path) -> Result<Self, SimError> {
        let snap: Snapshot = core_lattice::io::read_checkpoint(path, CHECKPOINT_MODEL)?;
        snap.params.validate()?;
        if snap.params.dim != D {
            return Err(SimError::DimMismatch(D, snap.params.dim));
        }
        if snap.positions.len() % D != 0 || snap.positions.is_empty() {
            return Err(SimError::CheckpointUsage(format!(
                "{} coordinates is not a whole number of {D}D positions",
                snap.positions.len()
            )));
        }
        let params = snap.params;
        let mut cluster = Cluster::new(&params)?;
        let mut growth = Growth::new(&params);
        for c in snap.positions.chunks_exact(D) {
            let mut p = [0.0; D];
            p.copy_from_slice(c);
            growth.add(&mut cluster, p, params.particles)?;
        }
        growth.samples = snap.samples;
        growth.next_sample = snap.next_sample;
        if let Some(t) = Instant::now().checked_sub(std::time::Duration::from_secs_f64(
            snap.seconds.clamp(0.0, 1e9),
        )) {
            growth.started = t;
        }
        Ok(Simulation {
            walk: WalkState::new(&params),
            params,
            seed: snap.seed,
            cluster,
            growth,
            rng: snap.rng,
            discarded: 0,
            parallel_seconds: 0.0,
            lock_wait_seconds: 0.0,
        })
    }

    /// Grow to `params.particles` without progress reports.
    pub fn run(&mut self) -> Result<(), SimError> {
        self.run_with(&|_| {})
    }

    /// Release one walker and grow the cluster by the particle it becomes (serial DLA).
    pub fn add_one(&mut self) -> Result<[f64; D], SimError> {
        let mut w = Walker::born(self.growth.r_ext + self.params.birth_gap, &mut self.rng);
        self.walk.reset();
        loop {
            if let Some(p) = w.advance(
                &mut self.walk,
                &self.cluster,
                self.growth.r_ext,
                &self.params,
                &mut self.rng,
            ) {
                return self.growth.add(&mut self.cluster, p, self.params.particles);
            }
        }
    }

    /// PDLA: `params.threads` walkers at once. Each thread walks on its own replica of the
    /// orthtree, so walking takes no lock and touches no shared cache line but one atomic
    /// counter; stuck particles go through a shared log (a mutex held only to copy the new
    /// entries, re-check against them, append and account for one particle; inserting into the
    /// replica happens after the mutex is released). Before every move a thread applies the
    /// particles other threads appended since its last move, so it walks on the cluster as it
    /// was at most one move ago, as in the paper's shared tree. At sticking it re-checks, under
    /// the log's lock, that none of the particles stored since its last move lies within
    /// [`OVERLAP_DISTANCE`] (seed 002, section 3.4), and against its replica before taking the
    /// lock (a move can end inside a particle stored during it); if one does the walker is
    /// discarded and counted. The replicas receive the same points in the same order, so they
    /// are identical;
    /// thread 0's becomes the simulation's tree.
    fn run_parallel(&mut self, progress: &(dyn Fn(u64) + Sync)) -> Result<(), SimError> {
        let params = &self.params;
        let target = params.particles;
        let threads = params.threads;
        let start = self.growth.n as usize;
        let log = Mutex::new(Log {
            points: Vec::new(),
            base: start,
            growth: std::mem::replace(&mut self.growth, Growth::new(params)),
            guard: DiscardGuard::default(),
            error: None,
        });
        // Particles stored so far (log positions are absolute: the serial ones come first).
        let published = AtomicUsize::new(start);
        let applied: Vec<AtomicUsize> = (0..threads).map(|_| AtomicUsize::new(start)).collect();
        let stop = AtomicBool::new(false);
        let seed = self.seed;
        let r_ext0 = log.lock().growth.r_ext;
        // The replicas share one set of distance maps, sized for the final cluster now (they
        // cannot grow once shared).
        self.cluster.reserve_maps(
            crate::cluster::expected_r_ext(D, target).max(r_ext0) + params.birth_gap,
        )?;
        let mut replicas: Vec<Cluster<D>> = (1..threads).map(|_| self.cluster.clone()).collect();
        replicas.insert(0, std::mem::take(&mut self.cluster));
        let wait_nanos = AtomicU64::new(0);
        let started = Instant::now();
        let ctx = Ctx {
            log: &log,
            published: &published,
            applied: &applied,
            stop: &stop,
            target,
            wait_nanos: &wait_nanos,
        };
        let mut clusters: Vec<Cluster<D>> = std::thread::scope(|s| {
            let handles: Vec<_> = replicas
                .into_iter()
                .enumerate()
                .map(|(t, cluster)| {
                    s.spawn(move || {
                        let mut rep = Replica {
                            cluster,
                            r_ext: r_ext0,
                            applied: start,
                            pending: Vec::new(),
                            index: t,
                            walk: WalkState::new(params),
                        };
                        let mut rng = stream(seed, stream_id(PURPOSE_PDLA, t as u32));
                        ctx.walk(&mut rep, params, &mut rng, progress);
                        // Whatever was taken from the log is counted as applied.
                        ctx.insert_pending(&mut rep);
                        rep.cluster
                    })
                })
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().expect("a PDLA thread panicked"))
                .collect()
        });
        self.parallel_seconds += started.elapsed().as_secs_f64();
        self.lock_wait_seconds += wait_nanos.into_inner() as f64 * 1e-9;
        let mut log = log.into_inner();
        let mut cluster = clusters.swap_remove(0);
        drop(clusters);
        // Thread 0 may have stopped before applying the last particles of the others.
        let done = applied[0].load(Ordering::Relaxed);
        for q in &log.points[done - log.base..] {
            // Their threads lowered the shared maps already.
            cluster.insert_tree(*q)?;
        }
        self.cluster = cluster;
        self.discarded += log.guard.total;
        self.growth = log.growth;
        match log.error.take() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// The parameters.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Particles in the cluster.
    pub fn particles(&self) -> u64 {
        self.growth.n
    }

    /// Largest centre distance from the origin.
    pub fn r_ext(&self) -> f64 {
        self.growth.r_ext
    }

    /// Radius of gyration of the cluster.
    pub fn radius_of_gyration(&self) -> f64 {
        self.growth.gyration.radius()
    }

    /// PDLA walkers discarded at the re-check (0 for one thread).
    pub fn discarded_walkers(&self) -> u64 {
        self.discarded
    }

    /// Wall seconds of the parallel (PDLA) phase; 0 for one thread.
    pub fn parallel_seconds(&self) -> f64 {
        self.parallel_seconds
    }

    /// Seconds PDLA threads spent waiting for the shared log's mutex, summed over threads (the
    /// serialised part of PDLA; 0 for one thread).
    pub fn lock_wait_seconds(&self) -> f64 {
        self.lock_wait_seconds
    }

    /// Hash of the stored positions in arrival order (f64 bits): equal runs, equal hashes.
    pub fn state_hash(&self) -> String {
        self.growth.hasher.finish_hex()
    }

    /// The growth samples (about 1000, log-spaced in N, the last at the final size).
    pub fn samples(&self) -> &[Sample] {
        &self.growth.samples
    }

    /// Positions in arrival order, if `params.keep_positions`.
    pub fn positions(&self) -> Option<&[[f64; D]]> {
        self.growth.positions.as_deref()
    }

    /// The spatial structure holding the cluster.
    pub fn tree(&self) -> &Orthtree<D> {
        self.cluster.tree()
    }

    /// The cluster (orthtree and distance map).
    pub fn cluster(&self) -> &Cluster<D> {
        &self.cluster
    }

    /// Fractal dimension from `log N = D log R_g + c` over the samples with `N >= fit_from`.
    pub fn fractal_dimension(&self) -> Result<FractalFit, core_lattice::stats::StatsError> {
        let (rg, n): (Vec<f64>, Vec<f64>) = self
            .growth
            .samples
            .iter()
            .filter(|s| s.n >= self.params.fit_from)
            .map(|s| (s.radius_of_gyration, s.n as f64))
            .unzip();
        LogLogFit::fit(&rg, &n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Walkers on a grown cluster: the number of moves answered by a built near cache.
    fn cached_moves<const D: usize>(precision: f64) -> usize {
        let params = Params {
            dim: D,
            particles: 1500,
            precision,
            ..Params::default()
        };
        let mut sim = Simulation::<D>::new(params.clone(), 4).unwrap();
        sim.run().unwrap();
        let mut state = WalkState::<D>::new(&params);
        let mut rng = stream(9, 0);
        let mut live = 0;
        for _ in 0..20 {
            let mut w = Walker::born(sim.growth.r_ext + params.birth_gap, &mut rng);
            state.reset();
            while w
                .advance(
                    &mut state,
                    &sim.cluster,
                    sim.growth.r_ext,
                    &params,
                    &mut rng,
                )
                .is_none()
            {
                live += usize::from(state.near.covers(&w.p, 0.0));
            }
        }
        live
    }

    #[test]
    fn near_cache_is_used_only_where_the_tree_is_exact() {
        // Default precision: (2 - 1/2) leaf diagonals cover the cache's radius.
        assert!(cached_moves::<2>(2.0) > 0);
        assert!(cached_moves::<3>(2.0) > 0);
        // kappa 0.8: exact only within 0.3 leaf diagonals (3.4 in 2D, 4.2 in 3D), less than
        // the radius: the cache must stay off.
        assert_eq!(cached_moves::<2>(0.8), 0);
        assert_eq!(cached_moves::<3>(0.8), 0);
    }
}
