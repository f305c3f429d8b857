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
use crate::substrate::Substrate;
use spatial::distmap::{DistanceMap, DistanceMapError, PointMap, SparseDistanceMap};
use spatial::orthtree::Orthtree;
use std::sync::Arc;

mod maps;
mod window;
use maps::Maps;
pub(crate) use maps::{MapBall, MapLevel};
use window::Window;

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
    /// A deposit's substrate: every particle near a lateral edge is stored again across it
    /// ([`Substrate::for_each_image`]).
    substrate: Option<Substrate>,
    /// A deposit's map window: the maps cover a cube around a point that follows the
    /// deposit's top ([`Window`]).
    window: Option<Window>,
}

impl<const D: usize> Cluster<D> {
    /// An empty cluster for `params` (leaf side, distance map on or off).
    pub fn new(params: &Params) -> Result<Self, SimError>
    where
        Dim<D>: Space<D>,
    {
        let mut tree = Orthtree::with_leaf_side(params.leaf_side)?;
        let window = params.substrate().map(|s| Window::new::<D>(&s));
        if params.connectivity {
            tree.keep_tags()?;
        }
        Ok(Cluster {
            tree,
            maps: Arc::new(
                if params.distance_map
                    && let Some(w) = window
                {
                    w.maps(params.leaf_side)?
                } else if params.distance_map {
                    Maps::new(
                        Dim::<D>::SPARSE_LEVEL
                            .map(|(cell, cap, block)| SparseDistanceMap::new(cell, cap, block))
                            .transpose()?,
                        Dim::<D>::MAP_LEVELS
                            .iter()
                            .enumerate()
                            .map(|(k, &(cell, cap))| {
                                let map = DistanceMap::new(cell, cap)?;
                                match Dim::<D>::MAP_SUB_BOXES.get(k) {
                                    Some(&sub) if k > 0 && sub > 0 => map.with_sub_boxes(sub),
                                    _ => Ok(map),
                                }
                            })
                            .collect::<Result<_, _>>()?,
                        params.leaf_side,
                    )
                } else {
                    Maps::default()
                },
            ),
            substrate: params.substrate(),
            window,
        })
    }

    /// Stores a particle at `p` in the tree and the maps; returns its stored position (the
    /// orthtree's fixed-point rounding of `p`, which is what the maps and every observable
    /// see). With shared maps they are updated through [`update_maps`](Self::update_maps).
    pub fn insert(&mut self, p: [f64; D]) -> Result<[f64; D], SimError> {
        self.insert_beside(p, None, 0)
    }

    /// The parent of a particle that stuck to the stored particle `touched`: its arrival
    /// index (the tree's tag), or `-1` for a particle that touched none (the seed, or one
    /// rebuilt from a log). `None` without `connectivity` (the tree keeps no tags).
    pub fn parent_of(&self, touched: Option<&[f64; D]>) -> Result<Option<i64>, SimError> {
        if !self.tree.keeps_tags() {
            return Ok(None);
        }
        match touched {
            None => Ok(Some(-1)),
            Some(t) => match self.tree.tag_of(t) {
                Some(tag) => Ok(Some(i64::from(tag))),
                None => Err(SimError::ParentUnknown(format!("{t:?}"))),
            },
        }
    }

    /// [`insert`](Self::insert) of a particle that stuck to the stored particle `touched`: the
    /// per-particle maps visit only the cells nearer the new particle than `touched`, the only
    /// ones it can lower (the maps end up byte for byte as with [`insert`](Self::insert);
    /// [`spatial::distmap::DistanceMap::insert_beside`]). That holds at any distance between
    /// the two (at distance 1, or `noise_reduction` with it below 1; below 1/2 the maps
    /// visit every cell). `index`: its arrival index, kept with `connectivity`.
    ///
    /// On a substrate `p` is first wrapped into the strip, and the particle's images are
    /// stored beside it with the same index (the maps lowered by each in full).
    pub fn insert_beside(
        &mut self,
        mut p: [f64; D],
        mut touched: Option<&[f64; D]>,
        index: u32,
    ) -> Result<[f64; D], SimError> {
        let Some(substrate) = self.substrate else {
            return self.insert_one(p, touched, index);
        };
        if substrate.wrap(&mut p) {
            // The particle touched lies across the edge from the wrapped position.
            touched = None;
        }
        let q = self.insert_one(p, touched, index)?;
        let mut images = Vec::new();
        substrate.for_each_image(&q, |image| images.push(image));
        for image in images {
            self.insert_one(image, None, index)?;
        }
        // From the stored height, so that a run rebuilt from its stored positions moves its
        // window at the same particles to the same place.
        self.follow_top(q[D - 1])?;
        Ok(q)
    }

