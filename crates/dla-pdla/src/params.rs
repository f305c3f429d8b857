//! Parameters of a DLA/PDLA run, with their defaults, validated before anything runs.
//!
//! Invariant: a [`Params`] that passed [`Params::validate`] has every field in its accepted
//! range, which every other module assumes (in particular `dim` is one of
//! [`DIMENSIONS`]).
//!
//! [`Params`]'s declaration also writes the table of the parameters a front end sets,
//! [`PARAMS`] (name, flag, unit, meaning and accepted range), and with the feature `files`
//! their defaults by name, `defaults()`.

use crate::space::DIMENSIONS;
use core_lattice::spec::{DeclaredParams, End, Input, Kind, ParamValue, Range, RangeError};
use serde::{Deserialize, Serialize};

#[cfg(test)]
mod spec;

/// What happens to a walker outside the birth sphere (`|p| > R_b`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FarField {
    /// Exact return to the birth circle/sphere at the harmonic-measure hit point
    /// ([`crate::farfield`], `docs/dla.md`); no walker is ever killed.
    Return,
    /// Sosa-Herrera & Rodriguez-Romo, section 3.2: jump `|p| - R_ext - 1` in a random direction (the distance to the
    /// cluster's bounding sphere less the contact distance), relaunch beyond the death radius.
    Jump,
}

impl FarField {
    /// Every far field, in declaration order.
    pub const ALL: [FarField; 2] = [FarField::Return, FarField::Jump];

    /// The flag values of [`ALL`](Self::ALL), in the same order: the one spelling the command
    /// line, config files, Python and `run.json` use.
    pub const NAMES: [&'static str; 2] = ["return", "jump"];

    /// The flag value.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }
}

impl std::str::FromStr for FarField {
    type Err = String;

