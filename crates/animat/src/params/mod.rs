//! Parameters of an animat run (`docs/animat.md`, "Parameters and defaults"), validated
//! before anything runs.
//!
//! Every field has a default ([`Params::default`]) chosen by the experiment documented in
//! `docs/animat.md`; `data/animat-default.toml` spells the same values out. A config file may
//! set any subset of the fields; unknown keys are rejected.
//!
//! [`Params`]'s declaration also writes the table of the parameters, [`PARAMS`] (name, flag,
//! unit, meaning and accepted range of every field), and with the feature `files` their
//! defaults by name, `defaults()`. `--density`, which sets `start_radius` from the start
//! population, is the front ends' own ([`Params::set_density`]), not a declared parameter.

use core_lattice::spec::{DeclaredParams, End, Input, Kind, ParamValue, Range, RangeError};
use serde::{Deserialize, Serialize};
use spatial::plane::BoxSize;
use std::fmt;

#[cfg(test)]
mod spec;

/// The two species of the model (Hawick, James & Scogings 2006, section II.B).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Species {
    /// Predator.
    Fox,
    /// Prey.
    Rabbit,
}

impl Species {
    /// `fox` or `rabbit`.
    pub const fn name(self) -> &'static str {
        match self {
            Species::Fox => "fox",
            Species::Rabbit => "rabbit",
        }
    }

    /// A stable code for state hashes: fox 0, rabbit 1.
    pub fn code(self) -> u64 {
        match self {
            Species::Fox => 0,
            Species::Rabbit => 1,
        }
    }

    /// The species of `code` ([`Species::code`]), if it is one.
    pub fn from_code(code: u64) -> Option<Self> {
        [Species::Fox, Species::Rabbit]
            .into_iter()
            .find(|s| s.code() == code)
    }
}

/// A fox rule (`docs/animat.md`, "Rules"). Priority is the position in [`Params::fox_rules`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FoxRule {
    /// Hungry and a rabbit adjacent: eat it, hunger = 0.
    Eat,
    /// Not hungry, a fox adjacent, not overcrowded, enough prey within vision: breed with
    /// probability `fox_breed_p`.
    Breed,
    /// Hungry and a rabbit within vision: step towards the nearest rabbit.
    Hunt,
    /// Not hungry and another fox within vision: step towards the nearest fox.
    SeekMate,
    /// Random step.
    Wander,
}

impl FoxRule {
    /// Every fox rule, in the default priority order.
    pub const ALL: [FoxRule; 5] = [
        FoxRule::Eat,
        FoxRule::Breed,
        FoxRule::Hunt,
        FoxRule::SeekMate,
        FoxRule::Wander,
    ];

    /// The names of [`ALL`](Self::ALL), in the same order.
    pub const NAMES: [&'static str; 5] = ["eat", "breed", "hunt", "seek_mate", "wander"];

    /// The rule's name in config files.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }
}

/// A rabbit rule (`docs/animat.md`, "Rules"). Priority is the position in
/// [`Params::rabbit_rules`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RabbitRule {
    /// A fox adjacent: step directly away from the nearest adjacent fox.
    Flee,
    /// Another rabbit adjacent, not overcrowded: breed with probability `rabbit_breed_p`.
    Breed,
    /// Another rabbit within vision: step towards the nearest rabbit.
    Herd,
    /// Random step.
    Wander,
}

impl RabbitRule {
    /// Every rabbit rule, in the default priority order.
    pub const ALL: [RabbitRule; 4] = [
        RabbitRule::Flee,
        RabbitRule::Breed,
        RabbitRule::Herd,
        RabbitRule::Wander,
    ];

    /// The names of [`ALL`](Self::ALL), in the same order.
    pub const NAMES: [&'static str; 4] = ["flee", "breed", "herd", "wander"];

    /// The rule's name in config files.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }
}

/// The grid-box setting (`--grid-box`; `docs/animat.md`, "Search"): in config files an
/// integer side, `"none"` or `"vision"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum GridBox {
    /// Boxes of side equal to the vision radius (the paper's choice; the default).
    #[default]
    Vision,
    /// No boxes: the exhaustive "no grid" search (Hawick, James & Scogings 2006, section IV.B,
    /// Fig. 9).
    None,
    /// Boxes of this side (must be positive).
    Side(i64),
}

