//! Orthtree: quadtree (D = 2), octree (D = 3), 2^D children in general, with an exact nearest
//! distance query and the variable-precision distance search `vpdist` of Sosa-Herrera &
//! Rodriguez-Romo, *Variable precision distance search for random fractal cluster simulations*
//! (the variable-precision paper, section 3.1 and Listing 1; storage after section 3.3).
//!
//! Built for off-lattice DLA/PDLA (the variable-precision paper, sections 3.3 and 3.4): particle
//! centres in units of particle diameters, inserted one at a time, queried millions of times by
//! random walkers.
//!
//! # Structure
//!
//! Space is cut into **leaf cells**: the cubes `[k s, (k + 1) s)^D` of side `s` (the *leaf side*,
//! a power of two, default [`DEFAULT_LEAF_SIDE`] = 4 diameters), integer `k`. A node at level `l`
//! covers `2^l x 2^l (x ...)` leaf cells; leaves are level 0, the root has level >= 1. All leaves
//! sit at level 0 (the paper's `ISLEAF`: "the node is at the last level"), so the depth is
//! `log2(root side / s)` and no leaf ever splits.
//!
//! - **Root growth.** The first point gets a root of level 1 (2 x 2 leaf cells) whose centre is
//!   the leaf-cell corner nearest to it. A point outside the root makes the root grow by
//!   doubling: a new root of twice the side is created with the old root as one of its children,
//!   on the side of the new point along each axis where the point is outside, and on the side
//!   that keeps the root centred on the first point along the other axes. Leaf cells never move,
//!   so the stored (decoded) position of a point does not depend on insertion order or growth.
//! - **Nodes.** One flat array of `u32` with `2^D` child slots per internal node (16 bytes per node
//!   in 2D, 32 in 3D): a child is a node index, or a leaf index for level-1 nodes, or `u32::MAX`
//!   when empty. Nodes exist only on the paths to stored points, so every node holds at least one
//!   point (the error bound below relies on this).
//! - **Leaves.** One array of 8-byte records: the start and length of the leaf's block in the
//!   pool, in one word.
//! - **Points.** One pool of `[u32; D]` records: each coordinate is a fixed-point offset inside
//!   the leaf cell, in units of `s / 2^32` (the variable-precision paper, section 3.3, stores
//!   relative coordinates in one byte; that is far too coarse for contact within 1e-6, 32 bits
//!   give `s / 2^33`, about 5e-10 for `s = 4`). A leaf's points are contiguous; blocks come in size classes with free
//!   lists (exact sizes up to 16 points, see `pool.rs`), so small leaves waste nothing. When
//!   more than 1/8 of the pool sits on free lists (leaves that all grow at once, e.g. uniform
//!   points inserted in random order), an insert compacts the pool in place: O(N) at that
//!   insert, amortised O(leaf size) per insert. DLA growth, which keeps creating leaves at the
//!   front, reuses the free blocks and practically never compacts.
//! - **Growth of the arrays** is capped at 1/8 of their capacity, not doubled, so the heap slack
//!   counted by [`Orthtree::memory_bytes`] stays near 12 %. Large arrays grow by `realloc`,
//!   which remaps pages instead of copying, so growing never holds two copies.
//!
//! Memory (2D): 8 bytes per point record plus the node and leaf records and the capped slack,
//! about 12 bytes per point with the default leaf side (`examples/orthtree_memory.rs` measures
//! it; `docs/spatial.md` has the table). Positions are restored to within `s / 2^33` per
//! coordinate (4.7e-10 for the default), far inside the 1e-6 that DLA contact needs, plus the
//! rounding of `f64` at the coordinate's magnitude.
//!
//! # Choosing the leaf side
//!
//! The leaf side `s` trades memory against query work: a larger `s` means fewer nodes and leaf
//! records (less memory, a shallower tree) but more points scanned per visited leaf (and a
//! larger exact region of `vpdist`, `(kappa - 1/2)` leaf diagonals); a smaller `s` means more
//! nodes per point. For unit-diameter particles `s = 4` holds 4 to 5 DLA particles per leaf and
//! keeps the structure near 12 bytes per point in 2D; `s = 8` (about 12 particles per leaf)
//! needs less memory and is one level shallower, so it is worth benchmarking for large clusters;
//! `s = 2` costs more memory than it saves work (`docs/spatial.md` has the measured trade-off).
//! Accepted: powers of two from [`MIN_LEAF_SIDE`] to [`MAX_LEAF_SIDE`] (powers of two make every
//! cell corner, centre and decoded position an exact binary fraction, so the geometry used by
//! the queries is exact).
//!
//! # Queries and complexity
//!
//! `h = log2(root side / s)` is the depth (about `log2(2 R / s)` for a cluster of radius `R`).
//!
//! | operation | cost |
//! |---|---|
//! | [`insert`](Orthtree::insert) | O(h + points in the leaf) (a leaf's block is copied when it grows) |
//! | [`nearest`](Orthtree::nearest), [`nearest_distance`](Orthtree::nearest_distance) | branch and bound: O(h) plus the nodes whose box is closer than the answer |
//! | [`vpdist`](Orthtree::vpdist) | O(h) nodes times a constant depending on `kappa` and `D` only (the variable-precision paper, Listing 1) |
//! | [`for_each_within`](Orthtree::for_each_within), [`range_into`](Orthtree::range_into) | O(h + nodes meeting the ball + the points of their leaves) |
//! | [`iter`](Orthtree::iter) | O(N + nodes) |
//!
//! Queries take `&self` and never allocate (except [`iter`](Orthtree::iter), which keeps an
//! O(h) stack); [`insert`](Orthtree::insert) takes `&mut self`.
//!
//! # One writer, many readers
//!
//! PDLA's walkers share one tree (the variable-precision paper, section 3.4) instead of a copy
//! per thread: between [`prepare_shared`](Orthtree::prepare_shared) and
//! [`finish_shared`](Orthtree::finish_shared), [`insert_shared`](Orthtree::insert_shared)
//! stores a point through `&self` while other threads query, without a lock on the query side.
//!
//! - The arrays never move during sharing: `prepare_shared` reserves their room for the phase
//!   (address space; pages are only touched as they are used) and grows the root over the
//!   region the points will reach. A point that needs more is refused with
//!   [`OrthtreeError::NeedsExclusive`] and nothing changes.
//! - An insert builds the missing nodes, leaf and point below the first empty slot of its path,
//!   then links them with one `Release` store; child slots and leaf records are atomics read
//!   with `Acquire` (plain loads on x86), so a query sees the tree before or after an insert,
//!   never a node without a point.
//! - A leaf that outgrows its block moves to a larger one; the old block may still be scanned,
//!   so it is *retired* with the current epoch and reused only once every reader has announced
//!   a later [`epoch`](Orthtree::epoch) (epoch-based reclamation; a walker announces at birth).
//! - Compaction never runs while shared.
//! - Soundness rests on the readers' side of that protocol: `insert_shared` (an `unsafe fn`)
//!   trusts its
//!   `readers_epoch` to answer no more than the smallest epoch announced by a thread still
//!   reading, and readers announce only while they hold nothing from the tree (see
//!   [`insert_shared`](Orthtree::insert_shared)). `tests/loom_shared.rs` model-checks the
//!   protocol with loom on this code (`docs/spatial.md` has the command); `arena.rs` describes
//!   the `unsafe fn`s and their contracts.
//!
//! # Variable-precision distance and its error bound
//!
//! [`vpdist`](Orthtree::vpdist) is Listing 1 of the variable-precision paper in `D` dimensions with
//! the precision `kappa` as a parameter (the paper uses `kappa = 2`). Starting from the root, for
//! each node `n` with centre `c` and half diagonal `r` (`DIAGONAL = 2 r`):
//!
//! 1. if `|p - c| > kappa * 2 r` (the node is *far*), the node contributes the lower bound
//!    `|p - c| - r` and is not descended (lines 07-11);
//! 2. else if `n` is a leaf, its points contribute their exact distances (lines 13-19);
//! 3. else the children are visited, the one containing `p` first, skipping every child whose
//!    box does not meet the ball of radius "best so far" around `p` (lines 21-33).
//!
//! The answer `v` is the smallest contribution. Let `d` be the exact nearest distance.
//!
//! - **Never too large: `v <= d`.** Every point lies within `r` of the centre of each node
//!   containing it, so `|p - c| - r` is at most its distance; a skipped child's points are all
//!   farther than the best value already found. This holds for every `kappa`.
//! - **Absolute gap (the paper's `d in [d_app, d_app + 2r]`).** If `v < d`, then `v` was produced
//!   by a far node `eta` of half diagonal `r_eta`: `v = |p - c_eta| - r_eta`. The node holds at
//!   least one point, at distance at most `|p - c_eta| + r_eta`, so `d <= v + 2 r_eta`: the gap
//!   is at most the diagonal of the node that produced `v`. [`Orthtree::vpdist_detailed`]
//!   reports `r_eta`.
//! - **Relative gap.** `eta` was far: `|p - c_eta| > 2 kappa r_eta`, so `v > (2 kappa - 1) r_eta`
//!   and `d <= v + 2 r_eta < v (2 kappa + 1) / (2 kappa - 1)`. Hence, for `kappa > 1/2`,
//!
//!   `v > d (2 kappa - 1) / (2 kappa + 1)`, i.e. `(d - v) / d < 2 / (2 kappa + 1)`:
//!
//!   at most 2/3 of `d` for `kappa = 1`, **0.4 for `kappa = 2`** (the paper's "+0.4 d(p,q)"),
//!   2/9 for `kappa = 4`, and 0 for `kappa = inf` (the exact search). The bound is attained in
//!   the limit (a lone point in the far corner of a leaf seen along its diagonal from just beyond
//!   `2 kappa r`), so it cannot be improved.
//! - **Exact near the cluster.** If `d <= (2 kappa - 1) r_leaf = (kappa - 1/2) DIAGONAL(leaf)`,
//!   then `v = d`: every far node gives more than `(2 kappa - 1) r >= (2 kappa - 1) r_leaf`.
//!   For `kappa = 2` and `s = 4` this is 1.5 leaf diagonals, 8.49 diameters. The paper states
//!   exactness for `d(p, q) < 2 d_g` (2 leaf diagonals) or when `p` is closer than `2 d_g` to the
//!   centre of `q`'s leaf; neither is sufficient (another far leaf next to `p` can undercut `d`,
//!   see the unit test `paper_exactness_radius_is_not_sufficient`), while
//!   `(kappa - 1/2) d_g` is sufficient and tight.
//!
//! Floating point: distances to stored points are computed exactly as a brute-force loop over
//! [`iter`](Orthtree::iter) would (same operations, same order), child boxes are skipped using
//! face coordinates that are exact, and far-node bounds are shrunk by a relative `2^-44`, so
//! `v <= d` holds in floating point against that brute force, and the exact queries return its
//! value bit for bit.
//!
//! # Example
//!
//! ```
//! use spatial::orthtree::Orthtree;
//!
//! let mut tree = Orthtree::<2>::new();
//! tree.insert([0.0, 0.0])?;
//! tree.insert([1.0, 0.0])?;
//! assert_eq!(tree.nearest_distance(&[4.0, 0.0]), Some(3.0));
//! let v = tree.vpdist(&[100.0, 0.0], 2.0).unwrap();
//! assert!(v <= 99.0 && v > 99.0 * 3.0 / 5.0);
//! # Ok::<(), spatial::orthtree::OrthtreeError>(())
//! ```