    /// A flag value of [`FarField::NAMES`]; the error is the command line's.
    fn from_str(s: &str) -> Result<Self, String> {
        parse_choice("--far-field", s, &Self::ALL, Self::name)
    }
}

/// `value` as one of `all` by `name`; otherwise the command line's wording of the error.
fn parse_choice<T: Copy>(
    flag: &str,
    value: &str,
    all: &[T],
    name: fn(T) -> &'static str,
) -> Result<T, String> {
    all.iter()
        .copied()
        .find(|&x| name(x) == value)
        .ok_or_else(|| {
            let names: Vec<&str> = all.iter().map(|&x| name(x)).collect();
            format!(
                "invalid value '{value}' for '{flag}': possible values are {}",
                names.join(", ")
            )
        })
}

core_lattice::declare_params! {
    /// Every parameter of a run, with its default: declared once here, from which the `dla`
    /// binary's flags and config keys, the Python keyword arguments and stubs, the range
    /// checks and their messages, and the docs' flag table are made
    /// (`docs/architecture.md`, "Adding a parameter"). Fields missing from a checkpoint or
    /// config file written before they existed take their defaults.
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(default)]
    pub struct Params {
        /// Space dimension.
        dim: usize = 2 => { flag: "dim", unit: "", range: Range::Values(DIMENSIONS) },
        /// Particles in the final cluster, seed particle included (at most 2.5e9 in 4D and
        /// 5D, the orthtree's 32-bit indices). Memory: about 13 bytes per particle in 2D and 15
        /// in 3D at 1e7, and 4.6 more for the parents a run that streams its positions records
        /// (the `dla` binary's --no-parents records none); the tree and distance map take about
        /// 25 in 4D at 1e5 and 300 in 5D at 3e4 (mostly the map).
        particles: u64 = 10_000 => {
            flag: "particles", unit: "particles",
            range: Range::Int { min: 1, max: Some(MAX_PARTICLES as i128) },
            why: "the orthtree's 32-bit indices", required: true,
        },
        /// R_b - R_ext, the distance of the birth sphere outside the cluster.
        birth_gap: f64 = 5.0 => {
            flag: "birth-gap", unit: "diameters",
            range: Range::Real(End::Closed(1.0), End::Closed(MAX_BIRTH_GAP)),
            why: "a walker born closer than one diameter could overlap the cluster; a larger gap does not change where walkers arrive, only makes each one wander longer: in 3D about gap / R_ext times longer",
        },
        /// What happens to a walker outside the birth sphere. `return` puts it exactly where
        /// Brownian motion would first hit the birth sphere (harmonic measure); `jump` is the
        /// variable-precision paper's jump of |p| - R_ext - 1 with relaunch beyond the death
        /// radius.
        far_field: FarField = FarField::Return => {
            flag: "far-field", unit: "", range: Range::Choices(&FarField::NAMES),
        },
        /// R_d / R_b, the death radius of the jump far field: used with far field `jump`
        /// only, and refused with `return`, which has no death radius.
        death_ratio: f64 = PAPER_DEATH_RATIO => {
            flag: "death-ratio", unit: "birth radii",
            range: Range::Real(End::Open(1.0), End::Closed(MAX_DEATH_RATIO)),
            why: "a larger death radius would overflow the walkers' coordinates",
            optional: true,
        },
        /// Near-field step length: used when the distance to the cluster minus one is at most
        /// this. Smaller is closer to Brownian motion. The default is where the accuracy study
        /// converges at no cost; the paper's 0.5 biases the R_g prefactor about 5 % low.
        step_min: f64 = DEFAULT_STEP_MIN => {
            flag: "step-min", unit: "diameters",
            range: Range::Real(End::Closed(MIN_STEP_MIN), End::Closed(1e3)),
            why: "a step below the contact tolerance of 1e-6 diameters is lost to rounding at the cluster's coordinates, so the walker would never move",
        },
        /// Precision kappa of the variable-precision distance (inf: the exact nearest
        /// distance). Larger is more exact and slower; the paper uses 2.
        precision: f64 = PAPER_PRECISION => {
            flag: "precision", unit: "",
            range: Range::Real(End::Open(0.5), End::Unbounded),
            why: "inf = exact search",
        },
        /// Side of the orthtree's leaf cells, a power of two: speed and memory only, not the
        /// physics (8 is faster and smaller than 4: see docs/benchmarks.md).
        leaf_side: f64 = DLA_LEAF_SIDE => {
            flag: "leaf-side", unit: "diameters", range: Range::Values(&[1, 2, 4, 8, 16, 32, 64]),
        },
        /// Each walker's exact near cache: the particles within 5 diameters, copied out of
        /// the tree, answer its moves close to the cluster. Speed only: the same answers as
        /// the tree, so the same trajectory and state hash on or off. Used where the tree is
        /// exact at those distances anyway ((precision - 1/2) leaf diagonals of at least 5
        /// diameters, as by default).
        near_cache: bool = true => { flag: "near-cache", unit: "", range: Range::Any },
        /// The distance maps in front of the orthtree: speed only, another trajectory. One
        /// byte per cell: a sparse map of 2-diameter cells near the cluster (2D and 3D) and
        /// dense maps of coarser cells (about 2.7 bytes per particle at 1e6 in 2D, 7 in 3D):
        /// walkers away from the cluster jump by their bound without a tree query. Off is the
        /// paper's tree-only walk.
        distance_map: bool = true => { flag: "distance-map", unit: "", range: Range::Any },
        /// Walkers moving at once on the shared cluster (PDLA); 1 is DLA, exact and
        /// deterministic.
        threads: usize = 1 => {
            flag: "threads", unit: "walkers", range: Range::Int { min: 1, max: Some(1024) },
        },
        /// With threads > 1, grow with one walker up to this size before going parallel
        /// (refused with one thread, which is serial throughout).
        serial_until: u64 = 0 => { flag: "serial-until", unit: "particles", range: Range::Any },
        /// Smallest N in the fractal-dimension fit log N = D log R_g + c (above the final
        /// size: no fit, and a warning).
        fit_from: u64 = 1000 => {
            flag: "fit-from", unit: "particles", range: Range::Int { min: 2, max: None },
            why: "a single particle has no radius of gyration",
        },
        /// Probability that a walker sticks when a move ends in contact (1: DLA). A walker
        /// that does not stick stays at the contact point and walks on from there; steps that
        /// point away from a particle it touches are free. Below 1 the aggregation is
        /// reaction-limited at small scales: the clusters are more compact at small N.
        sticking_probability: f64 = 1.0 => {
            flag: "sticking-probability", unit: "",
            range: Range::Real(End::Open(0.0), End::Closed(1.0)),
            why: "a probability; at 0 no walker would ever stick",
        },
        /// Noise reduction factor f (1: DLA), fastDLA's noiseReductionFactor: a walker that
        /// sticks touching the stored particle t at the contact point c is stored at
        /// t + f (c - t), at distance f from t. Below 1 the stored particles overlap: no two lie
        /// closer than f.
        noise_reduction: f64 = 1.0 => {
            flag: "noise-reduction", unit: "",
            range: Range::Real(End::Open(0.0), End::Closed(1.0)),
            why: "the stored particle's distance to the one it touched, in diameters; at 0 the two would coincide",
        },
        /// Growth on a substrate of this width (0: radial growth from one seed particle). The
        /// substrate is a line (2D) or a plane (3D; a hyperplane in 4D and 5D) with periodic
        /// lateral boundaries of period W; walkers start above the deposit and stick to it or
        /// to the substrate (diffusion-limited deposition). Writes deposit.csv and
        /// deposit_growth.csv. One thread only.
        substrate_width: f64 = 0.0 => {
            flag: "substrate-width", unit: "diameters",
            range: Range::Real(End::Closed(0.0), End::Closed(MAX_SUBSTRATE_WIDTH)),
            why: "0 = radial growth; a substrate needs at least 8",
        },
        /// Drift towards the substrate, as the Péclet number Pe = v d / D_w (v the drift
        /// speed, d the diameter, D_w the walker's diffusion coefficient): a deposit is
        /// diffusion-limited up to heights of about 2 / Pe and ballistic above. Exact: each
        /// jump's direction is drawn from the drifting walker's exit law. Needs a substrate.
        drift: f64 = 0.0 => {
            flag: "drift", unit: "",
            range: Range::Real(End::Closed(0.0), End::Closed(MAX_DRIFT)),
            why: "Pe; beyond 1e6 a walker moves straight within 1e-6 radians, use --ballistic",
        },
        /// Straight-line walkers, the infinite-drift limit: ballistic deposition with a
        /// substrate (walkers fall straight down), ballistic aggregation without (each walker
        /// on a straight line from a random direction, Vold-Sutherland-Meakin). One thread
        /// only.
        ballistic: bool = false => { flag: "ballistic", unit: "", range: Range::Any },
        /// Grow from the particles of this positions file (.npy, .csv, .bin, .xyz or .vtk, as
        /// dla writes them) instead of one seed at the origin: each is stored first, in the
        /// file's order, with parent -1. With a substrate they must lie in the strip, on or
        /// above it. A resumed run keeps them (they are its first particles).
        seed_set: Option<SeedSet> = None => {
            flag: "seed-set", unit: "",
            range: Range::Text("a positions file"), optional: true,
        },
    }
    internal {
        /// Keep every position in arrival order (needed for position files and figures).
        /// Costs `8 D` bytes per particle; off by default. Set by the front ends: the binary
        /// streams the positions to a file instead, Python keeps them.
        keep_positions: bool = false,
        /// Record each stored particle's parent, the particle it stuck to (`-1` for the
        /// seed): the orthtree keeps every particle's arrival index (4 bytes per particle) to
        /// name the particle a walker touched. Set by the front ends wherever the positions
        /// are written or kept, so that the parents go with them; the walk is the same
        /// either way.
        connectivity: bool = false,
    }
    tables { const PARAMS; fn defaults; }
}

