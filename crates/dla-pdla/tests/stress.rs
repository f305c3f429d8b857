//! Numerical stability of `dla` at the edges of every accepted range: each case either runs to
//! a correct cluster (every particle in contact with an earlier one, none overlapping, every
//! coordinate finite) or is refused with a message naming the flag and its range. The usage
//! errors of ordinary bad values (`--step-min 0`, `--precision 0.5`, a damaged checkpoint, ...)
//! are in `tests/bad_input.rs`; this suite adds the extremes:
//!
//! | case | why it could fail |
//! |---|---|
//! | `--far-field jump` with `--death-ratio` 1e20 and 1e100 (the largest accepted), with the largest birth gap | the death radius `death_ratio * R_b` overflowed to infinity at 1e300, so no walker was ever relaunched and coordinates overflowed to NaN (a hang); walkers far out jump by `|p| - R_ext - 1` |
//! | `--birth-gap` 1 and 1e4 (the largest accepted), serial and PDLA | a walker born one diameter out may start in contact; a PDLA run sized its shared distance maps to cover the birth sphere, `(gap / 8)^3` bytes in 3D (16 GB at 1e4, an abort at 1e9); in 3D the walk takes about `gap / R_ext` times longer, hence the cap |
//! | `--step-min` 1e-6 and 1e3 | a step below the rounding of the coordinates never moves; a step of 1e3 diameters scans most of a small cluster per step |
//! | `--precision` just above 0.5, 1e300 and `inf` | `vpdist`'s bound tends to 0 as kappa falls to 1/2 (tiny jumps, near cache off); 1e300 must be the exact search, as `inf` |
//! | the radius of gyration of a cluster 1e12 from the origin, against exact integer sums | a running mean kept at the coordinates' magnitude loses digits to their spacing (2e-5 relative error at radius 10); merged halves too |
//! | the particle limit | the orthtree's 32-bit indices: `MAX_PARTICLES + 1` refused by name, `MAX_PARTICLES` accepted without allocating, and the arithmetic behind the limit (slots per particle) checked on grown clusters |
//! | NaN, infinities and out-of-range values in every float flag | must be refused with exit code 2 naming the flag |
//! | a checkpoint's `positions.npy` with NaN, infinity, 1e300 or 1e6 in a row | the rows were stored before the log was checked against the checkpoint's hash: a row 1e6 out sized the distance maps for it (a 62 GB allocation, an abort) |
//! | runs of 1 and 2 particles | no fit, radii 0 and 1/2: finite outputs, no panic |

mod common;

use common::check_contacts;
use core_lattice::Gyration;
use dla_pdla::params::{MAX_BIRTH_GAP, MAX_DEATH_RATIO, MAX_PARTICLES};
use dla_pdla::sim::POSITIONS_FILE;
use dla_pdla::{Dim, FarField, Params, ParamsError, SimError, Simulation, Space};
use run_cli::testing::refusals;
use spatial::distmap::PointMap;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// Grows `params` (positions kept) and checks the cluster: the target size, every coordinate
/// finite, no two centres closer than 1 - 1e-6, every particle within 1 + 1e-6 of an earlier
/// one.
fn grow_valid<const D: usize>(params: Params, seed: u64) -> Simulation<D>
where
    Dim<D>: Space<D>,
{
    let what = format!("{params:?}");
    let mut sim = Simulation::<D>::new(
        Params {
            dim: D,
            keep_positions: true,
            ..params
        },
        seed,
    )
    .unwrap_or_else(|e| panic!("{what}: {e}"));
    sim.run().unwrap_or_else(|e| panic!("{what}: {e}"));
    let pos = sim.positions().unwrap();
    assert_eq!(pos.len() as u64, sim.params().particles, "{what}");
    assert!(pos.iter().flatten().all(|x| x.is_finite()), "{what}");
    let (min_pair, max_contact) = check_contacts(pos);
    assert!(min_pair >= 1.0 - 1e-6, "{what}: two centres at {min_pair}");
    assert!(
        max_contact <= 1.0 + 1e-6,
        "{what}: a particle {max_contact} from every earlier one"
    );
    assert!(sim.radius_of_gyration().is_finite() && sim.r_ext().is_finite());
    sim
}

