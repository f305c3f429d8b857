//! Grid boxes hashed over the unbounded 2D integer plane, for the animat model: the grid-boxing
//! paper's own structure, kept as its **baseline setting** (the model runs it with the cell
//! search off and in the exhaustive `none` mode; its default search is [`crate::cells`]).
//!
//! This module serves Hawick, James & Scogings, *Grid-Boxing for Spatial Simulation Performance
//! Optimisation* (2006): the animat predator-prey model of section II.B lives on an unbounded
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
//! - **Counters**: [`AtomicU64`](std::sync::atomic::AtomicU64)s of distance evaluations, items
//!   scanned and boxes probed ([`SearchStats`]).
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
//! The counters are [`AtomicU64`](std::sync::atomic::AtomicU64)s updated with `Relaxed` ordering
//! once per query (each query tallies into local variables first). Queries take `&self`; atomics
//! keep [`PlaneGrid`] `Sync`, so read-only queries may run on several threads at once (a `Cell`
//! would forbid that). `Relaxed` suffices because the counters synchronise nothing else, and three
//! atomic adds per query cost nothing measurable next to the hash lookups.
//!
//! # Implementation
//!
//! `grid` owns the storage (boxes, slots, cell counts) and every update; `query` owns the
//! searches (ring search, exhaustive scan, the per-item test) and reads the storage; `stats`
//! owns the work counters. `query` depends on `grid` and `stats`, `grid` on `stats` only.

mod grid;
mod query;
mod stats;
#[cfg(test)]
mod tests;

use std::fmt;
use std::str::FromStr;

pub use grid::PlaneGrid;
pub use stats::SearchStats;

/// A cell of the unbounded integer plane, `[x, y]` (the grid-boxing paper, section II.B: animats
/// live on an unbounded plane, one per cell).
pub type Pos = [i64; 2];

/// Grid-box size of a [`PlaneGrid`] (the grid-boxing paper, sections II.B and IV.B: grids of 60,
/// 120 and 240 cells, or no grid at all).
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
