//! Deposits on a substrate and biased walkers: the geometry of growth on a line (2D) or a
//! (hyper)plane (3D to 5D) with periodic lateral boundaries, the exact return of a walker that
//! rises above the launch plane, and the directions of drifting and ballistic walkers.
//!
//! # Geometry
//!
//! The last axis is the height `z`; the substrate is the plane `z = -1/2`, so a walker touches
//! it when its centre reaches `z = 0`, and the first layer of the deposit lies at `z = 0`. The
//! lateral axes are periodic with period `W` (`--substrate-width`), coordinates in
//! `[-W/2, W/2)`. The spatial index is not periodic: every particle within [`Substrate::margin`]
//! of a lateral edge is stored again shifted by `±W` (its *images*, carrying its arrival index),
//! so a distance search from a walker inside the strip finds every image within the margin.
//! A lower bound `b` of the distance to the stored points is then a lower bound of the periodic
//! distance only up to the margin: the walk uses `min(b, margin)` (an image left out lies more
//! than the margin beyond an edge, so more than the margin from any walker in the strip).
//!
//! # Far field
//!
//! Walkers start on the launch plane `z = h + gap` (`h` the deposit's height, `gap` the
//! `--birth-gap`) at a uniform lateral position: by lateral translation invariance, that is
//! where walkers coming from far above first cross it. A walker that rises to `z` above the
//! launch plane is put back where it first returns to it, exactly: its vertical motion is a
//! one-dimensional Brownian motion (with the drift, if any), independent of the lateral one,
//! so the return time `tau` is the first-passage time over the height `a = z - z_launch`
//! (inverse Gaussian with mean `a / v` and shape `a^2` with drift `v`, Lévy without), and the
//! lateral displacement is Gaussian with variance `tau` per axis, wrapped into the strip.
//! Nothing can be touched on the way: every particle lies below the launch plane.
//!
//! # Drift
//!
//! With drift velocity `v` towards the substrate and diffusion coefficient `D_w`, the Péclet
//! number `Pe = v d / D_w` (`--drift`; `d = 1`, the particle diameter) is the one parameter. In
//! units where `D_w = 1/2` (unit variance per unit time and axis), `v = Pe / 2`. By Girsanov's
//! theorem the point where such a walker first leaves a ball of radius `r` around its start
//! (the ball free of particles, as every jump's is) has density proportional to
//! `exp(v u·y)` on the sphere (`u` the drift's direction): the exit time of driftless Brownian
//! motion is independent of the exit point, so the drift's weight `exp(v·y - v^2 tau / 2)`
//! only tilts the uniform exit law. That is the von Mises-Fisher law with concentration
//! `kappa = v r = Pe r / 2` around the drift's direction, sampled exactly by Wood's
//! algorithm ([`drift_direction`]). A jump with drift is as exact as one without; the near
//! field's straight steps of `--step-min` take their directions from the same law.
//!
//! # Ballistic walkers
//!
//! `--ballistic` is the limit `Pe -> infinity`: straight-line walkers. On a substrate they fall
//! straight down from a uniform lateral position (ballistic deposition with off-lattice
//! particles); in radial growth each walker comes from a uniformly random direction along a
//! straight line whose impact parameter is uniform over the birth sphere's cross-section, and
//! one that leaves the birth sphere without touching the cluster is replaced by a new one
//! (Vold's and Sutherland's ballistic particle-cluster aggregation, as Meakin simulated it).

use core_lattice::rng::{Rng, uniform01};

/// Largest image margin: how far from a lateral edge particles are stored again, and the
/// longest jump a walker takes by a bound from the spatial index (jumps are longer only
/// above the deposit's top, where the height alone bounds the distance). Half the width when
/// that is smaller.
pub const MAX_MARGIN: f64 = 32.0;

/// The narrowest accepted substrate, in diameters.
pub const MIN_SUBSTRATE_WIDTH: f64 = 8.0;

/// A substrate's lateral period and image margin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Substrate {
    /// Lateral period `W`, diameters.
    pub width: f64,
    /// Particles within this distance of a lateral edge are stored again across it:
    /// `min(MAX_MARGIN, W / 2)`.
    pub margin: f64,
}

