//! What a stored particle changes: the particle count, `R_ext`, the radius of gyration, the
//! state hash, the kept positions, the log-spaced growth samples of `growth.csv`, and the
//! streams a run writes as it grows (`positions.npy`, `growth.csv`).
//!
//! Invariants: every stored particle is accounted for exactly once, in arrival order (the
//! state hash is a hash of the stored positions in that order, and `positions.npy` holds them
//! in that order); a sample is taken at the first particle, at every
//! `max(N + 1, ceil(N r))` after it with `r = 10^(1 / SAMPLES_PER_DECADE)` (a schedule that
//! does not depend on the target size, so a run extended to more particles samples as a run
//! made to that size directly), and at the final size.

use crate::cluster::Cluster;
use crate::error::SimError;
use crate::farfield::norm;
use crate::params::Params;
use core_lattice::Gyration;
#[cfg(feature = "files")]
use run_io::NpyWriter;
use run_io::StateHasher;
use run_io::schema::{Column, Dtype, Form, Output};
use serde::{Deserialize, Serialize};
#[cfg(feature = "files")]
use std::fs::File;
#[cfg(feature = "files")]
use std::io::{BufWriter, Write};
#[cfg(feature = "files")]
use std::path::Path;
use std::time::Instant;

/// Growth samples per decade of N (every N up to about 87, where the log spacing exceeds one
/// particle; 1,200 samples to 1e6 and 1,800 to 1e9).
pub const SAMPLES_PER_DECADE: f64 = 200.0;

/// `growth.csv` in the schema (`crate::output::SCHEMA`): one row per growth sample.
pub const GROWTH: Output = Output {
    file: "growth.csv",
    form: Form::Csv,
    python: "growth",
    when: None,
    columns: &[
        Column::new("n", Dtype::Uint64, "particles"),
        Column::new("radius_of_gyration", Dtype::Float64, "diameters"),
        Column::new(
            "r_ext",
            Dtype::Float64,
            "diameters (largest centre distance from the seed)",
        ),
        Column::new("seconds", Dtype::Float64, "s since growth started").measured(),
    ],
};

/// The column names of `growth.csv`, from the schema ([`GROWTH`]).
pub const GROWTH_COLUMNS: [&str; 4] = {
    let c = GROWTH.columns;
    assert!(c.len() == 4, "growth.csv's columns are these four");
    [c[0].name, c[1].name, c[2].name, c[3].name]
};

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

/// The first sample size after `n` on the schedule.
pub(crate) fn next_on_schedule(n: u64) -> u64 {
    let ratio = 10f64.powf(1.0 / SAMPLES_PER_DECADE);
    (n + 1).max((n as f64 * ratio).ceil() as u64)
}

/// The files a run streams into its output directory as it grows.
#[cfg(feature = "files")]
#[derive(Debug)]
pub(crate) struct Streams {
    /// `positions.npy`: every stored position, in arrival order.
    pub(crate) positions: Option<NpyWriter>,
    /// `positions_parent.npy`: every stored particle's parent, beside the positions (with
    /// `connectivity`).
    pub(crate) parents: Option<NpyWriter>,
    /// `growth.csv`, a line per sample, flushed as it is taken.
    pub(crate) growth: BufWriter<File>,
    /// The first write error (the run goes on; it is reported at the next checkpoint or at the
    /// end).
    pub(crate) error: Option<std::io::Error>,
}

