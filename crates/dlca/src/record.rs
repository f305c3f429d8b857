//! What a DLCA run records as it goes (docs/dlca.md, "Outputs"): always the number of
//! clusters and the largest cluster per sweep; with `--timing` the wall time of each sweep; with
//! `--histogram` the number of candidate clusters examined per move at chosen sweeps (Hawick,
//! James & Scogings 2006, "Grid-Boxing for Spatial Simulation Performance Optimisation",
//! Figs. 4, 7, 8). Observables that were not asked for cost one branch per sweep or move.

use crate::params::Params;
use core_lattice::IntHistogram;

/// One row of `sweeps.csv`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SweepRecord {
    /// Sweep number (0: the initial state).
    pub sweep: u64,
    /// Clusters after the sweep.
    pub clusters: u64,
    /// Size of the largest cluster after the sweep.
    pub largest: u64,
    /// Wall seconds of the sweep (with `--timing`).
    pub seconds: Option<f64>,
}

/// The records of a run.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Records {
    sweeps: Vec<SweepRecord>,
    histogram_sweeps: Vec<u64>,
    histograms: Vec<(u64, IntHistogram)>,
    /// Whether the current sweep is one whose candidates are histogrammed.
    sampling: bool,
    moves: u64,
    examined: u128,
}

impl Records {
    /// Empty records for a run with `params`.
    pub fn new(params: &Params) -> Self {
        let mut histogram_sweeps = params.histogram_sweeps.clone();
        histogram_sweeps.sort_unstable();
        histogram_sweeps.dedup();
        Records {
            sweeps: Vec::new(),
            histogram_sweeps,
            histograms: Vec::new(),
            sampling: false,
            moves: 0,
            examined: 0,
        }
    }

    pub(crate) fn begin_sweep(&mut self, sweep: u64) {
        self.sampling = self.histogram_sweeps.binary_search(&sweep).is_ok();
        if self.sampling {
            self.histograms.push((sweep, IntHistogram::new()));
        }
    }

    #[inline]
    pub(crate) fn record_move(&mut self, examined: usize) {
        self.moves += 1;
        self.examined += examined as u128;
        if self.sampling {
            if let Some((_, h)) = self.histograms.last_mut() {
                h.add(examined as u64);
            }
        }
    }

    pub(crate) fn record_sweep(
        &mut self,
        sweep: u64,
        clusters: u64,
        largest: u64,
        seconds: Option<f64>,
    ) {
        self.sweeps.push(SweepRecord {
            sweep,
            clusters,
            largest,
            seconds,
        });
    }

    /// One record per sweep, starting with sweep 0 (the initial state).
    pub fn sweeps(&self) -> &[SweepRecord] {
        &self.sweeps
    }

    /// `(sweep, histogram of candidates examined per move)` for each sampled sweep.
    pub fn histograms(&self) -> &[(u64, IntHistogram)] {
        &self.histograms
    }

    /// Moves made (blocked and immobile clusters excluded).
    pub fn moves(&self) -> u64 {
        self.moves
    }

    /// Mean number of candidate clusters examined per move over the whole run.
    pub fn mean_examined(&self) -> f64 {
        self.examined as f64 / self.moves.max(1) as f64
    }
}
