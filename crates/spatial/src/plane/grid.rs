//! The storage of a [`PlaneGrid`] and every operation that changes it: construction and box
//! sizes, insert, remove, move, rebox, clear, the per-cell occupancy, and the invariant check.
//!
//! Invariants (checked by [`PlaneGrid::validate`]): every item sits in the box of its position
//! (`box_key`), at the index its slot records; no empty box stays in the map; ids are unique;
//! when cell counts are tracked, they equal the number of items on each cell.

use std::collections::hash_map::Entry as MapEntry;

use rustc_hash::FxHashMap;

use super::stats::Counters;
use super::{BoxSize, PlaneError, Pos};

/// Most spare box vectors kept for reuse, so boxes that empty and fill again (an animat walking
/// back and forth across a box boundary) do not allocate every time.
const SPARE_MAX: usize = 256;

/// One item as stored inside a box: everything a query needs, contiguous.
#[derive(Debug, Clone, Copy)]
pub(super) struct Entry<K> {
    pub(super) pos: Pos,
    pub(super) id: u64,
    pub(super) kind: K,
}

/// Where an item is: its position, kind and index inside its box's vector (back-index).
#[derive(Debug, Clone, Copy)]
pub(super) struct Slot<K> {
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

/// Grid boxes over the unbounded 2D integer plane, holding point items with an id, a kind and a
/// position (the grid-boxing paper, section II.B: a list of animats per grid box; section III: the
/// data structures; section IV.B, Fig. 9 and Table I: grid sizes against "no grid").
///
/// `K` is the kind of an item (the animat species); any small `Copy + Eq` type works. Ids are
/// `u64` and must be unique among the items present. Several items may share a cell.
///
/// Queries take an optional id to exclude (the querying animat itself) and an inclusive squared
/// radius `r2`: an item at squared distance `d2` qualifies when `d2 <= r2`. See the
/// [module documentation](crate::plane) for the layout, the cost of each operation and why every
/// answer equals the exhaustive scan's.
#[derive(Debug)]
pub struct PlaneGrid<K> {
    pub(super) side: Option<i64>,
    pub(super) boxes: FxHashMap<[i64; 2], Vec<Entry<K>>>,
    pub(super) slots: FxHashMap<u64, Slot<K>>,
    cells: FxHashMap<Pos, u32>,
    /// Whether `cells` is maintained (see [`PlaneGrid::without_cell_counts`]).
    track_cells: bool,
    spare: Vec<Vec<Entry<K>>>,
    pub(super) stats: Counters,
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
    /// An empty grid with the given box size (the grid-boxing paper, section IV.B: 60, 120, 240 or
    /// none).
    ///
    /// # Errors
    /// [`PlaneError::BadBoxSide`] if the side is zero or negative.
    pub fn new(size: BoxSize) -> Result<Self, PlaneError> {
        let size = size.validate()?;
        Ok(Self::empty(size.side()))
    }

    /// An empty grid with boxes of side `side` (already checked positive) or none.
    fn empty(side: Option<i64>) -> Self {
        PlaneGrid {
            side,
            boxes: FxHashMap::default(),
            slots: FxHashMap::default(),
            cells: FxHashMap::default(),
            track_cells: true,
            spare: Vec::new(),
            stats: Counters::default(),
        }
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

    /// An empty grid with boxes of side `a` cells (the grid-boxing paper, section II.B).
    ///
    /// # Errors
    /// [`PlaneError::BadBoxSide`] if `a <= 0`.
    pub fn with_side(a: i64) -> Result<Self, PlaneError> {
        Self::new(BoxSize::Side(a))
    }

    /// An empty grid without boxes: every query scans all items, the "no grid" baseline of
    /// the grid-boxing paper, Fig. 9 and Table I.
    pub fn exhaustive() -> Self {
        Self::empty(None)
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
    /// The animat model keeps its box size fixed (the grid-boxing paper, section II.B); this serves
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
    /// judge whether a box size suits the density (the grid-boxing paper, section V).
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
    pub(super) fn box_key(&self, p: Pos) -> [i64; 2] {
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
}
