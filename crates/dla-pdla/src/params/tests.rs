//! The range checks, their messages and the refusals of `Params`.

use super::*;

#[test]
fn defaults_are_valid_and_bad_values_are_named() {
    assert!(Params::default().validate().is_ok());
    let d = Params::default;
    let bad = [
        (Params { dim: 6, ..d() }, "--dim 6 ", "{2, 3, 4, 5}"),
        (Params { dim: 1, ..d() }, "--dim 1 ", "{2, 3, 4, 5}"),
        (
            Params {
                particles: 0,
                ..d()
            },
            "--particles 0 ",
            "1..=",
        ),
        (
            Params {
                precision: 0.0,
                ..d()
            },
            "--precision 0 ",
            "(0.5, inf]",
        ),
        (
            Params {
                precision: f64::NAN,
                ..d()
            },
            "--precision NaN ",
            "(0.5, inf]",
        ),
        (
            Params {
                step_min: 0.0,
                ..d()
            },
            "--step-min 0 ",
            "[1e-6, 1e3]",
        ),
        (
            Params {
                step_min: -1.0,
                ..d()
            },
            "--step-min -1 ",
            "[1e-6, 1e3]",
        ),
        (
            Params {
                step_min: 1e-300,
                ..d()
            },
            "--step-min 1e-300 ",
            "[1e-6, 1e3] (a step below",
        ),
        (Params { threads: 0, ..d() }, "--threads 0 ", "1..=1024"),
        (
            Params {
                birth_gap: 0.5,
                ..d()
            },
            "--birth-gap 0.5 ",
            "[1, 1e4]",
        ),
        (
            Params {
                death_ratio: 1.0,
                ..d()
            },
            "--death-ratio 1 ",
            "(1, 1e100]",
        ),
        (
            Params {
                leaf_side: 3.0,
                ..d()
            },
            "--leaf-side 3 ",
            "{1, 2, 4",
        ),
        (
            Params {
                leaf_side: 128.0,
                ..d()
            },
            "--leaf-side 128 ",
            "{1, 2, 4",
        ),
        (
            Params {
                sticking_probability: 0.0,
                ..d()
            },
            "--sticking-probability 0 ",
            "(0, 1] (a probability",
        ),
        (
            Params {
                sticking_probability: f64::NAN,
                ..d()
            },
            "--sticking-probability NaN ",
            "(0, 1]",
        ),
        (
            Params {
                noise_reduction: 1.5,
                ..d()
            },
            "--noise-reduction 1.5 ",
            "(0, 1] (the stored particle",
        ),
        (
            Params {
                noise_reduction: -0.5,
                ..d()
            },
            "--noise-reduction -0.5 ",
            "(0, 1]",
        ),
    ];
    for (p, flag, range) in bad {
        let e = p.validate().unwrap_err().to_string();
        // The message names the flag, the bad value and the accepted range.
        assert!(e.starts_with(flag), "{e}");
        assert!(e.contains(&format!("accepted range {range}")), "{e}");
    }
    let inf = Params {
        precision: f64::INFINITY,
        ..Params::default()
    };
    assert!(inf.validate().is_ok());
    for &dim in DIMENSIONS {
        assert!(Params { dim, ..d() }.validate().is_ok());
        let max = max_particles(dim);
        assert!(max > 1_000_000_000, "{dim}D: {max}");
        let top = Params {
            dim,
            particles: max,
            ..d()
        };
        assert!(top.validate().is_ok());
        let e = Params {
            particles: max + 1,
            ..top
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert_eq!(
            e,
            format!(
                "--particles {} is outside the accepted range 1..={max} in {dim}D (the orthtree's 32-bit indices)",
                max + 1
            )
        );
    }
    assert_eq!(max_particles(6), 0);
}

/// A deposit's estimate counts its images: twice the particles on a strip of twice the
/// margin (every particle near an edge), about 1.06 times on a wide one, and four times
/// in 3D on the narrow strip.
#[test]
fn a_deposit_estimate_counts_the_images() {
    let at = |dim: usize, w: f64| {
        Params {
            dim,
            substrate_width: w,
            ..Params::default()
        }
        .peak_bytes_per_particle()
    };
    assert_eq!(at(2, 0.0), 14);
    assert_eq!(at(2, 64.0), 28 + DEPOSIT_BYTES_PER_PARTICLE);
    assert_eq!(at(2, 1000.0), 15 + DEPOSIT_BYTES_PER_PARTICLE);
    assert_eq!(at(3, 64.0), 104 + DEPOSIT_BYTES_PER_PARTICLE);
}

#[test]
fn flags_the_run_would_ignore_are_refused() {
    let d = Params::default;
    assert_eq!(d().validate_given(|_| false), Ok(()));
    assert_eq!(
        d().validate_given(|n| n == "death_ratio"),
        Err(ParamsError::DeathRatioUnused)
    );
    let jump = Params {
        far_field: FarField::Jump,
        ..d()
    };
    assert_eq!(jump.validate_given(|n| n == "death_ratio"), Ok(()));
    let serial = Params {
        serial_until: 100,
        ..d()
    };
    let e = serial.validate_given(|_| false).unwrap_err().to_string();
    assert!(
        e.starts_with("--serial-until 100 is used with --threads > 1"),
        "{e}"
    );
    assert_eq!(
        Params {
            threads: 2,
            ..serial
        }
        .validate_given(|_| false),
        Ok(())
    );
    // Range errors come first, as from `validate`.
    let e = Params { threads: 0, ..d() }
        .validate_given(|n| n == "death_ratio")
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "--threads 0 is outside the accepted range 1..=1024"
    );
}
