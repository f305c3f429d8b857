//! The table of DLCA parameters ([`PARAMS`]): name, flag, unit, meaning and accepted range of
//! every parameter a front end sets, beside their defaults from [`Params::default`]
//! ([`defaults`]). The names are the flags' (and the Python keywords'); the front ends turn them
//! into [`Params`] with [`flags`](super::flags) (`--dim` and `--size` into
//! [`Params::size`], `--fill` or `--particles` into [`Params::init`]). The `dlca` binary, the
//! Python bindings, xtask and `docs/dlca.md` are checked against it (`docs/architecture.md`,
//! "Parameters: one declaration").

use super::{DEFAULT_HISTOGRAM_SWEEPS, MAX_MODEL_DIM, Params, Search};
use core_lattice::spec::{End, ParamSpec, Range};

const fn int(min: i128, max: Option<i128>) -> Range {
    Range::Int { min, max }
}

/// Every parameter a front end sets, in the order of `docs/dlca.md`'s flag table. The ranges
/// are those [`Params::validate`] accepts (written as its error messages write them; a unit
/// test probes each bound).
pub const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "dim",
        flag: Some("dim"),
        unit: "",
        doc: "Lattice dimension.",
        range: int(1, Some(MAX_MODEL_DIM as i128)),
    },
    ParamSpec {
        name: "size",
        flag: Some("size"),
        unit: "sites",
        doc: "Side lengths: one for every axis or one per axis.",
        range: Range::Any,
    },
    ParamSpec {
        name: "boundary",
        flag: Some("boundary"),
        unit: "",
        doc: "Boundary of every axis, or of each axis.",
        range: Range::Choices(&["periodic", "wall"]),
    },
    ParamSpec {
        name: "fill",
        flag: Some("fill"),
        unit: "",
        doc: "Fraction of sites holding a particle at the start.",
        range: Range::Real(End::Open(0.0), End::Open(1.0)),
    },
    ParamSpec {
        name: "particles",
        flag: Some("particles"),
        unit: "particles",
        doc: "Number of particles at the start.",
        range: Range::Text("1 to the number of sites"),
    },
    ParamSpec {
        name: "temperature",
        flag: Some("temperature"),
        unit: "",
        doc: "Move probability of a cluster per sweep.",
        range: Range::Real(End::Open(0.0), End::Closed(1.0)),
    },
    ParamSpec {
        name: "mobility_exponent",
        flag: Some("mobility-exponent"),
        unit: "",
        doc: "gamma: a cluster of s particles moves with probability temperature * s^-gamma.",
        range: Range::Real(End::Closed(0.0), End::Open(f64::INFINITY)),
    },
    ParamSpec {
        name: "gravity",
        flag: Some("gravity"),
        unit: "",
        doc: "g: moves down the last axis have weight 1+g, up 1-g.",
        range: Range::Real(End::Closed(0.0), End::Open(1.0)),
    },
    ParamSpec {
        name: "target_clusters",
        flag: Some("target-clusters"),
        unit: "clusters",
        doc: "Stop when at most this many clusters remain.",
        range: int(1, None),
    },
    ParamSpec {
        name: "max_sweeps",
        flag: Some("max-sweeps"),
        unit: "sweeps",
        doc: "Stop after this many sweeps at the latest (none: no limit).",
        range: Range::Any,
    },
    ParamSpec {
        name: "search",
        flag: Some("search"),
        unit: "",
        doc: "Contact search; every strategy gives the same trajectory.",
        range: Range::Choices(&Search::NAMES),
    },
    ParamSpec {
        name: "grid_box",
        flag: Some("grid-box"),
        unit: "sites",
        doc: "Initial grid-box side for the grid strategies (none: chosen).",
        range: Range::Text("a power of two"),
    },
    ParamSpec {
        name: "max_memory",
        flag: Some("max-memory"),
        unit: "bytes",
        doc: "Memory the occupancy lattice may take.",
        range: Range::Any,
    },
    ParamSpec {
        name: "gyration",
        flag: Some("gyration"),
        unit: "",
        doc: "Measure each final cluster's radius of gyration and fit the fractal dimension.",
        range: Range::Any,
    },
    ParamSpec {
        name: "fit_min_size",
        flag: Some("fit-min-size"),
        unit: "particles",
        doc: "Smallest cluster size in the fractal-dimension fit.",
        range: int(2, None),
    },
    ParamSpec {
        name: "timing",
        flag: Some("timing"),
        unit: "",
        doc: "Record the wall time of each sweep.",
        range: Range::Any,
    },
    ParamSpec {
        name: "histogram",
        flag: Some("histogram"),
        unit: "",
        doc: "Record histograms of candidate clusters examined per move.",
        range: Range::Any,
    },
    ParamSpec {
        name: "histogram_sweeps",
        flag: Some("histogram-sweeps"),
        unit: "sweeps",
        doc: "The sweeps at which histograms are recorded.",
        range: Range::Any,
    },
];