impl Substrate {
    /// The substrate of width `width` (`None` for 0, radial growth).
    pub fn new(width: f64) -> Option<Self> {
        (width > 0.0).then(|| Substrate {
            width,
            margin: MAX_MARGIN.min(width / 2.0),
        })
    }

    /// Wraps the lateral coordinates of `p` into `[-W/2, W/2)`; whether any moved.
    #[inline]
    pub fn wrap<const D: usize>(&self, p: &mut [f64; D]) -> bool {
        let half = 0.5 * self.width;
        let mut moved = false;
        for x in p.iter_mut().take(D - 1) {
            if *x < -half || *x >= half {
                *x -= self.width * ((*x + half) / self.width).floor();
                // Rounding can land exactly on +W/2.
                if *x >= half {
                    *x -= self.width;
                }
                moved = true;
            }
        }
        moved
    }

    /// The images of the stored position `q` (lateral coordinates in the strip): `q` shifted
    /// by `±W` along every combination of lateral axes on which it lies within the margin of
    /// an edge. Calls `f` for each (none for a particle away from every edge).
    pub fn for_each_image<const D: usize>(&self, q: &[f64; D], mut f: impl FnMut([f64; D])) {
        let half = 0.5 * self.width;
        // shift[i]: the image's shift along lateral axis i (0: none possible).
        let shift: [f64; D] = std::array::from_fn(|i| {
            if i + 1 == D {
                0.0
            } else if q[i] < -half + self.margin {
                self.width
            } else if q[i] >= half - self.margin {
                -self.width
            } else {
                0.0
            }
        });
        let axes: Vec<usize> = (0..D - 1).filter(|&i| shift[i] != 0.0).collect();
        for mask in 1u32..(1 << axes.len()) {
            let mut image = *q;
            for (bit, &i) in axes.iter().enumerate() {
                if mask & (1 << bit) != 0 {
                    image[i] += shift[i];
                }
            }
            f(image);
        }
    }

    /// A walker's start on the launch plane `z = height`: uniform over the strip.
    pub fn launch<const D: usize, R: Rng + ?Sized>(&self, height: f64, rng: &mut R) -> [f64; D] {
        std::array::from_fn(|i| {
            if i + 1 == D {
                height
            } else {
                (uniform01(rng) - 0.5) * self.width
            }
        })
    }

    /// Where a walker at `p`, above the launch plane `z = height`, first returns to it (see
    /// the module documentation): with drift `half_pe = Pe / 2` towards the substrate (0 for
    /// none), the first-passage time `tau` over `p_z - height`, then a Gaussian lateral
    /// displacement of variance `tau` per axis, wrapped into the strip.
    pub fn return_to_plane<const D: usize, R: Rng + ?Sized>(
        &self,
        p: &[f64; D],
        height: f64,
        half_pe: f64,
        rng: &mut R,
    ) -> [f64; D] {
        let a = p[D - 1] - height;
        let tau = first_passage_time(a, half_pe, rng);
        let s = tau.sqrt();
        let mut q = *p;
        let mut i = 0;
        while i + 1 < D {
            let (g1, g2) = normal_pair(rng);
            q[i] += s * g1;
            if i + 2 < D {
                q[i + 1] += s * g2;
            }
            i += 2;
        }
        q[D - 1] = height;
        self.wrap(&mut q);
        q
    }
}

/// Two independent standard normal variates (Marsaglia's polar method).
pub fn normal_pair<R: Rng + ?Sized>(rng: &mut R) -> (f64, f64) {
    loop {
        let x = 2.0 * uniform01(rng) - 1.0;
        let y = 2.0 * uniform01(rng) - 1.0;
        let s = x * x + y * y;
        if s < 1.0 && s > 0.0 {
            let k = (-2.0 * s.ln() / s).sqrt();
            return (x * k, y * k);
        }
    }
}

