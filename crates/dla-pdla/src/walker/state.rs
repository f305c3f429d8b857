//! What a walker remembers between moves ([`WalkState`]): bounds of its distance to the
//! cluster, where its map reads start, its near cache, the variant's motion and the counts of
//! what it did. Everything it holds stays valid while particles are only added.

use super::counts::WalkCounts;
use crate::cluster::MapLevel;
use crate::near::{NEAR_RADIUS, NearCache, REBUILD_UPPER};
use crate::params::Params;
use crate::space::{Dim, Space};
use crate::substrate::{Substrate, drift_direction};
use core_lattice::rng::Rng;
use spatial::orthtree::{Orthtree, dist_sq};

impl<const D: usize> WalkState<D>
where
    Dim<D>: Space<D>,
{
    /// A unit vector for a move of length `len`: uniform for a diffusive walker, the von
    /// Mises-Fisher exit law of a drifting one ([`drift_direction`], concentration
    /// `Pe len / 2`), the walker's own direction for a ballistic one.
    #[inline(always)]
    pub(super) fn heading<R: Rng + ?Sized>(&self, len: f64, rng: &mut R) -> [f64; D] {
        match self.motion {
            Motion::Diffusive => Dim::<D>::direction(rng),
            Motion::Ballistic => self.aim,
            Motion::Drift { half_pe } => drift_direction::<D, R>(half_pe * len, rng),
        }
    }
}

/// How walkers move between contacts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Motion {
    /// Brownian: every jump and step in a uniform direction.
    Diffusive,
    /// Brownian with a drift towards the substrate, `half_pe = Pe / 2` in the walk's units.
    Drift { half_pe: f64 },
    /// Straight lines: every move along the walker's `aim`.
    Ballistic,
}

/// What a walker remembers between moves: an upper bound of its exact distance to the
/// nearest centre (`+inf` when unknown), and the stored particle found nearest at the last
/// exact tree query (`anchor`). Both stay valid while particles are only added, so PDLA
/// threads keep them when other threads store particles.
#[derive(Debug, Clone)]
pub(crate) struct WalkState<const D: usize> {
    pub(super) upper: f64,
    pub(super) anchor: Option<[f64; D]>,
    /// The distance map level that answered the walker's last read, where the next starts.
    pub(super) map_level: MapLevel,
    /// Where the first read of a walker that knows nothing starts (just born or back from
    /// the far field): the level the last such read ended at. Those walkers are all about
    /// the birth distance from the cluster, and the coarsest level, the safe start, is
    /// usually two levels above the one that answers them. The answer does not depend on the
    /// start (`Cluster::map_bounds_from`).
    pub(super) fresh_level: MapLevel,
    /// Whether the walker's next map read is its first since it knew nothing.
    pub(super) fresh: bool,
    /// The stored particle the walker's last move ended in contact with.
    pub(super) touched: Option<[f64; D]>,
    /// Whether the near cache is used: `params.near_cache`, and the tree's answers are exact
    /// wherever the cache answers (`(kappa - 1/2)` leaf diagonals cover [`NEAR_RADIUS`]).
    pub(super) near_on: bool,
    /// Distances within which the tree's `vpdist` is exact: `(kappa - 1/2)` leaf diagonals.
    pub(super) exact_within: f64,
    /// Whether a contact may be refused: `params.sticking_probability < 1`.
    pub(crate) refuse: bool,
    /// The direction of the step that ended in the last contact.
    pub(super) step: [f64; D],
    /// Whether the last contact was with a deposit's substrate (`touched` is then `None`).
    pub(super) on_wall: bool,
    /// How the walker moves: `params.ballistic`, `params.drift`.
    pub(super) motion: Motion,
    /// A ballistic walker's direction (on a substrate, straight down).
    pub(super) aim: [f64; D],
    /// `params.substrate()`.
    pub(super) substrate: Option<Substrate>,
    pub(super) near: NearCache<D>,
    /// What the walkers of this state did, summed over them.
    pub(crate) counts: WalkCounts,
}

impl<const D: usize> WalkState<D> {
    pub(crate) fn new(params: &Params) -> Self {
        let kappa = params.precision;
        let exact_within = if kappa.is_nan() {
            f64::INFINITY
        } else {
            (kappa - 0.5) * params.leaf_side * (D as f64).sqrt()
        };
        WalkState {
            upper: f64::INFINITY,
            anchor: None,
            map_level: MapLevel::default(),
            fresh_level: MapLevel::default(),
            fresh: true,
            touched: None,
            near_on: params.near_cache && exact_within >= NEAR_RADIUS,
            exact_within,
            refuse: params.sticking_probability < 1.0,
            step: [0.0; D],
            on_wall: false,
            motion: if params.ballistic {
                Motion::Ballistic
            } else if params.drift > 0.0 {
                Motion::Drift {
                    half_pe: 0.5 * params.drift,
                }
            } else {
                Motion::Diffusive
            },
            aim: std::array::from_fn(|i| if i + 1 == D { -1.0 } else { 0.0 }),
            substrate: params.substrate(),
            near: NearCache::new(),
            counts: WalkCounts::default(),
        }
    }

