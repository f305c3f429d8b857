//! The distance maps as the walkers read them: the optional sparse fine map and the dense
//! levels ([`Maps`]), read coarsest first or from where a walker's last read ended
//! ([`MapLevel`]), every start giving the same bound ([`Cluster::map_bounds_from`]).

use super::Cluster;
use spatial::distmap::{DistanceMap, PointMap, Reading, SparseDistanceMap};

/// The distance maps: the optional sparse fine level, then the dense levels, finest first.
#[derive(Debug, Default)]
pub(super) struct Maps<const D: usize> {
    pub(super) sparse: Option<SparseDistanceMap<D>>,
    pub(super) levels: Box<[DistanceMap<D>]>,
    /// `enough[k]`: a lower bound from dense level `k` at least this says that the next finer
    /// map (level `k - 1`, or the sparse map below level 0) is capped where it was read, so
    /// reading that map could not sharpen it: the finer map's cap plus its cell's half
    /// diagonal (the point read is that close to its cell's centre), widened for rounding.
    /// `0` where there is no finer map.
    enough: Box<[f64]>,
    /// `sure[k]`: a distance below which dense level `k` is surely not capped (its cap less
    /// its cell's half diagonal, narrowed for rounding); `sure_sparse` the same for the
    /// sparse map (`-inf` without one). A walker known to be nearer the cluster than that
    /// starts reading at that level.
    sure: Box<[f64]>,
    sure_sparse: f64,
    /// What a coarse level's upper bound gains (`box_diagonal[k]`, `k >= 1`): those levels
    /// hold boxes (the tree's leaves, or the sub-boxes of their cells that hold them), so the
    /// nearest particle may lie a box diagonal beyond the nearest box.
    pub(super) box_diagonal: Box<[f64]>,
}

/// Where a walker's next map read starts ([`Cluster::map_bounds_from`]): the dense level its
/// last read answered from (the default starts at the coarsest level it may need), and
/// whether that read was answered by the sparse map with a cell that is not capped (the next
/// read then tries the sparse map first).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct MapLevel {
    dense: u8,
    sparse: bool,
}

impl Default for MapLevel {
    fn default() -> Self {
        MapLevel {
            dense: u8::MAX,
            sparse: false,
        }
    }
}

impl MapLevel {
    /// The same dense level, without the sparse map first: where a walker that knows
    /// nothing of the cluster starts (any start gives the same answer; a start near the
    /// level that answers saves reads).
    pub(crate) fn dense_only(self) -> Self {
        MapLevel {
            sparse: false,
            ..self
        }
    }
}

impl<const D: usize> Maps<D> {
    pub(super) fn new(
        sparse: Option<SparseDistanceMap<D>>,
        levels: Box<[DistanceMap<D>]>,
        leaf_side: f64,
    ) -> Self {
        let half_diagonal = |cell: f64| 0.5 * cell * (D as f64).sqrt();
        let reach = |cap: f64, cell: f64| (cap + half_diagonal(cell)) * (1.0 + 1e-9) + 1e-9;
        let sure = |cap: f64, cell: f64| (cap - half_diagonal(cell)) * (1.0 - 1e-9) - 1e-9;
        let enough = (0..levels.len())
            .map(|k| match k {
                0 => sparse
                    .as_ref()
                    .map_or(0.0, |s| reach(s.cap(), s.cell_side())),
                _ => reach(levels[k - 1].cap(), levels[k - 1].cell_side()),
            })
            .collect();
        let box_diagonal = levels
            .iter()
            .map(|m| {
                let sub = m.sub_boxes();
                let side = if sub > 0 {
                    leaf_side.max(m.cell_side() / sub as f64)
                } else {
                    leaf_side
                };
                side * (D as f64).sqrt() * (1.0 + 1e-12)
            })
            .collect();
        Maps {
            sure: levels
                .iter()
                .map(|m| sure(m.cap(), m.cell_side()))
                .collect(),
            sure_sparse: sparse
                .as_ref()
                .map_or(f64::NEG_INFINITY, |s| sure(s.cap(), s.cell_side())),
            sparse,
            levels,
            enough,
            box_diagonal,
        }
    }
}

