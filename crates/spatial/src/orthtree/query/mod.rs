//! Queries: exact nearest neighbour, variable-precision distance (the variable-precision paper,
//! section 3.1, Listing 1) and the fixed-radius range query.
//!
//! One recursive branch-and-bound walk serves the nearest and `vpdist` queries, monomorphised on
//! whether far nodes are approximated (`APPROX`) and whether the nearest point is tracked
//! (`TRACK`). Distances to points are compared squared; a square root is taken only when the
//! best value improves (the paper's section 3.3: "managing orthogonal distances whenever
//! possible, avoiding ... unnecessary calls to the standard function sqrt()").
//!
//! The walk is here; the nodes a bounded query starts from are found in `cover`, the leaf
//! scan is in `leaf` and the range query in `range`.

use super::{EMPTY, Orthtree, decode};
use leaf::nearest_in_leaf;

/// Declares `$cc`, the centre of child `$ci` (bit `i` set: the upper half along axis `i`) of
/// the node of centre `$c`, with `$q` a quarter of the node's side. A macro rather than a
/// function: the walk and the range query are the tree's hottest loops, and this expands to
/// exactly the code they had written out, where a function (even `#[inline(always)]`)
/// changed the machine code the compiler made of `visit`.
macro_rules! child_centre {
    ($cc:ident = $c:expr, $ci:expr, $q:expr) => {
        let mut $cc = $c;
        for (i, x) in $cc.iter_mut().enumerate() {
            if $ci >> i & 1 == 1 {
                *x += $q;
            } else {
                *x -= $q;
            }
        }
    };
}

mod cover;
mod leaf;
mod range;
pub use range::RangeSink;

/// Relative shrink applied to far-node lower bounds `|p - c| - r`, so that rounding in the
/// distance to the centre can never push the bound above a point's computed distance. `2^-44`
/// is about 500 units in the last place: far more than the rounding of a `D <= 8` distance,
/// far less than anything a simulation can notice (1e-8 at a distance of 1e6).
const FAR_SHRINK: f64 = 1.0 / 17_592_186_044_416.0;

/// Visiting order of the children of a node, as masks XORed with the child containing the query
/// point: by number of flipped axes (the paper's son, left and right siblings, then the opposite
/// sibling; the variable-precision paper, Listing 1, lines 22-32), generalised to `D` axes.
const CHILD_ORDER: [[u8; 256]; 9] = child_orders();

const fn child_orders() -> [[u8; 256]; 9] {
    let mut t = [[0u8; 256]; 9];
    let mut d = 0;
    while d <= 8 {
        let n = 1usize << d;
        let mut k = 0;
        let mut pc = 0;
        while pc <= d {
            let mut m = 0;
            while m < n {
                if (m as u32).count_ones() == pc as u32 {
                    t[d][k] = m as u8;
                    k += 1;
                }
                m += 1;
            }
            pc += 1;
        }
        d += 1;
    }
    t
}

/// The nearest stored point and its distance, from [`Orthtree::nearest`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neighbour<const D: usize> {
    /// Stored position of the nearest point (ties: the first found).
    pub point: [f64; D],
    /// Euclidean distance from the query point.
    pub distance: f64,
}

/// A variable-precision distance with where it came from, from [`Orthtree::vpdist_detailed`]
/// (the variable-precision paper, section 3.1: `d(p, q) in [d_app, d_app + 2r]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VpEstimate {
    /// The value [`Orthtree::vpdist`] returns: a lower bound of the exact nearest distance.
    pub distance: f64,
    /// `None` if `distance` is the exact nearest distance (it came from a leaf scan); otherwise
    /// the half diagonal `r` of the far node whose centre gave `distance = |p - c| - r`. The
    /// exact distance then lies in `[distance, distance + 2 r]`.
    pub half_diagonal: Option<f64>,
    /// Nodes and leaves the search read (those not pruned by their box or as far nodes
    /// before their memory was touched): the query's share of the tree's memory traffic.
    pub nodes: u32,
}

