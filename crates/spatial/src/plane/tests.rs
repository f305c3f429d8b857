//! Unit tests of the plane grid: errors, box keys, ties, inclusive radii, moves and
//! back-indices, extreme coordinates, random worlds against brute force, work counters.

use super::*;
use crate::testdata::{BOX_SIZES, SplitMix};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Species {
    Fox,
    Rabbit,
}
use Species::{Fox, Rabbit};

/// Uniform in `lo..=hi`, from the crate's SplitMix64 test generator.
fn range(rng: &mut SplitMix, lo: i64, hi: i64) -> i64 {
    lo + (rng.next_u64() % (hi - lo + 1) as u64) as i64
}

fn brute_nearest(
    items: &[(u64, Pos, Species)],
    p: Pos,
    kind: Option<Species>,
    r2: u64,
    exclude: Option<u64>,
) -> Option<(u64, u64)> {
    items
        .iter()
        .filter(|(id, _, k)| kind.is_none_or(|kk| kk == *k) && exclude != Some(*id))
        .map(|&(id, q, _)| (dist2(p, q), id))
        .filter(|&(d2, _)| d2 <= u128::from(r2))
        .min()
        .map(|(d2, id)| (id, d2 as u64))
}

fn brute_count(
    items: &[(u64, Pos, Species)],
    p: Pos,
    kind: Option<Species>,
    r2: u64,
    exclude: Option<u64>,
) -> usize {
    items
        .iter()
        .filter(|(id, q, k)| {
            kind.is_none_or(|kk| kk == *k) && exclude != Some(*id) && dist2(p, *q) <= u128::from(r2)
        })
        .count()
}

#[test]
fn bad_box_sides_are_errors() {
    for a in [0, -1, -60, i64::MIN] {
        assert_eq!(
            PlaneGrid::<Species>::with_side(a).unwrap_err(),
            PlaneError::BadBoxSide(a)
        );
        assert!(PlaneGrid::<Species>::new(BoxSize::Side(a)).is_err());
    }
    let mut g = PlaneGrid::<Species>::with_side(5).unwrap();
    g.insert(1, [0, 0], Fox).unwrap();
    assert_eq!(g.rebox(BoxSize::Side(0)), Err(PlaneError::BadBoxSide(0)));
    assert_eq!(g.box_size(), BoxSize::Side(5));
    assert!(g.validate().is_ok());
    assert!(PlaneGrid::<Species>::with_side(1).is_ok());
    assert!(PlaneGrid::<Species>::with_side(i64::MAX).is_ok());
}

#[test]
fn box_size_parses_and_prints() {
    assert_eq!("none".parse::<BoxSize>(), Ok(BoxSize::None));
    assert_eq!("NONE".parse::<BoxSize>(), Ok(BoxSize::None));
    assert_eq!("60".parse::<BoxSize>(), Ok(BoxSize::Side(60)));
    assert_eq!("0".parse::<BoxSize>(), Err(PlaneError::BadBoxSide(0)));
    assert_eq!("-3".parse::<BoxSize>(), Err(PlaneError::BadBoxSide(-3)));
    assert!(matches!(
        "sixty".parse::<BoxSize>(),
        Err(PlaneError::ParseBoxSize(_))
    ));
    assert_eq!(BoxSize::Side(120).to_string(), "120");
    assert_eq!(BoxSize::None.to_string(), "none");
    let msg = PlaneError::BadBoxSide(0).to_string();
    assert!(msg.contains('0') && msg.contains("positive"), "{msg}");
}