impl GridBox {
    /// The box size this setting gives for vision radius `vision`.
    pub fn box_size(self, vision: i64) -> BoxSize {
        match self {
            GridBox::Vision => BoxSize::Side(vision),
            GridBox::None => BoxSize::None,
            GridBox::Side(a) => BoxSize::Side(a),
        }
    }
}

impl fmt::Display for GridBox {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GridBox::Vision => f.write_str("vision"),
            GridBox::None => f.write_str("none"),
            GridBox::Side(a) => write!(f, "{a}"),
        }
    }
}

impl std::str::FromStr for GridBox {
    type Err = String;

    /// Parses `none`, `vision` or an integer side (checked by [`Params::validate`]).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim();
        if t.eq_ignore_ascii_case("none") {
            Ok(GridBox::None)
        } else if t.eq_ignore_ascii_case("vision") {
            Ok(GridBox::Vision)
        } else {
            t.parse::<i64>().map(GridBox::Side).map_err(|_| {
                format!("invalid grid box {s:?}: expected `none`, `vision` or a positive integer")
            })
        }
    }
}

/// How [`GridBox`] appears in config files and `run.json` (human-readable formats).
#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum GridBoxRepr {
    Side(i64),
    Name(String),
}

/// How [`GridBox`] appears in binary formats (checkpoints), which cannot read an untagged
/// enum.
#[derive(Serialize, Deserialize)]
enum GridBoxTagged {
    Side(i64),
    Vision,
    None,
}

impl Serialize for GridBox {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        if !s.is_human_readable() {
            return match *self {
                GridBox::Side(a) => GridBoxTagged::Side(a),
                GridBox::Vision => GridBoxTagged::Vision,
                GridBox::None => GridBoxTagged::None,
            }
            .serialize(s);
        }
        match self {
            GridBox::Side(a) => GridBoxRepr::Side(*a),
            other => GridBoxRepr::Name(other.to_string()),
        }
        .serialize(s)
    }
}

impl<'de> Deserialize<'de> for GridBox {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        if !d.is_human_readable() {
            return Ok(match GridBoxTagged::deserialize(d)? {
                GridBoxTagged::Side(a) => GridBox::Side(a),
                GridBoxTagged::Vision => GridBox::Vision,
                GridBoxTagged::None => GridBox::None,
            });
        }
        match GridBoxRepr::deserialize(d)? {
            GridBoxRepr::Side(a) => Ok(GridBox::Side(a)),
            GridBoxRepr::Name(n) => n.parse().map_err(serde::de::Error::custom),
        }
    }
}

/// `--grid-box` as the declarations read it: the text `none`, `vision` or a side.
impl ParamValue for GridBox {
    const KIND: Kind = Kind::Text;
    const PYTHON: &'static str = "GridBox";
    fn from_input(v: &Input) -> Result<Self, String> {
        // Every front end gives a text value its text (Python's ints too).
        match v {
            Input::Text(s) => s.parse(),
            other => Err(format!(
                "expected `none`, `vision` or a positive integer, not {other:?}"
            )),
        }
    }
    fn parse_text(s: &str) -> Result<Self, String> {
        s.parse()
    }
    /// A side from 1 to [`MAX_RADIUS`]; the names always.
    fn in_range(&self, _: &Range) -> bool {
        match *self {
            GridBox::Side(a) => (1..=MAX_RADIUS).contains(&a),
            GridBox::Vision | GridBox::None => true,
        }
    }
    fn show(&self) -> String {
        self.to_string()
    }
}

