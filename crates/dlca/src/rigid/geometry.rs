//! Lattice arithmetic of the rigid-cluster store in `D` dimensions: the store's indices of
//! positions relative to an origin (wrapped on periodic axes, bounds-checked on wall axes), an
//! extended lattice one layer beyond each wall for marking neighbour sites, and a bitset over
//! the sites.
//!
//! The store indexes its per-site arrays by a *site index* that is the lattice's k-index, except
//! on all-periodic lattices with power-of-two sides: there each axis's field of the index has a
//! spare bit above it that is always zero on a site (the *spread* index). Origin plus relative
//! position is then one addition and one mask, whatever the dimension: the carry out of a field
//! lands in its spare bit and the mask drops it (see [`SpreadFrame`](super::frame::SpreadFrame)).
//! The arrays are up to `2^(D-1)` times longer than the lattice and the indices with a spare bit
//! set are never touched; the store uses the spread index only where those come in whole pages
//! ([`Geometry::spread_costs_no_memory`]), so that it costs no memory.
//!
//! Invariant: the [`Geometry`] describes exactly the lattice it was built from (same sides,
//! strides and boundaries), and the site index is a one-to-one map of its sites into
//! `[0, volume)` that preserves their order.

use core_lattice::{Boundary, Lattice};

/// The lattice geometry with the arithmetic the store needs.
#[derive(Debug, Clone)]
pub(crate) struct Geometry<const D: usize> {
    pub(super) size: [i64; D],
    /// Strides of the site index.
    pub(super) stride: [u64; D],
    /// Strides of the lattice's k-index.
    lattice_stride: [u64; D],
    pub(super) periodic: [bool; D],
    /// Length of the arrays indexed by site index.
    pub(super) volume: u64,
    /// On a spread index (see the module documentation), the mask of the axes' fields.
    pub(super) spread: Option<u32>,
    /// Extended lattice for marking neighbour sites: one extra layer beyond each wall.
    ext_stride: [u64; D],
    pub(super) ext_volume: u64,
}

impl<const D: usize> Geometry<D> {
    pub(super) fn new(lattice: &Lattice) -> Self {
        assert_eq!(lattice.dim(), D);
        let mut g = Geometry {
            size: [0; D],
            stride: [0; D],
            lattice_stride: [0; D],
            periodic: [false; D],
            volume: lattice.volume(),
            spread: None,
            ext_stride: [0; D],
            ext_volume: 1,
        };
        for a in 0..D {
            g.size[a] = lattice.size(a) as i64;
            g.lattice_stride[a] = lattice.stride(a);
            g.periodic[a] = lattice.boundary(a) == Boundary::Periodic;
            g.ext_stride[a] = g.ext_volume;
            g.ext_volume *= lattice.size(a) + if g.periodic[a] { 0 } else { 2 };
        }
        g.stride = g.lattice_stride;
        g
    }

    /// The geometry with a spread site index (see the module documentation), if the lattice is
    /// periodic with power-of-two sides and the index fits 32 bits.
    pub(super) fn spread(lattice: &Lattice) -> Option<Self> {
        let mut g = Self::new(lattice);
        // Each field `bits` wide plus a spare bit, the last field without one.
        let bits: [u32; D] = std::array::from_fn(|a| lattice.size(a).trailing_zeros());
        let width = bits.iter().sum::<u32>() + D as u32 - 1;
        let pow2 = (0..D).all(|a| (lattice.size(a)).is_power_of_two());
        if !(pow2 && g.periodic.iter().all(|&p| p) && width <= 32) {
            return None;
        }
        let (mut shift, mut mask) = (0, 0u64);
        for a in 0..D {
            g.stride[a] = 1 << shift;
            mask |= (lattice.size(a) - 1) << shift;
            shift += bits[a] + 1;
        }
        g.volume = mask + 1;
        g.spread = Some(mask as u32);
        Some(g)
    }

    /// Whether each row along axis 0 is whole words of a [`Bits`] by site index: consecutive
    /// sites along axis 0, a side a multiple of 64 and row starts on word boundaries (where
    /// [`Members::xor_move`](super::members::Members::xor_move) writes whole words).
    pub(super) fn word_rows(&self) -> bool {
        self.stride[0] == 1 && self.size[0] % 64 == 0 && (1..D).all(|a| self.stride[a] % 64 == 0)
    }

    /// Whether consecutive sites along axis 0 have consecutive site indices and the first side
    /// is at least 64: what a move by rows needs, at any bit position
    /// ([`Members::xor_move`](super::members::Members::xor_move)).
    pub(super) fn bit_rows(&self) -> bool {
        self.stride[0] == 1 && self.size[0] >= 64
    }

    /// Whether the unused indices of a spread site index come in runs of whole 4 KiB pages of
    /// 4-byte cells (one axis, or a first axis of at least 1 024 sites), so that a page-aligned
    /// label array costs no more memory than the lattice's.
    pub(super) fn spread_costs_no_memory(&self) -> bool {
        D == 1 || self.size[0] >= 1024
    }

    /// The site index of the site with lattice k-index `k`.
    pub(super) fn index_of(&self, k: u64) -> usize {
        let mut i = 0;
        for a in 0..D {
            let x = (k / self.lattice_stride[a]) % self.size[a] as u64;
            i += x * self.stride[a];
        }
        i as usize
    }

    /// Coordinates of the site with site index `i`.
    pub(super) fn coords_of(&self, i: usize) -> [i64; D] {
        std::array::from_fn(|a| ((i as u64 / self.stride[a]) % self.size[a] as u64) as i64)
    }

