//! The `lattice` strategy's cluster store: rigid clusters as an origin plus relative sites, with
//! per-direction face and probe lists, over an occupancy lattice of labels.
//!
//! A DLCA cluster never changes shape between merges, it only translates. So each cluster keeps
//! its particles as coordinates *relative* to an origin, and a move changes the origin alone
//! (O(1)) instead of rewriting every particle's k-index. What the occupancy lattice and the
//! contact query need from a move by the unit vector `e` depends only on the shape `C` and `e`,
//! so it is worked out once per shape (at the start and after each merge, N - 1 times in a
//! run) and kept per direction:
//!
//! - the *face* `F(e) = {s in C : s + e not in C}`. A move by `e` covers exactly the sites
//!   `F(e)` (in the new frame) and vacates exactly `F(-e)` (in the old frame): only those
//!   occupancy cells are written; interior particles keep their label.
//! - the *probes* `P(e) = {q in N(C) : q + e not in C or N(C)}`, where `N(C)` is the set of
//!   sites face-adjacent to `C` and outside it. Before a move no other cluster is in `C` or
//!   `N(C)` (clusters merge as soon as they touch), so after it the only sites that can hold a
//!   cluster in contact are the new neighbours, `P(e)` in the new frame: one lookup each, each
//!   such site once.
//!
//! On a fractal DLCA cluster about half the particles are on each face, and the probes number
//! about as many, so a move costs a fraction of the particles in memory traffic and nothing
//! per interior particle.
//!
//! Coordinates: along a periodic axis relative coordinates of particles lie in `[0, L)` (taken
//! modulo `L`) and absolute ones are `origin + relative` reduced modulo `L`; along a wall axis
//! they are plain differences (the cluster cannot wrap) and the origin is one of the cluster's
//! own particles, so it stays on the lattice. Neighbour and probe coordinates reach one step
//! beyond a particle's, so a probe can fall beyond a wall; such probes are skipped. Wall
//! blocking is O(1) from the cluster's extent along the axis.

use core_lattice::{Blocked, Boundary, Direction, Lattice};
use spatial::lattice::{ItemId, SiteSets};
use std::fmt::Debug;
use std::sync::Arc;

/// Marks an empty site.
const EMPTY: u32 = u32::MAX;

/// Clusters of at most this many particles never keep parts (see [`Part`]).
const SMALL: u32 = 64;

/// Largest side length this store handles (relative coordinates are `i32` with a margin).
pub(crate) const MAX_SIDE: u64 = (i32::MAX as u64) / 2;

/// The face and probe lists of one cluster shape, in one allocation (so a move follows one
/// pointer from the cluster): `4d + 1` header entries holding the starts of the lists (encoded
/// by [`Frame::start`]), then the faces by direction index, then the probes by direction index.
/// List `i` is `lists[start(i)..start(i + 1)]`: face `i` for `i < 2d`, else probes `i - 2d`.
type Lists<E> = Arc<[E]>;

#[inline(always)]
fn list<const D: usize, F: Frame<D>>(lists: &[F::Entry], i: usize) -> &[F::Entry] {
    &lists[F::start_of(lists[i])..F::start_of(lists[i + 1])]
}

/// What a move of one rigid cluster in `D` dimensions reads, in one small record (its lists in
/// the entry format of frame `F`). Early in a run most clusters are a few particles and a move
/// costs little more than the cache misses on its data, so everything is one record away.
#[derive(Debug, Clone)]
#[repr(align(64))]
struct Cluster<const D: usize, F: Frame<D>> {
    /// Absolute coordinates of relative position 0, each in `[0, L)`.
    origin: [i64; D],
    /// Face and probe lists; single particles all share one.
    lists: Lists<F::Entry>,
    /// Clusters merged in since the lists were last computed, each with its own lists.
    parts: Parts<D, F>,
    /// Smallest and largest relative coordinate per axis (used on wall axes).
    lo: [i32; D],
    hi: [i32; D],
    /// Number of particles (0 for a cluster merged away).
    len: u32,
    /// Label of its sites in the occupancy lattice; a merge relabels only the smaller part and
    /// gives the survivor the larger part's label.
    label: u32,
}

