//! The stored particles as the walkers see them: the orthtree (the variable-precision
//! distance `vpdist` and exact first contact of Sosa-Herrera & Rodriguez-Romo, "Variable
//! precision distance search for random fractal cluster simulations") and, in front of it, the
//! coarse distance maps of [`spatial::distmap`] (levels from [`Space::MAP_LEVELS`]) that let a
//! walker a few diameters or more from the cluster jump without a tree query.
//!
//! Invariants: in serial growth every stored particle has lowered every map, so a map's bound
//! never exceeds the exact distance to the nearest stored particle (in PDLA a particle another
//! thread has just stored may not have lowered the shared maps yet; the re-check at sticking
//! catches a move made on such a stale bound). The maps are shared between clones and grow
//! only while unshared.

use crate::error::SimError;
use crate::params::Params;
use crate::space::{Dim, Space};
use spatial::distmap::DistanceMap;
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
    maps: Arc<[DistanceMap<D>]>,
}

impl<const D: usize> Cluster<D> {
    /// An empty cluster for `params` (leaf side, distance map on or off).
    pub fn new(params: &Params) -> Result<Self, SimError>
    where
        Dim<D>: Space<D>,
    {
        Ok(Cluster {
            tree: Orthtree::with_leaf_side(params.leaf_side)?,
            maps: if params.distance_map {
                Dim::<D>::MAP_LEVELS
                    .iter()
                    .map(|&(cell, cap)| DistanceMap::new(cell, cap))
                    .collect::<Result<_, _>>()?
            } else {
                Arc::new([])
            },
        })
    }

    /// Stores a particle at `p` in the tree and the maps; returns its stored position (the
    /// orthtree's fixed-point rounding of `p`, which is what the maps and every observable
    /// see). With shared maps they are updated through [`update_maps`](Self::update_maps).
    pub fn insert(&mut self, p: [f64; D]) -> Result<[f64; D], SimError> {
        let q = self.tree.insert(p)?;
        match Arc::get_mut(&mut self.maps) {
            Some(maps) => {
                for map in maps {
                    map.insert(&q)?;
                }
            }
            None => self.update_maps(&q)?,
        }
        Ok(q)
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
    /// grow (see [`reserve_maps`](Self::reserve_maps)).
    pub fn update_maps(&self, q: &[f64; D]) -> Result<(), SimError> {
        for map in self.maps.iter() {
            map.insert_shared(q)?;
        }
        Ok(())
    }

    /// Grows the maps to cover `|x_i| < r + cap + cell`, before they are shared (once shared
    /// they cannot grow, and this does nothing).
    pub fn reserve_maps(&mut self, r: f64) -> Result<(), SimError> {
        if let Some(maps) = Arc::get_mut(&mut self.maps) {
            for map in maps {
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

    /// The distance maps, finest first (empty when off).
    pub fn maps(&self) -> &[DistanceMap<D>] {
        &self.maps
    }

    /// A lower bound of the distance from `p` to the nearest particle from the distance maps,
    /// and whether it is capped: the finest map that covers `p` with a cell that is not capped
    /// (`false`), or else the last capped bound found (`true`: the distance may be far larger).
    /// `None` when the maps are off or none covers `p`.
    #[inline]
    pub fn map_bound(&self, p: &[f64; D]) -> Option<(f64, bool)> {
        let mut best = None;
        for map in self.maps.iter() {
            if let Some((lb, capped)) = map.lower_bound(p) {
                best = Some((lb, capped));
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

    /// Heap bytes of the tree and the map.
    pub fn memory_bytes(&self) -> usize {
        self.tree.memory_bytes()
            + self
                .maps
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
}