/// The path of a seed set (`--seed-set`), as given.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct SeedSet(pub String);

impl ParamValue for SeedSet {
    const KIND: Kind = Kind::Text;
    fn from_input(v: &Input) -> Result<Self, String> {
        match v {
            Input::Text(s) => Self::parse_text(s),
            other => Err(format!("expected a path, not {other:?}")),
        }
    }
    fn parse_text(s: &str) -> Result<Self, String> {
        if s.is_empty() {
            return Err("an empty path".into());
        }
        Ok(SeedSet(s.to_string()))
    }
    fn in_range(&self, _: &Range) -> bool {
        true
    }
    fn show(&self) -> String {
        self.0.clone()
    }
}

impl ParamValue for FarField {
    const KIND: Kind = Kind::Choice;
    fn from_input(v: &Input) -> Result<Self, String> {
        match v {
            Input::Choice(s) => s.parse(),
            other => Err(format!(
                "expected one of {}, not {other:?}",
                FarField::NAMES.join(", ")
            )),
        }
    }
    fn in_range(&self, _: &Range) -> bool {
        true
    }
    fn parse_text(s: &str) -> Result<Self, String> {
        s.parse()
    }
    fn show(&self) -> String {
        self.name().to_string()
    }
}

/// Default leaf side of the orthtree for DLA, in diameters: 8, twice the orthtree's own
/// default (`spatial::orthtree::DEFAULT_LEAF_SIDE`). In DLA the distance maps answer the far
/// queries, so the tree serves walkers close to the cluster, where larger leaves mean fewer
/// nodes to descend and less memory per particle (`docs/benchmarks.md`).
pub const DLA_LEAF_SIDE: f64 = 8.0;

