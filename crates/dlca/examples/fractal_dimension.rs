//! Pooled fractal dimension of DLCA clusters over seeds (used to size the statistical tests;
//! see docs/dlca.md). Usage: `cargo run --release -p dlca --example fractal_dimension -- D L FILL
//! TARGET SEEDS MIN_SIZE`.

use dlca::analysis::{fractal_dimension, gyration};
use dlca::{Init, Params, Simulation};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let arg = |i: usize, d: &str| a.get(i).cloned().unwrap_or_else(|| d.to_string());
    let dim: usize = arg(1, "2").parse().unwrap();
    let l: u64 = arg(2, "512").parse().unwrap();
    let fill: f64 = arg(3, "0.01").parse().unwrap();
    let target: u64 = arg(4, "20").parse().unwrap();
    let seeds: u64 = arg(5, "8").parse().unwrap();
    let min_size: u64 = arg(6, "10").parse().unwrap();
    let mut pooled = Vec::new();
    let t = std::time::Instant::now();
    for seed in 1..=seeds {
        let params = Params {
            size: vec![l; dim],
            boundary: vec![core_lattice::Boundary::Periodic; dim],
            init: Init::Fill(fill),
            target_clusters: target,
            ..Params::default()
        };
        let mut sim = Simulation::new(params, seed).unwrap();
        sim.run();
        let g = gyration(&sim);
        let one = fractal_dimension(&g, min_size)
            .map(|f| f.slope)
            .unwrap_or(f64::NAN);
        println!(
            "seed {seed}: {} sweeps, {} clusters, D = {one:.3}",
            sim.sweeps(),
            sim.clusters()
        );
        pooled.extend(g);
    }
    for m in [min_size, 2 * min_size, 4 * min_size] {
        match fractal_dimension(&pooled, m) {
            Ok(f) => println!(
                "pooled, s >= {m}: D = {:.4} +- {:.4} over {} clusters",
                f.slope, f.slope_stderr, f.n
            ),
            Err(e) => println!("pooled, s >= {m}: {e}"),
        }
    }
    println!("{:.1} s", t.elapsed().as_secs_f64());
}
