//! Parameters of a DLCA run (docs/dlca.md, "The model"), validated before anything runs.
//!
//! Invariant: a [`Params`] that passed [`Params::validate`] describes a run the simulation can
//! set up (dimension 1..=5, a valid lattice, 1 to 2^32 - 3 particles, every rate in range).
//!
//! The front ends' parameters are [`Settings`], whose declaration also writes their table,
//! [`PARAMS`], in the order of `dlca --help`: the ranges are those [`Params::validate`]
//! accepts, written as its error messages write them (a unit test probes each bound). With the
//! feature `files` it writes their defaults by name, `defaults()`: `null` where the front end
//! must be given a value (`size`, and one of `fill` and `particles`) or where none means a
//! choice (`max_sweeps`: no limit, `grid_box`: chosen).

use core_lattice::{Boundary, Lattice, LatticeError};
use serde::{Deserialize, Serialize};

mod settings;
#[cfg(test)]
mod spec;
#[cfg(feature = "files")]
pub use settings::defaults;
pub use settings::{Boundaries, Bytes, LATTICE_FLAGS, PARAMS, Settings, Sizes, Sweeps};

/// Largest dimension the model accepts (Hawick, James & Scogings 2006 run 2 to 5; 1 is
/// included for tests and teaching).
pub const MAX_MODEL_DIM: usize = 5;

/// Longest accepted lattice side, `2^62` sites: the grid boxes' modular arithmetic adds a
/// coordinate to a side (`x + L`), which must not overflow `u64`.
pub const MAX_SIDE: u64 = 1 << 62;

/// Default memory budget for the occupancy lattice: 4 GiB.
pub const DEFAULT_MAX_MEMORY: u64 = 4 << 30;

/// Peak memory that does not grow with the run (the binary and its libraries); see
/// `sim::peak_memory_bytes`.
pub const PEAK_FIXED_BYTES: u64 = 10 << 20;
/// Peak memory per particle and dimension with the occupancy lattice: a particle takes
/// `(d + 1)` times this (its site, its cluster's records, the initial grouping); see
/// `sim::peak_memory_bytes`.
pub const PEAK_BYTES_PER_PARTICLE_AXIS: u64 = 80;
/// Peak memory per particle and dimension with the other searches (grid boxes and their halo
/// lists, all-pairs); see `sim::peak_memory_bytes`.
pub const PEAK_BYTES_PER_PARTICLE_AXIS_GRID: u64 = 240;
/// Peak memory per lattice site with the occupancy lattice (its 4-byte cell and occupancy bit,
/// the placement's bitset); see `sim::peak_memory_bytes`.
pub const PEAK_BYTES_PER_SITE_LATTICE: f64 = 4.5;
/// Peak memory per lattice site without it (the placement's bitset, one bit per site, and the
/// grid's boxes); see `sim::peak_memory_bytes`.
pub const PEAK_BYTES_PER_SITE: f64 = 0.25;

/// Default sweeps at which `--histogram` records (`--histogram-sweeps`): about three per
/// decade up to 10^4, as in Figs. 4, 7, 8 of Hawick, James & Scogings 2006.
pub const DEFAULT_HISTOGRAM_SWEEPS: &[u64] =
    &[1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 10000];

/// The fields of [`Params`] that several parameters make, named as a resumed run's differences
/// name them on the command line.
pub const COMBINED_FLAGS: &[(&str, Option<&str>)] = &[
    ("init", Some("--fill/--particles")),
    ("histogram_sweeps", Some("--histogram/--histogram-sweeps")),
];

/// [`COMBINED_FLAGS`] as Python names them (keyword arguments).
pub const COMBINED_KEYWORDS: &[(&str, Option<&str>)] = &[
    ("init", Some("fill/particles")),
    ("histogram_sweeps", Some("histogram/histogram_sweeps")),
];

/// How many particles to place.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Init {
    /// A fraction of all sites, in (0, 1): `N = round(fill * sites)`.
    Fill(f64),
    /// An exact number of particles.
    Particles(u64),
}