/// The default of every parameter of [`PARAMS`], keyed by name, from [`Params::default`]:
/// `null` where the front end must be given a value (`size`, and one of `fill` and
/// `particles`) or where none means a choice (`max_sweeps`: no limit, `grid_box`: chosen).
pub fn defaults() -> serde_json::Map<String, serde_json::Value> {
    let p = Params::default();
    let sweeps: Vec<u64> = DEFAULT_HISTOGRAM_SWEEPS
        .split(',')
        .filter_map(|s| s.parse().ok())
        .collect();
    let v = serde_json::json!({
        "dim": p.dim(),
        "size": null,
        "boundary": p.boundary[0].to_string(),
        "fill": null,
        "particles": null,
        "temperature": p.temperature,
        "mobility_exponent": p.mobility_exponent,
        "gravity": p.gravity,
        "target_clusters": p.target_clusters,
        "max_sweeps": p.max_sweeps,
        "search": p.search.name(),
        "grid_box": p.grid_box,
        "max_memory": p.max_memory,
        "gyration": p.gyration,
        "fit_min_size": p.fit_min_size,
        "timing": p.timing,
        "histogram": !p.histogram_sweeps.is_empty(),
        "histogram_sweeps": sweeps,
    });
    match v {
        serde_json::Value::Object(m) => m,
        _ => unreachable!("a JSON object"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Init;
    use serde_json::Value;

    #[test]
    fn the_table_has_a_default_for_every_parameter() {
        assert!(core_lattice::spec::duplicates(PARAMS).is_empty());
        let d = defaults();
        assert_eq!(d.len(), PARAMS.len());
        for s in PARAMS {
            assert!(d.contains_key(s.name), "{}", s.name);
            assert_eq!(s.flag, Some(s.name.replace('_', "-")).as_deref());
        }
        assert_eq!(Search::ALL.map(Search::name), Search::NAMES);
        for x in Search::ALL {
            assert_eq!(x.name().parse::<Search>(), Ok(x));
        }
        assert!(
            "gird"
                .parse::<Search>()
                .unwrap_err()
                .ends_with("possible values are auto, all-pairs, grid, grid-doubling, lattice")
        );
        // Every boundary of the table parses, and nothing else.
        for b in PARAMS[2].range.choices() {
            assert_eq!(b.parse::<core_lattice::Boundary>().unwrap().to_string(), *b);
        }
    }

    /// `Params` with the parameter `name` set to `v`, as the front ends set it.
    fn with(name: &str, v: &Value) -> Result<Params, String> {
        let mut p = Params::default();
        let f = v.as_f64().unwrap();
        let n = || u64::try_from(v.as_i64().unwrap()).map_err(|e| e.to_string());
        match name {
            "dim" => {
                let (size, boundary) = super::super::flags::axes(
                    v.as_i64().unwrap().max(0) as usize,
                    &[64],
                    "periodic",
                )?;
                p.size = size;
                p.boundary = boundary;
            }
            "fill" => p.init = Init::Fill(f),
            "temperature" => p.temperature = f,
            "mobility_exponent" => p.mobility_exponent = f,
            "gravity" => p.gravity = f,
            "target_clusters" => p.target_clusters = n()?,
            "fit_min_size" => p.fit_min_size = n()?,
            other => panic!("no probe for {other}"),
        }
        Ok(p)
    }

    /// Validation accepts each range's bounds and refuses the nearest values outside, naming
    /// the range as the table writes it.
    #[test]
    fn validation_refuses_just_outside_each_stated_range() {
        core_lattice::spec::check_range_probes(PARAMS, |name, value| {
            let v: Value = serde_json::from_str(value).unwrap();
            with(name, &v).and_then(|p| p.validate().map_err(|e| e.to_string()))
        });
    }
}