impl<const D: usize, F: Frame<D>> Default for Cluster<D, F> {
    fn default() -> Self {
        Cluster {
            origin: [0; D],
            lists: Arc::new([]),
            parts: Parts(None),
            lo: [0; D],
            hi: [0; D],
            len: 0,
            label: 0,
        }
    }
}

/// A cluster merged into a larger one, kept with its own lists until the parts merged in
/// since the last computation of the lists hold as many particles as the lists cover (then the
/// lists are computed afresh). So a large cluster absorbing small ones does not recompute its
/// lists at every merge, and each particle is in O(log N) computations over a run. Moving
/// the parts one after the other is exact: all parts vacate their trailing faces before any
/// covers its leading face, and a probe that lands on another part of the same cluster sees
/// the cluster's own label.
#[derive(Debug, Clone)]
struct Part<const D: usize, F: Frame<D>> {
    /// Its origin relative to the cluster's.
    offset: [i32; D],
    lists: Lists<F::Entry>,
    /// Particles its lists cover.
    len: u32,
}

/// The parts of a cluster, boxed so that a cluster without parts (nearly all of them) keeps a
/// small record.
#[derive(Debug, Clone)]
#[allow(clippy::box_collection)] // a thin pointer: an empty `Vec` would take 24 bytes a record
struct Parts<const D: usize, F: Frame<D>>(Option<Box<Vec<Part<D, F>>>>);

impl<const D: usize, F: Frame<D>> Parts<D, F> {
    #[inline]
    fn as_slice(&self) -> &[Part<D, F>] {
        self.0.as_deref().map_or(&[], Vec::as_slice)
    }
    fn push(&mut self, p: Part<D, F>) {
        self.0.get_or_insert_with(Default::default).push(p);
    }
    fn clear(&mut self) {
        self.0 = None;
    }
    #[inline]
    fn is_empty(&self) -> bool {
        self.0.is_none()
    }
}

/// The particles of a cluster, needed only at merges and for output.
#[derive(Debug, Clone, Default)]
struct Cold<const D: usize> {
    /// Relative coordinates of the particles.
    sites: Vec<[i32; D]>,
    /// Size when the sites were last sorted into memory order.
    sorted_len: usize,
}

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
    /// A list start stored as an entry (see [`Lists`]).
    fn start(i: usize) -> Self::Entry;
    /// The list start stored in `e`.
    fn start_of(e: Self::Entry) -> usize;
    /// k-index of a particle site.
    fn site(&self, geo: &Geometry<D>, o: Self::Origin, e: Self::Entry) -> usize;
    /// k-index of a probe site, or `None` beyond a wall.
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

/// Periodic lattices whose sides are all powers of two with at most 2^32 sites: an entry is
/// the k-index of the relative position reduced modulo the sides, and the k-index of a site is
/// the sum of origin and entry computed field by field (each axis a bit field of the k-index)
/// with the carry between fields suppressed (SIMD within a register): four operations,
/// whatever the dimension.
#[derive(Debug, Clone)]
pub(crate) struct Pow2Frame {
    /// The top bit of every axis's field.
    high: u32,
}

impl Pow2Frame {
    #[inline(always)]
    fn add(&self, a: u32, b: u32) -> u32 {
        ((a & !self.high).wrapping_add(b & !self.high)) ^ ((a ^ b) & self.high)
    }
}

impl<const D: usize> Frame<D> for Pow2Frame {
    type Entry = u32;
    type Origin = u32;
    fn new(geo: &Geometry<D>) -> Option<Self> {
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
        Some(Pow2Frame { high })
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
        self.add(o, e) as usize
    }
    #[inline(always)]
    fn probe(&self, _: &Geometry<D>, o: u32, e: u32) -> Option<usize> {
        Some(self.add(o, e) as usize)
    }
}

