//! The samplers' tests: directions against the library's trigonometry, the 2D position
//! written whole, and the ball exits against their harmonic measure.

use super::*;

/// The angle `2 pi b / 2^64` as the library's trigonometric functions give it.
fn reference(b: u64) -> (f64, f64) {
    let theta = 2.0 * PI * (b as f64 / 18_446_744_073_709_551_616.0);
    (theta.cos(), theta.sin())
}

#[test]
fn a_whole_position_is_the_two_coordinates_bit_for_bit() {
    let values = [0.0, -0.0, 1.0, -3.5, 1e-300, 7.25e8, -0.3, 1e300];
    for &k in &values {
        for (&x, &y) in values.iter().zip(values.iter().rev()) {
            let (c, t) = ([x, -y], [y * 0.5, x + 1.0]);
            let want = [c[0] + k * t[0], c[1] + k * t[1]].map(f64::to_bits);
            assert_eq!(whole(&c, k, t).map(f64::to_bits), want, "{c:?} {k} {t:?}");
        }
    }
}

#[test]
fn the_sector_table_holds_the_sectors_angles() {
    // Against the library's functions at the angle within the quadrant (exact there to
    // an ulp), turned by the quadrant.
    let quarter = SECTORS / 4;
    for (k, [c, s]) in SECTOR_TABLE.iter().enumerate() {
        let a = 2.0 * PI * (k % quarter) as f64 / SECTORS as f64;
        let (ca, sa) = (a.cos(), a.sin());
        let (rc, rs) = match k / quarter {
            0 => (ca, sa),
            1 => (-sa, ca),
            2 => (-ca, -sa),
            _ => (sa, -ca),
        };
        assert!(
            (c - rc).abs() <= 2.3e-16,
            "cos of sector {k}: {c} against {rc}"
        );
        assert!(
            (s - rs).abs() <= 2.3e-16,
            "sin of sector {k}: {s} against {rs}"
        );
    }
}

/// Every draw's vector is the unit vector at its angle to about an ulp: at the ends of
/// each sector (where a wrong table entry or a series cut too short shows first) and at
/// random draws.
#[test]
fn circle_points_are_the_unit_vectors_at_their_angles() {
    let mut draws: Vec<u64> = Vec::new();
    for k in 0..SECTORS as u64 {
        let start = k << 56;
        draws.extend([start, start + 1, start + (1 << 55), start + ((1 << 56) - 1)]);
    }
    let mut x = 0x9e37_79b9_7f4a_7c15u64;
    for _ in 0..100_000 {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        draws.push(x);
    }
    for b in draws {
        let (c, s) = circle_point(b);
        let (rc, rs) = reference(b);
        // The reference's own angle is rounded to an ulp of 2 pi.
        assert!(
            (c - rc).abs() < 2e-15 && (s - rs).abs() < 2e-15,
            "b = {b:#x}"
        );
        assert!(
            (c * c + s * s - 1.0).abs() < 1e-15,
            "b = {b:#x}: not a unit vector"
        );
    }
}

/// The angles are uniform: counts in 1 024 equal arcs over 2^20 draws of the walk's
/// stream pass a chi-square test (the sectors' edges fall on arc edges, so a sector
/// drawn too often or too rarely shows).
#[test]
fn circle_directions_are_uniform_in_angle() {
    let mut rng = core_lattice::stream(7, 0);
    const ARCS: usize = 1024;
    const N: usize = 1 << 20;
    let mut counts = vec![0u32; ARCS];
    for _ in 0..N {
        let (c, s) = circle_direction(&mut rng);
        let a = s.atan2(c).rem_euclid(2.0 * PI) / (2.0 * PI);
        counts[((a * ARCS as f64) as usize).min(ARCS - 1)] += 1;
    }
    let expect = N as f64 / ARCS as f64;
    let chi2: f64 = counts
        .iter()
        .map(|&n| (f64::from(n) - expect).powi(2) / expect)
        .sum();
    // 1 023 degrees of freedom: mean 1 023, standard deviation 45; 5.5 of them above.
    assert!(chi2 < 1023.0 + 5.5 * 45.2, "chi-square {chi2}");
}

/// Exit points lie on the sphere to a few ulps of its radius, also for a walker a
/// half-diameter inside a ball of radius 16 383 (the coarsest 2D map's), where the 2D
/// automorphism's numerator and denominator both nearly vanish for exits near the walker.
#[test]
fn exits_stay_on_the_sphere_near_its_edge() {
    let mut rng = core_lattice::stream(12, 0);
    let big_r = 16_383.0;
    let c2 = [1.0e5 + 0.5, -3.0e4];
    let c3 = [1.0e4, -2.0e4 + 0.25, 512.0];
    for k in 0..200_000 {
        let a = 0.001 * k as f64;
        let r = big_r - 0.5;
        let p = [c2[0] + r * a.cos(), c2[1] + r * a.sin()];
        let y = exit_disk(&p, &c2, big_r, &mut rng);
        let off = ((y[0] - c2[0]).hypot(y[1] - c2[1]) - big_r).abs();
        assert!(off < 8.0 * f64::EPSILON * 1.0e5, "2D: {off} off the circle");
        let p = [
            c3[0] + r * a.cos(),
            c3[1] + r * a.sin() * 0.6,
            c3[2] + r * a.sin() * 0.8,
        ];
        let y = exit_ball_3d(&p, &c3, big_r, &mut rng);
        let off = (norm(&[y[0] - c3[0], y[1] - c3[1], y[2] - c3[2]]) - big_r).abs();
        assert!(off < 8.0 * f64::EPSILON * 2.0e4, "3D: {off} off the sphere");
    }
}