/// State of one query walk.
struct Search<const D: usize> {
    p: [f64; D],
    /// A node of side `a` is far when `|p - c|^2 > far_factor * a^2` (`far_factor = kappa^2 D`,
    /// i.e. `|p - c| > kappa * DIAGONAL`).
    far_factor: f64,
    /// Best value so far (exact distance or far-node lower bound).
    best: f64,
    /// `max(best, 0)^2` for exact values the squared distance itself: children whose box is at
    /// least this far are skipped.
    best_sq: f64,
    /// Half diagonal of the node that produced `best`, or 0 if `best` is exact.
    source: f64,
    /// Stored position of the best point (`TRACK` only).
    point: [f64; D],
    /// Nodes and leaves read ([`VpEstimate::nodes`]).
    nodes: u32,
}

impl<const D: usize> Orthtree<D> {
    /// Exact distance from `p` to the nearest stored point, `None` on an empty tree.
    ///
    /// Branch and bound over the tree: the child containing `p` first, then siblings whose box
    /// is closer than the best distance so far (the variable-precision paper, Listing 1 with `kappa
    /// = inf`). The value equals, bit for bit, `sqrt` of the minimum over [`iter`](Self::iter) of
    /// the squared distance summed axis by axis.
    pub fn nearest_distance(&self, p: &[f64; D]) -> Option<f64> {
        self.walk::<false, false>(p, f64::INFINITY).map(|s| s.best)
    }

    /// The nearest stored point and its exact distance, `None` on an empty tree (same walk as
    /// [`nearest_distance`](Self::nearest_distance)).
    pub fn nearest(&self, p: &[f64; D]) -> Option<Neighbour<D>> {
        self.walk::<false, true>(p, f64::INFINITY)
            .map(|s| Neighbour {
                point: s.point,
                distance: s.best,
            })
    }

    /// Variable-precision distance from `p` to the stored points: the variable-precision paper,
    /// section 3.1, Listing 1, in `D` dimensions with precision `kappa` (the paper's value is
    /// [`PAPER_KAPPA`](super::PAPER_KAPPA) = 2). `None` on an empty tree.
    ///
    /// A node whose centre `c` is farther from `p` than `kappa` times its diagonal gives the
    /// lower bound `|p - c| - DIAGONAL / 2` without being descended; near `p` the walk descends
    /// to the leaves and measures exact distances. The result `v` satisfies, with `d` the exact
    /// nearest distance (derivation in the [module docs](super)):
    ///
    /// - `v <= d` always (a walker may jump `v - 1` safely), for every `kappa`;
    /// - `v > d (2 kappa - 1) / (2 kappa + 1)` for `kappa > 1/2` (3/5 of `d` for `kappa = 2`);
    /// - `v = d` whenever `d <= (kappa - 1/2) * DIAGONAL(leaf)`, and for `kappa = +inf`.
    ///
    /// `kappa <= 1/2` still gives a valid lower bound, possibly negative and useless; NaN is
    /// treated as `+inf`. Validate user input with [`check_kappa`](Self::check_kappa). No
    /// allocation; square roots only when the best value improves.
    #[inline]
    pub fn vpdist(&self, p: &[f64; D], kappa: f64) -> Option<f64> {
        if kappa == f64::INFINITY || kappa.is_nan() {
            self.nearest_distance(p)
        } else {
            self.walk::<true, false>(p, far_factor::<D>(kappa))
                .map(|s| s.best)
        }
    }

    /// [`vpdist`](Self::vpdist) together with the half diagonal of the node that produced an
    /// approximate answer (the variable-precision paper, section 3.1: `d(p, q) in [d_app, d_app +
    /// 2r]`), for accuracy studies and tests. Same walk and same value as `vpdist`.
    pub fn vpdist_detailed(&self, p: &[f64; D], kappa: f64) -> Option<VpEstimate> {
        let s = if kappa == f64::INFINITY || kappa.is_nan() {
            self.walk::<false, false>(p, f64::INFINITY)
        } else {
            self.walk::<true, false>(p, far_factor::<D>(kappa))
        }?;
        Some(VpEstimate {
            distance: s.best,
            half_diagonal: (s.source > 0.0).then_some(s.source),
            nodes: s.nodes,
        })
    }