#[test]
fn duplicate_and_unknown_ids_are_errors() {
    for size in [BoxSize::None, BoxSize::Side(3)] {
        let mut g = PlaneGrid::new(size).unwrap();
        g.insert(7, [1, 2], Rabbit).unwrap();
        assert_eq!(g.insert(7, [5, 5], Fox), Err(PlaneError::DuplicateId(7)));
        assert_eq!(g.get(7), Some(([1, 2], Rabbit)));
        assert_eq!(g.remove(8), Err(PlaneError::UnknownId(8)));
        assert_eq!(g.move_to(8, [0, 0]), Err(PlaneError::UnknownId(8)));
        assert_eq!(g.remove(7), Ok(([1, 2], Rabbit)));
        assert_eq!(g.remove(7), Err(PlaneError::UnknownId(7)));
        assert!(g.is_empty());
        assert_eq!(g.box_count(), 0);
        g.validate().unwrap();
    }
}

#[test]
fn negative_coordinates_use_floor_boxes() {
    let g = PlaneGrid::<Species>::with_side(10).unwrap();
    assert_eq!(g.box_key([-1, -1]), [-1, -1]);
    assert_eq!(g.box_key([-10, 9]), [-1, 0]);
    assert_eq!(g.box_key([-11, 10]), [-2, 1]);
    assert_eq!(
        g.box_key([i64::MIN, i64::MAX]),
        [i64::MIN / 10 - 1, i64::MAX / 10]
    );
    // A query at the origin must see an item one cell away in the negative box.
    let mut g = g;
    g.insert(1, [-1, -1], Fox).unwrap();
    assert_eq!(g.nearest([0, 0], Fox, 2, None), Some((1, 2)));
    assert_eq!(g.nearest([0, 0], Fox, 1, None), None);
    assert!(g.any_within([0, 0], Fox, 2, None));
    assert_eq!(g.count_within([9, 9], 200, None), 1);
}

#[test]
fn ties_go_to_the_lower_id_whatever_the_insertion_order() {
    let ring = [[1, 0], [0, 1], [-1, 0], [0, -1], [3, 4], [-4, 3], [5, 0]];
    for size in [
        BoxSize::None,
        BoxSize::Side(1),
        BoxSize::Side(2),
        BoxSize::Side(60),
    ] {
        for rot in 0..ring.len() {
            let mut g = PlaneGrid::new(size).unwrap();
            for i in 0..ring.len() {
                let j = (i + rot) % ring.len();
                g.insert(100 - j as u64, ring[j], Rabbit).unwrap();
            }
            // ids 100..=97 at distance 1: the lowest is 97 ([0, -1]).
            assert_eq!(g.nearest([0, 0], Rabbit, 100, None), Some((97, 1)));
            assert_eq!(g.nearest([0, 0], Rabbit, 100, Some(97)), Some((98, 1)));
            assert_eq!(g.nearest([0, 0], Rabbit, 0, None), None);
            // From [0, 2]: [0, 1] (id 99) at 1.
            assert_eq!(g.nearest([0, 2], Rabbit, 1, None), Some((99, 1)));
            // Distance-5 ties from [0, 0]: [3, 4] (96), [-4, 3] (95), [5, 0] (94).
            let far: Vec<_> = g
                .within([0, 0], None, 25, None)
                .into_iter()
                .filter(|&(_, d2)| d2 == 25)
                .collect();
            assert_eq!(far, vec![(94, 25), (95, 25), (96, 25)]);
            assert_eq!(g.nearest([0, 0], Fox, u64::MAX, None), None);
        }
    }
}