/// The first time a one-dimensional Brownian motion with unit variance per unit time and drift
/// `v >= 0` towards a level `a > 0` below it reaches that level: inverse Gaussian with mean
/// `a / v` and shape `a^2` (Michael, Schucany & Haas's sampler, in a form free of
/// cancellation for small `v`), or Lévy (`a^2 / N^2`) for `v = 0`.
pub fn first_passage_time<R: Rng + ?Sized>(a: f64, v: f64, rng: &mut R) -> f64 {
    let (n, _) = normal_pair(rng);
    let y = n * n;
    if v <= 0.0 {
        return a * a / y.max(f64::MIN_POSITIVE);
    }
    let mu = a / v;
    let lambda = a * a;
    // x = mu (1 + k - sqrt(k^2 + 2k)) with k = mu y / (2 lambda), written as
    // mu / (1 + k + sqrt(k^2 + 2k)) since (1 + k)^2 - (k^2 + 2k) = 1.
    let k = mu * y / (2.0 * lambda);
    let x = mu / (1.0 + k + (k * k + 2.0 * k).sqrt());
    if uniform01(rng) <= mu / (mu + x) {
        x
    } else {
        mu * mu / x
    }
}

/// A unit vector from the von Mises-Fisher law on the sphere of `D` dimensions with
/// concentration `kappa >= 0` around `-e_z` (the last axis, towards the substrate): the
/// direction of a jump of radius `r` with drift `Pe` has `kappa = Pe r / 2` (module
/// documentation). The cosine `w` to the mean direction comes from Wood's rejection sampler
/// ("Simulation of the von Mises Fisher distribution", 1994) with its quantities rewritten so
/// that nothing cancels for tiny or huge `kappa`; the lateral part is uniform.
pub fn drift_direction<const D: usize, R: Rng + ?Sized>(kappa: f64, rng: &mut R) -> [f64; D] {
    let (w, sin) = vmf_cosine::<R>(D, kappa, rng);
    let mut lateral = [0.0; D];
    if D == 2 {
        lateral[0] = if uniform01(rng) < 0.5 { -1.0 } else { 1.0 };
    } else {
        loop {
            let mut norm2 = 0.0;
            let mut i = 0;
            while i + 1 < D {
                let (g1, g2) = normal_pair(rng);
                lateral[i] = g1;
                norm2 += g1 * g1;
                if i + 2 < D {
                    lateral[i + 1] = g2;
                    norm2 += g2 * g2;
                }
                i += 2;
            }
            if norm2 > 1e-300 {
                let inv = 1.0 / norm2.sqrt();
                lateral.iter_mut().for_each(|x| *x *= inv);
                break;
            }
        }
    }
    let mut u = [0.0; D];
    for i in 0..D - 1 {
        u[i] = sin * lateral[i];
    }
    u[D - 1] = -w;
    u
}

/// Wood's sampler of the cosine `w` of the von Mises-Fisher law on the sphere in `d`
/// dimensions, with `sqrt(1 - w^2)` computed without cancellation. With
/// `b = (d - 1) / (2 kappa + sqrt(4 kappa^2 + (d - 1)^2))`, `x0 = (1 - b) / (1 + b)` and
/// `z ~ Beta((d-1)/2, (d-1)/2)`, the proposal is `w = (1 - (1 + b) z) / (1 - (1 - b) z)`,
/// accepted when `kappa (w - x0) + (d - 1) ln(1 - x0 w) - (d - 1) ln(1 - x0^2) >= ln U`;
/// here `w - x0 = 2 b (1 - 2z) / ((1 + b)(1 - (1 - b) z))`,
/// `(1 - x0 w) / (1 - x0^2) = (1 + b) / (2 (1 - (1 - b) z))`,
/// `1 - w = 2 b z / (1 - (1 - b) z)` and `1 + w = 2 (1 - z) / (1 - (1 - b) z)`.
/// The Beta variate is `(1 + t) / 2` with `t` the first coordinate of a uniform unit vector in
/// `d` dimensions, drawn from normals.
pub fn vmf_cosine<R: Rng + ?Sized>(d: usize, kappa: f64, rng: &mut R) -> (f64, f64) {
    let m = (d - 1) as f64;
    let b = m / (2.0 * kappa + (4.0 * kappa * kappa + m * m).sqrt());
    loop {
        let z = beta_symmetric(d, rng);
        let den = 1.0 - (1.0 - b) * z;
        let w_minus_x0 = 2.0 * b * (1.0 - 2.0 * z) / ((1.0 + b) * den);
        let log_ratio = ((1.0 + b) / (2.0 * den)).ln();
        if kappa * w_minus_x0 + m * log_ratio >= uniform01(rng).ln() {
            let w = (1.0 - (1.0 + b) * z) / den;
            let sin = 2.0 * (b * z * (1.0 - z)).max(0.0).sqrt() / den;
            return (w.clamp(-1.0, 1.0), sin.min(1.0));
        }
    }
}