/// Bad parameters: each names the offending value and the accepted range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamsError {
    /// A value outside its declared range, named by its flag.
    #[error(transparent)]
    Range(#[from] RangeError),
    /// A rule name that is not a rule of that species.
    #[error("unknown {species} rule {name:?}; accepted: {accepted}")]
    UnknownRule {
        /// `fox` or `rabbit`.
        species: &'static str,
        /// The name given.
        name: String,
        /// The accepted names, comma separated.
        accepted: String,
    },
    /// A rule listed twice.
    #[error("{species} rule {name:?} is listed twice; each rule may appear at most once")]
    DuplicateRule {
        /// `fox` or `rabbit`.
        species: &'static str,
        /// The repeated name.
        name: String,
    },
    /// A species that starts with animats but has no rules: they would never act.
    #[error(
        "{species}_rules is empty, so a {species} would never act; give at least one of: {accepted}"
    )]
    NoRules {
        /// `fox` or `rabbit`.
        species: &'static str,
        /// The accepted names, comma separated.
        accepted: String,
    },
    /// `hungry_at` above `starve`: a fox would starve before it is ever hungry.
    #[error(
        "hungry_at = {hungry_at} is above starve = {starve}: a fox would starve before it is ever hungry (hunting and eating would never run); use hungry_at <= starve"
    )]
    NeverHungry {
        /// `hungry_at`.
        hungry_at: u32,
        /// `starve`.
        starve: u32,
    },
    /// More animats than [`MAX_ANIMATS`].
    #[error(
        "{animats} animats (foxes + rabbits) are more than the model numbers (at most 2^32 - 1 = {MAX_ANIMATS}); lower --foxes or --rabbits"
    )]
    TooManyAnimats {
        /// Foxes plus rabbits.
        animats: u64,
    },
    /// More animats than the start disc can hold at half occupancy.
    #[error(
        "{animats} animats do not fit in a start disc of radius {radius} \
         (at most {max} = half its cells); raise start_radius (--start-radius) or lower the populations (--foxes, --rabbits)"
    )]
    StartTooDense {
        /// Foxes plus rabbits.
        animats: u64,
        /// `start_radius`.
        radius: i64,
        /// Largest accepted number of animats.
        max: u64,
    },
}

/// Steps a run takes unless told otherwise (`--steps`).
pub const DEFAULT_STEPS: u64 = 1000;

/// Largest vision, crowding radius, start radius and grid-box side accepted: squared radii stay
/// far inside `u64` and coordinates far inside `i64`.
pub const MAX_RADIUS: i64 = 1 << 30;

/// Most live animats the model numbers: a step visits them through 32-bit indices. A start
/// population above it is refused; during a run a birth that would pass it does not happen (a
/// cap no run meets before memory runs out: [`ANIMAT_BYTES`] per animat is 1 TiB here).
pub const MAX_ANIMATS: u64 = u32::MAX as u64;

/// Memory per animat besides the cell index's tiles, in bytes: its record in id order and in
/// visiting order, its flags, its visiting-order index and its grid-box entry, with their
/// vectors' slack. 1e6 animats at density 0.2 take 267 MB of resident memory, about 45 MB of
/// it in tiles.
pub const ANIMAT_BYTES: u64 = 256;

/// Peak memory of a run that does not grow with the population (the binary, its libraries,
/// the step's scratch); see [`Params::peak_memory_bytes`].
pub const PEAK_FIXED_BYTES: u64 = 8 << 20;

/// Largest accepted radius, as a range bound.
const R: i128 = MAX_RADIUS as i128;

/// Largest `u32`, as a range bound.
const U32: i128 = u32::MAX as i128;

const fn int(min: i128, max: i128) -> Range {
    Range::Int {
        min,
        max: Some(max),
    }
}