/// The empty ball behind a map read ([`Cluster::map_bounds_from`]): the last map read's
/// lower bound, its cell's centre and the distance from that centre within which no particle
/// lies (see [`Reading`]). When `lower` is the lower bound the read returned and that was
/// not capped, the walker may leave this whole ball rather than the ball of its own bound.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MapBall<const D: usize> {
    pub(crate) lower: f64,
    pub(crate) centre: [f64; D],
    pub(crate) clear: f64,
}

impl<const D: usize> Default for MapBall<D> {
    fn default() -> Self {
        MapBall {
            lower: f64::NAN,
            centre: [0.0; D],
            clear: f64::NAN,
        }
    }
}

impl<const D: usize> MapBall<D> {
    /// Notes `r` unless it is capped and a read that is not was noted before (a capped finer
    /// map leaves the coarser answer standing), and returns its bounds.
    #[inline(always)]
    fn note(&mut self, r: Reading<D>) -> (f64, f64, bool) {
        if !r.capped || self.lower.is_nan() {
            self.lower = r.lower;
            self.centre = r.centre;
            self.clear = r.clear;
        }
        (r.lower, r.upper, r.capped)
    }

    /// The radius about `centre` within which a walker centre stays more than a diameter
    /// from every particle centre: `clear - 1`, less a margin for the rounding of a point
    /// computed on that sphere (a few ulps of the larger of the centre's coordinates and the
    /// radius).
    #[inline(always)]
    pub(crate) fn radius(&self) -> f64 {
        let scale = self.centre.iter().fold(self.clear, |s, x| s.max(x.abs()));
        self.clear - 1.0 - scale * 1e-15
    }
}

impl<const D: usize> Cluster<D> {
    /// A lower bound of the distance from `p` to the nearest particle from the distance maps,
    /// and whether it is capped (`true`: every map holding `p` is capped there, and the
    /// distance may be far larger than the bound). `None` when the maps are off or none
    /// covers `p`. See [`map_bounds`](Self::map_bounds).
    #[inline]
    pub fn map_bound(&self, p: &[f64; D]) -> Option<(f64, bool)> {
        self.map_bounds(p).map(|(lb, _, capped)| (lb, capped))
    }

    /// [`map_bound`](Self::map_bound) with an upper bound of the same distance from the map
    /// that gave the lower one (`+inf` when capped; see [`DistanceMap::bounds`]; a coarse map
    /// holds leaf boxes, so its bound gains a leaf diagonal), as `(lower, upper, capped)`.
    ///
    /// The maps are read coarsest first, so that a walker far from the cluster reads only
    /// the small coarse maps, which stay in cache while the fine ones (one byte per few
    /// square diameters of the whole cluster's disk or ball) do not. A finer map is read only
    /// where the coarser bound is below that map's cap plus its cell's half diagonal: at or
    /// above that the finer cell is capped and could not sharpen the bound. Reading stops at
    /// the first capped map:
    /// - if no coarser map answered, every finer one is capped too (each level's cap,
    ///   less its half diagonal, exceeds the finer level's cap plus its own): the bound is
    ///   capped;
    /// - otherwise the coarser answer stands, raised to the capped map's floor (`cap - |p -
    ///   z|`) when that is larger.
    ///
    /// The answer is that of the finest map that is not capped where `p` lies, or the
    /// coarsest capped one, whichever order the maps are read in; reading coarsest first only
    /// skips the reads that cannot change it (and adds the capped floor above).
    #[inline]
    pub fn map_bounds(&self, p: &[f64; D]) -> Option<(f64, f64, bool)> {
        self.map_bounds_within(p, f64::INFINITY)
    }

