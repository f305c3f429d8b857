//! Parallel DLA (PDLA; Sosa-Herrera & Rodriguez-Romo, "Variable precision distance search for
//! random fractal cluster simulations", section 3.4): `params.threads` walkers at once on one
//! shared tree, stuck particles stored and published under one lock, and a re-check at
//! sticking that discards a walker overlapping a particle stored meanwhile.
//!
//! Invariants: the stored particles have one total order, the order in which they entered the
//! tree under the log's lock (their published count, and their entries in the [`Ring`]); a
//! particle is stored only if no particle stored before it lies within
//! [`OVERLAP_DISTANCE`] of its walker's contact point (which is where it is stored, unless noise
//! reduction `f < 1` stores it at distance `f` from the particle it touched, then at least
//! `f - 1e-6` from every earlier one); every stored particle is accounted for once, under the
//! log's lock; a run that only discards stops with [`SimError::DiscardLivelock`].

use super::growth::{Growth, noise_reduced};
use super::ring::Ring;
use crate::cluster::Cluster;
use crate::error::SimError;
use crate::params::Params;
use crate::space::{Dim, Space};
use crate::walker::{WalkCounts, WalkState, Walker, detached};
use core_lattice::rng::{Rng, stream, stream_id};
use spatial::orthtree::{OrthtreeError, dist_sq};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError, TryLockError};
use std::time::Instant;

/// Stream purpose of PDLA walker threads (`stream_id(PURPOSE_PDLA, thread)`).
pub const PURPOSE_PDLA: u32 = 2;
/// PDLA re-check: a new particle closer than this to a stored one is discarded.
pub const OVERLAP_DISTANCE: f64 = 1.0 - 1e-6;

/// What the parallel phases of a run add up to.
#[derive(Debug, Default, Clone, Copy, PartialEq)]
pub(crate) struct PdlaStats {
    /// Walkers discarded at the re-check.
    pub(crate) discarded: u64,
    /// Wall seconds of the parallel phases.
    pub(crate) seconds: f64,
    /// Seconds threads waited for the log's mutex, summed over threads.
    pub(crate) lock_wait_seconds: f64,
    /// Parallel phases run (one per call, more when the tree needed more room).
    pub(crate) phases: u64,
    /// What the threads' walkers did.
    pub(crate) walk: WalkCounts,
}

/// The first phase reserves the tree's root for this many times the expected radius of the
/// final cluster (later phases for 1.5 times the radius reached).
const FIRST_RADIUS: f64 = 1.25;

#[cfg(test)]
thread_local! {
    /// Overrides [`FIRST_RADIUS`] in unit tests, to make phases run out of room.
    pub(crate) static FIRST_RADIUS_IN_TESTS: std::cell::Cell<f64> =
        const { std::cell::Cell::new(FIRST_RADIUS) };
}

fn first_radius() -> f64 {
    #[cfg(test)]
    return FIRST_RADIUS_IN_TESTS.get();
    #[cfg(not(test))]
    FIRST_RADIUS
}

