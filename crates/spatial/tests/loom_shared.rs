//! Model-checked test of the orthtree's shared inserts (PDLA's one writer, many readers), with
//! the loom crate. This runs the **real** orthtree code: built with `--cfg loom`, the tree's
//! atomics are loom's (`orthtree/sync.rs`) and every read and write of its arenas is recorded
//! on a loom cell (`orthtree/arena.rs`), so loom explores the interleavings of a writer and a
//! reader, and the weak-memory outcomes of every load, and fails on any access to a node, leaf
//! record or point record that the protocol does not order after its initialisation (or on a
//! block reused while a reader may still scan it).
//!
//! ```text
//! RUSTFLAGS="--cfg loom" CARGO_TARGET_DIR=target/loom LOOM_MAX_PREEMPTIONS=2 \
//!     cargo test -p spatial --test loom_shared --release
//! ```
//!
//! (`CARGO_TARGET_DIR` keeps the loom build apart from the ordinary one, which would otherwise
//! be rebuilt after it. `--release` because an iteration that runs beside inserts counts more
//! points than the tree's length when it began, and the iterator's remaining count wraps,
//! which debug builds report as an overflow.)
//!
//! Under `cfg(loom)` the reclamation epoch advances at every shared insert (64 otherwise) and
//! `prepare_shared` reserves little room, so that two inserts reach every step: a leaf that
//! outgrows its block (the block is retired), a new path of nodes and a leaf published by one
//! `Release` store, and the reuse of the retired block for the new leaf once the reader has
//! announced a later epoch.
#![cfg(loom)]
// The test calls `Orthtree::insert_shared`, an `unsafe fn` (its SAFETY note says why the call is sound).
#![allow(unsafe_code)]

use loom::sync::Arc;
use loom::sync::atomic::{AtomicU64, Ordering};
use loom::thread;
use spatial::orthtree::Orthtree;
use std::sync::atomic::AtomicBool;

/// Whether some execution reused the retired block, and whether some reader iteration saw a
/// point inserted meanwhile (plain `std` atomics: they record what the executions covered and
/// are not part of the model).
static REUSED: AtomicBool = AtomicBool::new(false);
static SAW_NEW: AtomicBool = AtomicBool::new(false);

fn dist(a: &[f64; 2], b: &[f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

/// One writer inserting two points with `insert_shared` while one reader, a PDLA walker in
/// miniature, announces epochs and runs nearest-distance queries and iterations. Every answer
/// must come from fully written, inserted points: distances are distances to inserted points,
/// never above the distance to the point present from the start, never increasing; iterations
/// yield distinct inserted points, never fewer than before.
#[test]
fn shared_inserts_while_a_reader_queries() {
    loom::model(|| {
        let mut t = Orthtree::<2>::new();
        // Leaf side 4: p0 and p1 share leaf cell (0, 0); p2 lies in another quadrant of the
        // prepared root (level 3), below an empty root slot.
        let p = [[0.5, 0.5], [1.5, 0.5], [6.0, 6.0]];
        let stored = p.map(|q| t.stored_position(&q).unwrap());
        t.insert(p[0]).unwrap();
        t.prepare_shared(4, 8.0).unwrap();
        let t = Arc::new(t);
        let announced = Arc::new(AtomicU64::new(t.epoch()));

        let reader = {
            let (t, announced) = (Arc::clone(&t), Arc::clone(&announced));
            thread::spawn(move || {
                let q = [3.0, 3.0];
                let mut last_distance = dist(&q, &stored[0]);
                let mut last_count = 1;
                for _ in 0..2 {
                    // A walker's birth: it holds nothing from the tree.
                    announced.store(t.epoch(), Ordering::Release);
                    let d = t.nearest_distance(&q).unwrap();
                    assert!(
                        stored.iter().any(|s| dist(&q, s) == d),
                        "distance {d} to no inserted point"
                    );
                    assert!(d <= last_distance, "distance grew: {d} > {last_distance}");
                    last_distance = d;
                    let mut seen = Vec::new();
                    for x in t.iter() {
                        assert!(stored.contains(&x), "{x:?} was never inserted");
                        assert!(!seen.contains(&x), "{x:?} seen twice");
                        seen.push(x);
                    }
                    assert!(seen.len() >= last_count, "fewer points than before");
                    assert!(seen.contains(&stored[0]));
                    if seen.len() > 1 {
                        SAW_NEW.store(true, Ordering::Relaxed);
                    }
                    last_count = seen.len();
                }
                // Gone: the writer may reuse every block.
                announced.store(u64::MAX, Ordering::Release);
            })
        };

        for i in 1..3 {
            let readers = || announced.load(Ordering::Acquire);
            // SAFETY: the reader announces only between its queries and iterations (Release),
            // and `readers` reads that announcement (Acquire).
            let (at, _) = unsafe { t.insert_shared(p[i], readers) }.unwrap();
            assert_eq!(at, stored[i]);
        }
        reader.join().unwrap();
        // Blocks of 1 (p0's, retired by p1) and 2 slots (p0 and p1), and 1 for p2: 4 slots,
        // or 3 if p2's block is p0's old one.
        if t.stats().point_slots == 3 {
            REUSED.store(true, Ordering::Relaxed);
        }

        let mut t = Arc::try_unwrap(t).ok().unwrap();
        t.finish_shared();
        assert_eq!(t.len(), 3);
        let mut all: Vec<[f64; 2]> = t.iter().collect();
        all.sort_by(|a, b| a.partial_cmp(b).unwrap());
        let mut want = stored.to_vec();
        want.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert_eq!(all, want);
    });
    assert!(
        REUSED.load(Ordering::Relaxed),
        "no execution reused a block"
    );
    assert!(
        SAW_NEW.load(Ordering::Relaxed),
        "no iteration saw an insert"
    );
}