#[test]
fn death_ratio_extremes_run_and_larger_ones_are_refused() {
    for death_ratio in [1e20, MAX_DEATH_RATIO] {
        let jump = |particles, birth_gap| Params {
            particles,
            far_field: FarField::Jump,
            death_ratio,
            birth_gap,
            ..Params::default()
        };
        grow_valid::<2>(jump(400, 5.0), 1);
        grow_valid::<3>(jump(400, 5.0), 1);
        // The largest death radius: 1e100 * (1e4 + R_ext), still finite with room to spare.
        grow_valid::<2>(jump(200, MAX_BIRTH_GAP), 2);
    }
    for bad in [MAX_DEATH_RATIO * 10.0, 1e300, f64::INFINITY, f64::NAN, 1.0] {
        let e = Params {
            far_field: FarField::Jump,
            death_ratio: bad,
            ..Params::default()
        }
        .validate()
        .unwrap_err();
        assert!(
            matches!(&e, ParamsError::Range(r) if r.flag == "--death-ratio"),
            "{bad}: {e}"
        );
        let text = e.to_string();
        assert!(
            text.starts_with("--death-ratio ") && text.contains("accepted range (1, 1e100]"),
            "{text}"
        );
    }
}

#[test]
fn birth_gap_extremes_run_and_pdla_maps_stay_small() {
    grow_valid::<2>(
        Params {
            particles: 500,
            birth_gap: 1.0,
            ..Params::default()
        },
        3,
    );
    grow_valid::<3>(
        Params {
            particles: 500,
            birth_gap: 1.0,
            ..Params::default()
        },
        3,
    );
    grow_valid::<2>(
        Params {
            particles: 300,
            birth_gap: MAX_BIRTH_GAP,
            ..Params::default()
        },
        4,
    );
    // In 3D each walker needs about gap / R_ext excursions: a few dozen particles suffice.
    grow_valid::<3>(
        Params {
            particles: 30,
            birth_gap: MAX_BIRTH_GAP,
            ..Params::default()
        },
        4,
    );
    // PDLA shares distance maps sized for the particles, not for the birth sphere: at the
    // largest gap in 3D that would be (2e4 / 8)^3 bytes.
    let sim = grow_valid::<3>(
        Params {
            particles: 40,
            threads: 2,
            serial_until: 30,
            birth_gap: MAX_BIRTH_GAP,
            ..Params::default()
        },
        5,
    );
    let maps: usize = sim.cluster().maps().iter().map(|m| m.memory_bytes()).sum();
    assert!(maps < 64 << 20, "PDLA distance maps of {maps} bytes");
    for bad in [0.5, MAX_BIRTH_GAP * 1.001, 1e9, f64::INFINITY, f64::NAN] {
        let e = Params {
            birth_gap: bad,
            ..Params::default()
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("--birth-gap ") && e.contains("accepted range [1, 1e4]"),
            "{e}"
        );
    }
}

#[test]
fn step_min_extremes_give_valid_clusters() {
    for step_min in [dla_pdla::params::MIN_STEP_MIN, 1e3] {
        let p = Params {
            particles: 300,
            step_min,
            ..Params::default()
        };
        grow_valid::<2>(p.clone(), 6);
        grow_valid::<3>(p, 6);
    }
}

#[test]
fn precision_extremes_give_valid_clusters_and_1e300_is_exact() {
    let p = |precision| Params {
        particles: 400,
        precision,
        ..Params::default()
    };
    grow_valid::<2>(p(0.5 + 1e-9), 7);
    grow_valid::<3>(p(0.5 + 1e-9), 7);
    // No node is ever "far" for a kappa beyond any distance ratio: the exact search.
    assert_eq!(
        grow_valid::<2>(p(1e300), 8).state_hash(),
        grow_valid::<2>(p(f64::INFINITY), 8).state_hash()
    );
    assert_eq!(
        grow_valid::<3>(p(1e300), 8).state_hash(),
        grow_valid::<3>(p(f64::INFINITY), 8).state_hash()
    );
}

/// `N^2 R_g^2 = N sum |x|^2 - |sum x|^2` of integer points, exactly in `i128`.
fn exact_rg2(pts: &[[i64; 3]]) -> f64 {
    let n = pts.len() as i128;
    let mut num = 0i128;
    for a in 0..3 {
        let s: i128 = pts.iter().map(|p| i128::from(p[a])).sum();
        let s2: i128 = pts.iter().map(|p| i128::from(p[a]).pow(2)).sum();
        num += n * s2 - s * s;
    }
    num as f64 / (n * n) as f64
}

