//! The space dimension as a type: [`Dim<D>`] implements [`Space<D>`] for every dimension the
//! model runs in (2 and 3), and owns everything that differs between dimensions: the
//! isotropic random direction of a move, the exact far-field return to the birth sphere, the
//! distance map levels, the expected cluster radius and the axis names of position files.
//!
//! Everything else in the crate is generic over `const D: usize` with a
//! `where Dim<D>: Space<D>` bound, so a dimension without an implementation does not compile,
//! and no code path branches on the dimension at run time. The one run-time choice is the
//! command line's `--dim`: it is checked against [`DIMENSIONS`] by
//! [`Params::validate`](crate::Params::validate) and turned into a type by one `match` in the
//! `dla` binary.
//!
//! Invariants: the trait's methods are `#[inline]` and statically dispatched (no trait
//! objects), so a kernel compiles to the same code as if written for its dimension; the
//! floating-point operations of each implementation, and the order of its random draws, are
//! part of the state hash and must not change.
//!
//! # Adding a dimension
//!
//! 1. `impl Space<4> for Dim<4>` here, with a `direction` (any isotropic unit vector, for
//!    example [`core_lattice::rng::unit_vector`]), a `return_to_sphere` (the harmonic measure
//!    of the sphere in that dimension, next to the 2D and 3D ones in [`crate::farfield`]), map
//!    levels, an `expected_r_ext` and axis names;
//! 2. add the dimension to [`DIMENSIONS`];
//! 3. add one arm to the dispatch in `main.rs` (`4 => run::<4>(cli, params)`).

use crate::farfield::{return_to_circle, return_to_sphere_3d};
use core_lattice::rng::{Rng, uniform01};

/// The dimensions with a [`Space`] implementation, the accepted values of `--dim`.
pub const DIMENSIONS: &[usize] = &[2, 3];

/// The space dimension `D` as a type; see [`Space`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Dim<const D: usize>;

/// Everything dimension-specific in DLA/PDLA; implemented by [`Dim<D>`] for each supported
/// `D` (see the module documentation for how to add one).
pub trait Space<const D: usize> {
    /// The distance maps, finest first, as `(cell side, cap distance)` in diameters: a fine
    /// map for walkers up to the cap from the cluster and a coarse one beyond it (a walker in
    /// a capped fine cell asks the coarse map). An insert lowers every cell whose centre lies
    /// within the cap, so the cost of an insert grows like `(cap / cell)^D`.
    const MAP_LEVELS: &'static [(f64, f64)];

    /// Axis names, the header of `positions.csv`.
    const AXES: [&'static str; D];

    /// A uniformly random unit vector (the direction of a jump or step).
    fn direction<R: Rng + ?Sized>(rng: &mut R) -> [f64; D];

    /// The point on the sphere of radius `big_r` where a walker at `p` (`|p| > big_r`) is next
    /// found: where Brownian motion from `p` first hits the sphere (harmonic measure), or a
    /// uniform point if it escapes to infinity.
    fn return_to_sphere<R: Rng + ?Sized>(p: &[f64; D], big_r: f64, rng: &mut R) -> [f64; D];

    /// A generous estimate of `R_ext` for a cluster of `n` particles, for sizing PDLA's shared
    /// distance maps up front. A cluster that outgrows it only loses the maps' help at its rim.
    fn expected_r_ext(n: u64) -> f64;
}

/// A point uniform in the unit disk by rejection from the square (two 32-bit uniforms from one
/// 64-bit draw, accepted with probability pi/4), normalised: a uniform direction in the plane
/// without trigonometric functions, isotropic exactly up to the 2^-31 granularity of the point.
#[inline(always)]
fn disk_direction<R: Rng + ?Sized>(rng: &mut R) -> (f64, f64) {
    const SCALE: f64 = 1.0 / 2_147_483_648.0;
    loop {
        let b = rng.next_u64();
        let x = ((b >> 32) as u32 as i32) as f64 * SCALE;
        let y = (b as u32 as i32) as f64 * SCALE;
        let s = x * x + y * y;
        if s <= 1.0 && s > 1e-12 {
            let inv = 1.0 / s.sqrt();
            return (x * inv, y * inv);
        }
    }
}

impl Space<2> for Dim<2> {
    /// A fine map of 8-diameter cells capped at 64 and a coarse one of 64-diameter cells
    /// capped at 512 (about 200 cells lowered per insert and map). Finer cells cost more
    /// memory than they save time; a larger coarse cap costs more per insert
    /// (`docs/benchmarks.md`).
    const MAP_LEVELS: &'static [(f64, f64)] = &[(8.0, 64.0), (64.0, 512.0)];

