//! Property tests of [`spatial::plane::PlaneGrid`] against a brute-force scan.
//!
//! Grid boxing is not an approximation (the grid-boxing paper, sections I and II.B): for every box
//! size, after any sequence of inserts, removals and moves, every answer of `nearest`,
//! `count_within`, `any_within`, `at_least` and `within` must equal an exhaustive scan over an
//! independent model of the items, ties (lower id wins) included.
//!
//! The item sets mix a dense patch around the origin (shared cells and many equal distances),
//! coordinates on and next to box boundaries, negative coordinates, far-away and extreme
//! (`i64::MIN`/`i64::MAX`) coordinates; the radii include 0, 2 (the 8 adjacent cells), radii
//! exactly equal to an item's distance (and one less or more), the animat vision radius 60 and
//! `u64::MAX`.

mod common;
use common::{EXTREME, config};

use std::collections::BTreeMap;

use proptest::prelude::*;
use proptest::sample::{Index, select};
use spatial::plane::{BoxSize, PlaneError, PlaneGrid, Pos, dist2};
use spatial::testdata::BOX_SIZES;

type Kind = u8;

/// Independent model: id -> (position, kind).
type Model = BTreeMap<u64, (Pos, Kind)>;

fn box_size() -> impl Strategy<Value = BoxSize> {
    prop_oneof![
        4 => select(BOX_SIZES.to_vec()),
        1 => (1i64..=100).prop_map(BoxSize::Side),
    ]
}

fn coord() -> impl Strategy<Value = i64> {
    prop_oneof![
        // Dense patch: shared cells and many ties.
        6 => -12i64..=12,
        // On and next to box boundaries of the sides under test, both signs.
        4 => (-4i64..=4, select(vec![1i64, 2, 3, 7, 60]), -1i64..=1)
            .prop_map(|(m, s, o)| m * s + o),
        3 => -150i64..=150,
        // Far away and extreme, and around 2^32, where a square overflows 64 bits.
        1 => select(
            EXTREME
                .into_iter()
                .chain([-(1i64 << 32), 1i64 << 32, (1i64 << 32) - 1])
                .collect::<Vec<_>>(),
        ),
        1 => any::<i64>(),
    ]
}

fn pos() -> impl Strategy<Value = Pos> {
    (coord(), coord()).prop_map(|(x, y)| [x, y])
}

fn kind() -> impl Strategy<Value = Kind> {
    0u8..2
}

#[derive(Debug, Clone)]
enum Op {
    Insert(Pos, Kind),
    Remove(Index),
    Move(Index, Pos),
    /// A unit step (the animat move), which often crosses box boundaries.
    Step(Index, i64, i64),
    RemoveUnknown(u64),
    InsertDuplicate(Index, Pos),
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        4 => (pos(), kind()).prop_map(|(p, k)| Op::Insert(p, k)),
        2 => any::<Index>().prop_map(Op::Remove),
        2 => (any::<Index>(), pos()).prop_map(|(i, p)| Op::Move(i, p)),
        4 => (any::<Index>(), -1i64..=1, -1i64..=1).prop_map(|(i, dx, dy)| Op::Step(i, dx, dy)),
        1 => (0u64..4).prop_map(Op::RemoveUnknown),
        1 => (any::<Index>(), pos()).prop_map(|(i, p)| Op::InsertDuplicate(i, p)),
    ]
}

#[derive(Debug, Clone)]
enum At {
    Free(Pos),
    OnItem(Index),
    NearItem(Index, i64, i64),
}

#[derive(Debug, Clone)]
enum Radius {
    Fixed(u64),
    /// Exactly the squared distance from the query point to an item, plus -1, 0 or +1.
    Exact(Index, i8),
}

#[derive(Debug, Clone)]
enum Excl {
    Nobody,
    Item(Index),
    Dead(u64),
}

#[derive(Debug, Clone)]
struct Query {
    at: At,
    r2: Radius,
    excl: Excl,
    cap: usize,
}