#[test]
fn radius_of_gyration_far_from_the_origin_matches_exact_sums() {
    // Integer offsets (exact in f64 at 1e12, whose spacing is 1.2e-4) from centres 1e12 and
    // 3e12 from the origin, so the reference is exact.
    let centre = [1e12, -1e12, 3e12];
    let mut rng = core_lattice::rng::stream(9, 0);
    for (spread, n) in [(1u64, 20_000usize), (10, 100_000), (1000, 100_000)] {
        let pts: Vec<[i64; 3]> = (0..n)
            .map(|_| {
                std::array::from_fn(|_| {
                    (core_lattice::rng::uniform01(&mut rng) * (2 * spread + 1) as f64).floor()
                        as i64
                        - spread as i64
                })
            })
            .collect();
        let far = |p: &[i64; 3]| -> [f64; 3] { std::array::from_fn(|a| centre[a] + p[a] as f64) };
        let exact = exact_rg2(&pts);
        let mut g = Gyration::<3>::new();
        pts.iter().for_each(|p| g.push(&far(p)));
        let rel = (g.radius_squared() - exact).abs() / exact;
        assert!(rel < 1e-12, "spread {spread}: relative error {rel:e}");
        // Halves accumulated apart (as PDLA threads would) and merged.
        let (mut a, mut b) = (Gyration::<3>::new(), Gyration::<3>::new());
        pts[..n / 3].iter().for_each(|p| a.push(&far(p)));
        pts[n / 3..].iter().for_each(|p| b.push(&far(p)));
        a.merge(&b);
        let rel = (a.radius_squared() - exact).abs() / exact;
        assert!(
            rel < 1e-12,
            "spread {spread}, merged: relative error {rel:e}"
        );
        // The centre of mass, to the spacing of the coordinates there.
        for axis in 0..3 {
            let mean = pts.iter().map(|p| p[axis] as f64).sum::<f64>() / n as f64;
            assert!((g.centre()[axis] - (centre[axis] + mean)).abs() <= 1e-3);
        }
    }
}

#[test]
fn particle_limit_is_refused_by_name_and_its_arithmetic_holds() {
    // Accepted without allocating for it (nothing is reserved before growth).
    let sim = Simulation::<2>::new(
        Params {
            particles: MAX_PARTICLES,
            ..Params::default()
        },
        1,
    )
    .unwrap();
    assert_eq!(sim.particles(), 1);
    let e = Params {
        particles: MAX_PARTICLES + 1,
        ..Params::default()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        format!(
            "--particles {} is outside the accepted range 1..={MAX_PARTICLES} in 2D (the orthtree's 32-bit indices)",
            MAX_PARTICLES + 1
        )
    );
    // The bound of `MAX_PARTICLES`: blocks of at most 1.25 n slots for a leaf of n points, at
    // most 1/8 of the pool (or 2^16 slots) free before it is compacted.
    let index_limit = f64::from(u32::MAX - 1);
    assert!(MAX_PARTICLES as f64 * 1.25 * 8.0 / 7.0 + 65536.0 <= index_limit);
    // The per-leaf bound on grown clusters, with leaves of a few points (smallest leaf side)
    // and of hundreds (largest); leaves and nodes stay below one per particle.
    for leaf_side in [1.0, 64.0] {
        let n = 3000;
        let p = Params {
            particles: n,
            leaf_side,
            ..Params::default()
        };
        let two = grow_valid::<2>(p.clone(), 10).tree().stats();
        let three = grow_valid::<3>(p, 10).tree().stats();
        for s in [two, three] {
            let used = (s.point_slots - s.free_slots) as f64;
            assert!(
                used <= 1.25 * n as f64,
                "leaf side {leaf_side}: {used} slots in use"
            );
            assert!(s.leaves as u64 <= n && (s.nodes as u64) < n, "{s:?}");
        }
    }
}

const DLA: &str = env!("CARGO_BIN_EXE_dla");

