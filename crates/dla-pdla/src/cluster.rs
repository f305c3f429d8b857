//! The stored particles as the walkers see them: the orthtree (the variable-precision
//! distance `vpdist` and exact first contact of Sosa-Herrera & Rodriguez-Romo, "Variable
//! precision distance search for random fractal cluster simulations") and, in front of it, the
//! distance maps of [`spatial::distmap`] that let a walker a few diameters or more from the
//! cluster jump without a tree query: where a dimension has one ([`Space::SPARSE_LEVEL`]), a
//! fine sparse map (cells of a diameter or two, blocks allocated only near the cluster) for
//! walkers within its cap, then the dense levels of [`Space::MAP_LEVELS`] for those farther out.
//!
//! Invariants: in serial growth every stored particle has lowered every map, so a map's bound
//! never exceeds the exact distance to the nearest stored particle (in PDLA a particle another
//! thread has just stored may not have lowered the shared maps yet; the re-check at sticking
//! catches a move made on such a stale bound). The maps are shared between clones and grow
//! only while unshared.

use crate::error::SimError;
use crate::params::Params;
use crate::space::{Dim, Space};
use spatial::distmap::{DistanceMap, SparseDistanceMap};
use spatial::orthtree::Orthtree;
use std::sync::Arc;

/// The cluster: its orthtree and, when `params.distance_map` is on, the distance maps.
///
/// In serial growth [`insert`](Self::insert) stores a particle in the tree and the maps and
/// grows both as needed. In PDLA all threads share one cluster: between
/// [`prepare_shared`](Self::prepare_shared) and [`finish_shared`](Self::finish_shared) a
/// particle enters the tree through [`Orthtree::insert_shared`] and lowers the maps
/// through [`update_maps`](Self::update_maps), both while other threads query. A clone shares
/// the maps, which then no longer grow.
#[derive(Debug, Clone, Default)]
pub struct Cluster<const D: usize> {
    tree: Orthtree<D>,
    maps: Arc<Maps<D>>,
}

/// The distance maps: the optional sparse fine level, then the dense levels, finest first.
#[derive(Debug)]
struct Maps<const D: usize> {
    sparse: Option<SparseDistanceMap<D>>,
    levels: Box<[DistanceMap<D>]>,
}

impl<const D: usize> Default for Maps<D> {
    fn default() -> Self {
        Maps {
            sparse: None,
            levels: Box::default(),
        }
    }
}

impl<const D: usize> Cluster<D> {
    /// An empty cluster for `params` (leaf side, distance map on or off).
    pub fn new(params: &Params) -> Result<Self, SimError>
    where
        Dim<D>: Space<D>,
    {
        Ok(Cluster {
            tree: Orthtree::with_leaf_side(params.leaf_side)?,
            maps: Arc::new(if params.distance_map {
                Maps {
                    sparse: Dim::<D>::SPARSE_LEVEL
                        .map(|(cell, cap, block)| SparseDistanceMap::new(cell, cap, block))
                        .transpose()?,
                    levels: Dim::<D>::MAP_LEVELS
                        .iter()
                        .map(|&(cell, cap)| DistanceMap::new(cell, cap))
                        .collect::<Result<_, _>>()?,
                }
            } else {
                Maps::default()
            }),
        })
    }

    /// Stores a particle at `p` in the tree and the maps; returns its stored position (the
    /// orthtree's fixed-point rounding of `p`, which is what the maps and every observable
    /// see). With shared maps they are updated through [`update_maps`](Self::update_maps).
    pub fn insert(&mut self, p: [f64; D]) -> Result<[f64; D], SimError> {
        self.insert_beside(p, None)
    }

