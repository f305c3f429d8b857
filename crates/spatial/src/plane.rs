//! Grid boxes hashed over the unbounded 2D integer plane, for the animat model.
//!
//! This module serves Hawick, James & Scogings, *Grid-Boxing for Spatial Simulation Performance
//! Optimisation* (seed 000): the animat predator-prey model of section II.B lives on an unbounded
//! plane, every animat needs its nearest neighbours of each species and a count of the animats
//! around it, and section IV.B (Fig. 9, Table I) compares grid boxes of side 60, 120 and 240
//! against the exhaustive "no grid" search. [`PlaneGrid`] offers both: boxes of any positive side
//! `A` ([`BoxSize::Side`]) and the exhaustive baseline ([`BoxSize::None`]). Both give exactly the
//! same answers; only the amount of work differs, which the work counters
//! ([`PlaneGrid::distance_evals`], [`PlaneGrid::stats`]) measure.
//!
//! # Layout
//!
//! - **Boxes**: `FxHashMap<[i64; 2], Vec<Entry>>` keyed by box coordinates
//!   `(x.div_euclid(A), y.div_euclid(A))` (floor division, so `x = -1` is in box `-1`, not `0`).
//!   Only non-empty boxes are stored, so the plane is unbounded and memory follows the items, not
//!   the area they roam (the paper's Fig. 1 grid, without its bounds). Each entry holds the item's
//!   id, position and kind inline, so scanning a box touches one contiguous slice. In
//!   [`BoxSize::None`] mode every item lives in one list (key `[0, 0]`): the paper's single list.
//! - **Slots**: `FxHashMap<u64, Slot>` from id to position, kind and index inside its box's
//!   vector (a back-index), so removal is a `swap_remove` plus one back-index fix.
//! - **Cells**: `FxHashMap<[i64; 2], u32>` counting the items on each cell, so "is this cell
//!   free" ([`PlaneGrid::is_occupied`]) is one hash lookup in every mode.
//! - **Counters**: [`AtomicU64`]s of distance evaluations, items scanned and boxes probed
//!   ([`SearchStats`]).
//!
//! # Complexity (N items, expected-time hashing)
//!
//! | operation | cost |
//! |---|---|
//! | [`insert`](PlaneGrid::insert), [`remove`](PlaneGrid::remove) | O(1) |
//! | [`move_to`](PlaneGrid::move_to) | O(1); the box map changes structure only when the box changes |
//! | [`get`](PlaneGrid::get), [`is_occupied`](PlaneGrid::is_occupied) | O(1) |
//! | [`items_at`](PlaneGrid::items_at) | O(1) if the cell is free, else O(items in its box) (O(N) in `None` mode) |
//! | [`nearest`](PlaneGrid::nearest) | O(boxes in the rings visited + items in the boxes that can hold an answer) |
//! | [`count_within`](PlaneGrid::count_within), [`any_within`](PlaneGrid::any_within) | O(boxes within the radius + their items), less with a cap / at the first hit |
//! | any query in `None` mode | O(N) (the "no grid" line of Fig. 9), with early stops for caps and `any` |
//!
//! With the radius `r` no larger than `A`, a query visits at most the 3 x 3 halo of boxes
//! (Fig. 1); with `A` much smaller than `r` it visits about `(2r/A)^2` boxes. When the rings left
//! to search would need more hash lookups than there are occupied boxes (a query far from every
//! item, or a huge radius), the search switches to one pass over the occupied boxes instead, so
//! no query costs more than O(occupied boxes + N).
//!
//! # Why the answers are exact
//!
//! All distances are squared Euclidean distances computed in integers: `|dx|` and `|dy|` come
//! from [`i64::abs_diff`] (exact for the whole `i64` range), each is first compared with
//! `isqrt(limit)` (the per-axis early exit of section II.A, `|dx| > isqrt(limit)` exactly when
//! `dx^2 > limit`), and only then is `dx^2 + dy^2` formed; it cannot overflow because both terms
//! are at most `limit <= u64::MAX` and the sum is computed with `checked_add` (an overflowing sum
//! exceeds every `u64` radius). **Supported range: every `[i64; 2]` position and every `u64`
//! squared radius**; box geometry is computed in `i128`.
//!
//! Let `p` lie in box `(bx, by)` at offset `(ox, oy)` inside it (`0 <= ox, oy < A`). Ring `k` is
//! the set of boxes at Chebyshev box-distance `k` from `(bx, by)`. Every cell of ring `k >= 1`
//! is at least `(k - 1) A + e` cells away along some axis, where
//! `e = min(ox + 1, A - ox, oy + 1, A - oy)`, so every item there is at Euclidean distance at
//! least that. [`nearest`](PlaneGrid::nearest) stops before ring `k` only when this bound
//! squared is **strictly** greater than the current limit (the radius, or the best distance
//! found so far), and skips a box only when its exact minimum distance to `p` is strictly
//! greater than the limit. Hence every item with distance `<= limit` is examined, and the answer
//! is the minimum of the total order `(dist2, id)` over all qualifying items: equally near items
//! are resolved by the lower id, independently of hash-map order, insertion order or box size.
//! Counts and existence tests visit every box that can hold an item within the radius, so they
//! are exact too, and they stop early only once their answer is known.
//!
//! # Work counters
//!
//! [`PlaneGrid::distance_evals`] counts full squared-distance evaluations against candidate
//! items (after the kind, exclusion and per-axis tests pass). Both modes apply the same per-item
//! test, so the counts compare like with like. Because the per-axis early exit rejects most
//! far items before a full evaluation, this count is small in both modes; the cost of the
//! exhaustive scan shows in [`SearchStats::items_scanned`] (N per query without boxes, the
//! halo's items with them) and [`SearchStats::boxes_probed`]: together they are the work
//! measure behind Fig. 9 and Table I.
//!
//! The counters are [`AtomicU64`]s updated with `Relaxed` ordering once per query (each query
//! tallies into local variables first). Queries take `&self`; atomics keep [`PlaneGrid`]
//! `Sync`, so read-only queries may run on several threads at once (a `Cell` would forbid
//! that). `Relaxed` suffices because the counters synchronise nothing else, and three atomic
//! adds per query cost nothing measurable next to the hash lookups.

use std::collections::hash_map::Entry as MapEntry;
use std::fmt;
use std::ops::ControlFlow;
use std::str::FromStr;
use std::sync::atomic::{AtomicU64, Ordering};

use rustc_hash::FxHashMap;

/// A cell of the unbounded integer plane, `[x, y]` (seed 000, section II.B: animats live on an
/// unbounded plane, one per cell).
pub type Pos = [i64; 2];

/// Most spare box vectors kept for reuse, so boxes that empty and fill again (an animat walking
/// back and forth across a box boundary) do not allocate every time.
const SPARE_MAX: usize = 256;

/// Grid-box size of a [`PlaneGrid`] (seed 000, sections II.B and IV.B: grids of 60, 120 and 240
/// cells, or no grid at all).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BoxSize {
    /// No grid boxes: every query is an exhaustive scan over all items, the paper's "no grid"
    /// baseline of Fig. 9 and Table I.
    None,
    /// Square grid boxes of side `A` cells; `A` must be positive (checked by
    /// [`PlaneGrid::new`]). The paper's default is the vision radius, 60.
    Side(i64),
}

impl BoxSize {
    /// The box side, or `None` for the exhaustive mode.
    pub fn side(self) -> Option<i64> {
        match self {
            BoxSize::None => None,
            BoxSize::Side(a) => Some(a),
        }
    }

    /// Checks that a [`BoxSize::Side`] is positive.
    ///
    /// # Errors
    /// [`PlaneError::BadBoxSide`] if the side is zero or negative.
    pub fn validate(self) -> Result<Self, PlaneError> {
        match self {
            BoxSize::Side(a) if a <= 0 => Err(PlaneError::BadBoxSide(a)),
            other => Ok(other),
        }
    }
}

