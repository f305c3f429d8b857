//! # dlca: diffusion-limited cluster-cluster aggregation
//!
//! The DLCA model of Hawick, James & Scogings 2006, "Grid-Boxing for Spatial Simulation
//! Performance Optimisation" (sections II.A, III, IV.A), as defined in docs/dlca.md: particles
//! on a periodic or walled hypercubic lattice in 1 to 5 dimensions form clusters that
//! random-walk one lattice step at a time and stick on contact. Three contact searches
//! (all-pairs, grid boxes, occupancy lattice) give bit-identical trajectories.
//!
//! Layout: [`params`] (validated parameters), [`sim`] (the run: placement, sweep, strategy
//! choice, checkpoints), `store` (the strategies behind one `ClusterStore` interface), `rigid`
//! (the rigid-cluster kernels of the `lattice` strategy, one per dimension), [`record`] (what a
//! run records as it goes), [`analysis`] and `output` (final measurements and files; feature
//! `files`). The library builds without the command line (`--no-default-features`); feature
//! `cli` (default) adds clap's derives and the `dlca` binary.
//!
//! ```
//! use dlca::{Params, Init, Simulation};
//! let params = Params {
//!     size: vec![64, 64],
//!     boundary: vec![core_lattice::Boundary::Periodic; 2],
//!     init: Init::Fill(0.05),
//!     target_clusters: 10,
//!     ..Params::default()
//! };
//! let mut sim = Simulation::new(params, 42).unwrap();
//! sim.run();
//! assert!(sim.clusters() <= 10);
//! ```

pub mod analysis;
#[cfg(feature = "figures")]
pub mod figure;
#[cfg(feature = "files")]
pub mod output;
pub mod params;
pub mod record;
mod rigid;
pub mod sim;
mod store;

pub use params::{Init, ParamError, Params, Search};
pub use sim::{Simulation, Snapshot};

/// The README's examples, compiled and run as doctests so that they stay true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
