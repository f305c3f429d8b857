//! Grid boxes over a lattice (the grid-boxing paper, section II, Fig. 1; section IV.A): the
//! paper's own structure, kept as its **baseline setting** (DLCA's `grid-doubling` strategy);
//! DLCA's default `grid` strategy runs [`HaloGrid`](super::HaloGrid) instead.

use super::{ContactSearch, ItemId, SiteSets, StampSet, coords_of, touches};
use core_lattice::{Boundary, Direction, Lattice, MAX_DIM};

/// Why grid boxes cannot be built with a given side.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum GridError {
    /// The box side is not a power of two (1, 2, 4, ...).
    #[error("grid box side {0} is not a power of two (1, 2, 4, ...)")]
    NotPowerOfTwo(u64),
    /// The number of boxes does not fit in memory indices.
    #[error("grid boxes of side {side} on lattice {sizes:?} are too many to index")]
    TooManyBoxes {
        /// Box side.
        side: u64,
        /// Lattice sides.
        sizes: Vec<u64>,
    },
}

/// Grid boxes of side `A` (a power of two) over a periodic or walled lattice, holding the items
/// registered in each box (the grid-boxing paper's grid-boxing of the DLCA model).
///
/// Each item is registered, with a particle count, in every box that holds one of its
/// particles, so items larger than a box span several boxes. A contact query gathers the items
/// registered in the mover's boxes and their `3^d` neighbourhood (the *halo*; wrapping on
/// periodic axes, stopping at walls), reports each candidate once, and tests candidates
/// particle by particle (pairwise for small movers; for movers of more than 16 particles by
/// looking up each candidate particle's neighbours among the mover's sorted sites). Since two
/// face-adjacent sites are at most one box apart on each axis, every item in contact with the mover
/// is among the candidates: the search is exact, only faster than [`super::AllPairs`].
///
/// A move updates only the particles that cross a box boundary (about one in `A` along the
/// move's axis); a merge moves the merged item's registrations to the survivor. When items grow
/// larger than a box the model doubles `A` with [`LatticeGridBoxes::set_side`], which rebuilds
/// the boxes. Once `3A >= L` on some axis ([`LatticeGridBoxes::stops_paying`]) the halo covers
/// the whole axis and grid boxes no longer save work (the grid-boxing paper, section IV.A).
#[derive(Debug, Clone)]
pub struct LatticeGridBoxes {
    lattice: Lattice,
    side: u64,
    shift: u32,
    /// Boxes along each axis, `ceil(L_a / A)`.
    counts: [u64; MAX_DIM],
    /// Strides of box indices, like k-index strides.
    strides: [u64; MAX_DIM],
    /// Items registered in each box, with how many of their particles the box holds.
    boxes: Vec<Vec<(ItemId, u32)>>,
    /// Boxes each item is registered in, indexed by item id.
    item_boxes: Vec<Vec<u32>>,
    seen_boxes: StampSet,
    seen_items: StampSet,
    candidates: Vec<ItemId>,
    halo: Vec<u32>,
    coords: Vec<[u64; MAX_DIM]>,
    /// The mover's sites, sorted, for the test of large movers.
    sorted: Vec<u64>,
}

/// Movers with more particles than this test candidates by looking up each candidate
/// particle's neighbours among the mover's sorted sites (O(s' d log s)) rather than comparing
/// every pair of particles (O(s s')).
const PAIRWISE_MAX: usize = 16;

impl LatticeGridBoxes {
    /// Empty grid boxes of side `side` (a power of two) over `lattice`.
    pub fn new(lattice: &Lattice, side: u64) -> Result<Self, GridError> {
        let mut g = LatticeGridBoxes {
            lattice: lattice.clone(),
            side: 1,
            shift: 0,
            counts: [1; MAX_DIM],
            strides: [0; MAX_DIM],
            boxes: Vec::new(),
            item_boxes: Vec::new(),
            seen_boxes: StampSet::default(),
            seen_items: StampSet::default(),
            candidates: Vec::new(),
            halo: Vec::new(),
            coords: Vec::new(),
            sorted: Vec::new(),
        };
        g.layout(side)?;
        Ok(g)
    }