/// Grows `cluster` (holding `growth.n` particles) to `until` (at most `params.particles`, the
/// run's final size) with `params.threads` walkers at once, adding to `stats`; returns early,
/// at a quiescent point, once `halt` is set. Every thread stops at a quiescent point: the
/// stored particles are all in the tree and walkers still on their way are dropped (walkers
/// are independent, so a new one born later is as good), which is where a PDLA checkpoint is
/// taken. `rounds` numbers the parallel phases of a run (each draws from its own random
/// streams) and is advanced for each.
///
/// All threads walk on one orthtree (the paper's shared tree), which takes no lock to query:
/// [`Orthtree::insert_shared`](spatial::orthtree::Orthtree::insert_shared) lets a query run
/// while a particle is inserted, and a walker's view is at most one insert behind. Stuck
/// particles go through a shared log under a mutex held to re-check, insert, record (in the
/// [`Ring`] of the newest positions) and account for one particle. At sticking a thread
/// re-checks (section 3.4) that no particle stored since its walker's last look at the tree
/// lies within [`OVERLAP_DISTANCE`]: against the walker's near cache or the tree before taking
/// the lock, and under the lock against the particles stored since; if one does the walker is
/// discarded and counted. Before every move
/// a thread reads the number of particles published and, when others stored some and its
/// walker's near cache can still answer, adds them to the cache from the ring, without the
/// lock (see `Ctx::catch_up`).
///
/// The tree's room for the phase is reserved up front (address space, not memory); a particle
/// that needs more, or lands outside the reserved root, ends the phase at a quiescent point and
/// the next phase reserves again.
#[allow(clippy::too_many_arguments)]
pub(crate) fn grow_parallel<const D: usize>(
    params: &Params,
    seed: u64,
    rounds: &mut u32,
    until: u64,
    halt: &AtomicBool,
    cluster: &mut Cluster<D>,
    growth: &mut Growth<D>,
    stats: &mut PdlaStats,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<(), SimError>
where
    Dim<D>: Space<D>,
{
    let target = until.min(params.particles);
    // The threads share one set of distance maps, sized for the final cluster now (they
    // cannot grow once shared). They must cover the particles (reserve_maps adds each map's
    // cap): a walker beyond them gets no bound and asks the tree. Not the birth sphere: a
    // large --birth-gap would cost (gap / cell)^D bytes.
    cluster.reserve_maps(Dim::<D>::expected_r_ext(params.particles).max(growth.r_ext))?;
    let mut radius = Dim::<D>::expected_r_ext(params.particles) * first_radius();
    while growth.n < target && !halt.load(Ordering::Relaxed) {
        radius = radius.max(growth.r_ext * 1.5) + params.birth_gap;
        // A phase reserves room for at most 16 times the cluster it starts from: the room per
        // point is estimated from the tree so far, which says little while it is small (a
        // first phase reserving for 1e8 particles from a seed asked for 30 GB). A phase that
        // fills its room ends, and the next one reserves again from a larger tree.
        let points = ((target - growth.n) as usize).min((growth.n as usize).max(1 << 16) * 16);
        cluster.prepare_shared(points, radius)?;
        let round = *rounds;
        *rounds += 1;
        stats.phases += 1;
        let phase = phase(
            params, seed, round, target, halt, cluster, growth, stats, progress,
        );
        cluster.finish_shared();
        match phase? {
            PhaseEnd::Done => break,
            PhaseEnd::NeedsRoom => {}
        }
    }
    Ok(())
}

/// How a parallel phase ended.
enum PhaseEnd {
    /// The target was reached, `halt` was set, or the run failed.
    Done,
    /// A particle needs more room in the tree than was reserved.
    NeedsRoom,
}

/// One parallel phase of [`grow_parallel`] on a tree prepared for shared inserts.
#[allow(clippy::too_many_arguments)]
fn phase<const D: usize>(
    params: &Params,
    seed: u64,
    round: u32,
    target: u64,
    halt: &AtomicBool,
    cluster: &Cluster<D>,
    growth: &mut Growth<D>,
    stats: &mut PdlaStats,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<PhaseEnd, SimError>
where
    Dim<D>: Space<D>,
{
    let threads = params.threads;
    let start = growth.n as usize;
    let log = Mutex::new(Log {
        growth: std::mem::replace(growth, Growth::new(params)),
        guard: DiscardGuard::default(),
        error: None,
        needs_room: false,
    });
    let r_ext0 = log
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .growth
        .r_ext;
    // Particles stored so far (log positions are absolute: the earlier ones come first).
    let published = Published {
        count: AtomicUsize::new(start),
        r_ext: AtomicU64::new(r_ext0.to_bits()),
    };
    let ring = Ring::new();
    let slots: Vec<Slot> = (0..threads)
        .map(|_| Slot {
            epoch: AtomicU64::new(0),
        })
        .collect();
    let stop = AtomicBool::new(false);
    let wait_nanos = AtomicU64::new(0);
    let started = Instant::now();
    let ctx = Ctx {
        cluster,
        log: &log,
        published: &published,
        ring: &ring,
        slots: &slots,
        stop: &stop,
        halt,
        target,
        final_target: params.particles,
        wait_nanos: &wait_nanos,
    };
    let walk = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                s.spawn(move || {
                    let mut me = Thread {
                        r_ext: r_ext0,
                        applied: start,
                        pending: Vec::new(),
                        index: t,
                        walk: WalkState::new(params),
                    };
                    // Round 0 draws from the streams of a run without checkpoints.
                    let index = round.wrapping_mul(1024).wrapping_add(t as u32);
                    let mut rng = stream(seed, stream_id(PURPOSE_PDLA, index));
                    ctx.walk(&mut me, params, &mut rng, progress);
                    // A finished thread no longer holds anything from the tree.
                    ctx.slots[t].epoch.store(u64::MAX, Ordering::Release);
                    me.walk.counts
                })
            })
            .collect();
        let mut walk = WalkCounts::default();
        for h in handles {
            walk.add(&h.join().expect("a PDLA thread panicked"));
        }
        walk
    });
    stats.walk.add(&walk);
    stats.seconds += started.elapsed().as_secs_f64();
    stats.lock_wait_seconds += wait_nanos.into_inner() as f64 * 1e-9;
    let mut log = log.into_inner().unwrap_or_else(PoisonError::into_inner);
    stats.discarded += log.guard.total;
    *growth = log.growth;
    match log.error.take() {
        Some(e) => Err(e),
        None if log.needs_room => Ok(PhaseEnd::NeedsRoom),
        None => Ok(PhaseEnd::Done),
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

/// The shared side of PDLA: everything a stored particle changes (the positions themselves go
/// to the [`Ring`] and the tree).
struct Log<const D: usize> {
    growth: Growth<D>,
    guard: DiscardGuard,
    error: Option<SimError>,
    /// A particle needed more room in the tree than the phase reserved.
    needs_room: bool,
}

/// One thread's side of PDLA.
struct Thread<const D: usize> {
    /// Largest centre distance over the particles seen.
    r_ext: f64,
    /// Particles stored that the thread has taken into account (an absolute index).
    applied: usize,
    /// Read from the ring but not yet given to the walker.
    pending: Vec<[f64; D]>,
    index: usize,
    /// The memory of the thread's current walker.
    walk: WalkState<D>,
}

/// What one thread tells the others, on cache lines of its own (the tree's writer reads the
/// others' about once per 64 inserts).
#[repr(align(128))]
struct Slot {
    /// The reclamation epoch the thread announced at its walker's birth (see
    /// [`Orthtree::insert_shared`](spatial::orthtree::Orthtree::insert_shared)).
    epoch: AtomicU64,
}

/// What a stored particle publishes, read before every move, on cache lines of its own (away
/// from the log's mutex, which every store writes).
#[repr(align(128))]
struct Published {
    /// Particles stored (an absolute count: the ring's entries below it are written).
    count: AtomicUsize,
    /// `f64` bits of the largest centre distance over them (written under the lock, so it
    /// only grows).
    r_ext: AtomicU64,
}

/// References shared by the PDLA threads.
#[derive(Clone, Copy)]
struct Ctx<'a, const D: usize> {
    cluster: &'a Cluster<D>,
    log: &'a Mutex<Log<D>>,
    published: &'a Published,
    /// The newest stored positions, for the threads' near caches.
    ring: &'a Ring<D>,
    slots: &'a [Slot],
    stop: &'a AtomicBool,
    /// Set from outside (a signal): stop at the next quiescent point.
    halt: &'a AtomicBool,
    /// Where this call stops.
    target: u64,
    /// The run's final size (the last growth sample is taken there).
    final_target: u64,
    /// Nanoseconds threads spent waiting for the log's mutex (summed over threads).
    wait_nanos: &'a AtomicU64,
}

