//! One walker's moves (Sosa-Herrera & Rodriguez-Romo, "Variable precision distance search for
//! random fractal cluster simulations", section 3.2): born on the birth sphere, returned to it
//! (or jumping and dying) in the far field, jumping by a lower bound of its distance to the
//! cluster (distance maps, then the orthtree's `vpdist` or the walker's near cache), or leaving
//! the empty ball of the map cell that gave the bound at its harmonic measure's exit point, and
//! taking `step_min` steps near it, until a step ends in exact contact and the walker sticks
//! (always with `sticking_probability` 1; otherwise with that probability, the walker walking
//! on from the contact point when it does not).
//!
//! Invariants: a move never brings the walker's centre closer than 1 to a particle stored
//! when the move starts (jumps stay within a lower bound of the distance minus 1, or inside a
//! ball whose centre is at least its radius plus 1 from every particle; steps stop at the first
//! contact; a walker left in contact by a refused sticking may step away from the
//! particle it touches, never into it); the walker's memory (`WalkState`) holds only bounds that
//! stay valid while particles are added, and is reset for every new walker. The walk is a pure
//! function of the random stream and the stored particles: the near cache and the tree give the
//! same answers bit for bit. With `sticking_probability` 1 nothing else is drawn from the
//! stream, so the walk is the one of the plain model bit for bit.

mod counts;
mod state;

pub use counts::WalkCounts;
pub(crate) use state::{Motion, WalkState};

use crate::cluster::{Cluster, MapBall};
use crate::contact::{contact, first_contact_with, wall_contact};
use crate::params::{FarField, Params};
use crate::space::{Dim, Space};
use crate::substrate::ballistic_start;
use core_lattice::rng::{Rng, uniform01};
use spatial::orthtree::VpEstimate;

pub use crate::contact::first_contact;
pub use crate::space::MAP_JUMP_MIN;
/// The far field starts at `|p| > r_b * FAR_FIELD_MARGIN`.
pub const FAR_FIELD_MARGIN: f64 = 1.0 + 1e-9;

/// A random walker: the centre of a ball of diameter 1.
#[derive(Debug, Clone, Copy)]
pub struct Walker<const D: usize> {
    /// Current centre.
    pub p: [f64; D],
}