    const AXES: [&'static str; 2] = ["x", "y"];

    /// The disk direction.
    #[inline]
    fn direction<R: Rng + ?Sized>(rng: &mut R) -> [f64; 2] {
        let (c, s) = disk_direction(rng);
        [c, s]
    }

    /// [`return_to_circle`].
    #[inline]
    fn return_to_sphere<R: Rng + ?Sized>(p: &[f64; 2], big_r: f64, rng: &mut R) -> [f64; 2] {
        return_to_circle(p, big_r, rng)
    }

    /// 1.3 times `0.85 n^(1/1.71)`: the off-lattice DLA dimension 1.71 with a prefactor fitted
    /// to grown clusters.
    #[inline]
    fn expected_r_ext(n: u64) -> f64 {
        1.3 * (0.85 * (n as f64).powf(1.0 / 1.71))
    }
}

impl Space<3> for Dim<3> {
    /// A fine map of 8-diameter cells capped at 32 and a coarse one of 32-diameter cells
    /// capped at 128 (about 270 cells lowered per insert and map).
    const MAP_LEVELS: &'static [(f64, f64)] = &[(8.0, 32.0), (32.0, 128.0)];

    const AXES: [&'static str; 3] = ["x", "y", "z"];

    /// `z` uniform in `[-1, 1]` (Archimedes), then the azimuth from a disk direction.
    #[inline]
    fn direction<R: Rng + ?Sized>(rng: &mut R) -> [f64; 3] {
        let z = 2.0 * uniform01(rng) - 1.0;
        let rho = (1.0 - z * z).max(0.0).sqrt();
        let (c, s) = disk_direction(rng);
        [rho * c, rho * s, z]
    }

    /// [`return_to_sphere_3d`].
    #[inline]
    fn return_to_sphere<R: Rng + ?Sized>(p: &[f64; 3], big_r: f64, rng: &mut R) -> [f64; 3] {
        return_to_sphere_3d(p, big_r, rng)
    }

    /// 1.3 times `1.15 n^(1/2.5)`: the off-lattice DLA dimension 2.5 with a prefactor fitted
    /// to grown clusters.
    #[inline]
    fn expected_r_ext(n: u64) -> f64 {
        1.3 * (1.15 * (n as f64).powf(1.0 / 2.5))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::farfield::norm;
    use core_lattice::rng::stream;

    fn unit_and_isotropic<const D: usize>()
    where
        Dim<D>: Space<D>,
    {
        let mut rng = stream(3, 0);
        let n = 200_000;
        let mut mean = [0.0; D];
        let mut second = [0.0; D];
        for _ in 0..n {
            let u = Dim::<D>::direction(&mut rng);
            assert!((norm(&u) - 1.0).abs() < 1e-12, "{u:?}");
            for i in 0..D {
                mean[i] += u[i] / n as f64;
                second[i] += u[i] * u[i] / n as f64;
            }
        }
        // Mean 0 and E[u_i^2] = 1/D on every axis (5 standard errors).
        for i in 0..D {
            assert!(
                mean[i].abs() < 5.0 / (n as f64).sqrt(),
                "{D}D mean {mean:?}"
            );
            assert!(
                (second[i] - 1.0 / D as f64).abs() < 5.0 * 0.5 / (n as f64).sqrt(),
                "{D}D second moments {second:?}"
            );
        }
    }

    #[test]
    fn directions_are_unit_vectors_with_isotropic_moments() {
        unit_and_isotropic::<2>();
        unit_and_isotropic::<3>();
    }

    #[test]
    fn every_listed_dimension_has_map_levels_finest_first() {
        for levels in [Dim::<2>::MAP_LEVELS, Dim::<3>::MAP_LEVELS] {
            assert!(!levels.is_empty());
            assert!(
                levels
                    .windows(2)
                    .all(|w| w[0].0 < w[1].0 && w[0].1 < w[1].1)
            );
        }
        assert_eq!(DIMENSIONS, &[2, 3]);
    }
}
