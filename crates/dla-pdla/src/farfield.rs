//! Exact far-field return of a walker outside the birth sphere (`--far-field return`; see
//! `docs/dla.md`): the samplers of the harmonic measure in 2D, 3D and `d >= 4` dimensions,
//! which [`Space::return_to_sphere`](crate::space::Space::return_to_sphere) dispatches to; the
//! samplers of the interior harmonic measure by which a walker leaves a map cell's empty ball
//! ([`Space::exit_ball`](crate::space::Space::exit_ball)); and the vector helpers they share.
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

/// Sectors of [`circle_direction`]'s table (a power of two).
const SECTORS: usize = 256;

/// `(cos, sin)` of `2 pi k / SECTORS`, from Taylor series evaluated at compile time on the
/// first eighth of a turn and turned into the rest by symmetry (within an ulp or two;
/// a direction's angle is exact to `2^-64` turns whatever the table's rounding, which only
/// moves the unit vector by about `1e-16`).
const SECTOR_TABLE: [[f64; 2]; SECTORS] = {
    let mut t = [[0.0; 2]; SECTORS];
    let quarter = SECTORS / 4;
    let mut k = 0;
    while k < SECTORS {
        let j = k % quarter;
        // The angle within the quadrant, as its complement above an eighth of a turn
        // (cos a = sin(pi/2 - a)), so that the series runs on [0, pi/4] only.
        let high = 2 * j > quarter;
        let a = 2.0 * PI * (if high { quarter - j } else { j }) as f64 / SECTORS as f64;
        // Taylor series to a^27: far below an ulp on [0, pi/4].
        let mut c = 0.0;
        let mut s = 0.0;
        let mut term = 1.0;
        let mut n = 0;
        while n < 28 {
            if n % 4 == 0 {
                c += term;
            } else if n % 4 == 1 {
                s += term;
            } else if n % 4 == 2 {
                c -= term;
            } else {
                s -= term;
            }
            n += 1;
            term = term * a / n as f64;
        }
        if high {
            (c, s) = (s, c);
        }
        t[k] = match k / quarter {
            0 => [c, s],
            1 => [-s, c],
            2 => [-c, -s],
            _ => [s, -c],
        };
        k += 1;
    }
    t
};

/// A uniform direction in the plane from one 64-bit draw, without rejection, branches or
/// division: the angle `2 pi b / 2^64`, as the table's sector (the top 8 bits) turned by the
/// rest, `delta < 2 pi / 256`, whose cosine and sine are short Taylor series (to `delta^6` and
/// `delta^7`; the first terms left out are below `1e-17`). Isotropic exactly up to the `2^-64`
/// grid of the angle.
#[inline(always)]
pub(crate) fn circle_direction<R: Rng + ?Sized>(rng: &mut R) -> (f64, f64) {
    circle_point(rng.next_u64())
}

/// The unit vector at the angle `2 pi b / 2^64` ([`circle_direction`]).
#[inline(always)]
fn circle_point(b: u64) -> (f64, f64) {
    const REST: u32 = 64 - SECTORS.trailing_zeros();
    const TURN: f64 = 2.0 * PI / 18_446_744_073_709_551_616.0; // 2 pi / 2^64
    let [c0, s0] = SECTOR_TABLE[(b >> REST) as usize];
    // Below 2^56: exact in `i64`, converted with rounding to the nearest `f64`.
    let d = ((b & ((1u64 << REST) - 1)) as i64) as f64 * TURN;
    let d2 = d * d;
    let cd = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0)));
    let sd = d * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * (-1.0 / 5040.0))));
    (c0 * cd - s0 * sd, s0 * cd + c0 * sd)
}