    /// [`map_bounds`](Self::map_bounds) for a point known to lie within `upper` of a stored
    /// particle: the read starts at the finest map that is surely not capped within that
    /// distance, since every coarser one would only send it down there (same answer, fewer
    /// reads for a walker near the cluster).
    #[inline(always)]
    pub fn map_bounds_within(&self, p: &[f64; D], upper: f64) -> Option<(f64, f64, bool)> {
        self.map_bounds_from(p, upper, &mut MapLevel::default(), &mut MapBall::default())
    }

    /// [`map_bounds_within`](Self::map_bounds_within), read from the dense level that
    /// answered the walker's last read (`level`, updated here) rather than from the coarsest
    /// one the walker may need: the same answer in fewer reads for a walker that stays at one
    /// distance from the cluster.
    ///
    /// The maps' caps are nested (each level's cap less its cell's half diagonal is above the
    /// next finer level's cap plus its half diagonal), so where a level is not capped every
    /// coarser one is not capped either and its bound is below the `enough` of the level
    /// under it: the coarsest-first read passes through that level and continues from there
    /// as this read does. Where the starting level is capped (or does not hold `p`), this
    /// read climbs to the first level that is not, and answers as the coarsest-first read
    /// would on arriving there: that level's bound, raised to the floor of the capped level
    /// just under it when it is below its `enough`; or, if every level up to the first one
    /// the walker may need is capped, the coarsest of them. `Cluster`'s tests hold the two
    /// reads equal from every starting level.
    #[inline(always)]
    pub(crate) fn map_bounds_from(
        &self,
        p: &[f64; D],
        upper: f64,
        level: &mut MapLevel,
        ball: &mut MapBall<D>,
    ) -> Option<(f64, f64, bool)> {
        let maps = &*self.maps;
        // The sparse map first for a walker known to be within its cap less a cell's half
        // diagonal (its answer then stands, capped or not), or one it answered last. Where
        // its cell is not capped the nearest particle lies within its cap plus a half
        // diagonal, so every dense level holds a bound below its `enough` there: the
        // coarsest-first read would descend through them to the same sparse answer.
        let sure = upper < maps.sure_sparse;
        // The sparse map's answer at `p` once read (kept for the descent, which may end there).
        let mut sparse = None;
        if sure || level.sparse {
            let bounds = self.sparse_bounds(p, ball);
            if let Some(b) = bounds
                && (sure || !b.2)
            {
                level.sparse = !b.2;
                return Some(b);
            }
            level.sparse = false;
            sparse = Some(bounds);
        }
        let top = maps
            .sure
            .iter()
            .position(|&sure| upper < sure)
            .unwrap_or(maps.levels.len().saturating_sub(1));
        let start = usize::from(level.dense).min(top);
        if start < top {
            // Climb from `start` while the levels are capped, keeping the last capped read.
            let mut floor = None;
            for k in start..=top {
                match self.level_bounds(k, p, ball) {
                    Some((lb, ub, false)) => {
                        level.dense = k as u8;
                        if lb >= maps.enough[k] {
                            return Some((lb, ub, false));
                        }
                        if let Some((f, _)) = floor {
                            return Some((lb.max(f), ub, false));
                        }
                        return self.descend(p, k, Some((lb, ub, false)), sparse, level, ball);
                    }
                    Some((lb, ub, true)) => {
                        level.dense = k as u8;
                        floor = Some((lb, ub));
                    }
                    None => {}
                }
            }
            if let Some((lb, ub)) = floor {
                // Every level up to `top` is capped: the coarsest of them answers.
                return Some((lb, ub, true));
            }
            // No level from `start` up holds `p`: read the finer ones as the coarsest-first
            // read does.
            return self.descend(p, start, None, sparse, level, ball);
        }
        self.descend(p, top + 1, None, sparse, level, ball)
    }

