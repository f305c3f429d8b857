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

/// The angle `phi` turned by whole turns into `[-pi, pi]`.
fn within_half_turn(mut phi: f64) -> f64 {
    while phi > PI {
        phi -= 2.0 * PI;
    }
    while phi < -PI {
        phi += 2.0 * PI;
    }
    phi
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
                within_half_turn(q[1].atan2(q[0]) - a)
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

/// The law of `ln s`, `s = |p - y|` the distance from the walker at `r = x R` to the point
/// `y` where it is next found, in `D >= 4` dimensions, as a CDF table: a hit (probability
/// `x^-(D - 2)`) with density in the cosine `u` proportional to
/// `(1 - u^2)^((D - 3)/2) s^-D` (the exterior Poisson kernel `(r^2 - R^2) / |p - y|^D` times the
/// area of the sphere's slice at `u`), or an escape and a uniform relaunch, density
/// `(1 - u^2)^((D - 3)/2)`. In `ln s` the densities gain the factor `|du / d ln s| ∝ s^2`; the
/// grid in `ln s` resolves the peak at `s = r - R` however close `x` is to 1.
fn return_distance_table<const D: usize>(x: f64, big_r: f64, hits_only: bool) -> Vec<(f64, f64)> {
    let r = x * big_r;
    let u_of = |ls: f64| {
        let s = ls.exp();
        ((r * r + big_r * big_r - s * s) / (2.0 * r * big_r)).clamp(-1.0, 1.0)
    };
    let slice = |u: f64| (1.0 - u * u).max(0.0).powf((D as f64 - 3.0) / 2.0);
    let (a, b) = ((r - big_r).ln(), (r + big_r).ln());
    let m = 200_000;
    let hit = cdf_table(
        |ls| slice(u_of(ls)) * (ls * (2.0 - D as f64)).exp(),
        a,
        b,
        m,
    );
    if hits_only {
        return hit;
    }
    let escape = cdf_table(|ls| slice(u_of(ls)) * (2.0 * ls).exp(), a, b, m);
    let p_hit = x.powi(2 - D as i32);
    hit.iter()
        .zip(&escape)
        .map(|(&(ls, h), &(_, e))| (ls, p_hit * h + (1.0 - p_hit) * e))
        .collect()
}

/// A unit vector from a seed-independent sequence, so the walkers come from many directions.
fn spread_direction<const D: usize>(i: usize) -> [f64; D] {
    let mut e: [f64; D] =
        std::array::from_fn(|k| ((i * (2 * k + 3)) as f64 * 0.618_034 + k as f64).sin());
    let n = e.iter().map(|v| v * v).sum::<f64>().sqrt();
    e.iter_mut().for_each(|v| *v /= n);
    e
}

/// The hit distance alone (from `return_cosine_nd`), then the whole return (hits and uniform
/// relaunches, from the returned points, which must lie on the sphere), against the harmonic
/// measure; walkers from `r = R (1 + 1e-6)` (cosines within 1e-12 of 1) to `r = 5 R`.
fn ks_nd_return_matches_harmonic_measure<const D: usize>(seed: u64)
where
    Dim<D>: Space<D>,
{
    let n = 40_000;
    for (k, &x) in [1.0 + 1e-6, 1.05, 2.0, 5.0].iter().enumerate() {
        let big_r = 7.0;
        let r = x * big_r;
        let mut rng = stream(seed, k as u64);
        let mut hits = Vec::new();
        while hits.len() < n {
            if let Some((u, sin)) = dla_pdla::farfield::return_cosine_nd::<D, _>(r, big_r, &mut rng)
            {
                assert!((u * u + sin * sin - 1.0).abs() < 1e-12 && (-1.0..=1.0).contains(&u));
                // s^2 = (r - R)^2 + 2 r R (1 - u), without the cancellation of r^2 + R^2 - 2rRu.
                let one_minus_u = sin * sin / (1.0 + u);
                let s2 = (r - big_r).powi(2) + 2.0 * r * big_r * one_minus_u;
                hits.push(0.5 * s2.ln());
            }
        }
        assert_ks_below_critical(hits, &return_distance_table::<D>(x, big_r, true), x);
        if x < 1.01 {
            // The returned point's rounding (1e-16 R) exceeds the hit distances at this x.
            continue;
        }
        let all: Vec<f64> = (0..n)
            .map(|i| {
                let e = spread_direction::<D>(i);
                let p: [f64; D] = std::array::from_fn(|j| r * e[j]);
                let q = Dim::<D>::return_to_sphere(&p, big_r, &mut rng);
                let qn = q.iter().map(|v| v * v).sum::<f64>().sqrt();
                assert!((qn - big_r).abs() < 1e-9, "{q:?}");
                let s = p
                    .iter()
                    .zip(&q)
                    .map(|(a, b)| (a - b) * (a - b))
                    .sum::<f64>()
                    .sqrt();
                s.ln()
            })
            .collect();
        assert_ks_below_critical(all, &return_distance_table::<D>(x, big_r, false), x);
    }
}

#[test]
fn ks_4d_return_matches_harmonic_measure() {
    ks_nd_return_matches_harmonic_measure::<4>(45);
}

#[test]
fn ks_5d_return_matches_harmonic_measure() {
    ks_nd_return_matches_harmonic_measure::<5>(46);
}

/// A walker at `r` hits the sphere with probability `(R / r)^(D - 2)` (5 standard errors).
#[test]
fn hit_probability_nd_is_r_over_big_r_to_the_d_minus_2() {
    fn check<const D: usize>(seed: u64) {
        for (k, &x) in [1.05f64, 2.0, 5.0].iter().enumerate() {
            let mut rng = stream(seed, k as u64);
            let big_r = 10.0;
            let n = 100_000;
            let hits = (0..n)
                .filter(|_| {
                    dla_pdla::farfield::return_cosine_nd::<D, _>(x * big_r, big_r, &mut rng)
                        .is_some()
                })
                .count() as f64;
            let p = x.powi(2 - D as i32);
            let sigma = (p * (1.0 - p) / n as f64).sqrt();
            assert!(
                (hits / n as f64 - p).abs() < 5.0 * sigma,
                "{D}D x = {x}: {} against {p}",
                hits / n as f64
            );
        }
    }
    check::<4>(47);
    check::<5>(48);
}

/// The density of one coordinate of a uniform point on the unit sphere of `R^m`:
/// `(1 - c^2)^((m - 3)/2)` on `[-1, 1]`.
fn coordinate_table(m: usize) -> Vec<(f64, f64)> {
    cdf_table(
        |c| (1.0 - c * c).max(0.0).powf((m as f64 - 3.0) / 2.0),
        -1.0,
        1.0,
        200_000,
    )
}

/// The returned point's direction orthogonal to the walker's is uniform on the
/// `(D - 2)`-sphere (for hits by construction, for relaunches because they are uniform): its
/// component along a unit vector `f` orthogonal to the walker's direction `e` has the law of a
/// coordinate on the unit sphere of `R^(D - 1)`, for walkers from many directions. The helper
/// that draws it keeps exactly orthogonal unit vectors.
#[test]
fn ks_nd_return_is_isotropic_about_the_walker() {
    fn check<const D: usize>(seed: u64)
    where
        Dim<D>: Space<D>,
    {
        let dot = |a: &[f64; D], b: &[f64; D]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let (big_r, r) = (5.0, 6.0);
        let mut rng = stream(seed, 0);
        let n = 40_000;
        let g: [f64; D] = std::array::from_fn(|j| if j == 0 { 1.0 } else { 0.5 });
        let comps: Vec<f64> = (0..n)
            .map(|i| {
                let e = spread_direction::<D>(i);
                let w = dla_pdla::farfield::orthogonal_direction(&e, &mut rng);
                assert!(dot(&w, &e).abs() < 1e-12 && (dot(&w, &w) - 1.0).abs() < 1e-12);
                let p: [f64; D] = std::array::from_fn(|j| r * e[j]);
                let q = Dim::<D>::return_to_sphere(&p, big_r, &mut rng);
                let along = dot(&q, &e) / big_r;
                let mut f: [f64; D] = std::array::from_fn(|j| g[j] - dot(&g, &e) * e[j]);
                let norm = dot(&f, &f).sqrt();
                f.iter_mut().for_each(|v| *v /= norm);
                dot(&q, &f) / (big_r * (1.0 - along * along).sqrt())
            })
            .collect();
        assert_ks_below_critical(comps, &coordinate_table(D - 1), D as f64);
    }
    check::<4>(49);
    check::<5>(50);
}

/// `Space::direction` in 4D and 5D is uniform on the sphere: each coordinate, and the
/// component along the diagonal, has the law `(1 - c^2)^((D - 3)/2)` of a coordinate of a
/// uniform point (the moments are checked in `space.rs`).
#[test]
fn ks_nd_directions_are_uniform_on_the_sphere() {
    fn check<const D: usize>(seed: u64)
    where
        Dim<D>: Space<D>,
    {
        let mut rng = stream(seed, 0);
        let n = 40_000;
        let table = coordinate_table(D);
        let dirs: Vec<[f64; D]> = (0..n).map(|_| Dim::<D>::direction(&mut rng)).collect();
        for axis in 0..=D {
            let comps: Vec<f64> = dirs
                .iter()
                .map(|u| {
                    if axis < D {
                        u[axis]
                    } else {
                        u.iter().sum::<f64>() / (D as f64).sqrt()
                    }
                })
                .collect();
            assert_ks_below_critical(comps, &table, axis as f64);
        }
    }
    check::<4>(51);
    check::<5>(52);
}

/// `Space::exit_ball` in 2D: the exit angle from a point at `x = r / R` inside the circle,
/// measured from the point's own direction about the centre, follows the interior Poisson
/// kernel `(1 - x^2) / (2 pi (1 - 2 x cos phi + x^2))`; every exit lies on the circle.
#[test]
fn ks_2d_ball_exit_matches_interior_harmonic_density() {
    let n = 20_000;
    let c = [37.0, -12.5];
    for (k, &x) in [0.0f64, 0.3, 0.8, 0.99].iter().enumerate() {
        let big_r = 6.0;
        let mut rng = stream(45, k as u64);
        let density = |phi: f64| (1.0 - x * x) / (2.0 * PI * (1.0 - 2.0 * x * phi.cos() + x * x));
        let table = cdf_table(density, -PI, PI, 200_000);
        let samples: Vec<f64> = (0..n)
            .map(|i| {
                let a = 0.37 * i as f64;
                let p = [c[0] + x * big_r * a.cos(), c[1] + x * big_r * a.sin()];
                let q = Dim::<2>::exit_ball(&p, &c, big_r, &mut rng).expect("a 2D sampler");
                assert!(((q[0] - c[0]).hypot(q[1] - c[1]) - big_r).abs() < 1e-12);
                within_half_turn((q[1] - c[1]).atan2(q[0] - c[0]) - a)
            })
            .collect();
        assert_ks_below_critical(samples, &table, x);
    }
}

/// `Space::exit_ball` in 3D: the cosine of the exit point's angle from the start's direction
/// about the centre follows the interior Poisson kernel, density proportional to
/// `(r^2 + R^2 - 2 r R u)^(-3/2)`, and the azimuth about that direction is uniform (the
/// component along a fixed perpendicular, over the sine, has the arcsine law of `cos` of a
/// uniform angle).
#[test]
fn ks_3d_ball_exit_matches_interior_harmonic_measure() {
    let n = 40_000;
    let c = [-3.0, 8.25, 0.5];
    // The arcsine law's CDF, 1/2 + asin(t) / pi, tabulated (its density is not integrable
    // by the trapezoid rule at the ends).
    let arcsine: Vec<(f64, f64)> = (0..=100_000)
        .map(|i| {
            let t = -1.0 + 2.0 * i as f64 / 100_000.0;
            (t, 0.5 + t.asin() / PI)
        })
        .collect();
    for (k, &x) in [0.0f64, 0.5, 0.9, 0.97].iter().enumerate() {
        let big_r = 5.0;
        let r = x * big_r;
        let mut rng = stream(46, k as u64);
        let table = cdf_table(
            |u| (r * r + big_r * big_r - 2.0 * r * big_r * u).powf(-1.5),
            -1.0,
            1.0,
            100_000,
        );
        let mut cosines = Vec::with_capacity(n);
        let mut azimuths = Vec::with_capacity(n);
        for i in 0..n {
            let (th, ph) = (0.3 + (i % 7) as f64 * 0.4, i as f64 * 0.77);
            let e = [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()];
            // A unit vector perpendicular to e.
            let f = [-ph.sin(), ph.cos(), 0.0];
            let p = [c[0] + r * e[0], c[1] + r * e[1], c[2] + r * e[2]];
            let q = Dim::<3>::exit_ball(&p, &c, big_r, &mut rng).expect("a 3D sampler");
            let d = [q[0] - c[0], q[1] - c[1], q[2] - c[2]];
            let dn = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            assert!((dn - big_r).abs() < 1e-12);
            let u = (d[0] * e[0] + d[1] * e[1] + d[2] * e[2]) / dn;
            let s = (1.0 - u * u).sqrt();
            cosines.push(u);
            if s > 1e-6 {
                azimuths.push((d[0] * f[0] + d[1] * f[1] + d[2] * f[2]) / dn / s);
            }
        }
        assert_ks_below_critical(cosines, &table, x);
        assert_ks_below_critical(azimuths, &arcsine, x);
    }
}
