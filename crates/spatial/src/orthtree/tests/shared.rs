//! Shared inserts (PDLA): one writer while readers query, refusals, and reclamation.

use super::*;

/// One writer inserting through `insert_shared` while two readers query: every answer is the
/// distance to a stored point (never a point read from a block being reused), never larger than
/// the nearest among the points published before the query, never smaller than the nearest of
/// all; afterwards the tree holds what serial inserts give, and retired blocks were reused.
#[test]
fn shared_inserts_while_readers_query() {
    use std::collections::HashSet;
    use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};

    let pts = crate::testdata::branching_cluster(12_000, 5);
    let mut serial = Orthtree::<2>::new();
    let stored: Vec<[f64; 2]> = pts.iter().map(|&p| serial.insert(p).unwrap()).collect();
    let known: HashSet<[u64; 2]> = stored.iter().map(|p| p.map(f64::to_bits)).collect();
    let radius = pts.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs())) + 8.0;

    let head = 50;
    let mut t = Orthtree::<2>::new();
    for &p in &pts[..head] {
        t.insert(p).unwrap();
    }
    t.prepare_shared(pts.len() - head, radius).unwrap();
    let published = AtomicUsize::new(head);
    let done = AtomicBool::new(false);
    let epochs = [AtomicU64::new(t.epoch()), AtomicU64::new(t.epoch())];
    let checked = AtomicUsize::new(0);
    std::thread::scope(|sc| {
        let (t, stored, known) = (&t, &stored, &known);
        let (published, done, epochs, checked) = (&published, &done, &epochs, &checked);
        for (k, announced) in epochs.iter().enumerate() {
            sc.spawn(move || {
                // Retires the reader however it ends, so the writer never waits for it.
                struct Leave<'a>(&'a AtomicU64);
                impl Drop for Leave<'_> {
                    fn drop(&mut self) {
                        self.0.store(u64::MAX, Ordering::Release);
                    }
                }
                let _leave = Leave(announced);
                let mut rng = Rng::new(100 + k as u64);
                while !done.load(Ordering::Acquire) {
                    announced.store(t.epoch(), Ordering::Release);
                    let before = published.load(Ordering::Acquire);
                    // Next to the newest points, whose leaves are growing.
                    let base = stored[before - 1 - rng.below(before.min(64))];
                    let p = [base[0] + rng.uniform() * 3.0, base[1] + rng.uniform() * 3.0];
                    let n = t.nearest(&p).unwrap();
                    let upper = stored[..before]
                        .iter()
                        .map(|q| d2(&p, q))
                        .fold(f64::MAX, f64::min);
                    assert!(n.distance * n.distance <= upper * (1.0 + 1e-12));
                    // Many cheap checks per brute-force one: a point read from a reused block
                    // is not a stored point.
                    for _ in 0..200 {
                        let q = [p[0] + rng.uniform() - 0.5, p[1] + rng.uniform() - 0.5];
                        let n = t.nearest(&q).unwrap();
                        assert!(known.contains(&n.point.map(f64::to_bits)), "{:?}", n.point);
                    }
                    checked.fetch_add(1, Ordering::Relaxed);
                }
            });
        }
        // Stops the readers however the writer ends (a failed assertion included).
        struct Done<'a>(&'a AtomicBool);
        impl Drop for Done<'_> {
            fn drop(&mut self) {
                self.0.store(true, Ordering::Release);
            }
        }
        let _done = Done(done);
        for (i, &p) in pts.iter().enumerate().skip(head) {
            let readers = || {
                epochs
                    .iter()
                    .map(|e| e.load(Ordering::Acquire))
                    .min()
                    .unwrap()
            };
            // SAFETY: each reader announces its epoch between queries only (Release), and
            // `readers` is the minimum of the announcements (Acquire).
            let (at, _) = unsafe { t.insert_shared(p, readers) }.unwrap();
            assert_eq!(at, stored[i]);
            published.store(i + 1, Ordering::Release);
            // Readers are far slower than the writer here (their answers are checked by brute
            // force); let them catch up now and then, as PDLA's walkers do at every birth.
            if i % 256 == 0 {
                let now = t.epoch();
                while epochs.iter().any(|e| e.load(Ordering::Acquire) < now) {
                    std::thread::yield_now();
                }
            }
        }
    });
    assert!(checked.load(Ordering::Relaxed) > 0);
    t.finish_shared();
    assert_eq!(t.len(), pts.len());
    let mut a: Vec<[u64; 2]> = t.iter().map(|p| p.map(f64::to_bits)).collect();
    let mut b: Vec<[u64; 2]> = serial.iter().map(|p| p.map(f64::to_bits)).collect();
    a.sort_unstable();
    b.sort_unstable();
    assert_eq!(a, b);
    let (s, r) = (t.stats(), serial.stats());
    // The prepared root is larger and grew in other directions, so internal nodes split space
    // a little differently; leaf cells never move.
    assert_eq!(s.leaves, r.leaves);
    assert!(
        s.nodes.abs_diff(r.nodes) * 10 <= r.nodes,
        "{s:?} against {r:?}"
    );
    // Without reuse every outgrown block would stay allocated: about twice the slots.
    assert!(
        s.point_slots as f64 <= r.point_slots as f64 * 1.1,
        "{} slots against {} serially",
        s.point_slots,
        r.point_slots
    );
    // Exclusive inserts work again, and the tree answers as the serial one.
    t.insert([radius * 3.0, 0.0]).unwrap();
    serial.insert([radius * 3.0, 0.0]).unwrap();
    for q in [[0.5, 0.5], [radius, -radius], [10.0, 3.0]] {
        assert_eq!(t.nearest_distance(&q), serial.nearest_distance(&q));
    }
}