/// The lattice geometry with the arithmetic the store needs.
#[derive(Debug, Clone)]
pub(crate) struct Geometry<const D: usize> {
    size: [i64; D],
    stride: [u64; D],
    periodic: [bool; D],
    /// Extended lattice for marking neighbour sites: one extra layer beyond each wall.
    ext_stride: [u64; D],
    ext_volume: u64,
}

impl<const D: usize> Geometry<D> {
    fn new(lattice: &Lattice) -> Self {
        assert_eq!(lattice.dim(), D);
        let mut g = Geometry {
            size: [0; D],
            stride: [0; D],
            periodic: [false; D],
            ext_stride: [0; D],
            ext_volume: 1,
        };
        for a in 0..D {
            g.size[a] = lattice.size(a) as i64;
            g.stride[a] = lattice.stride(a);
            g.periodic[a] = lattice.boundary(a) == Boundary::Periodic;
            g.ext_stride[a] = g.ext_volume;
            g.ext_volume *= lattice.size(a) + if g.periodic[a] { 0 } else { 2 };
        }
        g
    }

    /// k-index of a particle (a site known to be on the lattice) at `r` relative to `o`.
    #[inline(always)]
    fn site(&self, o: &[i64; D], r: &[i32; D]) -> usize {
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

    /// k-index of the site at `r` relative to `o` (`r` at most one step beyond a particle's
    /// relative coordinates), or `None` beyond a wall.
    #[inline(always)]
    fn probe(&self, o: &[i64; D], r: &[i32; D]) -> Option<usize> {
        let mut k = 0u64;
        for a in 0..D {
            let mut x = o[a] + i64::from(r[a]);
            if self.periodic[a] {
                if x >= self.size[a] {
                    x -= self.size[a];
                } else if x < 0 {
                    x += self.size[a];
                }
            } else if x < 0 || x >= self.size[a] {
                return None;
            }
            k += x as u64 * self.stride[a];
        }
        Some(k as usize)
    }

    /// Like [`Geometry::probe`] for any relative position (full modular reduction).
    fn any(&self, o: &[i64; D], r: &[i32; D]) -> Option<usize> {
        let mut k = 0u64;
        for a in 0..D {
            let mut x = o[a] + i64::from(r[a]);
            if self.periodic[a] {
                x = x.rem_euclid(self.size[a]);
            } else if x < 0 || x >= self.size[a] {
                return None;
            }
            k += x as u64 * self.stride[a];
        }
        Some(k as usize)
    }

    /// Index in the extended lattice (one layer beyond each wall) of the site at `r` relative
    /// to `o`, or `None` further out.
    fn ext(&self, o: &[i64; D], r: &[i32; D]) -> Option<usize> {
        let mut k = 0u64;
        for a in 0..D {
            let mut x = o[a] + i64::from(r[a]);
            if self.periodic[a] {
                x = x.rem_euclid(self.size[a]);
            } else if x < -1 || x > self.size[a] {
                return None;
            } else {
                x += 1;
            }
            k += x as u64 * self.ext_stride[a];
        }
        Some(k as usize)
    }

    /// The origin of a part at `offset` from origin `o`.
    #[inline(always)]
    fn shifted(&self, o: &[i64; D], offset: &[i32; D]) -> [i64; D] {
        let mut x = [0; D];
        for a in 0..D {
            x[a] = o[a] + i64::from(offset[a]);
            if self.periodic[a] && x[a] >= self.size[a] {
                x[a] -= self.size[a];
            }
        }
        x
    }

    /// Relative coordinates of absolute coordinates `x` in the frame with origin `o`.
    fn relative(&self, o: &[i64; D], x: &[i64; D]) -> [i32; D] {
        let mut r = [0; D];
        for a in 0..D {
            let d = x[a] - o[a];
            r[a] = if self.periodic[a] {
                d.rem_euclid(self.size[a])
            } else {
                d
            } as i32;
        }
        r
    }

    /// Absolute coordinates of the particle at `r` relative to `o`.
    fn absolute(&self, o: &[i64; D], r: &[i32; D]) -> [i64; D] {
        let mut x = [0; D];
        for a in 0..D {
            x[a] = o[a] + i64::from(r[a]);
            if self.periodic[a] {
                x[a] = x[a].rem_euclid(self.size[a]);
            }
        }
        x
    }
}

/// A bitset over the lattice sites.
#[derive(Debug, Clone)]
struct Bits(Vec<u64>);

impl Bits {
    fn new(n: usize) -> Self {
        Bits(vec![0; n.div_ceil(64)])
    }
    #[inline(always)]
    fn get(&self, k: usize) -> bool {
        self.0[k >> 6] & (1 << (k & 63)) != 0
    }
    #[inline(always)]
    fn set(&mut self, k: usize) {
        self.0[k >> 6] |= 1 << (k & 63);
    }
    #[inline(always)]
    fn clear(&mut self, k: usize) {
        self.0[k >> 6] &= !(1 << (k & 63));
    }
}

#[inline(always)]
fn step<const D: usize>(r: &[i32; D], dir: usize) -> [i32; D] {
    let mut q = *r;
    q[dir >> 1] += if dir & 1 == 1 { 1 } else { -1 };
    q
}

/// Clusters, the occupancy lattice and the scratch space of the `lattice` strategy, in `D`
/// dimensions.
#[derive(Debug, Clone)]
pub(crate) struct Rigid<const D: usize, F: Frame<D>> {
    geo: Geometry<D>,
    frame: F,
    /// The lists of a single particle, shared by all single particles.
    single: Option<Lists<F::Entry>>,
    lattice: Lattice,
    /// Which sites hold a particle, one bit a site: small enough to stay in cache where the
    /// label array does not, and all a contact probe reads unless it finds a particle.
    occupied: Bits,
    /// Label of the cluster on each occupied site (stale on empty sites).
    cells: Vec<u32>,
    /// Cluster owning each label.
    id_of: Vec<ItemId>,
    clusters: Vec<Cluster<D, F>>,
    cold: Vec<Cold<D>>,
    live: Vec<ItemId>,
    position: Vec<u32>,
    /// Scratch for rebuilding face and probe lists.
    marks: Vec<u64>,
    hood: Vec<([i32; D], usize)>,
    scratch: Vec<Vec<[i32; D]>>,
}

const DEAD: u32 = u32::MAX;

impl<const D: usize, F: Frame<D>> Rigid<D, F> {
    /// The store for the clusters of `sets` (ids kept), with their occupancy lattice, or `None`
    /// if frame `F` does not apply to the lattice.
    fn new(sets: &SiteSets) -> Option<Self> {
        let lattice = sets.lattice().clone();
        let geo = Geometry::<D>::new(&lattice);
        let frame = F::new(&geo)?;
        let n = sets.id_bound();
        let mut r = Rigid {
            frame,
            single: None,
            occupied: Bits::new(lattice.volume() as usize),
            cells: vec![EMPTY; lattice.volume() as usize],
            id_of: (0..n as ItemId).collect(),
            clusters: vec![Cluster::default(); n],
            cold: vec![Cold::default(); n],
            live: Vec::new(),
            position: vec![DEAD; n],
            marks: Vec::new(),
            hood: Vec::new(),
            scratch: vec![Vec::new(); 4 * D],
            geo,
            lattice,
        };
        let mut ids: Vec<ItemId> = sets.live().to_vec();
        ids.sort_unstable();
        for id in ids {
            let sites = sets.sites(id);
            let coords = |k: u64| -> [i64; D] {
                let x = r.lattice.coords_array(k);
                std::array::from_fn(|a| x[a] as i64)
            };
            let origin = coords(sites[0]);
            let c = &mut r.clusters[id as usize];
            c.origin = origin;
            c.len = sites.len() as u32;
            c.label = id;
            r.cold[id as usize].sites = sites
                .iter()
                .map(|&k| r.geo.relative(&origin, &coords(k)))
                .collect();
            for &k in sites {
                r.cells[k as usize] = id;
                r.occupied.set(k as usize);
            }
            r.position[id as usize] = r.live.len() as u32;
            r.live.push(id);
        }
        for i in 0..r.live.len() {
            let id = r.live[i];
            r.finish(id);
        }
        Some(r)
    }