// `unsafe_code` is allowed in the orthtree's modules only: `arena` holds the raw buffers (the
// only unsafe operations), the others call its `unsafe fn`s and their own, each call with a
// `// SAFETY:` note (see `arena.rs`, "The unsafe boundary").
mod arena;
mod error;
#[allow(unsafe_code)]
mod insert;
#[allow(unsafe_code)]
mod iter;
#[allow(unsafe_code)]
mod pool;
#[allow(unsafe_code)]
mod query;
mod sync;
#[cfg(test)]
#[allow(unsafe_code)]
mod tests;

use arena::Arena;
use pool::LeafPool;
use std::fmt;
use std::sync::{Mutex, MutexGuard};
use sync::{AtomicU32, AtomicU64, AtomicUsize, Ordering};

pub use error::OrthtreeError;
pub use iter::Points;
pub use query::{Neighbour, RangeSink, VpEstimate, dist_sq};

/// The orthtree's default leaf side `s`, in particle diameters: the side of the leaf cells
/// (the last level of the tree, where the variable-precision paper, section 3.3, keeps its chunks
/// of particles) that [`Orthtree::new`] uses. With `s = 4`, a leaf holds 4 to 5 DLA particles. A
/// model may choose another side through [`Orthtree::with_leaf_side`]; see the module docs for the
/// trade-off.
pub const DEFAULT_LEAF_SIDE: f64 = 4.0;

