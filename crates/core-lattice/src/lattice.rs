//! Hypercubic lattices addressed by k-index.
//!
//! Hawick, James & Scogings (2006), section III and Fig. 3: a site with Cartesian coordinates
//! `(x_1, ..., x_d)` on a lattice of side lengths `L_1, ..., L_d` is stored as the single integer
//! k-index
//!
//! ```text
//! k = x_1 + x_2 * L_1 + x_3 * L_1 * L_2 + ...
//! ```
//!
//! so that code written against k-indices does not depend on the dimension. This module adds what
//! the DLCA model (the grid-boxing paper, sections II.A and IV.A) needs on top: a boundary per axis
//! (periodic or wall), the `2d` face neighbours of a site, translation by a unit vector that
//! reports [`Blocked`] at a wall, and minimum-image displacements on periodic axes.
//!
//! Coordinates are 0-based. Axis 0 is `x_1`, the fastest-varying axis of the k-index.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};
use std::fmt;
use std::ops::Deref;

/// The largest supported dimension. Models use 1..=5; the lattice supports up to 8.
pub const MAX_DIM: usize = 8;

/// What happens at the two ends of one axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum Boundary {
    /// Site `L - 1` and site `0` are neighbours (a torus along this axis), as in the grid-boxing
    /// paper.
    Periodic,
    /// The axis ends: there is no neighbour beyond `0` or `L - 1`, and a move across is blocked.
    Wall,
}

impl fmt::Display for Boundary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Boundary::Periodic => "periodic",
            Boundary::Wall => "wall",
        })
    }
}

impl std::str::FromStr for Boundary {
    type Err = LatticeError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "periodic" => Ok(Boundary::Periodic),
            "wall" => Ok(Boundary::Wall),
            other => Err(LatticeError::UnknownBoundary(other.to_string())),
        }
    }
}

/// Errors from building a lattice or addressing a site on it.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LatticeError {
    /// The dimension is outside `1..=MAX_DIM`.
    #[error("lattice dimension {0} is outside the accepted range 1..={MAX_DIM}")]
    BadDimension(usize),
    /// One side length is zero.
    #[error("lattice side length on axis {axis} is 0; every side must be at least 1")]
    ZeroSize {
        /// The offending axis (0-based).
        axis: usize,
    },
    /// The number of sites does not fit in a `u64` k-index.
    #[error("lattice of sides {sizes:?} has more than 2^64 - 1 sites (k-index overflow)")]
    Overflow {
        /// The requested side lengths.
        sizes: Vec<u64>,
    },
    /// The boundary list has a different length from the side list.
    #[error("{boundaries} boundaries given for a {dim}-dimensional lattice; give one per axis")]
    BoundaryCount {
        /// Number of boundaries given.
        boundaries: usize,
        /// Dimension of the lattice.
        dim: usize,
    },
    /// A boundary name other than `periodic` or `wall`.
    #[error("unknown boundary '{0}'; accepted: periodic, wall")]
    UnknownBoundary(String),
    /// Coordinates of the wrong dimension.
    #[error("{given} coordinates given for a {dim}-dimensional lattice")]
    CoordCount {
        /// Number of coordinates given.
        given: usize,
        /// Dimension of the lattice.
        dim: usize,
    },
    /// A coordinate outside `0..L` on its axis.
    #[error("coordinate {value} on axis {axis} is outside 0..{size}")]
    CoordOutOfRange {
        /// The axis (0-based).
        axis: usize,
        /// The coordinate given.
        value: u64,
        /// The side length of that axis.
        size: u64,
    },
    /// A k-index outside `0..volume`.
    #[error("k-index {k} is outside 0..{volume}")]
    KOutOfRange {
        /// The k-index given.
        k: u64,
        /// The number of sites.
        volume: u64,
    },
}

/// A small fixed-capacity vector of per-axis values (coordinates or displacements), of length
/// equal to the lattice dimension. It dereferences to a slice and is `Copy`, so hot loops never
/// allocate.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct AxisVec<T: Copy + Default> {
    len: u8,
    v: [T; MAX_DIM],
}

