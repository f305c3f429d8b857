//! Statistics the models and the scaling harness share.
//!
//! - [`Welford`]: running mean and variance in one pass, numerically stable, mergeable (for
//!   per-thread accumulators).
//! - [`IntHistogram`] and [`LogHistogram`]: the candidate-count histograms of Hawick, James &
//!   Scogings (2006, Figs. 4, 7, 8) and cluster-size distributions.
//! - [`Fit`]: ordinary least squares with standard errors, on linear or log-log axes
//!   ([`Fit::linear`], [`Fit::log_log`]): log-log gradients, fractal dimensions from
//!   `ln N = D ln R_g + c`, linear run-time fits.
//! - [`Gyration`]: the radius of gyration of a point set in `D` dimensions (Sosa-Herrera &
//!   Rodriguez-Romo, section 3.4), accumulated with Welford updates so it stays accurate for
//!   clusters far from the origin.
//! - [`LatticeGyration`]: the same for integer lattice coordinates (DLCA clusters),
//!   with exact integer sums.

mod fit;
mod gyration;
mod histogram;
#[cfg(test)]
mod tests;
mod welford;

pub use fit::{Fit, FitScale};
pub use gyration::{Gyration, LatticeGyration};
pub use histogram::{IntHistogram, LogHistogram};
pub use welford::Welford;

/// Errors from statistics that refuse bad input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StatsError {
    /// A fit was asked of fewer than three points (no standard error is possible).
    #[error("a fit needs at least 3 points, got {0}")]
    TooFewPoints(usize),
    /// The x and y slices differ in length.
    #[error("x has {x} values but y has {y}")]
    LengthMismatch {
        /// Length of x.
        x: usize,
        /// Length of y.
        y: usize,
    },
    /// A value that must be positive (for logarithms) is not.
    #[error("point {index} has a non-positive value (x = {x}, y = {y}); logarithms need x, y > 0")]
    NonPositive {
        /// Index of the point.
        index: usize,
        /// Its x.
        x: f64,
        /// Its y.
        y: f64,
    },
    /// A NaN or infinite value.
    #[error("point {index} is not finite (x = {x}, y = {y})")]
    NonFinite {
        /// Index of the point.
        index: usize,
        /// Its x.
        x: f64,
        /// Its y.
        y: f64,
    },
    /// Every x is the same: the slope is undefined.
    #[error("all x values are equal ({0}); the slope is undefined")]
    Degenerate(f64),
    /// A histogram parameter outside its range.
    #[error("{0}")]
    BadParameter(String),
}