    /// [`vpdist_detailed`](Self::vpdist_detailed) given an upper bound `upper` of the exact
    /// nearest distance (for example the last answer's `distance + 2 half_diagonal` plus the
    /// distance moved since; the bound stays valid while points are only added).
    ///
    /// The walk starts from the at most `2^D` nodes of side `>= 2 upper` that cover the ball
    /// of radius `upper` around `p` (found by descending along their cells' paths, with no
    /// distance tests), instead of from the root, and prunes every node farther than `upper`
    /// from the start. The answer keeps every guarantee of [`vpdist`](Self::vpdist): it is at
    /// most the exact distance (even if `upper` is wrong: every point outside the searched
    /// nodes is farther than `upper`, and if nothing nearer than `upper` is found the query
    /// falls back to the walk from the root), and an approximate answer comes from a far node
    /// whose half diagonal is reported, so the relative gap stays below `2 / (2 kappa + 1)`
    /// and the answer is exact within `(kappa - 1/2) DIAGONAL(leaf)`. It may differ from
    /// `vpdist` either way (nodes are met in another order, so other far nodes give the
    /// bound). `upper` infinite or NaN: same as
    /// [`vpdist_detailed`](Self::vpdist_detailed).
    pub fn vpdist_bounded(&self, p: &[f64; D], kappa: f64, upper: f64) -> Option<VpEstimate> {
        if self.root == EMPTY {
            return None;
        }
        if !(0.0..f64::INFINITY).contains(&upper) {
            return self.vpdist_detailed(p, kappa);
        }
        self.vpdist_bounded_nearest(p, kappa, upper).map(|(e, _)| e)
    }

    /// [`vpdist_bounded`](Self::vpdist_bounded), and when its answer is exact (`half_diagonal`
    /// is `None`) the stored position of a nearest point, at that distance (ties: the first
    /// found). A walker keeps that point: its distance from wherever the walker moves next is
    /// an upper bound of the nearest distance there, usually much tighter than the last answer
    /// plus the distance moved. Same walk and same answer as `vpdist_bounded`. Always inlined:
    /// the hot path of walks instantiated more than once (DLA's plain and variant walks).
    #[inline(always)]
    pub fn vpdist_bounded_nearest(
        &self,
        p: &[f64; D],
        kappa: f64,
        upper: f64,
    ) -> Option<(VpEstimate, Option<[f64; D]>)> {
        if self.root == EMPTY {
            return None;
        }
        let s = if !(0.0..f64::INFINITY).contains(&upper) {
            Err(0)
        } else if kappa == f64::INFINITY || kappa.is_nan() {
            // SAFETY: the tree is not empty (checked above).
            unsafe { self.walk_bounded::<false>(p, f64::INFINITY, upper) }
        } else {
            // SAFETY: the tree is not empty (checked above).
            unsafe { self.walk_bounded::<true>(p, far_factor::<D>(kappa), upper) }
        };
        let s = match s {
            Ok(s) => s,
            Err(read) => {
                let mut s = if kappa == f64::INFINITY || kappa.is_nan() {
                    self.walk::<false, true>(p, f64::INFINITY)?
                } else {
                    self.walk::<true, true>(p, far_factor::<D>(kappa))?
                };
                s.nodes += read;
                s
            }
        };
        let exact = s.source == 0.0;
        Some((
            VpEstimate {
                distance: s.best,
                half_diagonal: (!exact).then_some(s.source),
                nodes: s.nodes,
            },
            exact.then_some(s.point),
        ))
    }