/// Smallest accepted leaf side, `2^-20`.
pub const MIN_LEAF_SIDE: f64 = 1.0 / 1_048_576.0;

/// Largest accepted leaf side, `2^11`: fixed-point offsets of `s / 2^32` then still restore
/// positions to within `2^-22`, about 2.4e-7 per coordinate.
pub const MAX_LEAF_SIDE: f64 = 2048.0;

/// Coordinates must satisfy `|x| < COORD_LIMIT_LEAVES * leaf_side` (`2^50` leaf sides, 4.5e15
/// diameters for the default), so that all cell geometry is exact in `f64`.
pub const COORD_LIMIT_LEAVES: f64 = 1_125_899_906_842_624.0;

/// The precision used in the paper (Listing 1, line 07: `DIAGONAL(node) * 2`).
pub const PAPER_KAPPA: f64 = 2.0;

/// Empty child slot.
const EMPTY: u32 = u32::MAX;

/// Whether `s` is an accepted leaf side: a power of two in [`MIN_LEAF_SIDE`,
/// `MAX_LEAF_SIDE`] (a normal `f64` with a zero mantissa). `const`, so the default is checked
/// at compile time.
const fn is_valid_leaf_side(s: f64) -> bool {
    let power_of_two = s.is_normal() && s > 0.0 && s.to_bits() & ((1u64 << 52) - 1) == 0;
    power_of_two && MIN_LEAF_SIDE <= s && s <= MAX_LEAF_SIDE
}

