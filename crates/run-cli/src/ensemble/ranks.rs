//! An ensemble over the ranks of an MPI job (feature `mpi`): `mpirun -np P PROG --seeds ...`.
//! Every rank runs members, up to `--jobs` at once, each in `DIR/seed-NNNN/` of the shared
//! directory. Rank 0 also hands them out: its own threads take the next member from the list,
//! and the other ranks ask it for one whenever they have room (a rank that finishes a member
//! takes the next seed); at the end it writes the combined result. Messages are `u64` triples.
//!
//! Worker to rank 0: `[seed, ended, want]`: the member `seed` ended (`ended` = [`OK`],
//! [`INTERRUPTED`] or [`FAILED`]; `seed` = [`NONE`] when there is nothing to report) and the
//! worker wants another one (`want` = 1) or not (0), or says goodbye (`want` = [`BYE`]). Rank 0
//! answers a `want` = 1 with `[seed, todo]` or `[NONE, 0]` (no more members).
//!
//! - **CPUs** ([`place`]). Launchers bind ranks to CPUs (Open MPI binds each rank to one core
//!   for up to two ranks, to a socket or NUMA domain beyond), and children inherit the binding:
//!   a rank's members would share one core. Each rank widens its CPU affinity to every CPU of
//!   its node it may use (the kernel limits the request to the job's cpuset, as Slurm's cgroups
//!   set it), and its members inherit that; the ranks on one node split its CPUs equally, and
//!   each sizes its default `--jobs` by its share.
//! - **Waiting** ([`receive`]): Open MPI's blocking receive polls, keeping a core busy; rank 0
//!   and the other ranks probe without blocking and sleep between probes instead, so the
//!   dispatching costs rank 0 next to no CPU.

use super::{Ended, Member, Todo, member_dir, run_member};
use crate::cli::Progress;
use mpi::point_to_point::{MatchedReceiveVec, Status};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use run_io::MpiPlace;
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

const NONE: u64 = u64::MAX;
const OK: u64 = 0;
const INTERRUPTED: u64 = 1;
const FAILED: u64 = 2;
const BYE: u64 = 2;

fn encode(end: &Ended) -> u64 {
    match end {
        Ended::Ok => OK,
        Ended::Interrupted => INTERRUPTED,
        Ended::Failed(_) => FAILED,
    }
}

