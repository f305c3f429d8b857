//! Synthetic 2D point sets for tests, examples and benchmarks of the search structures, and the
//! grid-box sizes the plane grid is tested with ([`BOX_SIZES`]).
//!
//! Deterministic for a given seed (a SplitMix64 sequence), with no dependency on the models.
//! [`branching_cluster`] imitates the *local* structure of an off-lattice DLA cluster (chains of
//! touching unit discs that branch) cheaply; it is not a DLA cluster and has no DLA statistics.

use crate::orthtree::Orthtree;
use crate::plane::BoxSize;
use std::f64::consts::{PI, TAU};

/// The SplitMix64 generator of [`core_lattice::rng`], under the name the benchmarks, examples
/// and tests of this crate use.
pub use core_lattice::rng::SplitMix64 as SplitMix;

/// The grid-box sizes the plane grid's unit and property tests sweep: no grid (the exhaustive
/// baseline), the smallest sides (boxes of one, two and three cells, where most queries cross
/// box boundaries), an odd side and the animat vision radius 60.
pub const BOX_SIZES: [BoxSize; 6] = [
    BoxSize::None,
    BoxSize::Side(1),
    BoxSize::Side(2),
    BoxSize::Side(3),
    BoxSize::Side(7),
    BoxSize::Side(60),
];

/// A DLA-like branched cluster of `n` touching unit discs, in growth order: persistent
/// self-avoiding walks from the origin and from random earlier particles, branching with
/// probability 0.08 per step. Locally chains of touching particles, like DLA, which makes it the
/// sparsest (most memory-hungry per point) case for the orthtree's leaves.
pub fn branching_cluster(n: usize, seed: u64) -> Vec<[f64; 2]> {
    let mut rng = SplitMix::new(seed);
    let mut t = Orthtree::<2>::new();
    let mut all = vec![t.insert([0.0, 0.0]).expect("finite")];
    // Tips: (position, direction).
    let mut tips: Vec<([f64; 2], f64)> =
        (0..3).map(|k| ([0.0, 0.0], k as f64 * TAU / 3.0)).collect();
    while all.len() < n {
        if tips.is_empty() {
            tips.push((all[rng.below(all.len())], rng.uniform() * TAU));
        }
        let k = rng.below(tips.len());
        let (from, dir) = tips[k];
        let a = dir + (rng.uniform() - 0.5) * 1.2;
        let cand = [from[0] + a.cos(), from[1] + a.sin()];
        if t.nearest_distance(&cand).expect("non-empty") >= 1.0 - 1e-9 {
            let s = t.insert(cand).expect("finite");
            all.push(s);
            tips[k] = (s, a);
            if rng.uniform() < 0.08 {
                tips.push((s, a + if rng.uniform() < 0.5 { 1.0 } else { -1.0 }));
            }
        } else if rng.uniform() < 0.3 {
            tips.swap_remove(k);
        }
    }
    all
}

/// `n` points uniform in the disc of area `n` centred on the origin (unit density).
pub fn uniform_disc(n: usize, seed: u64) -> Vec<[f64; 2]> {
    let mut rng = SplitMix::new(seed);
    let radius = (n as f64 / PI).sqrt();
    (0..n)
        .map(|_| {
            let r = radius * rng.uniform().sqrt();
            let a = rng.uniform() * TAU;
            [r * a.cos(), r * a.sin()]
        })
        .collect()
}
