//! Off-lattice diffusion-limited aggregation (DLA) and parallel DLA (PDLA) in 2D and 3D
//! (MODELS.md section 2; Sosa-Herrera & Rodriguez-Romo, seed 002, sections 3.2 to 3.4).
//!
//! A seed particle sits at the origin; walkers are born on the sphere of radius
//! `R_b = R_ext + birth_gap`, move by `vpdist` jumps far from the cluster and `step_min` steps
//! near it, and stick at exact contact (centre distance 1). Outside the birth sphere they are
//! returned to it exactly (harmonic measure) or, as in the paper, jump and die beyond the
//! death radius. The cluster lives in a [`spatial::orthtree::Orthtree`]. See `docs/dla.md`.
//!
//! ```
//! use dla_pdla::{Params, Simulation};
//! let params = Params { particles: 200, ..Params::default() };
//! let mut sim = Simulation::<2>::new(params, 7)?;
//! sim.run()?;
//! assert_eq!(sim.particles(), 200);
//! # Ok::<(), dla_pdla::SimError>(())
//! ```

pub mod cluster;
pub mod farfield;
mod near;
pub mod output;
pub mod params;
pub mod sim;

pub use cluster::Cluster;
pub use params::{FarField, Params, ParamsError};
pub use sim::{Sample, SimError, Simulation, Walker};
