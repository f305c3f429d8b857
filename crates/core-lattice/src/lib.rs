//! # core-lattice
//!
//! The foundation every model of the workspace stands on, with nothing that does I/O:
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
//! - [`hint`]: a cache prefetch hint.
//!
//! Feature `serde` (default) makes lattices, random streams and statistics serialisable, for
//! checkpoints and manifests. Everything around a run is in the crates `run-io` (outputs,
//! checkpoints), `run-cli` (the command line, ensembles) and `figures`.
//!
//! Conventions: a run is a pure function of its parameters and seed; bad input is a typed error,
//! never a panic.
//!
//! ```
//! use core_lattice::rng::RngExt;
//! use core_lattice::{Boundary, Direction, Lattice, stream};
//!
//! // A 16 x 8 lattice, periodic along x, walled along y.
//! let lattice = Lattice::new(&[16, 8], &[Boundary::Periodic, Boundary::Wall]).unwrap();
//! assert_eq!(lattice.volume(), 128);
//! let k = lattice.encode(&[15, 3]).unwrap(); // k = x1 + x2 L1
//! assert_eq!(k, 15 + 3 * 16);
//! // One step in +x wraps around the periodic axis; one step in +y from the top row is blocked.
//! let right = lattice.neighbour(k, Direction::new(0, true)).unwrap();
//! assert_eq!(lattice.decode(right).unwrap()[0], 0);
//! assert!(lattice.neighbour(lattice.encode(&[0, 7]).unwrap(), Direction::new(1, true)).is_none());
//!
//! // The same (seed, stream) always gives the same numbers.
//! let (mut a, mut b) = (stream(42, 7), stream(42, 7));
//! assert_eq!(a.random::<u64>(), b.random::<u64>());
//! ```

pub mod cpu;
pub mod hint;
pub mod lattice;
pub mod rng;
pub mod spec;
pub mod stats;

pub use lattice::{Blocked, Boundary, Coords, Direction, Lattice, LatticeError, MAX_DIM, Offset};
pub use rng::{SimRng, stream, stream_id};
pub use stats::{Fit, FitScale, Gyration, IntHistogram, LatticeGyration, LogHistogram, Welford};

/// The README's examples, compiled and run as doctests so that they stay true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