/// Largest number of internal nodes or leaves (indices are `u32`, `u32::MAX` is reserved).
const MAX_INDEX: u64 = u32::MAX as u64 - 1;

/// `2^32`: fixed-point offsets per leaf side.
const CODE_SCALE: f64 = 4_294_967_296.0;

/// A leaf's block in the point pool.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Leaf {
    /// First slot of the block.
    start: u32,
    /// Number of points stored.
    len: u32,
}

impl Leaf {
    /// The record as one word (stored in an `AtomicU64`, so a reader sees a block and its
    /// length from the same update).
    #[inline(always)]
    fn pack(self) -> u64 {
        u64::from(self.start) | u64::from(self.len) << 32
    }

    #[inline(always)]
    fn unpack(word: u64) -> Self {
        Leaf {
            start: word as u32,
            len: (word >> 32) as u32,
        }
    }
}

/// What only the tree's writer changes: the element counts of the arenas and the pool's
/// allocator. Behind a mutex, so that a shared insert has the same exclusive view as an
/// `&mut` one.
#[derive(Debug, Clone)]
struct Writer {
    /// Internal nodes in use.
    nodes: usize,
    /// Leaf records in use.
    leaves: usize,
    /// The point pool's allocator.
    pool: LeafPool,
    /// At least the length of every leaf (the longest leaf a push made): bounds what any
    /// insert may append to the pool without finding its leaf first.
    longest_leaf: u32,
    /// Shared inserts since the epoch was last advanced.
    since_epoch: u32,
    /// The smallest epoch the readers had announced when last asked, and the tree's epoch
    /// then (see [`Orthtree::insert_shared`]); reset for each phase of shared inserts.
    readers_known: u64,
    readers_asked_at: u64,
}

/// State the writer changes and readers may look at, in its own allocation so that updating
/// it never touches a cache line the queries read.
#[derive(Debug)]
struct Shared {
    writer: Mutex<Writer>,
    /// Number of stored points.
    len: AtomicUsize,
    /// Reclamation epoch of shared inserts (see [`Orthtree::insert_shared`]), on a cache line
    /// of its own: readers load it at every announcement, and `len` beside it changes at
    /// every insert.
    epoch: OwnLine<AtomicU64>,
}

/// A value alone on its cache lines (128 bytes: two lines, for adjacent-line prefetchers).
#[derive(Debug)]
#[repr(align(128))]
struct OwnLine<T>(T);

impl<T> std::ops::Deref for OwnLine<T> {
    type Target = T;
    fn deref(&self) -> &T {
        &self.0
    }
}

/// Shared inserts between two advances of the reclamation epoch (1 in the model-checked
/// build, so that a tiny loom test reaches block reuse).
const EPOCH_INSERTS: u32 = if cfg!(loom) { 1 } else { 64 };

