//! Orthtree benchmarks (the variable-precision paper, sections 3.1 and 3.3): insert throughput and
//! query throughput (exact nearest distance, `vpdist` at kappa = 1, 2, 4) at 1e5 and 1e6 points, on
//! a DLA-like branched cluster of touching unit discs and on uniform points in a disc at unit
//! density, against kiddo's nearest-one query (`ImmutableKdTree`, the fastest kiddo layout, and
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
use spatial::testdata::{SplitMix as Rng, branching_cluster, uniform_disc};

/// Walker-like query points around a cluster.
fn walker_queries(pts: &[[f64; 2]], count: usize, seed: u64) -> Vec<[f64; 2]> {
    let mut rng = Rng::new(seed);
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