    /// [`insert`](Self::insert) of a particle that stuck to the stored particle `touched`: the
    /// per-particle maps visit only the cells nearer the new particle than `touched`, the only
    /// ones it can lower (the maps end up byte for byte as with [`insert`](Self::insert);
    /// [`spatial::distmap::DistanceMap::insert_beside`]).
    pub fn insert_beside(
        &mut self,
        p: [f64; D],
        touched: Option<&[f64; D]>,
    ) -> Result<[f64; D], SimError> {
        let leaves = self.tree.leaf_count();
        let q = self.tree.insert(p)?;
        let new_leaf = self.tree.leaf_count() > leaves;
        let (lo, hi) = self.leaf_box(&q);
        match Arc::get_mut(&mut self.maps) {
            Some(maps) => {
                if let Some(sparse) = &mut maps.sparse {
                    match touched {
                        Some(t) => sparse.insert_beside(&q, t)?,
                        None => sparse.insert(&q)?,
                    }
                }
                if let Some((fine, coarse)) = maps.levels.split_first_mut() {
                    match touched {
                        Some(t) => fine.insert_beside(&q, t)?,
                        None => fine.insert(&q)?,
                    }
                    // The coarser maps hold the boxes of the tree's leaves: lowered once, by
                    // the first particle of a leaf, for every particle the leaf will hold.
                    if new_leaf {
                        for map in coarse {
                            map.insert_box(&lo, &hi)?;
                        }
                    }
                }
            }
            None => self.update_maps(&q, touched, new_leaf)?,
        }
        Ok(q)
    }

    /// The closed box of the tree's leaf cell holding the stored position `q`: the cells are
    /// `[k s, (k + 1) s)` and a stored position is its cell's corner plus less than `s` (its
    /// fixed-point offset, exact in `f64` for the coordinates `dla` reaches), so every
    /// particle of a leaf gets the same box.
    fn leaf_box(&self, q: &[f64; D]) -> ([f64; D], [f64; D]) {
        let s = self.tree.leaf_side();
        let lo = q.map(|x| (x / s).floor() * s);
        (lo, lo.map(|x| x + s))
    }

    /// Reserves the tree's room for a PDLA phase of about `points` particles within `radius`
    /// of the origin (see [`Orthtree::prepare_shared`]).
    pub fn prepare_shared(&mut self, points: usize, radius: f64) -> Result<(), SimError> {
        Ok(self.tree.prepare_shared(points, radius)?)
    }

    /// Ends a PDLA phase (see [`Orthtree::finish_shared`]).
    pub fn finish_shared(&mut self) {
        self.tree.finish_shared();
    }

    /// Lowers the (possibly shared) maps for a stored particle `q`, atomically; the maps do not
    /// grow (see [`reserve_maps`](Self::reserve_maps)). `new_leaf`: `q` is the first particle
    /// of its tree leaf, whose box then lowers the coarser maps, once for every particle the
    /// leaf will hold, in whichever phase (serial or PDLA) the leaf opened. Until its first
    /// particle's update is done, a walker may read a coarse bound that misses the leaf, as it
    /// may read any map before a stored particle's update: PDLA's re-check at sticking
    /// catches what such a jump could cause. `touched`: the stored particle `q` stuck to, if
    /// known; the per-particle maps then visit only the cells nearer `q` (as
    /// [`insert_beside`](Self::insert_beside)), the others being lowered by that particle's
    /// own update, done or under way.
    pub fn update_maps(
        &self,
        q: &[f64; D],
        touched: Option<&[f64; D]>,
        new_leaf: bool,
    ) -> Result<(), SimError> {
        if let Some(sparse) = &self.maps.sparse {
            match touched {
                Some(t) => sparse.insert_shared_beside(q, t)?,
                None => sparse.insert_shared(q)?,
            };
        }
        if let Some((fine, coarse)) = self.maps.levels.split_first() {
            match touched {
                Some(t) => fine.insert_shared_beside(q, t)?,
                None => fine.insert_shared(q)?,
            };
            if new_leaf {
                let (lo, hi) = self.leaf_box(q);
                for map in coarse {
                    map.insert_box_shared(&lo, &hi)?;
                }
            }
        }
        Ok(())
    }

