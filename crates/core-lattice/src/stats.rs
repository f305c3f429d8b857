//! Statistics the models and the scaling harness share.
//!
//! - [`Welford`]: running mean and variance in one pass, numerically stable, mergeable (for
//!   per-thread accumulators).
//! - [`IntHistogram`] and [`LogHistogram`]: the candidate-count histograms of seed 000 (Figs. 4,
//!   7, 8) and cluster-size distributions.
//! - [`Fit`]: ordinary least squares with standard errors, on linear or log-log axes
//!   ([`Fit::linear`], [`Fit::log_log`]): log-log gradients, fractal dimensions from
//!   `ln N = D ln R_g + c`, linear run-time fits.
//! - [`Gyration`]: the radius of gyration of a point set in `D` dimensions (seed 002 section 3.4),
//!   accumulated with Welford updates so it stays accurate for clusters far from the origin.
//! - [`LatticeGyration`]: the same for integer lattice coordinates (DLCA clusters, seed 000),
//!   with exact integer sums.

use serde::{Deserialize, Serialize};

/// Running count, mean and variance (Welford 1962), stable for large means and long runs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Welford {
    n: u64,
    mean: f64,
    /// Sum of squared deviations from the running mean.
    m2: f64,
    min: f64,
    max: f64,
}

impl Welford {
    /// An empty accumulator.
    pub fn new() -> Self {
        Self::default()
    }

    /// Add one observation.
    #[inline]
    pub fn push(&mut self, x: f64) {
        self.n += 1;
        if self.n == 1 {
            self.min = x;
            self.max = x;
        } else {
            self.min = self.min.min(x);
            self.max = self.max.max(x);
        }
        let delta = x - self.mean;
        self.mean += delta / self.n as f64;
        self.m2 += delta * (x - self.mean);
    }

    /// Combine with another accumulator (Chan, Golub & LeVeque's parallel update), as if every
    /// observation of `other` had been pushed into `self`.
    pub fn merge(&mut self, other: &Welford) {
        if other.n == 0 {
            return;
        }
        if self.n == 0 {
            *self = *other;
            return;
        }
        let n = self.n + other.n;
        let delta = other.mean - self.mean;
        let (na, nb) = (self.n as f64, other.n as f64);
        self.mean += delta * nb / n as f64;
        self.m2 += other.m2 + delta * delta * na * nb / n as f64;
        self.n = n;
        self.min = self.min.min(other.min);
        self.max = self.max.max(other.max);
    }

    /// Number of observations.
    pub fn count(&self) -> u64 {
        self.n
    }

    /// Mean (NaN when empty).
    pub fn mean(&self) -> f64 {
        if self.n == 0 { f64::NAN } else { self.mean }
    }

    /// Unbiased sample variance, `sum (x - mean)^2 / (n - 1)` (NaN below two observations).
    pub fn variance(&self) -> f64 {
        if self.n < 2 {
            f64::NAN
        } else {
            self.m2 / (self.n - 1) as f64
        }
    }

    /// Population variance, `sum (x - mean)^2 / n` (NaN when empty).
    pub fn population_variance(&self) -> f64 {
        if self.n == 0 {
            f64::NAN
        } else {
            self.m2 / self.n as f64
        }
    }

    /// Sample standard deviation.
    pub fn std_dev(&self) -> f64 {
        self.variance().sqrt()
    }

    /// Standard error of the mean, `std_dev / sqrt(n)`.
    pub fn std_error(&self) -> f64 {
        self.std_dev() / (self.n as f64).sqrt()
    }

    /// Smallest observation (NaN when empty).
    pub fn min(&self) -> f64 {
        if self.n == 0 { f64::NAN } else { self.min }
    }

    /// Largest observation (NaN when empty).
    pub fn max(&self) -> f64 {
        if self.n == 0 { f64::NAN } else { self.max }
    }
}

impl Extend<f64> for Welford {
    fn extend<I: IntoIterator<Item = f64>>(&mut self, iter: I) {
        iter.into_iter().for_each(|x| self.push(x));
    }
}

