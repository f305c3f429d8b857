//! A walker's near cache: the stored particles within [`NEAR_RADIUS`] of a centre, copied out
//! of the orthtree once, so that the walker's next moves near the cluster ask a short flat
//! list instead of the tree.
//!
//! A walker inside the cluster's envelope makes most of its moves within a few diameters of
//! one branch. Each such query descends the tree and scans a few leaves; the cache answers it
//! from the handful of particles around the walker, in a flat array scanned with vector
//! instructions, with the same exact value:
//!
//! - **Exact, and the tree's value bit for bit.** The cache holds every stored particle whose
//!   squared distance from the centre `c`, computed as the range query computes it, is at most
//!   `NEAR_RADIUS^2`, as the tree decodes it; distances are summed axis by axis as the leaf
//!   scan sums them. For a walker at `p` with `s = |p - c|`, every particle outside the cache
//!   is farther than `NEAR_RADIUS - s`, so the cache's nearest distance `m` is the exact
//!   nearest distance whenever `m <= NEAR_RADIUS - s` (less a margin for rounding). The tree
//!   answers exactly at such distances too (its `vpdist` is exact within `(kappa - 1/2)`
//!   leaf diagonals, which the caller checks covers `NEAR_RADIUS`), so both give the same
//!   number and the walk takes the same path: `--near-cache on` and `off` give the same state
//!   hash.
//! - **First contact.** A step's first contact needs every particle within `step_min + 1`
//!   of `p`; when that ball lies inside the cache's, the cache lists the same particles (same
//!   inclusion test) and the earliest contact time is the same minimum.
//! - **Growth.** Particles are only added. In serial DLA none is added while a walker moves;
//!   in PDLA the particles another thread stored are added to the cache before the walker's
//!   next move ([`NearCache::added`]), so the cache misses at most what the tree gained during
//!   one move, as the walk itself does (the re-check at sticking covers both).

use spatial::orthtree::{Orthtree, RangeSink, dist_sq};

/// Radius of the ball a cache holds, in diameters, tuned by instruction counts
/// (`docs/dla.md`, "The near cache"; `docs/tuning.md`): a smaller ball is rebuilt too often,
/// a larger one costs more to build and to scan at every move than the tree queries it saves.
pub const NEAR_RADIUS: f64 = 5.0;

/// A cache is (re)built at the walker's position when its nearest distance is known to be
/// at most this, so the answer lies inside the new ball (a diameter from its edge) and the
/// cache answers that move at once: a walker that close to the cluster would otherwise ask
/// the tree, which costs about as much as a rebuild and answers only one move. Tuned by
/// instruction counts (`docs/dla.md`, "The near cache"); it changes no walk.
pub const REBUILD_UPPER: f64 = NEAR_RADIUS - 1.0;

/// Absolute slack on the containment tests (diameters): far above the rounding of distances
/// between points within a few hundred thousand diameters of the origin, far below anything
/// the walk can notice.
const SLACK: f64 = 1e-9;

/// Lanes of the nearest scan (independent running minima; see the leaf scan in `spatial`).
const LANES: usize = 4;

/// The cache; see the module documentation.
#[derive(Debug, Clone)]
pub(crate) struct NearCache<const D: usize> {
    /// Whether the cache holds a ball (false before the first build and after a reset).
    live: bool,
    centre: [f64; D],
    /// The cached particles in blocks of [`LANES`], each block axis by axis (`block[i][k]` is
    /// axis `i` of its `k`-th particle), so the scan reads whole vectors. Lanes past `len` in
    /// the last block hold `+inf` coordinates, which are never nearest.
    blocks: Vec<[[f64; LANES]; D]>,
    len: usize,
    /// The rebuild's scratch space, kept for its capacity.
    found: Found<D>,
}

impl<const D: usize> NearCache<D> {
    pub(crate) fn new() -> Self {
        NearCache {
            live: false,
            centre: [0.0; D],
            blocks: Vec::new(),
            len: 0,
            found: Found::default(),
        }
    }

    /// Forgets the ball (a new walker).
    pub(crate) fn reset(&mut self) {
        self.live = false;
    }