#[cfg(feature = "files")]
impl Streams {
    /// `growth.csv` in `dir` holding `samples`, and `positions` as given.
    pub(crate) fn open(
        dir: &Path,
        samples: &[Sample],
        positions: Option<NpyWriter>,
        parents: Option<NpyWriter>,
    ) -> std::io::Result<Self> {
        let path = dir.join("growth.csv");
        let file = File::create(&path)
            .map_err(|e| std::io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
        let mut s = Streams {
            positions,
            parents,
            growth: BufWriter::new(file),
            error: None,
        };
        writeln!(s.growth, "{}", GROWTH_COLUMNS.join(","))?;
        for row in samples {
            s.sample(row);
        }
        s.growth.flush()?;
        Ok(s)
    }

    fn sample(&mut self, s: &Sample) {
        let line = writeln!(
            self.growth,
            "{},{},{},{}",
            s.n, s.radius_of_gyration, s.r_ext, s.seconds
        );
        if let Err(e) = line.and_then(|()| self.growth.flush()) {
            self.error.get_or_insert(e);
        }
    }

    /// Flushes both files and records the row count in `positions.npy` (a complete array
    /// after this); the first error of the run so far, if any.
    pub(crate) fn sync(&mut self) -> Result<(), SimError> {
        if let Some(e) = self.error.take() {
            return Err(SimError::Stream(e.to_string()));
        }
        self.growth
            .flush()
            .map_err(|e| SimError::Stream(e.to_string()))?;
        for log in [&mut self.positions, &mut self.parents]
            .into_iter()
            .flatten()
        {
            log.sync().map_err(|e| SimError::Stream(e.to_string()))?;
        }
        Ok(())
    }
}

/// Where a walker that stuck at the contact point `p`, touching the stored particle `touched`,
/// is stored: `p` itself with noise reduction `f = 1` (the plain model, bit for bit: nothing
/// is computed), else `touched + f (p - touched)`, at distance `f` from `touched` (fastDLA's
/// `noiseReductionFactor`). The contact point is at distance at least 1 from every stored
/// particle, so the stored position is at least `f` from every one (it lies within `1 - f` of
/// the contact point).
#[inline]
pub(crate) fn noise_reduced<const D: usize>(
    p: [f64; D],
    touched: Option<&[f64; D]>,
    f: f64,
) -> [f64; D] {
    match touched {
        Some(t) if f < 1.0 => std::array::from_fn(|i| t[i] + f * (p[i] - t[i])),
        _ => p,
    }
}

/// Everything that changes when a particle sticks (kept together under PDLA's write lock).
#[derive(Debug)]
pub(crate) struct Growth<const D: usize> {
    /// Particles stored.
    pub(crate) n: u64,
    /// Largest centre distance from the origin; on a substrate, the deposit's height (the
    /// largest centre height above the substrate's contact plane).
    pub(crate) r_ext: f64,
    /// Whether the run grows a deposit on a substrate.
    pub(crate) deposit: bool,
    pub(crate) gyration: Gyration<D>,
    pub(crate) hasher: StateHasher,
    /// Positions in arrival order, if kept.
    pub(crate) positions: Option<Vec<[f64; D]>>,
    /// Parents in arrival order, if kept (with the positions, and `connectivity`).
    pub(crate) parents: Option<Vec<i64>>,
    pub(crate) samples: Vec<Sample>,
    /// The particle count of the next scheduled sample.
    pub(crate) next_sample: u64,
    /// Whether the last sample was taken only because the target was reached (not on the
    /// schedule): a run extended past it drops it.
    pub(crate) last_off_schedule: bool,
    /// The start of growth (moved back on resume by the seconds already grown).
    pub(crate) started: Instant,
    /// What the run streams to its output directory, once opened.
    #[cfg(feature = "files")]
    pub(crate) streams: Option<Streams>,
}

impl<const D: usize> Growth<D> {
    pub(crate) fn new(params: &Params) -> Self {
        Growth {
            n: 0,
            r_ext: 0.0,
            deposit: params.substrate().is_some(),
            gyration: Gyration::new(),
            hasher: StateHasher::new(),
            positions: params.keep_positions.then(Vec::new),
            parents: (params.keep_positions && params.connectivity).then(Vec::new),
            samples: Vec::new(),
            next_sample: 1,
            last_off_schedule: false,
            started: Instant::now(),
            #[cfg(feature = "files")]
            streams: None,
        }
    }

    /// Store `p` in the cluster and account for it; returns the stored position.
    pub(crate) fn add(
        &mut self,
        cluster: &mut Cluster<D>,
        p: [f64; D],
        touched: Option<&[f64; D]>,
        target: u64,
    ) -> Result<[f64; D], SimError> {
        let parent = cluster.parent_of(touched)?;
        let q = cluster.insert_beside(p, touched, self.n as u32)?;
        self.account(q, parent, target);
        Ok(q)
    }

    /// Accounts for a particle already stored at `q`, with its parent if recorded.
    pub(crate) fn account(&mut self, q: [f64; D], parent: Option<i64>, target: u64) {
        self.n += 1;
        self.r_ext = self
            .r_ext
            .max(if self.deposit { q[D - 1] } else { norm(&q) });
        self.gyration.push(&q);
        self.hasher.f64s(&q);
        if let Some(v) = &mut self.positions {
            v.push(q);
        }
        #[cfg(feature = "files")]
        if let Some(s) = &mut self.streams
            && let Some(log) = &mut s.positions
            && s.error.is_none()
            && let Err(e) = log.push(&q)
        {
            s.error = Some(std::io::Error::other(e.to_string()));
        }
        if let Some(parent) = parent {
            if let Some(v) = &mut self.parents {
                v.push(parent);
            }
            #[cfg(feature = "files")]
            if let Some(s) = &mut self.streams
                && let Some(log) = &mut s.parents
                && s.error.is_none()
                && let Err(e) = log.push_int(parent)
            {
                s.error = Some(std::io::Error::other(e.to_string()));
            }
        }
        let scheduled = self.n >= self.next_sample;
        if scheduled || self.n == target {
            let sample = Sample {
                n: self.n,
                radius_of_gyration: self.gyration.radius(),
                r_ext: self.r_ext,
                seconds: self.started.elapsed().as_secs_f64(),
            };
            self.samples.push(sample);
            #[cfg(feature = "files")]
            if let Some(s) = &mut self.streams {
                s.sample(&sample);
            }
            self.last_off_schedule = !scheduled;
        }
        if scheduled {
            self.next_sample = next_on_schedule(self.n);
        }
    }
}