impl FromIterator<f64> for Welford {
    fn from_iter<I: IntoIterator<Item = f64>>(iter: I) -> Self {
        let mut w = Welford::new();
        w.extend(iter);
        w
    }
}

/// A histogram of non-negative integers with one bin per value, growing as needed: the number of
/// candidate clusters examined per move (seed 000, Figs. 4, 7, 8), cluster sizes.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct IntHistogram {
    counts: Vec<u64>,
    total: u64,
}

impl IntHistogram {
    /// An empty histogram.
    pub fn new() -> Self {
        Self::default()
    }

    /// Count one occurrence of `value`.
    #[inline]
    pub fn add(&mut self, value: u64) {
        self.add_n(value, 1);
    }

    /// Count `n` occurrences of `value`.
    pub fn add_n(&mut self, value: u64, n: u64) {
        let i = usize::try_from(value).expect("histogram value exceeds the address space");
        if i >= self.counts.len() {
            self.counts.resize(i + 1, 0);
        }
        self.counts[i] += n;
        self.total += n;
    }

    /// Add every count of `other`.
    pub fn merge(&mut self, other: &IntHistogram) {
        for (v, &c) in other.counts.iter().enumerate() {
            if c > 0 {
                self.add_n(v as u64, c);
            }
        }
    }

    /// Occurrences of `value`.
    pub fn count(&self, value: u64) -> u64 {
        usize::try_from(value)
            .ok()
            .and_then(|i| self.counts.get(i))
            .copied()
            .unwrap_or(0)
    }

    /// Total number of occurrences.
    pub fn total(&self) -> u64 {
        self.total
    }

    /// The largest value seen, if any.
    pub fn max_value(&self) -> Option<u64> {
        self.counts.iter().rposition(|&c| c > 0).map(|i| i as u64)
    }

    /// Mean value (NaN when empty), computed exactly in integers before the final division.
    pub fn mean(&self) -> f64 {
        let sum: u128 = self
            .counts
            .iter()
            .enumerate()
            .map(|(v, &c)| v as u128 * c as u128)
            .sum();
        sum as f64 / self.total as f64
    }

    /// `(value, count)` for every value with a non-zero count, in increasing value.
    pub fn iter(&self) -> impl Iterator<Item = (u64, u64)> + '_ {
        self.counts
            .iter()
            .enumerate()
            .filter(|(_, c)| **c > 0)
            .map(|(v, &c)| (v as u64, c))
    }
}

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

/// The checks every fit makes first: equal lengths, at least 3 points, all finite.
fn check_points(x: &[f64], y: &[f64]) -> Result<(), StatsError> {
    if x.len() != y.len() {
        return Err(StatsError::LengthMismatch {
            x: x.len(),
            y: y.len(),
        });
    }
    if x.len() < 3 {
        return Err(StatsError::TooFewPoints(x.len()));
    }
    for (index, (&xi, &yi)) in x.iter().zip(y).enumerate() {
        if !xi.is_finite() || !yi.is_finite() {
            return Err(StatsError::NonFinite {
                index,
                x: xi,
                y: yi,
            });
        }
    }
    Ok(())
}

/// The axes a [`Fit`] was made on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitScale {
    /// `y = slope * x + intercept`.
    Linear,
    /// `ln y = slope * ln x + intercept`, the power law `y = A x^slope` with `A = exp(intercept)`.
    LogLog,
}