/// Harmonic functions keep their value in expectation at the exit point (the exit law is
/// the harmonic measure): means over many exits against the value at the start.
#[test]
fn exits_keep_harmonic_functions_in_mean() {
    let mut rng = core_lattice::stream(11, 0);
    let n = 2_000_000;
    // 2D: the disk of radius 3 about c, from points at 0, 0.5 and 0.97 of the radius.
    let c = [10.25, -3.5];
    for f in [0.0, 0.5, 0.97] {
        let p = [c[0] + 3.0 * f * 0.6, c[1] + 3.0 * f * 0.8];
        let a = [c[0] + 4.0, c[1] + 1.0];
        let h = |y: &[f64; 2]| {
            [
                y[0],
                y[1],
                (y[0] - c[0]).powi(2) - (y[1] - c[1]).powi(2),
                ((y[0] - a[0]).powi(2) + (y[1] - a[1]).powi(2)).ln(),
            ]
        };
        let label = format!("2D f {f}");
        assert_means_kept(
            &label,
            n,
            &p,
            &c,
            3.0,
            || exit_disk(&p, &c, 3.0, &mut rng),
            h,
        );
    }
    // 3D: the ball of radius 2 about c.
    let c = [-1.0, 4.5, 0.25];
    for f in [0.0, 0.3, 0.9, 0.995] {
        let dir = [0.36, -0.48, 0.8];
        let p = [
            c[0] + 2.0 * f * dir[0],
            c[1] + 2.0 * f * dir[1],
            c[2] + 2.0 * f * dir[2],
        ];
        let a = [c[0] - 1.0, c[1] + 2.5, c[2] + 0.5];
        let h = |y: &[f64; 3]| {
            let (x, yy, z) = (y[0] - c[0], y[1] - c[1], y[2] - c[2]);
            [
                x,
                yy,
                z,
                x * yy,
                x * x - z * z,
                1.0 / ((y[0] - a[0]).powi(2) + (y[1] - a[1]).powi(2) + (y[2] - a[2]).powi(2))
                    .sqrt(),
            ]
        };
        let label = format!("3D f {f}");
        assert_means_kept(
            &label,
            n,
            &p,
            &c,
            2.0,
            || exit_ball_3d(&p, &c, 2.0, &mut rng),
            h,
        );
    }
    exits_nd_keep_harmonic_functions::<4>(&mut rng);
    exits_nd_keep_harmonic_functions::<5>(&mut rng);
}

/// [`exits_keep_harmonic_functions_in_mean`] in `D >= 4` dimensions: `x_0`, `x_0 x_1`,
/// `x_0^2 - x_{D-1}^2` about the centre and `|y - a|^(2 - D)` for `a` outside the ball.
fn exits_nd_keep_harmonic_functions<const D: usize>(rng: &mut impl Rng) {
    let n = 1_000_000;
    let c: [f64; D] = std::array::from_fn(|i| 0.5 * i as f64 - 1.0);
    for f in [0.0, 0.4, 0.9, 0.99] {
        let dir: [f64; D] = std::array::from_fn(|i| if i < 2 { 0.6 } else { 0.0 });
        let dir = scale(dir, 1.0 / norm(&dir));
        let p: [f64; D] = std::array::from_fn(|i| c[i] + 2.0 * f * dir[i]);
        let a: [f64; D] = std::array::from_fn(|i| c[i] + if i == 1 { 2.5 } else { 0.5 });
        let h = |y: &[f64; D]| {
            let x: [f64; D] = std::array::from_fn(|i| y[i] - c[i]);
            let ya: [f64; D] = std::array::from_fn(|i| y[i] - a[i]);
            [
                x[0],
                x[0] * x[1],
                x[0] * x[0] - x[D - 1] * x[D - 1],
                norm(&ya).powi(2 - D as i32),
            ]
        };
        let label = format!("{D}D f {f}");
        assert_means_kept(&label, n, &p, &c, 2.0, || exit_ball_nd(&p, &c, 2.0, rng), h);
    }
}

/// Draws `n` exits with `exit` from `p` inside the ball of radius `big_r` about `c`: each
/// lies on the sphere, and each function of `h` (harmonic in the ball) keeps its value at
/// `p` in the mean, within five standard errors.
fn assert_means_kept<const D: usize, const K: usize>(
    label: &str,
    n: usize,
    p: &[f64; D],
    c: &[f64; D],
    big_r: f64,
    mut exit: impl FnMut() -> [f64; D],
    h: impl Fn(&[f64; D]) -> [f64; K],
) {
    let mut sum = [0.0; K];
    let mut sq = [0.0; K];
    for _ in 0..n {
        let y = exit();
        let r = norm(&std::array::from_fn::<f64, D, _>(|i| y[i] - c[i]));
        assert!((r - big_r).abs() < 1e-12, "{label}: off the sphere: {r}");
        for (k, v) in h(&y).iter().enumerate() {
            sum[k] += v;
            sq[k] += v * v;
        }
    }
    let want = h(p);
    for k in 0..K {
        let mean = sum[k] / n as f64;
        let sd = ((sq[k] / n as f64 - mean * mean) / n as f64).sqrt();
        assert!(
            (mean - want[k]).abs() < 5.0 * sd + 1e-12,
            "{label} h{k}: {mean} against {} (sd {sd})",
            want[k]
        );
    }
}
