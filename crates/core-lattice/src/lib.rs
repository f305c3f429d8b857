//! # core-lattice
//!
//! The foundation every model of the workspace stands on:
//!
//! - [`lattice`]: d-dimensional hypercubic lattices (d = 1..=8) addressed by the k-index of
//!   Hawick, James & Scogings (2006, section III, Fig. 3), with periodic or wall boundaries
//!   per axis, face neighbours, unit translations and minimum-image displacements.
//! - [`rng`]: deterministic `Pcg64Mcg` streams derived from `(seed, stream id)`, and the sampling
//!   helpers the models share (isotropic unit vectors, weighted lattice directions, shuffles).
//! - [`stats`]: Welford mean/variance, integer and logarithmic histograms, least-squares and
//!   log-log fits with standard errors, and radius-of-gyration accumulators that stay accurate
//!   far from the origin.
//! - [`spec`]: descriptions of model parameters (name, flag, unit, range), one table per model
//!   that the front ends are derived from or checked against.
//! - [`cpu`]: the processor features the build was compiled for, checked at start.
//! - [`io`]: atomic file writes, the run manifest `run.json`, the checkpoint envelope, PNG and
//!   CSV writers, and the stable state hash.
//! - `cli` (feature `cli`): the model binaries' contract (usage errors: one line, exit code 2,
//!   nothing created; failed runs: exit code 1), `--out` checks, logging, progress and heartbeat.
//! - `testing` (feature `test-support`): the bad-input harness of the binaries' tests.
//!
//! Conventions (see `docs/architecture.md`): a run is a pure function of its parameters and seed;
//! bad input is a typed error, never a panic; every output file is written atomically.

#[cfg(feature = "cli")]
pub mod cli;
pub mod cpu;
#[cfg(feature = "cli")]
pub mod ensemble;
pub mod io;
pub mod lattice;
#[cfg(feature = "plot")]
pub mod plot;
pub mod rng;
pub mod spec;
pub mod stats;
#[cfg(feature = "test-support")]
pub mod testing;

pub use lattice::{Blocked, Boundary, Coords, Direction, Lattice, LatticeError, MAX_DIM, Offset};
pub use rng::{SimRng, stream, stream_id};
pub use stats::{Fit, FitScale, Gyration, IntHistogram, LatticeGyration, LogHistogram, Welford};
