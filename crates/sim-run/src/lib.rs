//! # sim-run
//!
//! Everything around a simulation run that is not the simulation: what the model binaries of
//! the workspace share, usable by any program that runs seeded simulations.
//!
//! - [`count`]: counts as physicists write them (`1e6`, `2.5e5`, `1_000_000`), exactly.
//! - [`declared`]: the docs' flag tables and Python stubs generated from a model's parameter
//!   declaration, and their check.
//! - [`io`]: atomic file writes, the run manifest `run.json` (parameters, seed, wall and CPU
//!   time, peak memory, provenance), the versioned and checksummed checkpoint envelope,
//!   NumPy `.npy` files streamed row by row, PNG (feature `plot`) and CSV writers, point files
//!   (CSV, `.npy`, VTK, XYZ) and the stable state hash.
//! - `cli` (feature `cli`): the model binaries' contract (usage errors: one line, exit code 2,
//!   nothing created; failed runs: exit code 1), `--out` checks, config files, logging,
//!   progress and heartbeat.
//! - `ensemble` (feature `cli`): `--seeds` for every binary, members as child processes or over
//!   the ranks of an MPI job (feature `mpi`), restart, and the merged statistics.
//! - `plot` (feature `plot`): PNG charts with error bands.
//! - `figure` (feature `plot`): figures of model states (axes, scale bar, header, legend,
//!   colour-blind-safe palettes) as PNGs or GIF animations.
//! - `testing` (feature `test-support`): the bad-input harness of the binaries' tests;
//!   `spec_check` (with `cli` too): a binary's flags and its docs table against the model's
//!   parameter table.
//!
//! Conventions: a run is a pure function of its parameters and seed; bad input is a typed
//! error, never a panic; every output file is written atomically (a reader never sees half a
//! file).
//!
//! ```
//! use sim_run::io::{read_checkpoint, write_checkpoint};
//!
//! #[derive(serde::Serialize, serde::Deserialize, PartialEq, Debug)]
//! struct State { step: u64, x: Vec<f64> }
//!
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("state.ckpt");
//! let state = State { step: 3, x: vec![0.5, -1.25] };
//! write_checkpoint(&path, "my-model", &state).unwrap();
//! let back: State = read_checkpoint(&path, "my-model").unwrap();
//! assert_eq!(back, state);
//! // A checkpoint of another model is refused with a typed error, never misread.
//! assert!(read_checkpoint::<State>(&path, "other-model").is_err());
//! ```

#[cfg(feature = "cli")]
pub mod cli;
pub mod count;
pub mod declared;
#[cfg(feature = "cli")]
pub mod ensemble;
#[cfg(feature = "plot")]
pub mod figure;
#[cfg(any(test, feature = "test-support"))]
pub mod fuzz;
pub mod guard;
pub mod io;
pub mod memory;
#[cfg(feature = "cli")]
pub mod model;
#[cfg(feature = "plot")]
pub mod plot;
pub mod schema;
#[cfg(all(feature = "test-support", feature = "cli"))]
pub mod spec_check;
#[cfg(feature = "test-support")]
pub mod testing;
#[cfg(feature = "plot")]
mod text;

/// The README's examples, compiled and run as doctests so that they stay true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