/// Default near-field step, in diameters: where the accuracy study (`cargo xtask scaling --only
/// accuracy`, `docs/results/accuracy.md`) has converged. In 2D at 1e5 particles the R_g
/// prefactor with step 0.1 is within its error (+0.5 +- 1.0 %) of the reference (exact search,
/// step 0.05), while the variable-precision paper's 0.5 is 4.8 +- 1.0 % low; the run time is
/// the same (2D 1e6: 0.98 times that of 0.5; 3D 2e5: 0.85 times, since shorter steps near a
/// branch stick sooner). `--step-min 0.5` is the paper's setting.
pub const DEFAULT_STEP_MIN: f64 = 0.1;

/// The fields [`Params::paper_settings`] sets; as flags (dashes for underscores) they cannot be
/// given beside `--paper-settings`.
pub const PAPER_SETTINGS: [&str; 5] = [
    "far_field",
    "death_ratio",
    "step_min",
    "precision",
    "distance_map",
];

/// The variable-precision paper's near-field step, in diameters ([`Params::paper_settings`]).
pub const PAPER_STEP_MIN: f64 = 0.5;

/// The variable-precision paper's death radius over birth radius, "`R_dh` as far as
/// `R_bh x 10^2`" ([`Params::paper_settings`], and the default `--death-ratio`).
pub const PAPER_DEATH_RATIO: f64 = 100.0;

/// The variable-precision paper's `vpdist` precision ([`Params::paper_settings`], and the
/// default: it changes speed, not the physics).
pub const PAPER_PRECISION: f64 = 2.0;

/// Smallest accepted near-field step: the contact tolerance. A walker at distance `r` from the
/// origin moves only if its step exceeds the rounding of `r` (about `r * 1.1e-16`); 1e-6 is ten
/// thousand times that at the radius of a 1e9-particle cluster, while `--step-min 1e-300` would
/// leave a walker in place forever.
pub const MIN_STEP_MIN: f64 = 1e-6;

/// Largest accepted `--substrate-width`, in diameters: far beyond what a deposit of
/// [`MAX_PARTICLES`] covers with more than one layer in 2D.
pub const MAX_SUBSTRATE_WIDTH: f64 = 1e7;

/// Largest accepted `--drift` (Péclet number): at Pe 1e6 a step of 0.1 diameters deviates
/// from the drift's direction by about 1e-2.5 radians and a jump of 10 by 1e-3.5; larger values
/// are the ballistic limit, `--ballistic`.
pub const MAX_DRIFT: f64 = 1e6;