/// A shared insert outside the prepared root, or beyond the reserved room, is refused with
/// `NeedsExclusive` and changes nothing; an empty tree cannot be prepared.
#[test]
fn shared_inserts_that_need_exclusive_access_change_nothing() {
    let mut empty = Orthtree::<2>::new();
    assert_eq!(
        empty.prepare_shared(10, 10.0),
        Err(OrthtreeError::NeedsExclusive)
    );
    let mut t = Orthtree::<2>::new();
    t.insert([0.0, 0.0]).unwrap();
    t.prepare_shared(10, 50.0).unwrap();
    let before = (t.len(), t.stats(), t.root_cell());
    // SAFETY (here and below): no other thread reads the tree, so `u64::MAX` is truthful.
    assert_eq!(
        unsafe { t.insert_shared([1e6, 0.0], || u64::MAX) },
        Err(OrthtreeError::NeedsExclusive)
    );
    assert_eq!((t.len(), t.stats(), t.root_cell()), before);
    // Fill the reserved room with points in distinct leaves until a refusal.
    let mut i = 0u64;
    let refused = loop {
        let p = [
            (i % 20) as f64 * 4.0 - 40.0 + 0.5,
            (i / 20 % 20) as f64 * 4.0 - 40.0 + 0.5,
        ];
        let before = (t.len(), t.stats());
        match unsafe { t.insert_shared(p, || u64::MAX) } {
            Ok(_) => i += 1,
            Err(e) => {
                assert_eq!((t.len(), t.stats()), before);
                break e;
            }
        }
        assert!(i < 1_000_000, "room never ran out");
    };
    assert_eq!(refused, OrthtreeError::NeedsExclusive);
    t.finish_shared();
    t.insert([1e6, 0.0]).unwrap();
    assert_eq!(t.len() as u64, i + 2);
}