    fn layout(&mut self, side: u64) -> Result<(), GridError> {
        if !side.is_power_of_two() {
            return Err(GridError::NotPowerOfTwo(side));
        }
        let too_many = || GridError::TooManyBoxes {
            side,
            sizes: self.lattice.sizes().to_vec(),
        };
        let mut total: u64 = 1;
        let mut counts = [1; MAX_DIM];
        let mut strides = [0; MAX_DIM];
        for axis in 0..self.lattice.dim() {
            counts[axis] = self.lattice.size(axis).div_ceil(side);
            strides[axis] = total;
            total = total.checked_mul(counts[axis]).ok_or_else(too_many)?;
        }
        let total = usize::try_from(total)
            .ok()
            .filter(|&t| t < u32::MAX as usize)
            .ok_or_else(too_many)?;
        self.side = side;
        self.shift = side.trailing_zeros();
        self.counts = counts;
        self.strides = strides;
        self.boxes = vec![Vec::new(); total];
        self.item_boxes.iter_mut().for_each(Vec::clear);
        Ok(())
    }

    /// Rebuild with box side `side` (the model doubles it as clusters grow), re-registering
    /// every live item of `sets`.
    pub fn set_side(&mut self, side: u64, sets: &SiteSets) -> Result<(), GridError> {
        self.layout(side)?;
        for &id in sets.live() {
            self.insert(sets, id);
        }
        Ok(())
    }

    /// The box side `A`.
    pub fn side(&self) -> u64 {
        self.side
    }

    /// Number of boxes.
    pub fn box_count(&self) -> usize {
        self.boxes.len()
    }

    /// Whether `3A >= L` on some axis, where the halo spans the whole axis and the grid-boxing
    /// paper finds grid-boxing stops paying.
    pub fn stops_paying(&self) -> bool {
        (0..self.lattice.dim()).any(|a| 3 * self.side >= self.lattice.size(a))
    }

    /// The boxes item `id` is registered in (in no particular order).
    pub fn boxes_of(&self, id: ItemId) -> &[u32] {
        self.item_boxes.get(id as usize).map_or(&[], Vec::as_slice)
    }

    /// The box holding site `k`.
    #[inline]
    pub fn box_of(&self, k: u64) -> u32 {
        let c = coords_of(&self.lattice, k);
        let mut b = 0;
        for axis in 0..self.lattice.dim() {
            b += (c[axis] >> self.shift) * self.strides[axis];
        }
        b as u32
    }

    fn add(&mut self, b: u32, id: ItemId, n: u32) {
        let list = &mut self.boxes[b as usize];
        if let Some(entry) = list.iter_mut().find(|e| e.0 == id) {
            entry.1 += n;
        } else {
            list.push((id, n));
            let i = id as usize;
            if i >= self.item_boxes.len() {
                self.item_boxes.resize_with(i + 1, Vec::new);
            }
            self.item_boxes[i].push(b);
        }
    }

    /// Take `n` particles of `id` out of box `b` (all of them with `n = u32::MAX`); returns how
    /// many there were.
    fn take(&mut self, b: u32, id: ItemId, n: u32) -> u32 {
        let list = &mut self.boxes[b as usize];
        let at = list
            .iter()
            .position(|e| e.0 == id)
            .expect("item registered in its box");
        let had = list[at].1;
        if n >= had {
            list.swap_remove(at);
            let boxes = &mut self.item_boxes[id as usize];
            let j = boxes
                .iter()
                .position(|&x| x == b)
                .expect("box listed for its item");
            boxes.swap_remove(j);
        } else {
            list[at].1 -= n;
        }
        had
    }

