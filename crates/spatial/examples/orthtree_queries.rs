//! Query cost of the orthtree by kind of query point (seed 002, section 3.2: walkers near the
//! cluster, inside the birth circle, outside it), against kiddo's nearest-one.
//!
//! ```text
//! cargo run --release -p spatial --example orthtree_queries -- [N] [leaf_side]
//! ```

use std::hint::black_box;
use std::time::Instant;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
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

/// Nanoseconds per call of `f` over `qs` (best of 5 passes).
fn time<F: FnMut(&[f64; 2]) -> f64>(qs: &[[f64; 2]], mut f: F) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t0 = Instant::now();
        let mut s = 0.0;
        for q in qs {
            s += f(black_box(q));
        }
        black_box(s);
        best = best.min(t0.elapsed().as_secs_f64() * 1e9 / qs.len() as f64);
    }
    best
}

fn main() {
    let mut args = std::env::args().skip(1);
    let n = args
        .next()
        .map_or(1_000_000, |a| a.parse::<f64>().expect("N") as usize);
    let side = args
        .next()
        .map_or(4.0, |a| a.parse::<f64>().expect("leaf side"));
    println!("N = {n}, leaf side {side}: ns per query (best of 5 passes over 20000 queries)");
    println!("data      queries   exact  vp_k1  vp_k2  vp_k4  kiddo_imm");
    for (name, pts) in [
        ("dla-like", branching_cluster(n, 1)),
        ("uniform", uniform_disc(n, 2)),
    ] {
        let mut t = Orthtree::<2>::with_leaf_side(side).unwrap();
        for p in &pts {
            t.insert(*p).unwrap();
        }
        let kd: ImmutableKdTree<f64, 2> = ImmutableKdTree::new_from_slice(&pts).unwrap();
        let r_b = pts.iter().map(|p| p[0].hypot(p[1])).fold(0.0, f64::max) + 5.0;
        let mut rng = Rng(3);
        let mut make_query = |kind: usize| -> [f64; 2] {
            let a = rng.uniform() * std::f64::consts::TAU;
            let (c, r) = match kind {
                0 => (pts[rng.below(pts.len())], 1.0 + 5.0 * rng.uniform()),
                1 => ([0.0, 0.0], r_b * rng.uniform().sqrt()),
                _ => ([0.0, 0.0], r_b * (1.0 + 2.0 * rng.uniform())),
            };
            [c[0] + r * a.cos(), c[1] + r * a.sin()]
        };
        for (kind, label) in ["near 1-6", "inside", "outside"].iter().enumerate() {
            let qs: Vec<[f64; 2]> = (0..20_000).map(|_| make_query(kind)).collect();
            let e = time(&qs, |q| t.nearest_distance(q).unwrap());
            let v1 = time(&qs, |q| t.vpdist(q, 1.0).unwrap());
            let v2 = time(&qs, |q| t.vpdist(q, 2.0).unwrap());
            let v4 = time(&qs, |q| t.vpdist(q, 4.0).unwrap());
            let k = time(&qs, |q| {
                kd.query(q)
                    .nearest_one::<SquaredEuclidean<f64>>()
                    .execute()
                    .distance
            });
            println!("{name:9} {label:8} {e:6.0} {v1:6.0} {v2:6.0} {v4:6.0} {k:9.0}");
        }
    }
}
