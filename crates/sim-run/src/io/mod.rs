//! Output and checkpoint I/O shared by every model (`docs/architecture.md`, "How data flows
//! through a run").
//!
//! - [`atomic`]: every file is written to a temporary file in its target directory, flushed to
//!   disk and renamed into place, so a crashed or failed run never leaves a partial file.
//! - [`manifest`]: `run.json`, the record of one run (model, version, seed, threads, parameters,
//!   wall and CPU seconds, peak memory from the operating system, results).
//! - [`checkpoint`]: a versioned, checksummed envelope around a model's serde state.
//! - `image` (feature `plot`): grayscale and RGB PNG.
//! - [`table`]: CSV with a header line.
//! - [`hash`]: the stable 64-bit state hash models report as `state_hash`.
//! - [`points`]: point sets (particles, animats) as CSV, `.npy`, legacy VTK or extended XYZ.
//! - [`provenance`]: date, version, git commit, command line, host and CPU of a run.
//! - [`bytes`]: byte counts in flags (`4G`) and messages (`4.0 GiB`).
//! - [`npy`]: rows of `f64` streamed to a NumPy `.npy` file as a run goes (the exception to
//!   atomic writes: an arrival log that a checkpoint refers to).

pub mod atomic;
pub mod bytes;
pub mod checkpoint;
pub mod hash;
#[cfg(feature = "plot")]
pub mod image;
pub mod manifest;
pub mod npy;
pub mod points;
pub mod provenance;
pub mod table;

pub use atomic::{AtomicFile, remove_stale_temporaries, write_atomic};
pub use bytes::{parse_bytes, show_bytes};
pub use checkpoint::{CheckpointError, read_checkpoint, write_checkpoint};
pub use hash::StateHasher;
#[cfg(feature = "plot")]
pub use image::{write_png_gray, write_png_rgb};
pub use manifest::{ProcessUsage, RunClock, RunManifest};
pub use npy::{NpyError, NpyReader, NpyWriter};
pub use points::{Attribute, Coords, PointFormat, PointSet, Positions, write_points};
pub use provenance::{MpiPlace, Provenance};
pub use table::{CsvField, CsvWriter};

/// Why a model's output could not be written (every model's `output::write_outputs`); each
/// displays as the underlying error does.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// Creating, writing or renaming a file.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// Encoding a picture (feature `plot`).
    #[cfg(feature = "plot")]
    #[error(transparent)]
    Image(#[from] image::ImageError),
    /// Serialising the manifest or the parameters in it.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// A stored lattice site that does not decode: the model's state is inconsistent.
    #[error(transparent)]
    Lattice(#[from] core_lattice::LatticeError),
    /// Drawing a figure or writing an animation (`sim_run::figure`, feature `plot`).
    #[error("{0}")]
    Figure(String),
}