core_lattice::declare_params! {
    /// Every parameter of the model (`docs/animat.md`, "Parameters and defaults"), declared
    /// once: the `animat` binary's flags and config keys, the Python keyword arguments, the
    /// stubs and the docs' table are made from this list. Build one (or start from
    /// [`Params::default`]), call [`Params::validate`] (the [`World`](crate::World) does), run.
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields, default)]
    pub struct Params {
        /// Foxes at the start.
        foxes: u64 = 300 => { flag: "foxes", unit: "foxes", range: Range::Any },
        /// Rabbits at the start.
        rabbits: u64 = 2000 => { flag: "rabbits", unit: "rabbits", range: Range::Any },
        /// Radius of the start disc around the origin (its cells at least twice the animats).
        /// The start population is placed on distinct cells drawn uniformly in it; --density
        /// sets it from a density instead.
        start_radius: i64 = 60 => {
            flag: "start-radius", unit: "cells", range: int(0, R),
            why: "coordinates stay far inside 64-bit integers",
        },
        /// Vision radius, Euclidean. The paper's is 60.
        vision: i64 = 60 => {
            flag: "vision", unit: "cells", range: int(1, R),
            why: "squared radii stay far inside 64-bit integers",
        },
        /// Grid-box side: speed only, every setting gives the same trajectory. A positive
        /// integer, `vision` (boxes of the vision radius, the paper's choice) or `none` (the
        /// exhaustive search without boxes).
        grid_box: GridBox = GridBox::Vision => {
            flag: "grid-box", unit: "cells",
            range: Range::Text("a positive integer up to 1073741824, `vision` or `none`"),
        },
        /// A fox is hungry when its hunger (steps since it last ate) is at least this.
        hungry_at: u32 = 10 => { flag: "hungry-at", unit: "steps", range: Range::Text("0..=`starve`") },
        /// A fox whose hunger exceeds this dies of starvation.
        starve: u32 = 30 => { flag: "starve", unit: "steps", range: int(1, U32) },
        /// A fox older than this dies.
        fox_max_age: u32 = 400 => { flag: "fox-max-age", unit: "steps", range: int(1, U32) },
        /// A rabbit older than this dies.
        rabbit_max_age: u32 = 200 => { flag: "rabbit-max-age", unit: "steps", range: int(1, U32) },
        /// Probability that the fox breed rule, once its condition holds, produces a fox.
        fox_breed_p: f64 = 0.02 => {
            flag: "fox-breed-p", unit: "", range: Range::Real(End::Closed(0.0), End::Closed(1.0)),
        },
        /// Probability that the rabbit breed rule, once its condition holds, produces a rabbit.
        rabbit_breed_p: f64 = 0.1 => {
            flag: "rabbit-breed-p", unit: "", range: Range::Real(End::Closed(0.0), End::Closed(1.0)),
        },
        /// Rabbits needed within vision for a fox to breed.
        prey_needed: u32 = 10 => { flag: "prey-needed", unit: "rabbits", range: int(0, U32) },
        /// More than this many animats within crowd_radius forbid breeding. Either species
        /// counts, the breeder excluded.
        crowd_max: u32 = 4 => { flag: "crowd-max", unit: "animats", range: int(0, U32 - 1) },
        /// Radius of the overcrowding count, Euclidean.
        crowd_radius: i64 = 2 => { flag: "crowd-radius", unit: "cells", range: int(1, R) },
        /// Fox rules in priority order, each at most once.
        fox_rules: Vec<String> = FoxRule::ALL.iter().map(|r| r.name().to_string()).collect() => {
            flag: "fox-rules", unit: "", range: Range::Choices(&FoxRule::NAMES),
        },
        /// Rabbit rules in priority order, each at most once.
        rabbit_rules: Vec<String> = RabbitRule::ALL.iter().map(|r| r.name().to_string()).collect() => {
            flag: "rabbit-rules", unit: "", range: Range::Choices(&RabbitRule::NAMES),
        },
    }
    internal {}
    tables { const PARAMS; fn defaults; }
}

/// The names of `all` rules, comma separated.
fn rule_names<R: Copy>(all: &[R], name_of: fn(R) -> &'static str) -> String {
    all.iter()
        .map(|&r| name_of(r))
        .collect::<Vec<_>>()
        .join(", ")
}

fn parse_rules<R: Copy + PartialEq>(
    species: &'static str,
    names: &[String],
    all: &[R],
    name_of: fn(R) -> &'static str,
) -> Result<Vec<R>, ParamsError> {
    let mut out: Vec<R> = Vec::with_capacity(names.len());
    for n in names {
        let rule = all
            .iter()
            .copied()
            .find(|&r| name_of(r) == n.as_str())
            .ok_or_else(|| ParamsError::UnknownRule {
                species,
                name: n.clone(),
                accepted: rule_names(all, name_of),
            })?;
        if out.contains(&rule) {
            return Err(ParamsError::DuplicateRule {
                species,
                name: n.clone(),
            });
        }
        out.push(rule);
    }
    Ok(out)
}

impl Params {
    /// The fox rules as typed values, in priority order.
    ///
    /// # Errors
    /// [`ParamsError::UnknownRule`] or [`ParamsError::DuplicateRule`].
    pub fn fox_rule_list(&self) -> Result<Vec<FoxRule>, ParamsError> {
        parse_rules("fox", &self.fox_rules, &FoxRule::ALL, FoxRule::name)
    }

    /// The rabbit rules as typed values, in priority order.
    ///
    /// # Errors
    /// [`ParamsError::UnknownRule`] or [`ParamsError::DuplicateRule`].
    pub fn rabbit_rule_list(&self) -> Result<Vec<RabbitRule>, ParamsError> {
        parse_rules(
            "rabbit",
            &self.rabbit_rules,
            &RabbitRule::ALL,
            RabbitRule::name,
        )
    }

    /// Largest start population the start disc accepts: half the cells of the disc.
    pub fn start_capacity(&self) -> u64 {
        let r = self.start_radius as f64;
        (std::f64::consts::PI * r * r / 2.0).floor() as u64
    }

