//! The bounding region of a cluster ([`Region`]): one [`Span`] of coordinates per axis, which
//! may wrap around a periodic axis; grown by one site on every side it is the cluster's halo.
//!
//! Invariant: every particle of the cluster has, on every axis, its coordinate inside the span.
//! Spans only grow (at merges) and translate (at moves), so they stay exact on wall axes and are
//! the smallest arc covering both parts after a merge on periodic axes.

use core_lattice::{Boundary, Direction, Lattice, MAX_DIM};

/// The coordinates `lo, lo + 1, ..., lo + len - 1` along one axis, modulo its side `L` on a
/// periodic axis (on a wall axis `lo + len <= L`). `len == L`: the whole axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(super) struct Span {
    pub(super) lo: u64,
    pub(super) len: u64,
}

impl Span {
    /// The whole axis of side `size`.
    fn full(size: u64) -> Self {
        Span { lo: 0, len: size }
    }

    /// The smallest span holding every coordinate of `coords` (not empty), on an axis of side
    /// `size`: on a wall axis from the least to the greatest; on a periodic axis the complement
    /// of the largest gap between consecutive coordinates around the circle.
    fn of(coords: &mut [u64], size: u64, periodic: bool) -> Self {
        coords.sort_unstable();
        let (first, last) = (coords[0], coords[coords.len() - 1]);
        if !periodic {
            return Span {
                lo: first,
                len: last - first + 1,
            };
        }
        // The gap from the last coordinate around to the first, then the inner gaps.
        let mut best_gap = first + size - last;
        let mut lo = first;
        for w in coords.windows(2) {
            if w[1] - w[0] > best_gap {
                best_gap = w[1] - w[0];
                lo = w[1];
            }
        }
        Span {
            lo,
            len: size + 1 - best_gap,
        }
    }

    /// Whether coordinate `x` is in the span, on an axis of side `size`.
    #[inline]
    pub(super) fn contains(&self, x: u64, size: u64) -> bool {
        let d = if x >= self.lo {
            x - self.lo
        } else {
            x + size - self.lo
        };
        d < self.len
    }

    /// Whether the two spans share a coordinate, on an axis of side `size`.
    #[inline]
    fn meets(&self, other: &Span, size: u64) -> bool {
        self.contains(other.lo, size) || other.contains(self.lo, size)
    }

    /// The smallest span covering both, on an axis of side `size`.
    fn union(&self, other: &Span, size: u64, periodic: bool) -> Span {
        if !periodic {
            let lo = self.lo.min(other.lo);
            let hi = (self.lo + self.len).max(other.lo + other.len);
            return Span { lo, len: hi - lo };
        }
        if self.len >= size || other.len >= size {
            return Span::full(size);
        }
        // Starting at one span's start, reach the end of the other; the shorter way wins.
        let from_self = self.len.max((other.lo + size - self.lo) % size + other.len);
        let from_other = other.len.max((self.lo + size - other.lo) % size + self.len);
        let (lo, len) = if from_self <= from_other {
            (self.lo, from_self)
        } else {
            (other.lo, from_other)
        };
        if len >= size {
            Span::full(size)
        } else {
            Span { lo, len }
        }
    }

    /// The span grown by one coordinate on each side (clipped at walls).
    fn grown(&self, size: u64, periodic: bool) -> Span {
        if periodic {
            if self.len + 2 >= size {
                Span::full(size)
            } else {
                Span {
                    lo: (self.lo + size - 1) % size,
                    len: self.len + 2,
                }
            }
        } else {
            let lo = self.lo.saturating_sub(1);
            let hi = (self.lo + self.len + 1).min(size);
            Span { lo, len: hi - lo }
        }
    }
}

/// A cluster's bounding region: a [`Span`] per axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(super) struct Region {
    pub(super) spans: [Span; MAX_DIM],
}

impl Region {
    /// The bounding region of `sites` (not empty).
    pub(super) fn of(lattice: &Lattice, sites: &[u64]) -> Self {
        let mut region = Region::default();
        let mut coords = Vec::with_capacity(sites.len());
        for axis in 0..lattice.dim() {
            coords.clear();
            coords.extend(sites.iter().map(|&k| lattice.coord(k, axis)));
            region.spans[axis] = Span::of(
                &mut coords,
                lattice.size(axis),
                lattice.boundary(axis) == Boundary::Periodic,
            );
        }
        region
    }

