//! The state of a run between two sweeps ([`Snapshot`]), for checkpoints (`--checkpoint-every`,
//! `--resume`). `Simulation::snapshot` and `Simulation::restore` convert to and from it.
//!
//! Invariant: a snapshot holds everything the rest of the run depends on (clusters with their
//! ids and site order, the random stream, the strategy and the grid box side, the records), so
//! a restored run reaches the same final state as one never interrupted.

use super::strategy::SearchEvent;
use crate::params::{Params, Search};
use crate::record::Records;
use core_lattice::rng::SimRng;
use spatial::lattice::ItemId;

/// The state of a run between two sweeps: `Simulation::restore` continues it to the same final
/// state as an uninterrupted run. Serialisable with serde (the `dlca` binary writes it in
/// `run_io`'s checkpoint envelope).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Snapshot {
    pub(super) params: Params,
    pub(super) seed: u64,
    pub(super) sweep: u64,
    pub(super) rng: SimRng,
    /// Live clusters in increasing id, with their sites (k-indices).
    pub(super) clusters: Vec<(ItemId, Vec<u64>)>,
    /// One more than the largest cluster id.
    pub(super) id_bound: u64,
    pub(super) particles: u64,
    pub(super) largest: u64,
    /// The search in use, and the grid box side if it is the grid.
    pub(super) strategy: Search,
    pub(super) grid_side: Option<u64>,
    pub(super) strategy_reason: String,
    pub(super) events: Vec<SearchEvent>,
    pub(super) records: Records,
}

impl Snapshot {
    /// The parameters of the saved run.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The seed of the saved run.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Sweeps done when it was saved.
    pub fn sweeps(&self) -> u64 {
        self.sweep
    }

    /// Checks that the saved state is one a run can be in, before anything is built from it
    /// (a damaged or hand-made checkpoint whose checksum was made right must be an error, not
    /// a panic or an allocation sized by a corrupted count): every site on the lattice and
    /// taken once, the particle count and the largest cluster those of the clusters, ids
    /// increasing below `id_bound`, which the particles bound; every cluster connected and no
    /// two clusters face-adjacent (they would have merged); a grid box side that is a power of
    /// two no longer than the lattice.
    pub(super) fn check(&self, lattice: &core_lattice::Lattice) -> Result<(), String> {
        let volume = lattice.volume();
        let total: u64 = self.clusters.iter().map(|(_, s)| s.len() as u64).sum();
        if total != self.particles || Ok(self.particles) != self.params.particles() {
            return Err(format!(
                "{total} particles in the clusters, {} recorded, {} by the parameters",
                self.particles,
                self.params.particles().unwrap_or(0)
            ));
        }
        // Ids are never more than the initial clusters, at most one per particle.
        if self.id_bound > self.particles.max(1) {
            return Err(format!(
                "cluster id bound {} above the {} particles",
                self.id_bound, self.particles
            ));
        }
        let mut owner = std::collections::HashMap::with_capacity(self.particles as usize);
        let mut previous = None;
        let mut largest = 0;
        for (id, sites) in &self.clusters {
            if previous.is_some_and(|p| p >= *id) || u64::from(*id) >= self.id_bound {
                return Err(format!("cluster id {id} out of order or bound"));
            }
            previous = Some(*id);
            if sites.is_empty() {
                return Err(format!("cluster {id} has no site"));
            }
            largest = largest.max(sites.len() as u64);
            for &k in sites {
                if k >= volume {
                    return Err(format!("site {k} outside the {volume} sites"));
                }
                if owner.insert(k, *id).is_some() {
                    return Err(format!("site {k} taken twice"));
                }
            }
        }
        if largest != self.largest {
            return Err(format!(
                "largest cluster {largest}, {} recorded",
                self.largest
            ));
        }
        for (id, sites) in &self.clusters {
            // Connected: a search from its first site over its own sites reaches them all.
            let mut seen = std::collections::HashSet::from([sites[0]]);
            let mut stack = vec![sites[0]];
            while let Some(k) = stack.pop() {
                for n in lattice.neighbours(k) {
                    match owner.get(&n) {
                        Some(o) if o == id && seen.insert(n) => stack.push(n),
                        Some(o) if o != id => {
                            return Err(format!("clusters {id} and {o} touch"));
                        }
                        _ => {}
                    }
                }
            }
            if seen.len() != sites.len() {
                return Err(format!("cluster {id} is not connected"));
            }
        }
        if let Some(a) = self.grid_side {
            // Tuned at run time, a side may exceed what `--grid-box` accepts, not the lattice.
            let longest = lattice.sizes().iter().copied().max().unwrap_or(1);
            if !a.is_power_of_two() || a > longest.next_power_of_two() {
                return Err(format!("grid box side {a}"));
            }
        }
        Ok(())
    }

    /// Change where the resumed run stops (`--target-clusters`, `--max-sweeps`): the only
    /// parameters that may differ from the saved run's.
    pub fn set_stop(&mut self, target_clusters: u64, max_sweeps: Option<u64>) {
        self.params.target_clusters = target_clusters;
        self.params.max_sweeps = max_sweeps;
    }
}
