//! The rigid-cluster store of the `lattice` strategy in `D` dimensions ([`Rigid`]): each
//! cluster as an origin plus relative sites with its face and probe lists, over an occupancy
//! lattice of labels (see the parent module for the method).
//!
//! *Large* clusters (at least [`Rigid::large_at`] particles) write no labels when they move:
//! their covering of a site is a bit in the occupancy lattice only, and what a cluster's probe
//! finds there is told by the large clusters' own [`Members`] bits, asked before the label.
//! At most `N / 32` clusters are large, and the label writes they skip were most of a late
//! run's memory traffic (a 4-byte store into an array of 4 bytes a site, far beyond the L2).
//! Where the lattice's rows along axis 0 are whole words of the occupancy bits, a large
//! cluster's move flips its image a word at a time from its members' rows when that visits at
//! most half as many words and rows as its faces hold sites ([`RowMoves`]): a fractal cluster
//! in 2D has a few face sites in each word its rows span, and the run ends with its largest
//! clusters moving.
//!
//! Invariants, checked by [`Rigid::check`]: the occupancy bits hold exactly the live clusters'
//! particles, each occupied cell of a small cluster holds its label, each large cluster's
//! members are exactly its particles and it is in `large`, `id_of` maps every live small
//! cluster's label back to its id, each cluster's lists equal a fresh computation from its
//! sites (unless it keeps parts, which then cover less than half of it), and the extent along
//! every wall axis is exact.
//!
//! This file holds the records, construction, merges and checks; `moves` the moves and the
//! contact search, `lists` the computation of a shape's face and probe lists.

use super::frame::Frame;
use super::geometry::{Bits, Geometry};
use super::members::Members;
use core_lattice::Lattice;
use spatial::lattice::{ItemId, SiteSets};
use std::sync::Arc;

mod lists;
mod moves;

/// Clusters of at most this many particles never keep parts (see [`Part`]), and never count as
/// large.
const SMALL: u32 = 64;

/// At most about this many clusters are large: `large_at` is the particles over this.
const MAX_LARGE: u64 = 32;

/// Largest side length this store handles (relative coordinates are `i32` with a margin).
pub(super) const MAX_SIDE: u64 = (i32::MAX as u64) / 2;

/// The face and probe lists of one cluster shape, in one allocation (so a move follows one
/// pointer from the cluster): `4d + 1` header entries holding the starts of the lists (encoded
/// by [`Frame::start`]), then the faces by direction index, then the probes by direction index.
/// List `i` is `lists[start(i)..start(i + 1)]`: face `i` for `i < 2d`, else probes `i - 2d`.
pub(super) type Lists<E> = Arc<[E]>;

/// List `i` of `lists` (see [`Lists`]).
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
    /// The sites as bits, for a large cluster (boxed: nearly all clusters are small, and this
    /// record is one of `N`).
    members: Option<Box<Members<D>>>,
}

/// Clusters, the occupancy lattice and the scratch space of the `lattice` strategy, in `D`
/// dimensions.
#[derive(Debug, Clone)]
pub(crate) struct Rigid<const D: usize, F: Frame<D>> {
    pub(super) geo: Geometry<D>,
    frame: F,
    /// The lists of a single particle, shared by all single particles.
    single: Option<Lists<F::Entry>>,
    lattice: Lattice,
    /// Which sites hold a particle, one bit a site by site index: small enough to stay in cache
    /// where the label array does not, and all a contact probe reads unless it finds a particle.
    occupied: Bits,
    /// Label of the cluster on each occupied site (stale on empty sites), by site index.
    cells: Cells,
    /// Cluster owning each label.
    id_of: Vec<ItemId>,
    /// Clusters of at least this many particles are large: `max(SMALL, N / MAX_LARGE)`.
    large_at: u32,
    /// The live large clusters.
    large: Vec<ItemId>,
    /// When large clusters move by rows ([`RowMoves`]).
    pub(super) row_moves: RowMoves,
    clusters: Vec<Cluster<D, F>>,
    cold: Vec<Cold<D>>,
    pub(super) live: Vec<ItemId>,
    position: Vec<u32>,
    /// Scratch for rebuilding face and probe lists.
    marks: Vec<u64>,
    hood: Vec<([i32; D], usize)>,
    scratch: Vec<Vec<[i32; D]>>,
}