/// An ordinary least-squares line with standard errors, on linear or log-log axes: the log-log
/// gradients of Hawick, James & Scogings (2006, Table I), the fractal dimensions of DLA clusters
/// (`ln N = D ln R_g + c`) and the linear run-time fits of Sosa-Herrera & Rodriguez-Romo (Fig. 3).
///
/// On log-log axes `intercept` is `ln A` (natural logarithm) and its standard error that of
/// `ln A`; [`Fit::prefactor`] gives `A`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Fit {
    /// Fitted slope (on log-log axes the exponent).
    pub slope: f64,
    /// Fitted intercept (on log-log axes `ln A`).
    pub intercept: f64,
    /// Standard error of the slope, `sqrt(s^2 / Sxx)` with `s^2 = SSR / (n - 2)`.
    pub slope_stderr: f64,
    /// Standard error of the intercept, `sqrt(s^2 (1/n + mean_x^2 / Sxx))`.
    pub intercept_stderr: f64,
    /// Coefficient of determination on the fitted axes, `1 - SSR / SST` (1 when every y is
    /// equal and fitted).
    pub r2: f64,
    /// Number of points.
    pub n: usize,
    /// The axes of the fit.
    pub scale: FitScale,
}

impl Fit {
    /// Fit `y = slope * x + intercept` by least squares. Needs at least 3 finite points with
    /// at least two distinct x. Sums are taken about the means (two passes), so large offsets
    /// in x or y do not cancel.
    pub fn linear(x: &[f64], y: &[f64]) -> Result<Self, StatsError> {
        check_points(x, y)?;
        let n = x.len();
        let nf = n as f64;
        let mx = x.iter().sum::<f64>() / nf;
        let my = y.iter().sum::<f64>() / nf;
        let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
        for (&xi, &yi) in x.iter().zip(y) {
            let (dx, dy) = (xi - mx, yi - my);
            sxx += dx * dx;
            sxy += dx * dy;
            syy += dy * dy;
        }
        if sxx == 0.0 {
            return Err(StatsError::Degenerate(x[0]));
        }
        let slope = sxy / sxx;
        let intercept = my - slope * mx;
        let ssr: f64 = x
            .iter()
            .zip(y)
            .map(|(&xi, &yi)| {
                let r = yi - (slope * xi + intercept);
                r * r
            })
            .sum();
        let s2 = ssr / (nf - 2.0);
        Ok(Fit {
            slope,
            intercept,
            slope_stderr: (s2 / sxx).sqrt(),
            intercept_stderr: (s2 * (1.0 / nf + mx * mx / sxx)).sqrt(),
            r2: if syy == 0.0 {
                1.0
            } else {
                (1.0 - ssr / syy).clamp(0.0, 1.0)
            },
            n,
            scale: FitScale::Linear,
        })
    }

    /// Fit the power law `y = A x^slope` as `ln y = slope ln x + intercept`. Refuses fewer than
    /// 3 points and any `x <= 0` or `y <= 0` (or NaN/infinite values) with a typed error naming
    /// the first bad point.
    pub fn log_log(x: &[f64], y: &[f64]) -> Result<Self, StatsError> {
        check_points(x, y)?;
        for (index, (&xi, &yi)) in x.iter().zip(y).enumerate() {
            if xi <= 0.0 || yi <= 0.0 {
                return Err(StatsError::NonPositive {
                    index,
                    x: xi,
                    y: yi,
                });
            }
        }
        let lx: Vec<f64> = x.iter().map(|v| v.ln()).collect();
        let ly: Vec<f64> = y.iter().map(|v| v.ln()).collect();
        Ok(Fit {
            scale: FitScale::LogLog,
            ..Fit::linear(&lx, &ly)?
        })
    }

    /// The prefactor `A = exp(intercept)` of a log-log fit's `y = A x^slope` (of a linear fit,
    /// its intercept).
    pub fn prefactor(&self) -> f64 {
        match self.scale {
            FitScale::Linear => self.intercept,
            FitScale::LogLog => self.intercept.exp(),
        }
    }

    /// The fitted value at `x`: `slope * x + intercept`, or `A x^slope` on log-log axes.
    pub fn predict(&self, x: f64) -> f64 {
        match self.scale {
            FitScale::Linear => self.slope * x + self.intercept,
            FitScale::LogLog => (self.intercept + self.slope * x.ln()).exp(),
        }
    }
}