    /// Number of cached particles (0 when not live).
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        if self.live { self.len } else { 0 }
    }

    /// Copies the particles within [`NEAR_RADIUS`] of `p` out of `tree` and centres the cache
    /// on `p`.
    pub(crate) fn rebuild(&mut self, tree: &Orthtree<D>, p: &[f64; D]) {
        self.blocks.clear();
        self.found.len = 0;
        tree.range_into(p, NEAR_RADIUS, &mut self.found);
        // Transposed into blocks a whole block at a time (a point's store needs no test of
        // whether its block exists yet); the last block's lanes past the points stay +inf.
        let found = &self.found.points[..self.found.len];
        let chunks = found.chunks_exact(LANES);
        let rest = chunks.remainder();
        self.blocks.extend(
            chunks.map(|chunk| std::array::from_fn(|i| std::array::from_fn(|k| chunk[k][i]))),
        );
        if !rest.is_empty() {
            self.blocks.push(std::array::from_fn(|i| {
                std::array::from_fn(|k| rest.get(k).map_or(f64::INFINITY, |x| x[i]))
            }));
        }
        self.len = found.len();
        self.centre = *p;
        self.live = true;
    }

    fn push(&mut self, x: &[f64; D]) {
        let k = self.len % LANES;
        if k == 0 {
            self.blocks.push([[f64::INFINITY; LANES]; D]);
        }
        let block = self.blocks.last_mut().expect("a block was pushed");
        for i in 0..D {
            block[i][k] = x[i];
        }
        self.len += 1;
    }

    /// The `j`-th cached particle.
    #[inline(always)]
    fn get(&self, j: usize) -> [f64; D] {
        let block = &self.blocks[j / LANES];
        std::array::from_fn(|i| block[i][j % LANES])
    }

    /// A particle stored after the cache was built (PDLA: another thread's): kept if it lies
    /// within the ball. Keeping one outside would be harmless; missing one inside is not, so
    /// the test has the same slack as the reads.
    pub(crate) fn added(&mut self, q: &[f64; D]) {
        if self.live && dist_sq(q, &self.centre).sqrt() <= NEAR_RADIUS + SLACK {
            self.push(q);
        }
    }

    /// `NEAR_RADIUS - |p - c|` less the slack: a ball around `p` of at most this radius lies
    /// inside the cache's (`None` when the cache is not live).
    #[inline]
    fn room(&self, p: &[f64; D]) -> Option<f64> {
        self.live
            .then(|| NEAR_RADIUS - dist_sq(p, &self.centre).sqrt() - SLACK)
    }

    /// The exact nearest distance from `p` to the stored particles and a particle at that
    /// distance, if the cache can prove it (see the module documentation); `None` otherwise.
    #[inline(always)]
    pub(crate) fn nearest(&self, p: &[f64; D]) -> Option<(f64, [f64; D])> {
        let room = self.room(p)?;
        if room <= 0.0 {
            return None;
        }
        // One pass: lane-wise minima and, per lane, the first block holding that lane's
        // minimum (selected without branches, so the loop stays a handful of vector
        // instructions per block). The answer's particle is the first at the smallest value
        // (ties to the lowest index): among the lanes at that value, the lowest block, then
        // the lowest lane.
        let mut m = [f64::INFINITY; LANES];
        let mut at = [0.0f64; LANES];
        let mut b = 0.0f64;
        for block in &self.blocks {
            let d2 = block_dist_sq(p, block);
            for k in 0..LANES {
                let lower = d2[k] < m[k];
                m[k] = if lower { d2[k] } else { m[k] };
                at[k] = if lower { b } else { at[k] };
            }
            b += 1.0;
        }
        let mut best = m[0];
        for &v in &m[1..] {
            best = if v < best { v } else { best };
        }
        let d = best.sqrt();
        // Answer only when `d <= room` (a NaN position never passes).
        if d.partial_cmp(&room)
            .is_none_or(|o| o == std::cmp::Ordering::Greater)
        {
            return None;
        }
        // Each lane's index as a float (whole numbers far below 2^53: exact), the lanes not at
        // the smallest value left at +inf, then one conversion of the smallest.
        let mut first = f64::INFINITY;
        for k in 0..LANES {
            let index = at[k] * LANES as f64 + k as f64;
            let index = if m[k] == best { index } else { f64::INFINITY };
            first = if index < first { index } else { first };
        }
        Some((d, self.get(first as usize)))
    }

    /// Whether the ball of radius `r` around `p` lies inside the cache's, so that
    /// [`for_each_within`](Self::for_each_within) lists every stored particle in it.
    #[inline]
    pub(crate) fn covers(&self, p: &[f64; D], r: f64) -> bool {
        self.room(p).is_some_and(|room| r <= room)
    }

    /// Calls `f` with every cached particle at distance `<= r` from `p`, with the inclusion
    /// test of `Orthtree::for_each_within` (squared distance summed axis by axis against
    /// `r * r`). Lists every stored particle in that ball when [`covers`](Self::covers).
    #[inline(always)]
    pub(crate) fn for_each_within<F: FnMut([f64; D])>(&self, p: &[f64; D], r: f64, mut f: F) {
        if !self.live {
            return;
        }
        let r_sq = r * r;
        for (b, block) in self.blocks.iter().enumerate() {
            let d2 = block_dist_sq(p, block);
            for (k, &v) in d2.iter().enumerate() {
                // Lanes past `len` hold +inf coordinates: their distance is never <= r^2.
                if v <= r_sq {
                    f(self.get(b * LANES + k));
                }
            }
        }
    }
}

