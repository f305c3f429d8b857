//! Hand-built scenes for the world: each rule's condition and action, thresholds, ties,
//! laziness of perception, and that the cell-index and grid-box paths agree.

use super::rules::Action;
use super::*;
use crate::params::GridBox;
use Species::{Fox, Rabbit};

/// Parameters for hand-built scenes: breeding always succeeds, nobody dies of age or
/// hunger within a step.
fn scene_params() -> Params {
    Params {
        foxes: 0,
        rabbits: 0,
        fox_breed_p: 1.0,
        rabbit_breed_p: 1.0,
        hungry_at: 5,
        starve: 100,
        fox_max_age: 1000,
        rabbit_max_age: 1000,
        prey_needed: 2,
        crowd_max: 3,
        crowd_radius: 2,
        ..Params::default()
    }
}

fn world(p: Params) -> World {
    World::empty(p, 1).unwrap()
}

/// Checks that the cell index (and the grid, when kept) hold exactly the live animats, each
/// on its cell, and that the id lists are in order.
fn check_consistent(w: &World) {
    let live: Vec<Animat> = w.animats().collect();
    assert!(w.ids.windows(2).all(|p| p[0] < p[1]));
    assert_eq!(w.ids.len(), live.len());
    assert_eq!(w.cells.len(), live.len());
    for a in &live {
        assert_eq!(w.cells.kind(a.pos), kind_byte(a.species == Rabbit));
        assert_eq!(w.cells.id(a.pos), a.id);
    }
    match w.grid() {
        Some(g) => {
            g.validate().unwrap();
            assert_eq!(g.len(), live.len());
            for a in &live {
                assert_eq!(g.get(a.id), Some((a.pos, a.species)));
            }
        }
        None => assert!(w.cell_search()),
    }
}

fn only(rules_f: &[&str], rules_r: &[&str]) -> Params {
    Params {
        fox_rules: rules_f.iter().map(|s| s.to_string()).collect(),
        rabbit_rules: rules_r.iter().map(|s| s.to_string()).collect(),
        ..scene_params()
    }
}

#[test]
fn flee_steps_directly_away_from_the_nearest_adjacent_fox() {
    let mut w = world(only(&[], &["flee"]));
    let r = w.add(Rabbit, [0, 0], 0, 0).unwrap();
    w.add(Fox, [1, 1], 0, 0).unwrap();
    w.step();
    assert_eq!(w.get(r).unwrap().pos, [-1, -1]);
    // Orthogonal fox (d2 = 1) is nearer than a diagonal one (d2 = 2).
    let mut w = world(only(&[], &["flee"]));
    let r = w.add(Rabbit, [0, 0], 0, 0).unwrap();
    w.add(Fox, [1, 1], 0, 0).unwrap();
    w.add(Fox, [0, -1], 0, 0).unwrap();
    w.step();
    assert_eq!(w.get(r).unwrap().pos, [0, 1]);
}

#[test]
fn eat_removes_the_rabbit_and_resets_hunger() {
    let mut w = world(only(&["eat"], &[]));
    let f = w.add(Fox, [0, 0], 0, 7).unwrap();
    let r = w.add(Rabbit, [1, 0], 0, 0).unwrap();
    w.step();
    assert!(w.get(r).is_none());
    assert_eq!(w.rabbits(), 0);
    // Hunger reset to 0 by eating, then +1 at the end of the turn.
    assert_eq!(w.get(f).unwrap().hunger, 1);
    assert!(!w.cells.occupied([1, 0]));
    check_consistent(&w);
    // A fox that is not hungry does not eat.
    let mut w = world(only(&["eat"], &[]));
    w.add(Fox, [0, 0], 0, 4).unwrap();
    let r = w.add(Rabbit, [1, 0], 0, 0).unwrap();
    w.step();
    assert!(w.get(r).is_some());
}

