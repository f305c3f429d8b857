//! The host's own latencies: core to core, measured next to the multi-threaded workloads of
//! `cargo xtask bench`, and memory by working-set size (`cargo xtask latency`), which turns
//! the DLA walk's counts of reads into a floor in microseconds.
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

/// One node of the pointer chase: the index of the next node, alone on its cache line.
#[repr(align(64))]
#[derive(Clone, Copy)]
struct Node(usize);

/// The mean latency in nanoseconds of a dependent load in a working set of `bytes` (rounded
/// down to whole 64-byte lines, at least two): a pointer chase through every line in one
/// random cycle (Sattolo's shuffle, so no line is skipped and each next address is
/// unpredictable to the prefetchers), `loads` loads after one warming lap. With transparent
/// huge pages `madvise`d it measures the caches and DRAM rather than the page walks on top, as
/// a large arena with huge pages would see; `huge_pages` false leaves the default 4 KiB pages.
#[allow(unsafe_code)] // madvise, on the vector's own allocation
pub fn memory_latency_ns(bytes: usize, loads: u64, huge_pages: bool, seed: u64) -> f64 {
    let n = (bytes / size_of::<Node>()).max(2);
    let cycle = single_cycle(n, seed);
    // Allocated and advised before any page is touched: a page faulted in before the advice
    // stays a 4 KiB page until the kernel's background collapse, if ever.
    let mut nodes: Vec<Node> = Vec::with_capacity(n);
    #[cfg(target_os = "linux")]
    if huge_pages {
        // madvise takes a page-aligned start (the allocator's header puts a large vector 16
        // bytes past a page boundary, and an unaligned call fails with EINVAL): advise the
        // whole pages inside the vector.
        let start = nodes.as_mut_ptr() as usize;
        let aligned = start.next_multiple_of(4096);
        let end = start + nodes.capacity() * size_of::<Node>();
        if end > aligned {
            // SAFETY: the range lies inside the vector's own allocation; MADV_HUGEPAGE only
            // changes how the kernel backs it.
            let rc = unsafe {
                libc::madvise(
                    aligned as *mut libc::c_void,
                    end - aligned,
                    libc::MADV_HUGEPAGE,
                )
            };
            assert_eq!(rc, 0, "madvise(MADV_HUGEPAGE) failed");
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = huge_pages;
    nodes.extend(cycle.into_iter().map(Node));
    let mut at = 0usize;
    for _ in 0..n {
        at = nodes[at].0;
    }
    let start = Instant::now();
    for _ in 0..loads {
        at = nodes[at].0;
    }
    let ns = start.elapsed().as_nanos() as f64 / loads.max(1) as f64;
    std::hint::black_box(at);
    ns
}

/// A uniformly random permutation of `0..n` that is one cycle through all of them (Sattolo's
/// algorithm), as each element's successor.
fn single_cycle(n: usize, seed: u64) -> Vec<usize> {
    let mut order: Vec<usize> = (0..n).collect();
    let mut state = seed | 1;
    for i in (1..n).rev() {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        order.swap(i, (state % i as u64) as usize);
    }
    let mut next = vec![0; n];
    for w in 0..n {
        next[order[w]] = order[(w + 1) % n];
    }
    next
}

/// `cargo xtask latency`: the memory latency at working sets from 16 KiB to `max_bytes`
/// (powers of 2), with 4 KiB and with huge pages, as a markdown table.
pub fn latency_table(max_bytes: usize, loads: u64) -> String {
    let mut out = String::from(
        "| working set | ns per dependent load, 4 KiB pages | ns, transparent huge pages |\n|---|---|---|\n",
    );
    let mut bytes = 16 << 10;
    while bytes <= max_bytes {
        let small = memory_latency_ns(bytes, loads, false, 1);
        let huge = memory_latency_ns(bytes, loads, true, 1);
        let size = if bytes >= 1 << 30 {
            format!("{} GiB", bytes >> 30)
        } else if bytes >= 1 << 20 {
            format!("{} MiB", bytes >> 20)
        } else {
            format!("{} KiB", bytes >> 10)
        };
        out.push_str(&format!("| {size} | {small:.1} | {huge:.1} |\n"));
        eprintln!("{size}: {small:.1} ns, {huge:.1} ns with huge pages");
        bytes *= 2;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pointer_chase_visits_every_line_and_takes_time() {
        let ns = memory_latency_ns(64 << 10, 10_000, true, 7);
        assert!(ns.is_finite() && ns > 0.0, "{ns}");
        // One cycle through all lines: from 0, the chase returns to 0 after exactly n loads.
        for n in [2, 3, 1000] {
            let next = single_cycle(n, 7);
            let (mut at, mut steps) = (next[0], 1);
            while at != 0 {
                at = next[at];
                steps += 1;
            }
            assert_eq!(steps, n);
        }
    }

    #[test]
    fn a_round_trip_takes_time_and_ends() {
        // Few trips: other tests' threads may share the cores.
        if let Some(ns) = core_round_trip_ns(1, 50) {
            assert!(ns.is_finite() && ns > 0.0, "{ns}");
        }
    }
}
