//! Exact far-field return of a walker outside the birth sphere (`--far-field return`; see
//! `docs/dla.md`): the samplers of the harmonic measure in 2D, 3D and `d >= 4` dimensions,
//! which [`Space::return_to_sphere`](crate::space::Space::return_to_sphere) dispatches to, and
//! the vector helpers they share.
//!
//! A Brownian walker at radius `r > R` outside a sphere of radius `R` centred on the origin
//! either hits the sphere (always in 2D, where Brownian motion is recurrent; with probability
//! `(R / r)^(d - 2)` in `d >= 3` dimensions) or escapes to infinity. A walker that escapes
//! would come back, if it came back at all, uniformly over the sphere, so escaping is treated
//! as a uniform relaunch. The hit point follows the harmonic measure (exterior Poisson kernel)
//! seen from `p`: density on the sphere proportional to `(r^2 - R^2) / |p - y|^d`.
//!
//! # `d >= 4`: rejection from the 3D kernel
//!
//! In `d` dimensions the cosine `u` of the angle between `p` and the hit point has density
//! `f_d(u) ∝ (1 - u^2)^((d - 3)/2) s(u)^(-d)`, `s(u)^2 = r^2 + R^2 - 2 r R u` (`s` is the
//! distance from `p` to the hit point; `(1 - u^2)^((d - 3)/2)` is the area of the sphere's
//! slice at `u`), and the direction orthogonal to `p` is uniform on the `(d - 2)`-sphere.
//! Write `f_d = f_3 h` with `f_3(u) ∝ s(u)^(-3)`, the 3D density, which has a closed-form
//! inverse CDF, and `h(u) = q(u)^((d - 3)/2)`, `q(u) = (1 - u^2) r^2 / s(u)^2`. With
//! `t = R / r`, `q = (1 - u^2) / (1 + t^2 - 2 t u)`, whose derivative in `u` vanishes where
//! `t u^2 - (1 + t^2) u + t = 0`, i.e. at `u = t` (the root `1 / t` lies outside `[-1, 1]`),
//! where `q = 1`; at `u = ±1`, `q = 0`. So `0 <= h <= 1`, and drawing `u` from `f_3` and
//! accepting it with probability `h(u)` samples `f_d` exactly (von Neumann's rejection with
//! the envelope `f_3 >= f_d` up to normalisation). The acceptance rate `E_3[h]` is bounded
//! away from 0 for every `r / R`: `pi / 4` (4D) and `2 / 3` (5D) far away, where `f_3` is
//! uniform, and above one half as `r -> R`, where `f_3` concentrates on a cap of angular
//! size `r / R - 1` on which `h` is of order one. `q` is computed from the factors
//! `1 - u = (s - (r - R)) (s + r - R) / (2 r R)` and
//! `1 + u = (r + R - s) (r + R + s) / (2 r R)`, free of cancellation, so even a walker at
//! `r = R (1 + 1e-9)`, whose hit cosines lie within `1e-18` of 1, is accepted with the right
//! probability to about `1e-16`.
use core_lattice::rng::{Rng, uniform01, unit_vector};
use std::f64::consts::PI;

/// A point `(x, y)` uniform in the unit disk (less a disk of radius 1e-6 around the centre) by
/// rejection from the square (two 32-bit uniforms from one 64-bit draw, accepted with
/// probability pi/4), and `s = x^2 + y^2`, uniform in `(1e-12, 1]`.
#[inline(always)]
pub(crate) fn disk_point<R: Rng + ?Sized>(rng: &mut R) -> (f64, f64, f64) {
    const SCALE: f64 = 1.0 / 2_147_483_648.0;
    loop {
        let b = rng.next_u64();
        let x = ((b >> 32) as u32 as i32) as f64 * SCALE;
        let y = (b as u32 as i32) as f64 * SCALE;
        let s = x * x + y * y;
        if s <= 1.0 && s > 1e-12 {
            return (x, y, s);
        }
    }
}

/// A [`disk_point`] normalised: a uniform direction in the plane without trigonometric
/// functions, isotropic exactly up to the 2^-31 granularity of the point.
#[inline(always)]
pub(crate) fn disk_direction<R: Rng + ?Sized>(rng: &mut R) -> (f64, f64) {
    let (x, y, s) = disk_point(rng);
    let inv = 1.0 / s.sqrt();
    (x * inv, y * inv)
}

