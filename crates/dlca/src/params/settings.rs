//! The parameters as the front ends take them ([`Settings`]): one flat declaration whose fields
//! are the `dlca` binary's flags, its config keys and the Python keywords, from which the flags,
//! the keywords, the parameter table ([`PARAMS`]), the docs' table and the stubs
//! are made. [`Settings::to_params`] turns them into the engine's [`Params`], where several
//! of them become one field: `--dim`, `--size` and `--boundary` the axes, `--fill` or
//! `--particles` the [`Init`](super::Init), `--histogram` and `--histogram-sweeps` the sweeps
//! recorded.
//!
//! The values that are not one number or name have their own types, which read and write the
//! command line's spelling: [`Sizes`] (`1024x512`), [`Boundaries`] (`periodic,wall`), [`Bytes`]
//! (`4G`) and [`Sweeps`] (`1,2,5`).

use super::{DEFAULT_HISTOGRAM_SWEEPS, DEFAULT_MAX_MEMORY, MAX_MODEL_DIM, Params, Search, flags};
use core_lattice::Boundary;
use core_lattice::spec::{End, Input, Kind, ParamValue, Range};
use serde::Serialize;

core_lattice::declare_params! {
    /// Every parameter of a run as the front ends give it, with its default: declared once
    /// here, from which the `dlca` binary's flags and config keys, the Python keyword
    /// arguments and stubs and the docs' flag table are made (`docs/architecture.md`, "Adding
    /// a parameter"). The docs are the flags' help as written (the binary shows them in the
    /// `Plain` style of `run_cli::cli::ParamFlags`), so each states its unit and range.
    /// [`Settings::to_params`] makes the engine's [`Params`], whose validation checks the
    /// ranges.
    #[derive(Debug, Clone, PartialEq, Serialize)]
    pub struct Settings {
        /// Lattice dimension, 1..=5. With a single --size value, every axis gets that length.
        dim: usize = 2 => {
            flag: "dim", unit: "", range: Range::Int { min: 1, max: Some(MAX_MODEL_DIM as i128) },
        },
        /// Side lengths in sites: one number for every axis (`1024`) or one per axis
        /// (`1024x512`).
        size: Option<Sizes> = None => {
            flag: "size", unit: "sites", range: Range::Any, optional: true,
        },
        /// Fraction of sites holding a particle at the start, in (0, 1).
        fill: Option<f64> = None => {
            flag: "fill", unit: "", range: Range::Real(End::Open(0.0), End::Open(1.0)),
            optional: true,
        },
        /// Number of particles at the start, 1 to the number of sites.
        particles: Option<u64> = None => {
            flag: "particles", unit: "particles", range: Range::Text("1 to the number of sites"),
            optional: true,
        },
        /// Boundaries: `periodic` or `wall` for every axis, or one per axis separated by
        /// commas (`periodic,wall`).
        boundary: Boundaries = Boundaries::default() => {
            flag: "boundary", unit: "", range: Range::Choices(&["periodic", "wall"]),
        },
        /// Overall move probability of a cluster per sweep, in (0, 1].
        temperature: f64 = 1.0 => {
            flag: "temperature", unit: "", range: Range::Real(End::Open(0.0), End::Closed(1.0)),
        },
        /// Gravity g in [0, 1): the move down the last axis has weight 1+g, up 1-g, others 1.
        gravity: f64 = 0.0 => {
            flag: "gravity", unit: "", range: Range::Real(End::Closed(0.0), End::Open(1.0)),
        },
        /// Mobility exponent gamma in [0, inf): a cluster of s particles moves with probability
        /// temperature * s^-gamma (0: all clusters equally mobile, as in the paper).
        mobility_exponent: f64 = 0.0 => {
            flag: "mobility-exponent", unit: "",
            range: Range::Real(End::Closed(0.0), End::Open(f64::INFINITY)),
        },
        /// Stop when at most this many clusters remain, 1.. (the paper stops at 100 to 1000).
        target_clusters: u64 = 100 => {
            flag: "target-clusters", unit: "clusters", range: Range::Int { min: 1, max: None },
        },
        /// Stop after this many sweeps at the latest (default: no limit).
        max_sweeps: Option<u64> = None => {
            flag: "max-sweeps", unit: "sweeps", range: Range::Any, optional: true,
        },
        /// Contact search. All give the same trajectory; `auto` picks by regime and logs why.
        search: Search = Search::Auto => {
            flag: "search", unit: "", range: Range::Choices(&Search::NAMES),
        },
        /// Initial grid-box side in sites for `--search grid` or `grid-doubling`, a power of
        /// two (default: `grid` takes the side of least predicted cost and re-tunes it as
        /// clusters grow; `grid-doubling` starts from the cluster spacing and doubles with the
        /// largest cluster).
        grid_box: Option<u64> = None => {
            flag: "grid-box", unit: "sites", range: Range::Text("a power of two"), optional: true,
        },
        /// Memory in bytes; suffixes K, M, G, T (powers of 1024). The occupancy lattice
        /// (`--search lattice`, or `auto`) must fit in it; given explicitly, it is also the
        /// limit of the whole run: a run whose estimated peak (docs/dlca.md, "Memory") is
        /// larger is refused before it starts. Not given, that limit is the memory available
        /// (MemAvailable, or a lower cgroup limit).
        max_memory: Bytes = Bytes(DEFAULT_MAX_MEMORY) => {
            flag: "max-memory", unit: "bytes", range: Range::Any,
        },
        /// Record the wall time of every sweep (a `seconds` column in sweeps.csv).
        timing: bool = false => { flag: "timing", unit: "", range: Range::Any },
        /// Record histograms of candidate clusters examined per move (histogram.csv) at the
        /// sweeps of --histogram-sweeps (as in figures 4, 7 and 8 of Hawick, James & Scogings
        /// 2006).
        histogram: bool = false => { flag: "histogram", unit: "", range: Range::Any },
        /// Sweeps at which --histogram records, comma separated.
        histogram_sweeps: Sweeps = Sweeps(DEFAULT_HISTOGRAM_SWEEPS.to_vec()) => {
            flag: "histogram-sweeps", unit: "sweeps", range: Range::Any,
        },
        /// Measure every final cluster's radius of gyration (clusters.csv) and fit the fractal
        /// dimension from log s = D log R_g + c.
        gyration: bool = false => { flag: "gyration", unit: "", range: Range::Any },
        /// Smallest cluster size (particles) used in the fractal-dimension fit, 2..
        fit_min_size: u64 = 10 => {
            flag: "fit-min-size", unit: "particles", range: Range::Int { min: 2, max: None },
            why: "a single particle has no radius of gyration",
        },
    }
    internal {}
    tables { const PARAMS; fn defaults; }
}

