//! An ensemble over the ranks of an MPI job (feature `mpi`): `mpirun -np P PROG --seeds ...`.
//! Rank 0 hands out members one at a time as the other ranks ask (a rank that finishes a member
//! takes the next seed), then writes the combined result; every other rank runs up to `--jobs`
//! members at once, each in `DIR/seed-NNNN/` of the shared directory. Messages are `u64` triples.
//!
//! Worker to rank 0: `[seed, ended, want]`: the member `seed` ended (`ended` = [`OK`],
//! [`INTERRUPTED`] or [`FAILED`]; `seed` = [`NONE`] when there is nothing to report) and the
//! worker wants another one (`want` = 1) or not (0), or says goodbye (`want` = [`BYE`]). Rank 0
//! answers a `want` = 1 with `[seed, todo]` or `[NONE, 0]` (no more members).

use super::{Ended, Todo, member_dir, run_member};
use crate::cli::Progress;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use std::ffi::OsString;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;

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

/// Rank 0: answers the workers until each has said goodbye; returns how each member ended
/// (a failure's message is the last line of the member's log in the shared directory).
pub(super) fn dispatch(
    world: &SimpleCommunicator,
    out: &Path,
    work: &[(u64, Todo)],
    stop: &AtomicBool,
    progress: &Progress,
) -> Vec<(u64, Ended)> {
    let mut next = 0;
    let mut workers = world.size() - 1;
    let mut ended = Vec::new();
    while workers > 0 {
        let (msg, status) = world.any_process().receive_vec::<u64>();
        let [seed, end, want] = msg[..] else {
            continue;
        };
        if seed != NONE {
            let e = match end {
                OK => Ended::Ok,
                INTERRUPTED => Ended::Interrupted,
                _ => {
                    let log = member_dir(out, seed).join(super::MEMBER_LOG);
                    let last = super::last_line(&log);
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
            ended.push((seed, e));
            progress.set_position(ended.len() as u64);
        }
        match want {
            1 => {
                let reply = match work.get(next) {
                    Some(&(s, todo)) if !stop.load(Ordering::Relaxed) => {
                        next += 1;
                        [s, u64::from(todo == Todo::Resume)]
                    }
                    _ => [NONE, 0],
                };
                world.process_at_rank(status.source_rank()).send(&reply[..]);
            }
            BYE => workers -= 1,
            _ => {}
        }
    }
    ended
}

/// Any rank but 0: runs the members rank 0 hands out, `jobs` at a time, until there are none.
pub(super) fn work(
    world: &SimpleCommunicator,
    exe: &Path,
    args: &[OsString],
    out: &Path,
    jobs: usize,
    stop: &AtomicBool,
) {
    let root = world.process_at_rank(0);
    let (tx, rx) = mpsc::channel::<(u64, Ended)>();
    std::thread::scope(|s| {
        let mut in_flight = 0usize;
        let mut more = true;
        let mut report: Option<(u64, Ended)> = None;
        loop {
            // Ask for members while there is room (reporting the last one that ended).
            while more && in_flight < jobs && !stop.load(Ordering::Relaxed) {
                let (seed, end) = report.take().map_or((NONE, OK), |(s, e)| (s, encode(&e)));
                root.send(&[seed, end, 1][..]);
                let (reply, _) = root.receive_vec::<u64>();
                match reply[..] {
                    [seed, resume] if seed != NONE => {
                        let todo = if resume == 1 { Todo::Resume } else { Todo::Run };
                        let tx = tx.clone();
                        s.spawn(move || {
                            let end = run_member(exe, args, out, seed, todo, stop);
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
                    report = Some(done);
                }
                Err(_) => break,
            }
        }
        root.send(&[NONE, OK, BYE][..]);
    });
}
