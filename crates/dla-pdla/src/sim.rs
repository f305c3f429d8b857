//! The growth of one cluster: walkers, sticking, observables (MODELS.md section 2; seed 002,
//! sections 3.2 to 3.4).

use crate::farfield::{norm, return_to_sphere};
use crate::params::{FarField, Params, ParamsError};
use core_lattice::io::StateHasher;
use core_lattice::rng::{Rng, SimRng, stream, stream_id, unit_vector};
use core_lattice::{Gyration, LogLogFit};
use parking_lot::{Mutex, RwLock, RwLockReadGuard};
use serde::Serialize;
use spatial::orthtree::{Orthtree, OrthtreeError};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

/// Stream purpose of the serial walker (`stream_id(PURPOSE_WALK, 0)`).
pub const PURPOSE_WALK: u32 = 1;
/// Stream purpose of PDLA walker threads (`stream_id(PURPOSE_PDLA, thread)`).
pub const PURPOSE_PDLA: u32 = 2;
/// PDLA re-check: a new particle closer than this to a stored one is discarded (MODELS.md).
pub const OVERLAP_DISTANCE: f64 = 1.0 - 1e-6;
/// The far field starts at `|p| > r_b * FAR_FIELD_MARGIN`.
pub const FAR_FIELD_MARGIN: f64 = 1.0 + 1e-9;
/// Number of log-spaced growth samples aimed at.
pub const GROWTH_SAMPLES: f64 = 1000.0;