impl fmt::Display for BoxSize {
    /// `none` or the side as a decimal integer, the syntax [`BoxSize::from_str`] accepts (the
    /// `--grid-box` flag of the animat binary).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BoxSize::None => f.write_str("none"),
            BoxSize::Side(a) => write!(f, "{a}"),
        }
    }
}

impl FromStr for BoxSize {
    type Err = PlaneError;

    /// Parses `none` (any case) or a positive integer side, as given to `--grid-box`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim();
        if t.eq_ignore_ascii_case("none") {
            return Ok(BoxSize::None);
        }
        match t.parse::<i64>() {
            Ok(a) => BoxSize::Side(a).validate(),
            Err(_) => Err(PlaneError::ParseBoxSize(s.to_string())),
        }
    }
}

/// Errors of [`PlaneGrid`] operations on bad input (never panics).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PlaneError {
    /// A grid-box side that is zero or negative.
    #[error("grid box side must be a positive integer (1..={max}), got {0}", max = i64::MAX)]
    BadBoxSide(i64),
    /// A grid-box size string that is neither `none` nor an integer.
    #[error("invalid grid box size {0:?}: expected `none` or a positive integer")]
    ParseBoxSize(String),
    /// Inserting an id that is already present.
    #[error("item id {0} is already present")]
    DuplicateId(u64),
    /// Removing or moving an id that is not present.
    #[error("unknown item id {0}")]
    UnknownId(u64),
}

/// Work done by the queries of a [`PlaneGrid`], for the scaling study of seed 000, section IV.B
/// (Fig. 9, Table I): what the grid boxes save compared with the exhaustive scan.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct SearchStats {
    /// Full squared-distance evaluations against candidate items: items of the wanted kind, not
    /// excluded, that passed the per-axis early exit (`|dx|` and `|dy|` within the radius).
    pub distance_evals: u64,
    /// Items looked at (kind, exclusion and per-axis tests): every item of every box a query
    /// scanned, up to the point where it stopped. In [`BoxSize::None`] mode this is N per query
    /// (less for capped counts and `any_within`); with boxes, the items of the halo.
    pub items_scanned: u64,
    /// Box-map lookups and box visits: hash lookups of ring boxes (only for boxes that can hold
    /// an answer) plus occupied boxes examined by the one-pass fallback; 1 per query in
    /// [`BoxSize::None`] mode.
    pub boxes_probed: u64,
}

/// The atomic counters behind [`SearchStats`]; one `Relaxed` add per counter per query.
#[derive(Debug, Default)]
struct Counters {
    distance_evals: AtomicU64,
    items_scanned: AtomicU64,
    boxes_probed: AtomicU64,
}

impl From<SearchStats> for Counters {
    fn from(s: SearchStats) -> Self {
        Counters {
            distance_evals: AtomicU64::new(s.distance_evals),
            items_scanned: AtomicU64::new(s.items_scanned),
            boxes_probed: AtomicU64::new(s.boxes_probed),
        }
    }
}

impl Counters {
    fn load(&self) -> SearchStats {
        SearchStats {
            distance_evals: self.distance_evals.load(Ordering::Relaxed),
            items_scanned: self.items_scanned.load(Ordering::Relaxed),
            boxes_probed: self.boxes_probed.load(Ordering::Relaxed),
        }
    }

    fn take(&self) -> SearchStats {
        SearchStats {
            distance_evals: self.distance_evals.swap(0, Ordering::Relaxed),
            items_scanned: self.items_scanned.swap(0, Ordering::Relaxed),
            boxes_probed: self.boxes_probed.swap(0, Ordering::Relaxed),
        }
    }

    fn add(&self, evals: u64, scanned: u64, probed: u64) {
        for (c, n) in [
            (&self.distance_evals, evals),
            (&self.items_scanned, scanned),
            (&self.boxes_probed, probed),
        ] {
            if n > 0 {
                c.fetch_add(n, Ordering::Relaxed);
            }
        }
    }
}

/// One item as stored inside a box: everything a query needs, contiguous.
#[derive(Debug, Clone, Copy)]
struct Entry<K> {
    pos: Pos,
    id: u64,
    kind: K,
}

/// Where an item is: its position, kind and index inside its box's vector (back-index).
#[derive(Debug, Clone, Copy)]
struct Slot<K> {
    pos: Pos,
    kind: K,
    index: usize,
}

/// Box coordinates of cell `p` for boxes of side `side` (floor division), or `[0, 0]` for the
/// single list of the exhaustive mode.
#[inline]
fn box_key(side: Option<i64>, p: Pos) -> [i64; 2] {
    match side {
        None => [0, 0],
        Some(a) => [p[0].div_euclid(a), p[1].div_euclid(a)],
    }
}

/// Exact squared Euclidean distance between two cells, valid for the whole `i64` plane.
///
/// The result can exceed `u64::MAX` (up to about `2^129`), hence `u128`, saturated at
/// `u128::MAX` when it would not fit. [`PlaneGrid`] compares against `u64` radii with the
/// same exact arithmetic; this function is the reference for callers and tests.
pub fn dist2(a: Pos, b: Pos) -> u128 {
    let dx = u128::from(a[0].abs_diff(b[0]));
    let dy = u128::from(a[1].abs_diff(b[1]));
    (dx * dx).saturating_add(dy * dy)
}

/// The per-item test shared by every query and both modes: per-axis early exit against
/// `lim_r = isqrt(limit)`, then (counted) the full squared distance. Returns `None` when the
/// item is certainly farther than `limit`; otherwise the exact squared distance (which the
/// caller still compares with `limit`).
#[inline(always)]
fn item_dist2(p: Pos, q: Pos, lim_r: u64, evals: &mut u64) -> Option<u64> {
    let dx = p[0].abs_diff(q[0]);
    if dx > lim_r {
        return None;
    }
    let dy = p[1].abs_diff(q[1]);
    if dy > lim_r {
        return None;
    }
    *evals += 1;
    // dx, dy <= isqrt(u64::MAX) = 2^32 - 1, so each square fits in u64; the sum may not, and
    // then it is larger than any u64 limit.
    (dx * dx).checked_add(dy * dy)
}

/// What every query carries: the query point, the filter, the current inclusive limit on the
/// squared distance (with its integer square root for the per-axis test) and the work tally.
struct Probe<K> {
    p: Pos,
    kind: Option<K>,
    exclude: Option<u64>,
    limit: u64,
    lim_r: u64,
    evals: u64,
    scanned: u64,
}

impl<K: Copy + Eq> Probe<K> {
    fn new(p: Pos, kind: Option<K>, r2: u64, exclude: Option<u64>) -> Self {
        Probe {
            p,
            kind,
            exclude,
            limit: r2,
            lim_r: r2.isqrt(),
            evals: 0,
            scanned: 0,
        }
    }

    /// The per-item test: kind filter, exclusion, per-axis early exit, then the counted full
    /// squared distance. `Some(d2)` exactly when the item qualifies, `d2 <= limit`.
    #[inline(always)]
    fn test(&mut self, e: &Entry<K>) -> Option<u64> {
        self.scanned += 1;
        if !self.kind.is_none_or(|k| e.kind == k) || self.exclude == Some(e.id) {
            return None;
        }
        item_dist2(self.p, e.pos, self.lim_r, &mut self.evals).filter(|&d2| d2 <= self.limit)
    }
}

/// A query as the search driver sees it: its [`Probe`] (whose limit says which boxes and rings
/// can still matter) and what to do with a box's items.
trait Visitor<K> {
    /// The query's probe (current limit and work tally).
    fn probe(&self) -> &Probe<K>;
    /// Examines the items of one box; `Break` ends the search (answer known).
    fn visit(&mut self, entries: &[Entry<K>]) -> ControlFlow<()>;
}