#[test]
fn an_eaten_rabbit_does_not_act() {
    // The rabbit acts only if its turn comes before the fox's: with flee it steps away to
    // [2, 0] and the fox, its prey gone, stays. When the fox goes first the rabbit is eaten
    // and must not take its turn: had it fled, [2, 0] would be occupied. Over several seeds
    // both orders occur.
    let (mut fled, mut eaten) = (0, 0);
    for seed in 0..20 {
        let mut w = World::empty(only(&["eat"], &["flee"]), seed).unwrap();
        let f = w.add(Fox, [0, 0], 0, 7).unwrap();
        let r = w.add(Rabbit, [1, 0], 0, 0).unwrap();
        w.step();
        assert_eq!(w.get(f).unwrap().pos, [0, 0]);
        match w.get(r) {
            Some(a) => {
                assert_eq!(a.pos, [2, 0]);
                fled += 1;
            }
            None => {
                assert_eq!(w.rabbits(), 0);
                assert_eq!(w.animats().count(), 1);
                for c in [[1, 0], [2, 0]] {
                    assert!(!w.cells.occupied(c), "seed {seed}: {c:?} occupied");
                }
                eaten += 1;
            }
        }
        check_consistent(&w);
    }
    assert!(fled > 0 && eaten > 0, "fled {fled}, eaten {eaten}");
}

#[test]
fn fox_breeding_needs_prey_and_room() {
    // Two foxes side by side, not hungry, two rabbits within vision: breeds.
    let scene = |rabbits: &[Pos], crowd: &[Pos]| {
        let mut w = world(only(&["breed"], &[]));
        let f = w.add(Fox, [0, 0], 0, 0).unwrap();
        w.add(Fox, [10, 10], 0, 0).unwrap(); // far fox: no partner
        for &p in rabbits {
            w.add(Rabbit, p, 0, 0).unwrap();
        }
        for &p in crowd {
            w.add(Rabbit, p, 0, 0).unwrap();
        }
        (w, f)
    };
    // No adjacent fox: no breeding.
    let (mut w, _) = scene(&[[30, 0], [0, 30]], &[]);
    w.step();
    assert_eq!(w.foxes(), 2);
    // Adjacent partner, enough prey.
    let (mut w, _) = scene(&[[30, 0], [0, 30]], &[]);
    w.add(Fox, [1, 0], 0, 0).unwrap();
    w.step();
    assert!(w.foxes() > 3, "breeding refused with prey and room");
    // Prey short: only one rabbit within vision (prey_needed = 2).
    let (mut w, _) = scene(&[[30, 0], [100, 100]], &[]);
    w.add(Fox, [1, 0], 0, 0).unwrap();
    w.step();
    assert_eq!(w.foxes(), 3, "breeding allowed with prey short");
    // Overcrowded for both foxes: within radius 2 of [0, 0] the partner and 4 rabbits
    // (5 > crowd_max 3); of [1, 0] the fox and 3 rabbits (4 > 3).
    let (mut w, _) = scene(&[[30, 0], [0, 30]], &[[-1, 0], [0, -1], [-1, -1], [1, -1]]);
    w.add(Fox, [1, 0], 0, 0).unwrap();
    w.step();
    assert_eq!(w.foxes(), 3, "breeding allowed when overcrowded");
}

#[test]
fn rabbit_breeding_refused_when_overcrowded() {
    let mut w = world(only(&[], &["breed"]));
    w.add(Rabbit, [0, 0], 0, 0).unwrap();
    w.add(Rabbit, [1, 0], 0, 0).unwrap();
    w.step();
    assert!(w.rabbits() >= 3);
    let mut w = world(only(&[], &["breed"]));
    // A dense 3x3 block: every rabbit has more than 3 others within radius 2.
    for x in 0..3 {
        for y in 0..3 {
            w.add(Rabbit, [x, y], 0, 0).unwrap();
        }
    }
    w.step();
    assert_eq!(w.rabbits(), 9);
}