    #[inline]
    fn len_of(&self, id: ItemId) -> usize {
        self.clusters[id as usize].len as usize
    }

    #[inline]
    fn contains(&self, id: ItemId) -> bool {
        self.clusters.get(id as usize).is_some_and(|c| c.len != 0)
    }

    /// Move cluster `id` by `dir`: all or nothing (a wall blocks it). On success the clusters
    /// now in contact with it are written to `out`, in increasing id.
    fn try_move(
        &mut self,
        id: ItemId,
        dir: Direction,
        out: &mut Vec<ItemId>,
    ) -> Result<(), Blocked> {
        out.clear();
        let Rigid {
            geo,
            frame,
            occupied,
            cells,
            id_of,
            clusters,
            ..
        } = self;
        let c = &mut clusters[id as usize];
        let (axis, d) = (dir.axis(), dir.index());
        if !geo.periodic[axis] {
            let blocked = if dir.is_positive() {
                c.origin[axis] + i64::from(c.hi[axis]) + 1 >= geo.size[axis]
            } else {
                c.origin[axis] + i64::from(c.lo[axis]) <= 0
            };
            if blocked {
                return Err(Blocked);
            }
        }
        let label = c.label;
        // Vacate the trailing face (in the old frame); labels of empty sites are never read.
        let mut o = c.origin;
        let lists = &*c.lists;
        let fo = frame.origin(geo, &o);
        for &e in list::<D, F>(lists, d ^ 1) {
            occupied.clear(frame.site(geo, fo, e));
        }
        for p in c.parts.as_slice() {
            let po = frame.origin(geo, &geo.shifted(&o, &p.offset));
            for &e in list::<D, F>(&p.lists, d ^ 1) {
                occupied.clear(frame.site(geo, po, e));
            }
        }
        o[axis] += if dir.is_positive() { 1 } else { -1 };
        if o[axis] >= geo.size[axis] {
            o[axis] -= geo.size[axis];
        } else if o[axis] < 0 {
            o[axis] += geo.size[axis];
        }
        c.origin = o;
        let fo = frame.origin(geo, &o);
        // Cover the leading face (in the new frame).
        for &e in list::<D, F>(lists, d) {
            let k = frame.site(geo, fo, e);
            debug_assert!(!occupied.get(k) || !c.parts.is_empty(), "clusters overlap");
            occupied.set(k);
            cells[k] = label;
        }
        for p in c.parts.as_slice() {
            let po = frame.origin(geo, &geo.shifted(&o, &p.offset));
            for &e in list::<D, F>(&p.lists, d) {
                let k = frame.site(geo, po, e);
                occupied.set(k);
                cells[k] = label;
            }
        }
        // Look at the new neighbours only.
        let mut probe = |fo: F::Origin, lists: &[F::Entry]| {
            for &e in list::<D, F>(lists, 2 * D + d) {
                if let Some(k) = frame.probe(geo, fo, e)
                    && occupied.get(k)
                {
                    let l = cells[k];
                    if l != label {
                        let other = id_of[l as usize];
                        if !out.contains(&other) {
                            out.push(other);
                        }
                    }
                }
            }
        };
        probe(fo, lists);
        for p in c.parts.as_slice() {
            probe(frame.origin(geo, &geo.shifted(&o, &p.offset)), &p.lists);
        }
        out.sort_unstable();
        Ok(())
    }