/// Nearest item by the total order `(dist2, id)` among those with `dist2 <= r2`; the limit
/// shrinks to the best distance found (never below it, so equally near items are still seen).
struct NearestVisitor<K> {
    probe: Probe<K>,
    best: Option<(u64, u64)>,
}

impl<K: Copy + Eq> Visitor<K> for NearestVisitor<K> {
    fn probe(&self) -> &Probe<K> {
        &self.probe
    }

    fn visit(&mut self, entries: &[Entry<K>]) -> ControlFlow<()> {
        for e in entries {
            let Some(d2) = self.probe.test(e) else {
                continue;
            };
            let better = match self.best {
                None => true,
                Some((bid, bd2)) => d2 < bd2 || (d2 == bd2 && e.id < bid),
            };
            if better {
                self.best = Some((e.id, d2));
                if d2 < self.probe.limit {
                    self.probe.limit = d2;
                    self.probe.lim_r = d2.isqrt();
                }
            }
        }
        ControlFlow::Continue(())
    }
}

/// Counts items with `dist2 <= r2`, stopping once the count reaches `cap`.
struct CountVisitor<K> {
    probe: Probe<K>,
    count: usize,
    cap: usize,
}

impl<K: Copy + Eq> Visitor<K> for CountVisitor<K> {
    fn probe(&self) -> &Probe<K> {
        &self.probe
    }

    fn visit(&mut self, entries: &[Entry<K>]) -> ControlFlow<()> {
        for e in entries {
            if self.probe.test(e).is_some() {
                self.count += 1;
                if self.count >= self.cap {
                    return ControlFlow::Break(());
                }
            }
        }
        ControlFlow::Continue(())
    }
}

/// Collects `(id, dist2)` of every item with `dist2 <= r2`.
struct CollectVisitor<K> {
    probe: Probe<K>,
    found: Vec<(u64, u64)>,
}

impl<K: Copy + Eq> Visitor<K> for CollectVisitor<K> {
    fn probe(&self) -> &Probe<K> {
        &self.probe
    }

    fn visit(&mut self, entries: &[Entry<K>]) -> ControlFlow<()> {
        for e in entries {
            if let Some(d2) = self.probe.test(e) {
                self.found.push((e.id, d2));
            }
        }
        ControlFlow::Continue(())
    }
}

/// Geometry of a query point relative to its own box, in `i128` so that no box arithmetic can
/// overflow anywhere on the `i64` plane.
#[derive(Clone, Copy)]
struct QueryBox {
    a: i128,
    bx: i128,
    by: i128,
    ox: i128,
    oy: i128,
}

impl QueryBox {
    fn new(a: i64, p: Pos) -> Self {
        let a = i128::from(a);
        let (px, py) = (i128::from(p[0]), i128::from(p[1]));
        let bx = px.div_euclid(a);
        let by = py.div_euclid(a);
        QueryBox {
            a,
            bx,
            by,
            ox: px - bx * a,
            oy: py - by * a,
        }
    }

    /// Cells between the query point and the nearest cell of a box `d` boxes away along one
    /// axis (`o` = the point's offset inside its own box on that axis).
    #[inline]
    fn gap(&self, d: i128, o: i128) -> i128 {
        if d > 0 {
            d * self.a - o
        } else if d < 0 {
            (-d - 1) * self.a + o + 1
        } else {
            0
        }
    }

    /// The smallest distance, along its nearest axis, from the point to any cell of ring 1:
    /// ring `k >= 1` is at least `(k - 1) A + edge` away.
    fn edge(&self) -> i128 {
        (self.ox + 1)
            .min(self.a - self.ox)
            .min(self.oy + 1)
            .min(self.a - self.oy)
    }

    /// Whether the box at offset `(dx, dy)` (in boxes) can hold an item within `limit`
    /// (`lim_r = isqrt(limit)`): its exact minimum squared distance is `<= limit`.
    #[inline]
    fn box_within(&self, dx: i128, dy: i128, limit: u64, lim_r: u64) -> bool {
        let gx = self.gap(dx, self.ox);
        let gy = self.gap(dy, self.oy);
        let lr = i128::from(lim_r);
        if gx > lr || gy > lr {
            return false;
        }
        // Both gaps are at most 2^32 - 1 here, so this cannot overflow.
        gx * gx + gy * gy <= i128::from(limit)
    }

    /// The map key of the box at offset `(dx, dy)`, if it is a box some `i64` cell can be in.
    #[inline]
    fn key(&self, dx: i128, dy: i128) -> Option<[i64; 2]> {
        Some([
            i64::try_from(self.bx + dx).ok()?,
            i64::try_from(self.by + dy).ok()?,
        ])
    }
}

/// Grid boxes over the unbounded 2D integer plane, holding point items with an id, a kind and a
/// position (seed 000, section II.B: a list of animats per grid box; section III: the data
/// structures; section IV.B, Fig. 9 and Table I: grid sizes against "no grid").
///
/// `K` is the kind of an item (the animat species); any small `Copy + Eq` type works. Ids are
/// `u64` and must be unique among the items present. Several items may share a cell.
///
/// Queries take an optional id to exclude (the querying animat itself) and an inclusive squared
/// radius `r2`: an item at squared distance `d2` qualifies when `d2 <= r2`. See the
/// [module documentation](self) for the layout, the cost of each operation and why every answer
/// equals the exhaustive scan's.
#[derive(Debug)]
pub struct PlaneGrid<K> {
    side: Option<i64>,
    boxes: FxHashMap<[i64; 2], Vec<Entry<K>>>,
    slots: FxHashMap<u64, Slot<K>>,
    cells: FxHashMap<Pos, u32>,
    /// Whether `cells` is maintained (see [`PlaneGrid::without_cell_counts`]).
    track_cells: bool,
    spare: Vec<Vec<Entry<K>>>,
    stats: Counters,
}

impl<K: Copy> Clone for PlaneGrid<K> {
    /// Clones the items and the structure; the clone's work counters start at the original's
    /// current values.
    fn clone(&self) -> Self {
        PlaneGrid {
            side: self.side,
            boxes: self.boxes.clone(),
            slots: self.slots.clone(),
            cells: self.cells.clone(),
            track_cells: self.track_cells,
            spare: Vec::new(),
            stats: Counters::from(self.stats.load()),
        }
    }
}

impl<K: Copy + Eq> PlaneGrid<K> {
    /// An empty grid with the given box size (seed 000, section IV.B: 60, 120, 240 or none).
    ///
    /// # Errors
    /// [`PlaneError::BadBoxSide`] if the side is zero or negative.
    pub fn new(size: BoxSize) -> Result<Self, PlaneError> {
        let size = size.validate()?;
        Ok(PlaneGrid {
            side: size.side(),
            boxes: FxHashMap::default(),
            slots: FxHashMap::default(),
            cells: FxHashMap::default(),
            track_cells: true,
            spare: Vec::new(),
            stats: Counters::default(),
        })
    }

    /// An empty grid that does not keep the per-cell counts behind
    /// [`is_occupied`](Self::is_occupied): for callers that track occupancy themselves (the
    /// animat model keeps a dense cell index). Every answer is the same; `insert`, `remove`
    /// and `move_to` skip two hash-map updates, while [`is_occupied`](Self::is_occupied),
    /// [`occupancy`](Self::occupancy) and [`items_at`](Self::items_at) scan the cell's box
    /// instead of one lookup (O(N) in [`BoxSize::None`] mode).
    ///
    /// # Errors
    /// [`PlaneError::BadBoxSide`] if the side is zero or negative.
    pub fn without_cell_counts(size: BoxSize) -> Result<Self, PlaneError> {
        let mut g = Self::new(size)?;
        g.track_cells = false;
        Ok(g)
    }

    /// Whether the grid keeps per-cell counts (false for
    /// [`without_cell_counts`](Self::without_cell_counts)).
    pub fn tracks_cells(&self) -> bool {
        self.track_cells
    }