/// `Beta((d-1)/2, (d-1)/2)`: `(1 + t) / 2`, `t` the first coordinate of a uniform unit vector
/// in `d` dimensions (`t = g_1 / |g|` for `d` standard normals `g`).
fn beta_symmetric<R: Rng + ?Sized>(d: usize, rng: &mut R) -> f64 {
    loop {
        let mut first = 0.0;
        let mut norm2 = 0.0;
        let mut i = 0;
        while i < d {
            let (g1, g2) = normal_pair(rng);
            if i == 0 {
                first = g1;
            }
            norm2 += g1 * g1;
            if i + 1 < d {
                norm2 += g2 * g2;
            }
            i += 2;
        }
        if norm2 > 1e-300 {
            return 0.5 * (1.0 + first / norm2.sqrt());
        }
    }
}

/// The start of a ballistic walker in radial growth: a uniform direction `aim` and a straight
/// line along it whose impact parameter is uniform over the disk (ball) of radius `r_b`
/// perpendicular to it; the walker starts where that line enters the birth sphere. `dir` is a
/// uniform unit vector source (the dimension's [`Space::direction`](crate::space::Space)).
pub fn ballistic_start<const D: usize, R: Rng + ?Sized>(
    r_b: f64,
    rng: &mut R,
    dir: fn(&mut R) -> [f64; D],
) -> ([f64; D], [f64; D]) {
    let aim = dir(rng);
    // A uniform direction perpendicular to `aim`: a uniform one with its component along
    // `aim` removed (the rare one nearly parallel to `aim` is drawn again).
    let across = loop {
        let g = dir(rng);
        let along: f64 = (0..D).map(|i| g[i] * aim[i]).sum();
        let mut v: [f64; D] = std::array::from_fn(|i| g[i] - along * aim[i]);
        let n2: f64 = v.iter().map(|x| x * x).sum();
        if n2 > 1e-12 {
            let inv = 1.0 / n2.sqrt();
            v.iter_mut().for_each(|x| *x *= inv);
            break v;
        }
    };
    let rho = r_b * uniform01(rng).powf(1.0 / (D - 1) as f64);
    let back = (r_b * r_b - rho * rho).max(0.0).sqrt();
    let p = std::array::from_fn(|i| rho * across[i] - back * aim[i]);
    (p, aim)
}

#[cfg(test)]
mod tests {
    use super::*;
    use core_lattice::rng::stream;

    #[test]
    fn wrap_keeps_lateral_coordinates_in_the_strip() {
        let s = Substrate::new(10.0).unwrap();
        let mut p = [5.0, 3.0];
        assert!(s.wrap(&mut p));
        assert_eq!(p, [-5.0, 3.0]);
        let mut p = [-5.5, 1.0, 7.0];
        assert!(s.wrap(&mut p));
        assert_eq!(p, [4.5, 1.0, 7.0]);
        let mut p = [-5.0, 100.0];
        assert!(!s.wrap(&mut p));
        let mut p = [123.25, -0.5];
        s.wrap(&mut p);
        assert!((p[0] - 3.25).abs() < 1e-12, "{p:?}");
    }

    #[test]
    fn images_cover_the_edges_and_corners() {
        let s = Substrate::new(100.0).unwrap();
        assert_eq!(s.margin, 32.0);
        let mut n = 0;
        s.for_each_image(&[0.0, 0.0, 5.0], |_| n += 1);
        assert_eq!(n, 0);
        let mut images = Vec::new();
        s.for_each_image(&[-40.0, 45.0, 5.0], |q| images.push(q));
        images.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert_eq!(
            images,
            vec![[-40.0, -55.0, 5.0], [60.0, -55.0, 5.0], [60.0, 45.0, 5.0]]
        );
        // Half the width: every particle has an image.
        let s = Substrate::new(8.0).unwrap();
        let mut images = Vec::new();
        s.for_each_image(&[0.0, 1.0], |q| images.push(q));
        assert_eq!(images, vec![[-8.0, 1.0]]);
    }