/// Quadtree (`D = 2`), octree (`D = 3`) or `2^D`-ary tree of points with exact nearest-distance
/// and variable-precision distance queries (the variable-precision paper, sections 3.1 and 3.3,
/// Listing 1).
///
/// See the [module documentation](self) for the layout, the complexity and the error bound of
/// [`vpdist`](Self::vpdist). `D` must be in `1..=8`.
pub struct Orthtree<const D: usize> {
    /// Leaf side `s` (a power of two).
    leaf_side: f64,
    /// `s / 2^32`: the unit of the fixed-point offsets.
    step: f64,
    /// `sqrt(D)` rounded up, so half diagonals `half_side * sqrt_d_up` are never too small.
    sqrt_d_up: f64,
    /// Root node index, `EMPTY` while the tree is empty.
    root: u32,
    /// Level of the root (>= 1); its side is `2^root_level` leaf sides.
    root_level: u32,
    /// Lower corner of the root, in leaf sides.
    root_origin: [i64; D],
    /// Centre of the first root, in leaf sides: growth keeps the root centred on it.
    anchor: [i64; D],
    /// `2^D` child slots per internal node (a node, a leaf, or `EMPTY`).
    children: Arena<AtomicU32>,
    /// Leaf records ([`Leaf::pack`]).
    leaves: Arena<AtomicU64>,
    /// Point records of all leaves (blocks carved by the writer's [`LeafPool`]).
    slots: Arena<[u32; D]>,
    /// A tag per point slot, beside `slots` and of its capacity, when the tree keeps tags
    /// ([`Orthtree::keep_tags`]); read and written by the writer only.
    tags: Option<Arena<u32>>,
    /// Counts, allocator and epoch.
    shared: Box<Shared>,
    /// Largest number of nodes, leaves or point slots ([`MAX_INDEX`] unless lowered by
    /// [`Orthtree::set_index_limit`]).
    index_limit: u64,
}

/// Counts describing an [`Orthtree`]'s shape and memory, for diagnostics and benchmarks (the
/// variable-precision paper, section 3.3, reports bytes per particle).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OrthtreeStats {
    /// Stored points.
    pub points: usize,
    /// Internal nodes (including the root).
    pub nodes: usize,
    /// Leaves (non-empty leaf cells).
    pub leaves: usize,
    /// Levels below the root: the root side is `2^depth` leaf sides.
    pub depth: u32,
    /// Point slots allocated in the pool, used or on a free list.
    pub point_slots: usize,
    /// Point slots on the free lists.
    pub free_slots: usize,
    /// Same as [`Orthtree::memory_bytes`].
    pub memory_bytes: usize,
}

impl<const D: usize> Default for Orthtree<D> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const D: usize> fmt::Debug for Orthtree<D> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Orthtree")
            .field("dim", &D)
            .field("leaf_side", &self.leaf_side)
            .field("len", &self.len())
            .field("root_level", &self.root_level)
            .field("root_origin", &self.root_origin)
            .field("nodes", &self.node_count())
            .field("leaves", &self.leaf_count())
            .finish()
    }
}

impl<const D: usize> Clone for Orthtree<D> {
    #[allow(unsafe_code)]
    fn clone(&self) -> Self {
        // The writer's lock is held until the arenas are copied: a shared insert running
        // meanwhile would write point slots inside the copied prefix (appends, reused blocks).
        let guard = self.writer();
        let w = &*guard;
        // SAFETY: the writer's counts, read under its lock, are the initialised prefixes of
        // the arenas (nodes, leaf records, pool slots), and the lock held keeps a shared writer
        // from writing any of them meanwhile (readers only read).
        let (children, leaves, slots, tags) = unsafe {
            (
                self.children
                    .duplicate(w.nodes * Self::FANOUT, self.children.capacity()),
                self.leaves.duplicate(w.leaves, self.leaves.capacity()),
                self.slots.duplicate(w.pool.len, self.slots.capacity()),
                self.tags
                    .as_ref()
                    .map(|t| t.duplicate(w.pool.len, t.capacity())),
            )
        };
        let shared = Box::new(Shared {
            writer: Mutex::new(w.clone()),
            len: AtomicUsize::new(self.len()),
            epoch: OwnLine(AtomicU64::new(self.shared.epoch.load(Ordering::Acquire))),
        });
        drop(guard);
        Self {
            leaf_side: self.leaf_side,
            step: self.step,
            sqrt_d_up: self.sqrt_d_up,
            root: self.root,
            root_level: self.root_level,
            root_origin: self.root_origin,
            anchor: self.anchor,
            children,
            leaves,
            slots,
            tags,
            shared,
            index_limit: self.index_limit,
        }
    }
}

