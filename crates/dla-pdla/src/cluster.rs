//! The stored particles as the walkers see them: the orthtree (seed 002: `vpdist`, exact
//! first contact) and, in front of it, the coarse distance map of [`spatial::distmap`] that
//! lets a walker a few diameters or more from the cluster jump without a tree query.

use crate::params::Params;
use crate::sim::SimError;
use spatial::distmap::DistanceMap;
use spatial::orthtree::Orthtree;
use std::sync::Arc;

/// The distance maps, finest first, as `(cell side, cap distance)` in diameters, in `dim`
/// dimensions: a fine map for walkers up to the cap from the cluster and a coarse one beyond
/// it (a walker in a capped fine cell asks the coarse map). An insert lowers every cell whose
/// centre lies within the cap, `(pi / 4) (2 cap / cell)^2` cells in 2D and `(pi / 6) (2 cap /
/// cell)^3` in 3D: about 200 per map in 2D and 270 per map in 3D with these values. Chosen
/// by measurement (`docs/benchmarks.md`): in 2D a fine map with 4-diameter cells costs more
/// memory than it saves time, a coarse cap of 1024 costs more per insert, and coarse cells of
/// 32 or 64 diameters are within noise of each other (64 is smaller and cheaper to update).
pub fn map_levels(dim: usize) -> &'static [(f64, f64)] {
    if dim <= 2 {
        &[(8.0, 64.0), (64.0, 512.0)]
    } else {
        &[(8.0, 32.0), (32.0, 128.0)]
    }
}

/// A generous estimate of `R_ext` for a cluster of `n` particles in `dim` dimensions, for
/// sizing PDLA's shared distance maps up front: 1.3 times `0.85 n^(1/1.71)` in 2D and
/// `1.15 n^(1/2.5)` in 3D (fitted to our runs: `R_ext` was 2 640-2 770 at 1e6 in 2D and 178
/// at 3e5 in 3D). A cluster that outgrows it only loses the maps' help at its rim.
pub fn expected_r_ext(dim: usize, n: u64) -> f64 {
    let n = n as f64;
    1.3 * if dim <= 2 {
        0.85 * n.powf(1.0 / 1.71)
    } else {
        1.15 * n.powf(1.0 / 2.5)
    }
}

/// The cluster: its orthtree and, when `params.distance_map` is on, the distance maps.
///
/// A clone shares the maps (PDLA: every thread has its own replica of the tree and all threads
/// share one set of maps, which each stuck particle lowers once, atomically, through
/// [`update_maps`](Self::update_maps)); a cluster that is the maps' only owner updates them in
/// [`insert`](Self::insert) and grows them as needed.
#[derive(Debug, Clone, Default)]
pub struct Cluster<const D: usize> {
    tree: Orthtree<D>,
    maps: Arc<[DistanceMap<D>]>,
}

impl<const D: usize> Cluster<D> {
    /// An empty cluster for `params` (leaf side, distance map on or off).
    pub fn new(params: &Params) -> Result<Self, SimError> {
        Ok(Cluster {
            tree: Orthtree::with_leaf_side(params.leaf_side)?,
            maps: if params.distance_map {
                map_levels(D)
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
        let q = self.insert_tree(p)?;
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

    /// Stores a particle in the tree only (a PDLA replica applying a particle whose maps
    /// update is another call's job); returns its stored position.
    pub fn insert_tree(&mut self, p: [f64; D]) -> Result<[f64; D], SimError> {
        Ok(self.tree.insert(p)?)
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

    /// The distance maps, finest first (empty when off).
    pub fn maps(&self) -> &[DistanceMap<D>] {
        &self.maps
    }

    /// A lower bound of the distance from `p` to the nearest particle from the distance maps:
    /// the finest map that covers `p` with a cell that is not capped, or else the last capped
    /// bound found. `None` when the maps are off or none covers `p`.
    #[inline]
    pub fn map_bound(&self, p: &[f64; D]) -> Option<f64> {
        let mut best = None;
        for map in self.maps.iter() {
            if let Some((lb, capped)) = map.lower_bound(p) {
                best = Some(lb);
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
    use crate::Simulation;

    /// The walker's bound from the maps never exceeds the exact distance to the nearest
    /// particle (brute force), after serial growth and after PDLA (shared maps lowered by
    /// both threads).
    fn bound_is_below_exact<const D: usize>(n: u64, threads: usize) {
        let params = Params {
            dim: D,
            particles: n,
            threads,
            keep_positions: true,
            ..Params::default()
        };
        let mut sim = Simulation::<D>::new(params, 5).unwrap();
        sim.run().unwrap();
        let cluster = sim.cluster();
        assert_eq!(cluster.maps().len(), 2);
        if threads == 1 {
            assert!(cluster.maps().iter().all(|m| m.len() == n));
        }
        let pos = sim.positions().unwrap();
        let r = sim.r_ext() + 80.0;
        let mut rng = core_lattice::rng::stream(9, 0);
        let mut used = 0;
        for _ in 0..4000 {
            let mut p = [0.0; D];
            for x in &mut p {
                *x = (2.0 * core_lattice::rng::uniform01(&mut rng) - 1.0) * r;
            }
            let exact = pos
                .iter()
                .map(|q| (0..D).map(|i| (p[i] - q[i]).powi(2)).sum::<f64>().sqrt())
                .fold(f64::INFINITY, f64::min);
            if let Some(lb) = cluster.map_bound(&p) {
                assert!(
                    lb <= exact,
                    "{D}D: map bound {lb} above exact {exact} at {p:?}"
                );
                used += 1;
            }
        }
        assert!(
            used > 3000,
            "the maps cover the birth region ({used} of 4000)"
        );
    }

    #[test]
    fn map_bound_is_below_the_exact_distance() {
        bound_is_below_exact::<2>(3000, 1);
        bound_is_below_exact::<3>(1500, 1);
        bound_is_below_exact::<2>(3000, 2);
        bound_is_below_exact::<3>(1500, 2);
    }

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
