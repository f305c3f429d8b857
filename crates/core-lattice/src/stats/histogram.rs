//! Histograms: [`IntHistogram`] (one bin per non-negative integer, growing as needed) and
//! [`LogHistogram`] (logarithmic bins over positive reals). Counts are exact integers; the total
//! is always the sum of the bins (plus the log histogram's underflow).

use super::StatsError;
#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

/// A histogram of non-negative integers with one bin per value, growing as needed: the number of
/// candidate clusters examined per move (Hawick, James & Scogings 2006, Figs. 4, 7, 8), cluster
/// sizes.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
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

/// A histogram of positive reals in logarithmic bins: bin `i` covers
/// `[min * 10^(i/b), min * 10^((i+1)/b))` with `b` bins per decade. Values below `min` are counted
/// apart (`underflow`). Used for wide distributions: cluster sizes, query errors, step lengths.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
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
