//! The exhaustive baseline: the "no grid" search of the grid-boxing paper.

use super::{ContactSearch, ItemId, SiteSets, coords_of, touches};
use core_lattice::{Direction, MAX_DIM};

/// The grid-boxing paper's all-pairs contact search: the mover is tested against every other live
/// item, particle by particle, comparing one axis at a time and leaving at the first axis on which
/// two particles are more than one step apart. Costs O(s * N) per move for a mover of `s` particles
/// among `N`; keeps no index, so insert, move and merge cost nothing.
#[derive(Debug, Clone, Default)]
pub struct AllPairs {
    coords: Vec<[u64; MAX_DIM]>,
}

impl AllPairs {
    /// A new all-pairs search.
    pub fn new() -> Self {
        Self::default()
    }
}

impl ContactSearch for AllPairs {
    fn name(&self) -> &'static str {
        "all-pairs"
    }

    fn insert(&mut self, _: &SiteSets, _: ItemId) {}

    fn remove(&mut self, _: &SiteSets, _: ItemId) {}

    fn moved(&mut self, _: &SiteSets, _: ItemId, _: &[u64], _: &[u64], _: Direction) {}

    fn merge(&mut self, _: &SiteSets, _: ItemId, _: ItemId, _: usize) {}

    fn contacts(&mut self, sets: &SiteSets, id: ItemId, out: &mut Vec<ItemId>) -> usize {
        out.clear();
        let lattice = sets.lattice();
        self.coords.clear();
        self.coords
            .extend(sets.sites(id).iter().map(|&k| coords_of(lattice, k)));
        let mut examined = 0;
        for &other in sets.live() {
            if other == id {
                continue;
            }
            examined += 1;
            if touches(lattice, &self.coords, sets.sites(other)) {
                out.push(other);
            }
        }
        out.sort_unstable();
        examined
    }
}