#[test]
fn radius_is_inclusive_and_r2_two_means_adjacent() {
    for size in [
        BoxSize::None,
        BoxSize::Side(1),
        BoxSize::Side(3),
        BoxSize::Side(7),
    ] {
        let mut g = PlaneGrid::new(size).unwrap();
        let mut id = 0;
        for x in -2..=2 {
            for y in -2..=2 {
                id += 1;
                g.insert(id, [x, y], if (x + y) % 2 == 0 { Fox } else { Rabbit })
                    .unwrap();
            }
        }
        let me = 13; // the centre [0, 0]
        assert_eq!(g.get(me), Some(([0, 0], Fox)));
        assert_eq!(g.count_within([0, 0], 0, Some(me)), 0);
        assert_eq!(g.count_within([0, 0], 0, None), 1);
        assert_eq!(g.count_within([0, 0], 1, Some(me)), 4);
        assert_eq!(g.count_within([0, 0], 2, Some(me)), 8);
        assert_eq!(g.count_within([0, 0], 3, Some(me)), 8);
        assert_eq!(g.count_within([0, 0], 4, Some(me)), 12);
        assert_eq!(g.count_within([0, 0], 8, Some(me)), 24);
        assert_eq!(g.count_within_kind([0, 0], Rabbit, 2, Some(me)), 4);
        assert_eq!(g.count_within_kind([0, 0], Fox, 2, Some(me)), 4);
        assert_eq!(g.count_within_capped([0, 0], None, 8, Some(me), 5), 5);
        assert_eq!(g.count_within_capped([0, 0], None, 8, Some(me), 0), 0);
        assert!(g.at_least([0, 0], None, 2, Some(me), 8));
        assert!(!g.at_least([0, 0], None, 2, Some(me), 9));
        assert!(g.at_least([0, 0], None, 0, Some(me), 0));
        assert!(g.any_within([0, 0], Rabbit, 1, Some(me)));
        assert!(!g.any_within([0, 0], Fox, 1, Some(me)));
        assert!(g.any_within([0, 0], Fox, 2, Some(me)));
    }
}

#[test]
fn moves_update_boxes_cells_and_back_indices() {
    let mut g = PlaneGrid::with_side(4).unwrap();
    for id in 0..20u64 {
        g.insert(id, [id as i64 % 4, 0], Rabbit).unwrap();
    }
    g.validate().unwrap();
    // Walk item 3 across several boundaries, including into negative boxes.
    for x in (-9..=9).rev() {
        g.move_to(3, [x, -x]).unwrap();
        g.validate().unwrap();
        assert_eq!(g.get(3), Some(([x, -x], Rabbit)));
        assert!(g.is_occupied([x, -x]));
    }
    assert_eq!(g.move_to(3, [-9, 9]), Ok([-9, 9]));
    // Shared cells.
    assert_eq!(g.occupancy([0, 0]), 5);
    assert_eq!(
        g.items_at([0, 0]).iter().map(|x| x.0).collect::<Vec<_>>(),
        vec![0, 4, 8, 12, 16]
    );
    g.move_to(8, [100, 100]).unwrap();
    assert_eq!(g.occupancy([0, 0]), 4);
    assert!(g.items_at([55, 55]).is_empty());
    // Remove half, in an order that exercises the swap_remove back-index.
    for id in (0..20u64).step_by(2) {
        g.remove(id).unwrap();
        g.validate().unwrap();
    }
    assert_eq!(g.len(), 10);
    assert!(!g.is_occupied([0, 0]));
    let mut ids: Vec<u64> = g.iter().map(|(id, _, _)| id).collect();
    ids.sort_unstable();
    assert_eq!(ids, (1..20).step_by(2).collect::<Vec<_>>());
    g.rebox(BoxSize::Side(1)).unwrap();
    g.validate().unwrap();
    g.rebox(BoxSize::None).unwrap();
    g.validate().unwrap();
    assert_eq!(g.box_count(), 1);
    let c = g.clone();
    c.validate().unwrap();
    g.clear();
    assert!(g.is_empty() && g.validate().is_ok() && c.len() == 10);
}