/// The contact search (docs/dlca.md, "The search strategies"). All give bit-identical
/// trajectories; they differ only in speed and memory.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Search {
    /// Pick by regime (memory, dimension, density) and log why.
    Auto,
    /// The all-pairs baseline of Hawick, James & Scogings 2006.
    AllPairs,
    /// Grid boxes (Hawick, James & Scogings 2006) with a halo per cluster: small boxes, each
    /// cluster listed in every box its bounding region grown by one site overlaps, the box side
    /// re-tuned at run time by a cost model.
    Grid,
    /// The paper's grid boxes (Hawick, James & Scogings 2006), doubling with the largest
    /// cluster, falling back to all-pairs once `3A >= L` on some axis (the Fig. 6 rule).
    GridDoubling,
    /// Occupancy lattice: a cluster id per site.
    Lattice,
}

impl Search {
    /// Every strategy, in declaration order.
    pub const ALL: [Search; 5] = [
        Search::Auto,
        Search::AllPairs,
        Search::Grid,
        Search::GridDoubling,
        Search::Lattice,
    ];

    /// The names of [`ALL`](Self::ALL), in the same order: the one spelling the command line,
    /// config files, Python and the outputs use (each with its help in
    /// [`Settings`]'s declaration).
    pub const NAMES: [&'static str; 5] = ["auto", "all-pairs", "grid", "grid-doubling", "lattice"];

    /// The name used on the command line and in outputs.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }
}

impl std::str::FromStr for Search {
    type Err = String;

    /// A name of [`Search::NAMES`]; the error is the command line's.
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .iter()
            .copied()
            .find(|x| x.name() == s)
            .ok_or_else(|| {
                format!(
                    "invalid value '{s}' for '--search': possible values are {}",
                    Self::NAMES.join(", ")
                )
            })
    }
}

/// Every parameter of a run. Build one, call [`Params::validate`] (the simulation does), run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// Side length of each axis (`--size 1024x512`); its length is the dimension.
    pub size: Vec<u64>,
    /// Boundary of each axis (`--boundary`).
    pub boundary: Vec<Boundary>,
    /// Number of particles, directly or as a fill fraction.
    pub init: Init,
    /// Overall move probability, in (0, 1] (`--temperature`).
    pub temperature: f64,
    /// Bias of moves down the last axis, in [0, 1) (`--gravity`).
    pub gravity: f64,
    /// Mobility exponent `gamma >= 0`: a cluster of size `s` moves with probability
    /// `temperature * s^-gamma` (`--mobility-exponent`).
    pub mobility_exponent: f64,
    /// Stop when at most this many clusters remain (`--target-clusters`, >= 1).
    pub target_clusters: u64,
    /// Stop after this many sweeps at the latest (`--max-sweeps`).
    pub max_sweeps: Option<u64>,
    /// Contact search strategy (`--search`).
    pub search: Search,
    /// Initial grid-box side for the grid strategies, a power of two (`--grid-box`); by default
    /// `grid` takes the side of least predicted cost and `grid-doubling` the cluster spacing
    /// (raised to the largest initial cluster).
    pub grid_box: Option<u64>,
    /// Memory the occupancy lattice may take, in bytes (`--max-memory`).
    pub max_memory: u64,
    /// Record the wall time of each sweep (`--timing`).
    pub timing: bool,
    /// Record histograms of candidate clusters examined per move at these sweeps
    /// (`--histogram`, `--histogram-sweeps`); empty: none.
    pub histogram_sweeps: Vec<u64>,
    /// Measure each final cluster's radius of gyration and fit the fractal dimension
    /// (`--gyration`).
    pub gyration: bool,
    /// Smallest cluster size used in the fractal-dimension fit (`--fit-min-size`).
    pub fit_min_size: u64,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            size: vec![1024, 1024],
            boundary: vec![Boundary::Periodic; 2],
            init: Init::Fill(0.01),
            temperature: 1.0,
            gravity: 0.0,
            mobility_exponent: 0.0,
            target_clusters: 100,
            max_sweeps: None,
            search: Search::Auto,
            grid_box: None,
            max_memory: DEFAULT_MAX_MEMORY,
            timing: false,
            histogram_sweeps: Vec::new(),
            gyration: false,
            fit_min_size: 10,
        }
    }
}

