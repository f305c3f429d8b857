//! The experiment behind the default parameters (docs/animat.md): run the default start (or
//! the defaults overridden by `name=value` pairs, separated by spaces, given as the first
//! argument) for `STEPS` steps
//! (second argument, default 3000) on seeds 1..=10 and report, per seed, whether both species
//! survived, the step at which one died out, and the population extremes. A third argument
//! `FIRST-LAST` picks other seeds.
//!
//! `cargo run --release -p animat --example defaults_experiment -- 'rabbit_breed_p=0.2 starve=40' 3000`

use animat::Params;
use core_lattice::spec::DeclaredParams;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mut params = Params::default();
    for pair in args.get(1).map_or("", String::as_str).split_whitespace() {
        let (name, value) = pair
            .split_once('=')
            .unwrap_or_else(|| panic!("{pair}: expected name=value"));
        match params.set_text(name, value) {
            Ok(true) => {}
            Ok(false) => panic!("{name} is not a parameter"),
            Err(e) => panic!("{name}: {e}"),
        }
    }
    params.validate().unwrap_or_else(|e| panic!("{e}"));
    let steps: u64 = args.get(2).map_or(3000, |s| s.parse().expect("steps"));
    // Optional third argument: the seeds, `FIRST-LAST` (default 1-10).
    let (first, last): (u64, u64) = args.get(3).map_or((1, 10), |s| {
        let (a, b) = s.split_once('-').expect("seeds as FIRST-LAST");
        (
            a.parse().expect("first seed"),
            b.parse().expect("last seed"),
        )
    });
    let mut survived = 0;
    for seed in first..=last {
        let mut w = animat::World::new(params.clone(), seed).expect("valid");
        let (mut fmin, mut fmax, mut rmin, mut rmax) = (u64::MAX, 0, u64::MAX, 0);
        let mut died = None;
        for t in 1..=steps {
            w.step();
            let (f, r) = (w.foxes(), w.rabbits());
            fmin = fmin.min(f);
            fmax = fmax.max(f);
            rmin = rmin.min(r);
            rmax = rmax.max(r);
            if f == 0 || r == 0 {
                died = Some(t);
                break;
            }
            if t % 500 == 0 {
                eprint!("[{seed}:{t} {f}/{r}] ");
            }
        }
        eprintln!();
        if died.is_none() {
            survived += 1;
        }
        println!(
            "seed {seed}: {} foxes {} rabbits {} (foxes {fmin}..{fmax}, rabbits {rmin}..{rmax})",
            died.map_or("survived".to_string(), |t| format!("died out at step {t}")),
            w.foxes(),
            w.rabbits()
        );
    }
    println!(
        "both species alive after {steps} steps in {survived} of {} seeds",
        last - first + 1
    );
}