/// A histogram of positive reals in logarithmic bins: bin `i` covers
/// `[min * 10^(i/b), min * 10^((i+1)/b))` with `b` bins per decade. Values below `min` are counted
/// apart (`underflow`). Used for wide distributions: cluster sizes, query errors, step lengths.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LogHistogram {
    min: f64,
    bins_per_decade: u32,
    counts: Vec<u64>,
    underflow: u64,
    total: u64,
}

impl LogHistogram {
    /// Bins from `min > 0` upwards, `bins_per_decade >= 1`.
    pub fn new(min: f64, bins_per_decade: u32) -> Result<Self, StatsError> {
        if !(min > 0.0 && min.is_finite()) {
            return Err(StatsError::BadParameter(format!(
                "log-histogram minimum {min} must be finite and > 0"
            )));
        }
        if bins_per_decade == 0 {
            return Err(StatsError::BadParameter(
                "log-histogram needs at least 1 bin per decade".into(),
            ));
        }
        Ok(LogHistogram {
            min,
            bins_per_decade,
            counts: Vec::new(),
            underflow: 0,
            total: 0,
        })
    }

    /// The bin `x` falls in, or `None` below `min`. Bin edges are computed the same way as
    /// [`LogHistogram::bin_edges`], so a value exactly on an edge lands in the bin it opens.
    pub fn bin_of(&self, x: f64) -> Option<usize> {
        if x < self.min {
            return None;
        }
        let mut i = ((x / self.min).log10() * f64::from(self.bins_per_decade)).floor() as usize;
        // Correct the rounding of the logarithm against the exact edges.
        while i > 0 && x < self.bin_edges(i).0 {
            i -= 1;
        }
        while x >= self.bin_edges(i).1 {
            i += 1;
        }
        Some(i)
    }

    /// Count one value. Refuses `x <= 0`, NaN and infinities.
    pub fn add(&mut self, x: f64) -> Result<(), StatsError> {
        if !(x > 0.0 && x.is_finite()) {
            return Err(StatsError::BadParameter(format!(
                "log-histogram value {x} must be finite and > 0"
            )));
        }
        self.total += 1;
        match self.bin_of(x) {
            None => self.underflow += 1,
            Some(i) => {
                if i >= self.counts.len() {
                    self.counts.resize(i + 1, 0);
                }
                self.counts[i] += 1;
            }
        }
        Ok(())
    }

    /// The `[lower, upper)` edges of bin `i`.
    pub fn bin_edges(&self, i: usize) -> (f64, f64) {
        let b = f64::from(self.bins_per_decade);
        (
            self.min * 10f64.powf(i as f64 / b),
            self.min * 10f64.powf((i + 1) as f64 / b),
        )
    }

    /// Count in bin `i`.
    pub fn count(&self, i: usize) -> u64 {
        self.counts.get(i).copied().unwrap_or(0)
    }

    /// Number of values below `min`.
    pub fn underflow(&self) -> u64 {
        self.underflow
    }

    /// Total number of values added (including underflow).
    pub fn total(&self) -> u64 {
        self.total
    }

    /// `(lower, upper, count, density)` for every non-empty bin, where density is
    /// `count / (total * (upper - lower))`, the estimate of the probability density.
    pub fn iter(&self) -> impl Iterator<Item = (f64, f64, u64, f64)> + '_ {
        self.counts
            .iter()
            .enumerate()
            .filter(|(_, c)| **c > 0)
            .map(|(i, &c)| {
                let (lo, hi) = self.bin_edges(i);
                (lo, hi, c, c as f64 / (self.total as f64 * (hi - lo)))
            })
    }
}

/// Radius of gyration of a point set in `D` dimensions,
/// `R_g^2 = (1/N) sum |x_i - mean|^2` (seed 002 section 3.4: the fractal dimension is fitted from
/// `R_g(N)`).
///
/// Each point updates the mean and the sum of squared deviations by Welford's recurrence, so
/// the result does not suffer the catastrophic cancellation of `sum x^2 - N mean^2` when the
/// cluster sits far from the origin. Mergeable across threads.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Gyration<const D: usize> {
    n: u64,
    #[serde(with = "serde_arrays")]
    mean: [f64; D],
    /// Sum over points and axes of squared deviations from the mean.
    m2: f64,
}