/// A parameter outside its accepted range. The message names the value and the range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamError {
    /// A large allocation of the set-up (the particles' sites, the occupancy lattice) was
    /// refused by the system: not bad input, a run that failed (the binary exits with code 1).
    #[error(transparent)]
    Alloc(#[from] run_io::memory::AllocError),
    /// A checkpoint whose state no run can be in (damaged, or made by hand).
    #[error("the saved state is inconsistent: {0}")]
    Checkpoint(String),
    /// Dimension outside 1..=5.
    #[error("--dim {0} is outside the accepted range 1..={MAX_MODEL_DIM}")]
    Dimension(usize),
    /// The lattice itself is invalid.
    #[error("{0}")]
    Lattice(#[from] LatticeError),
    /// Fill fraction outside (0, 1).
    #[error("--fill {0} is outside the accepted range (0, 1)")]
    Fill(f64),
    /// Fill too small to place a single particle.
    #[error(
        "--fill {fill} of {sites} sites places no particle; use a larger --fill or --particles"
    )]
    EmptyFill {
        /// Fill asked for.
        fill: f64,
        /// Sites in the lattice.
        sites: u64,
    },
    /// Particle count outside 1..=sites.
    #[error(
        "--particles {particles} is outside the accepted range 1..={sites} (the number of sites)"
    )]
    Particles {
        /// Particles asked for.
        particles: u64,
        /// Sites in the lattice.
        sites: u64,
    },
    /// Temperature outside (0, 1].
    #[error("--temperature {0} is outside the accepted range (0, 1]")]
    Temperature(f64),
    /// Gravity outside [0, 1).
    #[error("--gravity {0} is outside the accepted range [0, 1)")]
    Gravity(f64),
    /// Negative or non-finite mobility exponent.
    #[error("--mobility-exponent {0} is outside the accepted range [0, inf)")]
    MobilityExponent(f64),
    /// Target of zero clusters.
    #[error("--target-clusters {0} is outside the accepted range 1..")]
    TargetClusters(u64),
    /// Grid-box side not a power of two.
    #[error("--grid-box {0} is not a power of two >= 1")]
    GridBox(u64),
    /// The occupancy lattice does not fit the memory budget.
    #[error(
        "the lattice strategy needs {bytes} bytes for {sites} sites, over --max-memory {budget}; use --search grid or raise --max-memory"
    )]
    TooLarge {
        /// Bytes needed.
        bytes: u64,
        /// Sites in the lattice.
        sites: u64,
        /// The budget.
        budget: u64,
    },
    /// A grid box so large that it does not split the lattice: `3A >= L` on the shortest axis
    /// (the grid would be all-pairs from the start).
    #[error(
        "--grid-box {side} does not split the lattice: grid boxes need 3 x side < {shortest} (the shortest lattice side); use a smaller box or --search all-pairs"
    )]
    GridBoxTooLarge {
        /// The box side asked for.
        side: u64,
        /// The shortest side of the lattice.
        shortest: u64,
    },
    /// A grid box given to a strategy that has none.
    #[error("--grid-box is used by --search grid, grid-doubling and auto only, not {0}")]
    GridBoxUnused(&'static str),
    /// Too small a smallest size for the fractal-dimension fit.
    #[error(
        "--fit-min-size {0} is outside the accepted range 2.. (a single particle has no radius of gyration)"
    )]
    FitMinSize(u64),
    /// A lattice side above [`MAX_SIDE`].
    #[error("--size: a side of {0} sites is above the longest accepted, 2^62 = {MAX_SIDE}")]
    SideTooLong(u64),
    /// Particle count too large to number.
    #[error(
        "{given} places {particles} particles, more than this implementation numbers (at most 2^32 - 3 = 4294967293)"
    )]
    TooManyParticles {
        /// The flag and value that asked for them (`--fill 0.6`).
        given: String,
        /// Particles asked for.
        particles: u64,
    },
}