#[test]
fn float_flags_refuse_nan_infinity_and_out_of_range_values() {
    let tmp = tempfile::tempdir().unwrap();
    let base = ["--particles", "100", "--out", "out"];
    let cases: Vec<(Vec<&str>, &str)> = [
        (vec!["--birth-gap", "NaN"], "--birth-gap NaN"),
        (vec!["--birth-gap", "inf"], "--birth-gap inf"),
        (vec!["--birth-gap", "-inf"], "--birth-gap -inf"),
        (vec!["--birth-gap", "1e9"], "--birth-gap 1000000000"),
        (
            vec!["--far-field", "jump", "--death-ratio", "NaN"],
            "--death-ratio NaN",
        ),
        (
            vec!["--far-field", "jump", "--death-ratio", "inf"],
            "--death-ratio inf",
        ),
        (
            vec!["--far-field", "jump", "--death-ratio", "1e300"],
            "--death-ratio 1e300",
        ),
        (vec!["--step-min", "inf"], "--step-min inf"),
        (vec!["--step-min", "1001"], "--step-min 1001"),
        (vec!["--precision", "-inf"], "--precision -inf"),
        (vec!["--precision", "NaN"], "--precision NaN"),
        (vec!["--leaf-side", "NaN"], "--leaf-side NaN"),
        (vec!["--leaf-side", "inf"], "--leaf-side inf"),
        (vec!["--particles", "3000000001"], "--particles 3000000001"),
    ]
    .into_iter()
    .map(|(extra, culprit)| {
        let mut v = base.to_vec();
        v.extend(extra);
        (v, culprit)
    })
    .collect();
    let cases: Vec<(&[&str], &str)> = cases.iter().map(|(a, c)| (a.as_slice(), *c)).collect();
    let failures = refusals(Path::new(DLA), "dla", tmp.path(), &cases);
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn damaged_positions_logs_are_refused_before_anything_is_built() {
    let tmp = tempfile::tempdir().unwrap();
    let good = tmp.path().join("good");
    std::fs::create_dir(&good).unwrap();
    let mut sim = Simulation::<2>::new(
        Params {
            particles: 300,
            ..Params::default()
        },
        1,
    )
    .unwrap();
    sim.stream_into(&good, true).unwrap();
    assert!(
        sim.run_checkpointed(100, &AtomicBool::new(false), &|_| {})
            .unwrap()
    );
    assert!(Simulation::<2>::resume(&good, None).is_ok());
    // `.npy`: a 128-byte header, then the rows as little-endian float64.
    let row = |i: usize, axis: usize| 128 + (2 * i + axis) * 8;
    for (name, value) in [
        ("nan", f64::NAN),
        ("inf", f64::INFINITY),
        ("huge", 1e300),
        ("far", 1e6),
        ("near", 3.0),
    ] {
        let dir = tmp.path().join(name);
        std::fs::create_dir(&dir).unwrap();
        for f in ["checkpoint.bin", POSITIONS_FILE] {
            std::fs::copy(good.join(f), dir.join(f)).unwrap();
        }
        let mut bytes = std::fs::read(dir.join(POSITIONS_FILE)).unwrap();
        let at = row(150, 0);
        bytes[at..at + 8].copy_from_slice(&value.to_le_bytes());
        std::fs::write(dir.join(POSITIONS_FILE), bytes).unwrap();
        match Simulation::<2>::resume(&dir, None) {
            Err(SimError::CheckpointUsage(m)) => {
                assert!(
                    m.contains("does not belong to the checkpoint"),
                    "{name}: {m}"
                )
            }
            Err(e) => panic!("{name}: {e}"),
            Ok(_) => panic!("{name}: a damaged log was accepted"),
        }
    }
}

#[test]
fn runs_of_one_and_two_particles_have_finite_results() {
    let one = grow_valid::<2>(
        Params {
            particles: 1,
            ..Params::default()
        },
        1,
    );
    assert_eq!((one.radius_of_gyration(), one.r_ext()), (0.0, 0.0));
    assert!(one.fractal_dimension().is_err());
    let two = grow_valid::<3>(
        Params {
            particles: 2,
            fit_from: 2,
            ..Params::default()
        },
        1,
    );
    assert!((two.radius_of_gyration() - 0.5).abs() < 1e-6);
    assert!((two.r_ext() - 1.0).abs() < 1e-6);
    assert!(two.fractal_dimension().is_err());
}