/// How many declared parameters the `dlca` binary shows before its run flags (`--seed`,
/// `--out`, ...): the lattice and its particles, `--dim` to `--particles`.
pub const LATTICE_FLAGS: usize = 4;

impl Settings {
    /// The engine's parameters, validated: the axes of `dim`, `size` and `boundary`, the
    /// particles of `fill` or `particles` (exactly one), the sweeps `histogram` records, and
    /// the rest as they are. `given(name)` says whether the front end was given parameter
    /// `name` (the sweeps of `histogram_sweeps` are refused without `histogram`). The errors
    /// are the command line's, naming the flags.
    pub fn to_params(&self, given: impl Fn(&str) -> bool) -> Result<Params, String> {
        if given("histogram_sweeps") && !self.histogram {
            return Err("--histogram-sweeps is used with --histogram only".into());
        }
        let lengths = self.size.as_ref().map_or(&[][..], |s| s.0.as_slice());
        let (size, boundary) = flags::axes(self.dim, lengths, &self.boundary.0)?;
        let p = Params {
            size,
            boundary,
            init: flags::init(self.fill, self.particles)?,
            temperature: self.temperature,
            gravity: self.gravity,
            mobility_exponent: self.mobility_exponent,
            target_clusters: self.target_clusters,
            max_sweeps: self.max_sweeps,
            search: self.search,
            grid_box: self.grid_box,
            max_memory: self.max_memory.0,
            timing: self.timing,
            histogram_sweeps: if self.histogram {
                self.histogram_sweeps.0.clone()
            } else {
                Vec::new()
            },
            gyration: self.gyration,
            fit_min_size: self.fit_min_size,
        };
        p.validate().map_err(|e| e.to_string())?;
        Ok(p)
    }
}

/// The error of a value of a text parameter that is neither text nor, where allowed, a count.
fn not_text(v: &Input) -> String {
    format!("expected text, not {v:?}")
}

/// `--size`: the lengths given, one for every axis (`1024`) or one per axis (`1024x512`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(transparent)]
pub struct Sizes(pub Vec<u64>);