fn query() -> impl Strategy<Value = Query> {
    let at = prop_oneof![
        2 => pos().prop_map(At::Free),
        2 => any::<Index>().prop_map(At::OnItem),
        2 => (any::<Index>(), -80i64..=80, -80i64..=80).prop_map(|(i, dx, dy)| At::NearItem(i, dx, dy)),
    ];
    let r2 = prop_oneof![
        4 => select(vec![0u64, 1, 2, 3, 4, 5, 8, 9, 25, 50, 100, 3600, 14400, u64::MAX])
            .prop_map(Radius::Fixed),
        2 => (0u64..20_000).prop_map(Radius::Fixed),
        1 => any::<u64>().prop_map(Radius::Fixed),
        3 => (any::<Index>(), -1i8..=1).prop_map(|(i, o)| Radius::Exact(i, o)),
    ];
    let excl = prop_oneof![
        1 => Just(Excl::Nobody),
        2 => any::<Index>().prop_map(Excl::Item),
        1 => any::<u64>().prop_map(Excl::Dead),
    ];
    (at, r2, excl, 0usize..8).prop_map(|(at, r2, excl, cap)| Query { at, r2, excl, cap })
}

fn pick(model: &Model, i: &Index) -> Option<(u64, Pos, Kind)> {
    if model.is_empty() {
        return None;
    }
    let (&id, &(p, k)) = model.iter().nth(i.index(model.len()))?;
    Some((id, p, k))
}

/// Resolves a symbolic query against the current items: (point, r2, exclude, cap).
fn resolve(model: &Model, q: &Query) -> (Pos, u64, Option<u64>, usize) {
    let p = match &q.at {
        At::Free(p) => *p,
        At::OnItem(i) => pick(model, i).map_or([0, 0], |(_, p, _)| p),
        At::NearItem(i, dx, dy) => pick(model, i).map_or([*dx, *dy], |(_, p, _)| {
            [p[0].saturating_add(*dx), p[1].saturating_add(*dy)]
        }),
    };
    let r2 = match &q.r2 {
        Radius::Fixed(r) => *r,
        Radius::Exact(i, o) => {
            let d = pick(model, i).map_or(0, |(_, ip, _)| dist2(p, ip));
            let d = u64::try_from(d).unwrap_or(u64::MAX);
            match o {
                -1 => d.saturating_sub(1),
                1 => d.saturating_add(1),
                _ => d,
            }
        }
    };
    let exclude = match &q.excl {
        Excl::Nobody => None,
        Excl::Item(i) => pick(model, i).map(|(id, _, _)| id),
        Excl::Dead(id) => Some(*id),
    };
    (p, r2, exclude, q.cap)
}

/// The brute-force reference: every item, exact u128 squared distances, order (dist2, id).
fn brute(
    model: &Model,
    p: Pos,
    kind: Option<Kind>,
    r2: u64,
    exclude: Option<u64>,
) -> Vec<(u64, u64)> {
    let mut v: Vec<(u64, u64)> = model
        .iter()
        .filter(|&(&id, &(_, k))| kind.is_none_or(|kk| kk == k) && exclude != Some(id))
        .filter_map(|(&id, &(q, _))| {
            let d = dist2(p, q);
            (d <= u128::from(r2)).then_some((id, d as u64))
        })
        .collect();
    v.sort_unstable_by_key(|&(id, d2)| (d2, id));
    v
}

