//! Property tests of the orthtree against brute force (the variable-precision paper, section 3.1,
//! Listing 1 and its error analysis; storage of section 3.3).
//!
//! Brute force works on the stored positions returned by `insert` (they differ from the inserted
//! ones by at most `leaf_side / 2^33` per coordinate, checked here too) with the reference
//! formula `sqrt(sum over axes of (p_i - x_i)^2)`, summed from 0 in axis order. Exact queries must
//! return that value bit for bit; `vpdist` must never exceed it and must satisfy the bounds
//! derived in the module docs of `spatial::orthtree`:
//!
//! - exact answer when it says so (`half_diagonal == None`), and always when
//!   `d <= (2 kappa - 1) r_leaf`;
//! - otherwise the producing node of half diagonal `r` was far (`|p - c| > 2 kappa r`) and
//!   `d - v <= 2 r` (the paper's `d in [d_app, d_app + 2r]`);
//! - `v > d (2 kappa - 1) / (2 kappa + 1)`.

use proptest::prelude::*;
use spatial::orthtree::{Orthtree, RangeSink};

/// What a range query kept, piece by piece, lending at most three slots at a time (so leaves
/// are scanned in pieces), and whether it ever kept more than the room it lent.
#[derive(Default)]
struct Kept<const D: usize> {
    points: Vec<[f64; D]>,
    slots: Vec<[f64; D]>,
    overflow: bool,
}

impl<const D: usize> RangeSink<D> for Kept<D> {
    fn room(&mut self, n: usize) -> &mut [[f64; D]] {
        // Slots the query must overwrite: NaN would show as a kept point never written.
        self.slots = vec![[f64::NAN; D]; n.min(3)];
        &mut self.slots
    }

    fn keep(&mut self, kept: usize) {
        self.overflow |= kept > self.slots.len();
        self.points
            .extend_from_slice(&self.slots[..kept.min(self.slots.len())]);
    }
}

/// Reference squared distance.
fn d2<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    let mut s = 0.0;
    for i in 0..D {
        let e = a[i] - b[i];
        s += e * e;
    }
    s
}

/// Relative tolerance for the bounds (the far-node shrink is 2^-44 ~ 6e-14).
const TOL: f64 = 1e-12;

const KAPPAS: [f64; 6] = [0.75, 1.0, 2.0, 3.0, 4.0, f64::INFINITY];