    /// The walk of [`vpdist_bounded`](Self::vpdist_bounded); `Err` with the nodes it read if
    /// nothing nearer than `upper` was found.
    ///
    /// # Safety
    ///
    /// The tree is not empty.
    unsafe fn walk_bounded<const APPROX: bool>(
        &self,
        p: &[f64; D],
        far_factor: f64,
        upper: f64,
    ) -> Result<Search<D>, u32> {
        let mut s = Search {
            p: *p,
            far_factor,
            best: upper,
            best_sq: upper * upper,
            source: 0.0,
            point: [f64::NAN; D],
            nodes: 0,
        };
        let cell = |tree: &Self, node, level, c, half| {
            if box_dist_sq(p, &c, half) >= s.best_sq {
                return;
            }
            // SAFETY: `for_each_cover_cell` passes reached nodes (leaves at level 0) with
            // their levels.
            unsafe {
                if level == 0 {
                    tree.visit_leaf::<APPROX, true>(&mut s, node, c, half);
                } else {
                    tree.visit::<APPROX, true>(&mut s, node, level, c, half);
                }
            }
        };
        // SAFETY: the tree is not empty (the caller's contract).
        unsafe { self.for_each_cover_cell(p, upper, cell) };
        if s.best < upper { Ok(s) } else { Err(s.nodes) }
    }

    /// Centre and half side of the root.
    #[inline]
    fn root_geometry(&self) -> ([f64; D], f64) {
        let half_leaves = (1u64 << (self.root_level - 1)) as f64;
        let c = self
            .root_origin
            .map(|o| (o as f64 + half_leaves) * self.leaf_side);
        (c, half_leaves * self.leaf_side)
    }

    /// Runs the walk from the root; `None` on an empty tree.
    #[inline]
    fn walk<const APPROX: bool, const TRACK: bool>(
        &self,
        p: &[f64; D],
        far_factor: f64,
    ) -> Option<Search<D>> {
        if self.root == EMPTY {
            return None;
        }
        let mut s = Search {
            p: *p,
            far_factor,
            best: f64::INFINITY,
            best_sq: f64::INFINITY,
            source: 0.0,
            point: [f64::NAN; D],
            nodes: 0,
        };
        let (c, half) = self.root_geometry();
        // SAFETY: the root of a non-empty tree (checked above) at its level.
        unsafe { self.visit::<APPROX, TRACK>(&mut s, self.root, self.root_level, c, half) };
        Some(s)
    }

    /// Listing 1, lines 07-11: if the node (centre `c`, half side `half`) is far from `p`,
    /// record its lower bound and return `true` (do not descend).
    #[inline(always)]
    fn try_far(&self, s: &mut Search<D>, c: &[f64; D], half: f64) -> bool {
        let d2 = dist_sq(&s.p, c);
        let side = half + half;
        // Not far (or NaN): descend.
        if d2.partial_cmp(&(s.far_factor * side * side)) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        let r = half * self.sqrt_d_up;
        // Take the square root only if the bound can beat the best value (with slack, so a
        // skipped bound is never below `best`).
        let t = (s.best + r) * (1.0 + 4.0 * FAR_SHRINK);
        if d2 < t * t {
            let v = d2.sqrt() * (1.0 - FAR_SHRINK) - r;
            if v < s.best {
                s.best = v;
                s.best_sq = if v > 0.0 { v * v } else { 0.0 };
                s.source = r;
            }
        }
        true
    }