impl<T: Copy + Default> AxisVec<T> {
    /// A vector of `len` default values (`len <= MAX_DIM`).
    ///
    /// # Panics
    /// If `len > MAX_DIM` (a programming error: lattices never have more axes).
    pub fn zeros(len: usize) -> Self {
        assert!(len <= MAX_DIM, "AxisVec length {len} exceeds MAX_DIM");
        AxisVec {
            len: len as u8,
            v: [T::default(); MAX_DIM],
        }
    }

    /// Copy of a slice of at most `MAX_DIM` values.
    ///
    /// # Panics
    /// If `s.len() > MAX_DIM`.
    pub fn from_slice(s: &[T]) -> Self {
        let mut out = Self::zeros(s.len());
        out.v[..s.len()].copy_from_slice(s);
        out
    }
}

impl<T: Copy + Default> Deref for AxisVec<T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        &self.v[..self.len as usize]
    }
}

impl<T: Copy + Default> std::ops::DerefMut for AxisVec<T> {
    fn deref_mut(&mut self) -> &mut [T] {
        &mut self.v[..self.len as usize]
    }
}

impl<T: Copy + Default + fmt::Debug> fmt::Debug for AxisVec<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

/// Lattice coordinates `(x_1, ..., x_d)` of one site.
pub type Coords = AxisVec<u64>;
/// A displacement between two sites, one signed component per axis.
pub type Offset = AxisVec<i64>;

/// One of the `2d` unit lattice vectors `+e_a` or `-e_a`.
///
/// Directions are numbered `0..2d`: direction `2a` is `-e_a` and `2a + 1` is `+e_a`, so
/// `dir ^ 1` is the opposite direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Direction(u8);

impl Direction {
    /// The direction along `axis`, positive or negative.
    pub fn new(axis: usize, positive: bool) -> Self {
        debug_assert!(axis < MAX_DIM);
        Direction((2 * axis + usize::from(positive)) as u8)
    }
    /// The direction with number `index` in `0..2d` (see the type docs).
    pub fn from_index(index: usize) -> Self {
        debug_assert!(index < 2 * MAX_DIM);
        Direction(index as u8)
    }
    /// The number of this direction in `0..2d`.
    pub fn index(self) -> usize {
        usize::from(self.0)
    }
    /// The axis this direction runs along.
    pub fn axis(self) -> usize {
        usize::from(self.0 >> 1)
    }
    /// Whether this is `+e_a` (true) or `-e_a` (false).
    pub fn is_positive(self) -> bool {
        self.0 & 1 == 1
    }
    /// The opposite direction.
    pub fn opposite(self) -> Self {
        Direction(self.0 ^ 1)
    }
    /// All `2d` directions of a `d`-dimensional lattice, in index order.
    pub fn all(dim: usize) -> impl Iterator<Item = Direction> {
        (0..2 * dim).map(Direction::from_index)
    }
}

/// A translation was refused because it would cross a wall (the grid-boxing paper DLCA with closed
/// boundaries; `docs/dlca.md`, "The model", step 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("move blocked by a wall")]
pub struct Blocked;

/// The shape of a `d`-dimensional hypercubic lattice: a side length and a boundary per axis,
/// and the strides of its k-index (the grid-boxing paper, section III, Fig. 3).
///
/// Built only through validating constructors, so every `Lattice` value has `1 <= d <= 8`,
/// non-zero sides and a volume that fits in `u64`. Deserialisation validates too.
#[derive(Clone, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(
    feature = "serde",
    serde(try_from = "LatticeSpec", into = "LatticeSpec")
)]
pub struct Lattice {
    dim: usize,
    sizes: [u64; MAX_DIM],
    boundaries: [Boundary; MAX_DIM],
    /// `strides[a] = L_1 * ... * L_a` (so `strides[0] = 1`).
    strides: [u64; MAX_DIM],
    volume: u64,
    /// When every side is a power of two, `log2(strides[a])`: coordinates are then extracted
    /// with a shift and a mask instead of two divisions.
    shifts: Option<[u32; MAX_DIM]>,
}

/// The serialised form of a [`Lattice`]: its side lengths and boundaries.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct LatticeSpec {
    /// Side length of each axis.
    pub sizes: Vec<u64>,
    /// Boundary of each axis.
    pub boundaries: Vec<Boundary>,
}