/// Errors of a run.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// Invalid parameters.
    #[error(transparent)]
    Params(#[from] ParamsError),
    /// `D` does not match `params.dim`.
    #[error("Simulation<{0}> built with --dim {1}")]
    DimMismatch(usize, usize),
    /// The orthtree refused a particle (coordinate range or capacity).
    #[error("storing a particle: {0}")]
    Tree(#[from] OrthtreeError),
}

/// One row of `growth.csv`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
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
struct Growth<const D: usize> {
    n: u64,
    r_ext: f64,
    gyration: Gyration<D>,
    hasher: StateHasher,
    positions: Option<Vec<[f64; D]>>,
    samples: Vec<Sample>,
    next_sample: u64,
    ratio: f64,
    started: Instant,
}

impl<const D: usize> Growth<D> {
    fn new(params: &Params) -> Self {
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

    /// Store `p` in the tree and account for it; returns the stored position.
    fn add(
        &mut self,
        tree: &mut Orthtree<D>,
        p: [f64; D],
        target: u64,
    ) -> Result<[f64; D], OrthtreeError> {
        let q = tree.insert(p)?;
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
        Ok(q)
    }
}

/// A random walker (seed 002, section 3.2).
#[derive(Debug, Clone, Copy)]
pub struct Walker<const D: usize> {
    /// Current centre.
    pub p: [f64; D],
}

impl<const D: usize> Walker<D> {
    /// A walker born uniformly on the sphere of radius `r_b`.
    pub fn born<R: Rng + ?Sized>(r_b: f64, rng: &mut R) -> Self {
        let mut p = unit_vector::<D, _>(rng);
        p.iter_mut().for_each(|x| *x *= r_b);
        Walker { p }
    }

    /// One move on a non-empty cluster whose particles all lie within `r_ext` of the origin.
    /// Returns the sticking position (centre distance 1 to the particle first touched) when
    /// the move ends in contact.
    pub fn step<R: Rng + ?Sized>(
        &mut self,
        tree: &Orthtree<D>,
        r_ext: f64,
        params: &Params,
        rng: &mut R,
    ) -> Option<[f64; D]> {
        let r_b = r_ext + params.birth_gap;
        let r = norm(&self.p);
        // Far field. The margin keeps a walker just returned to the birth sphere (whose norm
        // may round to slightly above r_b) in the near field, which is valid everywhere;
        // without it a walker at r_b (1 + 1e-16) would be "returned" to itself forever.
        if r > r_b * FAR_FIELD_MARGIN {
            match params.far_field {
                FarField::Return => self.p = return_to_sphere(&self.p, r_b, rng),
                FarField::Jump => {
                    if r > params.death_ratio * r_b {
                        *self = Walker::born(r_b, rng);
                    } else {
                        // Every particle is within r_ext of the origin, so within distance
                        // r - r_ext - 1 the walker cannot touch one.
                        self.jump(r - r_ext - 1.0, rng);
                    }
                }
            }
            return None;
        }
        // Near field: a lower bound on the distance to the nearest centre.
        let delta = tree
            .vpdist(&self.p, params.precision)
            .expect("the cluster is never empty");
        if delta - 1.0 > params.step_min {
            self.jump(delta - 1.0, rng);
            return None;
        }
        let u = unit_vector::<D, _>(rng);
        let t = first_contact(tree, &self.p, &u, params.step_min);
        if let Some(t) = t {
            let mut q = self.p;
            for i in 0..D {
                q[i] += t * u[i];
            }
            return Some(q);
        }
        for i in 0..D {
            self.p[i] += params.step_min * u[i];
        }
        None
    }

    fn jump<R: Rng + ?Sized>(&mut self, len: f64, rng: &mut R) {
        let u = unit_vector::<D, _>(rng);
        for i in 0..D {
            self.p[i] += len * u[i];
        }
    }
}

/// Smallest `t` in `[0, len]` with `|p + t u - q| = 1` over every stored centre `q` (`u` a unit
/// vector): the first contact along the step (seed 002, section 3.2, Fig. 6). A centre already
/// at distance <= 1 gives `t = 0`.
pub fn first_contact<const D: usize>(
    tree: &Orthtree<D>,
    p: &[f64; D],
    u: &[f64; D],
    len: f64,
) -> Option<f64> {
    let mut best = f64::INFINITY;
    tree.for_each_within(p, len + 1.0, |q| {
        let mut b = 0.0;
        let mut w2 = 0.0;
        for i in 0..D {
            let w = p[i] - q[i];
            b += w * u[i];
            w2 += w * w;
        }
        let c = w2 - 1.0;
        let t = if c <= 0.0 {
            0.0
        } else {
            let disc = b * b - c;
            if disc < 0.0 || b >= 0.0 {
                return;
            }
            // Stable form of -b - sqrt(disc) (b < 0): c / (-b + sqrt(disc)).
            c / (-b + disc.sqrt())
        };
        if t < best {
            best = t;
        }
    });
    (best <= len).then_some(best)
}

/// A DLA/PDLA run in `D` dimensions (2 or 3), a pure function of `(Params, seed)` for one
/// thread.
#[derive(Debug)]
pub struct Simulation<const D: usize> {
    params: Params,
    seed: u64,
    tree: Orthtree<D>,
    growth: Growth<D>,
    rng: SimRng,
    discarded: u64,
}

/// The fitted fractal dimension (`log N = D log R_g + c`).
pub type FractalFit = LogLogFit;

impl<const D: usize> Simulation<D> {
    /// A cluster holding the seed particle at the origin.
    pub fn new(params: Params, seed: u64) -> Result<Self, SimError> {
        params.validate()?;
        if params.dim != D {
            return Err(SimError::DimMismatch(D, params.dim));
        }
        let mut tree = Orthtree::new();
        let mut growth = Growth::new(&params);
        growth.add(&mut tree, [0.0; D], params.particles)?;
        Ok(Simulation {
            rng: stream(seed, stream_id(PURPOSE_WALK, 0)),
            params,
            seed,
            tree,
            growth,
            discarded: 0,
        })
    }

    /// Grow the cluster to `params.particles`, calling `progress(n)` about every 1024
    /// particles.
    pub fn run_with(&mut self, progress: &(dyn Fn(u64) + Sync)) -> Result<(), SimError> {
        let target = self.params.particles;
        let serial_to = if self.params.threads == 1 {
            target
        } else {
            self.params.serial_until.clamp(1, target)
        };
        while self.growth.n < serial_to {
            self.add_one()?;
            if self.growth.n % 1024 == 0 {
                progress(self.growth.n);
            }
        }
        if self.growth.n < target {
            self.run_parallel(progress)?;
        }
        progress(self.growth.n);
        Ok(())
    }

    /// Grow to `params.particles` without progress reports.
    pub fn run(&mut self) -> Result<(), SimError> {
        self.run_with(&|_| {})
    }

    /// Release one walker and grow the cluster by the particle it becomes (serial DLA).
    pub fn add_one(&mut self) -> Result<[f64; D], SimError> {
        let mut w = Walker::born(self.growth.r_ext + self.params.birth_gap, &mut self.rng);
        loop {
            if let Some(p) = w.step(&self.tree, self.growth.r_ext, &self.params, &mut self.rng) {
                return Ok(self.growth.add(&mut self.tree, p, self.params.particles)?);
            }
        }
    }

    fn run_parallel(&mut self, progress: &(dyn Fn(u64) + Sync)) -> Result<(), SimError> {
        struct Shared<const D: usize> {
            tree: Orthtree<D>,
            growth: Growth<D>,
        }
        let params = &self.params;
        let target = params.particles;
        let shared = RwLock::new(Shared {
            tree: std::mem::take(&mut self.tree),
            growth: std::mem::replace(&mut self.growth, Growth::new(params)),
        });
        let discarded = AtomicU64::new(0);
        let stop = AtomicBool::new(false);
        let error: Mutex<Option<OrthtreeError>> = Mutex::new(None);
        let seed = self.seed;
        std::thread::scope(|s| {
            for t in 0..params.threads {
                let (shared, discarded, stop, error) = (&shared, &discarded, &stop, &error);
                s.spawn(move || {
                    let mut rng = stream(seed, stream_id(PURPOSE_PDLA, t as u32));
                    'walkers: loop {
                        let mut g = shared.read();
                        if g.growth.n >= target || stop.load(Ordering::Relaxed) {
                            break;
                        }
                        let mut w = Walker::born(g.growth.r_ext + params.birth_gap, &mut rng);
                        let mut moves = 0u32;
                        let stick = loop {
                            if let Some(p) = w.step(&g.tree, g.growth.r_ext, params, &mut rng) {
                                break p;
                            }
                            moves = moves.wrapping_add(1);
                            if moves % 64 == 0 {
                                RwLockReadGuard::bump(&mut g);
                                if g.growth.n >= target || stop.load(Ordering::Relaxed) {
                                    break 'walkers;
                                }
                            }
                        };
                        drop(g);
                        let mut g = shared.write();
                        if g.growth.n >= target {
                            break;
                        }
                        // Re-check under the write lock (seed 002, section 3.4): particles
                        // stored since the walker's last query may overlap it.
                        let mut overlap = false;
                        g.tree
                            .for_each_within(&stick, OVERLAP_DISTANCE, |_| overlap = true);
                        if overlap {
                            discarded.fetch_add(1, Ordering::Relaxed);
                            continue;
                        }
                        let Shared { tree, growth } = &mut *g;
                        if let Err(e) = growth.add(tree, stick, target) {
                            *error.lock() = Some(e);
                            stop.store(true, Ordering::Relaxed);
                            break;
                        }
                        if growth.n % 1024 == 0 {
                            progress(growth.n);
                        }
                    }
                });
            }
        });
        let Shared { tree, growth } = shared.into_inner();
        self.tree = tree;
        self.growth = growth;
        self.discarded += discarded.into_inner();
        match error.into_inner() {
            Some(e) => Err(e.into()),
            None => Ok(()),
        }
    }

    /// The parameters.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Particles in the cluster.
    pub fn particles(&self) -> u64 {
        self.growth.n
    }

    /// Largest centre distance from the origin.
    pub fn r_ext(&self) -> f64 {
        self.growth.r_ext
    }

    /// Radius of gyration of the cluster.
    pub fn radius_of_gyration(&self) -> f64 {
        self.growth.gyration.radius()
    }

    /// PDLA walkers discarded at the re-check (0 for one thread).
    pub fn discarded_walkers(&self) -> u64 {
        self.discarded
    }

    /// Hash of the stored positions in arrival order (f64 bits): equal runs, equal hashes.
    pub fn state_hash(&self) -> String {
        self.growth.hasher.finish_hex()
    }

    /// The growth samples (about 1000, log-spaced in N, the last at the final size).
    pub fn samples(&self) -> &[Sample] {
        &self.growth.samples
    }

    /// Positions in arrival order, if `params.keep_positions`.
    pub fn positions(&self) -> Option<&[[f64; D]]> {
        self.growth.positions.as_deref()
    }

    /// The spatial structure holding the cluster.
    pub fn tree(&self) -> &Orthtree<D> {
        &self.tree
    }

    /// Fractal dimension from `log N = D log R_g + c` over the samples with `N >= fit_from`.
    pub fn fractal_dimension(&self) -> Result<FractalFit, core_lattice::stats::StatsError> {
        let (rg, n): (Vec<f64>, Vec<f64>) = self
            .growth
            .samples
            .iter()
            .filter(|s| s.n >= self.params.fit_from)
            .map(|s| (s.radius_of_gyration, s.n as f64))
            .unzip();
        LogLogFit::fit(&rg, &n)
    }
}
