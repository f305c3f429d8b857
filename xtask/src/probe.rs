//! The host's core-to-core latency, measured next to the multi-threaded workloads of
//! `cargo xtask bench`.
//!
//! PDLA's threads share one tree, one set of distance maps and one log, so every stored
//! particle moves a handful of cache lines from one core to the other. On a virtual machine
//! the time of that move depends on where the hypervisor places the virtual CPUs (two
//! hyperthreads of one core, two cores of one L3, or two L3s): on the 2-core VM of
//! `docs/benchmarks.md` the round trip below went from about 60 to about 350 ns between runs
//! a few seconds apart, and the two-thread speed-up with it. A speed-up reported without this
//! figure cannot be told apart from a slow placement.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// A counter on a cache line of its own.
#[repr(align(128))]
struct Line(AtomicU64);

/// Median over `rounds` of the mean round trip, in nanoseconds, of a cache line bounced
/// between two threads (`trips` round trips per round): one thread writes an odd value and
/// waits for the next even one, the other answers. Both spin on plain loads (a pause hint in
/// the loop would add its own latency to every trip), so each holds a core; `None` on a
/// machine with fewer than two.
pub fn core_round_trip_ns(rounds: usize, trips: u64) -> Option<f64> {
    if std::thread::available_parallelism().map_or(1, usize::from) < 2 {
        return None;
    }
    // The first `warm` trips are not timed: they wait for the second thread to be scheduled
    // (which can take milliseconds if it starts on the core the first one spins on).
    let warm = 1000;
    let mut means: Vec<f64> = (0..rounds.max(1))
        .map(|_| {
            let flag = Line(AtomicU64::new(0));
            std::thread::scope(|s| {
                s.spawn(|| {
                    for i in 0..warm + trips {
                        while flag.0.load(Ordering::Acquire) != 2 * i + 1 {}
                        flag.0.store(2 * i + 2, Ordering::Release);
                    }
                });
                let mut start = Instant::now();
                for i in 0..warm + trips {
                    if i == warm {
                        start = Instant::now();
                    }
                    flag.0.store(2 * i + 1, Ordering::Release);
                    while flag.0.load(Ordering::Acquire) != 2 * i + 2 {}
                }
                start.elapsed().as_nanos() as f64 / trips.max(1) as f64
            })
        })
        .collect();
    means.sort_by(f64::total_cmp);
    Some(means[means.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_round_trip_takes_time_and_ends() {
        // Few trips: other tests' threads may share the cores.
        if let Some(ns) = core_round_trip_ns(1, 50) {
            assert!(ns.is_finite() && ns > 0.0, "{ns}");
        }
    }
}