    /// An empty grid with boxes of side `a` cells (seed 000, section II.B).
    ///
    /// # Errors
    /// [`PlaneError::BadBoxSide`] if `a <= 0`.
    pub fn with_side(a: i64) -> Result<Self, PlaneError> {
        Self::new(BoxSize::Side(a))
    }

    /// An empty grid without boxes: every query scans all items, the "no grid" baseline of
    /// seed 000, Fig. 9 and Table I.
    pub fn exhaustive() -> Self {
        PlaneGrid {
            side: None,
            boxes: FxHashMap::default(),
            slots: FxHashMap::default(),
            cells: FxHashMap::default(),
            track_cells: true,
            spare: Vec::new(),
            stats: Counters::default(),
        }
    }

    /// The box size this grid uses.
    pub fn box_size(&self) -> BoxSize {
        match self.side {
            None => BoxSize::None,
            Some(a) => BoxSize::Side(a),
        }
    }

    /// Rebuilds the boxes with a new size, keeping every item (and all answers). O(N).
    ///
    /// The animat model keeps its box size fixed (seed 000, section II.B); this serves
    /// experiments that compare sizes on one population, and the box doubling of section II.A.
    ///
    /// # Errors
    /// [`PlaneError::BadBoxSide`] if the side is zero or negative; the grid is then unchanged.
    pub fn rebox(&mut self, size: BoxSize) -> Result<(), PlaneError> {
        let size = size.validate()?;
        let entries: Vec<Entry<K>> = self.boxes.drain().flat_map(|(_, v)| v).collect();
        self.side = size.side();
        self.spare.clear();
        for e in entries {
            let key = self.box_key(e.pos);
            let list = self.boxes.entry(key).or_default();
            let index = list.len();
            list.push(e);
            if let Some(slot) = self.slots.get_mut(&e.id) {
                slot.index = index;
            }
        }
        Ok(())
    }

    /// Number of items.
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// Whether there are no items.
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Number of non-empty grid boxes (1 in [`BoxSize::None`] mode unless empty). Useful to
    /// judge whether a box size suits the density (seed 000, section V).
    pub fn box_count(&self) -> usize {
        self.boxes.len()
    }

    /// Whether an item with this id is present.
    pub fn contains(&self, id: u64) -> bool {
        self.slots.contains_key(&id)
    }

    /// Position and kind of an item, or `None` if the id is not present.
    pub fn get(&self, id: u64) -> Option<(Pos, K)> {
        self.slots.get(&id).map(|s| (s.pos, s.kind))
    }

    /// The box coordinates of a cell: floor division by the side (`div_euclid`), so negative
    /// coordinates go to negative boxes. All cells share box `[0, 0]` in `None` mode.
    fn box_key(&self, p: Pos) -> [i64; 2] {
        box_key(self.side, p)
    }

    /// Adds an item. O(1).
    ///
    /// # Errors
    /// [`PlaneError::DuplicateId`] if an item with this id is already present; the grid is then
    /// unchanged.
    pub fn insert(&mut self, id: u64, pos: Pos, kind: K) -> Result<(), PlaneError> {
        let key = self.box_key(pos);
        let MapEntry::Vacant(vacant) = self.slots.entry(id) else {
            return Err(PlaneError::DuplicateId(id));
        };
        let spare = &mut self.spare;
        let list = self
            .boxes
            .entry(key)
            .or_insert_with(|| spare.pop().unwrap_or_default());
        let index = list.len();
        list.push(Entry { pos, id, kind });
        vacant.insert(Slot { pos, kind, index });
        if self.track_cells {
            *self.cells.entry(pos).or_insert(0) += 1;
        }
        Ok(())
    }

    /// Removes an item and returns its position and kind. O(1): `swap_remove` in its box plus
    /// one back-index fix; a box that empties leaves the map.
    ///
    /// # Errors
    /// [`PlaneError::UnknownId`] if the id is not present.
    pub fn remove(&mut self, id: u64) -> Result<(Pos, K), PlaneError> {
        let slot = self.slots.remove(&id).ok_or(PlaneError::UnknownId(id))?;
        let key = self.box_key(slot.pos);
        self.detach(key, slot.index);
        if self.track_cells {
            self.cell_dec(slot.pos);
        }
        Ok((slot.pos, slot.kind))
    }

    /// Moves an item to `to` and returns its previous position. O(1). When the box does not
    /// change, the box map keeps its structure: one lookup updates the entry in place. Only a
    /// box change moves the entry (`swap_remove` in the old box, push in the new one).
    ///
    /// # Errors
    /// [`PlaneError::UnknownId`] if the id is not present.
    pub fn move_to(&mut self, id: u64, to: Pos) -> Result<Pos, PlaneError> {
        let side = self.side;
        let slot = self.slots.get_mut(&id).ok_or(PlaneError::UnknownId(id))?;
        let from = slot.pos;
        if from == to {
            return Ok(from);
        }
        let old_key = box_key(side, from);
        let new_key = box_key(side, to);
        slot.pos = to;
        let (index, kind) = (slot.index, slot.kind);
        if old_key == new_key {
            if let Some(e) = self
                .boxes
                .get_mut(&old_key)
                .and_then(|list| list.get_mut(index))
            {
                e.pos = to;
            }
        } else {
            self.detach(old_key, index);
            let spare = &mut self.spare;
            let list = self
                .boxes
                .entry(new_key)
                .or_insert_with(|| spare.pop().unwrap_or_default());
            let new_index = list.len();
            list.push(Entry { pos: to, id, kind });
            if let Some(s) = self.slots.get_mut(&id) {
                s.index = new_index;
            }
        }
        if self.track_cells {
            self.cell_dec(from);
            *self.cells.entry(to).or_insert(0) += 1;
        }
        Ok(from)
    }

    /// Removes every item (the counter is kept).
    pub fn clear(&mut self) {
        self.boxes.clear();
        self.slots.clear();
        self.cells.clear();
        self.spare.clear();
    }

    /// Removes the entry at `index` of box `key`, fixing the back-index of the entry that
    /// `swap_remove` moves into its place, and drops the box if it empties.
    fn detach(&mut self, key: [i64; 2], index: usize) {
        let MapEntry::Occupied(mut occ) = self.boxes.entry(key) else {
            debug_assert!(false, "item's box {key:?} missing");
            return;
        };
        let list = occ.get_mut();
        if index >= list.len() {
            debug_assert!(false, "back-index {index} out of range");
            return;
        }
        list.swap_remove(index);
        if let Some(moved) = list.get(index) {
            if let Some(s) = self.slots.get_mut(&moved.id) {
                s.index = index;
            }
        }
        if list.is_empty() {
            let list = occ.remove();
            if self.spare.len() < SPARE_MAX {
                self.spare.push(list);
            }
        }
    }

    fn cell_dec(&mut self, p: Pos) {
        if let MapEntry::Occupied(mut occ) = self.cells.entry(p) {
            if *occ.get() <= 1 {
                occ.remove();
            } else {
                *occ.get_mut() -= 1;
            }
        }
    }

    /// Whether any item is on cell `p` (the model's "is this cell free" test). O(1) in every
    /// mode.
    pub fn is_occupied(&self, p: Pos) -> bool {
        if self.track_cells {
            self.cells.contains_key(&p)
        } else {
            self.occupancy(p) > 0
        }
    }

    /// Number of items on cell `p`. O(1).
    pub fn occupancy(&self, p: Pos) -> usize {
        if self.track_cells {
            self.cells.get(&p).map_or(0, |&c| c as usize)
        } else {
            self.boxes
                .get(&self.box_key(p))
                .map_or(0, |list| list.iter().filter(|e| e.pos == p).count())
        }
    }