/// Largest accepted `--birth-gap`. The birth sphere only has to enclose the cluster: where a
/// walker first comes near the cluster does not depend on how far out it was born (uniformly
/// on a larger concentric sphere, with the exact far-field return or the jumps of `jump`), so a
/// larger gap changes nothing but the time each walker wanders. That time grows slowly with the
/// gap in 2D but like `gap / R_ext` in 3D (a walker must find a cluster of radius `R_ext` from
/// the birth sphere: `--birth-gap 1e9` would take hours per particle). 1e4 diameters is far
/// beyond any gap that affects the physics.
pub const MAX_BIRTH_GAP: f64 = 1e4;

/// Largest accepted `--death-ratio`. The death radius `death_ratio * R_b` must stay a finite
/// `f64` with room to spare (a walker jumps about its own distance from the origin, and its
/// squared norm is computed): with `R_b` below `1e4 + R_ext` that holds far beyond 1e100, while
/// `1e300 * R_b` can overflow to infinity, so that no walker would ever be relaunched and their
/// coordinates would overflow in turn. The truncation bias of a death radius is of order
/// `R_b / R_d`, negligible long before 1e100.
pub const MAX_DEATH_RATIO: f64 = 1e100;

/// Largest accepted particle count in 2D and 3D ([`max_particles`] gives every dimension's).
/// The orthtree numbers its nodes, leaves and point slots
/// with 32-bit indices (at most `2^32 - 2` of each). Point slots bound the count: a leaf of `n`
/// points owns a block of at most `1.25 n` slots (size classes a quarter of a power of two
/// apart above 16 points), and outgrown blocks wait on free lists until they pass 1/8 of the
/// pool (and 2^16 slots), when the pool is compacted, so a cluster of `N` particles uses at most
/// `1.25 N * 8 / 7 + 2^16` slots whatever the leaf side: under `2^32 - 2` for `N <= 3e9`.
/// Leaves and nodes are fewer than particles (each leaf holds a particle; a DLA cluster has
/// under 0.96 leaves and 0.83 nodes per particle even with the smallest leaf side). Typical
/// clusters use fewer slots (about 1.05 per particle in 2D and 1.1 in 3D with the default leaf
/// side), but leaves of hundreds of particles (3D, leaf sides 32 and 64) come close to the
/// bound: about 1.4 slots per particle, at which 3.5e9 particles would not fit. A run that
/// still runs out (PDLA's reserved room) stops with
/// [`OrthtreeError::CapacityExceeded`](spatial::orthtree::OrthtreeError::CapacityExceeded).
pub const MAX_PARTICLES: u64 = 3_000_000_000;

/// Largest accepted particle count in `dim` dimensions (0 for a dimension the model does not
/// run in): [`MAX_PARTICLES`] in 2D and 3D, 2.5e9 in 4D and 5D.
///
/// In 4D and 5D a leaf cell of side 8 holds tens of particles (50 to 90 at 1e4-1e5), so
/// nodes and leaves number a few hundredths per particle, far from their limit, while leaf
/// blocks are in the size classes of quarter powers of two: up to 25 % of a block is spare,
/// and up to 1/8 of the pool may sit on free lists before it is compacted, at most
/// `1.25 / (7/8) = 1.43` point slots per particle (1.15 measured at 1e5 in 4D). 2.5e9
/// particles then need at most 3.6e9 of the `2^32 - 2` slots. (Memory, not indexing, is the
/// practical limit there: about 25 bytes per particle in 4D and 40-50 in 5D, plus the distance
/// map; see `docs/dla.md`.)
pub const fn max_particles(dim: usize) -> u64 {
    match dim {
        2 | 3 => MAX_PARTICLES,
        4 | 5 => 2_500_000_000,
        _ => 0,
    }
}