impl TryFrom<LatticeSpec> for Lattice {
    type Error = LatticeError;
    fn try_from(spec: LatticeSpec) -> Result<Self, LatticeError> {
        Lattice::new(&spec.sizes, &spec.boundaries)
    }
}

impl From<Lattice> for LatticeSpec {
    fn from(l: Lattice) -> Self {
        LatticeSpec {
            sizes: l.sizes().to_vec(),
            boundaries: l.boundaries().to_vec(),
        }
    }
}

impl fmt::Debug for Lattice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Lattice")
            .field("sizes", &self.sizes())
            .field("boundaries", &self.boundaries())
            .finish()
    }
}

impl Lattice {
    /// A lattice with the given side lengths and one boundary per axis.
    ///
    /// Rejects a dimension outside `1..=8`, a zero side, a boundary count different from the
    /// dimension, and a volume (product of sides) above `u64::MAX`.
    pub fn new(sizes: &[u64], boundaries: &[Boundary]) -> Result<Self, LatticeError> {
        let dim = sizes.len();
        if dim == 0 || dim > MAX_DIM {
            return Err(LatticeError::BadDimension(dim));
        }
        if boundaries.len() != dim {
            return Err(LatticeError::BoundaryCount {
                boundaries: boundaries.len(),
                dim,
            });
        }
        let mut lattice = Lattice {
            dim,
            sizes: [1; MAX_DIM],
            boundaries: [Boundary::Periodic; MAX_DIM],
            strides: [0; MAX_DIM],
            volume: 1,
            shifts: None,
        };
        for (axis, &size) in sizes.iter().enumerate() {
            if size == 0 {
                return Err(LatticeError::ZeroSize { axis });
            }
            lattice.strides[axis] = lattice.volume;
            lattice.volume =
                lattice
                    .volume
                    .checked_mul(size)
                    .ok_or_else(|| LatticeError::Overflow {
                        sizes: sizes.to_vec(),
                    })?;
            lattice.sizes[axis] = size;
            lattice.boundaries[axis] = boundaries[axis];
        }
        if sizes.iter().all(|s| s.is_power_of_two()) {
            let mut shifts = [0; MAX_DIM];
            for axis in 0..dim {
                shifts[axis] = lattice.strides[axis].trailing_zeros();
            }
            lattice.shifts = Some(shifts);
        }
        Ok(lattice)
    }

    /// A lattice with the same boundary on every axis.
    pub fn with_boundary(sizes: &[u64], boundary: Boundary) -> Result<Self, LatticeError> {
        Self::new(sizes, &vec![boundary; sizes.len()])
    }

    /// A lattice periodic on every axis (the paper's setting).
    pub fn periodic(sizes: &[u64]) -> Result<Self, LatticeError> {
        Self::with_boundary(sizes, Boundary::Periodic)
    }

    /// The dimension `d`.
    #[inline]
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Side lengths `L_1..L_d`.
    #[inline]
    pub fn sizes(&self) -> &[u64] {
        &self.sizes[..self.dim]
    }

    /// Side length of one axis.
    #[inline]
    pub fn size(&self, axis: usize) -> u64 {
        self.sizes[axis]
    }

    /// Boundaries of each axis.
    #[inline]
    pub fn boundaries(&self) -> &[Boundary] {
        &self.boundaries[..self.dim]
    }

    /// Boundary of one axis.
    #[inline]
    pub fn boundary(&self, axis: usize) -> Boundary {
        self.boundaries[axis]
    }

    /// The k-index stride of one axis: `L_1 * ... * L_axis`.
    #[inline]
    pub fn stride(&self, axis: usize) -> u64 {
        self.strides[axis]
    }

    /// The number of sites, `L_1 * ... * L_d`.
    #[inline]
    pub fn volume(&self) -> u64 {
        self.volume
    }

