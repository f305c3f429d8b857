//! Property tests of [`spatial::cells::CellIndex`] and its queries against a brute-force scan.
//!
//! The cell index is the animat model's hot-path search: after any sequence of puts, clears,
//! moves and re-bucketings, every cell read (directly, through a window and its row words),
//! every rectangle scan, the near cache's bit tricks, the ring searches of a window and the
//! wide grid-box queries must equal
//! an exhaustive scan over an independent model of the items, ties (lower id wins) included,
//! for every box side of the wide queries.
//!
//! Positions mix a dense patch (many equal distances), coordinates on and next to tile and
//! block boundaries (64 and 8), a wider spread, and far-away and extreme coordinates (where
//! windows are refused); radii include 0, 2 (the 8 adjacent cells), 81, the animat vision
//! radius 60 (3600), random ones and `u64::MAX`.

mod common;
use common::{EXTREME, config};

use std::collections::BTreeMap;
use std::ops::ControlFlow;

use proptest::prelude::*;
use proptest::sample::{Index, select};
use spatial::cells::near::{
    NEAR_HALF, NEAR_ROWS, NEAR_WINDOW_MIN, Near, RING_CLASSES, count_in, kind_bits, lowest_in,
    row_byte, row_cell,
};
use spatial::cells::{CellIndex, FREE, KIND_A, KIND_B, KIND_MASK, WINDOW_MAX};
use spatial::plane::{Pos, dist2};

/// Independent model: cell -> (id, kind byte).
type Model = BTreeMap<Pos, (u64, u8)>;

fn coord() -> impl Strategy<Value = i64> {
    prop_oneof![
        6 => -12i64..=12,
        // On and next to tile and block boundaries, both signs.
        4 => (-3i64..=3, select(vec![8i64, 64]), -1i64..=1).prop_map(|(m, s, o)| m * s + o),
        3 => -200i64..=200,
        1 => select(EXTREME.to_vec()),
    ]
}

fn pos() -> impl Strategy<Value = Pos> {
    (coord(), coord()).prop_map(|(x, y)| [x, y])
}

fn kind() -> impl Strategy<Value = u8> {
    select(vec![KIND_A, KIND_B])
}

#[derive(Debug, Clone)]
enum Op {
    /// Put a new item (the next id) of this kind on the cell, if free.
    Put(Pos, u8),
    /// Clear the cell of an existing item.
    Clear(Index),
    /// Move an existing item by an offset, if the target is free.
    Move(Index, [i64; 2]),
    /// Map ids to buckets afresh.
    Rebucket(u64, u32),
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        8 => (pos(), kind()).prop_map(|(p, k)| Op::Put(p, k)),
        2 => any::<Index>().prop_map(Op::Clear),
        3 => (any::<Index>(), (-70i64..=70, -70i64..=70)).prop_map(|(i, (dx, dy))| Op::Move(i, [dx, dy])),
        1 => (0u64..40, 0u32..5).prop_map(|(b, s)| Op::Rebucket(b, s)),
    ]
}

/// The index and the model after `ops`; ids are 1, 2, ... in order of puts.
fn build(ops: &[Op]) -> (CellIndex, Model) {
    let mut c = CellIndex::default();
    let mut m = Model::new();
    let mut next = 1u64;
    for op in ops {
        match op {
            Op::Put(p, k) if !m.contains_key(p) => {
                c.set(*p, *k, next);
                m.insert(*p, (next, *k));
                next += 1;
            }
            Op::Clear(i) if !m.is_empty() => {
                let p = *m.keys().nth(i.index(m.len())).unwrap();
                c.clear(p);
                m.remove(&p);
            }
            Op::Move(i, d) if !m.is_empty() => {
                let p = *m.keys().nth(i.index(m.len())).unwrap();
                let to = [p[0].saturating_add(d[0]), p[1].saturating_add(d[1])];
                if !m.contains_key(&to) {
                    c.relocate(p, to);
                    let v = m.remove(&p).unwrap();
                    m.insert(to, v);
                }
            }
            Op::Rebucket(base, shift) => {
                c.rebucket(*base, *shift, m.iter().map(|(p, v)| (*p, v.0)));
            }
            _ => {}
        }
    }
    (c, m)
}