/// Rank 0: answers the other ranks until each has said goodbye, and meanwhile runs members
/// itself, `local.1` at a time (none when `local` is `None`), from the same list; returns how
/// each member ended (a failure's message is the last line of the member's log in the shared
/// directory).
pub(super) fn dispatch(
    world: &SimpleCommunicator,
    out: &Path,
    work: &[(u64, Todo)],
    local: Option<(&Member<'_>, usize)>,
    stop: &AtomicBool,
    progress: &Progress,
) -> Vec<(u64, Ended)> {
    let next = AtomicUsize::new(0);
    let ended: Mutex<Vec<(u64, Ended)>> = Mutex::new(Vec::new());
    let record = |seed: u64, e: Ended| {
        let mut ended = ended.lock().unwrap_or_else(|p| p.into_inner());
        ended.push((seed, e));
        progress.set_position(ended.len() as u64);
    };
    std::thread::scope(|s| {
        if let Some((member, jobs)) = local {
            for _ in 0..jobs {
                // Each thread starts its members and waits for them (`tie_member_to_ensemble`).
                s.spawn(|| {
                    while !stop.load(Ordering::Relaxed) {
                        let Some(&(seed, todo)) = work.get(next.fetch_add(1, Ordering::Relaxed))
                        else {
                            return;
                        };
                        record(seed, run_member(member, seed, todo, stop));
                    }
                });
            }
        }
        let mut workers = world.size() - 1;
        while workers > 0 {
            let (msg, status) = receive(&world.any_process());
            let [seed, end, want] = msg[..] else {
                continue;
            };
            if seed != NONE {
                let e = match end {
                    OK => Ended::Ok,
                    INTERRUPTED => Ended::Interrupted,
                    _ => {
                        let log = member_dir(out, seed).join(super::MEMBER_LOG);
                        let last = super::member::last_line(&log);
                        Ended::Failed(if last.is_empty() {
                            format!(
                                "failed on MPI rank {} (nothing in {})",
                                status.source_rank(),
                                log.display()
                            )
                        } else {
                            last
                        })
                    }
                };
                record(seed, e);
            }
            match want {
                1 => {
                    let reply = match work.get(next.load(Ordering::Relaxed)) {
                        Some(_) if !stop.load(Ordering::Relaxed) => {
                            match work.get(next.fetch_add(1, Ordering::Relaxed)) {
                                Some(&(s, todo)) => [s, u64::from(todo == Todo::Resume)],
                                None => [NONE, 0],
                            }
                        }
                        _ => [NONE, 0],
                    };
                    world.process_at_rank(status.source_rank()).send(&reply[..]);
                }
                BYE => workers -= 1,
                _ => {}
            }
        }
    });
    ended.into_inner().unwrap_or_else(|p| p.into_inner())
}

/// A message from `source`, waited for without keeping a core busy: probes that do not block,
/// with sleeps between them from 1 ms growing to 20 ms (so a reply comes within 20 ms, and an
/// idle rank 0 wakes 50 times a second).
fn receive<S: Source>(source: &S) -> (Vec<u64>, Status) {
    let mut pause = Duration::from_millis(1);
    loop {
        if let Some(probed) = source.immediate_matched_probe() {
            return probed.matched_receive_vec::<u64>();
        }
        std::thread::sleep(pause);
        pause = (pause * 2).min(Duration::from_millis(20));
    }
}

/// Where a rank is and what its members may use.
#[derive(Debug, Clone)]
pub(super) struct Place {
    /// Rank and ranks, and the CPUs of this rank's share of its node.
    pub mpi: MpiPlace,
    /// CPUs the launcher bound this rank to.
    pub bound: usize,
    /// CPUs of the node its members may use (after widening).
    pub node_cpus: usize,
    /// Ranks on this node (each runs members).
    pub node_workers: usize,
}

/// Collective over `world`: finds the ranks sharing this rank's node, widens this rank's CPU
/// affinity to the node's CPUs it may use (see the module documentation), and returns its
/// share of them.
pub(super) fn place(world: &SimpleCommunicator) -> Place {
    let rank = world.rank();
    let node = world.split_shared(rank);
    let mut on_node = vec![0i32; usize::try_from(node.size()).unwrap_or(1)];
    node.all_gather_into(&rank, &mut on_node[..]);
    on_node.sort_unstable();
    let index = on_node.iter().position(|&r| r == rank).unwrap_or(0);
    let bound = affinity::count();
    let node_cpus = affinity::widen();
    let share = super::node_share(node_cpus, on_node.len(), index);
    Place {
        mpi: MpiPlace {
            rank: u64::try_from(rank).unwrap_or(0),
            ranks: u64::try_from(world.size()).unwrap_or(1),
            cpus: share as u64,
        },
        bound,
        node_cpus,
        node_workers: on_node.len(),
    }
}

/// The calling thread's CPU affinity (Linux); threads and processes it starts inherit it.
mod affinity {
    /// CPUs the calling thread may run on.
    #[cfg(target_os = "linux")]
    pub fn count() -> usize {
        use nix::sched::{CpuSet, sched_getaffinity};
        use nix::unistd::Pid;
        sched_getaffinity(Pid::from_raw(0)).map_or_else(
            |_| std::thread::available_parallelism().map_or(1, |n| n.get()),
            |set| {
                (0..CpuSet::count())
                    .filter(|&c| set.is_set(c).unwrap_or(false))
                    .count()
                    .max(1)
            },
        )
    }

    /// Asks for every CPU; the kernel grants those of the process's cpuset (all online CPUs
    /// outside a batch system's cgroup). Returns the CPUs granted (the old ones if refused).
    #[cfg(target_os = "linux")]
    pub fn widen() -> usize {
        use nix::sched::{CpuSet, sched_setaffinity};
        use nix::unistd::Pid;
        let mut all = CpuSet::new();
        for c in 0..CpuSet::count() {
            let _ = all.set(c);
        }
        if let Err(e) = sched_setaffinity(Pid::from_raw(0), &all) {
            tracing::warn!("could not widen this rank's CPU affinity for its members: {e}");
        }
        count()
    }

    #[cfg(not(target_os = "linux"))]
    pub fn count() -> usize {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    }

    #[cfg(not(target_os = "linux"))]
    pub fn widen() -> usize {
        count()
    }
}

/// Any rank but 0: runs the members rank 0 hands out, `jobs` at a time, until there are none.
/// Returns whether it stopped early (a signal, or a member interrupted).
pub(super) fn work(
    world: &SimpleCommunicator,
    member: &Member<'_>,
    jobs: usize,
    stop: &AtomicBool,
) -> bool {
    let root = world.process_at_rank(0);
    let (tx, rx) = mpsc::channel::<(u64, Ended)>();
    let mut interrupted = false;
    std::thread::scope(|s| {
        let mut in_flight = 0usize;
        let mut more = true;
        let mut report: Option<(u64, Ended)> = None;
        loop {
            // Ask for members while there is room (reporting the last one that ended).
            while more && in_flight < jobs && !stop.load(Ordering::Relaxed) {
                let (seed, end) = report.take().map_or((NONE, OK), |(s, e)| (s, encode(&e)));
                root.send(&[seed, end, 1][..]);
                let (reply, _) = receive(&root);
                match reply[..] {
                    [seed, resume] if seed != NONE => {
                        let todo = if resume == 1 { Todo::Resume } else { Todo::Run };
                        let tx = tx.clone();
                        // The member's thread starts it and waits for it: the member dies
                        // when that thread ends (`tie_member_to_ensemble`).
                        s.spawn(move || {
                            let end = run_member(member, seed, todo, stop);
                            let _ = tx.send((seed, end));
                        });
                        in_flight += 1;
                    }
                    _ => more = false,
                }
            }
            if let Some((seed, e)) = report.take() {
                root.send(&[seed, encode(&e), 0][..]);
            }
            if in_flight == 0 {
                break;
            }
            match rx.recv() {
                Ok(done) => {
                    in_flight -= 1;
                    interrupted |= done.1 == Ended::Interrupted;
                    report = Some(done);
                }
                Err(_) => break,
            }
        }
        root.send(&[NONE, OK, BYE][..]);
    });
    interrupted || stop.load(Ordering::Relaxed)
}

/// Rank 0's CPU seconds so far (user and system, every thread: its MPI library's too).
pub(super) fn cpu_seconds() -> f64 {
    run_io::ProcessUsage::now().map_or(0.0, |u| u.cpu_seconds)
}

/// What rank 0 reports after dispatching: the wall time and its own CPU time over it (its
/// members' CPU time is theirs, not counted).
pub(super) fn dispatch_line(
    program: &str,
    members: usize,
    ranks: i32,
    wall: Instant,
    cpu0: f64,
) -> String {
    format!(
        "{program}: MPI rank 0 dispatched {members} members over {ranks} ranks in {:.1} s of wall time, using {:.2} s of CPU itself",
        wall.elapsed().as_secs_f64(),
        (cpu_seconds() - cpu0).max(0.0)
    )
}
