//! Synthetic 2D point sets for tests, examples and benchmarks of the search structures.
//!
//! Deterministic for a given seed (a SplitMix64 sequence), with no dependency on the models.
//! [`branching_cluster`] imitates the *local* structure of an off-lattice DLA cluster (chains of
//! touching unit discs that branch) cheaply; it is not a DLA cluster and has no DLA statistics.

use crate::orthtree::Orthtree;
use std::f64::consts::{PI, TAU};

/// SplitMix64: a small deterministic generator for synthetic data.
#[derive(Debug, Clone)]
pub struct SplitMix(pub u64);

impl SplitMix {
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`, 53 bits.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `0..n` (`n > 0`; modulo bias below 2^-40 for the sizes used here).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// A DLA-like branched cluster of `n` touching unit discs, in growth order: persistent
/// self-avoiding walks from the origin and from random earlier particles, branching with
/// probability 0.08 per step. Locally chains of touching particles, like DLA, which makes it the
/// sparsest (most memory-hungry per point) case for the orthtree's leaves.
pub fn branching_cluster(n: usize, seed: u64) -> Vec<[f64; 2]> {
    let mut rng = SplitMix(seed);
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
    let mut rng = SplitMix(seed);
    let radius = (n as f64 / PI).sqrt();
    (0..n)
        .map(|_| {
            let r = radius * rng.uniform().sqrt();
            let a = rng.uniform() * TAU;
            [r * a.cos(), r * a.sin()]
        })
        .collect()
}
