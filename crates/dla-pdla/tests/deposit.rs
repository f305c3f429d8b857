//! Deposits on a substrate, drift and ballistic walkers: brute force over the stored
//! positions and parents (periodic lateral distances), exact naive references for the
//! ballistic walks on the same random stream, the drift's effect, and checkpoint/resume.

mod common;

use common::tolerance;
use core_lattice::rng::{stream, stream_id, uniform01};
use dla_pdla::deposit::Deposit;
use dla_pdla::sim::PURPOSE_WALK;
use dla_pdla::substrate::ballistic_start;
use dla_pdla::{Dim, Params, Simulation, Space};

/// A finished run with positions and parents kept.
fn grow<const D: usize>(params: Params, seed: u64) -> Simulation<D>
where
    Dim<D>: Space<D>,
{
    let params = Params {
        dim: D,
        keep_positions: true,
        connectivity: true,
        ..params
    };
    let mut sim = Simulation::<D>::new(params, seed).unwrap();
    sim.run().unwrap();
    sim
}

/// The squared distance between `a` and `b` with the lateral axes periodic of period `w`.
fn periodic_d2<const D: usize>(a: &[f64; D], b: &[f64; D], w: f64) -> f64 {
    (0..D)
        .map(|i| {
            let mut d = (a[i] - b[i]).abs();
            if i + 1 < D {
                d = d.min(w - d);
            }
            d * d
        })
        .sum()
}

/// The invariants of a deposit: every particle in the strip and on or above the substrate; no
/// two closer than `f` (the noise reduction) across the periodic edges; every particle either
/// on the substrate (parent -1) or at distance `f` from its parent, an earlier particle; the
/// deposit analysis accepts it. All to within the stored positions' rounding.
fn assert_deposit<const D: usize>(sim: &Simulation<D>, what: &str) {
    let params = sim.params();
    let w = params.substrate_width;
    let f = params.noise_reduction;
    let tol = tolerance::<D>(params) + 1e-9;
    let pos = sim.positions().unwrap();
    let parents = sim.parents().unwrap();
    assert_eq!(pos.len() as u64, params.particles, "{what}");
    let mut deposit = Deposit::new(D, w);
    let mut on_substrate = 0;
    for (i, p) in pos.iter().enumerate() {
        for x in &p[..D - 1] {
            assert!(
                *x >= -w / 2.0 && *x < w / 2.0,
                "{what}: {p:?} outside the strip"
            );
        }
        assert!(p[D - 1] >= -tol, "{what}: {p:?} below the substrate");
        let nearest = pos[..i]
            .iter()
            .map(|q| periodic_d2(p, q, w))
            .fold(f64::INFINITY, f64::min)
            .sqrt();
        assert!(
            nearest >= f - tol,
            "{what}: particle {i} {nearest} from another"
        );
        match parents[i] {
            -1 => {
                assert!(
                    p[D - 1].abs() <= tol,
                    "{what}: seedless particle {i} at {p:?}"
                );
                on_substrate += 1;
            }
            j => {
                assert!(j >= 0 && (j as usize) < i, "{what}: parent {j} of {i}");
                let d = periodic_d2(p, &pos[j as usize], w).sqrt();
                assert!(
                    (d - f).abs() <= tol,
                    "{what}: {i} is {d} from its parent {j}"
                );
            }
        }
        deposit.push(p, parents[i]).unwrap();
    }
    deposit.finish();
    assert!(on_substrate > 0);
    assert_eq!(deposit.trees(), on_substrate);
    assert_eq!(deposit.layers.iter().sum::<u64>(), params.particles);
}

