//! How the face and probe lists of a rigid cluster store relative positions, and how an entry
//! plus a cluster origin becomes a site index: [`AnyFrame`] for every lattice, [`Pow2Frame`]
//! for all-periodic lattices with power-of-two sides and at most 2^32 sites, [`SpreadFrame`]
//! for those among them whose geometry has a spread site index (the two are one
//! [`FieldFrame`] with different sums).
//!
//! Invariant: for the same origin and relative position, every frame gives the same site index
//! (so the choice of frame never changes a trajectory).

use super::geometry::Geometry;
use std::fmt::Debug;

/// How list entries are stored and turned into k-indices.
pub(crate) trait Frame<const D: usize>: Debug + Clone {
    /// A relative position as stored in the lists.
    type Entry: Copy + Debug + PartialEq;
    /// An origin in the form the entries are added to.
    type Origin: Copy;
    /// The frame for geometry `geo`, if it applies.
    fn new(geo: &Geometry<D>) -> Option<Self>;
    /// Origin coordinates `o` in this frame's form.
    fn origin(&self, geo: &Geometry<D>, o: &[i64; D]) -> Self::Origin;
    /// Relative coordinates `r` (at most two steps beyond a particle's) as an entry.
    fn entry(&self, geo: &Geometry<D>, r: &[i32; D]) -> Self::Entry;
    /// A list start stored as an entry (see [`Lists`](super::clusters::Lists)).
    fn start(i: usize) -> Self::Entry;
    /// The list start stored in `e`.
    fn start_of(e: Self::Entry) -> usize;
    /// Site index of a particle site.
    fn site(&self, geo: &Geometry<D>, o: Self::Origin, e: Self::Entry) -> usize;
    /// Site index of a probe site, or `None` beyond a wall.
    fn probe(&self, geo: &Geometry<D>, o: Self::Origin, e: Self::Entry) -> Option<usize>;
}

/// Any lattice: entries are relative coordinates, wrapped or bounds-checked axis by axis.
#[derive(Debug, Clone)]
pub(crate) struct AnyFrame;

impl<const D: usize> Frame<D> for AnyFrame {
    type Entry = [i32; D];
    type Origin = [i64; D];
    fn new(_: &Geometry<D>) -> Option<Self> {
        Some(AnyFrame)
    }
    #[inline(always)]
    fn origin(&self, _: &Geometry<D>, o: &[i64; D]) -> [i64; D] {
        *o
    }
    fn entry(&self, _: &Geometry<D>, r: &[i32; D]) -> [i32; D] {
        *r
    }
    fn start(i: usize) -> [i32; D] {
        let mut e = [0; D];
        e[0] = i32::try_from(i).expect("lists shorter than 2^31");
        e
    }
    #[inline(always)]
    fn start_of(e: [i32; D]) -> usize {
        e[0] as usize
    }
    #[inline(always)]
    fn site(&self, geo: &Geometry<D>, o: [i64; D], e: [i32; D]) -> usize {
        geo.site(&o, &e)
    }
    #[inline(always)]
    fn probe(&self, geo: &Geometry<D>, o: [i64; D], e: [i32; D]) -> Option<usize> {
        geo.probe(&o, &e)
    }
}

/// How a bit-field frame ([`FieldFrame`]) adds an origin and an entry, each a site index with
/// one bit field per axis.
pub(crate) trait FieldSum: Debug + Clone {
    /// The sum for geometry `geo`, if it applies.
    fn new<const D: usize>(geo: &Geometry<D>) -> Option<Self>;
    /// The site index of origin `a` plus entry `b`.
    fn add(&self, a: u32, b: u32) -> u32;
}

/// Periodic lattices whose sides are all powers of two, indexed by their k-index with at most
/// 2^32 sites: the sum is computed field by field with the carry between fields suppressed
/// (SIMD within a register), five operations whatever the dimension.
#[derive(Debug, Clone)]
pub(crate) struct Carryless {
    /// The top bit of every axis's field.
    high: u32,
}

impl FieldSum for Carryless {
    fn new<const D: usize>(geo: &Geometry<D>) -> Option<Self> {
        if geo.spread.is_some() {
            return None;
        }
        let fits = geo.size.iter().product::<i64>() <= 1 << 32;
        let pow2 = geo.size.iter().all(|&l| (l as u64).is_power_of_two());
        if !(fits && pow2 && geo.periodic.iter().all(|&p| p)) {
            return None;
        }
        let mut high = 0;
        for a in 0..D {
            if geo.size[a] > 1 {
                high |= ((geo.size[a] as u64 / 2) * geo.stride[a]) as u32;
            }
        }
        Some(Carryless { high })
    }
    #[inline(always)]
    fn add(&self, a: u32, b: u32) -> u32 {
        ((a & !self.high).wrapping_add(b & !self.high)) ^ ((a ^ b) & self.high)
    }
}

/// Periodic lattices whose sides are all powers of two, with a spread site index of at most 32
/// bits (see [`Geometry`]'s module): the sum is a plain addition with the spare bits masked
/// off, two operations whatever the dimension.
#[derive(Debug, Clone)]
pub(crate) struct Spread {
    /// The fields of the spread index.
    mask: u32,
}

impl FieldSum for Spread {
    fn new<const D: usize>(geo: &Geometry<D>) -> Option<Self> {
        geo.spread.map(|mask| Spread { mask })
    }
    #[inline(always)]
    fn add(&self, a: u32, b: u32) -> u32 {
        a.wrapping_add(b) & self.mask
    }
}

/// Periodic power-of-two lattices: an entry is the site index of the relative position reduced
/// modulo the sides, and a site's index is origin plus entry by the [`FieldSum`] `S`.
#[derive(Debug, Clone)]
pub(crate) struct FieldFrame<S>(S);

/// The field-wise sum over the k-index.
pub(crate) type Pow2Frame = FieldFrame<Carryless>;

/// The sum over a spread site index.
pub(crate) type SpreadFrame = FieldFrame<Spread>;

impl<const D: usize, S: FieldSum> Frame<D> for FieldFrame<S> {
    type Entry = u32;
    type Origin = u32;
    fn new(geo: &Geometry<D>) -> Option<Self> {
        S::new(geo).map(FieldFrame)
    }
    #[inline(always)]
    fn origin(&self, geo: &Geometry<D>, o: &[i64; D]) -> u32 {
        (0..D).map(|a| o[a] as u64 * geo.stride[a]).sum::<u64>() as u32
    }
    fn entry(&self, geo: &Geometry<D>, r: &[i32; D]) -> u32 {
        geo.any(&[0; D], r).expect("periodic") as u32
    }
    fn start(i: usize) -> u32 {
        u32::try_from(i).expect("lists shorter than 2^32")
    }
    #[inline(always)]
    fn start_of(e: u32) -> usize {
        e as usize
    }
    #[inline(always)]
    fn site(&self, _: &Geometry<D>, o: u32, e: u32) -> usize {
        self.0.add(o, e) as usize
    }
    #[inline(always)]
    fn probe(&self, _: &Geometry<D>, o: u32, e: u32) -> Option<usize> {
        Some(self.0.add(o, e) as usize)
    }
}