    /// Whether a move by `dir` would take a particle across a wall.
    #[inline]
    pub(super) fn blocked(&self, lattice: &Lattice, dir: Direction) -> bool {
        let axis = dir.axis();
        if lattice.boundary(axis) == Boundary::Periodic {
            return false;
        }
        let s = self.spans[axis];
        if dir.is_positive() {
            s.lo + s.len >= lattice.size(axis)
        } else {
            s.lo == 0
        }
    }

    /// Translate by `dir` (not [`Region::blocked`]).
    #[inline]
    pub(super) fn shift(&mut self, lattice: &Lattice, dir: Direction) {
        let axis = dir.axis();
        let size = lattice.size(axis);
        let s = &mut self.spans[axis];
        s.lo = if dir.is_positive() {
            (s.lo + 1) % size
        } else {
            (s.lo + size - 1) % size
        };
    }

    /// The smallest region covering both.
    pub(super) fn union(&self, other: &Region, lattice: &Lattice) -> Region {
        let mut u = Region::default();
        for axis in 0..lattice.dim() {
            u.spans[axis] = self.spans[axis].union(
                &other.spans[axis],
                lattice.size(axis),
                lattice.boundary(axis) == Boundary::Periodic,
            );
        }
        u
    }

    /// The halo: the region grown by one site on every side, which holds every site
    /// face-adjacent to the cluster (on a wall axis, only sites on the lattice).
    #[inline]
    pub(super) fn halo(&self, lattice: &Lattice) -> Region {
        let mut h = *self;
        for axis in 0..lattice.dim() {
            h.spans[axis] = self.spans[axis].grown(
                lattice.size(axis),
                lattice.boundary(axis) == Boundary::Periodic,
            );
        }
        h
    }

    /// Whether the two regions share a site.
    #[inline]
    pub(super) fn meets(&self, other: &Region, lattice: &Lattice) -> bool {
        (0..lattice.dim()).all(|a| self.spans[a].meets(&other.spans[a], lattice.size(a)))
    }

    /// Whether the site with coordinates `x` is in the region.
    #[inline]
    pub(super) fn contains(&self, lattice: &Lattice, x: &[u64; MAX_DIM]) -> bool {
        (0..lattice.dim()).all(|a| self.spans[a].contains(x[a], lattice.size(a)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn periodic_span_is_the_complement_of_the_largest_gap() {
        // 8, 9, 0, 1 on an axis of 10: the span starts at 8 and wraps.
        assert_eq!(
            Span::of(&mut [0, 1, 8, 9], 10, true),
            Span { lo: 8, len: 4 }
        );
        assert_eq!(Span::of(&mut [3, 5], 10, true), Span { lo: 3, len: 3 });
        assert_eq!(Span::of(&mut [4], 10, true), Span { lo: 4, len: 1 });
        assert_eq!(Span::of(&mut [0, 9], 10, false), Span { lo: 0, len: 10 });
    }

    #[test]
    fn union_covers_both_the_short_way() {
        let a = Span { lo: 0, len: 5 };
        let b = Span { lo: 8, len: 4 };
        assert_eq!(a.union(&b, 10, true), Span { lo: 8, len: 7 });
        assert_eq!(b.union(&a, 10, true), Span { lo: 8, len: 7 });
        let c = Span { lo: 2, len: 6 };
        assert_eq!(
            b.union(&Span { lo: 3, len: 6 }, 10, true),
            Span { lo: 3, len: 9 }
        );
        assert_eq!(b.union(&c, 10, true), Span::full(10));
        assert_eq!(
            Span { lo: 2, len: 2 }.union(&Span { lo: 6, len: 1 }, 10, false),
            Span { lo: 2, len: 5 }
        );
    }

    #[test]
    fn every_coordinate_of_a_union_is_covered() {
        // Exhaustive over small arcs on circles of 1 to 7.
        for size in 1..=7u64 {
            for (lo1, len1, lo2, len2) in (0..size).flat_map(|lo1| {
                (1..=size).flat_map(move |len1| {
                    (0..size)
                        .flat_map(move |lo2| (1..=size).map(move |len2| (lo1, len1, lo2, len2)))
                })
            }) {
                let (a, b) = (Span { lo: lo1, len: len1 }, Span { lo: lo2, len: len2 });
                let u = a.union(&b, size, true);
                assert!(u.len <= size);
                for x in 0..size {
                    if a.contains(x, size) || b.contains(x, size) {
                        assert!(u.contains(x, size), "{a:?} {b:?} {u:?} {x}");
                    }
                }
                let meets = (0..size).any(|x| a.contains(x, size) && b.contains(x, size));
                assert_eq!(a.meets(&b, size), meets, "{a:?} {b:?}");
            }
        }
    }
}
