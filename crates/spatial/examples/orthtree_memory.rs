//! Bytes per point of the orthtree (seed 002, section 3.3 reports memory per particle) on a
//! DLA-like branched cluster of touching unit discs and on uniform points at unit density, for
//! several leaf sides.
//!
//! ```text
//! cargo run --release -p spatial --example orthtree_memory -- [N ...]
//! ```
//!
//! Default sizes: 1e6 and 1e7. Prints one line per (data set, N, leaf side) with bytes per
//! point, points per leaf, depth and build time.

use std::time::Instant;

use spatial::orthtree::Orthtree;

/// splitmix64.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// Same generator as `benches/orthtree.rs`: persistent self-avoiding walks from random tips,
/// branching with probability 0.08 per step.
fn branching_cluster(n: usize, seed: u64) -> Vec<[f64; 2]> {
    use std::f64::consts::TAU;
    let mut rng = Rng(seed);
    let mut t = Orthtree::<2>::new();
    let mut all = vec![t.insert([0.0, 0.0]).unwrap()];
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
        if t.nearest_distance(&cand).unwrap() >= 1.0 - 1e-9 {
            let s = t.insert(cand).unwrap();
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

fn uniform_disc(n: usize, seed: u64) -> Vec<[f64; 2]> {
    let mut rng = Rng(seed);
    let radius = (n as f64 / std::f64::consts::PI).sqrt();
    (0..n)
        .map(|_| {
            let r = radius * rng.uniform().sqrt();
            let a = rng.uniform() * std::f64::consts::TAU;
            [r * a.cos(), r * a.sin()]
        })
        .collect()
}

fn main() {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse::<f64>().expect("N") as usize)
        .collect();
    let sizes = if sizes.is_empty() {
        vec![1_000_000, 10_000_000]
    } else {
        sizes
    };
    println!("data      N          leaf  bytes/pt  pts/leaf  nodes/pt  depth  free%  build_s");
    for &n in &sizes {
        let t0 = Instant::now();
        let sets = [
            ("dla-like", branching_cluster(n, 1)),
            ("uniform", uniform_disc(n, 2)),
        ];
        eprintln!("generated N = {n} in {:.1} s", t0.elapsed().as_secs_f64());
        for (name, pts) in &sets {
            for side in [2.0, 4.0, 8.0] {
                let t0 = Instant::now();
                let mut t = Orthtree::<2>::with_leaf_side(side).unwrap();
                for p in pts {
                    t.insert(*p).unwrap();
                }
                let dt = t0.elapsed().as_secs_f64();
                let s = t.stats();
                println!(
                    "{name:9} {n:<10} {side:4}  {:8.2}  {:8.2}  {:8.3}  {:5}  {:5.1}  {dt:7.2}",
                    s.memory_bytes as f64 / n as f64,
                    n as f64 / s.leaves as f64,
                    s.nodes as f64 / n as f64,
                    s.depth,
                    100.0 * s.free_slots as f64 / s.point_slots as f64,
                );
            }
        }
    }
}
