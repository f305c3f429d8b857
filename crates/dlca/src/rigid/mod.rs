//! The `lattice` strategy's cluster store: rigid clusters as an origin plus relative sites, with
//! per-direction face and probe lists, over an occupancy lattice of labels.
//!
//! A DLCA cluster never changes shape between merges, it only translates. So each cluster keeps
//! its particles as coordinates *relative* to an origin, and a move changes the origin alone
//! (O(1)) instead of rewriting every particle's k-index. What the occupancy lattice and the
//! contact query need from a move by the unit vector `e` depends only on the shape `C` and `e`,
//! so it is worked out once per shape (at the start and after each merge, N - 1 times in a
//! run) and kept per direction:
//!
//! - the *face* `F(e) = {s in C : s + e not in C}`. A move by `e` covers exactly the sites
//!   `F(e)` (in the new frame) and vacates exactly `F(-e)` (in the old frame): only those
//!   occupancy cells are written; interior particles keep their label.
//! - the *probes* `P(e) = {q in N(C) : q + e not in C or N(C)}`, where `N(C)` is the set of
//!   sites face-adjacent to `C` and outside it. Before a move no other cluster is in `C` or
//!   `N(C)` (clusters merge as soon as they touch), so after it the only sites that can hold a
//!   cluster in contact are the new neighbours, `P(e)` in the new frame: one lookup each, each
//!   such site once.
//!
//! On a fractal DLCA cluster about half the particles are on each face, and the probes number
//! about as many, so a move costs a fraction of the particles in memory traffic and nothing
//! per interior particle.
//!
//! Coordinates: along a periodic axis relative coordinates of particles lie in `[0, L)` (taken
//! modulo `L`) and absolute ones are `origin + relative` reduced modulo `L`; along a wall axis
//! they are plain differences (the cluster cannot wrap) and the origin is one of the cluster's
//! own particles, so it stays on the lattice. Neighbour and probe coordinates reach one step
//! beyond a particle's, so a probe can fall beyond a wall; such probes are skipped. Wall
//! blocking is O(1) from the cluster's extent along the axis.
//!
//! This module owns the choice of kernel: [`RigidStore`] holds a [`Rigid`] store for the
//! lattice's dimension and the frame that applies to it, and [`RigidStore::new`] is the one
//! place where the runtime dimension selects a const-generic kernel. The dimensions listed in
//! its dispatch are those where rigid clusters pay: beyond 3, a fractal cluster has nearly every
//! particle on every face and about `2d - 1` probes per particle and direction, so the lists
//! cost more than moving every particle, and the `lattice` strategy uses the plain occupancy
//! lattice instead (`RigidError::Dimension`; see `crate::sim`'s strategy installation).

mod clusters;
mod frame;
mod geometry;
mod members;
#[cfg(test)]
mod tests;

#[cfg(test)]
use clusters::RowMoves;
use clusters::{MAX_SIDE, Rigid};
use core_lattice::{Blocked, Direction};
use frame::{AnyFrame, Frame, Pow2Frame, SpreadFrame};
use geometry::Geometry;
use spatial::lattice::{ItemId, SiteSets};

/// Why the rigid-cluster store does not take a lattice.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub(crate) enum RigidError {
    /// No rigid kernel for this dimension (see the module documentation).
    #[error("no rigid-cluster kernel in {0} dimensions")]
    Dimension(usize),
    /// A side longer than the store's relative coordinates reach.
    #[error("side {0} is longer than the rigid-cluster store handles ({MAX_SIDE})")]
    Side(u64),
    /// The occupancy lattice could not be allocated.
    #[error(transparent)]
    Alloc(#[from] run_io::memory::AllocError),
}

