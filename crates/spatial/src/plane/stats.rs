//! The work counters of the plane-grid queries: the public snapshot [`SearchStats`] and the
//! atomic `Counters` a [`PlaneGrid`](super::PlaneGrid) keeps.
//!
//! Invariant: each query adds its own tally once, when it finishes (`Counters::add`), so the
//! counters are sums over whole queries; `Relaxed` ordering suffices because they synchronise
//! nothing else.

use std::sync::atomic::{AtomicU64, Ordering};

/// Work done by the queries of a [`PlaneGrid`](super::PlaneGrid), for the scaling study of the
/// grid-boxing paper, section IV.B (Fig. 9, Table I): what the grid boxes save compared with the
/// exhaustive scan.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct SearchStats {
    /// Full squared-distance evaluations against candidate items: items of the wanted kind, not
    /// excluded, that passed the per-axis early exit (`|dx|` and `|dy|` within the radius).
    pub distance_evals: u64,
    /// Items looked at (kind, exclusion and per-axis tests): every item of every box a query
    /// scanned, up to the point where it stopped. In [`BoxSize::None`](super::BoxSize::None) mode
    /// this is N per query (less for capped counts and `any_within`); with boxes, the items of the
    /// halo.
    pub items_scanned: u64,
    /// Box-map lookups and box visits: hash lookups of ring boxes (only for boxes that can hold
    /// an answer) plus occupied boxes examined by the one-pass fallback; 1 per query in
    /// [`BoxSize::None`](super::BoxSize::None) mode.
    pub boxes_probed: u64,
}

/// The atomic counters behind [`SearchStats`]; one `Relaxed` add per counter per query.
#[derive(Debug, Default)]
pub(super) struct Counters {
    pub(super) distance_evals: AtomicU64,
    pub(super) items_scanned: AtomicU64,
    pub(super) boxes_probed: AtomicU64,
}

impl From<SearchStats> for Counters {
    fn from(s: SearchStats) -> Self {
        Counters {
            distance_evals: AtomicU64::new(s.distance_evals),
            items_scanned: AtomicU64::new(s.items_scanned),
            boxes_probed: AtomicU64::new(s.boxes_probed),
        }
    }
}

impl Counters {
    pub(super) fn load(&self) -> SearchStats {
        SearchStats {
            distance_evals: self.distance_evals.load(Ordering::Relaxed),
            items_scanned: self.items_scanned.load(Ordering::Relaxed),
            boxes_probed: self.boxes_probed.load(Ordering::Relaxed),
        }
    }

    pub(super) fn take(&self) -> SearchStats {
        SearchStats {
            distance_evals: self.distance_evals.swap(0, Ordering::Relaxed),
            items_scanned: self.items_scanned.swap(0, Ordering::Relaxed),
            boxes_probed: self.boxes_probed.swap(0, Ordering::Relaxed),
        }
    }

    pub(super) fn add(&self, evals: u64, scanned: u64, probed: u64) {
        for (c, n) in [
            (&self.distance_evals, evals),
            (&self.items_scanned, scanned),
            (&self.boxes_probed, probed),
        ] {
            if n > 0 {
                c.fetch_add(n, Ordering::Relaxed);
            }
        }
    }
}