impl ParamValue for Sizes {
    const KIND: Kind = Kind::Text;
    const PYTHON: &'static str = "Size";
    fn from_input(v: &Input) -> Result<Self, String> {
        match v {
            Input::Text(s) => Self::parse_text(s),
            Input::Count(n) => Ok(Sizes(vec![*n])),
            other => Err(not_text(other)),
        }
    }
    fn parse_text(s: &str) -> Result<Self, String> {
        flags::parse_size(s).map(Sizes)
    }
    fn in_range(&self, _: &Range) -> bool {
        true
    }
    fn show(&self) -> String {
        let parts: Vec<String> = self.0.iter().map(u64::to_string).collect();
        parts.join("x")
    }
}

/// `--boundary`: `periodic` or `wall` for every axis, or one per axis separated by commas, as
/// given; read with the axes ([`flags::axes`]), which know how many there are.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(transparent)]
pub struct Boundaries(pub String);

impl Default for Boundaries {
    fn default() -> Self {
        Boundaries(Boundary::Periodic.to_string())
    }
}

impl ParamValue for Boundaries {
    const KIND: Kind = Kind::Text;
    const PYTHON: &'static str = "Boundary";
    fn from_input(v: &Input) -> Result<Self, String> {
        match v {
            Input::Text(s) => Self::parse_text(s),
            other => Err(not_text(other)),
        }
    }
    fn parse_text(s: &str) -> Result<Self, String> {
        Ok(Boundaries(s.to_string()))
    }
    fn in_range(&self, _: &Range) -> bool {
        true
    }
    fn show(&self) -> String {
        self.0.clone()
    }
}

/// `--max-memory`: a byte count, written with a suffix K, M, G or T (powers of 1024) or
/// without.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(transparent)]
pub struct Bytes(pub u64);

impl ParamValue for Bytes {
    const KIND: Kind = Kind::Text;
    const PYTHON: &'static str = "Union[Count, str]";
    fn from_input(v: &Input) -> Result<Self, String> {
        match v {
            Input::Text(s) => Self::parse_text(s),
            Input::Count(n) => Ok(Bytes(*n)),
            other => Err(not_text(other)),
        }
    }
    fn parse_text(s: &str) -> Result<Self, String> {
        flags::parse_bytes(s).map(Bytes)
    }
    fn in_range(&self, _: &Range) -> bool {
        true
    }
    /// With the largest suffix that keeps it whole: `4G`, `1536M`, `1000`.
    fn show(&self) -> String {
        let n = self.0;
        for (k, suffix) in [(40, 'T'), (30, 'G'), (20, 'M'), (10, 'K')] {
            if n != 0 && n % (1u64 << k) == 0 {
                return format!("{}{suffix}", n >> k);
            }
        }
        n.to_string()
    }
}

/// `--histogram-sweeps`: sweeps, separated by commas (`1,2,5`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(transparent)]
pub struct Sweeps(pub Vec<u64>);

impl ParamValue for Sweeps {
    const KIND: Kind = Kind::List;
    const PYTHON: &'static str = "Sequence[Count]";
    fn from_input(v: &Input) -> Result<Self, String> {
        match v {
            Input::Text(s) => Self::parse_text(s),
            Input::Count(n) => Ok(Sweeps(vec![*n])),
            other => Err(not_text(other)),
        }
    }
    fn parse_text(s: &str) -> Result<Self, String> {
        s.split(',')
            .map(|x| run_io::count::count::<u64>(x.trim()))
            .collect::<Result<_, _>>()
            .map(Sweeps)
    }
    fn in_range(&self, _: &Range) -> bool {
        true
    }
    fn show(&self) -> String {
        let parts: Vec<String> = self.0.iter().map(u64::to_string).collect();
        parts.join(",")
    }
}

impl ParamValue for Search {
    const KIND: Kind = Kind::Choice;
    const CHOICE_HELP: &'static [&'static str] = &[
        "Pick by regime (memory, dimension, density) and log why",
        "The all-pairs baseline of Hawick, James & Scogings 2006",
        "Grid boxes (Hawick, James & Scogings 2006) with a halo per cluster: small boxes, each cluster listed in every box its bounding region grown by one site overlaps, the box side re-tuned at run time by a cost model",
        "The paper's grid boxes (Hawick, James & Scogings 2006), doubling with the largest cluster, falling back to all-pairs once 3A >= L on some axis (the Fig. 6 rule)",
        "Occupancy lattice: a cluster id per site",
    ];
    fn from_input(v: &Input) -> Result<Self, String> {
        match v {
            Input::Choice(s) => s.parse(),
            other => Err(format!(
                "expected one of {}, not {other:?}",
                Search::NAMES.join(", ")
            )),
        }
    }
    fn parse_text(s: &str) -> Result<Self, String> {
        s.parse()
    }
    fn in_range(&self, _: &Range) -> bool {
        true
    }
    fn show(&self) -> String {
        self.name().to_string()
    }
}