#[test]
fn crowding_and_prey_thresholds_are_exact() {
    // crowd_max = 3, crowd_radius = 2: exactly 3 others within radius 2 (one exactly at
    // distance 2) is not overcrowded, 4 is; [2, 1] at d2 = 5 never counts.
    let mut w = world(scene_params());
    let me = w.add(Rabbit, [0, 0], 0, 0).unwrap();
    w.add(Fox, [2, 0], 0, 0).unwrap();
    w.add(Rabbit, [1, 1], 0, 0).unwrap();
    w.add(Rabbit, [2, 1], 0, 0).unwrap();
    w.add(Rabbit, [0, -2], 0, 0).unwrap();
    let a = w.get(me).unwrap();
    assert!(!w.overcrowded(&a));
    w.add(Fox, [-1, 0], 0, 0).unwrap();
    assert!(w.overcrowded(&a));
    // prey_needed = 2: rabbits within vision 60, the one at [60, 0] exactly on the edge.
    let mut w = world(scene_params());
    let f = w.add(Fox, [0, 0], 0, 0).unwrap();
    w.add(Rabbit, [60, 0], 0, 0).unwrap();
    w.add(Rabbit, [43, 43], 0, 0).unwrap(); // d2 = 3698 > 3600: unseen
    let a = w.get(f).unwrap();
    assert!(!w.enough_prey(&a));
    w.add(Rabbit, [0, -60], 0, 0).unwrap();
    assert!(w.enough_prey(&a));
}

#[test]
fn newborns_act_next_step_and_ids_increase() {
    let mut w = world(only(&[], &["breed"]));
    w.add(Rabbit, [0, 0], 0, 0).unwrap();
    w.add(Rabbit, [1, 0], 0, 0).unwrap();
    w.step();
    let ages: Vec<(u64, u32)> = w.animats().map(|a| (a.id, a.age)).collect();
    assert!(ages.len() > 2, "no rabbit was born");
    assert!(ages.windows(2).all(|p| p[0].0 < p[1].0), "{ages:?}");
    assert_eq!(&ages[..2], &[(0, 1), (1, 1)]);
    for &(id, age) in &ages[2..] {
        assert!(id >= 2);
        assert_eq!(age, 0, "newborn acted in its birth step");
    }
}

#[test]
fn blocked_steps_stay_put() {
    // Hunting fox whose step towards the rabbit is blocked by another rabbit.
    let mut w = world(only(&["hunt"], &[]));
    let f = w.add(Fox, [0, 0], 0, 9).unwrap();
    w.add(Rabbit, [1, 1], 0, 0).unwrap();
    w.add(Rabbit, [5, 5], 0, 0).unwrap();
    w.step();
    assert_eq!(w.get(f).unwrap().pos, [0, 0]);
    // Unblocked: it moves diagonally towards the rabbit.
    let mut w = world(only(&["hunt"], &[]));
    let f = w.add(Fox, [0, 0], 0, 9).unwrap();
    w.add(Rabbit, [5, 3], 0, 0).unwrap();
    w.step();
    assert_eq!(w.get(f).unwrap().pos, [1, 1]);
    // A fleeing rabbit with its escape cell taken stays.
    let mut w = world(only(&[], &["flee"]));
    let r = w.add(Rabbit, [0, 0], 0, 0).unwrap();
    w.add(Fox, [1, 0], 0, 0).unwrap();
    w.add(Fox, [-1, 0], 0, 0).unwrap();
    w.step();
    // Nearest adjacent fox: both at d2 = 1, lower id (the one at [1, 0]); away is [-1, 0],
    // occupied.
    assert_eq!(w.get(r).unwrap().pos, [0, 0]);
}

#[test]
fn ties_go_to_the_lower_id() {
    // Two rabbits equally near the fox, on opposite sides; the lower id wins.
    for (first, second, want) in [([3, 0], [-3, 0], [1, 0]), ([-3, 0], [3, 0], [-1, 0])] {
        let mut w = world(only(&["hunt"], &[]));
        w.add(Rabbit, first, 0, 0).unwrap();
        w.add(Rabbit, second, 0, 0).unwrap();
        let f = w.add(Fox, [0, 0], 0, 9).unwrap();
        w.step();
        assert_eq!(w.get(f).unwrap().pos, want);
    }
}