/// Brute force: the items other than the one on `p` of a kind meeting `kinds` within `r2`.
fn within(m: &Model, p: Pos, kinds: u8, r2: u64) -> impl Iterator<Item = (Pos, u64)> + '_ {
    m.iter()
        .filter(move |(q, v)| **q != p && v.1 & kinds != 0 && dist2(p, **q) <= u128::from(r2))
        .map(|(q, v)| (*q, v.0))
}

fn query_point(m: &Model, i: &Index, free: Pos, on_item: bool) -> Pos {
    if on_item && !m.is_empty() {
        *m.keys().nth(i.index(m.len())).unwrap()
    } else {
        free
    }
}

fn radius() -> impl Strategy<Value = u64> {
    prop_oneof![
        select(vec![0u64, 1, 2, 8, 81, 3600, u64::MAX]),
        0u64..20_000,
    ]
}

fn side() -> impl Strategy<Value = i64> {
    prop_oneof![select(vec![1i64, 2, 3, 7, 60, i64::MAX]), 1i64..=200,]
}

proptest! {
    #![proptest_config(config(300))]

    /// Cell reads, windows and row words agree with the model.
    #[test]
    fn cells_and_windows_match_the_model(
        ops in prop::collection::vec(op(), 0..120),
        probes in prop::collection::vec((any::<Index>(), pos(), any::<bool>()), 1..6),
        k in NEAR_WINDOW_MIN..=WINDOW_MAX,
    ) {
        let (c, m) = build(&ops);
        prop_assert_eq!(c.len(), m.len());
        prop_assert_eq!(c.is_empty(), m.is_empty());
        for (p, &(id, kb)) in &m {
            prop_assert_eq!(c.kind(*p), kb);
            prop_assert!(c.occupied(*p));
            prop_assert_eq!(c.id(*p), id);
        }
        for (i, free, on_item) in &probes {
            let p = query_point(&m, i, *free, *on_item);
            let expect = |q: Pos| m.get(&q).map_or(FREE, |v| v.1);
            prop_assert_eq!(c.kind(p), expect(p));
            let Some(w) = c.window(p, k) else {
                // Only near the i64 limits.
                prop_assert!(p.iter().any(|v| !(i64::MIN + 1024..=i64::MAX - 1024).contains(v)));
                continue;
            };
            for y in p[1] - k..=p[1] + k {
                for x in p[0] - k..=p[0] + k {
                    prop_assert_eq!(w.at(x, y), expect([x, y]), "{:?} {} {}", p, x, y);
                    if let Some(&(id, kb)) = m.get(&[x, y]) {
                        prop_assert_eq!(w.id(x, y), id);
                        prop_assert_eq!(w.byte(x, y), kb | c.bucket(id) << 2);
                    } else {
                        prop_assert_eq!(w.byte(x, y), FREE);
                    }
                }
            }
            let rows = w.rows::<NEAR_ROWS>(p[0] - NEAR_HALF, p[1] - NEAR_HALF);
            for (r, &row) in rows.iter().enumerate() {
                for i in 0..8 {
                    let q = [p[0] - NEAR_HALF + i, p[1] - NEAR_HALF + r as i64];
                    prop_assert_eq!((row >> (8 * i)) as u8, w.byte(q[0], q[1]));
                }
            }
        }
    }

    /// Buckets are non-decreasing in the id and capped at 63.
    #[test]
    fn buckets_are_monotone(base in 0u64..1000, shift in 0u32..64, a in any::<u64>(), b in any::<u64>()) {
        let mut c = CellIndex::default();
        c.rebucket(base, shift, std::iter::empty());
        let (lo, hi) = (a.min(b), a.max(b));
        prop_assert!(c.bucket(lo) <= c.bucket(hi));
        prop_assert!(c.bucket(hi) <= 63);
        prop_assert_eq!(c.bucket_capped(hi), (hi.saturating_sub(base) >> shift) > 63);
    }

    /// A rectangle scan visits exactly the occupied cells of the kinds in the rectangle.
    #[test]
    fn scan_rect_matches_the_model(
        ops in prop::collection::vec(op(), 0..120),
        corner in pos(),
        size in (0i64..300, 0i64..300),
        kinds in 0u8..4,
    ) {
        let (c, m) = build(&ops);
        let xs = [corner[0], corner[0].saturating_add(size.0)];
        let ys = [corner[1], corner[1].saturating_add(size.1)];
        let mut seen = Vec::new();
        let _ = c.scan_rect(xs, ys, kinds, |x, y, byte| {
            seen.push(([x, y], byte));
            ControlFlow::Continue(())
        });
        seen.sort_unstable();
        let want: Vec<(Pos, u8)> = m
            .iter()
            .filter(|(p, v)| {
                (xs[0]..=xs[1]).contains(&p[0]) && (ys[0]..=ys[1]).contains(&p[1]) && v.1 & kinds != 0
            })
            .map(|(p, v)| (*p, v.1 | c.bucket(v.0) << 2))
            .collect();
        prop_assert_eq!(seen, want);
    }

    /// The wide queries equal the exhaustive answers for every box side.
    #[test]
    fn wide_queries_match_brute_force(
        ops in prop::collection::vec(op(), 0..150),
        queries in prop::collection::vec(
            (any::<Index>(), pos(), any::<bool>(), radius(), 1u8..4, side(), 0usize..6),
            1..8,
        ),
    ) {
        let (c, m) = build(&ops);
        for (i, free, on_item, r2, kinds, side, n) in &queries {
            let p = query_point(&m, i, *free, *on_item);
            let want = within(&m, p, *kinds, *r2)
                .min_by_key(|&(q, id)| (dist2(p, q), id))
                .map(|(q, _)| q);
            prop_assert_eq!(c.nearest_within(p, *kinds, *r2, *side).0, want,
                "p {:?} r2 {} kinds {} side {}", p, r2, kinds, side);
            let count = within(&m, p, *kinds, *r2).count();
            for n in [*n, count, count + 1] {
                prop_assert_eq!(c.at_least_within(p, *kinds, *r2, n, *side).0, count >= n,
                    "p {:?} r2 {} kinds {} side {} n {}", p, r2, kinds, side, n);
            }
        }
    }

    /// The near cache's classes, counts and lowest ids equal a scan of the 5 x 5 square; wide
    /// buckets make equally near cells share a bucket, so ties are settled by the ids.
    #[test]
    fn near_rows_match_brute_force(
        ops in prop::collection::vec(prop_oneof![
            3 => ((-4i64..=4, -4i64..=4), kind()).prop_map(|((x, y), k)| Op::Put([x, y], k)),
            1 => op(),
        ], 0..150),
        shift in 0u32..8,
        probes in prop::collection::vec((any::<Index>(), pos(), any::<bool>(), kind()), 1..6),
    ) {
        let (mut c, m) = build(&ops);
        c.rebucket(0, shift, m.iter().map(|(p, v)| (*p, v.0)));
        for (i, free, on_item, kb) in &probes {
            let p = query_point(&m, i, *free, *on_item);
            let mut near = Near::new(c.window(p, NEAR_WINDOW_MIN));
            let Some((w, rows)) = near.parts(p) else { continue };
            let rows = *rows;
            for dy in -NEAR_HALF..=NEAR_HALF {
                for dx in -NEAR_HALF..=NEAR_HALF {
                    let q = [p[0] + dx, p[1] + dy];
                    prop_assert_eq!(row_cell(&rows, dx, dy), c.kind(q));
                    prop_assert_eq!(row_byte(&rows, dx, dy) & KIND_MASK, c.kind(q));
                }
            }
            let bits = kind_bits(&rows, *kb);
            for (class, d2) in RING_CLASSES.iter().zip([1u128, 2, 4, 5, 8]) {
                let cells: Vec<(u64, Pos)> = m
                    .iter()
                    .filter(|(q, v)| v.1 == *kb && dist2(p, **q) == d2)
                    .map(|(q, v)| (v.0, *q))
                    .collect();
                let n = count_in(&bits, class);
                prop_assert_eq!(n, cells.len() as u64);
                if n > 0 {
                    let lowest = cells.iter().min().unwrap().1;
                    prop_assert_eq!(lowest_in(&bits, class, n, p, &rows, w), lowest);
                }
            }
        }
    }

    /// The ring searches of a window equal a scan of the rings (and, once settled, of the
    /// whole plane).
    #[test]
    fn ring_searches_match_brute_force(
        ops in prop::collection::vec(prop_oneof![
            2 => ((-10i64..=10, -10i64..=10), kind()).prop_map(|((x, y), k)| Op::Put([x, y], k)),
            1 => op(),
        ], 0..150),
        shift in 0u32..8,
        probes in prop::collection::vec(
            (any::<Index>(), pos(), any::<bool>(), kind(), radius(), 1i64..=3, 0i64..=WINDOW_MAX, 1usize..8),
            1..6,
        ),
    ) {
        let (mut c, m) = build(&ops);
        c.rebucket(0, shift, m.iter().map(|(p, v)| (*p, v.0)));
        for (i, free, on_item, kb, r2, k_first, k_max, n) in &probes {
            let p = query_point(&m, i, *free, *on_item);
            let Some(w) = c.window(p, WINDOW_MAX) else { continue };
            let cheb = |q: &Pos| p[0].abs_diff(q[0]).max(p[1].abs_diff(q[1])) as i64;
            let of_kind = |lo: i64, hi: i64| {
                m.iter()
                    .filter(move |(q, v)| {
                        v.1 == *kb && (lo..=hi).contains(&cheb(q)) && dist2(p, **q) <= u128::from(*r2)
                    })
                    .map(|(q, v)| (dist2(p, *q), v.0, *q))
            };
            let got = w.nearest_in_rings(p, *kb, *r2, *k_first, *k_max);
            let want = if got.settled {
                of_kind(*k_first, i64::MAX).min()
            } else {
                of_kind(*k_first, *k_max).min()
            };
            prop_assert_eq!(got.found, want.map(|t| t.2), "p {:?} r2 {} settled {}", p, r2, got.settled);
            if !got.settled {
                // Not settled only when another ring could matter.
                prop_assert!(*k_max < *k_first || ((*k_max + 1) * (*k_max + 1)) as u64 <= *r2);
            }
            let count = of_kind(1, *k_max).count();
            prop_assert_eq!(w.count_in_rings(p, *kb, *r2, *n, *k_max), (count >= *n, count.min(*n)));
        }
    }
}

/// A tie across rings: (4, 3) in ring 4 and (5, 0) in ring 5 are both at squared distance 25,
/// so ring 4 cannot settle the search and the lower id, in ring 5, wins.
#[test]
fn ring_search_ties_across_rings_go_to_the_lower_id() {
    for (near_id, far_id) in [(2, 1), (1, 2)] {
        let mut c = CellIndex::default();
        c.rebucket(0, 8, std::iter::empty());
        c.set([4, 3], KIND_B, near_id);
        c.set([5, 0], KIND_B, far_id);
        let w = c.window([0, 0], WINDOW_MAX).unwrap();
        let got = w.nearest_in_rings([0, 0], KIND_B, 100, 1, 8);
        let want = if far_id < near_id { [5, 0] } else { [4, 3] };
        assert_eq!(got.found, Some(want));
        assert!(got.settled);
    }
}