impl Params {
    /// The lattice these parameters describe.
    pub fn lattice(&self) -> Result<Lattice, ParamError> {
        if self.size.is_empty() || self.size.len() > MAX_MODEL_DIM {
            return Err(ParamError::Dimension(self.size.len()));
        }
        if let Some(&side) = self.size.iter().find(|&&l| l > MAX_SIDE) {
            return Err(ParamError::SideTooLong(side));
        }
        Ok(Lattice::new(&self.size, &self.boundary)?)
    }

    /// The dimension.
    pub fn dim(&self) -> usize {
        self.size.len()
    }

    /// Whether the run records histograms of candidates examined per move (`--histogram`).
    pub fn records_histograms(&self) -> bool {
        !self.histogram_sweeps.is_empty()
    }

    /// Number of particles these parameters place (after validation).
    pub fn particles(&self) -> Result<u64, ParamError> {
        let sites = self.lattice()?.volume();
        match self.init {
            Init::Fill(f) => {
                if !(f > 0.0 && f < 1.0) {
                    return Err(ParamError::Fill(f));
                }
                let n = (f * sites as f64).round() as u64;
                if n == 0 {
                    return Err(ParamError::EmptyFill { fill: f, sites });
                }
                Ok(n.min(sites))
            }
            Init::Particles(n) => {
                if n == 0 || n > sites {
                    return Err(ParamError::Particles {
                        particles: n,
                        sites,
                    });
                }
                Ok(n)
            }
        }
    }

    /// Check every parameter; the first problem found is returned.
    pub fn validate(&self) -> Result<(), ParamError> {
        let lattice = self.lattice()?;
        let n = self.particles()?;
        if n >= u64::from(u32::MAX) - 1 {
            return Err(ParamError::TooManyParticles {
                given: match self.init {
                    Init::Fill(f) => format!("--fill {f}"),
                    Init::Particles(p) => format!("--particles {p}"),
                },
                particles: n,
            });
        }
        if !(self.temperature > 0.0 && self.temperature <= 1.0) {
            return Err(ParamError::Temperature(self.temperature));
        }
        if !(0.0..1.0).contains(&self.gravity) {
            return Err(ParamError::Gravity(self.gravity));
        }
        if !(self.mobility_exponent >= 0.0 && self.mobility_exponent.is_finite()) {
            return Err(ParamError::MobilityExponent(self.mobility_exponent));
        }
        if self.target_clusters == 0 {
            return Err(ParamError::TargetClusters(0));
        }
        if let Some(a) = self.grid_box {
            if !a.is_power_of_two() {
                return Err(ParamError::GridBox(a));
            }
            if matches!(self.search, Search::AllPairs | Search::Lattice) {
                return Err(ParamError::GridBoxUnused(self.search.name()));
            }
            let shortest = self.size.iter().copied().min().unwrap_or(0);
            if a.saturating_mul(3) >= shortest {
                return Err(ParamError::GridBoxTooLarge { side: a, shortest });
            }
        }
        if self.fit_min_size < 2 {
            return Err(ParamError::FitMinSize(self.fit_min_size));
        }
        if self.search == Search::Lattice {
            let bytes = spatial::lattice::Occupancy::bytes_needed(&lattice);
            if bytes > self.max_memory {
                return Err(ParamError::TooLarge {
                    bytes,
                    sites: lattice.volume(),
                    budget: self.max_memory,
                });
            }
        }
        Ok(())
    }
}

/// The command line's spellings of the parameters, parsed and checked with the `dlca`
/// binary's messages; any front end (the binary, the Python bindings) builds its [`Params`]
/// with these.
pub mod flags {
    use super::{Init, MAX_MODEL_DIM};
    use core_lattice::Boundary;

