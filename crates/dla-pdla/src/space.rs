//! The space dimension as a type: [`Dim<D>`] implements [`Space<D>`] for every dimension the
//! model runs in (2, 3, 4 and 5), and owns everything that differs between dimensions: the
//! isotropic random direction of a move, the exact far-field return to the birth sphere, the
//! distance map levels, the expected cluster radius and the axis names of position files.
//!
//! Everything else in the crate is generic over `const D: usize` with a
//! `where Dim<D>: Space<D>` bound, so a dimension without an implementation does not compile,
//! and no code path branches on the dimension at run time. The one run-time choice is the
//! command line's `--dim`: it is checked against [`DIMENSIONS`] by
//! [`Params::validate`](crate::Params::validate) and turned into a type by
//! [`with_dim!`](crate::with_dim), which every front end uses.
//!
//! Invariants: the trait's methods are `#[inline]` and statically dispatched (no trait
//! objects), so a kernel compiles to the same code as if written for its dimension; the
//! floating-point operations of each implementation, and the order of its random draws, are
//! part of the state hash and must not change.
//!
//! # Adding a dimension
//!
//! 1. `impl Space<6> for Dim<6>` here, with a `direction` (any isotropic unit vector, for
//!    example [`core_lattice::rng::unit_vector`]), a `return_to_sphere` (the harmonic measure
//!    of the sphere: [`return_to_sphere_nd`] serves every dimension from 4 on), map levels
//!    measured for that dimension, an `expected_r_ext` and axis names (the orthtree takes up
//!    to 8 dimensions);
//! 2. add the dimension to [`DIMENSIONS`];
//! 3. add one arm to [`with_dim!`](crate::with_dim), the one dispatch on the dimension (the
//!    binary, the Python bindings and `cargo xtask scaling` use it);
//! 4. check the orthtree's index limits against [`max_particles`](crate::params::max_particles).

use crate::farfield::{
    circle_direction, direction_3d, disk_point, exit_ball_3d, exit_ball_nd, exit_disk,
    return_to_circle, return_to_sphere_3d, return_to_sphere_nd,
};
use core_lattice::rng::{Rng, uniform01};

/// The dimensions with a [`Space`] implementation, the accepted values of `--dim`.
pub const DIMENSIONS: &[usize] = &[2, 3, 4, 5];

/// A walker jumps by the distance map's bound `lb` when `lb - 1` exceeds this (diameters);
/// closer to the cluster the tree's sharper bound pays for its cost. The default of
/// [`Space::MAP_JUMP_MIN`]; 2D and 3D, behind their sparse maps, use their own. (Here rather
/// than in `walker`, which uses this module, so that the dependency points one way.)
pub const MAP_JUMP_MIN: f64 = 2.0;

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

    /// For each level of [`MAP_LEVELS`](Self::MAP_LEVELS) from the second on (the first is
    /// lowered by every particle), how it is lowered: `0`, by the box of each new tree leaf;
    /// `n`, by the sub-box of side `cell / n` of its cells that holds the new leaf, once per
    /// sub-box ([`spatial::distmap::DistanceMap::insert_box_by_sub_box`]), when that side is
    /// a whole number of leaf sides (otherwise by the leaf's box). Fewer, larger boxes: fewer
    /// inserts, a bound looser by at most the sub-box's diagonal. Missing entries are `0`.
    const MAP_SUB_BOXES: &'static [usize] = &[];

    /// A sparse fine map in front of [`MAP_LEVELS`](Self::MAP_LEVELS), as `(cell side, cap,
    /// block side in cells)` (diameters; see [`spatial::distmap::SparseDistanceMap`]), or
    /// `None`. Its bound lies within a small cell's diagonal of the distance, so walkers a few
    /// diameters from the cluster jump by it instead of asking the tree; blocks of cells are
    /// allocated only within its cap of the cluster.
    const SPARSE_LEVEL: Option<(f64, f64, usize)> = None;

    /// A walker jumps by a map's bound `lb` (cell not capped) when `lb - 1` exceeds this, in
    /// diameters; closer in it asks the tree or its near cache, whose sharper bound pays for
    /// its cost there.
    const MAP_JUMP_MIN: f64 = MAP_JUMP_MIN;

    /// Axis names, the header of `positions.csv`.
    const AXES: [&'static str; D];

    /// A uniformly random unit vector (the direction of a jump or step).
    fn direction<R: Rng + ?Sized>(rng: &mut R) -> [f64; D];

    /// The point on the sphere of radius `big_r` where a walker at `p` (`|p| > big_r`) is next
    /// found: where Brownian motion from `p` first hits the sphere (harmonic measure), or a
    /// uniform point if it escapes to infinity.
    fn return_to_sphere<R: Rng + ?Sized>(p: &[f64; D], big_r: f64, rng: &mut R) -> [f64; D];

    /// Where Brownian motion from `p`, inside the ball of radius `big_r` around `c`
    /// (`|p - c| < big_r`), first leaves it (harmonic measure of the ball seen from `p`), or
    /// `None` (nothing drawn) for a dimension without a sampler (every supported one has one):
    /// then the walker jumps by the ball of `p`'s own bound instead.
    #[inline(always)]
    fn exit_ball<R: Rng + ?Sized>(
        _p: &[f64; D],
        _c: &[f64; D],
        _big_r: f64,
        _rng: &mut R,
    ) -> Option<[f64; D]> {
        None
    }

    /// A generous estimate of `R_ext` for a cluster of `n` particles, for sizing PDLA's shared
    /// distance maps up front. A cluster that outgrows it only loses the maps' help at its rim.
    fn expected_r_ext(n: u64) -> f64;
}