/// Builds the tree, checks storage, and checks every query against brute force.
fn check<const D: usize>(
    leaf_side: f64,
    pts: &[[f64; D]],
    queries: &[[f64; D]],
    radii: &[f64],
) -> Result<(), TestCaseError> {
    let mut tree = Orthtree::<D>::with_leaf_side(leaf_side).unwrap();
    let mut stored = Vec::with_capacity(pts.len());
    for p in pts {
        let s = tree.insert(*p).unwrap();
        for i in 0..D {
            let err = (s[i] - p[i]).abs();
            // s / 2^33 from the fixed point, plus f64 rounding at the coordinate's magnitude.
            let allowed = leaf_side / 8_589_934_592.0 + p[i].abs() * f64::EPSILON;
            prop_assert!(err <= allowed, "{p:?} stored as {s:?}");
            if p[i].abs() < 1e6 {
                prop_assert!(err <= 1e-6);
            }
        }
        stored.push(s);
    }
    prop_assert_eq!(tree.len(), pts.len());

    // Iteration gives back exactly the stored positions.
    let key = |a: &[f64; D], b: &[f64; D]| a.partial_cmp(b).unwrap();
    let mut it: Vec<[f64; D]> = tree.iter().collect();
    prop_assert_eq!(tree.iter().len(), pts.len());
    it.sort_by(key);
    let mut sorted = stored.clone();
    sorted.sort_by(key);
    prop_assert_eq!(&it, &sorted);

    // Every stored point lies in the root.
    let (corner, side) = tree.root_cell().unwrap();
    for x in &stored {
        for i in 0..D {
            prop_assert!(x[i] >= corner[i] && x[i] <= corner[i] + side);
        }
    }

    let r_leaf = leaf_side * (D as f64).sqrt() / 2.0;
    for q in queries.iter().chain(stored.iter()) {
        let best_sq = stored
            .iter()
            .map(|x| d2(q, x))
            .fold(f64::INFINITY, f64::min);
        let d = best_sq.sqrt();

        // Exact queries: bit for bit.
        prop_assert_eq!(tree.nearest_distance(q), Some(d), "query {:?}", q);
        let n = tree.nearest(q).unwrap();
        prop_assert_eq!(n.distance, d);
        prop_assert_eq!(d2(q, &n.point), best_sq);
        prop_assert!(stored.contains(&n.point));

        for kappa in KAPPAS {
            let est = tree.vpdist_detailed(q, kappa).unwrap();
            let v = est.distance;
            prop_assert_eq!(tree.vpdist(q, kappa), Some(v));
            // Never more than the exact distance: no tolerance.
            prop_assert!(
                v <= d,
                "kappa {}: vpdist {} > exact {} at {:?}",
                kappa,
                v,
                d,
                q
            );
            match est.half_diagonal {
                None => prop_assert_eq!(v, d, "kappa {}: claimed exact", kappa),
                Some(r) => {
                    prop_assert!(kappa.is_finite(), "kappa = inf must be exact");
                    // r is a half diagonal of some level: r_leaf * 2^k.
                    let k = (r / r_leaf).log2();
                    prop_assert!(k > -1e-9 && (k - k.round()).abs() < 1e-9, "r = {}", r);
                    // The producing node was far: |p - c| = v + r > 2 kappa r.
                    prop_assert!(
                        v + r > 2.0 * kappa * r * (1.0 - TOL),
                        "not far: {} {}",
                        v,
                        r
                    );
                    // Absolute gap: d in [v, v + 2r].
                    prop_assert!(
                        d - v <= 2.0 * r * (1.0 + TOL) + TOL * d,
                        "kappa {}: gap {} > 2r = {}",
                        kappa,
                        d - v,
                        2.0 * r
                    );
                }
            }
            // The bounded walk: with a true upper bound (tight, loose, or the exact distance
            // itself) or a wrong one, never above the exact distance, within the relative bound,
            // and an approximate answer always comes from a far node.
            for upper in [
                d,
                d * 1.5 + 0.25,
                d + 2.0 * leaf_side,
                0.5 * d,
                0.0,
                f64::INFINITY,
            ] {
                // `vpdist_bounded` is this walk without the point.
                let (b, near) = tree.vpdist_bounded_nearest(q, kappa, upper).unwrap();
                prop_assert_eq!(tree.vpdist_bounded(q, kappa, upper), Some(b));
                prop_assert!(
                    b.distance <= d
                        && (!kappa.is_finite()
                            || b.distance
                                >= d * (2.0 * kappa - 1.0) / (2.0 * kappa + 1.0) * (1.0 - TOL)),
                    "kappa {}, upper {}: bounded {} vs vpdist {} exact {} at {:?}",
                    kappa,
                    upper,
                    b.distance,
                    v,
                    d,
                    q
                );
                match b.half_diagonal {
                    None => prop_assert_eq!(b.distance, d),
                    Some(r) => prop_assert!(
                        kappa.is_finite()
                            && b.distance + r > 2.0 * kappa * r * (1.0 - TOL)
                            && d - b.distance <= 2.0 * r * (1.0 + TOL) + TOL * d
                    ),
                }
                // When exact, a stored point at exactly that distance.
                match (b.half_diagonal, near) {
                    (None, Some(x)) => {
                        if upper == d {
                            // One exact nearest query per point is enough to show it is stored.
                            prop_assert_eq!(tree.nearest(&x).unwrap().point, x, "not stored");
                        }
                        prop_assert_eq!(d2(q, &x).sqrt(), d);
                    }
                    (Some(_), None) => {}
                    other => prop_assert!(false, "exact answer without point or back: {:?}", other),
                }
            }
            if kappa.is_finite() {
                // Relative bound.
                let ratio = (2.0 * kappa - 1.0) / (2.0 * kappa + 1.0);
                prop_assert!(
                    v >= d * ratio * (1.0 - TOL),
                    "kappa {}: vpdist {} < {} * exact {}",
                    kappa,
                    v,
                    ratio,
                    d
                );
                // Exact within (2 kappa - 1) r_leaf.
                if d <= (2.0 * kappa - 1.0) * r_leaf * (1.0 - 1e-9) {
                    prop_assert_eq!(v, d, "kappa {}: not exact at d = {}", kappa, d);
                }
            } else {
                prop_assert_eq!(v, d);
            }
        }

        // Range queries, including radii equal to a stored point's distance (inclusive).
        let mut rs: Vec<f64> = radii.to_vec();
        rs.push(d);
        if let Some(x) = stored.get(stored.len() / 2) {
            rs.push(d2(q, x).sqrt());
        }
        for r in rs {
            let mut got = Vec::new();
            tree.for_each_within(q, r, |x| got.push(x));
            let mut want: Vec<[f64; D]> = stored
                .iter()
                .filter(|x| d2(q, x) <= r * r)
                .copied()
                .collect();
            // The sink form keeps the same points, in the same order, within the room it
            // lent, leaves scanned in pieces.
            let mut kept = Kept::default();
            tree.range_into(q, r, &mut kept);
            prop_assert!(!kept.overflow, "kept more points than the room lent");
            prop_assert_eq!(&kept.points, &got, "range_into {} around {:?}", r, q);
            got.sort_by(key);
            want.sort_by(key);
            prop_assert_eq!(got, want, "range {} around {:?}", r, q);
        }
    }
    Ok(())
}

