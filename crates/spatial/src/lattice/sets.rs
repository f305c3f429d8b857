//! The clusters themselves: arrays of k-indices, one per live item, with an indirect list of
//! live items (the grid-boxing paper, section III, Fig. 2).

use super::ItemId;
use core_lattice::{Blocked, Boundary, Direction, Lattice};

/// Items (clusters) as sets of lattice sites, stored as k-index arrays (the grid-boxing paper,
/// Fig. 2).
///
/// Ids are handed out in increasing order from 0 and never reused. The live list plays the role
/// of the paper's left-hand array: it makes iterating over the live items cheap although merged
/// items leave holes among the ids. Its order changes when items are removed (the last live
/// item takes the removed one's place), deterministically for a given sequence of operations.
#[derive(Debug, Clone)]
pub struct SiteSets {
    lattice: Lattice,
    sets: Vec<Vec<u64>>,
    live: LiveList,
    total_sites: u64,
}

const DEAD: u32 = u32::MAX;

/// The live ids among `0..bound` as a dense list with each id's position in it: O(1)
/// membership, iteration over the live ids only, O(1) retirement (the last live id takes the
/// retired one's place). Shared by [`SiteSets`] and the halo grid, which starts from a copy.
#[derive(Debug, Clone, Default)]
pub(crate) struct LiveList {
    live: Vec<ItemId>,
    /// Position of each id in `live`, or `DEAD`.
    position: Vec<u32>,
}

impl LiveList {
    /// Hands out the next id (`bound()`) as live.
    fn push_next(&mut self) -> ItemId {
        let id = ItemId::try_from(self.position.len())
            .ok()
            .filter(|&i| i != DEAD)
            .expect("too many items");
        self.position.push(self.live.len() as u32);
        self.live.push(id);
        id
    }

    /// Whether `id` is live.
    #[inline]
    pub(crate) fn contains(&self, id: ItemId) -> bool {
        self.position.get(id as usize).is_some_and(|&p| p != DEAD)
    }

    /// The live ids.
    #[inline]
    pub(crate) fn ids(&self) -> &[ItemId] {
        &self.live
    }

    /// Retires live id `id`.
    pub(crate) fn unlink(&mut self, id: ItemId) {
        let p = self.position[id as usize] as usize;
        self.live.swap_remove(p);
        if let Some(&moved) = self.live.get(p) {
            self.position[moved as usize] = p as u32;
        }
        self.position[id as usize] = DEAD;
    }
}

impl SiteSets {
    /// No items on `lattice`.
    pub fn new(lattice: Lattice) -> Self {
        SiteSets {
            lattice,
            sets: Vec::new(),
            live: LiveList::default(),
            total_sites: 0,
        }
    }

    /// The lattice the sites live on.
    pub fn lattice(&self) -> &Lattice {
        &self.lattice
    }

    /// Add an item occupying `sites` (k-indices on the lattice) and return its id.
    ///
    /// # Panics
    /// If a site is outside the lattice or the number of ids reaches `u32::MAX` (programming
    /// errors: models validate their sizes first).
    pub fn push(&mut self, sites: Vec<u64>) -> ItemId {
        assert!(
            sites.iter().all(|&k| k < self.lattice.volume()),
            "site outside the lattice"
        );
        let id = self.live.push_next();
        self.total_sites += sites.len() as u64;
        self.sets.push(sites);
        id
    }

    /// Whether `id` is a live item.
    pub fn contains(&self, id: ItemId) -> bool {
        self.live.contains(id)
    }

    /// The sites of item `id` (empty for a removed item).
    #[inline]
    pub fn sites(&self, id: ItemId) -> &[u64] {
        &self.sets[id as usize]
    }

    /// Live item ids (see the type docs for their order).
    pub fn live(&self) -> &[ItemId] {
        self.live.ids()
    }

    /// The live list itself, for a structure that starts from the same ids.
    pub(crate) fn live_list(&self) -> &LiveList {
        &self.live
    }

    /// Number of live items.
    pub fn len(&self) -> usize {
        self.live.ids().len()
    }

    /// Whether there are no live items.
    pub fn is_empty(&self) -> bool {
        self.live.ids().is_empty()
    }

    /// One more than the largest id ever handed out: the size of arrays indexed by id.
    pub fn id_bound(&self) -> usize {
        self.sets.len()
    }

    /// Total number of sites over the live items.
    pub fn total_sites(&self) -> u64 {
        self.total_sites
    }

    /// Translate every site of `id` by the unit vector `dir`, all or nothing: if any site would
    /// cross a wall, nothing moves and [`Blocked`] is returned. On success `old` receives the
    /// previous sites (in the same order as the new ones).
    pub fn translate(
        &mut self,
        id: ItemId,
        dir: Direction,
        old: &mut Vec<u64>,
    ) -> Result<(), Blocked> {
        let lattice = &self.lattice;
        let set = &mut self.sets[id as usize];
        if lattice.boundary(dir.axis()) == Boundary::Wall
            && set.iter().any(|&k| lattice.translate(k, dir).is_err())
        {
            return Err(Blocked);
        }
        old.clear();
        old.extend_from_slice(set);
        for k in set.iter_mut() {
            *k = lattice.translate(*k, dir).expect("checked above");
        }
        Ok(())
    }

    /// Merge item `from` into item `into` (the union keeps `into`'s id, as DLCA keeps the lower
    /// id) and return the number of sites `from` had. `from` stops being live.
    ///
    /// Cost O(smaller of the two): the larger site array keeps its place and the smaller is
    /// appended to it. So the union's array is laid out as `[larger..., smaller...]` (with `into`
    /// first on a tie), and [`SiteSets::merged_parts`] tells the strategies which part was whose.
    ///
    /// # Panics
    /// If either is not live or they are the same item.
    pub fn merge(&mut self, into: ItemId, from: ItemId) -> usize {
        assert!(into != from && self.contains(into) && self.contains(from));
        let mut moved = std::mem::take(&mut self.sets[from as usize]);
        let from_len = moved.len();
        let target = &mut self.sets[into as usize];
        if moved.len() > target.len() {
            std::mem::swap(target, &mut moved);
        }
        target.extend_from_slice(&moved);
        self.live.unlink(from);
        from_len
    }

    /// After `merge(into, from)` returned `from_len`: the sites that were `into`'s and the
    /// sites that were `from`'s, as slices of the union's array.
    pub fn merged_parts(&self, into: ItemId, from_len: usize) -> (&[u64], &[u64]) {
        let all = &self.sets[into as usize];
        let into_len = all.len() - from_len;
        if from_len > into_len {
            let (f, i) = all.split_at(from_len);
            (i, f)
        } else {
            all.split_at(into_len)
        }
    }

    /// Sort the sites of `id` by k-index. Order carries no meaning for the model, but walking
    /// sorted sites visits per-site arrays (the occupancy lattice) in memory order, which is
    /// much faster for large items. Call it only between operations: a strategy may hold
    /// indices into the array until the next operation.
    pub fn sort_sites(&mut self, id: ItemId) {
        self.sets[id as usize].sort_unstable();
    }

    /// Remove item `id` and return its sites.
    ///
    /// # Panics
    /// If `id` is not live.
    pub fn remove(&mut self, id: ItemId) -> Vec<u64> {
        assert!(self.contains(id));
        let sites = std::mem::take(&mut self.sets[id as usize]);
        self.total_sites -= sites.len() as u64;
        self.live.unlink(id);
        sites
    }
}
