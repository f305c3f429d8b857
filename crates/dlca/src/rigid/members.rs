//! The particles of a *large* cluster as bits over a box in its own frame ([`Members`]): what
//! tells which cluster holds a site once large clusters stop writing their labels (see
//! [`Rigid`](super::clusters::Rigid)).
//!
//! Invariant: the bits set are exactly the relative positions given to
//! [`Members::build`] and [`Members::extend`] since the last build, and all lie in the box.

use super::geometry::Geometry;

/// Relative positions as bits over the box `lo .. lo + side` (axis 0 fastest). On a periodic
/// axis of side `L` a relative position in `[L/2, L)` is taken as the one `L` lower, so that a
/// cluster with particles on both sides of its origin has a box of its own extent, not `L`.
#[derive(Debug, Clone)]
pub(super) struct Members<const D: usize> {
    lo: [i32; D],
    side: [u32; D],
    /// `L` on a periodic axis, 0 on a wall axis.
    period: [i32; D],
    bits: Vec<u64>,
}

impl<const D: usize> Members<D> {
    /// The bits of `sites` (relative positions in a frame of `geo`), over their bounding box
    /// widened by a quarter of its extent (at least 8) on each side, so that a cluster growing
    /// by merges rebuilds its box O(log) times; on periodic axes the box stays within
    /// `[0, L)`, where relative positions lie.
    pub(super) fn build<'a>(
        geo: &Geometry<D>,
        sites: impl IntoIterator<Item = &'a [i32; D]> + Clone,
    ) -> Self {
        let period: [i32; D] = std::array::from_fn(|a| {
            if geo.periodic[a] {
                geo.size[a] as i32
            } else {
                0
            }
        });
        let (mut lo, mut hi) = ([i32::MAX; D], [i32::MIN; D]);
        for s in sites.clone() {
            let s = fold(&period, s);
            for a in 0..D {
                lo[a] = lo[a].min(s[a]);
                hi[a] = hi[a].max(s[a]);
            }
        }
        let mut side = [0; D];
        for a in 0..D {
            let margin = ((hi[a] - lo[a]) / 4).max(8);
            lo[a] -= margin;
            hi[a] += margin;
            if period[a] > 0 {
                // The folded positions: `[-L/2, L/2)` or so.
                lo[a] = lo[a].max(period[a] / 2 - period[a]);
                hi[a] = hi[a].min(period[a] / 2);
            }
            side[a] = (hi[a] - lo[a] + 1) as u32;
        }
        let cells: usize = side.iter().map(|&s| s as usize).product();
        let mut m = Members {
            lo,
            side,
            period,
            bits: vec![0; cells.div_ceil(64)],
        };
        for s in sites {
            let i = m.index(s).expect("inside the box");
            m.bits[i / 64] |= 1 << (i % 64);
        }
        m
    }

    /// Bit index of relative position `r` (in `[0, L)` on periodic axes), or `None` outside
    /// the box.
    #[inline]
    fn index(&self, r: &[i32; D]) -> Option<usize> {
        let r = fold(&self.period, r);
        let (mut i, mut stride) = (0usize, 1usize);
        for a in 0..D {
            let d = r[a].wrapping_sub(self.lo[a]) as u32;
            if d >= self.side[a] {
                return None;
            }
            i += d as usize * stride;
            stride *= self.side[a] as usize;
        }
        Some(i)
    }

    /// Whether relative position `r` is set.
    #[inline]
    pub(super) fn contains(&self, r: &[i32; D]) -> bool {
        self.index(r)
            .is_some_and(|i| self.bits[i / 64] & (1 << (i % 64)) != 0)
    }

    /// Set `added`, the sites merged in; `all` are all the cluster's sites, `added` among them,
    /// from which the box is rebuilt when an added site lies outside it.
    pub(super) fn extend(&mut self, geo: &Geometry<D>, all: &[[i32; D]], added: &[[i32; D]]) {
        if added.iter().any(|r| self.index(r).is_none()) {
            *self = Members::build(geo, all);
            return;
        }
        for r in added {
            let i = self.index(r).expect("inside the box");
            self.bits[i / 64] |= 1 << (i % 64);
        }
    }

    /// Number of positions set.
    pub(super) fn count(&self) -> usize {
        self.bits.iter().map(|w| w.count_ones() as usize).sum()
    }
}

/// `r` with each coordinate in `[ceil(L/2), L)` of an axis of period `L` taken `L` lower.
#[inline]
fn fold<const D: usize>(period: &[i32; D], r: &[i32; D]) -> [i32; D] {
    std::array::from_fn(|a| {
        if period[a] > 0 && 2 * r[a] >= period[a] {
            r[a] - period[a]
        } else {
            r[a]
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use core_lattice::{Boundary, Lattice};

    /// Members hold exactly what they were given, on both sides of the origin of a periodic axis
    /// (positions near `L` are the ones just below 0), beside a wall axis with negative
    /// positions, and after an extension that rebuilds the box.
    #[test]
    fn members_are_exactly_the_positions_given() {
        let lattice = Lattice::new(&[10, 300], &[Boundary::Periodic, Boundary::Wall]).unwrap();
        let geo = Geometry::<2>::new(&lattice);
        let mut all = vec![[0, 0], [9, 0], [5, -3], [1, 2]];
        let mut m = Members::build(&geo, &all);
        let check = |m: &Members<2>, all: &[[i32; 2]]| {
            assert_eq!(m.count(), all.len());
            for x in 0..10 {
                for y in -299..300 {
                    assert_eq!(m.contains(&[x, y]), all.contains(&[x, y]), "{x}, {y}");
                }
            }
        };
        check(&m, &all);
        // Inside the box, then far outside it along the wall axis.
        for added in [vec![[2, 2]], vec![[3, 250], [4, -200]]] {
            let before = all.len();
            all.extend(added);
            m.extend(&geo, &all, &all[before..]);
            check(&m, &all);
        }
    }
}