/// What a rebuild's range query found: each leaf's points kept where the query wrote them (see
/// `RangeSink`), so the first `len` are the particles `Orthtree::for_each_within` lists, in
/// its order.
#[derive(Debug, Clone, Default)]
struct Found<const D: usize> {
    points: Vec<[f64; D]>,
    len: usize,
}

impl<const D: usize> RangeSink<D> for Found<D> {
    #[inline(always)]
    fn room(&mut self, n: usize) -> &mut [[f64; D]] {
        if self.points.len() < self.len + n {
            self.points.resize(self.len + n, [0.0; D]);
        }
        &mut self.points[self.len..]
    }

    #[inline(always)]
    fn keep(&mut self, kept: usize) {
        self.len += kept;
    }

    const WHOLE_LEAF: bool = true;
}

/// Squared distances from `p` to the particles of a block, each summed axis by axis from 0,
/// as [`dist_sq`] (the tree's formula) sums them.
#[inline(always)]
fn block_dist_sq<const D: usize>(p: &[f64; D], block: &[[f64; LANES]; D]) -> [f64; LANES] {
    let mut d2 = [0.0f64; LANES];
    for i in 0..D {
        for k in 0..LANES {
            let e = p[i] - block[i][k];
            d2[k] += e * e;
        }
    }
    d2
}

#[cfg(test)]
mod tests {
    use super::*;
    use core_lattice::rng::{stream, uniform01};

    /// A random tenuous cloud: points in a box of side 40, at least 1 apart.
    fn cloud<const D: usize>(n: usize, seed: u64) -> (Orthtree<D>, Vec<[f64; D]>) {
        let mut tree = Orthtree::<D>::with_leaf_side(8.0).unwrap();
        let mut pts: Vec<[f64; D]> = Vec::new();
        let mut rng = stream(seed, 0);
        while pts.len() < n {
            let p: [f64; D] = std::array::from_fn(|_| 40.0 * uniform01(&mut rng) - 20.0);
            if tree.nearest_distance(&p).is_none_or(|d| d >= 1.0) {
                pts.push(tree.insert(p).unwrap());
            }
        }
        (tree, pts)
    }

    fn check<const D: usize>(seed: u64) {
        let (tree, pts) = cloud::<D>(600, seed);
        let mut rng = stream(seed, 1);
        let mut near = NearCache::<D>::new();
        assert!(near.nearest(&[0.0; D]).is_none(), "not live: no answer");
        let mut served = 0;
        for _ in 0..300 {
            let c: [f64; D] = std::array::from_fn(|_| 30.0 * uniform01(&mut rng) - 15.0);
            near.rebuild(&tree, &c);
            // Every stored point within the radius is cached, and nothing else.
            let inside = pts
                .iter()
                .filter(|x| dist_sq(x, &c) <= NEAR_RADIUS * NEAR_RADIUS)
                .count();
            assert_eq!(near.len(), inside);
            for _ in 0..10 {
                let u: [f64; D] = std::array::from_fn(|_| 2.0 * uniform01(&mut rng) - 1.0);
                let len = 12.0 * uniform01(&mut rng);
                let p: [f64; D] = std::array::from_fn(|i| c[i] + len * u[i] / D as f64);
                let exact = tree.nearest(&p).unwrap();
                if let Some((d, x)) = near.nearest(&p) {
                    served += 1;
                    // The first cached particle at the smallest squared distance.
                    let first = (0..near.len())
                        .map(|j| near.get(j))
                        .min_by(|a, b| dist_sq(&p, a).total_cmp(&dist_sq(&p, b)))
                        .unwrap();
                    assert_eq!(x, first);
                    // The tree's exact value, bit for bit, and a stored point at it.
                    assert_eq!(d.to_bits(), exact.distance.to_bits());
                    assert_eq!(dist_sq(&p, &x).sqrt().to_bits(), d.to_bits());
                    assert!(pts.contains(&x));
                } else {
                    // Refused only when the proof fails: the answer may lie outside.
                    assert!(
                        near.room(&p)
                            .is_none_or(|room| exact.distance > room - 1e-6)
                    );
                }
                let r = 1.5 * uniform01(&mut rng) + 0.5;
                if near.covers(&p, r) {
                    let mut a = Vec::new();
                    tree.for_each_within(&p, r, |x| a.push(x));
                    let mut b = Vec::new();
                    near.for_each_within(&p, r, |x| b.push(x));
                    let key = |v: &[f64; D]| v.map(f64::to_bits);
                    a.sort_by_key(key);
                    b.sort_by_key(key);
                    assert_eq!(a, b, "same particles in the ball");
                }
            }
        }
        assert!(served > 500, "the cache served only {served} queries");
    }