    /// Grows the maps to cover `|x_i| < r + cap + cell`, before they are shared (once shared
    /// they cannot grow, and this does nothing).
    pub fn reserve_maps(&mut self, r: f64) -> Result<(), SimError> {
        if let Some(maps) = Arc::get_mut(&mut self.maps) {
            if let Some(sparse) = &mut maps.sparse {
                sparse.reserve(r + sparse.cap() + sparse.cell_side())?;
            }
            for map in maps.levels.iter_mut() {
                map.reserve(r + map.cap() + map.cell_side())?;
            }
        }
        Ok(())
    }

    /// The orthtree.
    pub fn tree(&self) -> &Orthtree<D> {
        &self.tree
    }

    /// See [`Orthtree::set_index_limit`].
    pub fn set_tree_index_limit(&mut self, limit: u64) {
        self.tree.set_index_limit(limit);
    }

    /// The dense distance maps, finest first (empty when off).
    pub fn maps(&self) -> &[DistanceMap<D>] {
        &self.maps.levels
    }

    /// The sparse fine map in front of the dense ones, if the dimension has one and the maps
    /// are on.
    pub fn sparse_map(&self) -> Option<&SparseDistanceMap<D>> {
        self.maps.sparse.as_ref()
    }

    /// A lower bound of the distance from `p` to the nearest particle from the distance maps,
    /// and whether it is capped: the finest map that covers `p` with a cell that is not capped
    /// (`false`), or else the last capped bound found (`true`: the distance may be far larger).
    /// A capped sparse cell's bound (`cap - |p - z|`) is a floor under the dense maps' bound.
    /// `None` when the maps are off or none covers `p`.
    #[inline]
    pub fn map_bound(&self, p: &[f64; D]) -> Option<(f64, bool)> {
        self.map_bounds(p).map(|(lb, _, capped)| (lb, capped))
    }

    /// [`map_bound`](Self::map_bound) with an upper bound of the same distance from the map
    /// that gave the lower one (`+inf` when that map's cell is capped; see
    /// [`DistanceMap::bounds`]; a coarser map holds leaf boxes, so its bound gains a leaf
    /// diagonal), as `(lower, upper, capped)`.
    ///
    /// The sparse fine map is asked first: a cell that is not capped answers alone (its bound
    /// is within a small cell's diagonal of the distance). A capped one (or an absent block)
    /// says the distance is at least its cap less `|p - z|`; that floor is combined with the
    /// dense maps' answer (the larger lower bound; the dense map's upper bound and capped
    /// flag), or returned as capped when no dense map covers `p`.
    #[inline(always)]
    pub fn map_bounds(&self, p: &[f64; D]) -> Option<(f64, f64, bool)> {
        let mut floor = None;
        if let Some(sparse) = &self.maps.sparse {
            match sparse.bounds(p) {
                Some((lb, ub, false)) => return Some((lb, ub, false)),
                Some((lb, _, true)) => floor = Some(lb),
                None => {}
            }
        }
        match (self.dense_bounds(p), floor) {
            (Some((lb, ub, capped)), Some(f)) => Some((lb.max(f), ub, capped)),
            (None, Some(f)) => Some((f, f64::INFINITY, true)),
            (best, None) => best,
        }
    }

    /// [`map_bounds`](Self::map_bounds) of the dense levels alone.
    #[inline(always)]
    fn dense_bounds(&self, p: &[f64; D]) -> Option<(f64, f64, bool)> {
        let mut best = None;
        for (level, map) in self.maps.levels.iter().enumerate() {
            if let Some((lb, mut ub, capped)) = map.bounds(p) {
                if level > 0 {
                    ub += self.tree.leaf_side() * (D as f64).sqrt() * (1.0 + 1e-12);
                }
                best = Some((lb, ub, capped));
                if !capped {
                    break;
                }
            }
        }
        best
    }

