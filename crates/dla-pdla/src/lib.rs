//! Off-lattice diffusion-limited aggregation (DLA) and parallel DLA (PDLA) in 2D to 5D, after
//! Sosa-Herrera & Rodriguez-Romo, "Variable precision distance search for random fractal
//! cluster simulations" (sections 3.2 to 3.4).
//!
//! A seed particle sits at the origin; walkers are born on the sphere of radius
//! `R_b = R_ext + birth_gap`, move by `vpdist` jumps far from the cluster and `step_min` steps
//! near it, and stick at exact contact (centre distance 1). Outside the birth sphere they are
//! returned to it exactly (harmonic measure) or, as in the paper, jump and die beyond the
//! death radius. The cluster lives in a [`spatial::orthtree::Orthtree`]. See `docs/dla.md`.
//!
//! | module | owns |
//! |---|---|
//! | [`farfield`] | the exact far-field return samplers and the ball-exit samplers of the walk |
//! | [`space`] | everything dimension-specific ([`Dim`], [`Space`]) |
//! | [`params`] | the run's parameters, their table ([`params::PARAMS`]) and validation |
//! | [`error`] | [`SimError`] |
//! | [`cluster`] | the stored particles: orthtree and distance maps |
//! | `near` | a walker's near cache (private) |
//! | [`walker`] | one walker's moves |
//! | [`sim`] | the simulation: serial DLA, PDLA, checkpoints, observables |
//! | `output` | the output files of a finished run (feature `files`) |
//!
//! Each module uses only modules above it in this list (no import cycles).
//!
//! With the default feature `cli` the parameter enums implement `clap::ValueEnum` and the `dla`
//! binary is built; without it the library does not depend on clap. Without `files` (implied
//! by `cli` and `figures`) it writes no files: `output`, checkpoints and streamed positions
//! are compiled out.
//!
//! ```
//! use dla_pdla::{Params, Simulation};
//! let params = Params { particles: 200, ..Params::default() };
//! let mut sim = Simulation::<2>::new(params, 7)?;
//! sim.run()?;
//! assert_eq!(sim.particles(), 200);
//! # Ok::<(), dla_pdla::SimError>(())
//! ```

pub mod branches;
pub mod cluster;
mod contact;
pub mod deposit;
pub mod error;
pub mod farfield;
#[cfg(feature = "figures")]
pub mod figure;
mod near;
#[cfg(feature = "files")]
pub mod output;
pub mod params;
pub mod seeds;
pub mod sim;
pub mod space;
pub mod substrate;
pub mod walker;

pub use cluster::Cluster;
pub use error::SimError;
pub use params::{FarField, Params, ParamsError};
pub use sim::{Sample, Simulation};
pub use space::{Dim, Space};
pub use walker::Walker;

/// The one run-time dimension dispatch, shared by every front end (the `dla` binary, Python,
/// xtask): evaluates `$body` with the constant `$D` set to `$dim` when it is one of
/// [`space::DIMENSIONS`], else `$fallback` with `$other` matched against the value.
///
/// ```
/// use dla_pdla::{Params, Simulation};
/// let params = Params { dim: 3, particles: 50, ..Params::default() };
/// let n = dla_pdla::with_dim!(params.dim, D => {
///     let mut sim = Simulation::<D>::new(params.clone(), 1)?;
///     sim.run()?;
///     sim.particles()
/// }, d => panic!("no {d}D"));
/// assert_eq!(n, 50);
/// # Ok::<(), dla_pdla::SimError>(())
/// ```
#[macro_export]
macro_rules! with_dim {
    ($dim:expr, $D:ident => $body:expr, $other:pat => $fallback:expr $(,)?) => {
        match $dim {
            2 => {
                const $D: usize = 2;
                $body
            }
            3 => {
                const $D: usize = 3;
                $body
            }
            4 => {
                const $D: usize = 4;
                $body
            }
            5 => {
                const $D: usize = 5;
                $body
            }
            $other => $fallback,
        }
    };
}

/// The README's examples, compiled and run as doctests so that they stay true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