/// Every variant on a substrate in 2D to 5D, strips narrow enough that many particles sit
/// across the periodic edges and have images.
#[test]
fn deposits_are_periodic_packings_of_trees_on_the_substrate() {
    fn each<const D: usize>(n: u64, width: f64)
    where
        Dim<D>: Space<D>,
    {
        let base = Params {
            particles: n,
            substrate_width: width,
            ..Params::default()
        };
        let variants = [
            ("plain", base.clone()),
            (
                "drift",
                Params {
                    drift: 1.5,
                    ..base.clone()
                },
            ),
            (
                "ballistic",
                Params {
                    ballistic: true,
                    ..base.clone()
                },
            ),
            (
                "sticky",
                Params {
                    sticking_probability: 0.2,
                    drift: 0.3,
                    ..base.clone()
                },
            ),
            (
                "reduced",
                Params {
                    noise_reduction: 0.5,
                    ..base.clone()
                },
            ),
        ];
        for (name, params) in variants {
            let sim = grow::<D>(params, 3);
            assert_deposit(&sim, &format!("{D}D {name}"));
        }
    }
    each::<2>(1200, 16.0);
    each::<3>(600, 9.0);
    each::<4>(300, 8.0);
    each::<5>(150, 8.0);
}

/// Ballistic deposition against a naive one on the same random stream: each particle drops
/// straight down from a uniform lateral position (one uniform per particle, as the engine
/// draws it) and stops at the highest contact over every particle and its periodic images, or
/// on the substrate. The engine's walk (jumps by distance bounds, steps, images, wrapping)
/// must find the same contacts: the same deposit to within rounding.
#[test]
fn ballistic_deposition_is_the_naive_drop_on_the_same_stream() {
    let (w, n, seed) = (20.0, 500u64, 5u64);
    let sim = grow::<2>(
        Params {
            particles: n,
            substrate_width: w,
            ballistic: true,
            ..Params::default()
        },
        seed,
    );
    let mut rng = stream(seed, stream_id(PURPOSE_WALK, 0));
    let mut naive: Vec<[f64; 2]> = Vec::new();
    for _ in 0..n {
        let x = (uniform01(&mut rng) - 0.5) * w;
        let mut z: f64 = 0.0;
        for q in &naive {
            let dx = (x - q[0]).abs();
            let dx = dx.min(w - dx);
            if dx < 1.0 {
                z = z.max(q[1] + (1.0 - dx * dx).sqrt());
            }
        }
        naive.push([x, z]);
    }
    let pos = sim.positions().unwrap();
    for (i, (a, b)) in pos.iter().zip(&naive).enumerate() {
        let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
        assert!(d < 1e-6, "particle {i}: engine {a:?}, naive {b:?}");
    }
}

/// Ballistic aggregation around a seed against a naive one on the same random stream: each
/// walker enters the birth sphere on its straight line ([`ballistic_start`], the engine's
/// draws) and stops at the first particle the line meets at distance 1; a line that meets
/// none is followed by the next walker.
#[test]
fn ballistic_aggregation_is_the_naive_ray_on_the_same_stream() {
    fn each<const D: usize>(n: u64, seed: u64)
    where
        Dim<D>: Space<D>,
    {
        let params = Params {
            particles: n,
            ballistic: true,
            ..Params::default()
        };
        let gap = params.birth_gap;
        let sim = grow::<D>(params, seed);
        let mut rng = stream(seed, stream_id(PURPOSE_WALK, 0));
        let mut naive: Vec<[f64; D]> = vec![[0.0; D]];
        let mut r_ext: f64 = 0.0;
        while (naive.len() as u64) < n {
            let (p, u) = ballistic_start::<D, _>(r_ext + gap, &mut rng, Dim::<D>::direction);
            let mut best = f64::INFINITY;
            for q in &naive {
                let w: [f64; D] = std::array::from_fn(|i| p[i] - q[i]);
                let b: f64 = (0..D).map(|i| w[i] * u[i]).sum();
                let c: f64 = (0..D).map(|i| w[i] * w[i]).sum::<f64>() - 1.0;
                let disc = b * b - c;
                if b < 0.0 && disc >= 0.0 {
                    best = best.min(-b - disc.sqrt());
                }
            }
            if best.is_finite() {
                let s: [f64; D] = std::array::from_fn(|i| p[i] + best * u[i]);
                r_ext = r_ext.max(s.iter().map(|x| x * x).sum::<f64>().sqrt());
                naive.push(s);
            }
        }
        let pos = sim.positions().unwrap();
        for (i, (a, b)) in pos.iter().zip(&naive).enumerate() {
            let d: f64 = (0..D).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
            assert!(d < 1e-6, "{D}D particle {i}: engine {a:?}, naive {b:?}");
        }
    }
    each::<2>(400, 1);
    each::<3>(300, 2);
}