    /// `--size`: one length for every axis (`1024`) or one per axis (`1024x512`).
    pub fn parse_size(s: &str) -> Result<Vec<u64>, String> {
        s.split('x')
            .map(|p| {
                run_io::count::count::<u64>(p.trim())
                    .map_err(|_| format!("'{s}' is not a size like 1024, 1024x512 or 1e3"))
            })
            .collect()
    }

    /// `--max-memory`: a byte count, with an optional suffix K, M, G or T (powers of 1024).
    pub use run_io::parse_bytes;

    /// The axes of `--dim`, `--size` (the lengths given: one for every axis, or one per axis)
    /// and `--boundary` (`periodic` or `wall` for every axis, or one per axis separated by
    /// commas): the side lengths and boundaries of [`Params`](super::Params).
    pub fn axes(
        dim: usize,
        size: &[u64],
        boundary: &str,
    ) -> Result<(Vec<u64>, Vec<Boundary>), String> {
        if dim == 0 || dim > MAX_MODEL_DIM {
            return Err(format!(
                "--dim {dim} is outside the accepted range 1..={MAX_MODEL_DIM}"
            ));
        }
        let size = match size {
            [] => {
                return Err(
                    "--size is required (for example --size 1024 or --size 1024x512)".into(),
                );
            }
            [l] => vec![*l; dim],
            many if many.len() == dim => many.to_vec(),
            many => {
                return Err(format!(
                    "--size has {} axes but --dim is {dim}; give one length or {dim} lengths",
                    many.len()
                ));
            }
        };
        let names: Vec<&str> = boundary.split(',').map(str::trim).collect();
        let boundary: Vec<Boundary> = match names.as_slice() {
            [one] => vec![parse_boundary(one)?; dim],
            many if many.len() == dim => many
                .iter()
                .map(|b| parse_boundary(b))
                .collect::<Result<_, _>>()?,
            many => {
                return Err(format!(
                    "--boundary has {} entries but --dim is {dim}; give one or {dim}",
                    many.len()
                ));
            }
        };
        Ok((size, boundary))
    }

    fn parse_boundary(s: &str) -> Result<Boundary, String> {
        s.parse::<Boundary>()
            .map_err(|e| format!("--boundary: {e}"))
    }