    /// Merge cluster `from` into `into` (which keeps its id). Call [`Rigid::finish`] on `into`
    /// after the last merge of a move.
    fn merge(&mut self, into: ItemId, from: ItemId) {
        let (ni, nf) = (self.len_of(into), self.len_of(from));
        let lf = self.clusters[from as usize].label;
        // Relabel the smaller part only.
        let (small, large) = if nf <= ni { (from, into) } else { (into, from) };
        let label = self.clusters[large as usize].label;
        let origin = self.clusters[small as usize].origin;
        for r in &self.cold[small as usize].sites {
            self.cells[self.geo.site(&origin, r)] = label;
        }
        if nf > ni {
            self.id_of[lf as usize] = into;
        }
        // Keep the larger part's frame and append the smaller part's sites.
        let mut other = std::mem::take(&mut self.clusters[from as usize]);
        let mut other_cold = std::mem::take(&mut self.cold[from as usize]);
        if nf > ni {
            std::mem::swap(&mut self.clusters[into as usize], &mut other);
            std::mem::swap(&mut self.cold[into as usize], &mut other_cold);
        }
        let target = &mut self.clusters[into as usize];
        target.len = (ni + nf) as u32;
        target.label = label;
        let geo = &self.geo;
        // The smaller cluster and its parts become parts of the union.
        let extra: u32 = other.parts.as_slice().iter().map(|p| p.len).sum();
        let off = geo.relative(&target.origin, &other.origin);
        for a in 0..D {
            target.lo[a] = target.lo[a].min(off[a] + other.lo[a]);
            target.hi[a] = target.hi[a].max(off[a] + other.hi[a]);
        }
        target.parts.push(Part {
            offset: off,
            lists: other.lists.clone(),
            len: other.len - extra,
        });
        for p in other.parts.as_slice() {
            target.parts.push(Part {
                offset: geo.relative(&target.origin, &geo.absolute(&other.origin, &p.offset)),
                lists: p.lists.clone(),
                len: p.len,
            });
        }
        self.cold[into as usize].sites.extend(
            other_cold
                .sites
                .iter()
                .map(|r| geo.relative(&target.origin, &geo.absolute(&other.origin, r))),
        );
        // Unlink `from`.
        let p = self.position[from as usize] as usize;
        self.live.swap_remove(p);
        if let Some(&moved) = self.live.get(p) {
            self.position[moved as usize] = p as u32;
        }
        self.position[from as usize] = DEAD;
    }

