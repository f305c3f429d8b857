//! Pooled fractal dimension of DLCA clusters over seeds (used to size the statistical tests;
//! see docs/dlca.md, "Validation"), with the library's pooled fit
//! (`dlca::analysis::pooled_fractal_dimension`, as `dlca --seeds ... --gyration` reports it),
//! for the pooling moments the binary has no flag for (`mean:...`). Usage: `cargo run --release -p dlca --example
//! fractal_dimension -- D L FILL WHEN SEEDS MIN_SIZE [FIRST_SEED]`, where WHEN is a cluster count
//! (the clusters left when the run ends there are pooled) or `mean:8,16,32,64` (the clusters
//! present each time the mean cluster size passes one of these are pooled, as the 4D and 5D
//! tests do). Seeds FIRST_SEED (default 1) onwards.

use dlca::analysis::{PoolAt, fractal_dimension, pooled_clusters, pooled_fractal_dimension};
use dlca::{Init, Params};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let arg = |i: usize, d: &str| a.get(i).cloned().unwrap_or_else(|| d.to_string());
    let dim: usize = arg(1, "2").parse().unwrap();
    let l: u64 = arg(2, "512").parse().unwrap();
    let fill: f64 = arg(3, "0.01").parse().unwrap();
    let when = arg(4, "20");
    let seeds: u64 = arg(5, "8").parse().unwrap();
    let min_size: u64 = arg(6, "10").parse().unwrap();
    let first: u64 = arg(7, "1").parse().unwrap();
    let at = match when.strip_prefix("mean:") {
        Some(sizes) => PoolAt::MeanSizes(sizes.split(',').map(|m| m.parse().unwrap()).collect()),
        None => PoolAt::End(when.parse().unwrap()),
    };
    let params = Params {
        size: vec![l; dim],
        boundary: vec![core_lattice::Boundary::Periodic; dim],
        init: Init::Fill(fill),
        ..Params::default()
    };
    let mut runs = Vec::new();
    let t = std::time::Instant::now();
    for seed in first..first + seeds {
        let g = pooled_clusters(&params, seed, &at).unwrap();
        let one = fractal_dimension(&g, min_size)
            .map(|f| f.slope)
            .unwrap_or(f64::NAN);
        println!("seed {seed}: {} clusters, D = {one:.3}", g.len());
        runs.push(g);
    }
    for m in [min_size, 2 * min_size, 4 * min_size] {
        match pooled_fractal_dimension(&runs, m) {
            Ok(f) => println!(
                "pooled, s >= {m}: D = {:.4} +- {} (jackknife over seeds; regression {:.4}) over {} clusters",
                f.slope,
                f.jackknife_stderr
                    .map_or_else(|| "n/a".to_string(), |e| format!("{e:.4}")),
                f.fit_stderr,
                f.clusters
            ),
            Err(e) => println!("pooled, s >= {m}: {e}"),
        }
    }
    println!("{:.1} s", t.elapsed().as_secs_f64());
}