#[test]
fn seek_mate_and_herd_step_towards_the_nearest() {
    // Each fox steps one cell towards its nearest other fox, each rabbit towards its nearest
    // other rabbit (whatever the order: the targets move along the same line and no step is
    // blocked).
    let mut w = world(only(&["seek_mate"], &["herd"]));
    let f = w.add(Fox, [0, 0], 0, 0).unwrap();
    let mate = w.add(Fox, [0, 20], 0, 0).unwrap();
    let far_fox = w.add(Fox, [0, -30], 0, 0).unwrap();
    let r = w.add(Rabbit, [40, 0], 0, 0).unwrap();
    let herd = w.add(Rabbit, [40, -10], 0, 0).unwrap();
    let far_rabbit = w.add(Rabbit, [40, 25], 0, 0).unwrap();
    w.step();
    let pos = |id| w.get(id).unwrap().pos;
    // [0, 0] seeks its mate at distance 20, not the fox at distance 30; the mate and the far
    // fox seek [0, 0], their nearest.
    assert_eq!(pos(f), [0, 1]);
    assert_eq!(pos(mate), [0, 19]);
    assert_eq!(pos(far_fox), [0, -29]);
    // [40, 0] herds towards [40, -10] (10 away), not [40, 25] (25 away).
    assert_eq!(pos(r), [40, -1]);
    assert_eq!(pos(herd), [40, -9]);
    assert_eq!(pos(far_rabbit), [40, 24]);
    // Hungry foxes do not seek mates; another fox seeks a hungry one all the same.
    let mut w = world(only(&["seek_mate"], &[]));
    let f = w.add(Fox, [0, 0], 0, 9).unwrap();
    let mate = w.add(Fox, [0, 20], 0, 0).unwrap();
    w.step();
    assert_eq!(w.get(f).unwrap().pos, [0, 0]);
    assert_eq!(w.get(mate).unwrap().pos, [0, 19]);
    // Vision (60) is inclusive: a pair 60 apart herd together, a pair 61 apart (and foxes
    // 61 apart) see nothing and stay.
    let mut w = world(only(&["seek_mate"], &["herd"]));
    let seen = [
        w.add(Rabbit, [1000, 0], 0, 0).unwrap(),
        w.add(Rabbit, [1000, 60], 0, 0).unwrap(),
    ];
    let unseen = [
        w.add(Rabbit, [2000, 0], 0, 0).unwrap(),
        w.add(Rabbit, [2061, 0], 0, 0).unwrap(),
        w.add(Fox, [3000, 0], 0, 0).unwrap(),
        w.add(Fox, [3000, -61], 0, 0).unwrap(),
    ];
    let before: Vec<Pos> = unseen.iter().map(|&id| w.get(id).unwrap().pos).collect();
    w.step();
    assert_eq!(w.get(seen[0]).unwrap().pos, [1000, 1]);
    assert_eq!(w.get(seen[1]).unwrap().pos, [1000, 59]);
    let after: Vec<Pos> = unseen.iter().map(|&id| w.get(id).unwrap().pos).collect();
    assert_eq!(after, before);
}

#[test]
fn cell_search_and_grid_boxes_agree_on_hand_built_ties() {
    // Orthogonal before diagonal, then lower id, through both paths.
    for cells in [true, false] {
        let mut w = world(only(&[], &["flee"]));
        w.set_cell_search(cells);
        let r = w.add(Rabbit, [0, 0], 0, 0).unwrap();
        w.add(Fox, [1, 1], 0, 0).unwrap();
        w.add(Fox, [0, -1], 0, 0).unwrap();
        w.add(Fox, [-1, 0], 0, 0).unwrap();
        w.step();
        // [0, -1] (id 2) and [-1, 0] (id 3) both at d2 = 1: id 2 wins, flee to [0, 1].
        assert_eq!(w.get(r).unwrap().pos, [0, 1], "cells {cells}");
        // Nearest within vision: equal distance 9 + 16 = 25 on both sides, lower id wins;
        // the one at d2 = 25 on ring 5 against one at d2 = 26 on ring 5 too.
        let mut w = world(only(&["hunt"], &[]));
        w.set_cell_search(cells);
        w.add(Rabbit, [-5, 1], 0, 0).unwrap(); // d2 = 26
        w.add(Rabbit, [4, -3], 0, 0).unwrap(); // d2 = 25, id 1
        w.add(Rabbit, [-3, 4], 0, 0).unwrap(); // d2 = 25, id 2
        let f = w.add(Fox, [0, 0], 0, 9).unwrap();
        w.step();
        assert_eq!(w.get(f).unwrap().pos, [1, -1], "cells {cells}");
        // Beyond the 8 rings: a rabbit at distance 20 is found through the grid.
        let mut w = world(only(&["hunt"], &[]));
        w.set_cell_search(cells);
        w.add(Rabbit, [0, -20], 0, 0).unwrap();
        let f = w.add(Fox, [0, 0], 0, 9).unwrap();
        w.step();
        assert_eq!(w.get(f).unwrap().pos, [0, -1], "cells {cells}");
    }
}