    /// The particles of `--fill` or `--particles`, exactly one of which must be given.
    pub fn init(fill: Option<f64>, particles: Option<u64>) -> Result<Init, String> {
        match (fill, particles) {
            (Some(f), None) => Ok(Init::Fill(f)),
            (None, Some(n)) => Ok(Init::Particles(n)),
            _ => Err("give exactly one of --fill and --particles".into()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with(f: impl FnOnce(&mut Params)) -> Result<(), ParamError> {
        let mut p = Params::default();
        f(&mut p);
        p.validate()
    }

    #[test]
    fn defaults_are_valid() {
        assert_eq!(with(|_| {}), Ok(()));
    }

    #[test]
    fn rejects_each_bad_value() {
        assert_eq!(with(|p| p.size = vec![]), Err(ParamError::Dimension(0)));
        assert_eq!(with(|p| p.size = vec![8; 6]), Err(ParamError::Dimension(6)));
        assert!(matches!(
            with(|p| p.size = vec![8, 0]),
            Err(ParamError::Lattice(_))
        ));
        assert_eq!(
            with(|p| p.init = Init::Fill(0.0)),
            Err(ParamError::Fill(0.0))
        );
        assert_eq!(
            with(|p| p.init = Init::Fill(1.0)),
            Err(ParamError::Fill(1.0))
        );
        assert!(matches!(
            with(|p| p.init = Init::Fill(f64::NAN)),
            Err(ParamError::Fill(_))
        ));
        assert!(matches!(
            with(|p| p.init = Init::Fill(1e-9)),
            Err(ParamError::EmptyFill { .. })
        ));
        assert!(matches!(
            with(|p| p.init = Init::Particles(1024 * 1024 + 1)),
            Err(ParamError::Particles { .. })
        ));
        assert!(matches!(
            with(|p| p.init = Init::Particles(0)),
            Err(ParamError::Particles { .. })
        ));
        assert_eq!(with(|p| p.gravity = 1.0), Err(ParamError::Gravity(1.0)));
        assert_eq!(with(|p| p.gravity = -0.5), Err(ParamError::Gravity(-0.5)));
        assert_eq!(
            with(|p| p.temperature = 0.0),
            Err(ParamError::Temperature(0.0))
        );
        assert_eq!(
            with(|p| p.mobility_exponent = -1.0),
            Err(ParamError::MobilityExponent(-1.0))
        );
        assert_eq!(
            with(|p| p.target_clusters = 0),
            Err(ParamError::TargetClusters(0))
        );
        assert_eq!(
            with(|p| p.grid_box = Some(12)),
            Err(ParamError::GridBox(12))
        );
        assert_eq!(
            with(|p| {
                p.size = vec![1024, 96];
                p.grid_box = Some(32);
            }),
            Err(ParamError::GridBoxTooLarge {
                side: 32,
                shortest: 96
            })
        );
        assert_eq!(
            with(|p| {
                p.grid_box = Some(16);
                p.search = Search::AllPairs;
            }),
            Err(ParamError::GridBoxUnused("all-pairs"))
        );
        assert_eq!(with(|p| p.grid_box = Some(256)), Ok(()));
        assert_eq!(with(|p| p.fit_min_size = 0), Err(ParamError::FitMinSize(0)));
        assert_eq!(with(|p| p.fit_min_size = 1), Err(ParamError::FitMinSize(1)));
        assert!(matches!(
            with(|p| {
                p.size = vec![1 << 20, 1 << 20];
                p.init = Init::Particles(1000);
                p.search = Search::Lattice;
            }),
            Err(ParamError::TooLarge { .. })
        ));
    }

    #[test]
    fn flags_parse_and_name_what_is_wrong() {
        use flags::*;
        assert_eq!(parse_size("1024x512"), Ok(vec![1024, 512]));
        assert_eq!(parse_size("64"), Ok(vec![64]));
        assert!(
            parse_size("64xx")
                .unwrap_err()
                .contains("'64xx' is not a size")
        );
        assert_eq!(parse_bytes("4G"), Ok(4 << 30));
        assert_eq!(parse_bytes("500"), Ok(500));
        assert!(
            parse_bytes("lots")
                .unwrap_err()
                .contains("is not a byte count")
        );
        assert_eq!(
            axes(2, &[64], "periodic,wall"),
            Ok((vec![64, 64], vec![Boundary::Periodic, Boundary::Wall]))
        );
        assert_eq!(
            axes(3, &[64, 32], "periodic").unwrap_err(),
            "--size has 2 axes but --dim is 3; give one length or 3 lengths"
        );
        assert_eq!(
            axes(6, &[64], "periodic").unwrap_err(),
            "--dim 6 is outside the accepted range 1..=5"
        );
        assert!(
            axes(2, &[], "periodic")
                .unwrap_err()
                .starts_with("--size is required")
        );
        assert!(
            axes(2, &[8], "sticky")
                .unwrap_err()
                .starts_with("--boundary: ")
        );
        assert_eq!(
            axes(2, &[8], "wall,wall,wall").unwrap_err(),
            "--boundary has 3 entries but --dim is 2; give one or 2"
        );
        assert_eq!(init(Some(0.1), None), Ok(Init::Fill(0.1)));
        assert_eq!(init(None, Some(7)), Ok(Init::Particles(7)));
        assert!(init(Some(0.1), Some(7)).is_err() && init(None, None).is_err());
    }

    #[test]
    fn serde_round_trip() {
        let p = Params {
            histogram_sweeps: vec![1, 100],
            ..Params::default()
        };
        let json = serde_json::to_string(&p).unwrap();
        assert_eq!(serde_json::from_str::<Params>(&json).unwrap(), p);
    }
}