impl<const D: usize> Orthtree<D> {
    /// Children per internal node.
    const FANOUT: usize = 1 << D;

    /// An empty tree with the default leaf side [`DEFAULT_LEAF_SIDE`] (the variable-precision
    /// paper, section 3.3).
    pub fn new() -> Self {
        const { assert!(is_valid_leaf_side(DEFAULT_LEAF_SIDE)) };
        Self::empty(DEFAULT_LEAF_SIDE)
    }

    /// An empty tree whose leaf cells have side `leaf_side` (a power of two in
    /// [`MIN_LEAF_SIDE`, `MAX_LEAF_SIDE`], in particle diameters). See the module docs for the
    /// trade-off (the variable-precision paper, section 3.3).
    pub fn with_leaf_side(leaf_side: f64) -> Result<Self, OrthtreeError> {
        if !is_valid_leaf_side(leaf_side) {
            return Err(OrthtreeError::InvalidLeafSide(leaf_side));
        }
        Ok(Self::empty(leaf_side))
    }

    /// An empty tree with a leaf side already checked by [`is_valid_leaf_side`].
    fn empty(leaf_side: f64) -> Self {
        const { assert!(D >= 1 && D <= 8, "Orthtree supports 1 to 8 dimensions") };
        Self {
            leaf_side,
            step: leaf_side / CODE_SCALE,
            sqrt_d_up: (D as f64).sqrt() * (1.0 + f64::EPSILON * 4.0),
            root: EMPTY,
            root_level: 1,
            root_origin: [0; D],
            anchor: [0; D],
            children: Arena::new(),
            leaves: Arena::new(),
            slots: Arena::new(),
            tags: None,
            shared: Box::new(Shared {
                writer: Mutex::new(Writer {
                    nodes: 0,
                    leaves: 0,
                    pool: LeafPool::new(),
                    longest_leaf: 0,
                    since_epoch: 0,
                    readers_known: 0,
                    readers_asked_at: 0,
                }),
                len: AtomicUsize::new(0),
                epoch: OwnLine(AtomicU64::new(1)),
            }),
            index_limit: MAX_INDEX,
        }
    }

    /// Checks a precision parameter for [`vpdist`](Self::vpdist) (the variable-precision paper,
    /// Listing 1, line 07): `kappa > 1/2` (finite) or `+inf`. Use it when validating run
    /// parameters; `vpdist` itself accepts any value.
    pub fn check_kappa(kappa: f64) -> Result<f64, OrthtreeError> {
        if kappa > 0.5 {
            Ok(kappa)
        } else {
            Err(OrthtreeError::InvalidKappa(kappa))
        }
    }

    /// Number of stored points.
    pub fn len(&self) -> usize {
        self.shared.len.load(Ordering::Relaxed)
    }