/// serde for `[f64; D]` with const generic `D` (serde implements arrays only up to 32 and not
/// for generic lengths).
mod serde_arrays {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer, const D: usize>(v: &[f64; D], s: S) -> Result<S::Ok, S::Error> {
        v.as_slice().serialize(s)
    }

    pub fn deserialize<'de, De: Deserializer<'de>, const D: usize>(
        d: De,
    ) -> Result<[f64; D], De::Error> {
        let v = Vec::<f64>::deserialize(d)?;
        v.try_into().map_err(|v: Vec<f64>| {
            serde::de::Error::invalid_length(v.len(), &"an array of the gyration dimension")
        })
    }
}

impl<const D: usize> Default for Gyration<D> {
    fn default() -> Self {
        Gyration {
            n: 0,
            mean: [0.0; D],
            m2: 0.0,
        }
    }
}

impl<const D: usize> Gyration<D> {
    /// An empty accumulator.
    pub fn new() -> Self {
        Self::default()
    }

    /// Add one point.
    #[inline]
    pub fn push(&mut self, p: &[f64; D]) {
        self.n += 1;
        let inv_n = 1.0 / self.n as f64;
        for (m, &x) in self.mean.iter_mut().zip(p) {
            let delta = x - *m;
            *m += delta * inv_n;
            self.m2 += delta * (x - *m);
        }
    }

    /// Combine with another accumulator, as if all its points had been pushed here.
    pub fn merge(&mut self, other: &Gyration<D>) {
        if other.n == 0 {
            return;
        }
        if self.n == 0 {
            *self = *other;
            return;
        }
        let n = self.n + other.n;
        let (na, nb, nf) = (self.n as f64, other.n as f64, n as f64);
        for (m, &mo) in self.mean.iter_mut().zip(&other.mean) {
            let delta = mo - *m;
            *m += delta * nb / nf;
            self.m2 += delta * delta * na * nb / nf;
        }
        self.m2 += other.m2;
        self.n = n;
    }

    /// Number of points.
    pub fn count(&self) -> u64 {
        self.n
    }

    /// Centre of mass (zeros when empty).
    pub fn centre(&self) -> [f64; D] {
        self.mean
    }

    /// `R_g^2` (0 for zero or one point).
    pub fn radius_squared(&self) -> f64 {
        if self.n == 0 {
            0.0
        } else {
            (self.m2 / self.n as f64).max(0.0)
        }
    }

    /// `R_g`.
    pub fn radius(&self) -> f64 {
        self.radius_squared().sqrt()
    }
}

/// Radius of gyration of a set of integer lattice points in `d <= 8` dimensions (DLCA clusters,
/// seed 000; coordinates unwrapped across periodic boundaries by the caller).
///
/// Sums are kept exactly in `i128`; the result is rounded only once, at the end. Supports
/// coordinates up to `|x| < 2^40` and up to `2^40` points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct LatticeGyration {
    dim: usize,
    n: u64,
    sum: [i128; crate::lattice::MAX_DIM],
    sum_sq: i128,
}

impl LatticeGyration {
    /// An empty accumulator for `dim`-dimensional points.
    ///
    /// # Panics
    /// If `dim > MAX_DIM`.
    pub fn new(dim: usize) -> Self {
        assert!(dim <= crate::lattice::MAX_DIM);
        LatticeGyration {
            dim,
            n: 0,
            sum: [0; crate::lattice::MAX_DIM],
            sum_sq: 0,
        }
    }

    /// Add one point (`x.len()` must equal the dimension).
    #[inline]
    pub fn push(&mut self, x: &[i64]) {
        debug_assert_eq!(x.len(), self.dim);
        self.n += 1;
        for (s, &v) in self.sum.iter_mut().zip(x) {
            let v = i128::from(v);
            *s += v;
            self.sum_sq += v * v;
        }
    }