/// Applies one operation to both the grid and the model, checking errors.
fn apply(
    g: &mut PlaneGrid<Kind>,
    model: &mut Model,
    next_id: &mut u64,
    op: &Op,
) -> Result<(), TestCaseError> {
    match op {
        Op::Insert(p, k) => {
            g.insert(*next_id, *p, *k)?;
            model.insert(*next_id, (*p, *k));
            *next_id += 1;
        }
        Op::Remove(i) => match pick(model, i) {
            Some((id, p, k)) => {
                prop_assert_eq!(g.remove(id), Ok((p, k)));
                model.remove(&id);
            }
            None => prop_assert_eq!(g.remove(*next_id), Err(PlaneError::UnknownId(*next_id))),
        },
        Op::Move(i, to) => {
            if let Some((id, p, k)) = pick(model, i) {
                prop_assert_eq!(g.move_to(id, *to), Ok(p));
                model.insert(id, (*to, k));
            }
        }
        Op::Step(i, dx, dy) => {
            if let Some((id, p, k)) = pick(model, i) {
                if let (Some(x), Some(y)) = (p[0].checked_add(*dx), p[1].checked_add(*dy)) {
                    prop_assert_eq!(g.move_to(id, [x, y]), Ok(p));
                    model.insert(id, ([x, y], k));
                }
            }
        }
        Op::RemoveUnknown(off) => {
            let id = *next_id + off;
            prop_assert_eq!(g.remove(id), Err(PlaneError::UnknownId(id)));
            prop_assert_eq!(g.move_to(id, [0, 0]), Err(PlaneError::UnknownId(id)));
        }
        Op::InsertDuplicate(i, p) => {
            if let Some((id, _, _)) = pick(model, i) {
                prop_assert_eq!(g.insert(id, *p, 0), Err(PlaneError::DuplicateId(id)));
            }
        }
    }
    Ok(())
}

/// Every query of the grid against the brute-force reference at one query.
fn check_query(
    g: &PlaneGrid<Kind>,
    model: &Model,
    p: Pos,
    r2: u64,
    exclude: Option<u64>,
    cap: usize,
) -> Result<(), TestCaseError> {
    let size = g.box_size();
    for kind in [Some(0u8), Some(1u8), None] {
        let want = brute(model, p, kind, r2, exclude);
        let nearest = match kind {
            Some(k) => g.nearest(p, k, r2, exclude),
            None => g.nearest_any(p, r2, exclude),
        };
        prop_assert_eq!(
            nearest,
            want.first().copied(),
            "nearest {:?} p={:?} kind={:?} r2={} excl={:?}",
            size,
            p,
            kind,
            r2,
            exclude
        );
        prop_assert_eq!(
            g.count_within_capped(p, kind, r2, exclude, usize::MAX),
            want.len(),
            "count {:?} p={:?} kind={:?} r2={}",
            size,
            p,
            kind,
            r2
        );
        prop_assert_eq!(
            g.count_within_capped(p, kind, r2, exclude, cap),
            want.len().min(cap),
            "capped count {:?} cap={}",
            size,
            cap
        );
        prop_assert_eq!(
            g.at_least(p, kind, r2, exclude, cap),
            want.len() >= cap,
            "at_least {:?} n={}",
            size,
            cap
        );
        prop_assert_eq!(&g.within(p, kind, r2, exclude), &want, "within {:?}", size);
        match kind {
            Some(k) => {
                prop_assert_eq!(
                    g.any_within(p, k, r2, exclude),
                    nearest.is_some(),
                    "any_within {:?} p={:?} r2={}",
                    size,
                    p,
                    r2
                );
                prop_assert_eq!(
                    g.count_within_kind(p, k, r2, exclude),
                    g.count_within_capped(p, kind, r2, exclude, usize::MAX)
                );
            }
            None => {
                prop_assert_eq!(g.count_within(p, r2, exclude), want.len());
            }
        }
    }
    Ok(())
}

/// Structure and bookkeeping agree with the model.
fn check_structure(g: &PlaneGrid<Kind>, model: &Model) -> Result<(), TestCaseError> {
    if let Err(e) = g.validate() {
        return Err(TestCaseError::fail(e));
    }
    prop_assert_eq!(g.len(), model.len());
    for (&id, &(p, k)) in model {
        prop_assert_eq!(g.get(id), Some((p, k)));
        prop_assert!(g.is_occupied(p));
    }
    let mut listed: Vec<(u64, Pos, Kind)> = g.iter().collect();
    listed.sort_unstable_by_key(|x| x.0);
    let want: Vec<(u64, Pos, Kind)> = model.iter().map(|(&id, &(p, k))| (id, p, k)).collect();
    prop_assert_eq!(listed, want);
    Ok(())
}