    /// Whether no point is stored.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The writer's state (locked: held only for an insert or to read counts).
    fn writer(&self) -> MutexGuard<'_, Writer> {
        self.shared
            .writer
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// The writer's state with exclusive access to the tree (no lock taken).
    fn writer_mut(shared: &mut Shared) -> &mut Writer {
        shared
            .writer
            .get_mut()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Child slot `i` (a reader's view: `Acquire`, so a node, leaf or point reached through
    /// it is initialised).
    ///
    /// # Safety
    ///
    /// `i` is `n * FANOUT + c` with `c < FANOUT` and `n` a *reached* node: the root, or a
    /// non-empty value read (by this function, or by the writer) from a child slot of a
    /// reached node of level `>= 2`.
    #[inline(always)]
    #[allow(unsafe_code)]
    unsafe fn child(&self, i: usize) -> u32 {
        // SAFETY: node n's slots were initialised by `new_node` before n was linked with a
        // `Release` store that the load which reached n read with `Acquire` (or on this
        // thread); child slots are never re-initialised while reachable.
        unsafe { self.children.get(i) }.load(Ordering::Acquire)
    }

    /// Leaf record `i` (`Acquire`, so the points of its block are written).
    ///
    /// # Safety
    ///
    /// `i` is a *reached* leaf: a non-empty value read from a child slot of a reached
    /// level-1 node (see [`child`](Self::child)).
    #[inline(always)]
    #[allow(unsafe_code)]
    unsafe fn leaf(&self, i: u32) -> Leaf {
        // SAFETY: leaf i's record was initialised before the `Release` store linking it, which
        // the caller's `Acquire` load of the child slot read; reachable records are only
        // stored into, never re-initialised.
        Leaf::unpack(unsafe { self.leaves.get(i as usize) }.load(Ordering::Acquire))
    }

    /// The stored point records of leaf `i`.
    ///
    /// # Safety
    ///
    /// As for [`leaf`](Self::leaf); besides, a thread reading the tree while a shared writer
    /// inserts announces an epoch only when it holds no slice from here (see
    /// [`insert_shared`](Self::insert_shared)), so the block is not reused while the slice
    /// lives.
    #[inline(always)]
    #[allow(unsafe_code)]
    unsafe fn leaf_points(&self, i: u32) -> &[[u32; D]] {
        // SAFETY: `i` is a reached leaf (the caller's contract), and the record is loaded with
        // `Acquire`, so it is a published record of this tree's pool whose block stays
        // unwritten while the slice lives.
        unsafe { LeafPool::points(&self.slots, self.leaf(i)) }
    }

    /// Side of the leaf cells (the variable-precision paper, section 3.1: the last level of the
    /// tree).
    pub fn leaf_side(&self) -> f64 {
        self.leaf_side
    }

    /// The root cell as `(lower corner, side)`, or `None` while the tree is empty.
    pub fn root_cell(&self) -> Option<([f64; D], f64)> {
        if self.root == EMPTY {
            return None;
        }
        let corner = self.root_origin.map(|o| o as f64 * self.leaf_side);
        Some((corner, self.leaf_side * (1u64 << self.root_level) as f64))
    }

    /// Number of internal nodes.
    pub fn node_count(&self) -> usize {
        self.writer().nodes
    }

    /// Number of leaves (non-empty leaf cells).
    pub fn leaf_count(&self) -> usize {
        self.writer().leaves
    }

    /// Lowers the number of nodes, leaves and point slots the tree may use to `limit` (capped at
    /// the 32-bit maximum, `2^32 - 2`), so that the capacity error can be met in a test without
    /// billions of points. Inserts that would pass it fail with
    /// [`OrthtreeError::CapacityExceeded`] and leave the tree unchanged.
    pub fn set_index_limit(&mut self, limit: u64) {
        self.index_limit = limit.min(MAX_INDEX);
    }

    /// Heap and inline bytes of the structure: the capacities (not lengths) of the node, leaf
    /// and point vectors, free blocks included, plus `size_of::<Self>()` (the variable-precision
    /// paper, section 3.3 reports memory per particle).
    pub fn memory_bytes(&self) -> usize {
        size_of::<Self>()
            + size_of::<Shared>()
            + self.children.capacity() * size_of::<u32>()
            + self.leaves.capacity() * size_of::<u64>()
            + self.slots.capacity() * size_of::<[u32; D]>()
            + self
                .tags
                .as_ref()
                .map_or(0, |t| t.capacity() * size_of::<u32>())
    }

    /// Shape and memory counts.
    pub fn stats(&self) -> OrthtreeStats {
        let w = self.writer();
        OrthtreeStats {
            points: self.len(),
            nodes: w.nodes,
            leaves: w.leaves,
            depth: if self.root == EMPTY {
                0
            } else {
                self.root_level
            },
            point_slots: w.pool.len,
            free_slots: w.pool.free_slots(),
            memory_bytes: self.memory_bytes(),
        }
    }

    /// Child slot index of leaf cell `k` inside the node at `level` on its path (bits of
    /// `k - root_origin` at `level - 1`).
    #[inline]
    fn child_index(&self, k: &[i64; D], level: u32) -> usize {
        let mut ci = 0;
        for i in 0..D {
            let rel = (k[i] - self.root_origin[i]) as u64;
            ci |= (((rel >> (level - 1)) & 1) as usize) << i;
        }
        ci
    }
}

/// Stored position of a fixed-point offset: the single formula used everywhere, so that every
/// query and [`Orthtree::iter`] see bit-identical coordinates.
#[inline(always)]
fn decode(origin: f64, code: u32, step: f64) -> f64 {
    origin + f64::from(code) * step
}