/// A uniform unit vector in 3D: `z` uniform in `[-1, 1]` (Archimedes), then the azimuth from
/// a [`circle_direction`].
#[inline(always)]
pub(crate) fn direction_3d<R: Rng + ?Sized>(rng: &mut R) -> [f64; 3] {
    let z = 2.0 * uniform01(rng) - 1.0;
    let rho = (1.0 - z * z).max(0.0).sqrt();
    let (c, s) = circle_direction(rng);
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
            let (ca, sa) = circle_direction(rng);
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
            return Some((cosine_from_factors(one_minus_u, one_plus_u), sin2.sqrt()));
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

/// The interior inversion of [`exit_ball_3d`] for one uniform `xi`, from a point `r` from the
/// centre of a ball of radius `big_r`: `(1 - u, 1 + u, s)`, `u` the exit point's cosine and
/// `s = a b / t` its distance from the point (`a = R - r`, `b = R + r`, `t = a + 2 r xi`).
#[inline(always)]
fn interior_factors(r: f64, big_r: f64, xi: f64) -> (f64, f64, f64) {
    let (a, b) = (big_r - r, big_r + r);
    let t = a + 2.0 * r * xi;
    let k = 1.0 / (big_r * t * t);
    (
        a * a * (1.0 - xi) * (b + t) * k,
        b * b * xi * (t + a) * k,
        a * b / t,
    )
}

/// The cosine `u` from its factors `1 - u` and `1 + u`, from the smaller one, which holds its
/// digits.
#[inline(always)]
fn cosine_from_factors(one_minus_u: f64, one_plus_u: f64) -> f64 {
    if one_minus_u < one_plus_u {
        1.0 - one_minus_u
    } else {
        one_plus_u - 1.0
    }
}

/// 2D: where Brownian motion from `p`, inside the disk of radius `big_r` around `c`
/// (`|p - c| < big_r`), first leaves it. The harmonic measure of the disk seen from `p` is the
/// image of the uniform one seen from its centre under the disk automorphism that takes the
/// centre to `p` (conformal invariance): with `z = (p - c) / big_r` and `w` a uniform point of
/// the unit circle (the walk's direction draw), the exit point is
/// `c + big_r (w + z) / (1 + conj(z) w)`, computed as
/// `c + big_r (big_r w + q) / (big_r + conj(q) w)` with `q = p - c` (the same quotient with
/// numerator and denominator times `big_r`), which leaves no division by `big_r` on the walk's
/// dependency chain.
#[inline(always)]
pub fn exit_disk<R: Rng + ?Sized>(p: &[f64; 2], c: &[f64; 2], big_r: f64, rng: &mut R) -> [f64; 2] {
    let (wx, wy) = circle_direction(rng);
    let (qx, qy) = (p[0] - c[0], p[1] - c[1]);
    // num / den as num conj(den) / (|num| |den|): the two moduli are equal (`|w| = 1`), and
    // dividing by their product rather than by |den|^2 keeps the point on the circle to an ulp
    // or two even where both are small (a walker near the ball's edge leaving near its nearest
    // point), where the quotient's own modulus would carry their relative rounding errors.
    let (nx, ny) = (big_r * wx + qx, big_r * wy + qy);
    let (dx, dy) = (big_r + qx * wx + qy * wy, qx * wy - qy * wx);
    let moduli2 = (nx * nx + ny * ny) * (dx * dx + dy * dy);
    // big_r / sqrt(moduli2) as (big_r / moduli2) sqrt(moduli2): the division and the square
    // root run side by side instead of one after the other on the walk's dependency chain.
    let k = big_r / moduli2 * moduli2.sqrt();
    whole(c, k, [nx * dx + ny * dy, ny * dx - nx * dy])
}

/// `[c[0] + k * t[0], c[1] + k * t[1]]`, bit for bit, as one two-lane vector on x86-64, so
/// the new position is stored whole: stored as two halves, the next move's vector read of it
/// cannot be forwarded from the stores and waits for them to reach the cache.
#[inline(always)]
fn whole(c: &[f64; 2], k: f64, t: [f64; 2]) -> [f64; 2] {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{__m128d, _mm_add_pd, _mm_mul_pd, _mm_set_pd, _mm_set1_pd};
        #[allow(unsafe_code)]
        // SAFETY: SSE2 is part of every x86-64 target; `__m128d` and `[f64; 2]` are the same
        // 16 bytes, lane 0 first.
        unsafe {
            let y = _mm_add_pd(
                _mm_set_pd(c[1], c[0]),
                _mm_mul_pd(_mm_set1_pd(k), _mm_set_pd(t[1], t[0])),
            );
            std::mem::transmute::<__m128d, [f64; 2]>(y)
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    [c[0] + k * t[0], c[1] + k * t[1]]
}

/// 3D: where Brownian motion from `p`, inside the ball of radius `big_r` around `c`
/// (`r = |p - c| < big_r`), first leaves it. The exit density on the sphere is proportional to
/// `|y - p|^-3` (the interior Poisson kernel), so the distance `s = |y - p|` has `1 / s`
/// uniform between `1 / (R + r)` and `1 / (R - r)` (as for [`return_cosine_3d`]); written with
/// `a = R - r`, `b = R + r`, `t = a + 2 r xi` (`xi` uniform), the cosine `u` of the exit point's
/// angle from `p - c` has `1 - u = a^2 (1 - xi)(b + t) / (R t^2)` and
/// `1 + u = b^2 xi (t + a) / (R t^2)`, free of cancellation and of any division by `r` (at
/// `r = 0`, `u = 2 xi - 1`, uniform); the azimuth is uniform (the walk's direction draw), about a
/// frame built without square roots (Duff et al., "Building an orthonormal basis, revisited",
/// 2017).
#[inline(always)]
pub fn exit_ball_3d<R: Rng + ?Sized>(
    p: &[f64; 3],
    c: &[f64; 3],
    big_r: f64,
    rng: &mut R,
) -> [f64; 3] {
    let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
    let r = norm(&d);
    let (one_minus_u, one_plus_u, _) = interior_factors(r, big_r, uniform01(rng));
    let u = cosine_from_factors(one_minus_u, one_plus_u);
    let sin_t = (one_minus_u * one_plus_u).max(0.0).sqrt();
    let e = if r > 0.0 {
        scale(d, 1.0 / r)
    } else {
        [0.0, 0.0, 1.0]
    };
    let sign = 1.0f64.copysign(e[2]);
    let g = -1.0 / (sign + e[2]);
    let h = e[0] * e[1] * g;
    let v1 = [1.0 + sign * e[0] * e[0] * g, sign * h, -sign * e[0]];
    let v2 = [h, sign + e[1] * e[1] * g, -e[1]];
    let (ca, sa) = circle_direction(rng);
    std::array::from_fn(|i| c[i] + big_r * (u * e[i] + sin_t * (ca * v1[i] + sa * v2[i])))
}

/// `d >= 4` (`D` dimensions): where Brownian motion from `p`, inside the ball of radius
/// `big_r` around `c` (`r = |p - c| < big_r`), first leaves it. The cosine `u` of the exit
/// point's angle from `p - c` has density proportional to `(1 - u^2)^((D - 3)/2) s(u)^(-D)`,
/// `s(u) = |y - p|`: drawn from the 3D law `s^-3` ([`exit_ball_3d`]'s inversion) and accepted
/// with probability `q^((D - 3)/2)`, `q = (1 - u^2) R^2 / s^2`, which is at most 1 (its maximum,
/// 1, is at `u = r / R`): von Neumann's rejection, exact, as [`return_cosine_nd`] does outside
/// the sphere. The direction orthogonal to `p - c` is uniform ([`orthogonal_direction`]; any
/// one at `r = 0`, where the law of `u` is the uniform direction's).
pub fn exit_ball_nd<const D: usize, R: Rng + ?Sized>(
    p: &[f64; D],
    c: &[f64; D],
    big_r: f64,
    rng: &mut R,
) -> [f64; D] {
    const { assert!(D >= 4, "2D and 3D have their own samplers") };
    let d: [f64; D] = std::array::from_fn(|i| p[i] - c[i]);
    let r = norm(&d);
    let (u, sin_t) = loop {
        let (one_minus_u, one_plus_u, s) = interior_factors(r, big_r, uniform01(rng));
        let sin2 = (one_minus_u * one_plus_u).max(0.0);
        let q = (sin2 * (big_r / s) * (big_r / s)).min(1.0);
        let v = uniform01(rng);
        if v * v < q.powi(D as i32 - 3) {
            break (cosine_from_factors(one_minus_u, one_plus_u), sin2.sqrt());
        }
    };
    let e = if r > 0.0 {
        scale(d, 1.0 / r)
    } else {
        let mut e = [0.0; D];
        e[D - 1] = 1.0;
        e
    };
    let w = orthogonal_direction(&e, rng);
    std::array::from_fn(|i| c[i] + big_r * (u * e[i] + sin_t * w[i]))
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

#[cfg(test)]
mod tests;