    /// The sparse map's `(lower, upper, capped)` at `p`, noted in `ball`; `None` without one or
    /// where it has no answer.
    #[inline(always)]
    fn sparse_bounds(&self, p: &[f64; D], ball: &mut MapBall<D>) -> Option<(f64, f64, bool)> {
        Some(ball.note(self.maps.sparse.as_ref()?.reading(p)?))
    }

    /// Dense level `k`'s `(lower, upper, capped)` at `p` (a coarse level's upper bound widened
    /// by a box diagonal: it holds boxes of particles, see `Maps::box_diagonal`), `None`
    /// where it does not hold `p`.
    #[inline(always)]
    fn level_bounds(
        &self,
        k: usize,
        p: &[f64; D],
        ball: &mut MapBall<D>,
    ) -> Option<(f64, f64, bool)> {
        let maps = &*self.maps;
        let (lb, mut ub, capped) = ball.note(maps.levels[k].reading(p)?);
        if k > 0 {
            ub += maps.box_diagonal[k];
        }
        Some((lb, ub, capped))
    }

    /// The coarsest-first read of the dense levels below `from`, then the sparse map, with
    /// `best` the answer of level `from` when it is not capped and below its `enough` (see
    /// [`map_bounds`](Self::map_bounds)) and `sparse` the sparse map's answer at `p` if it was
    /// read already; `level` becomes the finest dense level read.
    #[inline(always)]
    fn descend(
        &self,
        p: &[f64; D],
        from: usize,
        mut best: Option<(f64, f64, bool)>,
        sparse: Option<Option<(f64, f64, bool)>>,
        level: &mut MapLevel,
        ball: &mut MapBall<D>,
    ) -> Option<(f64, f64, bool)> {
        let maps = &*self.maps;
        let mut finer = true;
        for k in (0..from.min(maps.levels.len())).rev() {
            let Some((lb, ub, capped)) = self.level_bounds(k, p, ball) else {
                continue;
            };
            level.dense = k as u8;
            if capped {
                best = Some(match best {
                    Some((b_lb, b_ub, _)) => (b_lb.max(lb), b_ub, false),
                    None => (lb, ub, true),
                });
                finer = false;
                break;
            }
            best = Some((lb, ub, false));
            if lb >= maps.enough[k] {
                finer = false;
                break;
            }
        }
        if !finer {
            return best;
        }
        let sparse = sparse.unwrap_or_else(|| self.sparse_bounds(p, ball));
        match (sparse, best) {
            (Some((lb, ub, false)), _) => {
                level.sparse = true;
                Some((lb, ub, false))
            }
            (Some((lb, _, true)), Some((b_lb, b_ub, b_capped))) => {
                Some((b_lb.max(lb), b_ub, b_capped))
            }
            (Some((lb, ub, true)), None) => Some((lb, ub, true)),
            (None, best) => best,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;
    use crate::space::{Dim, Space};

    /// Uniform numbers in `[-1, 1)` from a xorshift generator seeded with `seed` (non-zero).
    fn signed_uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut rng = seed;
        move || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
    }

    /// A cluster of the default parameters in `D` dimensions holding one particle at the
    /// origin, and the stored positions.
    fn seeded_cluster<const D: usize>() -> (Cluster<D>, Vec<[f64; D]>)
    where
        Dim<D>: Space<D>,
    {
        let params = Params {
            dim: D,
            ..Params::default()
        };
        let mut c = Cluster::<D>::new(&params).unwrap();
        let first = c.insert([0.0; D]).unwrap();
        (c, vec![first])
    }

    /// A point one diameter from `a` in a random direction from `next` (as DLA's chains grow).
    fn touching<const D: usize>(a: &[f64; D], next: &mut impl FnMut() -> f64) -> [f64; D] {
        let u: [f64; D] = std::array::from_fn(|_| next());
        let len = u.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-9);
        std::array::from_fn(|i| a[i] + u[i] / len)
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
        let mut next = signed_uniform(seed);
        let (mut c, mut pts) = seeded_cluster::<D>();
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
                touching(&a, &mut next)
            };
            pts.push(c.insert(p).unwrap());
            if n % 50 == 49 {
                for i in 0..300 {
                    let reach = if i % 3 == 0 { 600.0 } else { 70.0 };
                    let probe: [f64; D] = std::array::from_fn(|_| next() * reach);
                    let d = pts
                        .iter()
                        .map(|q| spatial::orthtree::dist_sq(q, &probe).sqrt())
                        .fold(f64::INFINITY, f64::min);
                    if let Some((lb, ub, capped)) = c.map_bounds(&probe) {
                        assert!(lb <= d, "{D}D: bound {lb} above the distance {d}");
                        assert!(ub >= d, "{D}D: upper bound {ub} below the distance {d}");
                        // Coarsest first gives the finest-first answer, or a higher floor.
                        let (f_lb, f_ub, f_capped) = finest_first(&c, &probe).unwrap();
                        assert!(lb >= f_lb, "{D}D: {lb} below the finest-first {f_lb}");
                        assert_eq!((ub, capped), (f_ub, f_capped), "{D}D at {probe:?}");
                        // Starting lower for a walker known to be near gives the same, from
                        // whichever level its last read answered.
                        for slack in [1.0 + 1e-9, 1.5, 4.0, f64::INFINITY] {
                            let within = c.map_bounds_within(&probe, d * slack);
                            if slack.is_finite() {
                                assert_eq!(
                                    within,
                                    Some((lb, ub, capped)),
                                    "{D}D: read from within {}",
                                    d * slack
                                );
                            }
                            for start in 0..=c.maps.levels.len() {
                                for sparse in [false, true] {
                                    let mut level = MapLevel {
                                        dense: start as u8,
                                        sparse,
                                    };
                                    let mut ball = MapBall::default();
                                    assert_eq!(
                                        c.map_bounds_from(&probe, d * slack, &mut level, &mut ball),
                                        within,
                                        "{D}D: read from level {start} (sparse first: \
                                         {sparse}) within {}",
                                        d * slack
                                    );
                                    ball_holds(&ball, &probe, &pts, within);
                                }
                            }
                        }
                    }
                    if let Some((lb, _)) = c.map_bound(&probe) {
                        assert!(lb <= d, "{D}D: bound {lb} above the distance {d}");
                    }
                }
            }
        }
        drop(keep);
    }

    /// The ball a read noted: empty (no particle nearer its centre than `clear`), holding the
    /// probe `p` no farther from its centre than `clear - lower`, and, when it gave the read's
    /// answer `bounds`, that answer's lower bound; the radius a walker leaves it at keeps
    /// every walker centre inside at least a diameter from every particle.
    fn ball_holds<const D: usize>(
        ball: &MapBall<D>,
        p: &[f64; D],
        pts: &[[f64; D]],
        bounds: Option<(f64, f64, bool)>,
    ) {
        let Some((lb, _, _)) = bounds else {
            return;
        };
        assert!(
            !ball.lower.is_nan(),
            "{D}D: a read that answered noted no ball"
        );
        let from_centre = pts
            .iter()
            .map(|q| spatial::orthtree::dist_sq(q, &ball.centre).sqrt())
            .fold(f64::INFINITY, f64::min);
        assert!(
            ball.clear <= from_centre,
            "{D}D: clear {} beyond the nearest particle at {from_centre}",
            ball.clear
        );
        let e = spatial::orthtree::dist_sq(p, &ball.centre).sqrt();
        assert!(
            e <= ball.clear - ball.lower + 1e-9,
            "{D}D: the probe lies {e} from the centre, beyond {}",
            ball.clear - ball.lower
        );
        assert!(ball.radius() <= from_centre - 1.0);
        if ball.lower == lb && lb > 1.0 {
            assert!(e < ball.radius(), "{D}D: a jumping walker outside its ball");
        }
    }

    /// The maps read finest first, the finest that is not capped answering (a capped sparse
    /// map's floor under the dense answer): what [`Cluster::map_bounds`] must equal, up to
    /// the capped floors it adds.
    fn finest_first<const D: usize>(c: &Cluster<D>, p: &[f64; D]) -> Option<(f64, f64, bool)> {
        let mut floor = None;
        if let Some(sparse) = &c.maps.sparse {
            match sparse.bounds(p) {
                Some((lb, ub, false)) => return Some((lb, ub, false)),
                Some((lb, _, true)) => floor = Some(lb),
                None => {}
            }
        }
        let mut best = None;
        for (level, map) in c.maps.levels.iter().enumerate() {
            if let Some((lb, mut ub, capped)) = map.bounds(p) {
                if level > 0 {
                    ub += c.maps.box_diagonal[level];
                }
                best = Some((lb, ub, capped));
                if !capped {
                    break;
                }
            }
        }
        match (best, floor) {
            (Some((lb, ub, capped)), Some(f)) => Some((lb.max(f), ub, capped)),
            (None, Some(f)) => Some((f, f64::INFINITY, true)),
            (best, None) => best,
        }
    }

    /// Every coarse dense level's bounds against brute force on a cluster spread over
    /// thousands of diameters (chains of touching particles from scattered seeds), so that
    /// the 2D levels lowered by sub-boxes of 32 and 256 diameters hold many leaves per
    /// sub-box and several sub-boxes per cell: where a level is not capped its lower bound
    /// is at most the distance to the nearest particle and its upper bound (widened by the
    /// level's box diagonal) at least that; capped, the lower bound still holds. The last
    /// thousand particles lower the maps through `update_maps`, as PDLA does (a clone shares
    /// them).
    fn coarse_levels_hold<const D: usize>(seed: u64, spread: f64)
    where
        Dim<D>: Space<D>,
    {
        let mut next = signed_uniform(seed);
        let (mut c, mut pts) = seeded_cluster::<D>();
        let mut shared = None;
        for n in 1..3000 {
            if n == 2000 {
                c.reserve_maps(2.0 * spread).unwrap();
                shared = Some(c.clone());
            }
            let p: [f64; D] = if n % 40 == 0 {
                std::array::from_fn(|_| next() * spread)
            } else {
                let a = pts[pts.len() - 1 - (((next() + 1.0) * 4.0) as usize % pts.len())];
                touching(&a, &mut next)
            };
            pts.push(c.insert(p).unwrap());
        }
        assert!(
            c.maps.levels.iter().skip(1).any(|m| m.sub_boxes() > 0) == (D == 2),
            "the 2D coarse levels keep sub-boxes, the others leaf boxes"
        );
        for i in 0..1500 {
            let reach = [spread, 4.0 * spread, 20.0 * spread][i % 3];
            let probe: [f64; D] = std::array::from_fn(|_| next() * reach);
            let d = pts
                .iter()
                .map(|q| spatial::orthtree::dist_sq(q, &probe).sqrt())
                .fold(f64::INFINITY, f64::min);
            for k in 1..c.maps.levels.len() {
                if let Some((lb, ub, capped)) = c.level_bounds(k, &probe, &mut MapBall::default()) {
                    assert!(lb <= d, "{D}D level {k}: bound {lb} above the distance {d}");
                    assert!(
                        capped || ub >= d,
                        "{D}D level {k}: upper bound {ub} below the distance {d}"
                    );
                }
            }
        }
        drop(shared);
    }

    #[test]
    fn coarse_levels_hold_on_a_wide_cluster() {
        coarse_levels_hold::<2>(0x51_7cc1_b727, 3000.0);
        coarse_levels_hold::<3>(0x2545_f491, 400.0);
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