    /// Lattice k-index of a particle at `r` relative to `o`.
    pub(super) fn lattice_site(&self, o: &[i64; D], r: &[i32; D]) -> u64 {
        let x = self.absolute(o, r);
        (0..D).map(|a| x[a] as u64 * self.lattice_stride[a]).sum()
    }

    /// Site index of a particle (a site known to be on the lattice) at `r` relative to `o`.
    #[inline(always)]
    pub(super) fn site(&self, o: &[i64; D], r: &[i32; D]) -> usize {
        let mut k = 0u64;
        for a in 0..D {
            let mut x = o[a] + i64::from(r[a]);
            if self.periodic[a] {
                if x >= self.size[a] {
                    x -= self.size[a];
                } else if x < 0 {
                    x += self.size[a];
                }
            }
            k += x as u64 * self.stride[a];
        }
        k as usize
    }

    /// Site index of the site at `r` relative to `o` (`r` at most one step beyond a particle's
    /// relative coordinates), or `None` beyond a wall.
    #[inline(always)]
    pub(super) fn probe(&self, o: &[i64; D], r: &[i32; D]) -> Option<usize> {
        self.index_by(o, r, &self.stride, |a, mut x| {
            if self.periodic[a] {
                if x >= self.size[a] {
                    x -= self.size[a];
                } else if x < 0 {
                    x += self.size[a];
                }
            } else if x < 0 || x >= self.size[a] {
                return None;
            }
            Some(x)
        })
    }

    /// Like [`Geometry::probe`] for any relative position (full modular reduction).
    pub(super) fn any(&self, o: &[i64; D], r: &[i32; D]) -> Option<usize> {
        self.index_by(o, r, &self.stride, |a, x| {
            if self.periodic[a] {
                Some(x.rem_euclid(self.size[a]))
            } else if x < 0 || x >= self.size[a] {
                None
            } else {
                Some(x)
            }
        })
    }

    /// Index in the extended lattice (one layer beyond each wall) of the site at `r` relative
    /// to `o`, or `None` further out.
    pub(super) fn ext(&self, o: &[i64; D], r: &[i32; D]) -> Option<usize> {
        self.index_by(o, r, &self.ext_stride, |a, x| {
            if self.periodic[a] {
                Some(x.rem_euclid(self.size[a]))
            } else if x < -1 || x > self.size[a] {
                None
            } else {
                Some(x + 1)
            }
        })
    }

    /// The index with strides `stride` of the site at `r` relative to `o`, each axis'
    /// coordinate `x` placed by `place(axis, x)` (wrapped onto the lattice, or `None` off it):
    /// the one loop of [`Geometry::probe`], [`Geometry::any`] and [`Geometry::ext`], which
    /// differ only in `place`. Inlined, each still compiles to its own loop (`probe` is on the
    /// contact search's hot path).
    #[inline(always)]
    fn index_by(
        &self,
        o: &[i64; D],
        r: &[i32; D],
        stride: &[u64; D],
        place: impl Fn(usize, i64) -> Option<i64>,
    ) -> Option<usize> {
        let mut k = 0u64;
        for a in 0..D {
            let x = place(a, o[a] + i64::from(r[a]))?;
            k += x as u64 * stride[a];
        }
        Some(k as usize)
    }

    /// The origin of a part at `offset` from origin `o`.
    #[inline(always)]
    pub(super) fn shifted(&self, o: &[i64; D], offset: &[i32; D]) -> [i64; D] {
        let mut x = [0; D];
        for a in 0..D {
            x[a] = o[a] + i64::from(offset[a]);
            if self.periodic[a] && x[a] >= self.size[a] {
                x[a] -= self.size[a];
            }
        }
        x
    }

    /// Relative coordinates of absolute coordinates `x` in the frame with origin `o`, both on
    /// the lattice (in `[0, L)` on periodic axes).
    pub(super) fn relative(&self, o: &[i64; D], x: &[i64; D]) -> [i32; D] {
        let mut r = [0; D];
        for a in 0..D {
            let mut d = x[a] - o[a];
            if self.periodic[a] && d < 0 {
                d += self.size[a];
            }
            r[a] = d as i32;
        }
        r
    }

    /// Absolute coordinates of the site at `r` relative to `o` (`o` on the lattice).
    pub(super) fn absolute(&self, o: &[i64; D], r: &[i32; D]) -> [i64; D] {
        let mut x = [0; D];
        for a in 0..D {
            x[a] = o[a] + i64::from(r[a]);
            if self.periodic[a] && !(0..self.size[a]).contains(&x[a]) {
                x[a] = x[a].rem_euclid(self.size[a]);
            }
        }
        x
    }
}

/// A bitset over the lattice sites.
#[derive(Debug, Clone)]
pub(super) struct Bits(Vec<u64>);

impl Bits {
    pub(super) fn new(n: usize) -> Self {
        Bits(vec![0; n.div_ceil(64)])
    }
    #[inline(always)]
    pub(super) fn get(&self, k: usize) -> bool {
        self.0[k >> 6] & (1 << (k & 63)) != 0
    }
    #[inline(always)]
    pub(super) fn set(&mut self, k: usize) {
        self.0[k >> 6] |= 1 << (k & 63);
    }
    #[inline(always)]
    pub(super) fn clear(&mut self, k: usize) {
        self.0[k >> 6] &= !(1 << (k & 63));
    }
    pub(super) fn words_mut(&mut self) -> &mut [u64] {
        &mut self.0
    }
}

/// `r` moved one step along direction index `dir` (axis `dir / 2`, positive when `dir` is odd).
#[inline(always)]
pub(super) fn step<const D: usize>(r: &[i32; D], dir: usize) -> [i32; D] {
    let mut q = *r;
    q[dir >> 1] += if dir & 1 == 1 { 1 } else { -1 };
    q
}
