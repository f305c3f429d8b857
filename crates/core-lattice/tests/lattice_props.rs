//! Property tests of the k-index lattice against straightforward references.

use core_lattice::{Boundary, Direction, Lattice};
use proptest::prelude::*;

/// A random lattice of dimension 1..=8 with sides 1..=9 (small enough to enumerate) and random
/// boundaries.
fn small_lattice() -> impl Strategy<Value = Lattice> {
    (1usize..=8)
        .prop_flat_map(|d| {
            (
                prop::collection::vec(1u64..=9, d),
                prop::collection::vec(
                    prop_oneof![Just(Boundary::Periodic), Just(Boundary::Wall)],
                    d,
                ),
            )
        })
        .prop_filter_map("volume too large to sample", |(sizes, b)| {
            let l = Lattice::new(&sizes, &b).ok()?;
            Some(l)
        })
}

/// A lattice with a random site on it.
fn lattice_and_site() -> impl Strategy<Value = (Lattice, u64)> {
    small_lattice().prop_flat_map(|l| {
        let v = l.volume();
        (Just(l), 0..v)
    })
}

/// Lattices whose sides are all powers of two (the shift-and-mask fast path), up to 2^20.
fn pow2_lattice_and_site() -> impl Strategy<Value = (Lattice, u64)> {
    (1usize..=5)
        .prop_flat_map(|d| {
            (
                prop::collection::vec(0u32..=(60 / d as u32).min(20), d),
                prop::collection::vec(
                    prop_oneof![Just(Boundary::Periodic), Just(Boundary::Wall)],
                    d,
                ),
            )
        })
        .prop_flat_map(|(logs, b)| {
            let sizes: Vec<u64> = logs.iter().map(|&e| 1u64 << e).collect();
            let l = Lattice::new(&sizes, &b).unwrap();
            let v = l.volume();
            (Just(l), 0..v)
        })
}

/// Lattices with huge sides, to exercise k-index arithmetic near `u64::MAX`.
fn big_lattice() -> impl Strategy<Value = Lattice> {
    (1usize..=8)
        .prop_flat_map(|d| prop::collection::vec(1u64..=u64::MAX, d))
        .prop_filter_map("overflow", |sizes| {
            // Shrink sides until the volume fits, keeping them large.
            let mut s = sizes;
            let d = s.len() as u32;
            for x in s.iter_mut() {
                *x = (*x >> (64 - 64 / d)).max(1);
            }
            Lattice::periodic(&s).ok()
        })
}