    /// Listing 1 for an internal node at `level >= 1` with centre `c` and half side `half`.
    ///
    /// # Safety
    ///
    /// `node` is a reached node (the root, or read from a slot of a reached node) of level
    /// `level`.
    unsafe fn visit<const APPROX: bool, const TRACK: bool>(
        &self,
        s: &mut Search<D>,
        node: u32,
        level: u32,
        c: [f64; D],
        half: f64,
    ) {
        if APPROX && self.try_far(s, &c, half) {
            return;
        }
        s.nodes += 1;
        let q = half * 0.5;
        let mut home = 0usize;
        // Per axis, the squared distance from p to the lower and the upper half of the node:
        // the faces c - half, c, c + half are those of the children's boxes, so summing these
        // gives each child's `box_dist_sq` bit for bit, at 2 D instead of 2^D D evaluations.
        let mut slab = [[0.0f64; 2]; D];
        for i in 0..D {
            let x = s.p[i];
            if x >= c[i] {
                home |= 1 << i;
            }
            let lo = (c[i] - half - x).max(x - c[i]).max(0.0);
            let hi = (c[i] - x).max(x - (c[i] + half)).max(0.0);
            slab[i] = [lo * lo, hi * hi];
        }
        let base = node as usize * Self::FANOUT;
        for &m in &CHILD_ORDER[D][..Self::FANOUT] {
            let ci = home ^ m as usize;
            // SAFETY: `node` is a reached node (the caller's contract), `ci < FANOUT`.
            let child = unsafe { self.child(base + ci) };
            if child == EMPTY {
                continue;
            }
            // Listing 1, lines 25, 28, 31: INTERSECTS(CIRCLE(p, min_dist), sibling).
            let mut d2 = 0.0;
            for i in 0..D {
                d2 += slab[i][ci >> i & 1];
            }
            if d2 >= s.best_sq {
                continue;
            }
            child_centre!(cc = c, ci, q);
            // SAFETY: a non-empty slot of a reached node of level `level`: a reached leaf
            // if `level == 1`, else a reached node of level `level - 1`.
            unsafe {
                if level == 1 {
                    self.visit_leaf::<APPROX, TRACK>(s, child, cc, q);
                } else {
                    self.visit::<APPROX, TRACK>(s, child, level - 1, cc, q);
                }
            }
        }
    }

    /// Listing 1, lines 07-19 for a leaf: far test, then exact scan of its points.
    ///
    /// # Safety
    ///
    /// `leaf` is a reached leaf (read from a slot of a reached level-1 node).
    #[inline]
    unsafe fn visit_leaf<const APPROX: bool, const TRACK: bool>(
        &self,
        s: &mut Search<D>,
        leaf: u32,
        c: [f64; D],
        half: f64,
    ) {
        if APPROX && self.try_far(s, &c, half) {
            return;
        }
        s.nodes += 1;
        let origin = c.map(|x| x - half);
        // SAFETY: a reached leaf (the caller's contract); the slice lives for this call only.
        let pts = unsafe { self.leaf_points(leaf) };
        let (best_sq, best_j) = nearest_in_leaf(&s.p, &origin, self.step, pts, s.best_sq);
        if best_j != usize::MAX {
            s.best_sq = best_sq;
            s.best = best_sq.sqrt();
            s.source = 0.0;
            if TRACK {
                let code = pts[best_j];
                for i in 0..D {
                    s.point[i] = decode(origin[i], code[i], self.step);
                }
            }
        }
    }
}

/// `kappa^2 D` for the far test `|p - c|^2 > kappa^2 D a^2` (a node of side `a` has diagonal
/// `a sqrt(D)`). Non-positive `kappa` approximates every node.
#[inline]
fn far_factor<const D: usize>(kappa: f64) -> f64 {
    if kappa > 0.0 {
        kappa * kappa * D as f64
    } else {
        0.0
    }
}

/// Squared distance summed axis by axis from 0 (the order a brute-force loop uses): the formula
/// every query here compares, so a caller that keeps stored positions (as returned by the
/// queries) and measures with this function gets the queries' values bit for bit.
#[inline(always)]
pub fn dist_sq<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    let mut d2 = 0.0;
    for i in 0..D {
        let e = a[i] - b[i];
        d2 += e * e;
    }
    d2
}

/// Squared distance from `p` to the box of centre `c` and half side `half`, computed from the
/// box faces `c +- half` (exact dyadic numbers): by monotonicity of rounding it never exceeds the
/// computed squared distance from `p` to any point inside the box.
#[inline(always)]
fn box_dist_sq<const D: usize>(p: &[f64; D], c: &[f64; D], half: f64) -> f64 {
    let mut d2 = 0.0;
    for i in 0..D {
        let lo = c[i] - half;
        let hi = c[i] + half;
        // Same value as the three-way branch `p < lo`, `p > hi`, inside (one of the two
        // differences is <= 0 whenever the other is positive), without branches.
        let e = (lo - p[i]).max(p[i] - hi).max(0.0);
        d2 += e * e;
    }
    d2
}
