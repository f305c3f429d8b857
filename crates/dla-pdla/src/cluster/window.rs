//! A deposit's distance maps: a window that follows the deposit's top ([`Window`]) instead of
//! cubes around the origin as tall as the deposit, rebuilt from the tree when the top rises,
//! and the reads and inserts in the window's coordinates.

use super::{Cluster, Maps, insert_point, insert_point_shared, reserve_around};
use crate::error::SimError;
use crate::space::{Dim, Space};
use crate::substrate::Substrate;
use spatial::distmap::{DistanceMap, PointMap, SparseDistanceMap};
use std::sync::Arc;

/// The region a deposit's distance maps cover. The maps are cubes centred on their origin; a
/// deposit is a slab as wide as the substrate and as tall as it has grown, so cubes around
/// the substrate's centre would cover its height in every lateral direction too (in 3D
/// `(2 h / 8)^3` bytes for the finest level). Instead the maps' origin sits at `(0, ..., 0,
/// centre)` and they cover `half` around it, `half` at least half the strip plus the images'
/// margin: the part of the deposit where walkers move, near its top. When the top rises more
/// than `half / 2` above `centre`, the window moves up to it and the maps are rebuilt from
/// the tree's points that can lower them (each particle is inserted about four times over the
/// run). Below the window a walker gets no map answer and asks the tree; a map read is
/// always a valid bound, since every point within the cap of a covered cell is in the maps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Window {
    /// Height of the maps' origin.
    centre: f64,
    /// The maps cover `|x_i - origin_i| < half` (and grow no further).
    half: f64,
    /// The dimension's finest dense level, `(cell, cap)` ([`Space::MAP_LEVELS`]).
    dense: (f64, f64),
    /// Its sparse level, if any ([`Space::SPARSE_LEVEL`]).
    sparse: Option<(f64, f64, usize)>,
}

impl Window {
    pub(super) fn new<const D: usize>(s: &Substrate) -> Self
    where
        Dim<D>: Space<D>,
    {
        Window {
            centre: 0.0,
            half: (0.5 * s.width + s.margin + 16.0).max(128.0),
            dense: Dim::<D>::MAP_LEVELS[0],
            sparse: Dim::<D>::SPARSE_LEVEL,
        }
    }

    /// Empty maps for the window: the finest dense level and the sparse one in front of it
    /// where the dimension has one (the coarser levels' caps lie beyond the images' margin,
    /// which bounds a deposit's jumps), covering the window, a cap and a cell beyond.
    pub(super) fn maps<const D: usize>(&self, leaf_side: f64) -> Result<Maps<D>, SimError> {
        let mut sparse = self
            .sparse
            .map(|(cell, cap, block)| SparseDistanceMap::new(cell, cap, block))
            .transpose()?;
        let mut dense = DistanceMap::new(self.dense.0, self.dense.1)?;
        if let Some(sparse) = &mut sparse {
            reserve_around(sparse, self.half)?;
        }
        reserve_around(&mut dense, self.half)?;
        Ok(Maps::new(sparse, Box::new([dense]), leaf_side))
    }
}

impl<const D: usize> Cluster<D> {
    /// Moves a deposit's map window up to a particle just stored at height `z` if it lies
    /// more than half the window's half side above the window's centre, and rebuilds the
    /// maps there from the tree (see [`Window`]). The new centre is `z` rounded down to a
    /// whole number of the coarsest cell side, so the maps' cells stay on one grid.
    pub(super) fn follow_top(&mut self, z: f64) -> Result<(), SimError> {
        let Some(w) = self.window else {
            return Ok(());
        };
        if z <= w.centre + 0.5 * w.half || self.maps.levels.is_empty() {
            return Ok(());
        }
        let grid = w.dense.0;
        let w = Window {
            centre: (z / grid).floor() * grid,
            ..w
        };
        self.window = Some(w);
        let maps = w.maps(self.tree.leaf_side())?;
        // Every stored point within a map's cap of a covered cell: within the cube of half
        // side `half + cap` around the origin, inside the ball around it.
        let cap = maps.levels[0].cap();
        let extent = w.half + cap;
        let origin: [f64; D] = std::array::from_fn(|i| if i + 1 == D { w.centre } else { 0.0 });
        let mut points = Vec::new();
        self.tree
            .for_each_within(&origin, extent * (D as f64).sqrt(), |q| {
                if (0..D).all(|i| (q[i] - origin[i]).abs() < extent) {
                    points.push(q);
                }
            });
        self.maps = Arc::new(maps);
        for q in points {
            self.map_insert(&q, None)?;
        }
        Ok(())
    }

    /// Lowers a deposit's maps for the stored point `q` (`touched`: the stored point it stuck
    /// to, if any), in the maps' coordinates. The maps cover the window and a cap and a cell
    /// beyond ([`reserve_around`]) and never grow: a point inside the window is inserted as
    /// usual, one outside (in a deep valley, or within a cap below the window) through the
    /// non-growing insert, which lowers the covered cells it reaches and skips the rest.
    pub(super) fn map_insert(
        &mut self,
        q: &[f64; D],
        touched: Option<&[f64; D]>,
    ) -> Result<(), SimError> {
        let Some(w) = self.window else {
            return Ok(());
        };
        let inside = |m: &[f64; D]| m.iter().all(|x| x.abs() < w.half);
        let m = self.to_map(q);
        // Beside `touched` only if that point is in the maps in full: inside the window (each
        // rebuild inserts it again), not one of the points outside it that lower only part of
        // their neighbourhood, or none.
        let t = touched.map(|t| self.to_map(t)).filter(inside);
        let inside = inside(&m);
        let maps = Arc::get_mut(&mut self.maps).expect("a deposit's maps are not shared");
        if inside {
            if let Some(sparse) = &mut maps.sparse {
                insert_point(sparse, &m, t.as_ref())?;
            }
            if let Some(fine) = maps.levels.first_mut() {
                insert_point(fine, &m, t.as_ref())?;
            }
        } else {
            if let Some(sparse) = &maps.sparse {
                insert_point_shared(sparse, &m, None)?;
            }
            if let Some(fine) = maps.levels.first() {
                insert_point_shared(fine, &m, None)?;
            }
        }
        Ok(())
    }

    /// `p` in the maps' coordinates: shifted down by a deposit's window centre.
    #[inline(always)]
    pub(crate) fn to_map(&self, p: &[f64; D]) -> [f64; D] {
        match self.window {
            Some(w) => {
                let mut m = *p;
                m[D - 1] -= w.centre;
                m
            }
            None => *p,
        }
    }

    /// [`map_bounds_within`](Self::map_bounds_within) of a deposit's walker at `p`: read in
    /// the maps' coordinates, and only inside the window.
    #[inline(always)]
    pub(crate) fn deposit_map_bounds(&self, p: &[f64; D], upper: f64) -> Option<(f64, f64, bool)> {
        let w = self.window?;
        let m = self.to_map(p);
        if m.iter().any(|x| x.abs() >= w.half) {
            return None;
        }
        self.map_bounds_within(&m, upper)
    }
}