proptest! {
    #![proptest_config(config(3000))]

    /// After random inserts, removals and moves, every query equals brute force, for box
    /// sides 1, 2, 3, 7, 60, random sides and the exhaustive mode.
    #[test]
    fn random_ops_match_brute_force(
        size in box_size(),
        initial in prop::collection::vec((pos(), kind()), 0..120),
        ops in prop::collection::vec(op(), 0..60),
        queries in prop::collection::vec(query(), 1..16),
    ) {
        let mut g = PlaneGrid::new(size)?;
        let mut model = Model::new();
        let mut next_id = 0u64;
        for (p, k) in &initial {
            apply(&mut g, &mut model, &mut next_id, &Op::Insert(*p, *k))?;
        }
        for op in &ops {
            apply(&mut g, &mut model, &mut next_id, op)?;
        }
        check_structure(&g, &model)?;
        for q in &queries {
            let (p, r2, exclude, cap) = resolve(&model, q);
            check_query(&g, &model, p, r2, exclude, cap)?;
        }
    }

    /// A crowded patch with many equal distances and shared cells: ties must go to the lower
    /// id, radii exactly equal to a distance must count, r2 = 0 and r2 = 2 must be exact.
    #[test]
    fn dense_ties_match_brute_force(
        size in box_size(),
        items in prop::collection::vec(((-6i64..=6, -6i64..=6), kind()), 1..150),
        removals in prop::collection::vec(any::<Index>(), 0..20),
        queries in prop::collection::vec(((-9i64..=9, -9i64..=9), 0u64..=80, any::<Option<Index>>(), 0usize..10), 1..16),
    ) {
        let mut g = PlaneGrid::new(size)?;
        let mut model = Model::new();
        // Ids in a scrambled order, so insertion order differs from id order.
        for (i, ((x, y), k)) in items.iter().enumerate() {
            let id = (i as u64 * 7919) % 100_003;
            if model.contains_key(&id) {
                continue;
            }
            g.insert(id, [*x, *y], *k)?;
            model.insert(id, ([*x, *y], *k));
        }
        for i in &removals {
            if let Some((id, _, _)) = pick(&model, i) {
                g.remove(id)?;
                model.remove(&id);
            }
        }
        check_structure(&g, &model)?;
        for ((x, y), r2, ex, cap) in &queries {
            let exclude = ex.as_ref().and_then(|i| pick(&model, i)).map(|x| x.0);
            for r in [*r2, 0, 2] {
                check_query(&g, &model, [*x, *y], r, exclude, *cap)?;
            }
        }
    }

    /// Items walking by unit steps across box boundaries (also into negative boxes) keep the
    /// boxes, back-indices and cell counts consistent, and queries stay exact.
    #[test]
    fn moves_across_boundaries_keep_structure_consistent(
        side in 1i64..=8,
        start in prop::collection::vec(((-10i64..=10, -10i64..=10), kind()), 1..20),
        steps in prop::collection::vec((any::<Index>(), -1i64..=1, -1i64..=1), 0..200),
    ) {
        let mut g = PlaneGrid::with_side(side)?;
        let mut model = Model::new();
        for (id, ((x, y), k)) in start.iter().enumerate() {
            g.insert(id as u64, [*x, *y], *k)?;
            model.insert(id as u64, ([*x, *y], *k));
        }
        let mut next_id = model.len() as u64;
        for (i, dx, dy) in &steps {
            apply(&mut g, &mut model, &mut next_id, &Op::Step(*i, *dx, *dy))?;
            if let Err(e) = g.validate() {
                return Err(TestCaseError::fail(e));
            }
        }
        check_structure(&g, &model)?;
        for (&id, &(p, _)) in &model {
            let mut at: Vec<u64> = model.iter().filter(|e| e.1.0 == p).map(|e| *e.0).collect();
            at.sort_unstable();
            let got: Vec<u64> = g.items_at(p).into_iter().map(|x| x.0).collect();
            prop_assert_eq!(got, at);
            prop_assert_eq!(g.occupancy(p), g.items_at(p).len());
            check_query(&g, &model, p, 2, Some(id), 9)?;
        }
        prop_assert!(!g.is_occupied([1000, 1000]));
    }

    /// The same items in grids of different box sizes (and after `rebox`) give identical
    /// answers; a count with boxes never evaluates more distances or scans more items than the
    /// exhaustive scan.
    #[test]
    fn all_box_sizes_agree(
        items in prop::collection::vec(((-200i64..=200, -200i64..=200), kind()), 0..200),
        other in 1i64..=300,
        queries in prop::collection::vec(((-260i64..=260, -260i64..=260), select(vec![0u64, 2, 100, 3600, 14400, 90_000])), 1..12),
    ) {
        let sizes: Vec<BoxSize> = BOX_SIZES.into_iter().chain([BoxSize::Side(other)]).collect();
        let mut grids: Vec<PlaneGrid<Kind>> = Vec::new();
        for &s in &sizes {
            let mut g = PlaneGrid::new(s)?;
            for (id, ((x, y), k)) in items.iter().enumerate() {
                g.insert(id as u64, [*x, *y], *k)?;
            }
            grids.push(g);
        }
        let mut reboxed = grids[0].clone();
        reboxed.rebox(BoxSize::Side(other))?;
        if let Err(e) = reboxed.validate() {
            return Err(TestCaseError::fail(e));
        }
        grids.push(reboxed);
        for ((x, y), r2) in &queries {
            let p = [*x, *y];
            let want: Vec<_> = (0u8..2).map(|k| grids[0].nearest(p, k, *r2, Some(0))).collect();
            let want_all = grids[0].within(p, None, *r2, None);
            grids[0].reset_stats();
            let want_count = grids[0].count_within(p, *r2, None);
            let exhaustive = grids[0].take_stats();
            prop_assert_eq!(exhaustive.items_scanned, items.len() as u64);
            for g in &grids[1..] {
                let got: Vec<_> = (0u8..2).map(|k| g.nearest(p, k, *r2, Some(0))).collect();
                prop_assert_eq!(&got, &want, "{:?}", g.box_size());
                prop_assert_eq!(g.within(p, None, *r2, None), want_all.clone());
                g.reset_stats();
                prop_assert_eq!(g.count_within(p, *r2, None), want_count);
                let work = g.take_stats();
                prop_assert!(work.distance_evals <= exhaustive.distance_evals);
                prop_assert!(work.items_scanned <= exhaustive.items_scanned);
            }
        }
    }
}

