//! Orthtree benchmarks (seed 002, sections 3.1 and 3.3): insert throughput and query throughput
//! (exact nearest distance, `vpdist` at kappa = 1, 2, 4) at 1e5 and 1e6 points, on a DLA-like
//! branched cluster of touching unit discs and on uniform points in a disc at unit density,
//! against kiddo's nearest-one query (`ImmutableKdTree`, the fastest kiddo layout, and
//! `MutableKdTree`, which like the orthtree grows one point at a time) on the same query points.
//!
//! Query points are walker-like: half near the cluster (a stored point plus an offset of 1 to 6
//! diameters), a quarter anywhere inside the birth circle, a quarter outside it (1 to 3 radii).
//!
//! `ORTHTREE_BENCH_QUICK=1` shortens the measurement, `ORTHTREE_BENCH_LEAF_SIDE=8` changes the
//! leaf side; bytes per point of each tree are printed to stderr.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use kiddo::{ImmutableKdTree, MutableKdTree, SquaredEuclidean};
use spatial::orthtree::Orthtree;

/// splitmix64: deterministic data without extra dependencies.
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

/// DLA-like branched cluster of touching unit discs: persistent self-avoiding walks from random
/// tips, branching with probability 0.08 per step. Locally chains of touching particles, like
/// DLA; returned in growth order.
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

/// Uniform points in the disc of area `n` (unit density).
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

/// Walker-like query points for a cluster.
fn walker_queries(pts: &[[f64; 2]], count: usize, seed: u64) -> Vec<[f64; 2]> {
    let mut rng = Rng(seed);
    let r_ext = pts.iter().map(|p| p[0].hypot(p[1])).fold(0.0, f64::max);
    let r_birth = r_ext + 5.0;
    (0..count)
        .map(|i| {
            let a = rng.uniform() * std::f64::consts::TAU;
            match i % 4 {
                0 | 1 => {
                    let p = pts[rng.below(pts.len())];
                    let r = 1.0 + 5.0 * rng.uniform();
                    [p[0] + r * a.cos(), p[1] + r * a.sin()]
                }
                2 => {
                    let r = r_birth * rng.uniform().sqrt();
                    [r * a.cos(), r * a.sin()]
                }
                _ => {
                    let r = r_birth * (1.0 + 2.0 * rng.uniform());
                    [r * a.cos(), r * a.sin()]
                }
            }
        })
        .collect()
}

/// Leaf side from `ORTHTREE_BENCH_LEAF_SIDE` (default: the library default).
fn leaf_side() -> f64 {
    std::env::var("ORTHTREE_BENCH_LEAF_SIDE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(spatial::orthtree::DEFAULT_LEAF_SIDE)
}

fn build(pts: &[[f64; 2]]) -> Orthtree<2> {
    let mut t = Orthtree::<2>::with_leaf_side(leaf_side()).unwrap();
    for p in pts {
        t.insert(*p).unwrap();
    }
    t
}

fn benches(c: &mut Criterion) {
    let quick = std::env::var_os("ORTHTREE_BENCH_QUICK").is_some();
    let (warm, meas) = if quick {
        (Duration::from_millis(300), Duration::from_secs(1))
    } else {
        (Duration::from_secs(1), Duration::from_secs(3))
    };
    for n in [100_000usize, 1_000_000] {
        for (name, pts) in [
            ("dla-like", branching_cluster(n, 1)),
            ("uniform", uniform_disc(n, 2)),
        ] {
            let tree = build(&pts);
            eprintln!(
                "orthtree {name} n={n}: {:.2} bytes/point, {:?}",
                tree.memory_bytes() as f64 / n as f64,
                tree.stats()
            );
            let qs = walker_queries(&pts, 4096, 3);
            let kd_imm: ImmutableKdTree<f64, 2> = ImmutableKdTree::new_from_slice(&pts).unwrap();
            let mut kd_mut: MutableKdTree<f64, 2> = MutableKdTree::default();
            for (i, p) in pts.iter().enumerate() {
                kd_mut.add(p, i as u32).unwrap();
            }
            // Sanity: everyone agrees on the exact distances.
            for q in qs.iter().take(256) {
                let d = tree.nearest_distance(q).unwrap();
                let k = kd_imm
                    .query(q)
                    .nearest_one::<SquaredEuclidean<f64>>()
                    .execute()
                    .distance
                    .sqrt();
                assert!((d - k).abs() < 1e-6, "{d} vs {k}");
            }

            let mut g = c.benchmark_group(format!("orthtree_insert/{name}"));
            g.sample_size(10).warm_up_time(warm).measurement_time(meas);
            g.throughput(Throughput::Elements(n as u64));
            g.bench_function(BenchmarkId::new("orthtree", n), |b| {
                b.iter(|| black_box(build(black_box(&pts))))
            });
            g.bench_function(BenchmarkId::new("kiddo_mutable", n), |b| {
                b.iter(|| {
                    let mut t: MutableKdTree<f64, 2> = MutableKdTree::default();
                    for (i, p) in pts.iter().enumerate() {
                        t.add(p, i as u32).unwrap();
                    }
                    black_box(t)
                })
            });
            g.finish();

            let mut g = c.benchmark_group(format!("orthtree_query/{name}/{n}"));
            g.sample_size(20).warm_up_time(warm).measurement_time(meas);
            g.throughput(Throughput::Elements(qs.len() as u64));
            g.bench_function("orthtree_exact", |b| {
                b.iter(|| {
                    let mut s = 0.0;
                    for q in &qs {
                        s += tree.nearest_distance(black_box(q)).unwrap();
                    }
                    s
                })
            });
            for kappa in [1.0, 2.0, 4.0] {
                g.bench_function(format!("orthtree_vpdist_k{kappa}"), |b| {
                    b.iter(|| {
                        let mut s = 0.0;
                        for q in &qs {
                            s += tree.vpdist(black_box(q), kappa).unwrap();
                        }
                        s
                    })
                });
            }
            g.bench_function("kiddo_immutable_nearest_one", |b| {
                b.iter(|| {
                    let mut s = 0.0;
                    for q in &qs {
                        s += kd_imm
                            .query(black_box(q))
                            .nearest_one::<SquaredEuclidean<f64>>()
                            .execute()
                            .distance;
                    }
                    s
                })
            });
            g.bench_function("kiddo_mutable_nearest_one", |b| {
                b.iter(|| {
                    let mut s = 0.0;
                    for q in &qs {
                        s += kd_mut
                            .query(black_box(q))
                            .nearest_one::<SquaredEuclidean<f64>>()
                            .execute()
                            .distance;
                    }
                    s
                })
            });
            g.finish();
        }
    }
}

criterion_group!(orthtree, benches);
criterion_main!(orthtree);
