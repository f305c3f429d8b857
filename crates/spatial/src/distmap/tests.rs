//! Unit and property tests of the distance maps against brute force.

use super::*;
use proptest::prelude::*;
use std::sync::atomic::Ordering;

/// The exact distance from `p` to the nearest of `pts` (`+inf` for none).
pub(super) fn brute<const D: usize>(pts: &[[f64; D]], p: &[f64; D]) -> f64 {
    pts.iter()
        .map(|q| {
            let mut s = 0.0;
            for i in 0..D {
                s += (p[i] - q[i]) * (p[i] - q[i]);
            }
            s.sqrt()
        })
        .fold(f64::INFINITY, f64::min)
}

fn check<const D: usize>(cell: f64, cap: f64, pts: &[[f64; D]], probes: &[[f64; D]]) {
    let mut map = DistanceMap::<D>::new(cell, cap).unwrap();
    for (n, q) in pts.iter().enumerate() {
        map.insert(q).unwrap();
        // Check after every few inserts, so growth in the middle is covered.
        if n % 7 == 6 || n + 1 == pts.len() {
            let sofar = &pts[..=n];
            for p in probes {
                let Some((lb, capped)) = map.lower_bound(p) else {
                    // Outside the map: the map must cover cap + cell beyond every point.
                    assert!(brute(sofar, p) > cap, "{p:?} outside the map but near");
                    continue;
                };
                let d = brute(sofar, p);
                assert!(lb <= d, "bound {lb} above the distance {d} at {p:?}");
                if !capped {
                    let diag = cell * (D as f64).sqrt();
                    assert!(
                        lb >= d - diag - cap / 255.0 - 1e-9,
                        "bound {lb} too loose for distance {d}"
                    );
                } else {
                    let half_diag = 0.5 * cell * (D as f64).sqrt();
                    assert!(d >= cap - half_diag - 1e-9, "capped cell at distance {d}");
                }
            }
        }
    }
}

/// Points with every coordinate in `[-range, range)`.
pub(super) fn pt<const D: usize>(range: f64) -> impl Strategy<Value = [f64; D]> {
    proptest::array::uniform::<_, D>(-range..range)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn bound_is_valid_and_tight_2d(
        pts in proptest::collection::vec(pt::<2>(60.0), 1..40),
        probes in proptest::collection::vec(pt::<2>(90.0), 1..40),
        cell in prop_oneof![Just(1.0), Just(4.0), Just(8.0), Just(3.0)],
        cap in prop_oneof![Just(16.0), Just(64.0), Just(10.5)],
    ) {
        check(cell, cap, &pts, &probes);
    }

    #[test]
    fn bound_is_valid_and_tight_3d(
        pts in proptest::collection::vec(pt::<3>(30.0), 1..25),
        probes in proptest::collection::vec(pt::<3>(45.0), 1..25),
        cell in prop_oneof![Just(2.0), Just(8.0)],
        cap in prop_oneof![Just(16.0), Just(32.0)],
    ) {
        check(cell, cap, &pts, &probes);
    }
}

