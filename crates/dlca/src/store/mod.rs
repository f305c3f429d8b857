//! The cluster stores and contact searches of DLCA, behind one interface
//! ([`ClusterStore`]), and the [`Engine`] holding whichever is installed.
//!
//! - all-pairs and, in 4 and 5 dimensions, the occupancy lattice: a `spatial` contact search
//!   over the clusters as k-index arrays ([`indexed`]);
//! - grid boxes with a halo per cluster and a box side tuned at run time ([`halo`]);
//! - the paper's grid boxes, which track bounding boxes to double the box side ([`doubling`]);
//! - the occupancy lattice with rigid clusters in 1 to 3 dimensions ([`rigid`]).
//!
//! Invariant: every store gives the same trajectory (bit-identical state hashes); the
//! simulation never asks which one is installed. The doubling grid may hand its clusters over to
//! all-pairs during a merge ([`Merged::to_all_pairs`]); [`Engine`] makes the switch.

/// Inside an `impl ClusterStore`: the methods that query and move the clusters (`live`,
/// `contains`, `len_of`, `try_move`), forwarded either to the structure that holds them, `$e`
/// (an expression of `$s`, the store), which has methods of the same names and signatures
/// (`forward_clusters!(s => s.inner)`), or, for [`Engine`], to the installed store
/// (`forward_clusters!(each)`).
macro_rules! forward_clusters {
    ($s:ident => $e:expr) => {
        forward_clusters!(@methods ($s => $e));
    };
    (each) => {
        forward_clusters!(@methods each);
    };
    (@methods $to:tt) => {
        #[inline]
        fn live(&self) -> &[ItemId] {
            forward_clusters!(@call self, $to, live())
        }

        #[inline]
        fn contains(&self, id: ItemId) -> bool {
            forward_clusters!(@call self, $to, contains(id))
        }

        #[inline]
        fn len_of(&self, id: ItemId) -> usize {
            forward_clusters!(@call self, $to, len_of(id))
        }

        #[inline]
        fn try_move(
            &mut self,
            id: ItemId,
            dir: Direction,
            contacts: &mut Vec<ItemId>,
        ) -> Result<usize, Blocked> {
            forward_clusters!(@call self, $to, try_move(id, dir, contacts))
        }
    };
    (@call $store:expr, ($s:ident => $e:expr), $method:ident($($arg:expr),*)) => {{
        let $s = $store;
        $e.$method($($arg),*)
    }};
    (@call $store:expr, each, $method:ident($($arg:expr),*)) => {
        each!($store, s => s.$method($($arg),*))
    };
}

mod arrays;
mod doubling;
mod halo;
mod indexed;
mod rigid;
mod strategy;

pub(crate) use arrays::ClusterArrays;
pub(crate) use doubling::DoublingGrid;
pub(crate) use halo::HaloStore;
pub(crate) use indexed::Indexed;
pub(crate) use rigid::RigidClusters;
pub(crate) use strategy::{ClusterStore, Merged};

use crate::params::Search;
use core_lattice::{Blocked, Direction};
use spatial::lattice::{AllPairs, ItemId, Occupancy, SiteSets};

/// The installed strategy. An enum rather than a trait object, so that each move costs one
/// match and the stores' searches are called directly.
#[derive(Debug)]
pub(crate) enum Engine {
    /// All-pairs.
    AllPairs(Indexed<AllPairs>),
    /// Grid boxes with a halo per cluster.
    Grid(Box<HaloStore>),
    /// The paper's grid boxes, doubling with the largest cluster.
    GridDoubling(Box<DoublingGrid>),
    /// The `lattice` strategy where rigid clusters do not pay (4 and 5 dimensions).
    Occupancy(Indexed<Occupancy>),
    /// The `lattice` strategy with rigid clusters.
    Rigid(Box<RigidClusters>),
}

/// Evaluate `$e` with `$s` bound to the installed store.
macro_rules! each {
    ($self:expr, $s:ident => $e:expr) => {
        match $self {
            Engine::AllPairs($s) => $e,
            Engine::Grid($s) => $e,
            Engine::GridDoubling($s) => $e,
            Engine::Occupancy($s) => $e,
            Engine::Rigid($s) => $e,
        }
    };
}

impl Engine {
    /// All-pairs over `arrays`.
    pub(crate) fn all_pairs(arrays: ClusterArrays) -> Self {
        Engine::AllPairs(Indexed::new(arrays, AllPairs::new()))
    }
}

impl ClusterStore for Engine {
    fn kind(&self) -> Search {
        each!(self, s => s.kind())
    }

    fn grid_side(&self) -> Option<u64> {
        each!(self, s => s.grid_side())
    }

    forward_clusters!(each);

    #[inline]
    fn prefetch_record(&self, id: ItemId) {
        each!(self, s => s.prefetch_record(id))
    }

    #[inline]
    fn prefetch_lists(&self, id: ItemId) {
        each!(self, s => s.prefetch_lists(id))
    }

    /// Merges, then installs all-pairs in place of a store that has stopped paying.
    fn merge(&mut self, survivor: ItemId, others: &[ItemId], notes: &mut Vec<String>) -> Merged {
        let merged = each!(self, s => s.merge(survivor, others, notes));
        if merged.to_all_pairs {
            *self = Engine::all_pairs(self.take_arrays());
        }
        merged
    }

    fn sets(&self) -> &SiteSets {
        each!(self, s => s.sets())
    }

    fn forget_views(&mut self) {
        each!(self, s => s.forget_views())
    }

    fn check(&self) {
        each!(self, s => s.check())
    }

    fn take_arrays(&mut self) -> ClusterArrays {
        each!(self, s => s.take_arrays())
    }
}