    /// The first-passage time against its law: the mean `a / v` of the inverse Gaussian,
    /// and the probability `P(tau <= t)` of the Lévy law `2 (1 - Phi(a / sqrt t))` at `t = a^2`
    /// (0.3173).
    #[test]
    fn first_passage_times_follow_their_laws() {
        let mut rng = stream(7, 1);
        let n = 200_000;
        let (a, v) = (3.0, 0.5);
        let mean = (0..n)
            .map(|_| first_passage_time(a, v, &mut rng))
            .sum::<f64>()
            / n as f64;
        // Variance a / v^3 = 24: standard error 0.011.
        assert!((mean - a / v).abs() < 0.05, "{mean}");
        let below = (0..n)
            .filter(|_| first_passage_time(a, 0.0, &mut rng) <= a * a)
            .count() as f64
            / n as f64;
        assert!((below - 0.3173).abs() < 0.005, "{below}");
    }

    /// The von Mises-Fisher cosine against its exact mean: `coth(kappa) - 1/kappa` in 3D, and
    /// in general `I_{d/2}(kappa) / I_{d/2-1}(kappa)`, whose 2D value at `kappa = 1` is
    /// `I_1(1) / I_0(1) = 0.446390`; uniform at `kappa = 0` (mean 0); unit vectors.
    #[test]
    fn drift_directions_follow_von_mises_fisher() {
        let mut rng = stream(9, 2);
        let n = 200_000;
        let mean = |d: usize, kappa: f64, rng: &mut _| {
            (0..n).map(|_| vmf_cosine(d, kappa, rng).0).sum::<f64>() / n as f64
        };
        for kappa in [0.3f64, 2.0, 10.0] {
            let exact = 1.0 / kappa.tanh() - 1.0 / kappa;
            let m = mean(3, kappa, &mut rng);
            assert!(
                (m - exact).abs() < 0.005,
                "3D kappa {kappa}: {m} vs {exact}"
            );
        }
        let m = mean(2, 1.0, &mut rng);
        assert!((m - 0.446_390).abs() < 0.005, "2D: {m}");
        for d in 2..=5 {
            let m = mean(d, 0.0, &mut rng);
            assert!(m.abs() < 0.006, "{d}D uniform: {m}");
        }
        // Huge concentrations stay finite and point along the drift.
        let (w, s) = vmf_cosine(3, 1e12, &mut rng);
        assert!(w > 1.0 - 1e-9 && (0.0..1e-4).contains(&s), "{w} {s}");
        for _ in 0..1000 {
            let u = drift_direction::<4, _>(1.5, &mut rng);
            let n2: f64 = u.iter().map(|x| x * x).sum();
            assert!((n2 - 1.0).abs() < 1e-12);
        }
    }

    /// A walker returned to the launch plane lands on it, in the strip, with the lateral
    /// spread of the Lévy law (no drift: median `|dx|` of the Cauchy law is the height `a`).
    #[test]
    fn returns_land_on_the_launch_plane() {
        let s = Substrate::new(1e9).unwrap();
        let mut rng = stream(3, 3);
        let mut dx: Vec<f64> = (0..100_001)
            .map(|_| {
                let q = s.return_to_plane(&[0.0, 12.0], 10.0, 0.0, &mut rng);
                assert_eq!(q[1], 10.0);
                q[0].abs()
            })
            .collect();
        dx.sort_by(|a, b| a.partial_cmp(b).unwrap());
        let median = dx[dx.len() / 2];
        assert!((median - 2.0).abs() < 0.05, "{median}");
    }

    /// Ballistic starts lie on the birth sphere, entering it.
    #[test]
    fn ballistic_starts_enter_the_sphere() {
        let mut rng = stream(5, 4);
        for _ in 0..1000 {
            let (p, aim) = ballistic_start::<3, _>(10.0, &mut rng, |r| {
                core_lattice::rng::unit_vector::<3, _>(r)
            });
            let r: f64 = p.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!((r - 10.0).abs() < 1e-9);
            let inward: f64 = (0..3).map(|i| p[i] * aim[i]).sum();
            assert!(inward <= 1e-9);
        }
    }
}