    /// The k-index of a site (the grid-boxing paper, Fig. 3):
    /// `k = x_1 + x_2 L_1 + x_3 L_1 L_2 + ...`.
    pub fn encode(&self, x: &[u64]) -> Result<u64, LatticeError> {
        if x.len() != self.dim {
            return Err(LatticeError::CoordCount {
                given: x.len(),
                dim: self.dim,
            });
        }
        let mut k = 0;
        for (axis, &value) in x.iter().enumerate() {
            let size = self.sizes[axis];
            if value >= size {
                return Err(LatticeError::CoordOutOfRange { axis, value, size });
            }
            // Cannot overflow: k < stride[axis] and value * stride[axis] + k < volume.
            k += value * self.strides[axis];
        }
        Ok(k)
    }

    /// The coordinates of the site with k-index `k` (inverse of [`Lattice::encode`]).
    pub fn decode(&self, k: u64) -> Result<Coords, LatticeError> {
        if k >= self.volume {
            return Err(LatticeError::KOutOfRange {
                k,
                volume: self.volume,
            });
        }
        let mut out = Coords::zeros(self.dim);
        let mut rest = k;
        for (axis, slot) in out.iter_mut().enumerate() {
            *slot = rest % self.sizes[axis];
            rest /= self.sizes[axis];
        }
        Ok(out)
    }

    /// The coordinate of site `k` along one axis, without decoding the others.
    #[inline]
    pub fn coord(&self, k: u64, axis: usize) -> u64 {
        debug_assert!(k < self.volume);
        match &self.shifts {
            Some(shifts) => (k >> shifts[axis]) & (self.sizes[axis] - 1),
            None => (k / self.strides[axis]) % self.sizes[axis],
        }
    }

    /// Decode `k` into a fixed array of coordinates (entries beyond the dimension are 0):
    /// the allocation-free, division-light form of [`Lattice::decode`] for hot loops.
    #[inline]
    pub fn coords_array(&self, k: u64) -> [u64; MAX_DIM] {
        debug_assert!(k < self.volume);
        let mut out = [0; MAX_DIM];
        match &self.shifts {
            Some(shifts) => {
                for axis in 0..self.dim {
                    out[axis] = (k >> shifts[axis]) & (self.sizes[axis] - 1);
                }
            }
            None => {
                let mut rest = k;
                for axis in 0..self.dim {
                    out[axis] = rest % self.sizes[axis];
                    rest /= self.sizes[axis];
                }
            }
        }
        out
    }

    /// The neighbour of the site with coordinates `x` (and k-index `k`) in direction `dir`,
    /// computed without any division; `None` across a wall or onto itself (an axis of length 1).
    #[inline]
    pub fn neighbour_of(&self, k: u64, x: &[u64; MAX_DIM], dir: Direction) -> Option<u64> {
        let axis = dir.axis();
        let (size, stride) = (self.sizes[axis], self.strides[axis]);
        let n = if dir.is_positive() {
            if x[axis] + 1 < size {
                k + stride
            } else if self.boundaries[axis] == Boundary::Periodic {
                k - x[axis] * stride
            } else {
                return None;
            }
        } else if x[axis] > 0 {
            k - stride
        } else if self.boundaries[axis] == Boundary::Periodic {
            k + (size - 1) * stride
        } else {
            return None;
        };
        (n != k).then_some(n)
    }

    /// Translate site `k` by the unit vector `dir` (a DLCA move, `docs/dlca.md`).
    ///
    /// On a periodic axis the move wraps around; on a wall axis a move past `0` or `L - 1`
    /// returns [`Blocked`]. On a periodic axis of length 1 the site moves onto itself.
    #[inline]
    pub fn translate(&self, k: u64, dir: Direction) -> Result<u64, Blocked> {
        debug_assert!(k < self.volume);
        let axis = dir.axis();
        debug_assert!(axis < self.dim);
        let size = self.sizes[axis];
        let stride = self.strides[axis];
        let x = self.coord(k, axis);
        if dir.is_positive() {
            if x + 1 < size {
                Ok(k + stride)
            } else if self.boundaries[axis] == Boundary::Periodic {
                Ok(k - x * stride)
            } else {
                Err(Blocked)
            }
        } else if x > 0 {
            Ok(k - stride)
        } else if self.boundaries[axis] == Boundary::Periodic {
            Ok(k + (size - 1) * stride)
        } else {
            Err(Blocked)
        }
    }