    /// [`insert_beside`](Self::insert_beside) of one stored point.
    fn insert_one(
        &mut self,
        p: [f64; D],
        touched: Option<&[f64; D]>,
        index: u32,
    ) -> Result<[f64; D], SimError> {
        let leaves = self.tree.leaf_count();
        let q = self.tree.insert_tagged(p, index)?;
        let new_leaf = self.tree.leaf_count() > leaves;
        let (lo, hi) = self.leaf_box(&q);
        if self.window.is_some() {
            self.map_insert(&q, touched)?;
            return Ok(q);
        }
        match Arc::get_mut(&mut self.maps) {
            Some(maps) => {
                if let Some(sparse) = &mut maps.sparse {
                    insert_point(sparse, &q, touched)?;
                }
                if let Some((fine, coarse)) = maps.levels.split_first_mut() {
                    insert_point(fine, &q, touched)?;
                    // The coarser maps hold the boxes of the tree's leaves (or the sub-boxes
                    // of their cells that hold them): lowered once, by the first particle of
                    // a leaf, for every particle the leaf will hold.
                    if new_leaf {
                        for map in coarse {
                            insert_leaf_box(map, &lo, &hi)?;
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
            insert_point_shared(sparse, q, touched)?;
        }
        if let Some((fine, coarse)) = self.maps.levels.split_first() {
            insert_point_shared(fine, q, touched)?;
            if new_leaf {
                let (lo, hi) = self.leaf_box(q);
                for map in coarse {
                    insert_leaf_box_shared(map, &lo, &hi)?;
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
                reserve_around(sparse, r)?;
            }
            for map in maps.levels.iter_mut() {
                reserve_around(map, r)?;
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

    /// Points stored (particles, and on a substrate their images).
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
            + self.maps.sparse.as_ref().map_or(0, PointMap::memory_bytes)
            + self
                .maps
                .levels
                .iter()
                .map(PointMap::memory_bytes)
                .sum::<usize>()
    }
}

/// Inserts the stored position `q` into `map` (exclusive access), beside the stored particle
/// `touched` when known (the same map, fewer cells visited).
fn insert_point<const D: usize>(
    map: &mut impl PointMap<D>,
    q: &[f64; D],
    touched: Option<&[f64; D]>,
) -> Result<(), DistanceMapError> {
    match touched {
        Some(t) => map.insert_beside(q, t),
        None => map.insert(q),
    }
}

/// [`insert_point`] through a shared reference, while other threads read and insert (PDLA).
fn insert_point_shared<const D: usize>(
    map: &impl PointMap<D>,
    q: &[f64; D],
    touched: Option<&[f64; D]>,
) -> Result<(), DistanceMapError> {
    match touched {
        Some(t) => map.insert_shared_beside(q, t)?,
        None => map.insert_shared(q)?,
    };
    Ok(())
}

/// Lowers a coarse map by a new leaf's box `[lo, hi]`: by the sub-box holding it, once per
/// sub-box, where the map keeps sub-boxes (`Space::MAP_SUB_BOXES`), else by the box itself.
fn insert_leaf_box<const D: usize>(
    map: &mut DistanceMap<D>,
    lo: &[f64; D],
    hi: &[f64; D],
) -> Result<(), DistanceMapError> {
    if map.sub_boxes() > 0 {
        map.insert_box_by_sub_box(lo, hi)?;
    } else {
        map.insert_box(lo, hi)?;
    }
    Ok(())
}

/// [`insert_leaf_box`] through a shared reference, while other threads read and insert (PDLA).
fn insert_leaf_box_shared<const D: usize>(
    map: &DistanceMap<D>,
    lo: &[f64; D],
    hi: &[f64; D],
) -> Result<(), DistanceMapError> {
    if map.sub_boxes() > 0 {
        map.insert_box_by_sub_box_shared(lo, hi)?;
    } else {
        map.insert_box_shared(lo, hi)?;
    }
    Ok(())
}

/// Grows `map` to cover `|x_i| < r + cap + cell`: every cell a particle within `r` of the
/// origin can lower.
fn reserve_around<const D: usize>(
    map: &mut impl PointMap<D>,
    r: f64,
) -> Result<(), DistanceMapError> {
    map.reserve(r + map.cap() + map.cell_side())
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
}