/// A uniform unit vector in 4D by Marsaglia's method ("Choosing a point from the surface of a
/// sphere", 1972): two [`disk_point`]s `(x1, x2, s1)` and `(x3, x4, s2)`, then
/// `(x1, x2, k x3, k x4)` with `k = sqrt((1 - s1) / s2)`. On the 3-sphere `x1^2 + x2^2` is
/// uniform in `[0, 1]`, as `s1` is, and the second pair only gives a uniform direction in its
/// plane; no trigonometric functions or logarithms. Exact up to the 2^-31 grid of the points.
#[inline(always)]
fn marsaglia_4d<R: Rng + ?Sized>(rng: &mut R) -> [f64; 4] {
    let (x1, x2, s1) = disk_point(rng);
    let (x3, x4, s2) = disk_point(rng);
    let k = ((1.0 - s1) / s2).max(0.0).sqrt();
    [x1, x2, k * x3, k * x4]
}

impl Space<2> for Dim<2> {
    /// Behind the sparse map of 2-diameter cells ([`SPARSE_LEVEL`](Self::SPARSE_LEVEL)), dense
    /// maps of 16, 64, 256 and 2048-diameter cells capped at 64, 512, 2048 and 16384: the
    /// finest lowered by every particle (about 50 cells), the coarser by the box of each new
    /// tree leaf. Each cap is four to eight times the finer level's, so a walker at any
    /// distance up to 16384 reads a level whose cells are small beside its distance; the
    /// coarsest levels answer the walkers in the wide empty regions of a large cluster, which
    /// would otherwise ask the tree at every move (`docs/benchmarks.md`, "DLA at scale"). The
    /// three coarsest are small (about 3 MB at 1e8 particles) and read first, so such a
    /// walker's move reads no uncached memory. These levels, the sparse map
    /// and the jump threshold were chosen by instruction counts at 1e6: a dense level of
    /// 8-diameter cells behind the sparse map saves nothing and costs 0.6 byte per particle
    /// (`docs/benchmarks.md`, "2D distance maps").
    const MAP_LEVELS: &'static [(f64, f64)] = &[
        (16.0, 64.0),
        (64.0, 512.0),
        (256.0, 2048.0),
        (2048.0, 16384.0),
    ];

    /// The two coarsest levels by sub-boxes of 32 and 256 diameters (8 a cell side): a new
    /// leaf lowers them only when it is the first in such a box, and their bounds lose at
    /// most an eighth of their cells' diagonal; the 64-diameter level keeps the leaves'
    /// boxes (chosen by instruction counts, `docs/benchmarks.md`, "2D distance maps").
    const MAP_SUB_BOXES: &'static [usize] = &[0, 0, 8, 8];

    /// Cells of 2 diameters capped at 8, in blocks of 16^2 cells (256 bytes, 32 diameters a
    /// side), allocated only near the cluster: about 2.4 bytes per particle. Walkers 3-8
    /// diameters from the cluster jump by its bound instead of asking the tree.
    const SPARSE_LEVEL: Option<(f64, f64, usize)> = Some((2.0, 8.0, 16));

    /// Half a diameter, as in 3D: behind the sparse map's tight bound even short jumps cost
    /// less than the near-cache answers they replace.
    const MAP_JUMP_MIN: f64 = 0.5;

    const AXES: [&'static str; 2] = ["x", "y"];

    /// The circle direction (`circle_direction`: one draw, no rejection).
    #[inline(always)]
    fn direction<R: Rng + ?Sized>(rng: &mut R) -> [f64; 2] {
        let (c, s) = circle_direction(rng);
        [c, s]
    }

    /// [`return_to_circle`].
    #[inline]
    fn return_to_sphere<R: Rng + ?Sized>(p: &[f64; 2], big_r: f64, rng: &mut R) -> [f64; 2] {
        return_to_circle(p, big_r, rng)
    }

    /// [`exit_disk`].
    #[inline(always)]
    fn exit_ball<R: Rng + ?Sized>(
        p: &[f64; 2],
        c: &[f64; 2],
        big_r: f64,
        rng: &mut R,
    ) -> Option<[f64; 2]> {
        Some(exit_disk(p, c, big_r, rng))
    }

    /// 1.3 times `0.85 n^(1/1.71)`: the off-lattice DLA dimension 1.71 with a prefactor fitted
    /// to grown clusters.
    #[inline]
    fn expected_r_ext(n: u64) -> f64 {
        1.3 * (0.85 * (n as f64).powf(1.0 / 1.71))
    }
}