/// A uniform unit vector in 3D: `z` uniform in `[-1, 1]` (Archimedes), then the azimuth from
/// a [`disk_direction`].
#[inline(always)]
pub(crate) fn direction_3d<R: Rng + ?Sized>(rng: &mut R) -> [f64; 3] {
    let z = 2.0 * uniform01(rng) - 1.0;
    let rho = (1.0 - z * z).max(0.0).sqrt();
    let (c, s) = disk_direction(rng);
    [rho * c, rho * s, z]
}

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
/// turned by the angle of [`return_angle_2d`], drawn without trigonometric functions:
/// `tan(u pi / 2)` with `u` uniform in `(-1, 1)` is `b / |a|` for a point `(a, b)` uniform in
/// the unit disk (`disk_point`), so `t = tan(phi / 2) = k b / |a|`, `k = (x - 1)/(x + 1)`,
/// and `cos phi = (a^2 - k^2 b^2) / (a^2 + k^2 b^2)`, `sin phi = 2 k |a| b / (a^2 + k^2 b^2)`.
pub fn return_to_circle<R: Rng + ?Sized>(p: &[f64; 2], big_r: f64, rng: &mut R) -> [f64; 2] {
    let r = norm(p);
    let x = r / big_r;
    let k = (x - 1.0) / (x + 1.0);
    let (a, b, _) = disk_point(rng);
    let a = a.abs();
    let kb = k * b;
    let den = a * a + kb * kb;
    let (c, s) = ((a * a - kb * kb) / den, 2.0 * a * kb / den);
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
        None => out = scale(direction_3d(rng), big_r),
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
            let (ca, sa) = disk_direction(rng);
            for i in 0..3 {
                out[i] = big_r * (u * e[i] + sin_t * (ca * v1[i] + sa * v2[i]));
            }
        }
    }
    out
}

/// `d >= 4` (`D` dimensions): `Some((u, sin))`, the cosine and sine of the angle between the
/// walker's direction and its first hit point on the sphere of radius `big_r`, or `None` if the
/// walker, at radius `r > big_r`, escapes (probability `1 - (big_r / r)^(D - 2)`). Given a hit,
/// `u` comes from the 3D density by the closed-form inversion of [`return_cosine_3d`] and is
/// accepted with probability `q(u)^((D - 3) / 2)` (see the module documentation for the proof
/// that this samples the `D`-dimensional harmonic measure exactly).
pub fn return_cosine_nd<const D: usize, R: Rng + ?Sized>(
    r: f64,
    big_r: f64,
    rng: &mut R,
) -> Option<(f64, f64)> {
    const { assert!(D >= 4, "2D and 3D have their own samplers") };
    if uniform01(rng) >= (big_r / r).powi(D as i32 - 2) {
        return None;
    }
    let (dr, sr) = (r - big_r, r + big_r);
    let two_r_big_r = 2.0 * r * big_r;
    loop {
        // The 3D inversion: the distance s from the walker to the hit point, in [r - R, r + R].
        let xi = uniform01(rng);
        let inv_s = 2.0 * big_r * xi / (dr * sr) + 1.0 / sr;
        let s = (1.0 / inv_s).clamp(dr, sr);
        let one_minus_u = (s - dr) * (s + dr) / two_r_big_r;
        let one_plus_u = (sr - s) * (sr + s) / two_r_big_r;
        let sin2 = one_minus_u * one_plus_u;
        // q = (1 - u^2) r^2 / s^2, in [0, 1]; accept with probability q^((D - 3) / 2), i.e.
        // when v^2 < q^(D - 3) for v uniform in [0, 1).
        let q = sin2 * (r / s) * (r / s);
        let v = uniform01(rng);
        if v * v < q.powi(D as i32 - 3) {
            // u from the smaller of its two factors, which holds its digits.
            let u = if one_minus_u < one_plus_u {
                1.0 - one_minus_u
            } else {
                one_plus_u - 1.0
            };
            return Some((u, sin2.sqrt()));
        }
    }
}

/// A unit vector uniform on the `(D - 2)`-sphere orthogonal to the unit vector `e`: a uniform
/// unit vector with its component along `e` removed, normalised. Rotations about `e` leave the
/// uniform vector's law, and so the normalised remainder's, unchanged, so it is uniform; a
/// vector within about 1e-3 radians of `±e` (probability of order 1e-9 or less in `D >= 4`) is
/// drawn again, an event those rotations also leave unchanged.
pub fn orthogonal_direction<const D: usize, R: Rng + ?Sized>(
    e: &[f64; D],
    rng: &mut R,
) -> [f64; D] {
    loop {
        let mut w = unit_vector::<D, _>(rng);
        let c: f64 = w.iter().zip(e).map(|(a, b)| a * b).sum();
        w.iter_mut().zip(e).for_each(|(a, b)| *a -= c * b);
        let n = norm(&w);
        if n > 1e-3 {
            return scale(w, 1.0 / n);
        }
    }
}

/// `d >= 4` (`D` dimensions): the point on the sphere of radius `big_r` where a walker at `p`
/// (`|p| > big_r`) is next found: a hit with probability `(big_r / |p|)^(D - 2)`, at the angle
/// of [`return_cosine_nd`] from the walker's direction and a uniform direction orthogonal to
/// it ([`orthogonal_direction`]); otherwise (escape) a uniform point.
pub fn return_to_sphere_nd<const D: usize, R: Rng + ?Sized>(
    p: &[f64; D],
    big_r: f64,
    rng: &mut R,
) -> [f64; D] {
    let r = norm(p);
    match return_cosine_nd::<D, R>(r, big_r, rng) {
        None => scale(unit_vector::<D, _>(rng), big_r),
        Some((u, sin_t)) => {
            let e = scale(*p, 1.0 / r);
            let w = orthogonal_direction(&e, rng);
            std::array::from_fn(|i| big_r * (u * e[i] + sin_t * w[i]))
        }
    }
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
