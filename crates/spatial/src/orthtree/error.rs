//! What the orthtree's construction, inserts and shared inserts can refuse.

/// Errors of the orthtree (construction parameters and inserted points).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OrthtreeError {
    /// A coordinate of an inserted point is NaN or infinite.
    #[error("coordinate {axis} of the point is {value}; expected a finite number")]
    NonFinite {
        /// Axis of the offending coordinate.
        axis: usize,
        /// The offending value.
        value: f64,
    },
    /// A coordinate is too large for exact cell geometry.
    #[error("coordinate {axis} of the point is {value}; expected |x| < {limit} (2^50 leaf sides)")]
    OutOfRange {
        /// Axis of the offending coordinate.
        axis: usize,
        /// The offending value.
        value: f64,
        /// The exclusive bound on `|x|`.
        limit: f64,
    },
    /// The leaf side is not a power of two in the accepted range.
    #[error(
        "leaf side {0} is invalid; expected a power of two in [2^-20, 2^11] (default 4 diameters)"
    )]
    InvalidLeafSide(f64),
    /// The precision `kappa` is not usable (see
    /// [`Orthtree::check_kappa`](super::Orthtree::check_kappa)).
    #[error(
        "kappa {0} is invalid; expected kappa > 0.5 (paper value 2) or +inf for the exact search"
    )]
    InvalidKappa(f64),
    /// The tree is full: its 32-bit indices (or a limit set by
    /// [`Orthtree::set_index_limit`](super::Orthtree::set_index_limit)) cannot number another
    /// node, leaf or point slot.
    #[error("orthtree capacity exceeded: no index left for more {0}")]
    CapacityExceeded(&'static str),
    /// The allocator refused to grow the tree's arrays; the tree holds the same points as
    /// before the call.
    #[error("cannot allocate {bytes} bytes for the orthtree's arrays")]
    OutOfMemory {
        /// The size of the allocation refused.
        bytes: usize,
    },
    /// A shared insert ([`Orthtree::insert_shared`](super::Orthtree::insert_shared)) needs the
    /// root grown or more capacity than
    /// [`Orthtree::prepare_shared`](super::Orthtree::prepare_shared) reserved: both need
    /// exclusive access.
    #[error(
        "the point needs the orthtree's root or capacity grown, which a shared insert cannot do; insert it with exclusive access"
    )]
    NeedsExclusive,
    /// [`Orthtree::keep_tags`](super::Orthtree::keep_tags) on a tree that already holds points,
    /// whose tags are unknown.
    #[error("the orthtree can keep tags only from its first point")]
    TagsOnNonEmpty,
}