/// Points added through boxes that hold them (as `dla` adds its coarser maps' points by
/// their tree leaf's box) and points added one by one: the bound never exceeds the exact
/// distance to any of them, the upper bound of [`DistanceMap::bounds`] is never below it,
/// and a box's bound is at most its diagonal looser than the point's would be.
fn check_boxes<const D: usize>(
    cell: f64,
    cap: f64,
    side: f64,
    pts: &[[f64; D]],
    probes: &[[f64; D]],
) {
    let mut map = DistanceMap::<D>::new(cell, cap).unwrap();
    let mut exact = DistanceMap::<D>::new(cell, cap).unwrap();
    let mut shared = DistanceMap::<D>::new(cell, cap).unwrap();
    let reach = pts
        .iter()
        .flat_map(|q| q.iter())
        .fold(0.0f64, |m, x| m.max(x.abs()))
        + side
        + cap
        + cell
        + 1.0;
    shared.reserve(reach).unwrap();
    for (n, q) in pts.iter().enumerate() {
        let lo = q.map(|x| (x / side).floor() * side);
        let hi = lo.map(|x| x + side);
        if n % 3 == 0 {
            map.insert(q).unwrap();
            assert!(shared.insert_shared(q).unwrap());
        } else {
            map.insert_box(&lo, &hi).unwrap();
            assert!(shared.insert_box_shared(&lo, &hi).unwrap());
        }
        exact.insert(q).unwrap();
    }
    let diag = side * (D as f64).sqrt();
    for p in probes {
        let d = brute(pts, p);
        for m in [&map, &shared] {
            let Some((lb, ub, capped)) = m.bounds(p) else {
                // Outside the map: it covers cap + cell beyond every point and box.
                assert!(d > cap, "{p:?} outside the map but near");
                continue;
            };
            assert!(lb <= d, "bound {lb} above the distance {d} at {p:?}");
            assert!(
                ub + diag >= d,
                "upper bound {ub} too low for the distance {d}"
            );
            assert_eq!(m.lower_bound(p).map(|(l, _)| l), Some(lb));
            assert!(capped || ub.is_finite());
            // The per-point map may be smaller (boxes reach farther), so may not hold p.
            if let Some((le, _)) = exact.lower_bound(p) {
                assert!(lb >= le - diag - cap / 255.0 - 1e-9, "{lb} vs {le}");
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn box_inserts_keep_the_bound_2d(
        pts in proptest::collection::vec(pt::<2>(60.0), 1..40),
        probes in proptest::collection::vec(pt::<2>(90.0), 1..40),
        cell in prop_oneof![Just(8.0), Just(64.0)],
        cap in prop_oneof![Just(64.0), Just(40.0)],
    ) {
        check_boxes(cell, cap, 8.0, &pts, &probes);
    }

    #[test]
    fn box_inserts_keep_the_bound_3d(
        pts in proptest::collection::vec(pt::<3>(30.0), 1..30),
        probes in proptest::collection::vec(pt::<3>(45.0), 1..30),
        cell in prop_oneof![Just(8.0), Just(32.0)],
        cap in prop_oneof![Just(32.0), Just(128.0)],
    ) {
        check_boxes(cell, cap, 8.0, &pts, &probes);
    }

    #[test]
    fn box_inserts_keep_the_bound_4d_5d(
        pts4 in proptest::collection::vec(pt::<4>(20.0), 1..15),
        probes4 in proptest::collection::vec(pt::<4>(30.0), 1..15),
        pts5 in proptest::collection::vec(pt::<5>(12.0), 1..10),
        probes5 in proptest::collection::vec(pt::<5>(18.0), 1..10),
    ) {
        check_boxes(8.0, 32.0, 4.0, &pts4, &probes4);
        check_boxes(4.0, 16.0, 2.0, &pts5, &probes5);
    }
}

/// Inserts `pts` one by one into a map from `new` and, from two threads that each add half
/// of them through `insert_shared`, into another reserved to the first one's reach; checks
/// that the two hold the same byte at every probe, and returns both (sequential, shared).
pub(super) fn shared_and_sequential<M: PointMap<D> + Sync, const D: usize>(
    new: impl Fn() -> M,
    pts: &[[f64; D]],
    probes: impl IntoIterator<Item = [f64; D]>,
) -> (M, M) {
    let mut seq = new();
    for q in pts {
        seq.insert(q).unwrap();
    }
    let mut shared = new();
    shared.reserve(seq.reach()).unwrap();
    assert_eq!(shared.reach(), seq.reach());
    let (a, b) = pts.split_at(pts.len() / 2);
    std::thread::scope(|s| {
        for half in [a, b] {
            let map = &shared;
            s.spawn(move || {
                for q in half {
                    assert!(map.insert_shared(q).unwrap());
                }
            });
        }
    });
    for p in probes {
        assert_eq!(seq.value(&p), shared.value(&p), "{p:?}");
    }
    (seq, shared)
}

/// A cell's value is a minimum over the points, independent of their order: two threads
/// adding halves of a point set to one reserved map through `insert_shared` leave exactly
/// the bytes of the sequential map; points beyond the map are clipped, never wrong.
#[test]
fn shared_inserts_from_two_threads_equal_sequential_inserts() {
    let mut rng = crate::testdata::SplitMix::new(0x9e37_79b9_7f4a_7c15);
    let mut next = || rng.uniform();
    let pts: Vec<[f64; 2]> = (0..4000)
        .map(|_| [next() * 400.0 - 200.0, next() * 400.0 - 200.0])
        .collect();
    let probes = (-260..260)
        .step_by(3)
        .flat_map(|x| (-260..260).step_by(5).map(move |y| [x as f64, y as f64]));
    let (seq, shared) =
        shared_and_sequential(|| DistanceMap::<2>::new(8.0, 64.0).unwrap(), &pts, probes);
    // A point beyond the map: clipped, reported, and the stored cells stay valid bounds.
    let far = [seq.reach() - 10.0, 0.0];
    assert!(!shared.insert_shared(&far).unwrap());
    let mut all = pts.clone();
    all.push(far);
    let p = [seq.reach() - 30.0, 3.0];
    let (lb, _) = shared.lower_bound(&p).unwrap();
    assert!(lb <= brute(&all, &p));
    assert!(shared.insert_shared(&[f64::NAN, 0.0]).is_err());
}

/// Every byte of a dense map, in order.
fn bytes<const D: usize>(m: &DistanceMap<D>) -> Vec<u8> {
    m.values.iter().map(|v| v.load(Ordering::Relaxed)).collect()
}

/// Uniform numbers in `[0, 1)` from a xorshift generator seeded with `seed` (non-zero).
fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut rng = seed;
    move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The rows' ranges from the table of widths (in 3D, tabulated per insert with the rows'
/// offsets and keys) cover every cell the exactly solved ranges cover, and the extra cells
/// they visit are never lowered: the same bytes either way, in 2D and 3D, for the `dla` maps'
/// shapes and odd ones, with points at cell corners and centres among random ones.
#[test]
fn tabulated_row_ranges_give_the_exact_ranges_bytes() {
    fn same<const D: usize>(cell: f64, cap: f64, seed: u64) {
        let mut next = uniform(seed);
        let span = 6.0 * cap;
        let mut pts: Vec<[f64; D]> = (0..600)
            .map(|_| std::array::from_fn(|_| (next() - 0.5) * span))
            .collect();
        // Corners and centres of cells: the rounding edge cases of the ranges.
        for k in -3..3 {
            pts.push(std::array::from_fn(|i| (k + i as i64) as f64 * cell));
            pts.push(std::array::from_fn(|i| (k as f64 + 0.5 + i as f64) * cell));
        }
        let mut table = DistanceMap::<D>::new(cell, cap).unwrap();
        assert!(!table.grid.widths.is_empty());
        table.grid.window_inserts = false;
        let mut exact = table.clone();
        exact.grid.widths = Box::default();
        for q in &pts {
            table.insert(q).unwrap();
            exact.insert(q).unwrap();
        }
        assert_eq!(table.side, exact.side);
        let lowered = bytes(&table).iter().filter(|&&v| v < CAPPED).count();
        assert!(lowered > 100, "{lowered} cells lowered");
        assert!(bytes(&table) == bytes(&exact), "cell {cell}, cap {cap}");
    }
    same::<2>(8.0, 64.0, 1);
    same::<2>(64.0, 512.0, 2);
    same::<2>(3.0, 10.5, 3);
    same::<2>(1.0, 64.0, 4);
    same::<3>(8.0, 32.0, 5);
    same::<3>(32.0, 128.0, 6);
    same::<3>(2.5, 11.0, 7);
    // Wider than the rows' tables (13 cells per axis): rows from the table of widths alone.
    same::<3>(1.0, 6.5, 8);
}

#[test]
fn growth_keeps_old_cells() {
    // Points marching outward force several growths; values near the first point must
    // survive them.
    let mut map = DistanceMap::<2>::new(8.0, 64.0).unwrap();
    map.insert(&[0.0, 0.0]).unwrap();
    let before = map.value(&[3.0, 3.0]).unwrap();
    let reach0 = map.reach();
    for i in 1..200 {
        map.insert(&[i as f64 * 5.0, -(i as f64) * 3.0]).unwrap();
    }
    assert!(map.reach() > 4.0 * reach0);
    assert_eq!(map.value(&[3.0, 3.0]).unwrap(), before);
    assert_eq!(map.len(), 200);
    // The cell centre (4, 4) is 5.66 from the origin: the bound there loses at most one
    // quantum (64 / 255).
    let (lb, capped) = map.lower_bound(&[4.0, 4.0]).unwrap();
    let d = 32f64.sqrt();
    assert!(!capped && lb <= d && lb > d - 64.0 / 255.0, "{lb}");
}

#[test]
fn far_cells_are_capped_and_outside_is_none() {
    let mut map = DistanceMap::<3>::new(8.0, 32.0).unwrap();
    assert!(map.lower_bound(&[0.0; 3]).is_none());
    map.insert(&[1.0, 2.0, 3.0]).unwrap();
    // Centre (4, 4, 4) is sqrt(14) from the point: floor(sqrt(14) / (32 / 255)) = 29.
    assert_eq!(map.value(&[1.0, 2.0, 3.0]), Some(29));
    assert_eq!(map.value(&[-35.0, 35.0, 39.0]), Some(CAPPED));
    assert!(map.lower_bound(&[1e6, 0.0, 0.0]).is_none());
    assert!(map.memory_bytes() >= 10 * 10 * 10);
}

#[test]
fn bad_parameters_and_points_are_refused() {
    assert_eq!(
        DistanceMap::<2>::new(0.0, 1.0).unwrap_err(),
        DistanceMapError::CellSide(0.0)
    );
    assert!(matches!(
        DistanceMap::<2>::new(1.0, f64::NAN).unwrap_err(),
        DistanceMapError::Cap(_)
    ));
    let mut map = DistanceMap::<2>::new(1.0, 4.0).unwrap();
    assert!(matches!(
        map.insert(&[0.0, f64::INFINITY]).unwrap_err(),
        DistanceMapError::NonFinite { axis: 1, .. }
    ));
    assert!(matches!(
        map.insert(&[1e300, 0.0]).unwrap_err(),
        DistanceMapError::TooLarge { .. }
    ));
    assert!(map.is_empty());
}

/// A random aggregate: each point one diameter from an earlier one (some along an axis,
/// where the half-space's normal has a zero component; every fifth closer, between 0.3 and
/// 1, as DLA's noise reduction stores them), with the earlier one.
fn aggregate<const D: usize>(n: usize, seed: u64) -> Vec<([f64; D], Option<[f64; D]>)> {
    let mut next = uniform(seed);
    let mut pts: Vec<([f64; D], Option<[f64; D]>)> = vec![([0.3; D], None)];
    while pts.len() < n {
        let p = pts[(next() * pts.len() as f64) as usize % pts.len()].0;
        let u: [f64; D] = if pts.len() % 7 == 0 {
            std::array::from_fn(|i| if i == pts.len() % D { -1.0 } else { 0.0 })
        } else {
            let u: [f64; D] = std::array::from_fn(|_| next() - 0.5);
            let len = u.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-9);
            u.map(|x| x / len)
        };
        let f = if pts.len() % 5 == 0 {
            0.3 + 0.7 * next()
        } else {
            1.0
        };
        pts.push((std::array::from_fn(|i| p[i] + f * u[i]), Some(p)));
    }
    pts
}

/// The centres of the `per_axis^D` cells of side `cell` from `-reach` on along every axis.
fn centres<const D: usize>(
    reach: f64,
    cell: f64,
    per_axis: usize,
) -> impl Iterator<Item = [f64; D]> {
    (0..per_axis.pow(D as u32)).map(move |idx| {
        let mut rem = idx;
        std::array::from_fn(|_| {
            let k = rem % per_axis;
            rem /= per_axis;
            -reach + (k as f64 + 0.5) * cell
        })
    })
}

/// A point inserted beside the point it touches (visiting only the cells nearer it) leaves the
/// dense and the sparse maps exactly as a full insert does: every byte and every block.
#[test]
fn inserts_beside_the_touched_point_give_the_full_inserts_bytes() {
    fn dense<const D: usize>(cell: f64, cap: f64, seed: u64) {
        let pts = aggregate::<D>(700, seed);
        let mut full = DistanceMap::<D>::new(cell, cap).unwrap();
        full.grid.window_inserts = false;
        let mut beside = full.clone();
        for (q, p) in &pts {
            full.insert(q).unwrap();
            match p {
                Some(p) => beside.insert_beside(q, p).unwrap(),
                None => beside.insert(q).unwrap(),
            }
        }
        let lowered = bytes(&full).iter().filter(|&&v| v < CAPPED).count();
        assert!(lowered > 100, "{lowered} cells lowered");
        assert!(bytes(&full) == bytes(&beside), "cell {cell}, cap {cap}");
    }
    fn sparse<const D: usize>(cell: f64, cap: f64, seed: u64) {
        let pts = aggregate::<D>(700, seed);
        let mut full = SparseDistanceMap::<D>::new(cell, cap, 8).unwrap();
        let mut beside = SparseDistanceMap::<D>::new(cell, cap, 8).unwrap();
        full.grid_mut().window_inserts = false;
        beside.grid_mut().window_inserts = false;
        for (q, p) in &pts {
            full.insert(q).unwrap();
            match p {
                Some(p) => beside.insert_beside(q, p).unwrap(),
                None => beside.insert(q).unwrap(),
            }
        }
        assert_eq!(full.blocks(), beside.blocks());
        // Every cell centre of the cube the cluster's cap-neighbourhood lies in.
        let reach = pts
            .iter()
            .flat_map(|(q, _)| q.iter().map(|x| x.abs()))
            .fold(0.0, f64::max)
            + cap
            + cell;
        let (mut cells, mut lowered) = (0, 0);
        for c in centres::<D>(reach, cell, (2.0 * reach / cell).ceil() as usize) {
            let v = full.value(&c);
            assert_eq!(v, beside.value(&c), "at {c:?}");
            cells += 1;
            lowered += usize::from(v.is_some_and(|v| v < CAPPED));
        }
        assert!(lowered > 100 && cells > lowered, "{lowered} of {cells}");
    }
    dense::<2>(8.0, 64.0, 1);
    dense::<2>(1.0, 6.0, 2);
    dense::<3>(8.0, 32.0, 3);
    dense::<3>(2.5, 11.0, 4);
    dense::<4>(8.0, 32.0, 5);
    sparse::<3>(2.0, 8.0, 6);
    sparse::<2>(2.0, 8.0, 7);
}

/// Exclusive 2D and 3D inserts go by whole window rows where the ball's box spans at most
/// [`grid::WINDOW`] cells a side (the sparse map's with blocks of 8 or 16 cells a side), and
/// by rows otherwise; shared inserts always go by rows. Both leave every byte, and every block
/// of a sparse map, the same, with and without the touched point: for the `dla` maps' shapes,
/// odd ones, a cap one cell too wide for the window, points at cell corners and centres, and
/// points near the map's edge (where a dense row's 16 bytes would run past its end).
#[test]
fn window_inserts_give_the_row_inserts_bytes() {
    fn points<const D: usize>(cell: f64, cap: f64, seed: u64) -> Vec<([f64; D], Option<[f64; D]>)> {
        let mut pts = aggregate::<D>(400, seed);
        let mut next = uniform(seed + 100);
        let span = 6.0 * cap;
        pts.extend((0..200).map(|_| (std::array::from_fn(|_| (next() - 0.5) * span), None)));
        for k in -3..3 {
            pts.push((std::array::from_fn(|i| (k + i as i64) as f64 * cell), None));
            pts.push((
                std::array::from_fn(|i| (k as f64 + 0.5 + i as f64) * cell),
                None,
            ));
        }
        pts
    }
    /// Inserts `pts` into `window` (exclusively) and into `rows` (shared, reserved to the
    /// first one's reach: shared inserts go by rows).
    fn fill<M: PointMap<D>, const D: usize>(
        window: &mut M,
        rows: &mut M,
        pts: &[([f64; D], Option<[f64; D]>)],
    ) {
        for (q, p) in pts {
            match p {
                Some(p) => window.insert_beside(q, p).unwrap(),
                None => window.insert(q).unwrap(),
            }
        }
        rows.reserve(window.reach()).unwrap();
        for (q, p) in pts {
            let inside = match p {
                Some(p) => rows.insert_shared_beside(q, p).unwrap(),
                None => rows.insert_shared(q).unwrap(),
            };
            assert!(inside);
        }
    }
    fn dense<const D: usize>(cell: f64, cap: f64, seed: u64) {
        let mut window = DistanceMap::<D>::new(cell, cap).unwrap();
        let mut rows = window.clone();
        fill(&mut window, &mut rows, &points::<D>(cell, cap, seed));
        assert_eq!(window.side, rows.side);
        let lowered = bytes(&window).iter().filter(|&&v| v < CAPPED).count();
        assert!(lowered > 100, "{lowered} cells lowered");
        assert!(bytes(&window) == bytes(&rows), "cell {cell}, cap {cap}");
    }
    fn sparse<const D: usize>(cell: f64, cap: f64, block: usize, seed: u64) {
        let new = || SparseDistanceMap::<D>::new(cell, cap, block).unwrap();
        let (mut window, mut rows) = (new(), new());
        fill(&mut window, &mut rows, &points::<D>(cell, cap, seed));
        assert_eq!(window.blocks(), rows.blocks());
        let reach = window.reach();
        let mut lowered = 0;
        for c in centres::<D>(reach, cell, (2.0 * reach / cell).round() as usize) {
            let v = window.value(&c);
            assert_eq!(v, rows.value(&c), "at {c:?}");
            lowered += usize::from(v.is_some_and(|v| v < CAPPED));
        }
        assert!(lowered > 100, "{lowered} cells lowered");
    }
    // The `dla` shapes: the first dense level and the sparse map, in 2D and 3D.
    dense::<2>(16.0, 64.0, 1);
    sparse::<2>(2.0, 8.0, 16, 2);
    dense::<3>(8.0, 32.0, 3);
    sparse::<3>(2.0, 8.0, 8, 4);
    // Other caps within the window (up to 5.5 cells), and 6.5 cells (by rows).
    dense::<2>(3.0, 10.5, 5);
    dense::<2>(1.0, 5.5, 6);
    dense::<2>(1.0, 6.5, 7);
    dense::<3>(2.5, 11.0, 8);
    sparse::<2>(1.5, 7.0, 16, 9);
    sparse::<2>(1.0, 5.5, 16, 10);
    sparse::<3>(1.0, 5.5, 8, 11);
    // Blocks of 4 cells a side: by rows.
    sparse::<2>(2.0, 8.0, 4, 12);
}

/// Boxes added by the sub-boxes that hold them ([`DistanceMap::insert_box_by_sub_box`]), as
/// DLA adds its leaves' boxes to the coarse maps: each sub-box is inserted by its first box
/// only, the map then holds the bytes of a map given those sub-boxes by `insert_box` (and a
/// box across sub-boxes by itself), through growth in the middle; its bounds hold against
/// brute force over points in the boxes, looser by at most a sub-box's diagonal; and two
/// threads adding every box through the shared insert lower each sub-box exactly once, to
/// the same bytes.
fn check_sub_boxes<const D: usize>(cell: f64, cap: f64, sub: usize, leaf: f64, seed: u64) {
    let mut next = uniform(seed);
    let mut by_sub = DistanceMap::<D>::new(cell, cap)
        .unwrap()
        .with_sub_boxes(sub)
        .unwrap();
    let mut reference = DistanceMap::<D>::new(cell, cap).unwrap();
    let side = cell / sub as f64;
    let mut seen = std::collections::HashSet::new();
    let mut boxes = Vec::new();
    let mut pts = Vec::new();
    for n in 0..400 {
        // Spreading outwards, so that the map grows while it holds sub-boxes.
        let r = 3.0 * leaf + n as f64 * cell / 40.0;
        let p: [f64; D] = std::array::from_fn(|_| (2.0 * next() - 1.0) * r);
        let lo = p.map(|x| (x / leaf).floor() * leaf);
        let hi = lo.map(|x| x + leaf);
        let key = lo.map(|x| ((x + 0.5 * leaf) / side).floor() as i64);
        let first = seen.insert(key);
        assert_eq!(by_sub.insert_box_by_sub_box(&lo, &hi).unwrap(), first);
        if first {
            let slo = key.map(|k| k as f64 * side);
            reference.insert_box(&slo, &slo.map(|x| x + side)).unwrap();
        }
        boxes.push((lo, hi));
        pts.push(p);
        pts.push(hi.map(|x| x - 1e-9));
    }
    assert_eq!(bytes(&by_sub), bytes(&reference));
    // A box across a sub-box boundary is inserted by itself, every time.
    let mut lo = [0.25 * side; D];
    lo[0] = side - 0.5 * leaf;
    let hi = lo.map(|x| x + leaf);
    for _ in 0..2 {
        assert!(by_sub.insert_box_by_sub_box(&lo, &hi).unwrap());
    }
    reference.insert_box(&lo, &hi).unwrap();
    assert_eq!(bytes(&by_sub), bytes(&reference));
    pts.push(lo);
    pts.push(hi);
    let diag = side * (D as f64).sqrt();
    for _ in 0..400 {
        let r = 1.5 * (3.0 * leaf + 400.0 * cell / 40.0) + cap;
        let p: [f64; D] = std::array::from_fn(|_| (2.0 * next() - 1.0) * r);
        let d = brute(&pts, &p);
        if let Some((lb, ub, _)) = by_sub.bounds(&p) {
            assert!(lb <= d, "bound {lb} above the distance {d} at {p:?}");
            assert!(
                ub + diag >= d,
                "upper bound {ub} + {diag} below {d} at {p:?}"
            );
        } else {
            assert!(d > cap, "{p:?} outside the map but near");
        }
    }
    // Shared: two threads, each adding every box; each sub-box lowered exactly once.
    let mut shared = DistanceMap::<D>::new(cell, cap)
        .unwrap()
        .with_sub_boxes(sub)
        .unwrap();
    shared.reserve(by_sub.reach()).unwrap();
    let lowered = std::sync::atomic::AtomicUsize::new(0);
    std::thread::scope(|s| {
        for t in 0..2 {
            let (shared, boxes, lowered) = (&shared, &boxes, &lowered);
            s.spawn(move || {
                let order: Vec<_> = if t == 0 {
                    boxes.iter().collect()
                } else {
                    boxes.iter().rev().collect()
                };
                for (lo, hi) in order {
                    let (now, inside) = shared.insert_box_by_sub_box_shared(lo, hi).unwrap();
                    assert!(inside);
                    if now {
                        lowered.fetch_add(1, Ordering::Relaxed);
                    }
                }
            });
        }
    });
    assert_eq!(lowered.load(Ordering::Relaxed), seen.len());
    let mut exclusive = DistanceMap::<D>::new(cell, cap)
        .unwrap()
        .with_sub_boxes(sub)
        .unwrap();
    exclusive.reserve(by_sub.reach()).unwrap();
    for (lo, hi) in &boxes {
        exclusive.insert_box_by_sub_box(lo, hi).unwrap();
    }
    assert_eq!(bytes(&shared), bytes(&exclusive));
}

#[test]
fn sub_boxes_are_inserted_once_and_keep_the_bound() {
    // The 2D `dla` shapes (sub-boxes of 32 and 256 diameters, leaves of 4), odd ones, 3D.
    check_sub_boxes::<2>(256.0, 2048.0, 8, 4.0, 1);
    check_sub_boxes::<2>(2048.0, 16384.0, 8, 4.0, 2);
    check_sub_boxes::<2>(64.0, 512.0, 4, 8.0, 3);
    check_sub_boxes::<2>(24.0, 96.0, 3, 2.0, 4);
    check_sub_boxes::<3>(32.0, 128.0, 4, 4.0, 5);
    check_sub_boxes::<3>(16.0, 64.0, 2, 8.0, 6);
}

#[test]
fn sub_boxes_are_refused_where_they_cannot_be_kept() {
    let refused = |r: Result<DistanceMap<2>, DistanceMapError>| {
        matches!(r.unwrap_err(), DistanceMapError::SubBoxes(_))
    };
    assert!(refused(
        DistanceMap::<2>::new(8.0, 32.0).unwrap().with_sub_boxes(0)
    ));
    assert!(refused(
        DistanceMap::<2>::new(8.0, 32.0).unwrap().with_sub_boxes(9)
    ));
    assert!(
        DistanceMap::<2>::new(8.0, 32.0)
            .unwrap()
            .with_sub_boxes(8)
            .is_ok()
    );
    assert!(
        DistanceMap::<3>::new(8.0, 32.0)
            .unwrap()
            .with_sub_boxes(4)
            .is_ok()
    );
    assert!(matches!(
        DistanceMap::<3>::new(8.0, 32.0)
            .unwrap()
            .with_sub_boxes(5)
            .unwrap_err(),
        DistanceMapError::SubBoxes(5)
    ));
    let mut map = DistanceMap::<2>::new(8.0, 32.0).unwrap();
    map.insert(&[0.0, 0.0]).unwrap();
    assert!(refused(map.with_sub_boxes(2)));
    // A map without sub-boxes refuses the sub-box inserts.
    let mut plain = DistanceMap::<2>::new(8.0, 32.0).unwrap();
    assert!(matches!(
        plain.insert_box_by_sub_box(&[0.0; 2], &[1.0; 2]),
        Err(DistanceMapError::SubBoxes(0))
    ));
    assert!(
        plain
            .insert_box_by_sub_box_shared(&[0.0; 2], &[1.0; 2])
            .is_err()
    );
}