impl Space<3> for Dim<3> {
    /// A fine map of 8-diameter cells capped at 32 and coarse ones of 32 and 128-diameter
    /// cells capped at 128 and 512 (about 270 cells lowered per insert and map; the coarse
    /// ones by the box of each new tree leaf). The coarsest answers the walkers more than 128
    /// from a cluster of 1e7 or more, which otherwise asked the tree at every move.
    const MAP_LEVELS: &'static [(f64, f64)] = &[(8.0, 32.0), (32.0, 128.0), (128.0, 512.0)];

    /// Cells of 2 diameters capped at 8, in blocks of 8^3 cells (512 bytes, 16 diameters a
    /// side): about 270 cells visited per insert, and about 6 bytes per particle at 1e6 (the
    /// cap's neighbourhood of a 3D cluster fills much of its ball). A cap of 6 saves less in
    /// inserts than its walkers lose; four bits per cell (half the memory) lose more in
    /// moves than they save (`docs/tuning.md`, "3D DLA").
    const SPARSE_LEVEL: Option<(f64, f64, usize)> = Some((2.0, 8.0, 8));

    /// Half a diameter: the sparse map's bound lies within a 2-diameter cell's diagonal of the
    /// distance, so even its short jumps near the cluster cost less than the tree queries and
    /// near-cache answers they replace (callgrind at 1e5: 0.98x the instructions of 1 diameter,
    /// 0.84x those of 2).
    const MAP_JUMP_MIN: f64 = 0.5;