/// Drift packs a deposit: over an ensemble, the mean density of the first 30 diameters grows
/// with the Péclet number from diffusion-limited deposition's towards ballistic deposition's,
/// each step well outside the ensemble's error.
#[test]
fn drift_moves_the_deposit_from_diffusion_limited_to_ballistic() {
    let density = |params: Params| -> (f64, f64) {
        let values: Vec<f64> = (1..=8)
            .map(|seed| {
                let sim = grow::<2>(params.clone(), seed);
                let below = sim
                    .positions()
                    .unwrap()
                    .iter()
                    .filter(|p| p[1] < 30.0)
                    .count();
                below as f64 / (30.0 * params.substrate_width)
            })
            .collect();
        let m = values.iter().sum::<f64>() / values.len() as f64;
        let var = values.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (values.len() - 1) as f64;
        (m, (var / values.len() as f64).sqrt())
    };
    let base = Params {
        particles: 3000,
        substrate_width: 64.0,
        ..Params::default()
    };
    let plain = density(base.clone());
    let drift = density(Params {
        drift: 2.0,
        ..base.clone()
    });
    let ballistic = density(Params {
        ballistic: true,
        ..base
    });
    let apart = |a: (f64, f64), b: (f64, f64)| (b.0 - a.0) / (a.1 * a.1 + b.1 * b.1).sqrt();
    assert!(apart(plain, drift) > 4.0, "{plain:?} {drift:?}");
    assert!(apart(drift, ballistic) > 4.0, "{drift:?} {ballistic:?}");
}

/// A deposit with drift, sticking probability and noise reduction, checkpointed midway and
/// resumed, ends with the uninterrupted run's state hash; likewise radial ballistic growth.
#[test]
fn resumed_deposits_and_ballistic_runs_are_the_uninterrupted_ones() {
    let deposit = Params {
        particles: 1500,
        substrate_width: 24.0,
        drift: 0.7,
        sticking_probability: 0.5,
        noise_reduction: 0.8,
        ..Params::default()
    };
    let ballistic = Params {
        particles: 1500,
        ballistic: true,
        ..Params::default()
    };
    for params in [deposit, ballistic] {
        let mut whole = Simulation::<2>::new(params.clone(), 4).unwrap();
        whole.run().unwrap();
        let dir = tempfile::tempdir().unwrap();
        let mut sim = Simulation::<2>::new(
            Params {
                connectivity: true,
                ..params.clone()
            },
            4,
        )
        .unwrap();
        sim.stream_into(dir.path(), true).unwrap();
        for _ in 0..600 {
            sim.add_one().unwrap();
        }
        sim.write_checkpoint().unwrap();
        let at = sim.particles();
        for _ in 0..30 {
            sim.add_one().unwrap();
        }
        sim.sync_streams().unwrap();
        drop(sim);
        let mut resumed = Simulation::<2>::resume(dir.path(), None).unwrap();
        assert_eq!(resumed.particles(), at);
        resumed.stream_into(dir.path(), true).unwrap();
        resumed.run().unwrap();
        assert_eq!(resumed.state_hash(), whole.state_hash(), "{params:?}");
    }
}

/// The map window of a tall, narrow deposit moves up with its top: the maps stay small (a
/// deposit 20 times taller than wide), and the near cache and the maps change only the
/// speed of the walk, not its physics (no overlap with them off).
#[test]
fn a_tall_deposit_keeps_its_maps_small_and_valid() {
    let params = Params {
        particles: 6000,
        substrate_width: 8.0,
        drift: 0.2,
        ..Params::default()
    };
    let sim = grow::<2>(params.clone(), 9);
    assert!(sim.r_ext() > 160.0, "height {}", sim.r_ext());
    assert_deposit(&sim, "tall");
    let maps = sim.cluster().memory_bytes() - sim.tree().memory_bytes();
    assert!(maps < 1 << 20, "maps of {maps} bytes");
    let off = grow::<2>(
        Params {
            distance_map: false,
            near_cache: false,
            particles: 1500,
            ..params
        },
        9,
    );
    assert_deposit(&off, "tall, maps off");
}

