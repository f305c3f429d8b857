//! Property tests: the three lattice contact searches (all-pairs, grid boxes, occupancy) against
//! a brute-force reference, over random lattices (d = 1..5, periodic and walled, sides that are
//! and are not multiples of the box side), random items (including items larger than a box),
//! and random sequences of moves, merges, removals, insertions and box-side changes.

use core_lattice::{Boundary, Direction, Lattice};
use proptest::prelude::*;
use spatial::lattice::{AllPairs, ContactSearch, ItemId, LatticeGridBoxes, Occupancy, SiteSets};
use std::collections::BTreeSet;

#[derive(Debug, Clone)]
enum Op {
    Move { item: usize, dir: usize },
    Merge { a: usize, b: usize },
    Remove { item: usize },
    Insert { sites: Vec<usize> },
    Resize { log_side: u32 },
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        6 => (any::<usize>(), 0usize..10).prop_map(|(item, dir)| Op::Move { item, dir }),
        2 => (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Op::Merge { a, b }),
        1 => any::<usize>().prop_map(|item| Op::Remove { item }),
        1 => prop::collection::vec(any::<usize>(), 1..4).prop_map(|sites| Op::Insert { sites }),
        1 => (0u32..4).prop_map(|log_side| Op::Resize { log_side }),
    ]
}

#[derive(Debug, Clone)]
struct Case {
    lattice: Lattice,
    items: Vec<Vec<usize>>,
    log_side: u32,
    ops: Vec<Op>,
}

fn case() -> impl Strategy<Value = Case> {
    (1usize..=5)
        .prop_flat_map(|d| {
            let max_side = [0, 40, 14, 8, 5, 4][d];
            (
                prop::collection::vec(1u64..=max_side, d),
                prop::collection::vec(
                    prop_oneof![3 => Just(Boundary::Periodic), 2 => Just(Boundary::Wall)],
                    d,
                ),
                prop::collection::vec(prop::collection::vec(any::<usize>(), 1..6), 1..14),
                0u32..4,
                prop::collection::vec(op(), 0..25),
            )
        })
        .prop_map(|(sizes, boundaries, items, log_side, ops)| Case {
            lattice: Lattice::new(&sizes, &boundaries).unwrap(),
            items,
            log_side,
            ops,
        })
}

/// Brute force: every live item other than `id` with a site face-adjacent to a site of `id`,
/// using `Lattice::adjacent` (independent of the search code).
fn brute_contacts(sets: &SiteSets, id: ItemId) -> Vec<ItemId> {
    let l = sets.lattice();
    let mut out: Vec<ItemId> = sets
        .live()
        .iter()
        .copied()
        .filter(|&o| o != id)
        .filter(|&o| {
            sets.sites(id)
                .iter()
                .any(|&a| sets.sites(o).iter().any(|&b| l.adjacent(a, b)))
        })
        .collect();
    out.sort_unstable();
    out
}

struct World {
    sets: SiteSets,
    occupied: BTreeSet<u64>,
    all_pairs: AllPairs,
    grid: LatticeGridBoxes,
    occupancy: Occupancy,
    /// An occupancy lattice with the leading-face shortcut, queried only for a mover that
    /// touched nothing before its move (the promise it relies on).
    separated: Occupancy,
}

impl World {
    /// Apply `f` to each strategy, with the sets.
    fn each(&mut self, mut f: impl FnMut(&mut dyn ContactSearch, &SiteSets)) {
        let World {
            sets,
            all_pairs,
            grid,
            occupancy,
            separated,
            ..
        } = self;
        for s in [
            all_pairs as &mut dyn ContactSearch,
            grid,
            occupancy,
            separated,
        ] {
            f(s, sets);
        }
    }

    /// Add an item made of the free sites picked by `picks`, if any is free.
    fn insert(&mut self, picks: &[usize]) {
        let volume = self.sets.lattice().volume();
        let mut sites = Vec::new();
        for &p in picks {
            let k = (p as u64) % volume;
            if !self.occupied.contains(&k) && !sites.contains(&k) {
                sites.push(k);
            }
        }
        if sites.is_empty() {
            return;
        }
        self.occupied.extend(&sites);
        let id = self.sets.push(sites);
        self.each(|s, sets| s.insert(sets, id));
    }

    fn check(&mut self) -> Result<(), TestCaseError> {
        let live: Vec<ItemId> = self.sets.live().to_vec();
        for &id in &live {
            let expected = brute_contacts(&self.sets, id);
            // The halo holds every item in contact.
            let halo: BTreeSet<ItemId> = self.grid.halo_candidates(id).iter().copied().collect();
            prop_assert_eq!(
                halo.len(),
                self.grid.halo_candidates(id).len(),
                "halo repeats an item"
            );
            for c in &expected {
                prop_assert!(
                    halo.contains(c),
                    "item {} touches {} but is not in its halo",
                    c,
                    id
                );
            }
            // The grid registers each item in exactly the boxes of its sites.
            let mut boxes: Vec<u32> = self.grid.boxes_of(id).to_vec();
            boxes.sort_unstable();
            let mut want: Vec<u32> = self
                .sets
                .sites(id)
                .iter()
                .map(|&k| self.grid.box_of(k))
                .collect();
            want.sort_unstable();
            want.dedup();
            prop_assert_eq!(boxes, want);
            for &k in self.sets.sites(id) {
                prop_assert_eq!(self.occupancy.item_at(k), Some(id));
            }
            let sets = &self.sets;
            let mut out = Vec::new();
            let n_live = live.len();
            for s in [
                &mut self.all_pairs as &mut dyn ContactSearch,
                &mut self.grid,
                &mut self.occupancy,
            ] {
                let examined = s.contacts(sets, id, &mut out);
                prop_assert_eq!(&out, &expected, "strategy {}", s.name());
                prop_assert!(examined >= out.len());
                if s.name() == "all-pairs" {
                    prop_assert_eq!(examined, n_live - 1);
                }
            }
        }
        Ok(())
    }
}