const DEAD: u32 = u32::MAX;

/// How a large cluster's move updates the occupancy bits: by its faces, a site at a time, or by
/// its members' rows, a word at a time ([`Members::xor_move`]). Both give the same bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum RowMoves {
    /// By faces always (the lattice's rows are not whole words).
    Never,
    /// By rows where the words and rows to visit are at most half the face sites: a word costs
    /// about what a site costs, and a row's set-up about a word; the margin keeps sparse
    /// clusters with short rows (3D) on their faces.
    WhenCheaper,
    /// By rows always (for tests).
    #[cfg(test)]
    Always,
}

/// The labels of the sites, by site index, allocated zeroed (a page never written costs no
/// memory) and starting at a page boundary where the allocator allows it, so that the unused
/// runs of a spread site index are whole pages.
#[derive(Debug, Clone)]
struct Cells {
    v: Vec<u32>,
    /// Index in `v` of site index 0.
    at: usize,
}

impl Cells {
    /// Cells per 4 KiB page.
    const PAGE: usize = 1024;

    /// Room for `len` labels, allocated fallibly.
    fn new(len: usize) -> Result<Self, run_io::memory::AllocError> {
        let v: Vec<u32> = run_io::memory::try_zeros(len + Self::PAGE, "the occupancy lattice")?;
        let page = 4 * Self::PAGE;
        let at = (page - v.as_ptr() as usize % page) % page / 4;
        Ok(Cells { v, at })
    }
    #[inline(always)]
    fn get(&self) -> &[u32] {
        &self.v[self.at..]
    }
    #[inline(always)]
    fn get_mut(&mut self) -> &mut [u32] {
        &mut self.v[self.at..]
    }
}