    /// Particles stored.
    pub fn len(&self) -> usize {
        self.tree.len()
    }

    /// Whether no particle is stored.
    pub fn is_empty(&self) -> bool {
        self.tree.is_empty()
    }

    /// Heap bytes of the tree and the maps.
    pub fn memory_bytes(&self) -> usize {
        self.tree.memory_bytes()
            + self
                .maps
                .sparse
                .as_ref()
                .map_or(0, SparseDistanceMap::memory_bytes)
            + self
                .maps
                .levels
                .iter()
                .map(DistanceMap::memory_bytes)
                .sum::<usize>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_off_has_no_maps() {
        let params = Params {
            distance_map: false,
            ..Params::default()
        };
        let mut c = Cluster::<2>::new(&params).unwrap();
        c.insert([0.0, 0.0]).unwrap();
        assert!(c.maps().is_empty() && c.map_bound(&[3.0, 0.0]).is_none());
        assert_eq!(c.len(), 1);
        assert!(!c.is_empty() && c.memory_bytes() > 0);
    }

    /// The maps' bounds against brute force over random clusters (chains of touching
    /// particles from the origin, as DLA grows them, plus scattered ones) and random probes,
    /// in 2D to 5D: the lower bound never exceeds the exact distance to the nearest stored
    /// particle and the upper bound is never below it, for the serial inserts (the finest
    /// map by points, the coarser ones by the boxes of new leaves) and the shared ones of
    /// PDLA (maps shared by a clone, lowered through `update_maps`).
    fn map_bounds_hold<const D: usize>(seed: u64)
    where
        Dim<D>: Space<D>,
    {
        let mut rng = seed;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let params = Params {
            dim: D,
            ..Params::default()
        };
        let mut c = Cluster::<D>::new(&params).unwrap();
        let mut pts: Vec<[f64; D]> = vec![c.insert([0.0; D]).unwrap()];
        let mut keep = None;
        for n in 1..400 {
            if n == 250 {
                // From here the maps are shared and lowered atomically, without growing.
                c.reserve_maps(60.0).unwrap();
                keep = Some(c.clone());
            }
            let p: [f64; D] = if n % 10 == 0 {
                std::array::from_fn(|_| next() * 25.0)
            } else {
                let a = pts[((next() + 1.0) * 0.5 * pts.len() as f64) as usize % pts.len()];
                let u: [f64; D] = std::array::from_fn(|_| next());
                let len = u.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-9);
                std::array::from_fn(|i| a[i] + u[i] / len)
            };
            pts.push(c.insert(p).unwrap());
            if n % 50 == 49 {
                for _ in 0..200 {
                    let probe: [f64; D] = std::array::from_fn(|_| next() * 70.0);
                    let d = pts
                        .iter()
                        .map(|q| spatial::orthtree::dist_sq(q, &probe).sqrt())
                        .fold(f64::INFINITY, f64::min);
                    if let Some((lb, ub, _)) = c.map_bounds(&probe) {
                        assert!(lb <= d, "{D}D: bound {lb} above the distance {d}");
                        assert!(ub >= d, "{D}D: upper bound {ub} below the distance {d}");
                    }
                    if let Some((lb, _)) = c.map_bound(&probe) {
                        assert!(lb <= d, "{D}D: bound {lb} above the distance {d}");
                    }
                }
            }
        }
        drop(keep);
    }

    #[test]
    fn map_bounds_never_exceed_the_brute_force_distance() {
        for seed in [1, 2, 3] {
            map_bounds_hold::<2>(0x9e37_79b9 + seed);
            map_bounds_hold::<3>(0x85eb_ca6b + seed);
            map_bounds_hold::<4>(0xc2b2_ae35 + seed);
            map_bounds_hold::<5>(0x27d4_eb2f + seed);
        }
    }
}