    /// Combine with another accumulator of the same dimension.
    pub fn merge(&mut self, other: &LatticeGyration) {
        debug_assert_eq!(self.dim, other.dim);
        self.n += other.n;
        self.sum_sq += other.sum_sq;
        for (a, b) in self.sum.iter_mut().zip(&other.sum) {
            *a += b;
        }
    }

    /// Number of points.
    pub fn count(&self) -> u64 {
        self.n
    }

    /// `R_g^2`. Computed about the integer nearest the centre of mass, `c`:
    /// `R_g^2 = sum (x - c)^2 / N - (mean - c)^2`, where `sum (x - c)^2` is exact in integers and
    /// `|mean - c| <= 1/2`, so no large terms cancel.
    pub fn radius_squared(&self) -> f64 {
        if self.n == 0 {
            return 0.0;
        }
        let n = i128::from(self.n);
        let mut centred = self.sum_sq; // becomes sum over axes of sum (x - c)^2
        let mut offset2 = 0.0;
        for &s in &self.sum[..self.dim] {
            // c = round(s / n), with floor division for negative sums.
            let c = (2 * s + n).div_euclid(2 * n);
            centred += -2 * c * s + n * c * c;
            let off = (s - n * c) as f64 / self.n as f64;
            offset2 += off * off;
        }
        (centred as f64 / self.n as f64 - offset2).max(0.0)
    }