    /// Ids and kinds of the items on cell `p`, sorted by id. O(1) when the cell is free,
    /// otherwise O(items in its box) (O(N) in [`BoxSize::None`] mode). Allocates only when the
    /// cell is occupied.
    pub fn items_at(&self, p: Pos) -> Vec<(u64, K)> {
        if !self.is_occupied(p) {
            return Vec::new();
        }
        let mut out: Vec<(u64, K)> = self
            .boxes
            .get(&self.box_key(p))
            .map(|list| {
                list.iter()
                    .filter(|e| e.pos == p)
                    .map(|e| (e.id, e.kind))
                    .collect()
            })
            .unwrap_or_default();
        out.sort_unstable_by_key(|&(id, _)| id);
        out
    }

    /// All items as `(id, position, kind)`, in an unspecified order (it depends on the hash
    /// map); sort by id when order matters.
    pub fn iter(&self) -> impl Iterator<Item = (u64, Pos, K)> + '_ {
        self.boxes
            .values()
            .flat_map(|list| list.iter().map(|e| (e.id, e.pos, e.kind)))
    }

    /// Nearest item of `kind` to `p` with squared distance `<= r2`, excluding `exclude`, as
    /// `(id, dist2)`; equally near items are resolved by the lower id.
    ///
    /// Serves the "move towards the nearest rabbit / fox" rules (seed 000, section II.B) and
    /// is the query timed in Fig. 9 and Table I (section IV.B). With boxes, it searches box
    /// rings outward from `p`'s box and stops as soon as no closer item can exist; in
    /// [`BoxSize::None`] mode it scans every item.
    pub fn nearest(&self, p: Pos, kind: K, r2: u64, exclude: Option<u64>) -> Option<(u64, u64)> {
        self.nearest_filtered(p, Some(kind), r2, exclude)
    }

    /// Nearest item of any kind, as [`nearest`](Self::nearest) (seed 000, section II.B).
    pub fn nearest_any(&self, p: Pos, r2: u64, exclude: Option<u64>) -> Option<(u64, u64)> {
        self.nearest_filtered(p, None, r2, exclude)
    }

    fn nearest_filtered(
        &self,
        p: Pos,
        kind: Option<K>,
        r2: u64,
        exclude: Option<u64>,
    ) -> Option<(u64, u64)> {
        let mut v = NearestVisitor {
            probe: Probe::new(p, kind, r2, exclude),
            best: None,
        };
        self.search(p, &mut v);
        v.best
    }

    /// Number of items of any kind with squared distance `<= r2` from `p`, excluding
    /// `exclude` (seed 000, section II.B: counting the animats in the local area).
    pub fn count_within(&self, p: Pos, r2: u64, exclude: Option<u64>) -> usize {
        self.count_within_capped(p, None, r2, exclude, usize::MAX)
    }

    /// Number of items of `kind` with squared distance `<= r2` from `p`, excluding `exclude`
    /// (seed 000, section II.B: "predators will not breed unless there is sufficient prey
    /// nearby").
    pub fn count_within_kind(&self, p: Pos, kind: K, r2: u64, exclude: Option<u64>) -> usize {
        self.count_within_capped(p, Some(kind), r2, exclude, usize::MAX)
    }

    /// `min(count, cap)`, where `count` is the number of items (of `kind`, or of any kind when
    /// `None`) with squared distance `<= r2` from `p`, excluding `exclude`. Stops as soon as
    /// `cap` items are found, so an overcrowding test `count > crowd_max` costs only what it
    /// needs: `count_within_capped(p, None, r2, Some(me), crowd_max + 1) > crowd_max`
    /// (seed 000, section II.B).
    pub fn count_within_capped(
        &self,
        p: Pos,
        kind: Option<K>,
        r2: u64,
        exclude: Option<u64>,
        cap: usize,
    ) -> usize {
        if cap == 0 {
            return 0;
        }
        let mut v = CountVisitor {
            probe: Probe::new(p, kind, r2, exclude),
            count: 0,
            cap,
        };
        self.search(p, &mut v);
        v.count
    }

    /// Whether at least `n` items (of `kind`, or of any kind when `None`) lie within squared
    /// distance `r2` of `p`, excluding `exclude`; stops at the `n`-th. `at_least(.., 0)` is
    /// `true`. Overcrowding is `at_least(p, None, r2, Some(me), crowd_max + 1)`; "enough prey"
    /// is `at_least(p, Some(rabbit), v2, None, prey_needed)` (seed 000, section II.B).
    pub fn at_least(
        &self,
        p: Pos,
        kind: Option<K>,
        r2: u64,
        exclude: Option<u64>,
        n: usize,
    ) -> bool {
        self.count_within_capped(p, kind, r2, exclude, n) >= n
    }

    /// Whether any item of `kind` lies within squared distance `r2` of `p`, excluding
    /// `exclude`; stops at the first hit. With `r2 = 2` this is "a rabbit / fox adjacent" (the 8
    /// surrounding cells; seed 000, section II.B).
    pub fn any_within(&self, p: Pos, kind: K, r2: u64, exclude: Option<u64>) -> bool {
        self.count_within_capped(p, Some(kind), r2, exclude, 1) >= 1
    }

    /// Every item (of `kind`, or of any kind when `None`) within squared distance `r2` of `p`,
    /// excluding `exclude`, as `(id, dist2)` sorted by `(dist2, id)`. For diagnostics and for
    /// rules that need the whole neighbourhood.
    pub fn within(
        &self,
        p: Pos,
        kind: Option<K>,
        r2: u64,
        exclude: Option<u64>,
    ) -> Vec<(u64, u64)> {
        let mut v = CollectVisitor {
            probe: Probe::new(p, kind, r2, exclude),
            found: Vec::new(),
        };
        self.search(p, &mut v);
        let mut found = v.found;
        found.sort_unstable_by_key(|&(id, d2)| (d2, id));
        found
    }

    /// Distance evaluations (full squared-distance computations against candidate items) made
    /// by queries since creation or the last reset: the work measure behind seed 000, Fig. 9
    /// and Table I. Shorthand for `self.stats().distance_evals`.
    pub fn distance_evals(&self) -> u64 {
        self.stats.distance_evals.load(Ordering::Relaxed)
    }

    /// Resets the distance-evaluation counter to zero (the other [`SearchStats`] counters are
    /// kept).
    pub fn reset_distance_evals(&self) {
        self.stats.distance_evals.store(0, Ordering::Relaxed);
    }

    /// Returns the distance-evaluation counter and resets it to zero in one step (per-step
    /// accounting of seed 000, Fig. 9).
    pub fn take_distance_evals(&self) -> u64 {
        self.stats.distance_evals.swap(0, Ordering::Relaxed)
    }

    /// All work counters of the queries since creation or the last reset (seed 000, Fig. 9 and
    /// Table I; see [`SearchStats`]).
    pub fn stats(&self) -> SearchStats {
        self.stats.load()
    }

    /// Returns all work counters and resets them to zero.
    pub fn take_stats(&self) -> SearchStats {
        self.stats.take()
    }

    /// Resets all work counters to zero.
    pub fn reset_stats(&self) {
        self.stats.take();
    }

    /// Checks every internal invariant: each item sits in the box of its position at the index
    /// its slot records, ids are unique, no box is empty, and the cell counts match. O(N).
    /// For tests and debugging.
    ///
    /// # Errors
    /// A description of the first inconsistency found.
    pub fn validate(&self) -> Result<(), String> {
        let mut seen = 0usize;
        let mut cells: FxHashMap<Pos, u32> = FxHashMap::default();
        for (key, list) in &self.boxes {
            if list.is_empty() {
                return Err(format!("empty box {key:?} kept in the map"));
            }
            for (i, e) in list.iter().enumerate() {
                if self.box_key(e.pos) != *key {
                    return Err(format!(
                        "item {} at {:?} stored in box {key:?}",
                        e.id, e.pos
                    ));
                }
                let Some(slot) = self.slots.get(&e.id) else {
                    return Err(format!("item {} has no slot", e.id));
                };
                if slot.index != i || slot.pos != e.pos || slot.kind != e.kind {
                    return Err(format!(
                        "slot of item {} disagrees with its entry (index {} vs {i})",
                        e.id, slot.index
                    ));
                }
                *cells.entry(e.pos).or_insert(0) += 1;
                seen += 1;
            }
        }
        if seen != self.slots.len() {
            return Err(format!(
                "{seen} entries in boxes but {} slots",
                self.slots.len()
            ));
        }
        if self.track_cells && cells != self.cells {
            return Err("cell occupancy counts disagree with the items".to_string());
        }
        Ok(())
    }

    /// Runs a query: exhaustive scan in `None` mode, ring search otherwise; then adds the
    /// query's work to the counters (one atomic add per counter).
    fn search<V: Visitor<K>>(&self, p: Pos, v: &mut V) {
        let probed = match self.side {
            None => {
                let mut probed = 0;
                for list in self.boxes.values() {
                    probed += 1;
                    if v.visit(list).is_break() {
                        break;
                    }
                }
                probed
            }
            Some(a) => self.ring_search(a, p, v),
        };
        let probe = v.probe();
        self.stats.add(probe.evals, probe.scanned, probed);
    }

    /// Box rings outward from `p`'s box; see the module documentation for the stop rule and
    /// why it is exact. Returns the number of boxes probed.
    fn ring_search<V: Visitor<K>>(&self, a: i64, p: Pos, v: &mut V) -> u64 {
        let total = self.slots.len();
        if total == 0 {
            return 0;
        }
        let q = QueryBox::new(a, p);
        let mut seen = 0usize;
        let mut probed = 1u64;

        // Ring 0: p's own box (minimum distance 0, always within the limit).
        if let Some(list) = q.key(0, 0).and_then(|key| self.boxes.get(&key)) {
            seen += list.len();
            if v.visit(list).is_break() {
                return probed;
            }
        }

        let edge = q.edge();
        let nboxes = self.boxes.len() as i128;
        let mut k: i128 = 1;
        loop {
            if seen >= total {
                return probed;
            }
            let lr = i128::from(v.probe().lim_r);
            // Every item in ring k is at least (k - 1) A + edge away: stop when that exceeds
            // the limit (strictly: an item exactly at the limit may still win a tie).
            if (k - 1) * q.a + edge > lr {
                return probed;
            }
            // Last ring that can matter under the current limit, and the lookups left.
            let k_max = (lr - edge) / q.a + 1;
            let left = (2 * k_max + 1) * (2 * k_max + 1) - (2 * k - 1) * (2 * k - 1);
            if left > nboxes {
                return probed + self.scan_boxes_from(q, k, v);
            }
            let mut visit = |dx: i128, dy: i128, v: &mut V| -> ControlFlow<()> {
                let pr = v.probe();
                if !q.box_within(dx, dy, pr.limit, pr.lim_r) {
                    return ControlFlow::Continue(());
                }
                probed += 1;
                match q.key(dx, dy).and_then(|key| self.boxes.get(&key)) {
                    Some(list) => {
                        seen += list.len();
                        v.visit(list)
                    }
                    None => ControlFlow::Continue(()),
                }
            };
            for dx in -k..=k {
                if visit(dx, -k, v).is_break() || visit(dx, k, v).is_break() {
                    return probed;
                }
            }
            for dy in (-k + 1)..k {
                if visit(-k, dy, v).is_break() || visit(k, dy, v).is_break() {
                    return probed;
                }
            }
            k += 1;
        }
    }

    /// Finishes a ring search in one pass over the occupied boxes, visiting those at ring
    /// `k_from` or beyond that can hold an item within the limit. Used when the rings left
    /// would cost more lookups than there are boxes. Returns the number of boxes examined.
    fn scan_boxes_from<V: Visitor<K>>(&self, q: QueryBox, k_from: i128, v: &mut V) -> u64 {
        let mut probed = 0;
        for (key, list) in &self.boxes {
            probed += 1;
            let dx = i128::from(key[0]) - q.bx;
            let dy = i128::from(key[1]) - q.by;
            if dx.abs().max(dy.abs()) < k_from {
                continue; // already visited as part of an inner ring
            }
            let pr = v.probe();
            if q.box_within(dx, dy, pr.limit, pr.lim_r) && v.visit(list).is_break() {
                break;
            }
        }
        probed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    enum Species {
        Fox,
        Rabbit,
    }
    use Species::{Fox, Rabbit};

    /// splitmix64, enough for deterministic test data without a dependency.
    struct Mix(u64);
    impl Mix {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        }
        fn range(&mut self, lo: i64, hi: i64) -> i64 {
            lo + (self.next() % (hi - lo + 1) as u64) as i64
        }
    }

    fn brute_nearest(
        items: &[(u64, Pos, Species)],
        p: Pos,
        kind: Option<Species>,
        r2: u64,
        exclude: Option<u64>,
    ) -> Option<(u64, u64)> {
        items
            .iter()
            .filter(|(id, _, k)| kind.is_none_or(|kk| kk == *k) && exclude != Some(*id))
            .map(|&(id, q, _)| (dist2(p, q), id))
            .filter(|&(d2, _)| d2 <= u128::from(r2))
            .min()
            .map(|(d2, id)| (id, d2 as u64))
    }

    fn brute_count(
        items: &[(u64, Pos, Species)],
        p: Pos,
        kind: Option<Species>,
        r2: u64,
        exclude: Option<u64>,
    ) -> usize {
        items
            .iter()
            .filter(|(id, q, k)| {
                kind.is_none_or(|kk| kk == *k)
                    && exclude != Some(*id)
                    && dist2(p, *q) <= u128::from(r2)
            })
            .count()
    }

    #[test]
    fn bad_box_sides_are_errors() {
        for a in [0, -1, -60, i64::MIN] {
            assert_eq!(
                PlaneGrid::<Species>::with_side(a).unwrap_err(),
                PlaneError::BadBoxSide(a)
            );
            assert!(PlaneGrid::<Species>::new(BoxSize::Side(a)).is_err());
        }
        let mut g = PlaneGrid::<Species>::with_side(5).unwrap();
        g.insert(1, [0, 0], Fox).unwrap();
        assert_eq!(g.rebox(BoxSize::Side(0)), Err(PlaneError::BadBoxSide(0)));
        assert_eq!(g.box_size(), BoxSize::Side(5));
        assert!(g.validate().is_ok());
        assert!(PlaneGrid::<Species>::with_side(1).is_ok());
        assert!(PlaneGrid::<Species>::with_side(i64::MAX).is_ok());
    }

    #[test]
    fn box_size_parses_and_prints() {
        assert_eq!("none".parse::<BoxSize>(), Ok(BoxSize::None));
        assert_eq!("NONE".parse::<BoxSize>(), Ok(BoxSize::None));
        assert_eq!("60".parse::<BoxSize>(), Ok(BoxSize::Side(60)));
        assert_eq!("0".parse::<BoxSize>(), Err(PlaneError::BadBoxSide(0)));
        assert_eq!("-3".parse::<BoxSize>(), Err(PlaneError::BadBoxSide(-3)));
        assert!(matches!(
            "sixty".parse::<BoxSize>(),
            Err(PlaneError::ParseBoxSize(_))
        ));
        assert_eq!(BoxSize::Side(120).to_string(), "120");
        assert_eq!(BoxSize::None.to_string(), "none");
        let msg = PlaneError::BadBoxSide(0).to_string();
        assert!(msg.contains('0') && msg.contains("positive"), "{msg}");
    }

    #[test]
    fn duplicate_and_unknown_ids_are_errors() {
        for size in [BoxSize::None, BoxSize::Side(3)] {
            let mut g = PlaneGrid::new(size).unwrap();
            g.insert(7, [1, 2], Rabbit).unwrap();
            assert_eq!(g.insert(7, [5, 5], Fox), Err(PlaneError::DuplicateId(7)));
            assert_eq!(g.get(7), Some(([1, 2], Rabbit)));
            assert_eq!(g.remove(8), Err(PlaneError::UnknownId(8)));
            assert_eq!(g.move_to(8, [0, 0]), Err(PlaneError::UnknownId(8)));
            assert_eq!(g.remove(7), Ok(([1, 2], Rabbit)));
            assert_eq!(g.remove(7), Err(PlaneError::UnknownId(7)));
            assert!(g.is_empty());
            assert_eq!(g.box_count(), 0);
            g.validate().unwrap();
        }
    }

    #[test]
    fn negative_coordinates_use_floor_boxes() {
        let g = PlaneGrid::<Species>::with_side(10).unwrap();
        assert_eq!(g.box_key([-1, -1]), [-1, -1]);
        assert_eq!(g.box_key([-10, 9]), [-1, 0]);
        assert_eq!(g.box_key([-11, 10]), [-2, 1]);
        assert_eq!(
            g.box_key([i64::MIN, i64::MAX]),
            [i64::MIN / 10 - 1, i64::MAX / 10]
        );
        // A query at the origin must see an item one cell away in the negative box.
        let mut g = g;
        g.insert(1, [-1, -1], Fox).unwrap();
        assert_eq!(g.nearest([0, 0], Fox, 2, None), Some((1, 2)));
        assert_eq!(g.nearest([0, 0], Fox, 1, None), None);
        assert!(g.any_within([0, 0], Fox, 2, None));
        assert_eq!(g.count_within([9, 9], 200, None), 1);
    }

    #[test]
    fn ties_go_to_the_lower_id_whatever_the_insertion_order() {
        let ring = [[1, 0], [0, 1], [-1, 0], [0, -1], [3, 4], [-4, 3], [5, 0]];
        for size in [
            BoxSize::None,
            BoxSize::Side(1),
            BoxSize::Side(2),
            BoxSize::Side(60),
        ] {
            for rot in 0..ring.len() {
                let mut g = PlaneGrid::new(size).unwrap();
                for i in 0..ring.len() {
                    let j = (i + rot) % ring.len();
                    g.insert(100 - j as u64, ring[j], Rabbit).unwrap();
                }
                // ids 100..=97 at distance 1: the lowest is 97 ([0, -1]).
                assert_eq!(g.nearest([0, 0], Rabbit, 100, None), Some((97, 1)));
                assert_eq!(g.nearest([0, 0], Rabbit, 100, Some(97)), Some((98, 1)));
                assert_eq!(g.nearest([0, 0], Rabbit, 0, None), None);
                // From [0, 2]: [0, 1] (id 99) at 1.
                assert_eq!(g.nearest([0, 2], Rabbit, 1, None), Some((99, 1)));
                // Distance-5 ties from [0, 0]: [3, 4] (96), [-4, 3] (95), [5, 0] (94).
                let far: Vec<_> = g
                    .within([0, 0], None, 25, None)
                    .into_iter()
                    .filter(|&(_, d2)| d2 == 25)
                    .collect();
                assert_eq!(far, vec![(94, 25), (95, 25), (96, 25)]);
                assert_eq!(g.nearest([0, 0], Fox, u64::MAX, None), None);
            }
        }
    }

    #[test]
    fn radius_is_inclusive_and_r2_two_means_adjacent() {
        for size in [
            BoxSize::None,
            BoxSize::Side(1),
            BoxSize::Side(3),
            BoxSize::Side(7),
        ] {
            let mut g = PlaneGrid::new(size).unwrap();
            let mut id = 0;
            for x in -2..=2 {
                for y in -2..=2 {
                    id += 1;
                    g.insert(id, [x, y], if (x + y) % 2 == 0 { Fox } else { Rabbit })
                        .unwrap();
                }
            }
            let me = 13; // the centre [0, 0]
            assert_eq!(g.get(me), Some(([0, 0], Fox)));
            assert_eq!(g.count_within([0, 0], 0, Some(me)), 0);
            assert_eq!(g.count_within([0, 0], 0, None), 1);
            assert_eq!(g.count_within([0, 0], 1, Some(me)), 4);
            assert_eq!(g.count_within([0, 0], 2, Some(me)), 8);
            assert_eq!(g.count_within([0, 0], 3, Some(me)), 8);
            assert_eq!(g.count_within([0, 0], 4, Some(me)), 12);
            assert_eq!(g.count_within([0, 0], 8, Some(me)), 24);
            assert_eq!(g.count_within_kind([0, 0], Rabbit, 2, Some(me)), 4);
            assert_eq!(g.count_within_kind([0, 0], Fox, 2, Some(me)), 4);
            assert_eq!(g.count_within_capped([0, 0], None, 8, Some(me), 5), 5);
            assert_eq!(g.count_within_capped([0, 0], None, 8, Some(me), 0), 0);
            assert!(g.at_least([0, 0], None, 2, Some(me), 8));
            assert!(!g.at_least([0, 0], None, 2, Some(me), 9));
            assert!(g.at_least([0, 0], None, 0, Some(me), 0));
            assert!(g.any_within([0, 0], Rabbit, 1, Some(me)));
            assert!(!g.any_within([0, 0], Fox, 1, Some(me)));
            assert!(g.any_within([0, 0], Fox, 2, Some(me)));
        }
    }

    #[test]
    fn moves_update_boxes_cells_and_back_indices() {
        let mut g = PlaneGrid::with_side(4).unwrap();
        for id in 0..20u64 {
            g.insert(id, [id as i64 % 4, 0], Rabbit).unwrap();
        }
        g.validate().unwrap();
        // Walk item 3 across several boundaries, including into negative boxes.
        for x in (-9..=9).rev() {
            g.move_to(3, [x, -x]).unwrap();
            g.validate().unwrap();
            assert_eq!(g.get(3), Some(([x, -x], Rabbit)));
            assert!(g.is_occupied([x, -x]));
        }
        assert_eq!(g.move_to(3, [-9, 9]), Ok([-9, 9]));
        // Shared cells.
        assert_eq!(g.occupancy([0, 0]), 5);
        assert_eq!(
            g.items_at([0, 0]).iter().map(|x| x.0).collect::<Vec<_>>(),
            vec![0, 4, 8, 12, 16]
        );
        g.move_to(8, [100, 100]).unwrap();
        assert_eq!(g.occupancy([0, 0]), 4);
        assert!(g.items_at([55, 55]).is_empty());
        // Remove half, in an order that exercises the swap_remove back-index.
        for id in (0..20u64).step_by(2) {
            g.remove(id).unwrap();
            g.validate().unwrap();
        }
        assert_eq!(g.len(), 10);
        assert!(!g.is_occupied([0, 0]));
        let mut ids: Vec<u64> = g.iter().map(|(id, _, _)| id).collect();
        ids.sort_unstable();
        assert_eq!(ids, (1..20).step_by(2).collect::<Vec<_>>());
        g.rebox(BoxSize::Side(1)).unwrap();
        g.validate().unwrap();
        g.rebox(BoxSize::None).unwrap();
        g.validate().unwrap();
        assert_eq!(g.box_count(), 1);
        let c = g.clone();
        c.validate().unwrap();
        g.clear();
        assert!(g.is_empty() && g.validate().is_ok() && c.len() == 10);
    }

    #[test]
    fn extreme_coordinates_are_exact() {
        let corners = [
            [i64::MIN, i64::MIN],
            [i64::MAX, i64::MAX],
            [i64::MIN, i64::MAX],
            [i64::MAX, i64::MIN],
            [i64::MAX - 1, i64::MAX],
            [0, 0],
            [-(1 << 32), 0],
            [1 << 32, 1],
        ];
        for size in [
            BoxSize::None,
            BoxSize::Side(1),
            BoxSize::Side(7),
            BoxSize::Side(i64::MAX),
        ] {
            let mut g = PlaneGrid::new(size).unwrap();
            let items: Vec<(u64, Pos, Species)> = corners
                .iter()
                .enumerate()
                .map(|(i, &p)| (i as u64, p, Rabbit))
                .collect();
            for &(id, p, k) in &items {
                g.insert(id, p, k).unwrap();
            }
            g.validate().unwrap();
            for &q in &corners {
                for r2 in [0, 1, 2, u64::MAX / 2, u64::MAX - 1, u64::MAX] {
                    for ex in [None, Some(0), Some(4)] {
                        assert_eq!(
                            g.nearest(q, Rabbit, r2, ex),
                            brute_nearest(&items, q, Some(Rabbit), r2, ex),
                            "{size:?} {q:?} {r2}"
                        );
                        assert_eq!(
                            g.count_within(q, r2, ex),
                            brute_count(&items, q, None, r2, ex),
                            "{size:?} {q:?} {r2}"
                        );
                    }
                }
            }
        }
        // (2^32)^2 = 2^64 > u64::MAX: out of every radius; (2^32-1)^2 + 0 fits.
        let mut g = PlaneGrid::with_side(3).unwrap();
        g.insert(1, [1 << 32, 0], Fox).unwrap();
        g.insert(2, [0, (1 << 32) - 1], Fox).unwrap();
        assert_eq!(
            g.nearest([0, 0], Fox, u64::MAX, None),
            Some((2, ((1u64 << 32) - 1) * ((1u64 << 32) - 1)))
        );
        assert_eq!(g.count_within([0, 0], u64::MAX, None), 1);
    }

    #[test]
    fn random_worlds_match_brute_force_and_each_other() {
        let mut rng = Mix(0x5EED);
        let sizes = [
            BoxSize::None,
            BoxSize::Side(1),
            BoxSize::Side(2),
            BoxSize::Side(3),
            BoxSize::Side(7),
            BoxSize::Side(60),
            BoxSize::Side(240),
        ];
        for world in 0..6 {
            let span = [20, 80, 300, 1000, 50, 5000][world];
            let n = [50, 300, 800, 1500, 400, 200][world];
            let mut items: Vec<(u64, Pos, Species)> = Vec::new();
            for id in 0..n {
                let p = [rng.range(-span, span), rng.range(-span, span)];
                let k = if rng.next() % 4 == 0 { Fox } else { Rabbit };
                items.push((id, p, k));
            }
            let grids: Vec<PlaneGrid<Species>> = sizes
                .iter()
                .map(|&s| {
                    let mut g = PlaneGrid::new(s).unwrap();
                    for &(id, p, k) in &items {
                        g.insert(id, p, k).unwrap();
                    }
                    g
                })
                .collect();
            for _ in 0..150 {
                let p = if rng.next() % 2 == 0 {
                    items[(rng.next() % n) as usize].1
                } else {
                    [
                        rng.range(-span - 70, span + 70),
                        rng.range(-span - 70, span + 70),
                    ]
                };
                let r2 = [0, 1, 2, 5, 25, 100, 3600, 14400, u64::MAX][(rng.next() % 9) as usize];
                let ex = Some(rng.next() % (n + 5));
                for kind in [Some(Fox), Some(Rabbit), None] {
                    let want = brute_nearest(&items, p, kind, r2, ex);
                    let want_c = brute_count(&items, p, kind, r2, ex);
                    for g in &grids {
                        let got = match kind {
                            Some(k) => g.nearest(p, k, r2, ex),
                            None => g.nearest_any(p, r2, ex),
                        };
                        assert_eq!(got, want, "{:?} p={p:?} r2={r2}", g.box_size());
                        let c = g.count_within_capped(p, kind, r2, ex, usize::MAX);
                        assert_eq!(c, want_c, "{:?} p={p:?} r2={r2}", g.box_size());
                        let cap = (rng.next() % 6) as usize;
                        assert_eq!(g.count_within_capped(p, kind, r2, ex, cap), want_c.min(cap));
                    }
                }
            }
        }
    }

    #[test]
    fn counter_counts_full_evaluations_only() {
        let mut g = PlaneGrid::exhaustive();
        g.insert(1, [0, 0], Fox).unwrap();
        g.insert(2, [100, 0], Fox).unwrap(); // fails the per-axis test for r2 = 3600
        g.insert(3, [30, 30], Fox).unwrap(); // passes both axis tests, then d2 = 1800
        g.insert(4, [59, 59], Rabbit).unwrap(); // wrong kind: not evaluated
        assert_eq!(g.distance_evals(), 0);
        assert_eq!(g.nearest([0, 0], Fox, 3600, Some(1)), Some((3, 1800)));
        assert_eq!(g.distance_evals(), 1);
        assert_eq!(g.count_within([0, 0], 3600, None), 2); // items 1, 3; item 4 at 6962 > 3600
        assert_eq!(g.distance_evals(), 4); // 1 + (1, 3, 4)
        assert_eq!(g.take_distance_evals(), 4);
        assert_eq!(g.distance_evals(), 0);
        // any_within stops at the first hit: at most 2 evaluations.
        assert!(g.any_within([0, 0], Fox, 3600, None));
        assert!(g.distance_evals() <= 2);
        g.reset_distance_evals();
        assert_eq!(g.distance_evals(), 0);

        // Items scanned and boxes probed: all 4 items in the one list, per query.
        g.reset_stats();
        g.nearest([0, 0], Fox, 3600, None);
        assert_eq!(
            g.take_stats(),
            SearchStats {
                distance_evals: 1, // item 1 at d2 = 0 shrinks the limit to 0
                items_scanned: 4,
                boxes_probed: 1
            }
        );
        assert_eq!(g.stats(), SearchStats::default());

        // With boxes of side 60, a query far from every box evaluates nothing.
        let mut g = PlaneGrid::with_side(60).unwrap();
        for i in 0..100 {
            g.insert(i, [i as i64, 0], Rabbit).unwrap();
        }
        assert_eq!(g.nearest([10_000, 10_000], Rabbit, 3600, None), None);
        assert_eq!(g.distance_evals(), 0);
        assert_eq!(g.stats().items_scanned, 0);
        // Nearest from an item's own cell stops after ring 0/1.
        assert_eq!(g.nearest([50, 0], Rabbit, 3600, Some(50)), Some((49, 1)));
        assert!(g.distance_evals() < 100);
    }

    #[test]
    fn grid_is_send_and_sync() {
        fn check<T: Send + Sync>() {}
        check::<PlaneGrid<Species>>();
    }

    #[test]
    fn without_cell_counts_answers_the_same() {
        for size in [BoxSize::None, BoxSize::Side(3), BoxSize::Side(60)] {
            let mut a: PlaneGrid<u8> = PlaneGrid::new(size).unwrap();
            let mut b: PlaneGrid<u8> = PlaneGrid::without_cell_counts(size).unwrap();
            assert!(a.tracks_cells() && !b.tracks_cells());
            let pts: [Pos; 6] = [[0, 0], [0, 0], [-1, 5], [7, -3], [100, 100], [-50, 2]];
            for (id, &p) in pts.iter().enumerate() {
                a.insert(id as u64, p, (id % 2) as u8).unwrap();
                b.insert(id as u64, p, (id % 2) as u8).unwrap();
            }
            for g in [&mut a, &mut b] {
                g.move_to(2, [-1, 6]).unwrap();
                g.move_to(4, [-3, 1]).unwrap();
                g.remove(1).unwrap();
                g.validate().unwrap();
            }
            for x in -4..9 {
                for y in -4..9 {
                    let p = [x, y];
                    assert_eq!(a.is_occupied(p), b.is_occupied(p));
                    assert_eq!(a.occupancy(p), b.occupancy(p));
                    assert_eq!(a.items_at(p), b.items_at(p));
                    assert_eq!(a.nearest(p, 1, 400, None), b.nearest(p, 1, 400, None));
                }
            }
            assert!(b.clone().validate().is_ok());
        }
    }
}