    const AXES: [&'static str; 3] = ["x", "y", "z"];

    /// `z` uniform in `[-1, 1]` (Archimedes), then the azimuth from a circle direction.
    #[inline(always)]
    fn direction<R: Rng + ?Sized>(rng: &mut R) -> [f64; 3] {
        direction_3d(rng)
    }

    /// [`return_to_sphere_3d`].
    #[inline]
    fn return_to_sphere<R: Rng + ?Sized>(p: &[f64; 3], big_r: f64, rng: &mut R) -> [f64; 3] {
        return_to_sphere_3d(p, big_r, rng)
    }

    /// [`exit_ball_3d`].
    #[inline(always)]
    fn exit_ball<R: Rng + ?Sized>(
        p: &[f64; 3],
        c: &[f64; 3],
        big_r: f64,
        rng: &mut R,
    ) -> Option<[f64; 3]> {
        Some(exit_ball_3d(p, c, big_r, rng))
    }

    /// 1.3 times `1.15 n^(1/2.5)`: the off-lattice DLA dimension 2.5 with a prefactor fitted
    /// to grown clusters.
    #[inline]
    fn expected_r_ext(n: u64) -> f64 {
        1.3 * (1.15 * (n as f64).powf(1.0 / 2.5))
    }
}

impl Space<4> for Dim<4> {
    /// One map of 8-diameter cells capped at 32 (about 1 260 cells lowered per insert).
    /// Instruction counts per particle (cachegrind, 5e3 particles, seeds 1 and 2): 0.60 M,
    /// against 0.77 M without maps, 0.69 M with the 3D-like second level (32, 128) (it changed
    /// no move in those runs, whose trajectories were the same: it only costs its inserts) and
    /// 0.51-0.62 M with 4-diameter cells capped at 16, which hold 16 times the memory and were
    /// slower at 3e4 (CPU times in `docs/dla.md`, "Dimensions 4 and 5").
    const MAP_LEVELS: &'static [(f64, f64)] = &[(8.0, 32.0)];

    const AXES: [&'static str; 4] = ["x", "y", "z", "w"];

    /// Marsaglia's method ("Choosing a point from the surface of a sphere", 1972): two points
    /// `(x1, x2)` and `(x3, x4)` uniform in the unit disk, then `(x1, x2, k x3, k x4)` with
    /// `k = sqrt((1 - s1) / s2)`, `s` their squared norms.
    #[inline(always)]
    fn direction<R: Rng + ?Sized>(rng: &mut R) -> [f64; 4] {
        marsaglia_4d(rng)
    }

    /// [`return_to_sphere_nd`].
    #[inline]
    fn return_to_sphere<R: Rng + ?Sized>(p: &[f64; 4], big_r: f64, rng: &mut R) -> [f64; 4] {
        return_to_sphere_nd(p, big_r, rng)
    }

    /// [`exit_ball_nd`].
    #[inline]
    fn exit_ball<R: Rng + ?Sized>(
        p: &[f64; 4],
        c: &[f64; 4],
        big_r: f64,
        rng: &mut R,
    ) -> Option<[f64; 4]> {
        Some(exit_ball_nd(p, c, big_r, rng))
    }

    /// 1.3 times `1.7 n^(1/3.4)`: the literature's 4D dimension 3.40 with the prefactor of
    /// grown clusters (mean `R_ext` 26.1 at 1e4 over 32 clusters, 50.1 at 1e5 over 8; the
    /// largest was 1.13 times the mean).
    #[inline]
    fn expected_r_ext(n: u64) -> f64 {
        1.3 * (1.7 * (n as f64).powf(1.0 / 3.4))
    }
}

impl Space<5> for Dim<5> {
    /// One map of 4-diameter cells capped at 16 (about 5 400 cells lowered per insert). A map's
    /// bound lies up to a cell diagonal below the distance: 17.9 diameters for 8-diameter
    /// cells in 5D, most of the way to the cluster for walkers near it, 8.9 here. Instruction
    /// counts per particle (cachegrind, 2e3 particles, seeds 1 and 2): 1.9 M, against 2.5-2.7
    /// M with (8, 32), 2.6 M with a second level (16, 64) and 2.5-4.1 M without maps; CPU time
    /// at 1e4 (seeds 1-3) 333-361 microseconds per particle against 453-541 with (8, 32). The
    /// price is memory: one byte per cell of side 4 over the cube the cluster grows in, 100 to
    /// 300 bytes per particle from 1e4 to 1e6 particles (`docs/dla.md`).
    const MAP_LEVELS: &'static [(f64, f64)] = &[(4.0, 16.0)];

