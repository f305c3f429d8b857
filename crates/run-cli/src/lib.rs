//! # run-cli
//!
//! The command line of seeded simulation binaries, as the aggsim models (`dla`, `dlca`,
//! `animat`) share it; a run's files are the `run-io` crate's, its figures the `figures`
//! crate's.
//!
//! - [`model`]: the model contract ([`model::Model`]) and the one generic `main` of every
//!   binary: flags, config files, `--out`, ensembles, the run and its manifest.
//! - [`cli`]: the binaries' contract (usage errors: one line, exit code 2, nothing created;
//!   failed runs: exit code 1), `--out` checks, config files, logging, progress and heartbeat,
//!   signals as a flag a long run polls.
//! - [`ensemble`]: `--seeds` for every binary, members as child processes or over the ranks of
//!   an MPI job (feature `mpi`), restart, and the merged statistics.
//! - [`declared`]: the docs' flag tables and Python stubs generated from a model's parameter
//!   declaration, and their check.
//! - `testing` (feature `test-support`): the bad-input harness of the binaries' tests;
//!   `spec_check`: a binary's flags and its docs table against the model's parameter table.
//!
//! Conventions: a run is a pure function of its parameters and seed; bad input is a typed
//! error, never a panic; every output file is written atomically (a reader never sees half a
//! file).

pub mod cli;
pub mod declared;
pub mod ensemble;
#[cfg(any(test, feature = "test-support"))]
pub mod fuzz;
pub mod model;
#[cfg(feature = "test-support")]
pub mod spec_check;
#[cfg(feature = "test-support")]
pub mod testing;

/// The README's examples, compiled and run as doctests so that they stay true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
