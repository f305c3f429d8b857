//! Benchmarks of [`spatial::plane::PlaneGrid`]: the animat nearest-of-kind query with vision
//! radius 60 at a fixed density of one animat per 100 cells, for 1e3 to 1e6 animats, grid boxes
//! of side 60, 120 and 240 against the exhaustive "no grid" scan (the grid-boxing paper, section
//! IV.B, Fig. 9 and Table I). Also: the overcrowding count and the unit-step move.
//!
//! Run with `cargo bench -p spatial --bench plane`. Each benchmark iteration is a batch of
//! queries (throughput is reported per query); the work per query (distance evaluations, items
//! scanned, boxes probed: `SearchStats`) is printed to stderr once per configuration.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use spatial::plane::{BoxSize, PlaneGrid, Pos};
use spatial::testdata::SplitMix;

/// Animat species.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Species {
    Fox,
    Rabbit,
}

/// Vision radius of the animat model (the grid-boxing paper, section IV.B), squared.
const VISION2: u64 = 60 * 60;
/// Cells per animat.
const CELLS_PER_ANIMAT: u64 = 100;
/// Queries per benchmark iteration.
const BATCH: usize = 1000;

/// `n` animats, one per cell at most, uniformly over a square of `100 n` cells centred on the
/// origin (so half the coordinates are negative); one in five is a fox.
fn world(n: usize, seed: u64) -> Vec<(u64, Pos, Species)> {
    let side = ((n as u64 * CELLS_PER_ANIMAT) as f64).sqrt().ceil() as usize;
    let half = (side / 2) as i64;
    let mut rng = SplitMix::new(seed);
    let mut taken = std::collections::HashSet::with_capacity(n);
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let p = [rng.below(side) as i64 - half, rng.below(side) as i64 - half];
        if taken.insert(p) {
            let kind = if rng.below(5) == 0 {
                Species::Fox
            } else {
                Species::Rabbit
            };
            out.push((out.len() as u64, p, kind));
        }
    }
    out
}

fn build(size: BoxSize, items: &[(u64, Pos, Species)]) -> PlaneGrid<Species> {
    let mut g = PlaneGrid::new(size).expect("valid box size");
    for &(id, p, k) in items {
        g.insert(id, p, k).expect("fresh id");
    }
    g
}

/// The querying animats of one batch: (id, position, kind to look for).
fn batch(items: &[(u64, Pos, Species)], seed: u64) -> Vec<(u64, Pos, Species)> {
    let mut rng = SplitMix::new(seed);
    (0..BATCH)
        .map(|i| {
            let (id, p, _) = items[rng.below(items.len())];
            let want = if i % 2 == 0 {
                Species::Rabbit
            } else {
                Species::Fox
            };
            (id, p, want)
        })
        .collect()
}

fn sizes_for(n: usize) -> Vec<(String, BoxSize)> {
    let mut v: Vec<(String, BoxSize)> = [60, 120, 240]
        .iter()
        .map(|&a| (format!("grid{a}"), BoxSize::Side(a)))
        .collect();
    // The exhaustive scan is O(N) per query: only up to 1e5.
    if n <= 100_000 {
        v.push(("none".to_string(), BoxSize::None));
    }
    v
}

fn nearest_of_kind(c: &mut Criterion) {
    let mut group = c.benchmark_group("plane_nearest_r60");
    group.throughput(Throughput::Elements(BATCH as u64));
    for n in [1_000usize, 10_000, 100_000, 1_000_000] {
        let items = world(n, 42);
        let queries = batch(&items, 7);
        for (name, size) in sizes_for(n) {
            let g = build(size, &items);
            g.reset_stats();
            let found = queries
                .iter()
                .filter(|&&(id, p, k)| g.nearest(p, k, VISION2, Some(id)).is_some())
                .count();
            let w = g.take_stats();
            let per = |x: u64| x as f64 / BATCH as f64;
            eprintln!(
                "plane_nearest_r60/{name}/{n}: per query {:.1} distance evaluations, {:.1} items \
                 scanned, {:.1} boxes probed; {found}/{BATCH} found; {} occupied boxes",
                per(w.distance_evals),
                per(w.items_scanned),
                per(w.boxes_probed),
                g.box_count()
            );
            group.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter(|| {
                    let mut acc = 0u64;
                    for &(id, p, k) in &queries {
                        if let Some((nid, d2)) = g.nearest(black_box(p), k, VISION2, Some(id)) {
                            acc = acc.wrapping_add(nid ^ d2);
                        }
                    }
                    black_box(acc)
                })
            });
        }
    }
    group.finish();
}

fn overcrowding_count(c: &mut Criterion) {
    let mut group = c.benchmark_group("plane_crowd_capped_r10");
    group.throughput(Throughput::Elements(BATCH as u64));
    let n = 100_000;
    let items = world(n, 43);
    let queries = batch(&items, 8);
    for (name, size) in sizes_for(n) {
        let g = build(size, &items);
        group.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
            b.iter(|| {
                let mut crowded = 0usize;
                for &(id, p, _) in &queries {
                    // "more than 3 animats within radius 10"
                    crowded += usize::from(g.at_least(black_box(p), None, 100, Some(id), 4));
                }
                black_box(crowded)
            })
        });
    }
    group.finish();
}

fn unit_step_moves(c: &mut Criterion) {
    let mut group = c.benchmark_group("plane_move_step");
    group.throughput(Throughput::Elements(BATCH as u64));
    let n = 100_000;
    let items = world(n, 44);
    for (name, size) in sizes_for(n) {
        let mut g = build(size, &items);
        let mut rng = SplitMix::new(9);
        group.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
            b.iter(|| {
                for _ in 0..BATCH {
                    let id = rng.below(n) as u64;
                    let (p, _) = g.get(id).expect("present");
                    let to = [
                        p[0] + rng.below(3) as i64 - 1,
                        p[1] + rng.below(3) as i64 - 1,
                    ];
                    if !g.is_occupied(to) {
                        g.move_to(id, to).expect("present");
                    }
                }
            })
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_millis(1500))
        .sample_size(10);
    targets = nearest_of_kind, overcrowding_count, unit_step_moves
}
criterion_main!(benches);
