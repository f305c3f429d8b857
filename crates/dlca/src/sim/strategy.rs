//! Which contact search a run uses and why ([`choose`]), and installing it over the clusters
//! ([`install`]); the events of the search during a run ([`SearchEvent`]).
//!
//! Invariant: the choice depends only on the parameters, the lattice and the particle count, so
//! it is the same for a run and its restored continuation.

use crate::params::{ParamError, Params, Search};
use crate::rigid::{RigidError, RigidStore};
use crate::store::{ClusterArrays, DoublingGrid, Engine, HaloStore, Indexed, RigidClusters};
use core_lattice::Lattice;
use spatial::lattice::Occupancy;

/// Something that happened to the search during the run, for logs and `run.json`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SearchEvent {
    /// Sweep during which it happened (0: at start).
    pub sweep: u64,
    /// What happened.
    pub what: String,
}

/// Which strategy to use, and why (docs/dlca.md, "The search strategies"). `auto` takes the
/// occupancy lattice where it fits the memory budget, and grid boxes otherwise and in the dilute
/// limit on a large lattice, where their cost follows the particles rather than the sites (the
/// regimes of Hawick, James & Scogings 2006, "Grid-Boxing for Spatial Simulation Performance
/// Optimisation", section V).
pub(super) fn choose(params: &Params, lattice: &Lattice, particles: u64) -> (Search, String) {
    let bytes = Occupancy::bytes_needed(lattice);
    let density = particles as f64 / lattice.volume() as f64;
    match params.search {
        Search::Auto => {
            if bytes > params.max_memory {
                (
                    Search::Grid,
                    format!(
                        "auto: occupancy lattice needs {bytes} bytes, over --max-memory {}: grid boxes",
                        params.max_memory
                    ),
                )
            } else if density < 1e-4 && lattice.volume() > 1 << 26 {
                (
                    Search::Grid,
                    format!(
                        "auto: dilute limit (density {density:.2e} on {} sites): grid boxes, whose cost follows the particles rather than the lattice",
                        lattice.volume()
                    ),
                )
            } else {
                (
                    Search::Lattice,
                    format!(
                        "auto: occupancy lattice fits ({bytes} bytes, density {density:.3}): lattice lookups, O(2d) per moved particle"
                    ),
                )
            }
        }
        other => (other, format!("{} requested", other.name())),
    }
}

/// Install strategy `kind` over the clusters `arrays`, with grid box side `grid_box` for the
/// grids (see [`HaloStore::new`] and [`DoublingGrid::new`]), pushing what happened to `notes`. Fails only for the
/// `lattice` strategy when its occupancy lattice does not fit `params.max_memory` (or a side is
/// beyond the rigid-cluster store's reach).
pub(super) fn install(
    kind: Search,
    arrays: ClusterArrays,
    params: &Params,
    grid_box: Option<u64>,
    notes: &mut Vec<String>,
) -> Result<Engine, ParamError> {
    Ok(match kind {
        Search::Lattice => {
            let lattice = arrays.sets().lattice();
            let too_large = ParamError::TooLarge {
                bytes: Occupancy::bytes_needed(lattice),
                sites: lattice.volume(),
                budget: params.max_memory,
            };
            if Occupancy::bytes_needed(lattice) > params.max_memory {
                return Err(too_large);
            }
            match RigidStore::new(arrays.sets()) {
                Ok(store) => Engine::Rigid(Box::new(RigidClusters::new(store))),
                // Clusters merge as soon as they touch, so they are separated before every move.
                Err(RigidError::Dimension(_)) => {
                    let occupancy = Occupancy::new(lattice, params.max_memory)
                        .map_err(|_| too_large)?
                        .with_separated_items(true);
                    Engine::Occupancy(Indexed::new(arrays, occupancy))
                }
                Err(RigidError::Side(_)) => return Err(too_large),
                Err(RigidError::Alloc(e)) => return Err(e.into()),
            }
        }
        Search::AllPairs | Search::Auto => Engine::all_pairs(arrays),
        Search::Grid => Engine::Grid(Box::new(HaloStore::new(arrays, grid_box, notes))),
        Search::GridDoubling => match DoublingGrid::new(arrays, grid_box, notes) {
            Ok(grid) => Engine::GridDoubling(Box::new(grid)),
            Err(arrays) => Engine::all_pairs(arrays),
        },
    })
}