#[test]
fn extreme_coordinates_are_exact() {
    let corners = [
        [i64::MIN, i64::MIN],
        [i64::MAX, i64::MAX],
        [i64::MIN, i64::MAX],
        [i64::MAX, i64::MIN],
        [i64::MAX - 1, i64::MAX],
        [0, 0],
        [-(1 << 32), 0],
        [1 << 32, 1],
    ];
    for size in [
        BoxSize::None,
        BoxSize::Side(1),
        BoxSize::Side(7),
        BoxSize::Side(i64::MAX),
    ] {
        let mut g = PlaneGrid::new(size).unwrap();
        let items: Vec<(u64, Pos, Species)> = corners
            .iter()
            .enumerate()
            .map(|(i, &p)| (i as u64, p, Rabbit))
            .collect();
        for &(id, p, k) in &items {
            g.insert(id, p, k).unwrap();
        }
        g.validate().unwrap();
        for &q in &corners {
            for r2 in [0, 1, 2, u64::MAX / 2, u64::MAX - 1, u64::MAX] {
                for ex in [None, Some(0), Some(4)] {
                    assert_eq!(
                        g.nearest(q, Rabbit, r2, ex),
                        brute_nearest(&items, q, Some(Rabbit), r2, ex),
                        "{size:?} {q:?} {r2}"
                    );
                    assert_eq!(
                        g.count_within(q, r2, ex),
                        brute_count(&items, q, None, r2, ex),
                        "{size:?} {q:?} {r2}"
                    );
                }
            }
        }
    }
    // (2^32)^2 = 2^64 > u64::MAX: out of every radius; (2^32-1)^2 + 0 fits.
    let mut g = PlaneGrid::with_side(3).unwrap();
    g.insert(1, [1 << 32, 0], Fox).unwrap();
    g.insert(2, [0, (1 << 32) - 1], Fox).unwrap();
    assert_eq!(
        g.nearest([0, 0], Fox, u64::MAX, None),
        Some((2, ((1u64 << 32) - 1) * ((1u64 << 32) - 1)))
    );
    assert_eq!(g.count_within([0, 0], u64::MAX, None), 1);
}

#[test]
fn random_worlds_match_brute_force_and_each_other() {
    let mut rng = SplitMix::new(0x5EED);
    let sizes: Vec<BoxSize> = BOX_SIZES.into_iter().chain([BoxSize::Side(240)]).collect();
    for world in 0..6 {
        let span = [20, 80, 300, 1000, 50, 5000][world];
        let n = [50, 300, 800, 1500, 400, 200][world];
        let mut items: Vec<(u64, Pos, Species)> = Vec::new();
        for id in 0..n {
            let p = [range(&mut rng, -span, span), range(&mut rng, -span, span)];
            let k = if rng.next_u64() % 4 == 0 { Fox } else { Rabbit };
            items.push((id, p, k));
        }
        let grids: Vec<PlaneGrid<Species>> = sizes
            .iter()
            .map(|&s| {
                let mut g = PlaneGrid::new(s).unwrap();
                for &(id, p, k) in &items {
                    g.insert(id, p, k).unwrap();
                }
                g
            })
            .collect();
        for _ in 0..150 {
            let p = if rng.next_u64() % 2 == 0 {
                items[(rng.next_u64() % n) as usize].1
            } else {
                [
                    range(&mut rng, -span - 70, span + 70),
                    range(&mut rng, -span - 70, span + 70),
                ]
            };
            let r2 = [0, 1, 2, 5, 25, 100, 3600, 14400, u64::MAX][(rng.next_u64() % 9) as usize];
            let ex = Some(rng.next_u64() % (n + 5));
            for kind in [Some(Fox), Some(Rabbit), None] {
                let want = brute_nearest(&items, p, kind, r2, ex);
                let want_c = brute_count(&items, p, kind, r2, ex);
                for g in &grids {
                    let got = match kind {
                        Some(k) => g.nearest(p, k, r2, ex),
                        None => g.nearest_any(p, r2, ex),
                    };
                    assert_eq!(got, want, "{:?} p={p:?} r2={r2}", g.box_size());
                    let c = g.count_within_capped(p, kind, r2, ex, usize::MAX);
                    assert_eq!(c, want_c, "{:?} p={p:?} r2={r2}", g.box_size());
                    let cap = (rng.next_u64() % 6) as usize;
                    assert_eq!(g.count_within_capped(p, kind, r2, ex, cap), want_c.min(cap));
                }
            }
        }
    }
}