/// Reference minimum-image component: the representative of `d mod L` closest to 0, ties
/// going to +L/2.
fn reference_image(d: i64, size: u64, boundary: Boundary) -> i64 {
    if boundary == Boundary::Wall {
        return d;
    }
    let l = size as i64;
    (-2 * l..=2 * l)
        .map(|m| d + m * l)
        .filter(|c| 2 * c.abs() <= l)
        .max()
        .unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    #[test]
    fn k_index_round_trips((l, k) in lattice_and_site()) {
        let x = l.decode(k).unwrap();
        prop_assert_eq!(x.len(), l.dim());
        for (axis, &xi) in x.iter().enumerate() {
            prop_assert!(xi < l.size(axis));
            prop_assert_eq!(l.coord(k, axis), xi);
        }
        prop_assert_eq!(l.encode(&x).unwrap(), k);
        // The paper's formula, written out: k = x1 + x2 L1 + x3 L1 L2 + ...
        let mut k_ref = 0u64;
        let mut stride = 1u64;
        for (axis, &xi) in x.iter().enumerate() {
            k_ref += xi * stride;
            stride *= l.size(axis);
        }
        prop_assert_eq!(k_ref, k);
    }

    #[test]
    fn power_of_two_fast_path_matches_decode((l, k) in pow2_lattice_and_site()) {
        let x = l.coords_array(k);
        let reference = l.decode(k).unwrap();
        prop_assert_eq!(&x[..l.dim()], &reference[..]);
        for axis in 0..l.dim() {
            prop_assert_eq!(l.coord(k, axis), reference[axis]);
        }
        for dir in Direction::all(l.dim()) {
            let n = l.neighbour_of(k, &x, dir);
            prop_assert_eq!(n, l.neighbour(k, dir));
            if let Some(n) = n {
                prop_assert!(l.adjacent(k, n));
            }
        }
    }

    #[test]
    fn k_index_round_trips_on_huge_lattices(l in big_lattice(), frac in 0.0f64..1.0) {
        let k = ((l.volume() as f64 * frac) as u64).min(l.volume() - 1);
        let x = l.decode(k).unwrap();
        prop_assert_eq!(l.encode(&x).unwrap(), k);
        let last = l.volume() - 1;
        let x = l.decode(last).unwrap();
        for (axis, &xi) in x.iter().enumerate() {
            prop_assert_eq!(xi, l.size(axis) - 1);
        }
        prop_assert!(l.decode(l.volume()).is_err());
    }

    #[test]
    fn neighbours_match_definition_and_are_symmetric((l, k) in lattice_and_site()) {
        let n: Vec<u64> = l.neighbours(k).collect();
        // Distinct, never k itself.
        let mut sorted = n.clone();
        sorted.sort();
        sorted.dedup();
        prop_assert_eq!(sorted.len(), n.len());
        prop_assert!(!n.contains(&k));
        // Each is adjacent, and k is among each one's neighbours.
        for &j in &n {
            prop_assert!(l.adjacent(k, j));
            prop_assert!(l.neighbours(j).any(|i| i == k));
        }
        // Brute force: every adjacent site of the lattice is listed.
        if l.volume() <= 4096 {
            let expected = (0..l.volume()).filter(|&j| l.adjacent(k, j)).count();
            prop_assert_eq!(expected, n.len());
        }
    }

    #[test]
    fn fast_paths_match_decode_and_neighbour((l, k) in lattice_and_site()) {
        let x = l.coords_array(k);
        let reference = l.decode(k).unwrap();
        prop_assert_eq!(&x[..l.dim()], &reference[..]);
        prop_assert!(x[l.dim()..].iter().all(|&v| v == 0));
        for dir in Direction::all(l.dim()) {
            prop_assert_eq!(l.neighbour_of(k, &x, dir), l.neighbour(k, dir));
        }
    }

    #[test]
    fn translation_moves_one_unit((l, k) in lattice_and_site(), dir_index in 0usize..16) {
        let dir = Direction::from_index(dir_index % (2 * l.dim()));
        let axis = dir.axis();
        let x = l.decode(k).unwrap();
        match l.translate(k, dir) {
            Err(_) => {
                prop_assert_eq!(l.boundary(axis), Boundary::Wall);
                let edge = if dir.is_positive() { l.size(axis) - 1 } else { 0 };
                prop_assert_eq!(x[axis], edge);
            }
            Ok(j) => {
                let y = l.decode(j).unwrap();
                for a in 0..l.dim() {
                    if a != axis {
                        prop_assert_eq!(x[a], y[a]);
                    }
                }
                let step = if dir.is_positive() { 1 } else { -1 };
                let d = l.displacement(k, j);
                if l.size(axis) > 2 {
                    prop_assert_eq!(d[axis], step);
                }
                // Undo.
                prop_assert_eq!(l.translate(j, dir.opposite()), Ok(k));
            }
        }
    }

    #[test]
    fn displacement_is_minimum_image((l, a) in lattice_and_site(), b_frac in 0.0f64..1.0) {
        let b = ((l.volume() as f64 * b_frac) as u64).min(l.volume() - 1);
        let d = l.displacement(a, b);
        let (xa, xb) = (l.decode(a).unwrap(), l.decode(b).unwrap());
        for axis in 0..l.dim() {
            let raw = xb[axis] as i64 - xa[axis] as i64;
            prop_assert_eq!(d[axis], reference_image(raw, l.size(axis), l.boundary(axis)));
            // Applying the displacement from a lands on b.
            let size = l.size(axis) as i64;
            prop_assert_eq!((xa[axis] as i64 + d[axis]).rem_euclid(size), xb[axis] as i64);
        }
    }
}