fn run(case: Case) -> Result<(), TestCaseError> {
    let lattice = case.lattice.clone();
    let mut w = World {
        sets: SiteSets::new(lattice.clone()),
        occupied: BTreeSet::new(),
        all_pairs: AllPairs::new(),
        grid: LatticeGridBoxes::new(&lattice, 1 << case.log_side).unwrap(),
        occupancy: Occupancy::new(&lattice, 1 << 30).unwrap(),
        separated: Occupancy::new(&lattice, 1 << 30)
            .unwrap()
            .with_separated_items(true),
    };
    for picks in &case.items {
        w.insert(picks);
    }
    w.check()?;
    let mut old = Vec::new();
    for op in &case.ops {
        let live: Vec<ItemId> = w.sets.live().to_vec();
        if live.is_empty() {
            break;
        }
        match op {
            Op::Move { item, dir } => {
                let id = live[item % live.len()];
                let dir = Direction::from_index(dir % (2 * lattice.dim()));
                // Moves may not overlap another item (in DLCA items merge before that).
                let target: Option<Vec<u64>> = w
                    .sets
                    .sites(id)
                    .iter()
                    .map(|&k| lattice.translate(k, dir).ok())
                    .collect();
                let Some(target) = target else {
                    let before = w.sets.sites(id).to_vec();
                    prop_assert!(w.sets.translate(id, dir, &mut old).is_err());
                    prop_assert_eq!(w.sets.sites(id), &before[..]);
                    continue;
                };
                let mine: BTreeSet<u64> = w.sets.sites(id).iter().copied().collect();
                if target
                    .iter()
                    .any(|k| w.occupied.contains(k) && !mine.contains(k))
                {
                    continue;
                }
                let was_separate = brute_contacts(&w.sets, id).is_empty();
                w.sets.translate(id, dir, &mut old).unwrap();
                prop_assert_eq!(w.sets.sites(id), &target[..]);
                for k in &old {
                    w.occupied.remove(k);
                }
                w.occupied.extend(&target);
                w.each(|s, sets| s.moved(sets, id, &old, &target, dir));
                if was_separate {
                    let mut out = Vec::new();
                    w.separated.contacts(&w.sets, id, &mut out);
                    prop_assert_eq!(out, brute_contacts(&w.sets, id), "leading-face shortcut");
                }
            }
            Op::Merge { a, b } => {
                let (a, b) = (live[a % live.len()], live[b % live.len()]);
                if a == b {
                    continue;
                }
                let (into, from) = (a.min(b), a.max(b));
                let before_into = w.sets.sites(into).to_vec();
                let before_from = w.sets.sites(from).to_vec();
                let from_len = w.sets.merge(into, from);
                prop_assert_eq!(from_len, before_from.len());
                let (pi, pf) = w.sets.merged_parts(into, from_len);
                prop_assert_eq!(pi, &before_into[..]);
                prop_assert_eq!(pf, &before_from[..]);
                w.each(|s, sets| s.merge(sets, into, from, from_len));
                prop_assert!(!w.sets.contains(from));
            }
            Op::Remove { item } => {
                let id = live[item % live.len()];
                w.each(|s, sets| s.remove(sets, id));
                for k in w.sets.remove(id) {
                    w.occupied.remove(&k);
                }
            }
            Op::Insert { sites } => w.insert(sites),
            Op::Resize { log_side } => {
                w.grid.set_side(1 << log_side, &w.sets).unwrap();
                prop_assert_eq!(w.grid.side(), 1 << log_side);
            }
        }
        w.check()?;
        let total: usize = w.sets.live().iter().map(|&id| w.sets.sites(id).len()).sum();
        prop_assert_eq!(total as u64, w.sets.total_sites());
        prop_assert_eq!(total, w.occupied.len());
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn strategies_agree_with_brute_force(c in case()) {
        run(c)?;
    }
}

#[test]
fn grid_reports_when_it_stops_paying() {
    let l = Lattice::periodic(&[1024, 512]).unwrap();
    assert!(!LatticeGridBoxes::new(&l, 128).unwrap().stops_paying());
    assert!(LatticeGridBoxes::new(&l, 256).unwrap().stops_paying()); // 3 * 256 >= 512
    assert!(LatticeGridBoxes::new(&l, 6).is_err());
    assert!(LatticeGridBoxes::new(&l, 0).is_err());
}

#[test]
fn occupancy_respects_its_memory_budget() {
    let l = Lattice::periodic(&[1 << 20, 1 << 20]).unwrap();
    assert_eq!(Occupancy::bytes_needed(&l), 4 << 40);
    assert!(Occupancy::new(&l, 1 << 30).is_err());
}