    /// Call `f` on every box of the `3^d` neighbourhood of box `b` (including `b`), wrapping on
    /// periodic axes and stopping at walls. A box can be reached twice when an axis has fewer
    /// than three boxes; callers deduplicate.
    fn for_each_halo_box(&self, b: u32, mut f: impl FnMut(u32)) {
        let dim = self.lattice.dim();
        let mut centre = [0u64; MAX_DIM];
        let mut rest = u64::from(b);
        for axis in 0..dim {
            centre[axis] = rest % self.counts[axis];
            rest /= self.counts[axis];
        }
        // Odometer over offsets in {-1, 0, +1}^d.
        let mut offset = [-1i64; MAX_DIM];
        'outer: loop {
            let mut index = 0u64;
            let mut valid = true;
            for axis in 0..dim {
                let n = self.counts[axis] as i64;
                let mut c = centre[axis] as i64 + offset[axis];
                if c < 0 || c >= n {
                    if self.lattice.boundary(axis) == Boundary::Periodic {
                        c = c.rem_euclid(n);
                    } else {
                        valid = false;
                        break;
                    }
                }
                index += c as u64 * self.strides[axis];
            }
            if valid {
                f(index as u32);
            }
            for axis in 0..dim {
                offset[axis] += 1;
                if offset[axis] <= 1 {
                    continue 'outer;
                }
                offset[axis] = -1;
            }
            break;
        }
    }

    /// The candidate items of a contact query for `id`: every other item registered in the
    /// halo of `id`'s boxes, each once, in discovery order.
    pub fn halo_candidates(&mut self, id: ItemId) -> &[ItemId] {
        self.seen_boxes.clear();
        self.seen_items.clear();
        self.candidates.clear();
        let mut halo = std::mem::take(&mut self.halo);
        halo.clear();
        for &b in self.boxes_of(id) {
            self.for_each_halo_box(b, |h| halo.push(h));
        }
        for &h in &halo {
            if !self.seen_boxes.insert(h as usize) {
                continue;
            }
            for &(other, _) in &self.boxes[h as usize] {
                if other != id && self.seen_items.insert(other as usize) {
                    self.candidates.push(other);
                }
            }
        }
        self.halo = halo;
        &self.candidates
    }
}

impl ContactSearch for LatticeGridBoxes {
    fn name(&self) -> &'static str {
        "grid"
    }

    fn insert(&mut self, sets: &SiteSets, id: ItemId) {
        for &k in sets.sites(id) {
            let b = self.box_of(k);
            self.add(b, id, 1);
        }
    }

    fn remove(&mut self, _: &SiteSets, id: ItemId) {
        while let Some(&b) = self.item_boxes.get(id as usize).and_then(|v| v.last()) {
            self.take(b, id, u32::MAX);
        }
    }

    fn moved(&mut self, _: &SiteSets, id: ItemId, old: &[u64], new: &[u64], dir: Direction) {
        let axis = dir.axis();
        for (&o, &n) in old.iter().zip(new) {
            let (xo, xn) = (self.lattice.coord(o, axis), self.lattice.coord(n, axis));
            let (bo_a, bn_a) = (xo >> self.shift, xn >> self.shift);
            if bo_a != bn_a {
                let bo = self.box_of(o);
                let bn =
                    (u64::from(bo) + bn_a * self.strides[axis] - bo_a * self.strides[axis]) as u32;
                self.take(bo, id, 1);
                self.add(bn, id, 1);
            }
        }
    }

    fn merge(&mut self, _: &SiteSets, into: ItemId, from: ItemId, _: usize) {
        while let Some(&b) = self.item_boxes.get(from as usize).and_then(|v| v.last()) {
            let n = self.take(b, from, u32::MAX);
            self.add(b, into, n);
        }
    }

    fn contacts(&mut self, sets: &SiteSets, id: ItemId, out: &mut Vec<ItemId>) -> usize {
        out.clear();
        let lattice = sets.lattice();
        let mine = sets.sites(id);
        let mut coords = std::mem::take(&mut self.coords);
        let mut sorted = std::mem::take(&mut self.sorted);
        coords.clear();
        sorted.clear();
        if mine.len() <= PAIRWISE_MAX {
            coords.extend(mine.iter().map(|&k| coords_of(lattice, k)));
        } else {
            sorted.extend_from_slice(mine);
            sorted.sort_unstable();
        }
        let candidates = self.halo_candidates(id);
        let examined = candidates.len();
        out.extend(candidates.iter().copied().filter(|&c| {
            if sorted.is_empty() {
                touches(lattice, &coords, sets.sites(c))
            } else {
                sets.sites(c).iter().any(|&k| {
                    lattice
                        .neighbours(k)
                        .any(|n| sorted.binary_search(&n).is_ok())
                })
            }
        }));
        self.coords = coords;
        self.sorted = sorted;
        out.sort_unstable();
        examined
    }
}