    /// Whether the walk has a substrate, a drift or ballistic walkers: the walkers then move
    /// through [`Walker::advance`](super::Walker::advance)'s `VARIANT` code.
    pub(crate) fn variant(&self) -> bool {
        self.substrate.is_some() || self.motion != Motion::Diffusive
    }

    /// `Pe / 2`, the drift velocity in the walk's units (0 without drift).
    pub(super) fn half_pe(&self) -> f64 {
        match self.motion {
            Motion::Drift { half_pe } => half_pe,
            _ => 0.0,
        }
    }

    /// A deposit's lower bound of the centre distance to what the walker at `p` may touch,
    /// from a lower bound `b` of the distance to the stored points (particles and images):
    /// `b` is a bound of the periodic distance only up to the images' margin; the height
    /// above the deposit's top `h` bounds it too; the substrate is touched at `z = 0`, at a
    /// centre distance of 1 in the walk's terms at `z`.
    #[inline(always)]
    pub(super) fn deposit_bound(&self, b: f64, p: &[f64; D], h: f64) -> f64 {
        let margin = self.substrate.map_or(f64::INFINITY, |s| s.margin);
        let z = p[D - 1];
        b.min(margin).max(z - h).min(z + 1.0)
    }

    /// A new walker: nothing known.
    pub(crate) fn reset(&mut self) {
        self.counts.walkers += 1;
        self.forget();
    }

    /// Forgets what the walker knew (it left for the far field).
    pub(super) fn forget(&mut self) {
        self.upper = f64::INFINITY;
        self.anchor = None;
        self.map_level = self.fresh_level;
        self.fresh = true;
        self.touched = None;
        self.on_wall = false;
        self.near.reset();
    }

    /// The stored particle the walker touched, once a move has returned its sticking position.
    pub(crate) fn touched(&self) -> Option<&[f64; D]> {
        self.touched.as_ref()
    }

    /// A particle another PDLA thread stored while this walker moves: the near cache keeps it
    /// if it lies in the cache's ball (the bounds stay valid as they are).
    #[inline]
    pub(crate) fn particle_added(&mut self, q: &[f64; D]) {
        self.near.added(q);
    }

    /// Whether the near cache can still answer anything at `p` (it is built and `p` lies
    /// inside its ball). A cache that cannot is dropped here: it needs no more particles
    /// ([`particle_added`](Self::particle_added)) until it is rebuilt from the tree, which then
    /// holds them all.
    #[inline]
    pub(crate) fn near_useful(&mut self, p: &[f64; D]) -> bool {
        if self.near.covers(p, 0.0) {
            return true;
        }
        self.near.reset();
        false
    }

    /// Drops the near cache: it missed particles another PDLA thread stored, and a rebuild
    /// reads them from the tree.
    #[inline]
    pub(crate) fn drop_near(&mut self) {
        self.near.reset();
    }

    /// Whether a stored particle lies within `r` of `p`, answered by the near cache when its
    /// ball covers that one (`None`: ask the tree). The cache holds every particle of its ball
    /// stored before the walker's last [`particle_added`](Self::particle_added).
    #[inline]
    pub(crate) fn any_within_cached(&self, p: &[f64; D], r: f64) -> Option<bool> {
        if !self.near.covers(p, r) {
            return None;
        }
        let mut found = false;
        self.near.for_each_within(p, r, |_| found = true);
        Some(found)
    }

    /// Whether the near cache is built and holds `p` (tests: how often the cache serves).
    #[cfg(test)]
    pub(crate) fn cache_holds(&self, p: &[f64; D]) -> bool {
        self.near.covers(p, 0.0)
    }

    /// The exact nearest distance and a particle at it from the near cache, rebuilding the
    /// cache around `p` when it cannot answer and `p` is known to be close to the cluster;
    /// `None` when the tree must answer.
    #[inline(always)]
    pub(super) fn near_query(
        &mut self,
        p: &[f64; D],
        tree: &Orthtree<D>,
    ) -> Option<(f64, [f64; D])> {
        if !self.near_on {
            return None;
        }
        if let Some(hit) = self.near.nearest(p) {
            return Some(hit);
        }
        if self.upper(p) <= REBUILD_UPPER {
            self.counts.near_rebuilds += 1;
            self.near.rebuild(tree, &super::detached(p));
            return self.near.nearest(p);
        }
        None
    }

    /// An upper bound of the nearest distance from `p`: the smaller of `upper` (the last
    /// answer plus every distance moved since) and the distance to the anchor particle (the
    /// walker jumped in a random direction, so the anchor is typically about `sqrt 2` times
    /// the last answer away rather than twice), with a relative margin for rounding.
    #[inline]
    pub(super) fn upper(&self, p: &[f64; D]) -> f64 {
        match self.anchor {
            Some(a) => self.upper.min(dist_sq(p, &a).sqrt() * (1.0 + 1e-9) + 1e-9),
            None => self.upper,
        }
    }
}
