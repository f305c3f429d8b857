//! Exact far-field return of a walker outside the birth sphere (`--far-field return`; see
//! `docs/dla.md`): the samplers of the harmonic measure in 2D and 3D, which
//! [`Space::return_to_sphere`](crate::space::Space::return_to_sphere) dispatches to, and the
//! vector helpers they share.
//!
//! A Brownian walker at radius `r > R` outside a sphere of radius `R` centred on the origin
//! either hits the sphere (always in 2D, where Brownian motion is recurrent; with probability
//! `R / r` in 3D) or escapes to infinity. A walker that escapes would come back, if it came
//! back at all, uniformly over the sphere, so escaping is treated as a uniform relaunch. The
//! hit point follows the harmonic measure (Poisson kernel) seen from `p`.

use core_lattice::rng::{Rng, uniform01, unit_vector};
use std::f64::consts::PI;

/// 2D: the angle `phi` in `(-pi, pi)` between the walker's direction and the point where it
/// first hits the circle, for `x = r / R > 1`. Density
/// `(x^2 - 1) / (2 pi (x^2 - 2 x cos phi + 1))`, sampled by inversion:
/// `phi = 2 atan(((x - 1)/(x + 1)) tan(u pi / 2))`, `u` uniform in `(-1, 1)`.
pub fn return_angle_2d<R: Rng + ?Sized>(x: f64, rng: &mut R) -> f64 {
    let u = 2.0 * uniform01(rng) - 1.0;
    2.0 * (((x - 1.0) / (x + 1.0)) * (u * PI / 2.0).tan()).atan()
}

/// 3D: `Some(u)`, the cosine of the angle between the walker's direction and its first hit
/// point on the sphere, or `None` if the walker escapes (probability `1 - R / r`). Given a hit,
/// `u` has CDF `F(u) = ((r^2 - R^2) / (2 R)) (1 / s(u) - 1 / (r + R))`,
/// `s(u) = sqrt(r^2 + R^2 - 2 r R u)`, inverted in closed form.
pub fn return_cosine_3d<R: Rng + ?Sized>(r: f64, big_r: f64, rng: &mut R) -> Option<f64> {
    if uniform01(rng) >= big_r / r {
        return None;
    }
    let xi = uniform01(rng);
    let inv_s = 2.0 * big_r * xi / ((r - big_r) * (r + big_r)) + 1.0 / (r + big_r);
    let s = 1.0 / inv_s;
    let u = (r * r + big_r * big_r - s * s) / (2.0 * r * big_r);
    Some(u.clamp(-1.0, 1.0))
}

/// 2D: the point on the circle of radius `big_r` where a walker at `p` (`|p| > big_r`) first
/// hits it: always a hit (Brownian motion in the plane is recurrent), at the walker's direction
/// turned by [`return_angle_2d`].
pub fn return_to_circle<R: Rng + ?Sized>(p: &[f64; 2], big_r: f64, rng: &mut R) -> [f64; 2] {
    let r = norm(p);
    let phi = return_angle_2d(r / big_r, rng);
    let (s, c) = phi.sin_cos();
    let (ex, ey) = (p[0] / r, p[1] / r);
    [big_r * (c * ex - s * ey), big_r * (s * ex + c * ey)]
}

/// 3D: the point on the sphere of radius `big_r` where a walker at `p` (`|p| > big_r`) is next
/// found: a hit with probability `big_r / |p|`, at the polar angle of [`return_cosine_3d`] from
/// the walker's direction and a uniform azimuth; otherwise (escape) a uniform point.
pub fn return_to_sphere_3d<R: Rng + ?Sized>(p: &[f64; 3], big_r: f64, rng: &mut R) -> [f64; 3] {
    let r = norm(p);
    let mut out = [0.0; 3];
    match return_cosine_3d(r, big_r, rng) {
        None => out = scale(unit_vector::<3, _>(rng), big_r),
        Some(u) => {
            let e = scale(*p, 1.0 / r);
            // An orthonormal pair perpendicular to e.
            let a = if e[0].abs() < 0.6 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 1.0, 0.0]
            };
            let mut v1 = [
                a[1] * e[2] - a[2] * e[1],
                a[2] * e[0] - a[0] * e[2],
                a[0] * e[1] - a[1] * e[0],
            ];
            let n1 = (v1[0] * v1[0] + v1[1] * v1[1] + v1[2] * v1[2]).sqrt();
            v1.iter_mut().for_each(|x| *x /= n1);
            let v2 = [
                e[1] * v1[2] - e[2] * v1[1],
                e[2] * v1[0] - e[0] * v1[2],
                e[0] * v1[1] - e[1] * v1[0],
            ];
            let sin_t = (1.0 - u * u).max(0.0).sqrt();
            let (sa, ca) = (2.0 * PI * uniform01(rng)).sin_cos();
            for i in 0..3 {
                out[i] = big_r * (u * e[i] + sin_t * (ca * v1[i] + sa * v2[i]));
            }
        }
    }
    out
}

/// Euclidean norm.
#[inline]
pub fn norm<const D: usize>(p: &[f64; D]) -> f64 {
    p.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// `p` scaled by `k`.
#[inline]
pub(crate) fn scale<const D: usize>(mut p: [f64; D], k: f64) -> [f64; D] {
    p.iter_mut().for_each(|x| *x *= k);
    p
}
