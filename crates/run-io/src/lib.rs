//! # run-io
//!
//! A run's files and provenance, for any program that runs seeded simulations: what every
//! aggsim model writes and reads, without its command line or its figures.
//!
//! Always (no dependency beyond the standard library and one hash):
//! - [`count`]: counts as physicists write them (`1e6`, `2.5e5`, `1_000_000`), exactly.
//! - [`memory`]: the memory a run may take, checked before the work, and fallible large
//!   allocations.
//! - [`guard`]: what keeps a long run from being lost: timed checkpoints, signals and the
//!   memory watch, through one flag the run's loop polls.
//! - [`hash`]: the stable 64-bit state hash models report as `state_hash`.
//! - [`bytes`]: byte counts in flags (`4G`) and messages (`4.0 GiB`).
//! - [`schema`]: the schema of every output (files, columns, dtypes, units).
//!
//! Feature `files` (default):
//! - [`atomic`]: every file is written to a temporary file in its target directory, flushed to
//!   disk and renamed into place, so a crashed or failed run never leaves a partial file.
//! - [`manifest`]: `run.json`, the record of one run (model, version, seed, threads, parameters,
//!   wall and CPU seconds, peak memory from the operating system, results).
//! - [`provenance`]: date, version, git commit, command line, host and CPU of a run.
//! - [`checkpoint`]: a versioned, checksummed envelope around a model's serde state.
//! - [`table`]: CSV with a header line.
//! - [`points`]: point sets (particles, animats) as CSV, `.npy`, legacy VTK or extended XYZ.
//! - [`npy`]: rows of `f64` streamed to a NumPy `.npy` file as a run goes (the exception to
//!   atomic writes: an arrival log that a checkpoint refers to).
//! - [`params_json`]: a model's parameters as the JSON object `run.json` records.
//!
//! Conventions: a run is a pure function of its parameters and seed; bad input is a typed
//! error, never a panic; every output file is written atomically (a reader never sees half a
//! file).
//!
//! ```
//! use run_io::{read_checkpoint, write_checkpoint};
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

#[cfg(feature = "files")]
pub mod atomic;
pub mod bytes;
#[cfg(feature = "files")]
pub mod checkpoint;
pub mod count;
pub mod guard;
pub mod hash;
#[cfg(feature = "files")]
pub mod manifest;
pub mod memory;
#[cfg(feature = "files")]
pub mod npy;
#[cfg(feature = "files")]
pub mod params_json;
#[cfg(feature = "files")]
pub mod points;
#[cfg(feature = "files")]
pub mod provenance;
pub mod schema;
#[cfg(feature = "files")]
pub mod table;

#[cfg(feature = "files")]
pub use atomic::{AtomicFile, remove_stale_temporaries, write_atomic};
pub use bytes::{parse_bytes, show_bytes};
#[cfg(feature = "files")]
pub use checkpoint::{CheckpointError, read_checkpoint, write_checkpoint};
pub use hash::StateHasher;
#[cfg(feature = "files")]
pub use manifest::{ProcessUsage, RunClock, RunManifest};
#[cfg(feature = "files")]
pub use npy::{NpyError, NpyReader, NpyWriter};
#[cfg(feature = "files")]
pub use points::{Attribute, Coords, PointFormat, PointSet, Positions, write_points};
#[cfg(feature = "files")]
pub use provenance::{MpiPlace, Provenance};
#[cfg(feature = "files")]
pub use table::{CsvField, CsvWriter};

#[cfg(feature = "files")]
/// Why a model's output could not be written (every model's `output::write_outputs`); each
/// displays as the underlying error does.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// Creating, writing or renaming a file.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// Serialising the manifest or the parameters in it.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// A stored lattice site that does not decode: the model's state is inconsistent.
    #[error(transparent)]
    Lattice(#[from] core_lattice::LatticeError),
    /// Drawing or encoding a figure, or writing an animation (the `figures` crate).
    #[error("{0}")]
    Figure(String),
}

/// The README's examples, compiled and run as doctests so that they stay true.
#[cfg(all(doctest, feature = "files"))]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