/// A seed set read back from every positions format `dla` writes is the cluster that wrote
/// it, and growth from it stores the seeds first, with parent -1, then particles that each
/// touch an earlier one; with a substrate too. Bad sets are refused with their reason.
#[test]
fn growth_from_a_seed_set_in_every_format() {
    use dla_pdla::output::{PositionsFormat, write_outputs};
    use run_io::RunClock;
    let dir = tempfile::tempdir().unwrap();
    let mut first = Simulation::<2>::new(
        Params {
            particles: 300,
            keep_positions: true,
            connectivity: true,
            ..Params::default()
        },
        3,
    )
    .unwrap();
    first.stream_into(dir.path(), true).unwrap();
    first.run().unwrap();
    first.sync_streams().unwrap();
    let clock = RunClock::start();
    let want = first.positions().unwrap().to_vec();
    for format in [
        PositionsFormat::Csv,
        PositionsFormat::Bin,
        PositionsFormat::Xyz,
        PositionsFormat::Vtk,
    ] {
        write_outputs(&first, &clock, dir.path(), format, None).unwrap();
    }
    for ext in ["npy", "csv", "bin", "xyz", "vtk"] {
        let path = dir.path().join(format!("positions.{ext}"));
        let got = dla_pdla::seeds::read::<2>(&path).unwrap();
        assert_eq!(got, want, "{ext}");
    }
    // Growth on the set: the seeds first, then every particle touching an earlier one.
    let set = dla_pdla::params::SeedSet(dir.path().join("positions.bin").display().to_string());
    let sim = grow::<2>(
        Params {
            particles: 800,
            seed_set: Some(set.clone()),
            ..Params::default()
        },
        4,
    );
    let pos = sim.positions().unwrap();
    assert_eq!(&pos[..300], &want[..]);
    assert!(sim.parents().unwrap()[..300].iter().all(|&p| p == -1));
    let tol = tolerance::<2>(sim.params());
    for i in 300..800 {
        let parent = sim.parents().unwrap()[i] as usize;
        let d = (0..2)
            .map(|a| (pos[i][a] - pos[parent][a]).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!((d - 1.0).abs() <= tol, "{i}: {d}");
    }
    // A line of seeds above a substrate: a deposit growing on it and on the substrate.
    let line = dir.path().join("line.csv");
    let rows: Vec<String> = (0..10)
        .map(|i| format!("{},{}", i as f64 - 5.0, 6.0))
        .collect();
    std::fs::write(&line, format!("x,y\n{}\n", rows.join("\n"))).unwrap();
    let sim = grow::<2>(
        Params {
            particles: 600,
            substrate_width: 16.0,
            seed_set: Some(dla_pdla::params::SeedSet(line.display().to_string())),
            ..Params::default()
        },
        5,
    );
    assert!(sim.parents().unwrap()[..10].iter().all(|&p| p == -1));
    // The bad: a missing file, a foreign extension, the wrong dimension, a seed below the
    // substrate, more seeds than particles.
    let bad = |params: Params| {
        Simulation::<2>::new(params, 1)
            .map(|_| ())
            .unwrap_err()
            .to_string()
    };
    let with = |path: &str| Params {
        seed_set: Some(dla_pdla::params::SeedSet(path.into())),
        ..Params::default()
    };
    assert!(bad(with("/nonexistent/seeds.npy")).starts_with("--seed-set /nonexistent/seeds.npy: "));
    assert!(bad(with("seeds.txt")).contains("not a positions file"));
    let e = Simulation::<3>::new(
        Params {
            dim: 3,
            ..with(&set.0)
        },
        1,
    )
    .map(|_| ())
    .unwrap_err()
    .to_string();
    assert!(e.contains("2D positions, not 3D"), "{e}");
    let low = dir.path().join("low.csv");
    std::fs::write(&low, "x,y\n0,-2\n").unwrap();
    let e = bad(Params {
        substrate_width: 16.0,
        ..with(&low.display().to_string())
    });
    assert!(e.contains("not in the strip"), "{e}");
    let e = bad(Params {
        particles: 100,
        ..with(&set.0)
    });
    assert!(e.contains("300 seeds, more than --particles 100"), "{e}");
}

/// The largest distance between the empirical CDF of `x` (sorted) and `cdf`.
fn ks_one_sample(x: &[f64], cdf: impl Fn(f64) -> f64) -> f64 {
    let n = x.len() as f64;
    x.iter()
        .enumerate()
        .map(|(i, &v)| {
            let f = cdf(v);
            (f - i as f64 / n).abs().max((f - (i + 1) as f64 / n).abs())
        })
        .fold(0.0, f64::max)
}

/// The largest distance between the empirical CDFs of `a` and `b` (both sorted).
fn ks_two_sample(a: &[f64], b: &[f64]) -> f64 {
    let (mut i, mut j, mut d) = (0, 0, 0f64);
    while i < a.len() && j < b.len() {
        if a[i] <= b[j] {
            i += 1;
        } else {
            j += 1;
        }
        d = d.max((i as f64 / a.len() as f64 - j as f64 / b.len() as f64).abs());
    }
    d
}

/// The walk itself against the exact law of Brownian motion: the first particle of a deposit
/// starts on the launch plane, 5 diameters above the substrate's contact plane, at the
/// lateral position the run's first uniform draw gives, and lands where its path first
/// reaches the substrate. Without drift that lateral displacement is Cauchy with scale 5
/// (the half-plane's Poisson kernel); with drift v = Pe / 2 it is Gaussian with the variance
/// of the first-passage time, here from a plain Euler simulation of the drifting motion in
/// steps of 1e-3 (independent of the engine's samplers). The engine gets there by jumps of
/// the drift's exact exit law, steps near the substrate and, when the walker rises above the
/// launch plane, the exact return: one-sample and two-sample Kolmogorov-Smirnov tests at the
/// 0.1 % level (critical distances 0.098 for 400 runs, and 0.102 against 4 000 references).
#[test]
fn a_walker_reaches_the_substrate_where_brownian_motion_does() {
    let w = 1e4;
    let displacement = |pe: f64, seed: u64| -> f64 {
        let sim = grow::<2>(
            Params {
                particles: 1,
                substrate_width: w,
                drift: pe,
                ..Params::default()
            },
            seed,
        );
        let mut rng = stream(seed, stream_id(PURPOSE_WALK, 0));
        let x0 = (uniform01(&mut rng) - 0.5) * w;
        let x = sim.positions().unwrap()[0][0];
        assert_eq!(sim.positions().unwrap()[0][1], 0.0);
        x - x0
    };
    let mut plain: Vec<f64> = (1..=400).map(|s| displacement(0.0, s)).collect();
    plain.sort_by(f64::total_cmp);
    let d = ks_one_sample(&plain, |x| 0.5 + (x / 5.0).atan() / std::f64::consts::PI);
    eprintln!("no drift: KS distance {d:.4} from the Cauchy law");
    assert!(d < 0.098, "no drift: KS distance {d} from the Cauchy law");
    // Drift Pe = 0.5: v = 0.25, mean first-passage time 20.
    let pe = 0.5;
    let mut drift: Vec<f64> = (1..=400).map(|s| displacement(pe, s)).collect();
    drift.sort_by(f64::total_cmp);
    let mut rng = stream(77, 3);
    let normal = |rng: &mut _| dla_pdla::substrate::normal_pair(rng).0;
    let dt: f64 = 1e-3;
    let mut reference: Vec<f64> = (0..4000)
        .map(|_| {
            let (mut x, mut z) = (0.0, 5.0);
            while z > 0.0 {
                x += dt.sqrt() * normal(&mut rng);
                z += -0.5 * pe * dt + dt.sqrt() * normal(&mut rng);
            }
            x
        })
        .collect();
    reference.sort_by(f64::total_cmp);
    let d = ks_two_sample(&drift, &reference);
    eprintln!("drift: KS distance {d:.4} from the Euler reference");
    assert!(d < 0.102, "drift: KS distance {d} from the Euler reference");
    // The test can fail: the drifting walkers are not the plain ones.
    let d = ks_two_sample(&plain, &reference);
    eprintln!("plain against the drift's reference: KS distance {d:.4}");
    assert!(d > 0.102, "plain against drift: KS distance {d}");
}
