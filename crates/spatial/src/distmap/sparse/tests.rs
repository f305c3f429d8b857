//! The sparse map against the dense one (the same bytes wherever the dense map reaches) and
//! against brute force, serial and shared.

use super::super::DistanceMap;
use super::super::tests::{brute, pt, shared_and_sequential};
use super::*;
use proptest::prelude::*;

/// Inserts `pts` one by one into a sparse and a dense map of the same cells, checking after
/// every few inserts (so table growth in the middle is covered) that at every probe both
/// cover the two hold the same byte, and that the sparse bounds hold against brute force: the lower bound
/// never above the distance, the upper bound never below it, a capped cell (or an absent
/// block) at least `cap` less half a diagonal away, an uncapped one within a diagonal and a
/// quantum.
fn check<const D: usize>(cell: f64, cap: f64, block: usize, pts: &[[f64; D]], probes: &[[f64; D]]) {
    let mut sparse = SparseDistanceMap::<D>::new(cell, cap, block).unwrap();
    let mut dense = DistanceMap::<D>::new(cell, cap).unwrap();
    let diag = cell * (D as f64).sqrt();
    for (n, q) in pts.iter().enumerate() {
        sparse.insert(q).unwrap();
        dense.insert(q).unwrap();
        if n % 5 != 4 && n + 1 != pts.len() {
            continue;
        }
        let sofar = &pts[..=n];
        for p in probes {
            // The two tables grow on different steps: compare where both reach.
            if let (Some(v), Some(w)) = (dense.value(p), sparse.value(p)) {
                assert_eq!(w, v, "{p:?}");
            }
            let Some((lb, ub, capped)) = sparse.bounds(p) else {
                assert!(brute(sofar, p) > cap, "{p:?} outside the map but near");
                continue;
            };
            let d = brute(sofar, p);
            assert!(lb <= d, "bound {lb} above the distance {d} at {p:?}");
            assert!(ub >= d, "upper bound {ub} below the distance {d} at {p:?}");
            assert_eq!(sparse.lower_bound(p), Some((lb, capped)));
            if capped {
                assert!(d >= cap - 0.5 * diag - 1e-9, "capped cell at distance {d}");
            } else {
                assert!(
                    lb >= d - diag - cap / 255.0 - 1e-9,
                    "{lb} too loose for {d}"
                );
            }
        }
    }
    assert_eq!(sparse.len(), pts.len() as u64);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn sparse_matches_dense_and_brute_force_2d(
        pts in proptest::collection::vec(pt::<2>(40.0), 1..40),
        probes in proptest::collection::vec(pt::<2>(60.0), 1..60),
        cell in prop_oneof![Just(1.0), Just(2.0), Just(1.5)],
        cap in prop_oneof![Just(8.0), Just(6.5)],
        block in prop_oneof![Just(4usize), Just(8), Just(1)],
    ) {
        check(cell, cap, block, &pts, &probes);
    }

    #[test]
    fn sparse_matches_dense_and_brute_force_3d(
        pts in proptest::collection::vec(pt::<3>(25.0), 1..30),
        probes in proptest::collection::vec(pt::<3>(35.0), 1..60),
        cell in prop_oneof![Just(2.0), Just(1.0)],
        cap in prop_oneof![Just(8.0), Just(6.0)],
        block in prop_oneof![Just(8usize), Just(4), Just(2)],
    ) {
        check(cell, cap, block, &pts, &probes);
    }
}

