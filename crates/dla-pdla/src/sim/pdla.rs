//! Parallel DLA (PDLA; Sosa-Herrera & Rodriguez-Romo, "Variable precision distance search for
//! random fractal cluster simulations", section 3.4): `params.threads` walkers at once, each
//! thread on its own replica of the cluster, stuck particles published through one shared
//! log, and a re-check at sticking that discards a walker overlapping a particle stored
//! meanwhile.
//!
//! Invariants: the log holds the stored particles in one total order, and every replica
//! applies them in that order, so the replicas' trees are identical once they have applied
//! the same prefix; a particle is stored only if no particle stored before it (in log order)
//! lies within [`OVERLAP_DISTANCE`]; every stored particle is accounted for once, under the
//! log's lock; a run that only discards stops with [`SimError::DiscardLivelock`].

use super::growth::Growth;
use crate::cluster::Cluster;
use crate::error::SimError;
use crate::farfield::norm;
use crate::params::Params;
use crate::space::{Dim, Space};
use crate::walker::{WalkState, Walker};
use core_lattice::rng::{Rng, stream, stream_id};
use parking_lot::Mutex;
use spatial::orthtree::dist_sq;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
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
}

/// Grows `cluster` (holding `growth.n` particles) to `until` (at most `params.particles`, the
/// run's final size) with `params.threads` walkers at once, adding to `stats`; returns early,
/// at a quiescent point, once `halt` is set. Every thread stops at a quiescent point: the
/// particles of the log are applied everywhere and walkers still on their way are dropped
/// (walkers are independent, so a new one born later is as good), which is where a PDLA
/// checkpoint is taken. `round` numbers the calls of a run, so that each draws from its own
/// random streams.
///
/// Each thread walks on its own replica of the orthtree, so walking takes no lock and touches
/// no shared cache line but one atomic counter; stuck particles go through a shared log (a
/// mutex held only to copy the new entries, re-check against them, append and account for one
/// particle; inserting into the replica happens after the mutex is released). Before every
/// move a thread applies the particles other threads appended since its last move, so it walks
/// on the cluster as it was at most one move ago, as in the paper's shared tree. At sticking it
/// re-checks, under the log's lock, that none of the particles stored since its last move lies
/// within [`OVERLAP_DISTANCE`] (section 3.4), and against its replica before taking the lock
/// (a move can end inside a particle stored during it); if one does the walker is discarded
/// and counted. The replicas receive the same points in the same order, so they are
/// identical; thread 0's becomes the simulation's tree.
#[allow(clippy::too_many_arguments)]
pub(crate) fn grow_parallel<const D: usize>(
    params: &Params,
    seed: u64,
    round: u32,
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
    let threads = params.threads;
    let start = growth.n as usize;
    // The replicas share one set of distance maps, sized for the final cluster now (they
    // cannot grow once shared). Before anything is moved out of `growth` and `cluster`, so an
    // error leaves them as they were.
    cluster.reserve_maps(
        Dim::<D>::expected_r_ext(params.particles).max(growth.r_ext) + params.birth_gap,
    )?;
    let log = Mutex::new(Log {
        points: Vec::new(),
        base: start,
        growth: std::mem::replace(growth, Growth::new(params)),
        guard: DiscardGuard::default(),
        error: None,
    });
    // Particles stored so far (log positions are absolute: the serial ones come first).
    let published = AtomicUsize::new(start);
    let applied: Vec<AtomicUsize> = (0..threads).map(|_| AtomicUsize::new(start)).collect();
    let stop = AtomicBool::new(false);
    let r_ext0 = log.lock().growth.r_ext;
    let mut replicas: Vec<Cluster<D>> = (1..threads).map(|_| cluster.clone()).collect();
    replicas.insert(0, std::mem::take(cluster));
    let wait_nanos = AtomicU64::new(0);
    let started = Instant::now();
    let ctx = Ctx {
        log: &log,
        published: &published,
        applied: &applied,
        stop: &stop,
        halt,
        target,
        final_target: params.particles,
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
                    // Round 0 draws from the streams of a run without checkpoints.
                    let index = round.wrapping_mul(1024).wrapping_add(t as u32);
                    let mut rng = stream(seed, stream_id(PURPOSE_PDLA, index));
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
    stats.seconds += started.elapsed().as_secs_f64();
    stats.lock_wait_seconds += wait_nanos.into_inner() as f64 * 1e-9;
    let mut log = log.into_inner();
    let mut first = clusters.swap_remove(0);
    drop(clusters);
    // Thread 0 may have stopped before applying the last particles of the others. Their
    // threads lowered the shared maps already. An error here (the tree out of indices, say)
    // is reported after the cluster and the growth accounting are back in place.
    let done = applied[0].load(Ordering::Relaxed);
    let caught_up = log.points[done - log.base..]
        .iter()
        .try_for_each(|q| first.insert_tree(*q).map(drop));
    *cluster = first;
    stats.discarded += log.guard.total;
    *growth = log.growth;
    match (log.error.take(), caught_up) {
        (Some(e), _) | (None, Err(e)) => Err(e),
        (None, Ok(())) => Ok(()),
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
    /// Set from outside (a signal): stop at the next quiescent point.
    halt: &'a AtomicBool,
    /// Where this call stops.
    target: u64,
    /// The run's final size (the last growth sample is taken there).
    final_target: u64,
    /// Nanoseconds threads spent waiting for the log's mutex (summed over threads).
    wait_nanos: &'a AtomicU64,
}

/// Log entries are dropped once every thread has applied them and this many have piled up.
const LOG_TRIM: usize = 4096;

impl<const D: usize> Ctx<'_, D>
where
    Dim<D>: Space<D>,
{
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
            rep.walk.particle_added(&q);
            rep.r_ext = rep.r_ext.max(norm(&q));
        }
        true
    }

    /// Brings `rep` up to date if another thread stored particles; `false` to stop.
    #[inline]
    fn sync(&self, rep: &mut Replica<D>) -> bool {
        if self.stop.load(Ordering::Relaxed) || self.halt.load(Ordering::Relaxed) {
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
            if guard.growth.n >= self.target
                || self.stop.load(Ordering::Relaxed)
                || self.halt.load(Ordering::Relaxed)
            {
                return;
            }
            self.take_pending(&guard, rep);
            // Re-check under the lock (section 3.4) against the particles other
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
            log.growth.account(q, self.final_target);
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
