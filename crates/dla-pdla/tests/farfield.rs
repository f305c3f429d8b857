//! Kolmogorov-Smirnov tests of the exact far-field return samplers against the harmonic
//! densities (Poisson kernels of the circle and the sphere), integrated numerically (so the test
//! does not reuse the sampler's closed-form inversion). The hit point is measured from the returned
//! position, relative to the walker's direction, so a sampler that hits the wrong side fails.

use core_lattice::rng::stream;
use dla_pdla::{Dim, Space};
use std::f64::consts::PI;

/// Numerical CDF on a fine grid of `density` over `[a, b]` (trapezoid rule), normalised.
fn cdf_table(density: impl Fn(f64) -> f64, a: f64, b: f64, m: usize) -> Vec<(f64, f64)> {
    let h = (b - a) / m as f64;
    let mut out = vec![(a, 0.0)];
    let mut acc = 0.0;
    for i in 0..m {
        let x0 = a + i as f64 * h;
        acc += 0.5 * h * (density(x0) + density(x0 + h));
        out.push((x0 + h, acc));
    }
    let total = acc;
    out.iter_mut().for_each(|(_, c)| *c /= total);
    out
}

fn cdf_at(table: &[(f64, f64)], x: f64) -> f64 {
    let i = table.partition_point(|&(t, _)| t < x);
    if i == 0 {
        return 0.0;
    }
    if i >= table.len() {
        return 1.0;
    }
    let ((x0, c0), (x1, c1)) = (table[i - 1], table[i]);
    c0 + (c1 - c0) * (x - x0) / (x1 - x0)
}

/// KS statistic of `samples` against `table`.
fn ks(mut samples: Vec<f64>, table: &[(f64, f64)]) -> f64 {
    samples.sort_by(f64::total_cmp);
    let n = samples.len() as f64;
    let mut d: f64 = 0.0;
    for (i, &x) in samples.iter().enumerate() {
        let f = cdf_at(table, x);
        d = d
            .max((f - i as f64 / n).abs())
            .max(((i + 1) as f64 / n - f).abs());
    }
    d
}

/// Critical KS distance at significance 1e-3: 1.95 / sqrt(n).
fn critical(n: usize) -> f64 {
    1.95 / (n as f64).sqrt()
}

/// Asserts that `samples` (drawn for the distance ratio `x`) pass the KS test against `table`.
fn assert_ks_below_critical(samples: Vec<f64>, table: &[(f64, f64)], x: f64) {
    let n = samples.len();
    let d = ks(samples, table);
    assert!(
        d < critical(n),
        "x = {x}: KS distance {d} >= {}",
        critical(n)
    );
}

#[test]
fn ks_2d_return_angle_matches_harmonic_density() {
    let n = 20_000;
    for (k, &x) in [1.05f64, 1.5, 4.0].iter().enumerate() {
        let big_r = 10.0;
        let mut rng = stream(42, k as u64);
        let density = |phi: f64| (x * x - 1.0) / (2.0 * PI * (x * x - 2.0 * x * phi.cos() + 1.0));
        let table = cdf_table(density, -PI, PI, 200_000);
        let samples: Vec<f64> = (0..n)
            .map(|i| {
                let a = 0.37 * i as f64;
                let p = [x * big_r * a.cos(), x * big_r * a.sin()];
                let q = Dim::<2>::return_to_sphere(&p, big_r, &mut rng);
                assert!(((q[0].hypot(q[1])) - big_r).abs() < 1e-9);
                let mut phi = q[1].atan2(q[0]) - a;
                while phi > PI {
                    phi -= 2.0 * PI;
                }
                while phi < -PI {
                    phi += 2.0 * PI;
                }
                phi
            })
            .collect();
        assert_ks_below_critical(samples, &table, x);
    }
}

#[test]
fn ks_3d_return_matches_harmonic_measure() {
    let n = 40_000;
    for (k, &x) in [1.1f64, 2.0, 5.0].iter().enumerate() {
        let big_r = 7.0;
        let r = x * big_r;
        let mut rng = stream(43, k as u64);
        // Harmonic measure of the sphere seen from r: density in u = cos(theta) proportional to
        // (r^2 - R^2) / (r^2 + R^2 - 2 r R u)^(3/2) for hits (total mass R / r); escapes are
        // relaunched uniformly (density 1/2 in u).
        let hit = big_r / r;
        let norm_hit = cdf_table(
            |u| (r * r - big_r * big_r) / (r * r + big_r * big_r - 2.0 * r * big_r * u).powf(1.5),
            -1.0,
            1.0,
            100_000,
        );
        let table: Vec<(f64, f64)> = norm_hit
            .iter()
            .map(|&(u, c)| (u, hit * c + (1.0 - hit) * (u + 1.0) / 2.0))
            .collect();
        let samples: Vec<f64> = (0..n)
            .map(|i| {
                let (th, ph) = (0.3 + (i % 7) as f64 * 0.4, i as f64 * 0.77);
                let e = [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()];
                let p = [r * e[0], r * e[1], r * e[2]];
                let q = Dim::<3>::return_to_sphere(&p, big_r, &mut rng);
                let qn = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
                assert!((qn - big_r).abs() < 1e-9);
                (q[0] * e[0] + q[1] * e[1] + q[2] * e[2]) / qn
            })
            .collect();
        assert_ks_below_critical(samples, &table, x);
    }
}

#[test]
fn hit_probability_3d_is_r_over_big_r() {
    let mut rng = stream(44, 0);
    let (r, big_r) = (30.0, 10.0);
    let n = 100_000;
    let hits = (0..n)
        .filter(|_| dla_pdla::farfield::return_cosine_3d(r, big_r, &mut rng).is_some())
        .count() as f64;
    let p = big_r / r;
    let sigma = (p * (1.0 - p) / n as f64).sqrt();
    assert!((hits / n as f64 - p).abs() < 5.0 * sigma);
}
