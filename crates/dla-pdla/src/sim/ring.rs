//! The PDLA threads' record of the newest stored particles: a ring of the last [`RING`]
//! positions, written under the log's lock and read without it.
//!
//! A thread whose walker keeps a near cache needs the particles the others stored since its
//! last look. Reading them from a vector under the log's mutex moved the mutex's cache line to
//! the reading core and back for every particle stored; the ring is read like a sequence lock
//! instead: the reader copies the entries between its position and the published count, then
//! checks that the writers have not lapped the oldest of them meanwhile, and if they have (a
//! thread descheduled for thousands of stores) it drops what it copied and its near cache,
//! which the tree (holding every published particle) rebuilds.
//!
//! Ordering: entry `i` is written by the writer of particle `i`, under the lock, after a
//! release fence and before the count `i + 1` is published (release). A reader loads the count
//! (acquire), copies, then issues an acquire fence and loads the count again: if it copied any
//! entry that a later writer was overwriting, that writer's fence makes the count it had
//! published before writing, at least `i + RING`, visible to the second load. Coordinates are
//! stored as `AtomicU64` bits (plain moves on x86-64 and AArch64), so a torn read is a detected
//! lap, never undefined behaviour.

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering, fence};

/// Entries in the ring: far more than a thread falls behind between two moves.
pub(super) const RING: usize = 4096;

/// The last [`RING`] stored positions, by absolute particle index modulo `RING`.
pub(super) struct Ring<const D: usize> {
    entries: Box<[[AtomicU64; D]]>,
}

impl<const D: usize> Ring<D> {
    pub(super) fn new() -> Self {
        Ring {
            entries: (0..RING)
                .map(|_| std::array::from_fn(|_| AtomicU64::new(0)))
                .collect(),
        }
    }

    /// Records particle number `i` at `q`; the caller holds the log's lock and publishes the
    /// count `i + 1` (release) afterwards.
    pub(super) fn write(&self, i: usize, q: &[f64; D]) {
        // Orders the publication of the count `i` (made before the lock was taken) before the
        // overwrite of entry `i - RING` (see the module documentation).
        fence(Ordering::Release);
        for (e, x) in self.entries[i % RING].iter().zip(q) {
            e.store(x.to_bits(), Ordering::Relaxed);
        }
    }

    /// Appends particles `from..to` to `out`, where `to` is a count loaded (acquire) from
    /// `count`, the published count; `false` when they could not all be read intact (the ring
    /// has been lapped), and then `out` is as it was.
    pub(super) fn read(
        &self,
        from: usize,
        to: usize,
        count: &AtomicUsize,
        out: &mut Vec<[f64; D]>,
    ) -> bool {
        if to - from >= RING {
            return false;
        }
        let len = out.len();
        out.extend((from..to).map(|i| {
            let e = &self.entries[i % RING];
            std::array::from_fn(|k| f64::from_bits(e[k].load(Ordering::Relaxed)))
        }));
        fence(Ordering::Acquire);
        // Entry `from` is overwritten only once the count has reached `from + RING`.
        if count.load(Ordering::Relaxed) - from >= RING {
            out.truncate(len);
            return false;
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_what_was_written_until_it_is_lapped() {
        let ring = Ring::<2>::new();
        let count = AtomicUsize::new(0);
        let at = |i: usize| [i as f64, -(i as f64) * 0.5];
        for i in 0..RING + 10 {
            ring.write(i, &at(i));
            count.store(i + 1, Ordering::Release);
        }
        let n = count.load(Ordering::Acquire);
        let mut out = vec![[9.0, 9.0]];
        assert!(ring.read(n - 5, n, &count, &mut out));
        assert_eq!(out[1..], (n - 5..n).map(at).collect::<Vec<_>>()[..]);
        assert_eq!(out[0], [9.0, 9.0]);
        // The oldest entries still in the ring, and one that was overwritten.
        assert!(ring.read(n - RING + 1, n, &count, &mut Vec::new()));
        let mut lapped = vec![[1.0, 1.0]];
        assert!(!ring.read(n - RING, n, &count, &mut lapped));
        assert_eq!(lapped, vec![[1.0, 1.0]]);
        // Lapped after the count was read: the second look at the count sees it.
        let from = n - 3;
        for i in n..from + RING {
            ring.write(i, &at(i));
            count.store(i + 1, Ordering::Release);
        }
        assert!(!ring.read(from, n, &count, &mut Vec::new()));
    }
}