#[test]
fn starvation_and_old_age() {
    let p = Params {
        starve: 3,
        hungry_at: 3,
        fox_max_age: 10,
        rabbit_max_age: 2,
        ..only(&[], &[])
    };
    let mut w = world(p);
    w.add(Fox, [0, 0], 0, 2).unwrap();
    w.add(Fox, [10, 0], 10, 0).unwrap();
    w.add(Rabbit, [20, 0], 1, 0).unwrap();
    w.step();
    // hunger 3 (not > 3), age 11 > 10, age 2 (not > 2).
    assert_eq!((w.foxes(), w.rabbits()), (1, 1));
    w.step();
    assert_eq!((w.foxes(), w.rabbits()), (0, 0));
}

#[test]
fn perception_is_lazy() {
    // A hungry fox with a rabbit adjacent eats after exactly one query, even with foxes
    // and rabbits all around.
    let mut w = world(scene_params());
    w.add(Fox, [0, 0], 0, 9).unwrap();
    w.add(Rabbit, [1, 0], 0, 0).unwrap();
    let q0 = w.queries();
    let a = w.get(0).unwrap();
    assert_eq!(w.decide(&a), Action::Eat([1, 0]));
    let q = w.queries();
    assert_eq!(q.total() - q0.total(), 1);
    assert_eq!(q.adjacent, 1);
    assert_eq!(a.id, 0);

    // A sated fox with no fox adjacent: breed asks one adjacency query and stops; hunt is
    // skipped without a query (not hungry); seek_mate asks one nearest query and fires.
    let mut w = world(scene_params());
    w.add(Fox, [0, 0], 0, 0).unwrap();
    w.add(Fox, [0, 10], 0, 0).unwrap();
    for x in 0..5 {
        w.add(Rabbit, [20 + x, 0], 0, 0).unwrap();
    }
    assert_eq!(w.decide(&w.get(0).unwrap()), Action::Step([0, 1]));
    assert_eq!(
        w.queries(),
        QueryCounts {
            adjacent: 1,
            nearest: 1,
            count: 0
        }
    );

    // A rabbit with a fox adjacent flees after one query.
    let mut w = world(scene_params());
    w.add(Rabbit, [0, 0], 0, 0).unwrap();
    w.add(Fox, [1, 0], 0, 0).unwrap();
    w.add(Rabbit, [-1, 0], 0, 0).unwrap();
    assert_eq!(w.decide(&w.get(0).unwrap()), Action::Step([-1, 0]));
    assert_eq!(w.queries().total(), 1);

    // Over a whole step of a real run, fewer queries than the eager "ask everything"
    // (5 per animat) would need.
    let mut w = World::new(Params::default(), 3).unwrap();
    let n = w.foxes() + w.rabbits();
    w.step();
    assert!(w.queries().total() < 5 * n);
}

#[test]
fn same_seed_same_run_and_seeds_differ() {
    let p = Params {
        foxes: 50,
        rabbits: 300,
        start_radius: 40,
        ..Params::default()
    };
    let mut a = World::new(p.clone(), 5).unwrap();
    let mut b = World::new(p.clone(), 5).unwrap();
    let mut c = World::new(p, 6).unwrap();
    a.run(50);
    b.run(50);
    c.run(50);
    assert_eq!(a.state_hash(), b.state_hash());
    assert_ne!(a.state_hash(), c.state_hash());
}

#[test]
fn start_is_on_distinct_cells_in_the_disc() {
    let p = Params {
        grid_box: GridBox::Side(7),
        ..Params::default()
    };
    let w = World::new(p.clone(), 9).unwrap();
    assert_eq!(w.foxes(), p.foxes);
    assert_eq!(w.rabbits(), p.rabbits);
    let mut cells: Vec<Pos> = w.animats().map(|a| a.pos).collect();
    let r = p.start_radius;
    assert!(cells.iter().all(|c| c[0] * c[0] + c[1] * c[1] <= r * r));
    cells.sort();
    cells.dedup();
    assert_eq!(cells.len() as u64, p.foxes + p.rabbits);
    check_consistent(&w);
}