/// A parameter outside its accepted range, or given where it has no meaning; the message names
/// the flag, the value and the range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamsError {
    /// A declared parameter outside its declared range ([`Params::DECLARED`]).
    #[error(transparent)]
    Range(#[from] RangeError),
    /// `particles` above [`max_particles`] for the dimension (4D and 5D).
    #[error(
        "--particles {particles} is outside the accepted range 1..={max} in {dim}D (the orthtree's 32-bit indices)"
    )]
    Particles {
        /// The value given.
        particles: u64,
        /// The dimension.
        dim: usize,
        /// The largest accepted in that dimension.
        max: u64,
    },
    /// A death ratio given for the `return` far field, which has no death radius.
    #[error(
        "--death-ratio is used by --far-field jump only (the default `return` has no death radius)"
    )]
    DeathRatioUnused,
    /// A field of [`PAPER_SETTINGS`] given beside `--paper-settings`, which sets it.
    #[error(
        "--{} cannot be given with --paper-settings, which sets --far-field, --death-ratio, --step-min, --precision and --distance-map",
        .0.replace('_', "-")
    )]
    PaperSettingsConflict(&'static str),
    /// `serial_until` given with one thread, which is serial throughout.
    #[error("--serial-until {0} is used with --threads > 1 only (one thread is serial throughout)")]
    SerialUntilUnused(u64),
    /// A substrate narrower than [`MIN_SUBSTRATE_WIDTH`](crate::substrate::MIN_SUBSTRATE_WIDTH).
    #[error(
        "--substrate-width {0} is outside the accepted values: 0 (radial growth) or [8, 1e7] diameters (a narrower strip would hold under a few particles per layer)"
    )]
    SubstrateTooNarrow(f64),
    /// Drift without a substrate.
    #[error(
        "--drift needs --substrate-width: with a point seed a drifting walker that passes the cluster leaves for good, and where one would come back has no exact law (radial growth takes --ballistic, the infinite-drift limit)"
    )]
    DriftNeedsSubstrate,
    /// Both drift and the ballistic limit.
    #[error("--ballistic is the limit of infinite --drift: give one or the other")]
    BallisticDrift,
    /// A sticking probability below 1 with ballistic walkers.
    #[error(
        "--sticking-probability below 1 has no effect with --ballistic: a straight walker refused at a contact moves on into the same particle and touches it again"
    )]
    BallisticSticking,
    /// The `jump` far field with a substrate or ballistic walkers.
    #[error(
        "--far-field jump is the radial diffusive walk's: a deposit returns its walkers to the launch plane exactly and ballistic walkers never come back"
    )]
    FarFieldJumpUnused,
    /// A seed set that cannot be read or does not fit the run.
    #[error("{0}")]
    SeedSet(String),
    /// PDLA with a substrate or ballistic walkers.
    #[error(
        "--threads {0}: deposits (--substrate-width) and ballistic walkers grow with one thread only"
    )]
    VariantThreads(usize),
    /// A near-field step too long for the substrate's image margin.
    #[error(
        "--step-min {step} is too long for --substrate-width {width}: a step must stay below {max} diameters (the periodic images reach {margin} beyond each edge)"
    )]
    StepTooLongForSubstrate {
        /// The step given.
        step: f64,
        /// The substrate's width.
        width: f64,
        /// The longest step accepted.
        max: f64,
        /// The image margin.
        margin: f64,
    },
}

impl ParamsError {
    /// The error of a dimension the model does not run in (the dispatch's fallback).
    pub fn dim(dim: usize) -> Self {
        let d = &Params::DECLARED[0];
        debug_assert_eq!(d.spec.name, "dim");
        ParamsError::Range(RangeError::new(d, dim.to_string()))
    }
}

/// Memory a checkpoint needs while it is written, beside the run: the streams' buffers are
/// flushed and the checkpoint itself is a few kilobytes. Front ends keep this free
/// (`run_io::guard::MemoryWatch::reserve`).
pub const CHECKPOINT_RESERVE_BYTES: u64 = 16 << 20;

/// Peak memory of a run, bytes per particle by dimension (2 to 5): an upper bound of the peak
/// RSS per particle measured at 1e5 to 3e6 particles (docs/dla.md, "Memory", has the
/// calibration table), tree, distance maps and walkers included; the positions stream to disk.
/// 2D's allows for its maps' part that grows with the cluster's area (`R^2`, faster than `N`):
/// 12.9 bytes a particle at 1e8, about 13.4 extrapolated to 1e9.
pub const PEAK_BYTES_PER_PARTICLE: [u64; 4] = [14, 26, 40, 450];

