//! [`Fit`]: ordinary least squares with standard errors on linear or log-log axes. Every fit
//! checks its points first (equal lengths, at least three, all finite; positive on log axes) and
//! refuses bad input with a typed [`StatsError`] instead of returning NaN.

use super::StatsError;
#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

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
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
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
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
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
