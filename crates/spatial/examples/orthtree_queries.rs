//! Query cost of the orthtree by kind of query point (the variable-precision paper, section 3.2:
//! walkers near the cluster, inside the birth circle, outside it), against kiddo's nearest-one.
//!
//! ```text
//! cargo run --release -p spatial --example orthtree_queries -- [N] [leaf_side]
//! ```

use std::hint::black_box;
use std::time::Instant;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use spatial::orthtree::Orthtree;
use spatial::testdata::{SplitMix as Rng, branching_cluster, uniform_disc};

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
        let mut rng = Rng::new(3);
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