    /// After merges into cluster `id`: recompute its extent and its face and probe lists from
    /// its sites and the occupancy lattice (O(size)) if the parts merged in since the last time
    /// hold as many particles as the lists cover; otherwise keep the parts (see [`Part`]).
    fn finish(&mut self, id: ItemId) {
        let c = &self.clusters[id as usize];
        let extra: u32 = c.parts.as_slice().iter().map(|p| p.len).sum();
        // Small clusters are recomputed at once: cheap, and it spares their moves the parts'
        // extra pointers.
        if !c.parts.is_empty() && 2 * extra < c.len && c.len > SMALL {
            return;
        }
        if self.marks.is_empty() {
            self.marks = vec![0; self.geo.ext_volume.div_ceil(64) as usize];
        }
        let mut c = std::mem::take(&mut self.clusters[id as usize]);
        let mut cold = std::mem::take(&mut self.cold[id as usize]);
        // Large clusters are kept in memory order (re-sorted when they double), so their lists
        // walk the occupancy lattice in order.
        if cold.sites.len() >= 64 && cold.sites.len() >= 2 * cold.sorted_len {
            let (geo, o) = (&self.geo, c.origin);
            cold.sites.sort_by_cached_key(|r| geo.site(&o, r));
            cold.sorted_len = cold.sites.len();
        }
        c.parts.clear();
        c.lists = match &self.single {
            Some(single) if cold.sites.len() == 1 => single.clone(),
            _ => self.build_lists(&mut c, &cold.sites),
        };
        if cold.sites.len() == 1 && self.single.is_none() {
            self.single = Some(c.lists.clone());
        }
        self.clusters[id as usize] = c;
        self.cold[id as usize] = cold;
    }