/// One coordinate: ordinary, on cell boundaries (multiples of 1/2 up to 2^7), or large.
fn coord() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -40.0..40.0f64,
        3 => (-128i32..=128).prop_map(|k| f64::from(k) * 0.5),
        1 => (-8i32..=8).prop_map(|k| f64::from(k) * 1024.0),
        1 => -1e7..1e7f64,
    ]
}

fn point<const D: usize>() -> impl Strategy<Value = [f64; D]> {
    prop::collection::vec(coord(), D).prop_map(|v| std::array::from_fn(|i| v[i]))
}

/// Points plus near-duplicates (offsets from 0 to 1e-6) of some of them.
fn cloud<const D: usize>(max: usize) -> impl Strategy<Value = Vec<[f64; D]>> {
    (
        prop::collection::vec(point::<D>(), 1..max),
        prop::collection::vec(
            (
                any::<prop::sample::Index>(),
                prop::collection::vec(prop_oneof![Just(0.0), -1e-6..1e-6f64, -1e-11..1e-11f64], D),
            ),
            0..max / 3,
        ),
    )
        .prop_map(|(mut pts, dups)| {
            let n = pts.len();
            for (ix, off) in dups {
                let b = pts[ix.index(n)];
                pts.push(std::array::from_fn(|i| b[i] + off[i]));
            }
            pts
        })
}

/// Query points: anywhere, on boundaries, or far away (beyond the root).
fn queries<const D: usize>() -> impl Strategy<Value = Vec<[f64; D]>> {
    prop::collection::vec(
        prop_oneof![
            3 => point::<D>(),
            1 => prop::collection::vec(-1e9..1e9f64, D)
                .prop_map(|v| std::array::from_fn(|i| v[i])),
        ],
        1..12,
    )
}

fn leaf_side() -> impl Strategy<Value = f64> {
    prop_oneof![Just(0.5), Just(1.0), Just(2.0), Just(4.0), Just(8.0)]
}

fn radii() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(prop_oneof![0.0..3.0f64, 0.0..100.0f64, Just(0.0)], 0..3)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2500))]

    #[test]
    fn quadtree_matches_brute_force(
        s in leaf_side(), pts in cloud::<2>(90), qs in queries::<2>(), rs in radii()
    ) {
        check::<2>(s, &pts, &qs, &rs)?;
    }

    #[test]
    fn octree_matches_brute_force(
        s in leaf_side(), pts in cloud::<3>(90), qs in queries::<3>(), rs in radii()
    ) {
        check::<3>(s, &pts, &qs, &rs)?;
    }
}

/// Points in the cube `[-half, half)^D`.
fn cube<const D: usize>(half: f64, max: usize) -> impl Strategy<Value = Vec<[f64; D]>> {
    prop::collection::vec(
        prop::collection::vec(-half..half, D).prop_map(|v| std::array::from_fn(|i| v[i])),
        1..max,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1500))]

    /// Dense clusters of touching-scale points, queried close by: exercises the exact region
    /// and the transitions between exact and approximate answers.
    #[test]
    fn dense_cluster_near_queries_2d(
        s in leaf_side(), pts in cube::<2>(12.0, 200), qs in cube::<2>(40.0, 20),
    ) {
        check::<2>(s, &pts, &qs, &[1.5])?;
    }

    #[test]
    fn hypercube_tree_4d(
        s in leaf_side(), pts in cloud::<4>(40), qs in queries::<4>(), rs in radii()
    ) {
        check::<4>(s, &pts, &qs, &rs)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    /// `DLA --dim 5`'s tree: 32 children per node.
    #[test]
    fn hypercube_tree_5d(
        s in leaf_side(), pts in cloud::<5>(40), qs in queries::<5>(), rs in radii()
    ) {
        check::<5>(s, &pts, &qs, &rs)?;
    }

    /// Dense clusters in 4D and 5D (as many points per unit volume as the 2D ones have per
    /// unit area only in a far smaller cube), queried close by.
    #[test]
    fn dense_cluster_near_queries_4d(
        s in leaf_side(), pts in cube::<4>(4.0, 120), qs in cube::<4>(12.0, 12),
    ) {
        check::<4>(s, &pts, &qs, &[1.5])?;
    }

    #[test]
    fn dense_cluster_near_queries_5d(
        s in leaf_side(), pts in cube::<5>(3.0, 120), qs in cube::<5>(10.0, 12),
    ) {
        check::<5>(s, &pts, &qs, &[1.5])?;
    }
}