impl<const D: usize> Walker<D>
where
    Dim<D>: Space<D>,
{
    /// A walker born uniformly on the sphere of radius `r_b`.
    pub fn born<R: Rng + ?Sized>(r_b: f64, rng: &mut R) -> Self {
        let mut p = Dim::<D>::direction(rng);
        p.iter_mut().for_each(|x| *x *= r_b);
        Walker { p }
    }

    /// A new walker of the run whose memory is `state` (reset for it): born on the birth
    /// sphere of radius `r_b` ([`born`](Self::born)), or on a substrate's launch plane at
    /// height `r_b`, or, ballistic in radial growth, entering the birth sphere along its own
    /// straight line ([`ballistic_start`]).
    #[inline(always)]
    pub(crate) fn launch<R: Rng + ?Sized>(r_b: f64, state: &mut WalkState<D>, rng: &mut R) -> Self {
        if let Some(s) = state.substrate {
            return Walker {
                p: s.launch(r_b, rng),
            };
        }
        if let Motion::Ballistic = state.motion {
            let (p, aim) = ballistic_start(r_b, rng, Dim::<D>::direction::<R>);
            state.aim = aim;
            return Walker { p };
        }
        Walker::born(r_b, rng)
    }

    /// One move on a non-empty cluster whose particles all lie within `r_ext` of the origin.
    /// Returns the sticking position (centre distance 1 to the particle first touched) when
    /// the move ends in contact and the walker sticks (with `params.sticking_probability`;
    /// one that does not stays at the contact point).
    pub fn step<R: Rng + ?Sized>(
        &mut self,
        cluster: &Cluster<D>,
        r_ext: f64,
        params: &Params,
        rng: &mut R,
    ) -> Option<[f64; D]> {
        let state = &mut WalkState::new(params);
        if let Some(s) = state.substrate {
            s.wrap(&mut self.p);
        }
        let q = self.advance::<true, R>(state, cluster, r_ext, params, rng)?;
        if state.refuse {
            return self.settle(q, state, cluster, params, rng);
        }
        Some(q)
    }

    /// [`step`](Self::step) with the walker's memory `state` (reset it for each new walker):
    /// an upper bound of its distance to the cluster, so the tree query starts from the few
    /// nodes covering that ball ([`Orthtree::vpdist_bounded`](spatial::orthtree::Orthtree::vpdist_bounded)) rather than from the root.
    ///
    /// Every contact is returned, whatever `params.sticking_probability`: with it below 1 the
    /// caller then asks [`settle`](Self::settle) whether the walker sticks.
    ///
    /// `VARIANT`: the walk may have a substrate, a drift or ballistic walkers
    /// ([`WalkState::variant`]); a plain walk is compiled without them (the callers choose
    /// once per walker).
    #[inline(always)]
    pub(crate) fn advance<const VARIANT: bool, R: Rng + ?Sized>(
        &mut self,
        state: &mut WalkState<D>,
        cluster: &Cluster<D>,
        r_ext: f64,
        params: &Params,
        rng: &mut R,
    ) -> Option<[f64; D]> {
        let r_b = r_ext + params.birth_gap;
        state.counts.moves += 1;
        if VARIANT && let Some(s) = state.substrate {
            // A deposit's far field: above the launch plane, returned to it exactly.
            if self.p[D - 1] > r_b * FAR_FIELD_MARGIN {
                state.counts.far_field += 1;
                state.forget();
                self.p = s.return_to_plane(&self.p, r_b, state.half_pe(), rng);
                return None;
            }
            return self.near_move::<true, true, R>(state, cluster, r_ext, params, rng);
        }
        // Far field. The margin keeps a walker just returned to the birth sphere (whose norm
        // may round to slightly above r_b) in the near field, which is valid everywhere;
        // without it a walker at r_b (1 + 1e-16) would be "returned" to itself forever.
        // The norm's square root is taken only for a walker whose squared norm comes within
        // a relative 1e-12 of the margin's square (far above their rounding), so the test is
        // the one on the norm itself, and a move in the near field does not wait for a root.
        let r_far = r_b * FAR_FIELD_MARGIN;
        let r2: f64 = self.p.iter().map(|x| x * x).sum();
        if r2 > r_far * r_far * (1.0 - 1e-12)
            && let r = r2.sqrt()
            && r > r_far
        {
            state.counts.far_field += 1;
            state.forget();
            if VARIANT && let Motion::Ballistic = state.motion {
                // A straight walker that left the birth sphere never comes back: the next one.
                state.counts.walkers += 1;
                *self = Walker::launch(r_b, state, rng);
                return None;
            }
            match params.far_field {
                FarField::Return => {
                    self.p = Dim::<D>::return_to_sphere(&detached(&self.p), r_b, rng)
                }
                FarField::Jump => {
                    if r > params.death_ratio * r_b {
                        *self = Walker::born(r_b, rng);
                    } else {
                        // Every particle is within r_ext of the origin, so within distance
                        // r - r_ext - 1 the walker cannot touch one.
                        self.jump::<VARIANT, R>(r - r_ext - 1.0, state, rng);
                    }
                }
            }
            return None;
        }
        self.near_move::<false, VARIANT, R>(state, cluster, r_ext, params, rng)
    }

    /// One move in the near field (see [`advance`](Self::advance)); `DEPOSIT`: on a
    /// substrate, whose wall bounds the jumps and may be touched, whose images bound what
    /// the index's distances say, and whose lateral edges wrap the walker.
    #[inline(always)]
    fn near_move<const DEPOSIT: bool, const VARIANT: bool, R: Rng + ?Sized>(
        &mut self,
        state: &mut WalkState<D>,
        cluster: &Cluster<D>,
        r_ext: f64,
        params: &Params,
        rng: &mut R,
    ) -> Option<[f64; D]> {
        // Near field. First the distance map: one byte read bounds the distance to the
        // cluster from below; a walker at least a few diameters out jumps by it. A bound capped
        // by the coarsest map only says "at least its cap": in the large empty regions of a big
        // cluster the walker may be much farther from it, and jumps of the cap would take
        // (region / cap)^2 moves to cross them, a cost growing with the cluster. There the
        // tree's distance, a few hundred nanoseconds, gives the long jump instead.
        //
        // A walker known to be within `1 + MAP_JUMP_MIN` of the cluster skips the maps: their
        // lower bound cannot send it jumping and no map's cell is capped that near. What it
        // would lose is a map's upper bound, and where the tree's answer is exact (within
        // `exact_within`) it is the same whatever bound its query starts from (and the near
        // cache's is the tree's).
        let mut floor = 0.0;
        let mut ball = MapBall::default();
        let bounds = if !DEPOSIT
            && state.upper <= 1.0 + Dim::<D>::MAP_JUMP_MIN
            && state.upper <= state.exact_within
        {
            None
        } else if DEPOSIT {
            state.counts.map_reads += 1;
            cluster.deposit_map_bounds(&self.p, state.upper)
        } else {
            state.counts.map_reads += 1;
            let bounds =
                cluster.map_bounds_from(&self.p, state.upper, &mut state.map_level, &mut ball);
            if state.fresh {
                state.fresh = false;
                state.fresh_level = state.map_level.dense_only();
            }
            bounds
        };
        if let Some((lb, ub, capped)) = bounds {
            // The map bounds the distance from above too: a walker with no answer yet (just
            // born or returned) or a looser one starts its tree query from the few nodes
            // around that ball rather than from the root.
            state.upper = state.upper.min(ub);
            // A deposit's bound stops at the images' margin (or the height above its top), so
            // there a capped floor beyond the margin needs no tree query either.
            let lb = if DEPOSIT {
                state.deposit_bound(lb, &self.p, r_ext)
            } else {
                lb
            };
            if capped && !DEPOSIT {
                floor = lb;
            } else if lb - 1.0 > Dim::<D>::MAP_JUMP_MIN {
                state.counts.map_jumps += 1;
                // A diffusive walker leaves the answering cell's whole empty ball (about its
                // centre `z`, radius the centre's clearance less a diameter) where Brownian
                // motion from `p` would first leave it. That ball holds the ball of `p`'s own
                // bound, which is `|p - z|` smaller, so the move is as exact and longer: a
                // quarter to a third fewer moves a particle (`docs/dla.md`).
                if !DEPOSIT && (!VARIANT || state.motion == Motion::Diffusive) && ball.lower == lb {
                    let big_r = ball.radius();
                    if let Some(y) = Dim::<D>::exit_ball(&self.p, &ball.centre, big_r, rng) {
                        self.p = y;
                        // The walker moved at most the radius plus its distance from the
                        // centre, which is at most `clear - lower` (see `Reading`): a bound
                        // known before the exit point, so the next move does not wait for
                        // the square root of the distance moved.
                        let moved = big_r + (ball.clear - ball.lower);
                        state.upper += moved * (1.0 + 1e-9) + 1e-9;
                        return None;
                    }
                }
                self.jump::<VARIANT, R>(lb - 1.0, state, rng);
                state.upper += (lb - 1.0) * (1.0 + 1e-9);
                if DEPOSIT {
                    self.wrap(state);
                }
                return None;
            } else if capped {
                floor = lb;
            }
        }
        // Then the tree: a lower bound on the distance to the nearest centre.
        // Near the cluster the walker's near cache gives the same exact answer as the tree.
        let tree = cluster.tree();
        let (est, nearest) = match state.near_query(&self.p, tree) {
            Some((distance, x)) => {
                state.counts.near_answers += 1;
                (
                    VpEstimate {
                        distance,
                        half_diagonal: None,
                        nodes: 0,
                    },
                    Some(x),
                )
            }
            None => {
                state.counts.tree_queries += 1;
                let at = detached(&self.p);
                match tree.vpdist_bounded_nearest(&at, params.precision, state.upper(&at)) {
                    Some(answer) => {
                        state.counts.tree_nodes += u64::from(answer.0.nodes);
                        answer
                    }
                    // Only a deposit starts empty.
                    None => (
                        VpEstimate {
                            distance: f64::INFINITY,
                            half_diagonal: None,
                            nodes: 0,
                        },
                        None,
                    ),
                }
            }
        };
        state.anchor = nearest;
        // The exact distance is at most the estimate + 2 r (the gap of a far node's bound), with
        // a relative margin for the rounding of that bound.
        state.upper = (est.distance + 2.0 * est.half_diagonal.unwrap_or(0.0)) * (1.0 + 1e-9) + 1e-9;
        // Both the tree's estimate and a capped map bound are lower bounds: jump by the larger.
        let mut delta = est.distance.max(floor);
        if DEPOSIT {
            delta = state.deposit_bound(delta, &self.p, r_ext);
        }
        if delta - 1.0 > params.step_min {
            self.jump::<VARIANT, R>(delta - 1.0, state, rng);
            state.upper += (delta - 1.0) * (1.0 + 1e-9);
            if DEPOSIT {
                self.wrap(state);
            }
            return None;
        }
        state.upper += params.step_min * (1.0 + 1e-9);
        let u = if VARIANT {
            state.heading(params.step_min, rng)
        } else {
            Dim::<D>::direction(rng)
        };
        let r = params.step_min + 1.0;
        // `covers` is false unless the cache was built, which only `near_query` does, and only
        // when the cache is on.
        let t = if state.near.covers(&self.p, r) {
            state.counts.contact_near += 1;
            // The same particles as the tree's range query (see `near`), so the same contact.
            let mut best = (f64::INFINITY, [0.0; D]);
            state.near.for_each_within(&self.p, r, |q| {
                contact::<D, false>(&self.p, &u, &q, &mut best)
            });
            (best.0 <= params.step_min).then_some(best)
        } else {
            state.counts.contact_tree += 1;
            first_contact_with::<D, false>(tree, &detached(&self.p), &u, params.step_min)
        };
        if DEPOSIT
            && let Some(tw) = wall_contact::<false>(self.p[D - 1], u[D - 1], params.step_min)
            && t.is_none_or(|(tp, _)| tw < tp)
        {
            let mut q = self.p;
            for i in 0..D - 1 {
                q[i] += tw * u[i];
            }
            q[D - 1] = 0.0;
            state.touched = None;
            state.on_wall = true;
            state.step = u;
            return Some(q);
        }
        if let Some((t, touched)) = t {
            let mut q = self.p;
            for i in 0..D {
                q[i] += t * u[i];
            }
            state.touched = Some(touched);
            state.on_wall = false;
            state.step = u;
            return Some(q);
        }
        for i in 0..D {
            self.p[i] += params.step_min * u[i];
        }
        if DEPOSIT {
            self.wrap(state);
        }
        None
    }

    /// Wraps a deposit's walker into the strip; one that crossed an edge forgets its bounds
    /// and near cache, which were about the other side's images.
    #[inline]
    fn wrap(&mut self, state: &mut WalkState<D>) {
        if let Some(s) = state.substrate
            && s.wrap(&mut self.p)
        {
            state.forget();
        }
    }

    /// [`settle`](Self::settle) through a copy of the walker, written back: the walk loops
    /// call this, so that their walker's own address is never taken and its position stays
    /// in registers from one move to the next (see [`detached`]).
    #[inline(always)]
    pub(crate) fn settle_detached<R: Rng + ?Sized>(
        &mut self,
        q: [f64; D],
        state: &mut WalkState<D>,
        cluster: &Cluster<D>,
        params: &Params,
        rng: &mut R,
    ) -> Option<[f64; D]> {
        let mut moved = *self;
        let settled = moved.settle(q, state, cluster, params, rng);
        *self = moved;
        settled
    }

    /// What becomes of a walker whose last move ([`advance`](Self::advance)) ended in contact
    /// at `q`, when contacts may be refused (`params.sticking_probability < 1`, `state`'s
    /// `refuse`): the sticking position, or `None` when the walker walks on. The callers ask
    /// only then, so the walk of probability 1 is compiled as it was before the parameter.
    ///
    /// A centre at distance <= 1 counts as touched only if the step points into it (see
    /// [`contact`]): a walker left in contact by a refused sticking sits at distance 1 (or, by
    /// rounding, just inside) of the particle it touched, and every step would otherwise touch
    /// it again at once. The plain search counts such a centre at `t = 0` whatever the
    /// direction, so a contact at the walker's own position is searched again under that rule
    /// (the same particles, from the near cache or the tree as the move did); one further on
    /// is the same under both rules. The contact then sticks with probability
    /// `params.sticking_probability` (one uniform draw from `rng`); otherwise the walker stays
    /// at the contact point, the move counts as `refused`, and the walk goes on from there.
    /// The walker's bounds stay valid: the move raised them by a whole step, and the walker
    /// moves at most that.
    pub(crate) fn settle<R: Rng + ?Sized>(
        &mut self,
        q: [f64; D],
        state: &mut WalkState<D>,
        cluster: &Cluster<D>,
        params: &Params,
        rng: &mut R,
    ) -> Option<[f64; D]> {
        let u = state.step;
        let (q, touched) = if q == self.p {
            let len = params.step_min;
            let found = if state.near.covers(&self.p, len + 1.0) {
                let mut best = (f64::INFINITY, [0.0; D]);
                state.near.for_each_within(&self.p, len + 1.0, |x| {
                    contact::<D, true>(&self.p, &u, &x, &mut best)
                });
                (best.0 <= len).then_some(best)
            } else {
                first_contact_with::<D, true>(cluster.tree(), &self.p, &u, len)
            };
            let wall = state
                .substrate
                .and_then(|_| wall_contact::<true>(self.p[D - 1], u[D - 1], len))
                .filter(|&tw| found.is_none_or(|(tp, _)| tw < tp));
            match (found, wall) {
                (_, Some(tw)) => {
                    let mut q: [f64; D] = std::array::from_fn(|i| self.p[i] + tw * u[i]);
                    q[D - 1] = 0.0;
                    (q, None)
                }
                (Some((t, touched)), None) => {
                    (std::array::from_fn(|i| self.p[i] + t * u[i]), Some(touched))
                }
                (None, None) => {
                    state.touched = None;
                    for i in 0..D {
                        self.p[i] += len * u[i];
                    }
                    self.wrap(state);
                    return None;
                }
            }
        } else if state.on_wall {
            (q, None)
        } else {
            (
                q,
                Some(state.touched.expect("a contact sets the particle touched")),
            )
        };
        if uniform01(rng) >= params.sticking_probability {
            state.counts.refused += 1;
            state.touched = None;
            self.p = q;
            self.wrap(state);
            return None;
        }
        state.on_wall = touched.is_none();
        state.touched = touched;
        Some(q)
    }

    /// A jump of `len` in the walker's direction for it ([`WalkState::heading`]; uniform in
    /// a plain walk).
    #[inline(always)]
    fn jump<const VARIANT: bool, R: Rng + ?Sized>(
        &mut self,
        len: f64,
        state: &WalkState<D>,
        rng: &mut R,
    ) {
        let u = if VARIANT {
            state.heading(len, rng)
        } else {
            Dim::<D>::direction(rng)
        };
        for i in 0..D {
            self.p[i] += len * u[i];
        }
    }
}

/// A copy of the walker's position `p` for a call that is not inlined (tree queries, contact
/// searches, the near cache's rebuild, the far-field return), so that the callee takes the
/// copy's address and not the position's. A position whose address escapes lives on the
/// stack, and every move then stores it and loads it back on the walk's chain of dependent
/// operations; otherwise it stays in registers from one move to the next. `black_box` keeps
/// the compiler from handing the callee the position's own slot instead of the copy. Only
/// speed depends on it: the copy holds the same numbers.
#[inline(always)]
pub(crate) fn detached<const D: usize>(p: &[f64; D]) -> [f64; D] {
    std::hint::black_box(*p)
}

/// A uniformly random unit vector: [`Space::direction`] of [`Dim<D>`].
#[inline]
pub fn direction<const D: usize, R: Rng + ?Sized>(rng: &mut R) -> [f64; D]
where
    Dim<D>: Space<D>,
{
    Dim::<D>::direction(rng)
}