    /// The extent and the lists of `c`, whose particles are `sites`.
    fn build_lists(&mut self, c: &mut Cluster<D, F>, sites: &[[i32; D]]) -> Lists<F::Entry> {
        let label = c.label;
        let Rigid {
            geo,
            frame,
            occupied,
            cells,
            marks,
            hood,
            scratch,
            ..
        } = self;
        let o = c.origin;
        let in_c = |r: &[i32; D]| {
            geo.any(&o, r)
                .is_some_and(|k| occupied.get(k) && cells[k] == label)
        };
        scratch.iter_mut().for_each(Vec::clear);
        hood.clear();
        c.lo = [i32::MAX; D];
        c.hi = [i32::MIN; D];
        for s in sites {
            for a in 0..D {
                c.lo[a] = c.lo[a].min(s[a]);
                c.hi[a] = c.hi[a].max(s[a]);
            }
            for d in 0..2 * D {
                let q = step(s, d);
                if in_c(&q) {
                    continue;
                }
                scratch[d].push(*s);
                // A neighbour site (possibly one step beyond a wall), each once.
                let e = geo.ext(&o, &q).expect("one step from a particle");
                let (w, b) = (e / 64, 1u64 << (e % 64));
                if marks[w] & b == 0 {
                    marks[w] |= b;
                    hood.push((q, e));
                }
            }
        }
        for (q, _) in hood.iter() {
            for d in 0..2 * D {
                let n = step(q, d);
                let near = in_c(&n)
                    || geo
                        .ext(&o, &n)
                        .is_some_and(|e| marks[e / 64] & (1u64 << (e % 64)) != 0);
                if !near {
                    scratch[2 * D + d].push(*q);
                }
            }
        }
        for (_, e) in hood.iter() {
            marks[e / 64] &= !(1u64 << (e % 64));
        }
        let head = 4 * D + 1;
        let mut lists = Vec::with_capacity(head + scratch.iter().map(Vec::len).sum::<usize>());
        lists.push(F::start(head));
        let mut end = head;
        for list in scratch.iter() {
            end += list.len();
            lists.push(F::start(end));
        }
        for list in scratch.iter() {
            lists.extend(list.iter().map(|r| frame.entry(geo, r)));
        }
        lists.into()
    }

    /// Absolute k-indices of the particles of `id`.
    fn sites(&self, id: ItemId) -> Vec<u64> {
        let c = &self.clusters[id as usize];
        self.cold[id as usize]
            .sites
            .iter()
            .map(|r| self.geo.site(&c.origin, r) as u64)
            .collect()
    }

    /// Panic unless the occupancy lattice holds exactly the clusters' particles and every
    /// cluster's lists match a fresh computation. For tests.
    fn check(&mut self) {
        let mut total = 0;
        for i in 0..self.live.len() {
            let id = self.live[i];
            let label = self.clusters[id as usize].label;
            assert_eq!(self.id_of[label as usize], id, "label table");
            assert_eq!(self.len_of(id), self.cold[id as usize].sites.len());
            for k in self.sites(id) {
                assert!(
                    self.occupied.get(k as usize),
                    "site {k} of cluster {id} not marked"
                );
                assert_eq!(self.cells[k as usize], label, "occupancy of cluster {id}");
                total += 1;
            }
            let mut fresh = self.clusters[id as usize].clone();
            let sites = self.cold[id as usize].sites.clone();
            let lists = self.build_lists(&mut fresh, &sites);
            let c = &self.clusters[id as usize];
            if c.parts.is_empty() {
                assert_eq!(&*lists, &*c.lists);
            }
            let extra: u32 = c.parts.as_slice().iter().map(|p| p.len).sum();
            assert!(
                c.parts.is_empty() || (2 * extra < c.len && c.len > SMALL),
                "parts not consolidated"
            );
            for a in (0..D).filter(|&a| !self.geo.periodic[a]) {
                assert_eq!((fresh.lo[a], fresh.hi[a]), (c.lo[a], c.hi[a]), "extent");
            }
        }
        let filled = (0..self.cells.len())
            .filter(|&k| self.occupied.get(k))
            .count();
        assert_eq!(filled, total, "occupancy holds stray labels");
    }