impl<const D: usize, F: Frame<D>> Rigid<D, F> {
    /// The store for the clusters of `sets` (ids kept), with their occupancy lattice, in frame
    /// `frame` over `geo` (the geometry of the sets' lattice).
    /// The lattice's cells (4 bytes a site) are allocated fallibly; a cell never occupied costs
    /// no memory (the spread index's unused cells among them).
    pub(super) fn new(
        sets: &SiteSets,
        geo: Geometry<D>,
        frame: F,
    ) -> Result<Self, run_io::memory::AllocError> {
        let lattice = sets.lattice().clone();
        let n = sets.id_bound();
        let cells = Cells::new(geo.volume as usize)?;
        let mut r = Rigid {
            frame,
            single: None,
            occupied: Bits::new(geo.volume as usize),
            cells,
            id_of: (0..n as ItemId).collect(),
            large_at: 0,
            large: Vec::new(),
            row_moves: if geo.bit_rows() {
                RowMoves::WhenCheaper
            } else {
                RowMoves::Never
            },
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
                let i = r.geo.index_of(k);
                r.cells.get_mut()[i] = id;
                r.occupied.set(i);
            }
            r.position[id as usize] = r.live.len() as u32;
            r.live.push(id);
        }
        let particles: u64 = r.clusters.iter().map(|c| u64::from(c.len)).sum();
        r.large_at = SMALL.max(u32::try_from(particles.div_ceil(MAX_LARGE)).unwrap_or(u32::MAX));
        for i in 0..r.live.len() {
            let id = r.live[i];
            if r.clusters[id as usize].len >= r.large_at {
                let cold = &mut r.cold[id as usize];
                cold.members = Some(Box::new(Members::build(&r.geo, &cold.sites)));
                r.large.push(id);
            }
        }
        for i in 0..r.live.len() {
            let id = r.live[i];
            r.finish(id);
        }
        Ok(r)
    }

    #[inline]
    pub(super) fn len_of(&self, id: ItemId) -> usize {
        self.clusters[id as usize].len as usize
    }

    /// Start loading the record of cluster `id` (one cache line) into the cache.
    #[inline]
    pub(super) fn prefetch_record(&self, id: ItemId) {
        if let Some(c) = self.clusters.get(id as usize) {
            core_lattice::hint::prefetch(c);
        }
    }

    /// Start loading the head of cluster `id`'s lists (the list starts and its first entries)
    /// into the cache; reads its record.
    #[inline]
    pub(super) fn prefetch_lists(&self, id: ItemId) {
        if let Some(e) = self.clusters.get(id as usize).and_then(|c| c.lists.first()) {
            core_lattice::hint::prefetch(e);
        }
    }

    #[inline]
    pub(super) fn contains(&self, id: ItemId) -> bool {
        self.clusters.get(id as usize).is_some_and(|c| c.len != 0)
    }

    /// Merge cluster `from` into `into` (which keeps its id). Call [`Rigid::finish`] on `into`
    /// after the last merge of a move.
    pub(super) fn merge(&mut self, into: ItemId, from: ItemId) {
        let (ni, nf) = (self.len_of(into), self.len_of(from));
        let lf = self.clusters[from as usize].label;
        // Relabel the smaller part only, and only if the union is small (a large cluster's
        // labels are never read).
        let (small, big) = if nf <= ni { (from, into) } else { (into, from) };
        let label = self.clusters[big as usize].label;
        let union_is_large = (ni + nf) as u32 >= self.large_at;
        if !union_is_large {
            let origin = self.clusters[small as usize].origin;
            for r in &self.cold[small as usize].sites {
                self.cells.get_mut()[self.geo.site(&origin, r)] = label;
            }
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
        let cold = &mut self.cold[into as usize];
        let before = cold.sites.len();
        cold.sites.extend(
            other_cold
                .sites
                .iter()
                .map(|r| geo.relative(&target.origin, &geo.absolute(&other.origin, r))),
        );
        // The union's members (in the larger part's frame, which it keeps).
        self.large.retain(|&b| b != into && b != from);
        if union_is_large {
            let Cold { sites, members, .. } = cold;
            match members {
                Some(m) => m.extend(geo, sites, &sites[before..]),
                None => *members = Some(Box::new(Members::build(geo, sites.iter()))),
            }
            self.large.push(into);
        }
        // Unlink `from`.
        let p = self.position[from as usize] as usize;
        self.live.swap_remove(p);
        if let Some(&moved) = self.live.get(p) {
            self.position[moved as usize] = p as u32;
        }
        self.position[from as usize] = DEAD;
    }

    /// Absolute k-indices of the particles of `id`.
    pub(super) fn sites(&self, id: ItemId) -> Vec<u64> {
        let c = &self.clusters[id as usize];
        self.cold[id as usize]
            .sites
            .iter()
            .map(|r| self.geo.lattice_site(&c.origin, r))
            .collect()
    }

    /// Panic unless the occupancy lattice holds exactly the clusters' particles and every
    /// cluster's lists match a fresh computation. For tests.
    pub(super) fn check(&mut self) {
        let mut total = 0;
        for i in 0..self.live.len() {
            let id = self.live[i];
            let label = self.clusters[id as usize].label;
            assert_eq!(self.id_of[label as usize], id, "label table");
            assert_eq!(self.len_of(id), self.cold[id as usize].sites.len());
            let origin = self.clusters[id as usize].origin;
            let large = self.clusters[id as usize].len >= self.large_at;
            let members = self.cold[id as usize].members.as_deref();
            assert_eq!(large, self.large.contains(&id), "large list");
            assert_eq!(large, members.is_some(), "members of a large cluster only");
            if let Some(m) = members {
                m.check();
                assert_eq!(m.count(), self.len_of(id), "members of cluster {id}");
            }
            for r in &self.cold[id as usize].sites {
                let i = self.geo.site(&origin, r);
                assert!(
                    self.occupied.get(i),
                    "site {r:?} of cluster {id} not marked"
                );
                match members {
                    Some(m) => assert!(m.contains(r), "site {r:?} not a member of {id}"),
                    None => assert_eq!(self.cells.get()[i], label, "occupancy of cluster {id}"),
                }
                assert_eq!(self.owner_of(i), id, "owner of site {r:?}");
                assert_eq!(self.geo.index_of(self.geo.lattice_site(&origin, r)), i);
                total += 1;
            }
            let mut fresh = self.clusters[id as usize].clone();
            let cold = self.cold[id as usize].clone();
            let lists = self.build_lists(&mut fresh, &cold.sites, cold.members.as_deref());
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
        let filled = (0..self.geo.volume as usize)
            .filter(|&i| self.occupied.get(i))
            .count();
        assert_eq!(filled, total, "occupancy holds stray labels");
    }

    /// The clusters as k-index arrays (absolute sites), with the same ids.
    pub(super) fn to_sets(&self) -> SiteSets {
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