/// Shared inserts ask for the readers' epochs (cache lines other cores write) about once per
/// advance of the epoch, not at every insert, and still reuse retired blocks once the readers
/// have moved past them.
#[test]
fn shared_inserts_ask_the_readers_once_per_epoch() {
    let grow = |reader_keeps_up: bool| {
        let mut t = Orthtree::<2>::with_leaf_side(8.0).unwrap();
        t.insert([0.0, 0.0]).unwrap();
        t.prepare_shared(400_000, 100.0).unwrap();
        let mut asked = 0;
        // Points crowded into a few leaves, which outgrow their blocks again and again.
        for i in 0..20_000u64 {
            let p = [
                (i % 97) as f64 * 0.3 - 14.0,
                (i / 97 % 89) as f64 * 0.3 - 13.0,
            ];
            let announced = if reader_keeps_up { t.epoch() } else { 1 };
            // SAFETY: no other thread reads the tree; any answer is truthful (a too-small one
            // only keeps blocks from reuse, which is what this test measures).
            unsafe {
                t.insert_shared(p, || {
                    asked += 1;
                    announced
                })
            }
            .unwrap();
        }
        let slots = t.stats().point_slots;
        t.finish_shared();
        (asked, slots)
    };
    let (asked, slots) = grow(true);
    assert!(
        (1..=20_000 / 64 + 2).contains(&asked),
        "asked {asked} times"
    );
    // A reader stuck at the first epoch keeps every retired block from reuse.
    let (_, stuck_slots) = grow(false);
    assert!(
        slots < stuck_slots,
        "{slots} slots, {stuck_slots} with a stuck reader"
    );
}

/// Tags follow their points through block moves, compaction, shared inserts with retired
/// blocks, and clones: after each, every stored point's tag is its insertion index.
#[test]
fn tags_follow_their_points() {
    let pts = crate::testdata::branching_cluster(20_000, 7);
    let radius = pts.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs())) + 8.0;
    let mut t = Orthtree::<2>::new();
    t.keep_tags().unwrap();
    assert!(t.keeps_tags());
    let head = 12_000;
    let mut stored = Vec::new();
    for (i, &p) in pts[..head].iter().enumerate() {
        stored.push(t.insert_tagged(p, i as u32).unwrap());
    }
    t.prepare_shared(pts.len() - head, radius).unwrap();
    for (i, &p) in pts.iter().enumerate().skip(head) {
        // SAFETY: no other thread reads the tree.
        #[allow(unsafe_code)]
        let (q, _) = unsafe { t.insert_shared_tagged(p, i as u32, || u64::MAX) }.unwrap();
        stored.push(q);
    }
    t.finish_shared();
    let copy = t.clone();
    for (i, q) in stored.iter().enumerate() {
        assert_eq!(t.tag_of(q), Some(i as u32), "point {i}");
        assert_eq!(copy.tag_of(q), Some(i as u32), "point {i} of the clone");
    }
    assert_eq!(t.tag_of(&[1e6, 1e6]), None);
    assert_eq!(t.tag_of(&[stored[5][0] + 0.25, stored[5][1]]), None);
    // A tree without tags answers none, and keeping tags starts only on an empty tree.
    let mut plain = Orthtree::<2>::new();
    let q = plain.insert([0.5, 0.5]).unwrap();
    assert_eq!(plain.tag_of(&q), None);
    assert!(matches!(
        plain.keep_tags(),
        Err(OrthtreeError::TagsOnNonEmpty)
    ));
}

/// Compaction (many leaves outgrowing their blocks with exclusive inserts) keeps the tags
/// beside their points.
#[test]
fn tags_survive_compaction() {
    let mut t = Orthtree::<2>::with_leaf_side(64.0).unwrap();
    t.keep_tags().unwrap();
    let mut rng = Rng::new(3);
    let mut stored = Vec::new();
    for i in 0..200_000u32 {
        let p = [rng.uniform() * 4000.0, rng.uniform() * 4000.0];
        stored.push(t.insert_tagged(p, i).unwrap());
    }
    for (i, q) in stored.iter().enumerate().step_by(7) {
        assert_eq!(t.tag_of(q), Some(i as u32));
    }
    assert!(t.memory_bytes() >= 200_000 * 12);
}