proptest! {
    #![proptest_config(config(2000))]

    /// Non-positive box sides are typed errors, never panics, from every entry point.
    #[test]
    fn bad_box_sides_are_errors(a in prop_oneof![Just(i64::MIN), Just(0i64), i64::MIN..=0]) {
        prop_assert_eq!(PlaneGrid::<Kind>::with_side(a).err(), Some(PlaneError::BadBoxSide(a)));
        prop_assert_eq!(
            PlaneGrid::<Kind>::new(BoxSize::Side(a)).err(),
            Some(PlaneError::BadBoxSide(a))
        );
        prop_assert_eq!(a.to_string().parse::<BoxSize>(), Err(PlaneError::BadBoxSide(a)));
        let mut g = PlaneGrid::<Kind>::with_side(5)?;
        g.insert(1, [a, a], 0)?;
        prop_assert_eq!(g.rebox(BoxSize::Side(a)), Err(PlaneError::BadBoxSide(a)));
        prop_assert_eq!(g.box_size(), BoxSize::Side(5));
        prop_assert_eq!(g.get(1), Some(([a, a], 0)));
    }

    /// Positive sides are accepted and round-trip through the `--grid-box` syntax.
    #[test]
    fn good_box_sides_round_trip(a in 1i64..=i64::MAX) {
        prop_assert!(PlaneGrid::<Kind>::with_side(a).is_ok());
        prop_assert_eq!(BoxSize::Side(a).to_string().parse::<BoxSize>(), Ok(BoxSize::Side(a)));
    }
}