#[test]
fn counter_counts_full_evaluations_only() {
    let mut g = PlaneGrid::exhaustive();
    g.insert(1, [0, 0], Fox).unwrap();
    g.insert(2, [100, 0], Fox).unwrap(); // fails the per-axis test for r2 = 3600
    g.insert(3, [30, 30], Fox).unwrap(); // passes both axis tests, then d2 = 1800
    g.insert(4, [59, 59], Rabbit).unwrap(); // wrong kind: not evaluated
    assert_eq!(g.distance_evals(), 0);
    assert_eq!(g.nearest([0, 0], Fox, 3600, Some(1)), Some((3, 1800)));
    assert_eq!(g.distance_evals(), 1);
    assert_eq!(g.count_within([0, 0], 3600, None), 2); // items 1, 3; item 4 at 6962 > 3600
    assert_eq!(g.distance_evals(), 4); // 1 + (1, 3, 4)
    assert_eq!(g.take_distance_evals(), 4);
    assert_eq!(g.distance_evals(), 0);
    // any_within stops at the first hit: at most 2 evaluations.
    assert!(g.any_within([0, 0], Fox, 3600, None));
    assert!(g.distance_evals() <= 2);
    g.reset_distance_evals();
    assert_eq!(g.distance_evals(), 0);

    // Items scanned and boxes probed: all 4 items in the one list, per query.
    g.reset_stats();
    g.nearest([0, 0], Fox, 3600, None);
    assert_eq!(
        g.take_stats(),
        SearchStats {
            distance_evals: 1, // item 1 at d2 = 0 shrinks the limit to 0
            items_scanned: 4,
            boxes_probed: 1
        }
    );
    assert_eq!(g.stats(), SearchStats::default());

    // With boxes of side 60, a query far from every box evaluates nothing.
    let mut g = PlaneGrid::with_side(60).unwrap();
    for i in 0..100 {
        g.insert(i, [i as i64, 0], Rabbit).unwrap();
    }
    assert_eq!(g.nearest([10_000, 10_000], Rabbit, 3600, None), None);
    assert_eq!(g.distance_evals(), 0);
    assert_eq!(g.stats().items_scanned, 0);
    // Nearest from an item's own cell stops after ring 0/1.
    assert_eq!(g.nearest([50, 0], Rabbit, 3600, Some(50)), Some((49, 1)));
    assert!(g.distance_evals() < 100);
}

#[test]
fn grid_is_send_and_sync() {
    fn check<T: Send + Sync>() {}
    check::<PlaneGrid<Species>>();
}

#[test]
fn without_cell_counts_answers_the_same() {
    for size in [BoxSize::None, BoxSize::Side(3), BoxSize::Side(60)] {
        let mut a: PlaneGrid<u8> = PlaneGrid::new(size).unwrap();
        let mut b: PlaneGrid<u8> = PlaneGrid::without_cell_counts(size).unwrap();
        assert!(a.tracks_cells() && !b.tracks_cells());
        let pts: [Pos; 6] = [[0, 0], [0, 0], [-1, 5], [7, -3], [100, 100], [-50, 2]];
        for (id, &p) in pts.iter().enumerate() {
            a.insert(id as u64, p, (id % 2) as u8).unwrap();
            b.insert(id as u64, p, (id % 2) as u8).unwrap();
        }
        for g in [&mut a, &mut b] {
            g.move_to(2, [-1, 6]).unwrap();
            g.move_to(4, [-3, 1]).unwrap();
            g.remove(1).unwrap();
            g.validate().unwrap();
        }
        for x in -4..9 {
            for y in -4..9 {
                let p = [x, y];
                assert_eq!(a.is_occupied(p), b.is_occupied(p));
                assert_eq!(a.occupancy(p), b.occupancy(p));
                assert_eq!(a.items_at(p), b.items_at(p));
                assert_eq!(a.nearest(p, 1, 400, None), b.nearest(p, 1, 400, None));
            }
        }
        assert!(b.clone().validate().is_ok());
    }
}
