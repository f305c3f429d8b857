//! Whole-step throughput (animat-steps per second, timing off) for one population:
//! `cargo run --release -p animat --example throughput -- [POPULATION] [STEPS] [GRID] [DENSITY] [WARMUP] [SEED]`
//! (defaults 100000, 20, 60, 0.2, 5, 1). Prints one line with the figures and the state hash.

use animat::GridBox;
use animat::bench::step_throughput;

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, d: &str| a.get(i).cloned().unwrap_or_else(|| d.to_string());
    let pop: u64 = arg(0, "100000").parse().expect("population");
    let steps: u64 = arg(1, "20").parse().expect("steps");
    let grid = match arg(2, "60").as_str() {
        "none" => GridBox::None,
        s => GridBox::Side(s.parse().expect("grid side or none")),
    };
    let density: f64 = arg(3, "0.2").parse().expect("density");
    let warmup: u64 = arg(4, "5").parse().expect("warmup");
    let seed: u64 = arg(5, "1").parse().expect("seed");
    let t = step_throughput(pop, density, grid, warmup, steps, seed).expect("valid parameters");
    println!(
        "animats {pop} grid {grid} density {density} steps {} animat-steps {} seconds {:.3} \
         throughput {:.0} animat-steps/s ({:.1} ns each) cpu {:.1} ns each hash {:016x}",
        t.steps,
        t.animat_steps,
        t.seconds,
        t.animat_steps_per_second,
        1e9 / t.animat_steps_per_second,
        t.cpu_seconds.unwrap_or(f64::NAN) * 1e9 / t.animat_steps as f64,
        t.state_hash
    );
}