    fn to_sets(&self) -> SiteSets {
        let mut sets = SiteSets::new(self.lattice.clone());
        for id in 0..self.clusters.len() as ItemId {
            sets.push(if self.contains(id) {
                self.sites(id)
            } else {
                Vec::new()
            });
        }
        for id in 0..self.clusters.len() as ItemId {
            if !self.contains(id) {
                sets.remove(id);
            }
        }
        sets
    }
}

/// [`Rigid`] for the dimension of the lattice (1 to 3; see `RIGID_MAX_DIM` in `sim.rs`).
#[derive(Debug, Clone)]
pub(crate) enum RigidStore {
    D1(Rigid<1, AnyFrame>),
    D2(Rigid<2, AnyFrame>),
    D3(Rigid<3, AnyFrame>),
    P1(Rigid<1, Pow2Frame>),
    P2(Rigid<2, Pow2Frame>),
    P3(Rigid<3, Pow2Frame>),
}

macro_rules! each {
    ($self:expr, $r:ident => $e:expr) => {
        match $self {
            RigidStore::D1($r) => $e,
            RigidStore::D2($r) => $e,
            RigidStore::D3($r) => $e,
            RigidStore::P1($r) => $e,
            RigidStore::P2($r) => $e,
            RigidStore::P3($r) => $e,
        }
    };
}

impl RigidStore {
    /// The store for the clusters of `sets` (same ids). `None` when the dimension is outside
    /// 1..=3 or a side is larger than [`MAX_SIDE`].
    pub(crate) fn new(sets: &SiteSets) -> Option<Self> {
        let l = sets.lattice();
        if l.sizes().iter().any(|&s| s > MAX_SIDE) {
            return None;
        }
        // The power-of-two frame where it applies, else the general one.
        match l.dim() {
            1 => Rigid::new(sets)
                .map(RigidStore::P1)
                .or_else(|| Rigid::new(sets).map(RigidStore::D1)),
            2 => Rigid::new(sets)
                .map(RigidStore::P2)
                .or_else(|| Rigid::new(sets).map(RigidStore::D2)),
            3 => Rigid::new(sets)
                .map(RigidStore::P3)
                .or_else(|| Rigid::new(sets).map(RigidStore::D3)),
            _ => None,
        }
    }

    /// Live cluster ids.
    pub(crate) fn live(&self) -> &[ItemId] {
        each!(self, r => &r.live)
    }

    /// Number of particles of cluster `id`.
    pub(crate) fn len_of(&self, id: ItemId) -> usize {
        each!(self, r => r.len_of(id))
    }

    /// Whether `id` is live.
    pub(crate) fn contains(&self, id: ItemId) -> bool {
        each!(self, r => r.contains(id))
    }

    /// See [`Rigid::try_move`].
    pub(crate) fn try_move(
        &mut self,
        id: ItemId,
        dir: Direction,
        out: &mut Vec<ItemId>,
    ) -> Result<(), Blocked> {
        each!(self, r => r.try_move(id, dir, out))
    }

    /// See [`Rigid::merge`].
    pub(crate) fn merge(&mut self, into: ItemId, from: ItemId) {
        each!(self, r => r.merge(into, from))
    }

    /// See [`Rigid::finish`].
    pub(crate) fn finish(&mut self, id: ItemId) {
        each!(self, r => r.finish(id))
    }

    /// Panic unless the store is consistent (see [`Rigid::check`]).
    pub(crate) fn check(&mut self) {
        each!(self, r => r.check())
    }

    /// The clusters as k-index arrays (absolute sites), with the same ids.
    pub(crate) fn to_sets(&self) -> SiteSets {
        each!(self, r => r.to_sets())
    }
}