/// Defines [`RigidStore`] with three variants (general frame, power-of-two frame, spread
/// frame) per dimension listed, its constructor's dimension dispatch, and the `each!`
/// delegation. Adding a dimension is one line in the invocation below.
macro_rules! rigid_store {
    ($($dim:literal => $any:ident, $pow2:ident, $spread:ident;)+) => {
        /// [`Rigid`] for the dimension of the lattice: with the spread frame where it applies
        /// and costs no memory, else the power-of-two frame where that applies, else the
        /// general one.
        #[derive(Debug, Clone)]
        pub(crate) enum RigidStore {
            $(
                #[doc = concat!("Any lattice in ", stringify!($dim), "D.")]
                $any(Rigid<$dim, AnyFrame>),
                #[doc = concat!("All-periodic power-of-two lattice in ", stringify!($dim), "D.")]
                $pow2(Rigid<$dim, Pow2Frame>),
                #[doc = concat!("All-periodic power-of-two lattice in ", stringify!($dim), "D, spread site index.")]
                $spread(Rigid<$dim, SpreadFrame>),
            )+
        }

        /// Evaluate `$e` with `$r` bound to the store inside whichever variant is installed.
        macro_rules! each {
            ($self:expr, $r:ident => $e:expr) => {
                match $self {
                    $(
                        RigidStore::$any($r) => $e,
                        RigidStore::$pow2($r) => $e,
                        RigidStore::$spread($r) => $e,
                    )+
                }
            };
        }

        impl RigidStore {
            /// The store for the clusters of `sets` (same ids), or why there is none.
            pub(crate) fn new(sets: &SiteSets) -> Result<Self, RigidError> {
                let l = sets.lattice();
                if let Some(&side) = l.sizes().iter().find(|&&s| s > MAX_SIDE) {
                    return Err(RigidError::Side(side));
                }
                match l.dim() {
                    $(
                        $dim => {
                            let spread = Geometry::<$dim>::spread(l)
                                .filter(Geometry::spread_costs_no_memory);
                            if let Some(geo) = spread {
                                let frame = SpreadFrame::new(&geo).expect("a spread index");
                                return Ok(RigidStore::$spread(Rigid::new(sets, geo, frame)?));
                            }
                            let geo = Geometry::<$dim>::new(l);
                            Ok(match Pow2Frame::new(&geo) {
                                Some(frame) => RigidStore::$pow2(Rigid::new(sets, geo, frame)?),
                                None => RigidStore::$any(Rigid::new(sets, geo, AnyFrame)?),
                            })
                        }
                    )+
                    d => Err(RigidError::Dimension(d)),
                }
            }
        }
    };
}

rigid_store! {
    1 => D1, P1, S1;
    2 => D2, P2, S2;
    3 => D3, P3, S3;
}

impl RigidStore {
    /// Live cluster ids.
    pub(crate) fn live(&self) -> &[ItemId] {
        each!(self, r => &r.live)
    }

    /// Number of particles of cluster `id`.
    pub(crate) fn len_of(&self, id: ItemId) -> usize {
        each!(self, r => r.len_of(id))
    }

    /// Whether `id` is live.
    pub(crate) fn contains(&self, id: ItemId) -> bool {
        each!(self, r => r.contains(id))
    }

    /// See [`Rigid::try_move`]; returns the number of contacts found. The move and the contact
    /// search are one pass, so every contact found counts as a candidate examined.
    pub(crate) fn try_move(
        &mut self,
        id: ItemId,
        dir: Direction,
        out: &mut Vec<ItemId>,
    ) -> Result<usize, Blocked> {
        each!(self, r => r.try_move(id, dir, out))?;
        Ok(out.len())
    }

    /// Move large clusters by rows as `mode` says (the lattice's first side must be at least 64).
    #[cfg(test)]
    pub(crate) fn set_row_moves(&mut self, mode: RowMoves) {
        each!(self, r => {
            assert!(r.geo.bit_rows(), "rows too short to move by");
            r.row_moves = mode;
        })
    }

    /// See [`Rigid::prefetch_record`].
    #[inline]
    pub(crate) fn prefetch_record(&self, id: ItemId) {
        each!(self, r => r.prefetch_record(id))
    }

    /// See [`Rigid::prefetch_lists`].
    #[inline]
    pub(crate) fn prefetch_lists(&self, id: ItemId) {
        each!(self, r => r.prefetch_lists(id))
    }

    /// See [`Rigid::merge`].
    pub(crate) fn merge(&mut self, into: ItemId, from: ItemId) {
        each!(self, r => r.merge(into, from))
    }

    /// See [`Rigid::finish`].
    pub(crate) fn finish(&mut self, id: ItemId) {
        each!(self, r => r.finish(id))
    }

    /// Panic unless the store is consistent (see [`Rigid::check`]).
    pub(crate) fn check(&mut self) {
        each!(self, r => r.check())
    }

    /// The clusters as k-index arrays (absolute sites), with the same ids.
    pub(crate) fn to_sets(&self) -> SiteSets {
        each!(self, r => r.to_sets())
    }
}
