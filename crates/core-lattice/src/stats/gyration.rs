//! Radii of gyration: [`Gyration`] for off-lattice points in `D` dimensions (Welford updates
//! relative to the first point, accurate however far the set lies from the origin) and
//! [`LatticeGyration`] for integer lattice points (exact integer sums, rounded once).

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

/// Radius of gyration of a point set in `D` dimensions,
/// `R_g^2 = (1/N) sum |x_i - mean|^2` (Sosa-Herrera & Rodriguez-Romo, section 3.4: the fractal dimension is fitted from
/// `R_g(N)`).
///
/// Each point updates the mean and the sum of squared deviations by Welford's recurrence, so
/// the result does not suffer the catastrophic cancellation of `sum x^2 - N mean^2` when the
/// cluster sits far from the origin. The recurrence runs on the points' offsets from the first
/// point (the *shift*), not on their coordinates: a mean kept at the coordinates' magnitude is
/// rounded to their spacing there (1.2e-4 at 1e12), which leaves `R_g^2` of a cluster of radius
/// 10 centred 1e12 from the origin wrong in the fifth digit; the offsets are exact for points
/// near the shift, so the sums keep the precision of the cluster's own size. Mergeable across
/// threads.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Gyration<const D: usize> {
    n: u64,
    /// The first point: every other enters as its offset from this one.
    #[cfg_attr(feature = "serde", serde(with = "serde_arrays"))]
    shift: [f64; D],
    /// Mean offset from `shift`.
    #[cfg_attr(feature = "serde", serde(with = "serde_arrays"))]
    mean: [f64; D],
    /// Sum over points and axes of squared deviations from the mean.
    m2: f64,
}

/// serde for `[f64; D]` with const generic `D` (serde implements arrays only up to 32 and not
/// for generic lengths).
#[cfg(feature = "serde")]
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
            shift: [0.0; D],
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
        if self.n == 0 {
            self.shift = *p;
        }
        self.n += 1;
        let inv_n = 1.0 / self.n as f64;
        for ((m, &x), &c) in self.mean.iter_mut().zip(p).zip(&self.shift) {
            let x = x - c;
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
        for a in 0..D {
            // The other's mean offset, seen from this shift.
            let mo = other.mean[a] + (other.shift[a] - self.shift[a]);
            let m = &mut self.mean[a];
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
        std::array::from_fn(|a| self.shift[a] + self.mean[a])
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
/// coordinates unwrapped across periodic boundaries by the caller).
///
/// Sums are kept exactly in `i128`; the result is rounded only once, at the end. Supports
/// coordinates up to `|x| < 2^40` and up to `2^40` points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
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
