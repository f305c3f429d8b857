//! Bytes per point of the orthtree (the variable-precision paper, section 3.3 reports memory per
//! particle) on a DLA-like branched cluster of touching unit discs and on uniform points at unit
//! density, for several leaf sides.
//!
//! ```text
//! cargo run --release -p spatial --example orthtree_memory -- [N ...]
//! ```
//!
//! Default sizes: 1e6 and 1e7. Prints one line per (data set, N, leaf side) with bytes per
//! point, points per leaf, depth and build time.

use std::time::Instant;

use spatial::orthtree::Orthtree;
use spatial::testdata::{branching_cluster, uniform_disc};

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
