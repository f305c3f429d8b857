//! What a stored particle changes: the particle count, `R_ext`, the radius of gyration, the
//! state hash, the kept positions, and the log-spaced growth samples of `growth.csv`.
//!
//! Invariants: every stored particle is accounted for exactly once, in arrival order (the
//! state hash is a hash of the stored positions in that order); a sample is taken at the first
//! particle, at every `ceil(N ratio)` after it, and at the final size.

use crate::cluster::Cluster;
use crate::error::SimError;
use crate::farfield::norm;
use crate::params::Params;
use core_lattice::Gyration;
use core_lattice::io::StateHasher;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Number of log-spaced growth samples aimed at.
pub const GROWTH_SAMPLES: f64 = 1000.0;

/// One row of `growth.csv`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// Particles in the cluster.
    pub n: u64,
    /// Radius of gyration.
    pub radius_of_gyration: f64,
    /// Largest centre distance from the origin.
    pub r_ext: f64,
    /// Wall seconds since the start of growth.
    pub seconds: f64,
}

/// Everything that changes when a particle sticks (kept together under PDLA's write lock).
#[derive(Debug)]
pub(crate) struct Growth<const D: usize> {
    /// Particles stored.
    pub(crate) n: u64,
    /// Largest centre distance from the origin.
    pub(crate) r_ext: f64,
    pub(crate) gyration: Gyration<D>,
    pub(crate) hasher: StateHasher,
    /// Positions in arrival order, if kept.
    pub(crate) positions: Option<Vec<[f64; D]>>,
    pub(crate) samples: Vec<Sample>,
    /// The particle count of the next sample.
    pub(crate) next_sample: u64,
    /// Ratio between successive sample sizes, `particles^(1 / GROWTH_SAMPLES)`.
    ratio: f64,
    /// The start of growth (moved back on resume by the seconds already grown).
    pub(crate) started: Instant,
}

impl<const D: usize> Growth<D> {
    pub(crate) fn new(params: &Params) -> Self {
        Growth {
            n: 0,
            r_ext: 0.0,
            gyration: Gyration::new(),
            hasher: StateHasher::new(),
            positions: params.keep_positions.then(Vec::new),
            samples: Vec::new(),
            next_sample: 1,
            ratio: (params.particles as f64).powf(1.0 / GROWTH_SAMPLES),
            started: Instant::now(),
        }
    }

    /// Store `p` in the cluster and account for it; returns the stored position.
    pub(crate) fn add(
        &mut self,
        cluster: &mut Cluster<D>,
        p: [f64; D],
        target: u64,
    ) -> Result<[f64; D], SimError> {
        let q = cluster.insert(p)?;
        self.account(q, target);
        Ok(q)
    }

    /// Accounts for a particle already stored at `q`.
    pub(crate) fn account(&mut self, q: [f64; D], target: u64) {
        self.n += 1;
        self.r_ext = self.r_ext.max(norm(&q));
        self.gyration.push(&q);
        for x in q {
            self.hasher.f64(x);
        }
        if let Some(v) = &mut self.positions {
            v.push(q);
        }
        if self.n >= self.next_sample || self.n == target {
            self.samples.push(Sample {
                n: self.n,
                radius_of_gyration: self.gyration.radius(),
                r_ext: self.r_ext,
                seconds: self.started.elapsed().as_secs_f64(),
            });
            self.next_sample = (self.n + 1).max((self.n as f64 * self.ratio).ceil() as u64);
        }
    }
}