    const AXES: [&'static str; 5] = ["x", "y", "z", "w", "v"];

    /// The last axis `v` from the density `(3/4) (1 - v^2)` of one coordinate of a uniform
    /// point on the 4-sphere, as the median of three uniforms in `[-1, 1]` (whose density is
    /// `(3/4) (1 - v^2)`), then the other four a 4D direction (Marsaglia's) scaled by
    /// `sqrt(1 - v^2)`: a uniform point on the 4-sphere is `(sqrt(1 - v^2) w, v)` with `w`
    /// uniform on the 3-sphere and independent of `v`.
    #[inline(always)]
    fn direction<R: Rng + ?Sized>(rng: &mut R) -> [f64; 5] {
        let a = 2.0 * uniform01(rng) - 1.0;
        let b = 2.0 * uniform01(rng) - 1.0;
        let c = 2.0 * uniform01(rng) - 1.0;
        let v = a.max(b).min(a.min(b).max(c));
        let rho = (1.0 - v * v).max(0.0).sqrt();
        let w = marsaglia_4d(rng);
        [rho * w[0], rho * w[1], rho * w[2], rho * w[3], v]
    }

    /// [`return_to_sphere_nd`].
    #[inline]
    fn return_to_sphere<R: Rng + ?Sized>(p: &[f64; 5], big_r: f64, rng: &mut R) -> [f64; 5] {
        return_to_sphere_nd(p, big_r, rng)
    }

    /// [`exit_ball_nd`].
    #[inline]
    fn exit_ball<R: Rng + ?Sized>(
        p: &[f64; 5],
        c: &[f64; 5],
        big_r: f64,
        rng: &mut R,
    ) -> Option<[f64; 5]> {
        Some(exit_ball_nd(p, c, big_r, rng))
    }

    /// 1.3 times `1.95 n^(1/4.3)`: the literature's 5D dimension 4.33 (rounded) with the
    /// prefactor of grown clusters (mean `R_ext` 12.5 at 3e3 over 32 clusters, 21.3 at 3e4
    /// over 8; the largest was 1.23 times the mean).
    #[inline]
    fn expected_r_ext(n: u64) -> f64 {
        1.3 * (1.95 * (n as f64).powf(1.0 / 4.3))
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
        unit_and_isotropic::<4>();
        unit_and_isotropic::<5>();
    }

    #[test]
    fn every_listed_dimension_has_map_levels_finest_first() {
        for levels in [
            Dim::<2>::MAP_LEVELS,
            Dim::<3>::MAP_LEVELS,
            Dim::<4>::MAP_LEVELS,
            Dim::<5>::MAP_LEVELS,
        ] {
            assert!(
                levels
                    .windows(2)
                    .all(|w| w[0].0 < w[1].0 && w[0].1 < w[1].1)
            );
        }
        // The caps nest: where a level is capped every finer one is too, so the maps can be
        // read coarsest first and stop at the first capped one (`Cluster::map_bounds`).
        fn nest<const D: usize>()
        where
            Dim<D>: Space<D>,
        {
            let half = |cell: f64| 0.5 * cell * (D as f64).sqrt();
            let sparse = Dim::<D>::SPARSE_LEVEL.map(|(cell, cap, _)| (cell, cap));
            let levels: Vec<_> = sparse
                .into_iter()
                .chain(Dim::<D>::MAP_LEVELS.iter().copied())
                .collect();
            for w in levels.windows(2) {
                let ((fine, fine_cap), (coarse, coarse_cap)) = (w[0], w[1]);
                assert!(
                    coarse_cap - half(coarse) > fine_cap + half(fine),
                    "{D}D: {:?} does not nest in {:?}",
                    w[0],
                    w[1]
                );
            }
        }
        nest::<2>();
        nest::<3>();
        nest::<4>();
        nest::<5>();
        assert_eq!(DIMENSIONS, &[2, 3, 4, 5]);
    }
}
