//! The occupancy lattice: which item holds every site.

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
const EMPTY: u32 = u32::MAX;

/// An array holding, for every lattice site, the label of the item on it (4 bytes a site). A
/// contact query is `2d` lookups per particle of the mover, independent of how many items there
/// are; the cost is the memory of the whole lattice, so it suits 2D and 3D lattices, and dense
/// fills, best.
///
/// Sites hold *labels*, and a small table maps labels to item ids. A merge relabels only the
/// smaller of the two items' sites and points the larger one's label at the surviving id, so
/// merging costs O(smaller item), whichever id survives.
#[derive(Debug, Clone)]
pub struct Occupancy {
    cells: Vec<u32>,
    /// Label carried by each item's sites, indexed by item id.
    label_of: Vec<u32>,
    /// Item currently owning each label, indexed by label.
    id_of: Vec<ItemId>,
    seen: StampSet,
    /// Whether the caller guarantees that items never touch between operations (DLCA merges
    /// on contact), which enables the leading-face shortcut of [`Occupancy::contacts`].
    separated: bool,
    /// The item that moved last and the direction it moved, with the indices (into its site
    /// array) of its leading particles: those whose new site it did not occupy before.
    leading_of: Option<(ItemId, Direction)>,
    leading: Vec<u32>,
}

impl Occupancy {
    /// Bytes the occupancy array of `lattice` takes.
    pub fn bytes_needed(lattice: &Lattice) -> u64 {
        lattice.volume().saturating_mul(size_of::<u32>() as u64)
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
            label_of: Vec::new(),
            id_of: Vec::new(),
            seen: StampSet::default(),
            separated: false,
            leading_of: None,
            leading: Vec::new(),
        })
    }

    /// Promise that no two items touch before each move (as in DLCA, where items merge as soon
    /// as they touch). Then the contact query right after a move examines only the mover's
    /// *leading* particles, those whose new site the mover did not hold before: every site next
    /// to a non-leading particle was next to the mover before the move, so holds no other item.
    /// For a fractal cluster this skips a large share of the lookups.
    pub fn with_separated_items(mut self, separated: bool) -> Self {
        self.separated = separated;
        self
    }

    /// The item occupying site `k`, if any.
    #[inline]
    pub fn item_at(&self, k: u64) -> Option<ItemId> {
        let label = self.cells[k as usize];
        (label != EMPTY).then(|| self.id_of[label as usize])
    }

    fn fill(&mut self, sites: &[u64], label: u32) {
        for &k in sites {
            self.cells[k as usize] = label;
        }
    }
}

impl ContactSearch for Occupancy {
    fn name(&self) -> &'static str {
        "lattice"
    }

    fn insert(&mut self, sets: &SiteSets, id: ItemId) {
        let i = id as usize;
        if i >= self.label_of.len() {
            self.label_of.resize(i + 1, EMPTY);
            self.id_of.resize(i + 1, ItemId::MAX);
        }
        // An item's first label is its own id; ids are never reused, so neither are labels.
        self.label_of[i] = id;
        self.id_of[i] = id;
        debug_assert!(
            sets.sites(id)
                .iter()
                .all(|&k| self.cells[k as usize] == EMPTY),
            "items overlap"
        );
        self.fill(sets.sites(id), id);
    }

    fn remove(&mut self, sets: &SiteSets, id: ItemId) {
        self.leading_of = None;
        self.fill(sets.sites(id), EMPTY);
    }

    fn moved(&mut self, _: &SiteSets, id: ItemId, old: &[u64], new: &[u64], dir: Direction) {
        let label = self.label_of[id as usize];
        if self.separated {
            // Particles whose new site the item did not hold before (see
            // `with_separated_items`).
            self.leading.clear();
            for (i, &k) in new.iter().enumerate() {
                if self.cells[k as usize] != label {
                    self.leading.push(i as u32);
                }
            }
            self.leading_of = Some((id, dir));
        }
        self.fill(old, EMPTY);
        debug_assert!(
            new.iter().all(|&k| self.cells[k as usize] == EMPTY),
            "items overlap"
        );
        self.fill(new, label);
    }

    fn merge(&mut self, sets: &SiteSets, into: ItemId, from: ItemId, from_len: usize) {
        self.leading_of = None;
        let (into_sites, from_sites) = sets.merged_parts(into, from_len);
        let (into_label, from_label) = (self.label_of[into as usize], self.label_of[from as usize]);
        if from_sites.len() <= into_sites.len() {
            self.fill(from_sites, into_label);
        } else {
            self.fill(into_sites, from_label);
            self.label_of[into as usize] = from_label;
            self.id_of[from_label as usize] = into;
        }
    }

    fn contacts(&mut self, sets: &SiteSets, id: ItemId, out: &mut Vec<ItemId>) -> usize {
        out.clear();
        self.seen.clear();
        let lattice = sets.lattice();
        let mine = self.label_of[id as usize];
        let sites = sets.sites(id);
        match self.leading_of.take() {
            // Just moved by `dir`, items separated before: only leading particles, and not back
            // towards where they came from (their old site is the item's own or empty).
            Some((moved, dir)) if moved == id => {
                for j in 0..self.leading.len() {
                    let k = sites[self.leading[j] as usize];
                    self.check_site(lattice, k, Some(dir.opposite()), mine, out);
                }
            }
            _ => {
                for &k in sites {
                    self.check_site(lattice, k, None, mine, out);
                }
            }
        }
        out.sort_unstable();
        out.len()
    }
}

impl Occupancy {
    /// Report the items, other than the one labelled `mine`, on the face neighbours of `k`
    /// (all but `skip`), each once per query.
    #[inline(always)]
    fn check_site(
        &mut self,
        lattice: &Lattice,
        k: u64,
        skip: Option<Direction>,
        mine: u32,
        out: &mut Vec<ItemId>,
    ) {
        let x = lattice.coords_array(k);
        for dir in Direction::all(lattice.dim()) {
            if Some(dir) == skip {
                continue;
            }
            if let Some(n) = lattice.neighbour_of(k, &x, dir) {
                let label = self.cells[n as usize];
                if label != EMPTY && label != mine && self.seen.insert(label as usize) {
                    out.push(self.id_of[label as usize]);
                }
            }
        }
    }
}