    /// `R_g`.
    pub fn radius(&self) -> f64 {
        self.radius_squared().sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welford_basics() {
        let w: Welford = [2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]
            .into_iter()
            .collect();
        assert_eq!(w.count(), 8);
        assert!((w.mean() - 5.0).abs() < 1e-15);
        assert!((w.population_variance() - 4.0).abs() < 1e-15);
        assert!((w.variance() - 32.0 / 7.0).abs() < 1e-14);
        assert_eq!((w.min(), w.max()), (2.0, 9.0));
        assert!(Welford::new().mean().is_nan());
    }

    #[test]
    fn fit_recovers_exact_power_law() {
        let x: Vec<f64> = (1..=20).map(|i| i as f64 * 10.0).collect();
        let y: Vec<f64> = x.iter().map(|x| 3.5 * x.powf(1.71)).collect();
        let f = Fit::log_log(&x, &y).unwrap();
        assert!((f.slope - 1.71).abs() < 1e-12);
        assert!((f.prefactor() - 3.5).abs() < 1e-10);
        assert!(f.slope_stderr < 1e-12);
        assert!((f.r2 - 1.0).abs() < 1e-12);
        assert_eq!(f.n, 20);
    }

    #[test]
    fn fit_standard_errors_match_textbook() {
        // Worked example: x = 1..5, y = 2, 4, 5, 4, 5 -> slope 0.6, intercept 2.2,
        // SSR = 2.4, s^2 = 0.8, Sxx = 10: se(slope) = sqrt(0.08), se(intercept) = sqrt(0.8*(1/5+9/10)).
        let f = Fit::linear(&[1., 2., 3., 4., 5.], &[2., 4., 5., 4., 5.]).unwrap();
        assert!((f.slope - 0.6).abs() < 1e-14);
        assert!((f.intercept - 2.2).abs() < 1e-14);
        assert!((f.slope_stderr - 0.08f64.sqrt()).abs() < 1e-14);
        assert!((f.intercept_stderr - (0.8f64 * 1.1).sqrt()).abs() < 1e-14);
        assert!((f.r2 - 0.6).abs() < 1e-14); // SST = 6
    }

    #[test]
    fn predict_and_prefactor_follow_the_axes() {
        let x = [1.0, 2.0, 4.0, 8.0];
        let lin = Fit::linear(&x, &[3.0, 5.0, 9.0, 17.0]).unwrap();
        assert_eq!(lin.scale, FitScale::Linear);
        assert!((lin.predict(16.0) - 33.0).abs() < 1e-12);
        assert!((lin.prefactor() - 1.0).abs() < 1e-12);
        let pow = Fit::log_log(&x, &[3.0, 12.0, 48.0, 192.0]).unwrap();
        assert_eq!(pow.scale, FitScale::LogLog);
        assert!((pow.predict(16.0) - 768.0).abs() < 1e-9);
        assert!((pow.prefactor() - 3.0).abs() < 1e-12);
        // The same points on log axes give the same line as the linear fit of the logarithms.
        let logs = |v: &[f64]| v.iter().map(|a| a.ln()).collect::<Vec<_>>();
        let by_hand = Fit::linear(&logs(&x), &logs(&[3.0, 12.0, 48.0, 192.0])).unwrap();
        assert_eq!(
            (pow.slope, pow.intercept, pow.slope_stderr, pow.r2),
            (
                by_hand.slope,
                by_hand.intercept,
                by_hand.slope_stderr,
                by_hand.r2
            )
        );
    }

    #[test]
    fn fit_refuses_bad_input() {
        assert_eq!(
            Fit::log_log(&[1., 2.], &[1., 2.]),
            Err(StatsError::TooFewPoints(2))
        );
        assert!(matches!(
            Fit::log_log(&[1., 0., 3.], &[1., 2., 3.]),
            Err(StatsError::NonPositive { index: 1, .. })
        ));
        assert!(matches!(
            Fit::log_log(&[1., 2., 3.], &[1., -2., 3.]),
            Err(StatsError::NonPositive { index: 1, .. })
        ));
        assert!(matches!(
            Fit::log_log(&[1., 2., f64::NAN], &[1., 2., 3.]),
            Err(StatsError::NonFinite { index: 2, .. })
        ));
        assert!(matches!(
            Fit::linear(&[2., 2., 2.], &[1., 2., 3.]),
            Err(StatsError::Degenerate(_))
        ));
        assert!(matches!(
            Fit::linear(&[1., 2., 3.], &[1., 2.]),
            Err(StatsError::LengthMismatch { .. })
        ));
    }

    #[test]
    fn int_histogram_counts() {
        let mut h = IntHistogram::new();
        for v in [3, 0, 3, 7, 3] {
            h.add(v);
        }
        assert_eq!(h.count(3), 3);
        assert_eq!(h.count(1), 0);
        assert_eq!(h.count(1000), 0);
        assert_eq!(h.total(), 5);
        assert_eq!(h.max_value(), Some(7));
        assert!((h.mean() - 16.0 / 5.0).abs() < 1e-15);
        assert_eq!(h.iter().collect::<Vec<_>>(), vec![(0, 1), (3, 3), (7, 1)]);
    }

    #[test]
    fn log_histogram_edges() {
        let mut h = LogHistogram::new(1.0, 1).unwrap();
        for x in [0.5, 1.0, 9.999, 10.0, 99.0, 100.0, 1e6] {
            h.add(x).unwrap();
        }
        assert_eq!(h.underflow(), 1);
        assert_eq!(h.count(0), 2); // 1.0 and 9.999
        assert_eq!(h.count(1), 2); // 10 and 99
        assert_eq!(h.count(2), 1); // 100
        assert_eq!(h.count(6), 1);
        assert_eq!(h.total(), 7);
        assert!(h.add(0.0).is_err());
        assert!(h.add(f64::NAN).is_err());
        assert!(LogHistogram::new(0.0, 3).is_err());
        assert!(LogHistogram::new(1.0, 0).is_err());
    }

    #[test]
    fn gyration_of_a_square() {
        let mut g = Gyration::<2>::new();
        for p in [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0], [2.0, 2.0]] {
            g.push(&p);
        }
        assert!((g.radius_squared() - 2.0).abs() < 1e-15);
        assert_eq!(g.centre(), [1.0, 1.0]);
        let mut l = LatticeGyration::new(2);
        for p in [[0, 0], [2, 0], [0, 2], [2, 2]] {
            l.push(&p);
        }
        assert_eq!(l.radius_squared(), 2.0);
        assert_eq!(LatticeGyration::new(3).radius(), 0.0);
    }
}