    #[test]
    fn cache_answers_equal_the_tree_2d() {
        check::<2>(11);
    }

    #[test]
    fn cache_answers_equal_the_tree_3d() {
        check::<3>(12);
    }

    /// Ties go to the first cached particle, whichever lane and block the others sit in.
    #[test]
    fn ties_go_to_the_first_cached_particle() {
        let mut tree = Orthtree::<2>::with_leaf_side(8.0).unwrap();
        // Twelve particles at distance exactly 1.25 from the origin (three blocks of four; the
        // coordinates are exact in the tree's fixed point), then one farther.
        let mut ring = Vec::new();
        for (a, b) in [(0.75, 1.0), (1.0, 0.75), (1.25, 0.0)] {
            for (sa, sb) in [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)] {
                let x = [sa * a, sb * b];
                if !ring.contains(&x) {
                    ring.push(x);
                }
            }
        }
        ring.push([-0.0, 1.25]);
        ring.push([0.0, -1.25]);
        ring.push([2.5, 2.5]);
        for &x in &ring {
            tree.insert(x).unwrap();
        }
        let mut near = NearCache::<2>::new();
        near.rebuild(&tree, &[0.0, 0.0]);
        assert_eq!(near.len(), ring.len());
        let (d, x) = near.nearest(&[0.0, 0.0]).unwrap();
        assert_eq!(d, 1.25);
        let first = (0..near.len())
            .map(|j| near.get(j))
            .find(|y| dist_sq(&[0.0, 0.0], y) == 1.5625)
            .unwrap();
        assert_eq!(x, first);
    }

    #[test]
    fn added_particles_join_the_ball() {
        let (mut tree, _) = cloud::<3>(200, 5);
        let mut near = NearCache::<3>::new();
        let c = [1.0, -2.0, 0.5];
        near.rebuild(&tree, &c);
        let mut rng = stream(9, 0);
        // Particles stored after the build (as another PDLA thread's would be): the ones
        // inside the ball are kept, the ones outside are not.
        let mut kept = 0;
        for _ in 0..40 {
            let u: [f64; 3] = std::array::from_fn(|_| 2.0 * uniform01(&mut rng) - 1.0);
            let len = 20.0 * uniform01(&mut rng);
            let q: [f64; 3] = std::array::from_fn(|i| c[i] + len * u[i] / 3f64.sqrt());
            if tree.nearest_distance(&q).unwrap() < 1.0 {
                continue;
            }
            let before = near.len();
            let stored = tree.insert(q).unwrap();
            near.added(&stored);
            let inside = dist_sq(&stored, &c) <= NEAR_RADIUS * NEAR_RADIUS;
            assert_eq!(near.len(), before + usize::from(inside));
            kept += usize::from(inside);
        }
        assert!(kept >= 3, "only {kept} particles landed in the ball");
        for _ in 0..500 {
            let p: [f64; 3] = std::array::from_fn(|i| c[i] + 12.0 * uniform01(&mut rng) - 6.0);
            if let Some((d, _)) = near.nearest(&p) {
                assert_eq!(d.to_bits(), tree.nearest_distance(&p).unwrap().to_bits());
            }
        }
    }
}