    /// Checks every value against its accepted range.
    ///
    /// # Errors
    /// The first offending value, as a [`ParamsError`] naming it and its accepted range.
    pub fn validate(&self) -> Result<(), ParamsError> {
        self.check_ranges()?;
        self.fox_rule_list()?;
        self.rabbit_rule_list()?;
        // An empty list is accepted for a species with no animats (a hand-built scene).
        if self.fox_rules.is_empty() && self.foxes > 0 {
            return Err(ParamsError::NoRules {
                species: "fox",
                accepted: rule_names(&FoxRule::ALL, FoxRule::name),
            });
        }
        if self.rabbit_rules.is_empty() && self.rabbits > 0 {
            return Err(ParamsError::NoRules {
                species: "rabbit",
                accepted: rule_names(&RabbitRule::ALL, RabbitRule::name),
            });
        }
        if self.hungry_at > self.starve {
            return Err(ParamsError::NeverHungry {
                hungry_at: self.hungry_at,
                starve: self.starve,
            });
        }
        let animats = self.foxes.saturating_add(self.rabbits);
        if animats > MAX_ANIMATS {
            return Err(ParamsError::TooManyAnimats { animats });
        }
        let max = self.start_capacity();
        if animats > max {
            return Err(ParamsError::StartTooDense {
                animats,
                radius: self.start_radius,
                max,
            });
        }
        Ok(())
    }

    /// Memory the start population takes, estimated before placing it: a tile of the cell
    /// index ([`TILE_BYTES`](spatial::cells::TILE_BYTES), 36 KiB per 64 x 64 cells) for each
    /// square that gets an animat, the expected number when `N` animats fall uniformly on the
    /// `T` tiles meeting the start disc, `T (1 - exp(-N / T))` (so about `N` tiles for a
    /// dilute start), plus [`ANIMAT_BYTES`] per animat.
    pub fn start_memory_bytes(&self) -> u64 {
        let n = self.foxes.saturating_add(self.rabbits) as f64;
        let tile = spatial::cells::TILE as f64;
        let tiles = std::f64::consts::PI
            * (self.start_radius as f64 / tile + std::f64::consts::SQRT_2).powi(2);
        let occupied = tiles * -(-n / tiles).exp_m1();
        // Saturates at u64::MAX for absurd populations.
        (occupied * spatial::cells::TILE_BYTES as f64 + n * ANIMAT_BYTES as f64) as u64
    }

    /// Peak memory of a run of these parameters, estimated before it starts:
    /// [`start_memory_bytes`](Self::start_memory_bytes) plus [`PEAK_FIXED_BYTES`] (the
    /// binary, its libraries, the step's scratch). An upper bound of the measured peak RSS of
    /// a run whose population does not grow much (docs/animat.md, "Memory"); a world that
    /// grows past the limit is stopped by the binary as it steps.
    pub fn peak_memory_bytes(&self) -> u64 {
        self.start_memory_bytes().saturating_add(PEAK_FIXED_BYTES)
    }

    /// Start radius giving `animats` animats at `density` animats per cell:
    /// `ceil(sqrt(animats / (pi density)))` (`--density`).
    pub fn radius_for_density(animats: u64, density: f64) -> i64 {
        (animats as f64 / (std::f64::consts::PI * density))
            .sqrt()
            .ceil() as i64
    }

    /// `--density`: sets `start_radius` so that the start population (`foxes + rabbits`, as
    /// set now) has `density` animats per cell.
    ///
    /// # Errors
    /// A density outside (0, 0.5], or one so low that the radius exceeds [`MAX_RADIUS`]; the
    /// message is the `animat` binary's.
    pub fn set_density(&mut self, density: f64) -> Result<(), String> {
        let d = density;
        if !(d > 0.0 && d <= 0.5) {
            return Err(format!(
                "--density {d} is outside the accepted range (0, 0.5]"
            ));
        }
        let animats = self.foxes.saturating_add(self.rabbits);
        self.start_radius = Params::radius_for_density(animats, d);
        if self.start_radius > MAX_RADIUS {
            return Err(format!(
                "--density {d:e} spreads {animats} animats over a start disc of radius {:.3e} cells, above the largest accepted {MAX_RADIUS}; raise --density",
                (animats as f64 / (std::f64::consts::PI * d)).sqrt()
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
