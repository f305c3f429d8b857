//! The walk's software counters ([`WalkCounts`]): what walkers did, the cost model of a
//! particle on a machine without hardware counters.

/// What walkers did, summed over walkers (and over threads, for a run): the software counts
/// behind the cost of a particle, since this machine class exposes no hardware counters.
/// Counting is a handful of register increments per move, so it is always on. Every move
/// ends in exactly one of: a far-field return, a map jump, a tree or near-cache jump, or a
/// step of `step_min` (with a contact search, by the cache or the tree; a step that ends in a
/// refused contact stops at the contact point).
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct WalkCounts {
    /// Walkers released (a PDLA walker discarded at the re-check counts as released).
    pub walkers: u64,
    /// Moves: calls of the walk's one step, whatever it did.
    pub moves: u64,
    /// Moves in the far field (returned to the birth sphere, or the paper's far jump).
    pub far_field: u64,
    /// Distance-map reads (one per near-field move, except for a walker known to be too
    /// near the cluster for a map to send it jumping; each reads a cell of every level it
    /// needs).
    pub map_reads: u64,
    /// Moves that ended in a jump by the map's bound, without a tree query.
    pub map_jumps: u64,
    /// Nearest-distance answers from the near cache.
    pub near_answers: u64,
    /// Near-cache rebuilds (a range query of the tree each).
    pub near_rebuilds: u64,
    /// Nearest-distance queries of the tree (variable-precision search).
    pub tree_queries: u64,
    /// Tree nodes and leaves those queries read (see `spatial::orthtree::VpEstimate::nodes`).
    pub tree_nodes: u64,
    /// Contact searches of a `step_min` step answered by the near cache.
    pub contact_near: u64,
    /// Contact searches of a `step_min` step answered by the tree.
    pub contact_tree: u64,
    /// Contacts that did not stick (`sticking_probability < 1`): the walker walked on from
    /// the contact point. 0 with probability 1.
    pub refused: u64,
}

impl WalkCounts {
    /// Adds `other`'s counts to these.
    pub fn add(&mut self, other: &WalkCounts) {
        self.walkers += other.walkers;
        self.moves += other.moves;
        self.far_field += other.far_field;
        self.map_reads += other.map_reads;
        self.map_jumps += other.map_jumps;
        self.near_answers += other.near_answers;
        self.near_rebuilds += other.near_rebuilds;
        self.tree_queries += other.tree_queries;
        self.tree_nodes += other.tree_nodes;
        self.contact_near += other.contact_near;
        self.contact_tree += other.contact_tree;
        self.refused += other.refused;
    }
}
