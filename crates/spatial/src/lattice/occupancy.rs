//! The occupancy lattice: the cluster id of every site.

use super::{ContactSearch, ItemId, SiteSets, StampSet};
use core_lattice::{Direction, Lattice};

/// Why an occupancy lattice cannot be built.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum OccupancyError {
    /// The lattice needs more memory than allowed.
    #[error(
        "an occupancy lattice of {sites} sites needs {bytes} bytes, over the budget of {budget} bytes; use the grid or all-pairs search"
    )]
    TooLarge {
        /// Number of sites.
        sites: u64,
        /// Bytes needed.
        bytes: u64,
        /// Bytes allowed.
        budget: u64,
    },
}

/// Marks an empty site.
const EMPTY: ItemId = ItemId::MAX;

/// An array holding the item id of every lattice site (4 bytes a site). A contact query is `2d`
/// lookups per particle of the mover, independent of how many items there are; the cost is the
/// memory of the whole lattice, so it suits 2D and 3D lattices, and dense fills, best.
#[derive(Debug, Clone)]
pub struct Occupancy {
    cells: Vec<ItemId>,
    seen: StampSet,
}

impl Occupancy {
    /// Bytes the occupancy array of `lattice` takes.
    pub fn bytes_needed(lattice: &Lattice) -> u64 {
        lattice.volume().saturating_mul(size_of::<ItemId>() as u64)
    }

    /// An empty occupancy lattice, refusing one that needs more than `budget_bytes`.
    pub fn new(lattice: &Lattice, budget_bytes: u64) -> Result<Self, OccupancyError> {
        let bytes = Self::bytes_needed(lattice);
        let too_large = OccupancyError::TooLarge {
            sites: lattice.volume(),
            bytes,
            budget: budget_bytes,
        };
        if bytes > budget_bytes {
            return Err(too_large);
        }
        let sites = usize::try_from(lattice.volume()).map_err(|_| too_large)?;
        Ok(Occupancy {
            cells: vec![EMPTY; sites],
            seen: StampSet::default(),
        })
    }

    /// The item occupying site `k`, if any.
    pub fn item_at(&self, k: u64) -> Option<ItemId> {
        Some(self.cells[k as usize]).filter(|&c| c != EMPTY)
    }

    fn fill(&mut self, sites: &[u64], id: ItemId) {
        for &k in sites {
            self.cells[k as usize] = id;
        }
    }
}

impl ContactSearch for Occupancy {
    fn name(&self) -> &'static str {
        "lattice"
    }

    fn insert(&mut self, sets: &SiteSets, id: ItemId) {
        debug_assert!(
            sets.sites(id)
                .iter()
                .all(|&k| self.cells[k as usize] == EMPTY),
            "items overlap"
        );
        self.fill(sets.sites(id), id);
    }

    fn remove(&mut self, sets: &SiteSets, id: ItemId) {
        self.fill(sets.sites(id), EMPTY);
    }

    fn moved(&mut self, _: &SiteSets, id: ItemId, old: &[u64], new: &[u64], _: Direction) {
        self.fill(old, EMPTY);
        debug_assert!(
            new.iter().all(|&k| self.cells[k as usize] == EMPTY),
            "items overlap"
        );
        self.fill(new, id);
    }

    fn merge(&mut self, _: &SiteSets, into: ItemId, _: ItemId, from_sites: &[u64]) {
        self.fill(from_sites, into);
    }

    fn contacts(&mut self, sets: &SiteSets, id: ItemId, out: &mut Vec<ItemId>) -> usize {
        out.clear();
        self.seen.clear();
        let lattice = sets.lattice();
        for &k in sets.sites(id) {
            for dir in Direction::all(lattice.dim()) {
                if let Some(n) = lattice.neighbour(k, dir) {
                    let c = self.cells[n as usize];
                    if c != EMPTY && c != id && self.seen.insert(c as usize) {
                        out.push(c);
                    }
                }
            }
        }
        out.sort_unstable();
        out.len()
    }
}