impl<const D: usize> Ctx<'_, D>
where
    Dim<D>: Space<D>,
{
    /// Takes the log's mutex, timing the wait when it is contended.
    #[inline]
    fn lock(&self) -> MutexGuard<'_, Log<D>> {
        match self.log.try_lock() {
            Ok(g) => return g,
            // A thread that panicked holding the log ends the phase with its panic (the
            // scope re-raises it); the log itself is only appended to, so it stays readable.
            Err(TryLockError::Poisoned(p)) => return p.into_inner(),
            Err(TryLockError::WouldBlock) => {}
        }
        let t = Instant::now();
        let g = self.log.lock().unwrap_or_else(PoisonError::into_inner);
        self.wait_nanos
            .fetch_add(t.elapsed().as_nanos() as u64, Ordering::Relaxed);
        g
    }

    /// Brings `me`, whose walker is at `p`, up to date if another thread stored particles;
    /// `false` to stop. Runs before every move, so the common case (nothing new) is one load;
    /// `stop` and `halt` are read when something was published, at every walker's birth and
    /// under the lock at sticking: a thread that misses them finishes its walker and stops
    /// there. The rare call gets a copy of `p`, so that the walker's position stays in
    /// registers ([`detached`]).
    #[inline(always)]
    fn sync(&self, me: &mut Thread<D>, p: &[f64; D]) -> bool {
        self.published.count.load(Ordering::Acquire) == me.applied
            || self.catch_up(me, &detached(p))
    }

    /// Whether the run goes on: neither stopped by a thread nor halted from outside.
    #[inline]
    fn running(&self) -> bool {
        !(self.stop.load(Ordering::Relaxed) || self.halt.load(Ordering::Relaxed))
    }

    /// [`sync`](Self::sync) when other threads stored particles: takes the count and `r_ext`.
    /// Only a walker whose near cache can still answer needs the new particles themselves, read
    /// from the ring without a lock; one whose cache cannot (or that the writers lapped) drops
    /// the cache, and a rebuild reads the tree, which holds every published particle.
    #[cold]
    #[inline(never)]
    fn catch_up(&self, me: &mut Thread<D>, p: &[f64; D]) -> bool {
        if !self.running() {
            return false;
        }
        let n = self.published.count.load(Ordering::Acquire);
        me.r_ext = me
            .r_ext
            .max(f64::from_bits(self.published.r_ext.load(Ordering::Relaxed)));
        if me.walk.near_useful(p) {
            if self
                .ring
                .read(me.applied, n, &self.published.count, &mut me.pending)
            {
                for q in me.pending.drain(..) {
                    me.walk.particle_added(&q);
                }
            } else {
                me.walk.drop_near();
            }
        }
        me.applied = n;
        (n as u64) < self.target
    }

    fn fail(&self, log: &mut Log<D>, e: SimError) {
        log.error.get_or_insert(e);
        self.stop.store(true, Ordering::Relaxed);
    }

    /// The smallest epoch the threads announced (see [`Slot`]).
    fn readers_epoch(&self) -> u64 {
        self.slots
            .iter()
            .map(|s| s.epoch.load(Ordering::Acquire))
            .min()
            .unwrap_or(u64::MAX)
    }

    /// One thread's walkers until the cluster is complete or the run fails.
    fn walk<R: Rng + ?Sized>(
        &self,
        me: &mut Thread<D>,
        params: &Params,
        rng: &mut R,
        progress: &(dyn Fn(u64) + Sync),
    ) {
        let tree = self.cluster.tree();
        loop {
            me.walk.reset();
            if !(self.running() && self.sync(me, &[0.0; D])) {
                return;
            }
            // The walker holds nothing from the tree yet: announce the epoch.
            self.slots[me.index]
                .epoch
                .store(tree.epoch(), Ordering::Release);
            let mut w = Walker::born(me.r_ext + params.birth_gap, rng);
            let stick = loop {
                // Plain walks only: PDLA refuses substrates and ballistic walkers (`Params::validate`).
                if let Some(p) =
                    w.advance::<false, _>(&mut me.walk, self.cluster, me.r_ext, params, rng)
                {
                    if !me.walk.refuse {
                        break p;
                    }
                    if let Some(p) = w.settle_detached(p, &mut me.walk, self.cluster, params, rng) {
                        break p;
                    }
                }
                if !self.sync(me, &w.p) {
                    return;
                }
            };
            // A jump or step can end inside a particle another thread stored during it; once
            // that particle is seen the next move would stick at once, overlapping it. The
            // pre-check covers the particles before `seen`, the check under the lock the ones
            // after: the walker's near cache holds those it has taken from the ring when its
            // ball covers the sticking point (near the cluster, the usual case); else the
            // tree, which holds every particle published before the load. Both checks are made
            // at the contact point, at distance 1 from the particle touched, also with noise
            // reduction: the position stored then, at distance `f` from it, is within `1 - f`
            // of the contact point, so at least `f` (less the tolerance) from every particle.
            let (seen, mut overlap) = match me.walk.any_within_cached(&stick, OVERLAP_DISTANCE) {
                Some(found) => (me.applied, found),
                None => {
                    let seen = self.published.count.load(Ordering::Acquire);
                    let mut found = false;
                    tree.for_each_within(&stick, OVERLAP_DISTANCE, |_| found = true);
                    (seen, found)
                }
            };
            let mut guard = self.lock();
            if guard.growth.n >= self.target
                || self.stop.load(Ordering::Relaxed)
                || self.halt.load(Ordering::Relaxed)
            {
                return;
            }
            // Re-check under the lock (section 3.4) against the particles other threads
            // stored since the pre-check (a handful at most; the tree, in the rare case that
            // the ring no longer holds them all).
            let now = self.published.count.load(Ordering::Relaxed);
            if !overlap && now > seen {
                let r_sq = OVERLAP_DISTANCE * OVERLAP_DISTANCE;
                let mut since = std::mem::take(&mut me.pending);
                overlap = if self.ring.read(seen, now, &self.published.count, &mut since) {
                    since.iter().any(|x| dist_sq(&stick, x) <= r_sq)
                } else {
                    let mut found = false;
                    tree.for_each_within(&stick, OVERLAP_DISTANCE, |_| found = true);
                    found
                };
                since.clear();
                me.pending = since;
            }
            if let Err(e) = guard.guard.record(overlap) {
                return self.fail(&mut guard, e);
            }
            if overlap {
                continue;
            }
            let stored = noise_reduced(stick, me.walk.touched(), params.noise_reduction);
            // Inserts happen under the lock held here, so the particle touched keeps its
            // tag and the arrival index is `growth.n`.
            let parent = match self.cluster.parent_of(me.walk.touched()) {
                Ok(parent) => parent,
                Err(e) => return self.fail(&mut guard, e),
            };
            let index = guard.growth.n as u32;
            // SAFETY: every thread announces its epoch at a walker's birth only, where it holds
            // nothing from the tree (`walk`, Release store), or u64::MAX once it stops reading;
            // `readers_epoch` is the minimum over all threads' slots (Acquire loads).
            #[allow(unsafe_code)]
            let inserted =
                unsafe { tree.insert_shared_tagged(stored, index, || self.readers_epoch()) };
            let (q, new_leaf) = match inserted {
                Ok(stored) => stored,
                Err(OrthtreeError::NeedsExclusive) => {
                    // The walker is dropped; the next phase reserves more room.
                    guard.needs_room = true;
                    self.stop.store(true, Ordering::Relaxed);
                    return;
                }
                Err(e) => return self.fail(&mut guard, e.into()),
            };
            let log = &mut *guard;
            log.growth.account(q, parent, self.final_target);
            let n = log.growth.n as usize;
            self.ring.write(n - 1, &q);
            self.published
                .r_ext
                .store(log.growth.r_ext.to_bits(), Ordering::Relaxed);
            self.published.count.store(n, Ordering::Release);
            if n % 1024 == 0 {
                progress(n as u64);
            }
            drop(guard);
            // The stuck particle lowers the shared distance maps once, atomically; until it
            // has, another thread's walker may jump by a stale bound, which the re-check at
            // its sticking catches like any move made before a particle was stored.
            if let Err(e) = self.cluster.update_maps(&q, me.walk.touched(), new_leaf) {
                return self.fail(&mut self.lock(), e);
            }
        }
    }
}
