//! [`SimError`], the errors of a run: bad parameters, a particle the orthtree or the distance
//! maps refuse, checkpoint trouble, and PDLA's livelock guard. Every module that can fail
//! returns it; it depends on no other module of the crate but [`params`](crate::params).

use crate::params::ParamsError;
use spatial::distmap::DistanceMapError;
use spatial::orthtree::OrthtreeError;

/// Errors of a run.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// Invalid parameters.
    #[error(transparent)]
    Params(#[from] ParamsError),
    /// `D` (first) does not match `params.dim` (second).
    #[error("parameters for {1} dimensions given to a {0}-dimensional simulation")]
    DimMismatch(usize, usize),
    /// The orthtree refused a particle (coordinate range or capacity).
    #[error("storing a particle: {0}")]
    Tree(#[from] OrthtreeError),
    /// The distance map refused a particle (too large a cluster for its memory).
    #[error("distance map: {0}")]
    Map(#[from] DistanceMapError),
    /// A checkpoint could not be written or read (the message says so).
    #[error(transparent)]
    #[cfg(feature = "files")]
    Checkpoint(#[from] run_io::CheckpointError),
    /// Checkpoints need one thread and the positions kept in memory; or a checkpoint does not
    /// match the run it should continue (the message says which).
    #[error("{0}")]
    CheckpointUsage(String),
    /// Writing `positions.npy` or `growth.csv` as the run grows failed (the message names the
    /// file).
    #[error("{0}")]
    Stream(String),
    /// With `connectivity`, the particle a walker touched is not in the tree: a broken
    /// invariant (the contact query returns stored positions), reported rather than
    /// recorded as a wrong parent.
    #[error("the particle touched at {0} is not stored; its parent cannot be named")]
    ParentUnknown(String),
    /// PDLA discarded [`MAX_CONSECUTIVE_DISCARDS`](crate::sim::MAX_CONSECUTIVE_DISCARDS)
    /// walkers in a row without storing one.
    #[error(
        "PDLA livelock: {consecutive} walkers in a row discarded at the re-check ({total} in all); \
         the contact or re-check is broken"
    )]
    DiscardLivelock {
        /// Discarded in a row.
        consecutive: u64,
        /// Discarded in all.
        total: u64,
    },
}