/// Clusters as DLA grows them (chains of touching unit-distance points) probed densely near
/// them: most probes fall in allocated blocks, some in absent ones, and both kinds of answer
/// hold against brute force; fewer blocks are allocated than the table has.
#[test]
fn chains_of_touching_points_in_3d() {
    let mut rng = crate::testdata::SplitMix::new(0x2545_f491_4f6c_dd1d);
    let mut next = || rng.uniform() * 2.0 - 1.0;
    let mut pts: Vec<[f64; 3]> = vec![[0.0; 3]];
    for _ in 0..600 {
        let a = pts[((next() + 1.0) * 0.5 * pts.len() as f64) as usize % pts.len()];
        let u = [next(), next(), next()];
        let len = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt().max(1e-9);
        pts.push(std::array::from_fn(|i| a[i] + u[i] / len));
    }
    let probes: Vec<[f64; 3]> = (0..3000)
        .map(|_| std::array::from_fn(|_| next() * 40.0))
        .collect();
    check(2.0, 8.0, 8, &pts, &probes);
    let mut map = SparseDistanceMap::<3>::new(2.0, 8.0, 4).unwrap();
    for q in &pts {
        map.insert(q).unwrap();
    }
    assert!(
        map.blocks() > 0 && map.blocks() < map.table.len(),
        "{map:?}"
    );
    assert!(map.memory_bytes() > map.blocks() * 64);
}

/// Two threads inserting halves of a point set through `insert_shared` into a reserved map
/// leave the bytes of the sequential map (every cell a maximum of nearness, every block
/// allocated once); points beyond the table are clipped and reported.
#[test]
fn shared_inserts_from_two_threads_equal_sequential_inserts() {
    let mut rng = crate::testdata::SplitMix::new(0x9e37_79b9_7f4a_7c15);
    let mut next = || rng.uniform();
    let pts: Vec<[f64; 3]> = (0..3000)
        .map(|_| std::array::from_fn(|_| next() * 80.0 - 40.0))
        .collect();
    let probes = (-60..60).step_by(3).flat_map(|x| {
        (-60..60).step_by(5).flat_map(move |y| {
            (-60..60)
                .step_by(7)
                .map(move |z| [x as f64 + 0.3, y as f64, z as f64 - 0.2])
        })
    });
    let new = || SparseDistanceMap::<3>::new(2.0, 8.0, 8).unwrap();
    let (seq, shared) = shared_and_sequential(new, &pts, probes);
    let far = [seq.reach() - 3.0, 0.0, 0.0];
    assert!(!shared.insert_shared(&far).unwrap());
    assert!(shared.insert_shared(&[f64::NAN, 0.0, 0.0]).is_err());
}

/// A shared map whose slab has no room left marks the blocks it cannot allocate unknown:
/// no answer there, never a capped one.
#[test]
fn a_block_that_cannot_be_allocated_gives_no_answer() {
    let map = SparseDistanceMap::<3>::new(2.0, 8.0, 8).unwrap();
    assert!(map.bounds(&[0.0; 3]).is_none());
    let mut map = map;
    map.grow(40.0).unwrap();
    // No chunk slots reserved: every allocation fails.
    assert!(map.chunks.is_empty());
    map.insert_shared(&[1.0, 2.0, 3.0]).unwrap();
    assert!(map.bounds(&[1.0, 2.0, 3.0]).is_none());
    assert!(map.value(&[1.0, 2.0, 3.0]).is_none());
    // Far from the point the blocks are still absent: capped.
    assert_eq!(map.value(&[-35.0, 35.0, 39.0]), Some(CAPPED));
}

#[test]
fn bad_parameters_are_refused() {
    assert!(SparseDistanceMap::<3>::new(0.0, 8.0, 8).is_err());
    assert!(SparseDistanceMap::<3>::new(2.0, f64::NAN, 8).is_err());
    assert!(SparseDistanceMap::<3>::new(2.0, 8.0, 6).is_err());
    assert!(SparseDistanceMap::<3>::new(2.0, 8.0, 128).is_err());
    let mut map = SparseDistanceMap::<2>::new(1.0, 4.0, 4).unwrap();
    assert!(map.insert(&[0.0, f64::INFINITY]).is_err());
    assert!(map.insert(&[1e300, 0.0]).is_err());
    assert!(map.is_empty());
}
