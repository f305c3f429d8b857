//! Property tests of [`spatial::lattice::HaloGrid`] (DLCA's default `grid` search) against a
//! brute-force reference: over random lattices (d = 1..5, periodic and walled axes, sides that
//! are and are not multiples of the box side, axes of side 1 and 2), random clusters (scattered
//! sites, so bounding regions wrap and overlap) and random sequences of moves, each followed by
//! the merge DLCA makes, every move must be blocked exactly when a site would cross a wall and
//! report exactly the clusters face-adjacent to the mover, in increasing id; sizes, live ids
//! and the clusters' sites must follow the model, whatever the box side (requested or tuned).

mod common;
use common::config;

use core_lattice::{Direction, Lattice};
use proptest::prelude::*;
use spatial::lattice::{HaloGrid, ItemId, SiteSets};
use std::collections::BTreeSet;

#[derive(Debug, Clone)]
struct Case {
    lattice: Lattice,
    items: Vec<Vec<usize>>,
    side: Option<u64>,
    moves: Vec<(usize, usize)>,
}

fn case() -> impl Strategy<Value = Case> {
    (1usize..=5)
        .prop_flat_map(|d| {
            let max_side = [0, 40, 14, 8, 5, 4][d];
            (
                prop::collection::vec(1u64..=max_side, d),
                prop::collection::vec(any::<bool>(), d),
                prop::collection::vec(prop::collection::vec(any::<usize>(), 1..6), 1..16),
                prop_oneof![1 => Just(None), 2 => (0u32..4).prop_map(|s| Some(1u64 << s))],
                prop::collection::vec((any::<usize>(), 0usize..10), 0..60),
            )
        })
        .prop_map(|(sizes, walls, items, side, moves)| {
            let boundaries: Vec<_> = walls
                .iter()
                .map(|&w| {
                    if w {
                        core_lattice::Boundary::Wall
                    } else {
                        core_lattice::Boundary::Periodic
                    }
                })
                .collect();
            Case {
                lattice: Lattice::new(&sizes, &boundaries).unwrap(),
                items,
                side,
                moves,
            }
        })
}

/// Whether a site of `a` is face-adjacent to a site of `b`.
fn touching(l: &Lattice, a: &BTreeSet<u64>, b: &BTreeSet<u64>) -> bool {
    a.iter()
        .any(|&x| l.neighbours(x).any(|n| n != x && b.contains(&n)))
}

proptest! {
    #![proptest_config(config(400))]

    #[test]
    fn halo_grid_matches_brute_force(case in case()) {
        let l = &case.lattice;
        // Clusters: each item's sites, dropped where they would overlap or touch an earlier
        // cluster (clusters never touch between moves).
        let mut model: Vec<Option<BTreeSet<u64>>> = Vec::new();
        for item in &case.items {
            let sites: BTreeSet<u64> = item.iter().map(|&s| s as u64 % l.volume()).collect();
            let clear = model.iter().flatten().all(|other| {
                sites.is_disjoint(other) && !touching(l, &sites, other)
            });
            if clear {
                model.push(Some(sites));
            }
        }
        let mut sets = SiteSets::new(l.clone());
        for c in model.iter().flatten() {
            sets.push(c.iter().copied().collect());
        }
        let mut grid = HaloGrid::new(&sets, case.side);
        if let Some(side) = case.side {
            prop_assert_eq!(grid.side(), side);
        }
        grid.check();
        let dirs: Vec<Direction> = Direction::all(l.dim()).collect();
        let mut contacts = Vec::new();
        for &(pick, d) in &case.moves {
            let live: Vec<ItemId> = (0..model.len() as ItemId)
                .filter(|&i| model[i as usize].is_some())
                .collect();
            let id = live[pick % live.len()];
            let dir = dirs[d % dirs.len()];
            let moved: Result<BTreeSet<u64>, _> = model[id as usize]
                .as_ref()
                .unwrap()
                .iter()
                .map(|&k| l.translate(k, dir))
                .collect();
            let got = grid.try_move(id, dir, &mut contacts);
            let Ok(moved) = moved else {
                prop_assert!(got.is_err(), "move of {} by {:?} not blocked", id, dir);
                continue;
            };
            prop_assert!(got.is_ok(), "move of {} by {:?} blocked", id, dir);
            let want: Vec<ItemId> = live
                .iter()
                .copied()
                .filter(|&o| o != id && touching(l, &moved, model[o as usize].as_ref().unwrap()))
                .collect();
            prop_assert_eq!(&contacts, &want, "contacts of {} after {:?}", id, dir);
            model[id as usize] = Some(moved);
            if !want.is_empty() {
                // DLCA's merge: the lowest id survives.
                let mut all = want.clone();
                all.push(id);
                all.sort_unstable();
                let (survivor, others) = (all[0], &all[1..]);
                let mut union = BTreeSet::new();
                for &c in &all {
                    union.extend(model[c as usize].take().unwrap());
                }
                let size = union.len();
                model[survivor as usize] = Some(union);
                let (got_size, _) = grid.merge(survivor, others);
                prop_assert_eq!(got_size, size);
                grid.check();
            }
            for (i, c) in model.iter().enumerate() {
                prop_assert_eq!(grid.contains(i as ItemId), c.is_some());
                if let Some(c) = c {
                    prop_assert_eq!(grid.len_of(i as ItemId), c.len());
                }
            }
        }
        let mut live: Vec<ItemId> = grid.live().to_vec();
        live.sort_unstable();
        let want_live: Vec<ItemId> = (0..model.len() as ItemId)
            .filter(|&i| model[i as usize].is_some())
            .collect();
        prop_assert_eq!(live, want_live);
        let out = grid.to_sets();
        for (i, c) in model.iter().enumerate() {
            if let Some(c) = c {
                let have: BTreeSet<u64> = out.sites(i as ItemId).iter().copied().collect();
                prop_assert_eq!(&have, c);
            }
        }
    }
}