/// What `connectivity` adds per particle at the peak: the orthtree's 4-byte tag (the arrival
/// index) while the cluster grows, and at the end the branch analysis's 1-byte order beside
/// the cluster (it reads the parents from `positions_parent.npy` in blocks).
pub const CONNECTIVITY_BYTES_PER_PARTICLE: u64 = 5;

/// What a deposit adds per particle beyond its images (see
/// [`Params::peak_bytes_per_particle`]): the analysis after the run (each particle's tree, 4
/// bytes) and the map window's rebuilds. Checked against peak RSS for 2D widths 64 and 1000
/// and 3D widths 64 and 200 (`docs/dla.md`, "Memory").
pub const DEPOSIT_BYTES_PER_PARTICLE: u64 = 8;

/// Peak memory of a run that does not grow with it: the binary, its libraries, the distance
/// maps' smallest size, and the 1 MiB buffer of `positions.npy`, which streams for the
/// checkpoints by default.
pub const PEAK_FIXED_BYTES: u64 = 10 << 20;

impl Params {
    /// Peak memory of this run, estimated before it starts: [`PEAK_FIXED_BYTES`] plus
    /// [`PEAK_BYTES_PER_PARTICLE`] of the dimension per particle. An upper bound of the
    /// measured peak RSS, within about 1.5 times of it for 1e5 particles and more
    /// (docs/dla.md, "Memory"). The binaries refuse a run whose estimate does not fit the
    /// memory available or `--max-memory`.
    /// With `connectivity`, [`CONNECTIVITY_BYTES_PER_PARTICLE`] more, and the 1 MiB buffer of
    /// `positions_parent.npy`.
    pub fn peak_memory_bytes(&self) -> u64 {
        let fixed = if self.connectivity { 1 << 20 } else { 0 };
        (PEAK_FIXED_BYTES + fixed).saturating_add(
            self.particles
                .saturating_mul(self.peak_bytes_per_particle()),
        )
    }

    /// The bytes per particle of [`peak_memory_bytes`](Self::peak_memory_bytes). A deposit
    /// stores every particle near a lateral edge again across it: the dimension's bytes
    /// times the expected copies per particle, `(1 + 2 margin / W)^(d - 1)`, and
    /// [`DEPOSIT_BYTES_PER_PARTICLE`] more.
    pub fn peak_bytes_per_particle(&self) -> u64 {
        let base = PEAK_BYTES_PER_PARTICLE[self.dim.clamp(2, 5) - 2];
        let cluster = match self.substrate() {
            Some(s) => {
                let copies = (1.0 + 2.0 * s.margin / s.width).powi(self.dim as i32 - 1);
                (base as f64 * copies).ceil() as u64 + DEPOSIT_BYTES_PER_PARTICLE
            }
            None => base,
        };
        cluster
            + if self.connectivity {
                CONNECTIVITY_BYTES_PER_PARTICLE
            } else {
                0
            }
    }

    /// The variable-precision paper's walk (Sosa-Herrera & Rodriguez-Romo, section 3.2), for
    /// reproducing its numbers: far field `jump` with the death radius at 100 birth radii,
    /// near-field step 0.5, precision 2, and no distance maps (the paper's walk asks the tree
    /// only). Every other field is kept. The step of 0.5 biases the R_g prefactor about 5 % low
    /// against the converged default (`docs/results/accuracy.md`); the `dla` binary's
    /// `--paper-settings`. The fields it sets are [`PAPER_SETTINGS`].
    pub fn paper_settings(self) -> Self {
        Params {
            far_field: FarField::Jump,
            death_ratio: PAPER_DEATH_RATIO,
            step_min: PAPER_STEP_MIN,
            precision: PAPER_PRECISION,
            distance_map: false,
            ..self
        }
    }