    /// The face neighbour of `k` in direction `dir`, or `None` across a wall or where the
    /// periodic wrap leads back onto `k` itself (an axis of length 1).
    #[inline]
    pub fn neighbour(&self, k: u64, dir: Direction) -> Option<u64> {
        self.translate(k, dir).ok().filter(|&n| n != k)
    }

    /// The distinct face neighbours of `k`: sites differing by 1 along exactly one axis (across
    /// periodic boundaries too, never across walls). At most `2d`; fewer next to a wall, and on
    /// periodic axes of length 1 or 2, where the two directions reach the same site or `k` itself.
    /// Neighbourhood is symmetric: `j` is a neighbour of `k` exactly when `k` is one of `j`.
    pub fn neighbours(&self, k: u64) -> impl Iterator<Item = u64> + '_ {
        Direction::all(self.dim).filter_map(move |dir| {
            let n = self.neighbour(k, dir)?;
            // On a periodic axis of length 2, -e_a and +e_a reach the same site: report it once,
            // from the positive direction.
            let axis = dir.axis();
            let dup = !dir.is_positive()
                && self.sizes[axis] == 2
                && self.boundaries[axis] == Boundary::Periodic;
            (!dup).then_some(n)
        })
    }

    /// Minimum-image displacement from site `a` to site `b`: on a periodic axis of length `L`
    /// the component lies in `(-L/2, L/2]` (ties, at exactly `L/2`, are positive); on a wall axis
    /// it is the plain difference `x_b - x_a`.
    pub fn displacement(&self, a: u64, b: u64) -> Offset {
        let mut out = Offset::zeros(self.dim);
        for (axis, slot) in out.iter_mut().enumerate() {
            let d = self.coord(b, axis) as i64 - self.coord(a, axis) as i64;
            *slot = self.wrap_component(axis, d);
        }
        out
    }

    /// Reduce one displacement component to its minimum image on `axis` (unchanged on walls).
    #[inline]
    pub fn wrap_component(&self, axis: usize, d: i64) -> i64 {
        match self.boundaries[axis] {
            Boundary::Wall => d,
            Boundary::Periodic => {
                let size = self.sizes[axis] as i64;
                let r = d.rem_euclid(size);
                if 2 * r > size { r - size } else { r }
            }
        }
    }

    /// Whether two sites are face-adjacent (their minimum-image displacement is a unit vector).
    pub fn adjacent(&self, a: u64, b: u64) -> bool {
        let mut unit = 0;
        for axis in 0..self.dim {
            match self.wrap_component(
                axis,
                self.coord(b, axis) as i64 - self.coord(a, axis) as i64,
            ) {
                0 => {}
                1 | -1 => unit += 1,
                _ => return false,
            }
        }
        unit == 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_fig3_example() {
        // The grid-boxing paper, Fig. 3: a 12 x 6 lattice; site (x1, x2) = (3, 2) has k = 27.
        let l = Lattice::periodic(&[12, 6]).unwrap();
        assert_eq!(l.volume(), 72);
        assert_eq!(l.encode(&[3, 2]).unwrap(), 27);
        assert_eq!(&*l.decode(71).unwrap(), &[11, 5]);
        assert_eq!(l.encode(&[0, 5]).unwrap(), 60);
    }

    #[test]
    fn rejects_bad_shapes() {
        assert_eq!(Lattice::periodic(&[]), Err(LatticeError::BadDimension(0)));
        assert_eq!(
            Lattice::periodic(&[2; 9]),
            Err(LatticeError::BadDimension(9))
        );
        assert_eq!(
            Lattice::periodic(&[4, 0, 3]),
            Err(LatticeError::ZeroSize { axis: 1 })
        );
        assert!(matches!(
            Lattice::periodic(&[1 << 32, 1 << 32]),
            Err(LatticeError::Overflow { .. })
        ));
        // 2^32 * (2^32 - 1) fits.
        assert!(Lattice::periodic(&[1 << 32, (1 << 32) - 1]).is_ok());
        assert!(matches!(
            Lattice::new(&[4, 4], &[Boundary::Wall]),
            Err(LatticeError::BoundaryCount {
                boundaries: 1,
                dim: 2
            })
        ));
        let l = Lattice::periodic(&[4, 4]).unwrap();
        assert!(matches!(
            l.encode(&[4, 0]),
            Err(LatticeError::CoordOutOfRange { axis: 0, .. })
        ));
        assert!(matches!(
            l.encode(&[1]),
            Err(LatticeError::CoordCount { .. })
        ));
        assert!(matches!(
            l.decode(16),
            Err(LatticeError::KOutOfRange { .. })
        ));
    }

    #[test]
    #[cfg(feature = "serde")]
    fn serde_validates() {
        let l = Lattice::new(&[8, 4], &[Boundary::Periodic, Boundary::Wall]).unwrap();
        let json = serde_json::to_string(&l).unwrap();
        assert_eq!(json, r#"{"sizes":[8,4],"boundaries":["periodic","wall"]}"#);
        assert_eq!(serde_json::from_str::<Lattice>(&json).unwrap(), l);
        assert!(
            serde_json::from_str::<Lattice>(r#"{"sizes":[8,0],"boundaries":["wall","wall"]}"#)
                .is_err()
        );
    }

    #[test]
    fn translate_wraps_and_blocks() {
        let l = Lattice::new(&[5, 3], &[Boundary::Periodic, Boundary::Wall]).unwrap();
        let k = l.encode(&[4, 2]).unwrap();
        let right = l.translate(k, Direction::new(0, true)).unwrap();
        assert_eq!(&*l.decode(right).unwrap(), &[0, 2]);
        assert_eq!(l.translate(k, Direction::new(1, true)), Err(Blocked));
        let down = l.translate(k, Direction::new(1, false)).unwrap();
        assert_eq!(&*l.decode(down).unwrap(), &[4, 1]);
        let origin = l.encode(&[0, 0]).unwrap();
        assert_eq!(l.translate(origin, Direction::new(1, false)), Err(Blocked));
        let left = l.translate(origin, Direction::new(0, false)).unwrap();
        assert_eq!(&*l.decode(left).unwrap(), &[4, 0]);
    }

    #[test]
    fn neighbours_of_small_axes() {
        // Periodic length 1: no neighbour along it. Periodic length 2: one neighbour.
        let l = Lattice::periodic(&[1, 2, 5]).unwrap();
        let k = l.encode(&[0, 0, 0]).unwrap();
        let mut n: Vec<_> = l
            .neighbours(k)
            .map(|j| l.decode(j).unwrap().to_vec())
            .collect();
        n.sort();
        assert_eq!(n, vec![vec![0, 0, 1], vec![0, 0, 4], vec![0, 1, 0]]);
        // Interior site of a walled 3D lattice has 6 neighbours, a corner 3.
        let w = Lattice::with_boundary(&[3, 3, 3], Boundary::Wall).unwrap();
        assert_eq!(w.neighbours(w.encode(&[1, 1, 1]).unwrap()).count(), 6);
        assert_eq!(w.neighbours(0).count(), 3);
    }

    #[test]
    fn displacement_minimum_image() {
        let l = Lattice::new(&[10, 10], &[Boundary::Periodic, Boundary::Wall]).unwrap();
        let a = l.encode(&[1, 1]).unwrap();
        let b = l.encode(&[9, 9]).unwrap();
        assert_eq!(&*l.displacement(a, b), &[-2, 8]);
        assert_eq!(&*l.displacement(b, a), &[2, -8]);
        let c = l.encode(&[6, 1]).unwrap();
        // Exactly half the period: positive by convention, from both sides.
        assert_eq!(&*l.displacement(a, c), &[5, 0]);
        assert_eq!(&*l.displacement(c, a), &[5, 0]);
        assert!(l.adjacent(l.encode(&[0, 3]).unwrap(), l.encode(&[9, 3]).unwrap()));
        assert!(!l.adjacent(l.encode(&[3, 0]).unwrap(), l.encode(&[3, 9]).unwrap()));
    }

    #[test]
    fn direction_numbering() {
        let d = Direction::new(2, true);
        assert_eq!(d.index(), 5);
        assert_eq!(d.axis(), 2);
        assert!(d.is_positive());
        assert_eq!(d.opposite(), Direction::new(2, false));
        assert_eq!(Direction::all(3).count(), 6);
    }
}