    /// What `--paper-settings` sets, as flags with their values (`--far-field jump
    /// --death-ratio 100 ...`), from the declaration and [`paper_settings`](Self::paper_settings):
    /// the help of every front end says it with this.
    pub fn paper_settings_flags() -> String {
        let values = Params::default().paper_settings().to_text();
        PAPER_SETTINGS
            .iter()
            .map(|name| {
                let flag = Params::DECLARED
                    .iter()
                    .find(|d| d.spec.name == *name)
                    .map_or_else(|| name.replace('_', "-"), |d| d.spec.flag_or_name());
                let value = values
                    .iter()
                    .find(|(n, _)| n == name)
                    .map_or("", |(_, v)| v.as_str());
                format!("{flag} {value}")
            })
            .collect::<Vec<_>>()
            .join(" ")
    }

    /// [`paper_settings`](Self::paper_settings) for a front end, refusing a field of
    /// [`PAPER_SETTINGS`] that was also given (`given(name)`), since `--paper-settings` would
    /// override it silently. Every front end applies the rule with this: the `dla` binary
    /// (whose clap declaration refuses the same flags from [`PAPER_SETTINGS`]) and Python.
    pub fn with_paper_settings(self, given: impl Fn(&str) -> bool) -> Result<Self, ParamsError> {
        match PAPER_SETTINGS.iter().find(|name| given(name)) {
            Some(name) => Err(ParamsError::PaperSettingsConflict(name)),
            None => Ok(self.paper_settings()),
        }
    }

    /// Check every field against its accepted range.
    pub fn validate(&self) -> Result<(), ParamsError> {
        if !DIMENSIONS.contains(&self.dim) {
            return Err(ParamsError::dim(self.dim));
        }
        let max = max_particles(self.dim);
        if self.particles == 0 || self.particles > max {
            return Err(ParamsError::Particles {
                particles: self.particles,
                dim: self.dim,
                max,
            });
        }
        self.check_ranges()?;
        self.check_variants()?;
        Ok(())
    }

    /// The substrate, if the run grows a deposit.
    pub fn substrate(&self) -> Option<crate::substrate::Substrate> {
        crate::substrate::Substrate::new(self.substrate_width)
    }

    /// Refuses the combinations of the variants that have no meaning (or that the engine
    /// does not grow: PDLA deposits and ballistic walkers).
    fn check_variants(&self) -> Result<(), ParamsError> {
        let w = self.substrate_width;
        if w > 0.0 && w < crate::substrate::MIN_SUBSTRATE_WIDTH {
            return Err(ParamsError::SubstrateTooNarrow(w));
        }
        if self.drift > 0.0 && w == 0.0 {
            return Err(ParamsError::DriftNeedsSubstrate);
        }
        if self.ballistic && self.drift > 0.0 {
            return Err(ParamsError::BallisticDrift);
        }
        if self.ballistic && self.sticking_probability < 1.0 {
            return Err(ParamsError::BallisticSticking);
        }
        let variant = w > 0.0 || self.ballistic;
        if variant && self.far_field == FarField::Jump {
            return Err(ParamsError::FarFieldJumpUnused);
        }
        if variant && self.threads > 1 {
            return Err(ParamsError::VariantThreads(self.threads));
        }
        if let Some(s) = self.substrate() {
            // A step's contact search covers step + 1 around the walker: all within the
            // images' margin.
            let max = s.margin - 1.0;
            if self.step_min >= max {
                return Err(ParamsError::StepTooLongForSubstrate {
                    step: self.step_min,
                    width: w,
                    max,
                    margin: s.margin,
                });
            }
        }
        Ok(())
    }

    /// [`validate`](Self::validate), then refuse what a front end was given but the run would
    /// silently ignore: a death ratio without `--far-field jump`, and `serial_until` with one
    /// thread. `given(name)`: whether the front end was given the parameter `name` (the
    /// library knows which matter, so the front ends name none). The `dla` binary and the
    /// Python bindings check their parameters with this.
    pub fn validate_given(&self, given: impl Fn(&str) -> bool) -> Result<(), ParamsError> {
        self.validate()?;
        if given("death_ratio") && self.far_field != FarField::Jump {
            return Err(ParamsError::DeathRatioUnused);
        }
        if self.serial_until > 0 && self.threads == 1 {
            return Err(ParamsError::SerialUntilUnused(self.serial_until));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
