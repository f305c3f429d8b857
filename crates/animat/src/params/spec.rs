//! The table of animat parameters ([`PARAMS`]): name, flag, unit, meaning and accepted range of
//! every [`Params`] field (the config file's keys) and of `--density`, beside their defaults
//! from [`Params::default`] ([`defaults`]). The `animat` binary, its config files, the Python
//! bindings and `docs/animat.md` are checked against it (`docs/architecture.md`, "Parameters:
//! one declaration").

use super::{FoxRule, MAX_RADIUS, Params, RabbitRule};
use core_lattice::spec::{End, ParamSpec, Range};

const fn int(min: i128, max: i128) -> Range {
    Range::Int {
        min,
        max: Some(max),
    }
}

/// Largest accepted radius, as a range bound.
const R: i128 = MAX_RADIUS as i128;

/// Largest `u32`, as a range bound.
const U32: i128 = u32::MAX as i128;

/// Every parameter, in the order of `docs/animat.md`'s table: the fields of [`Params`] (their
/// names are the config file's keys and the Python keywords; [`FLAGS`](super::FLAGS) have a
/// flag too) and `density`, which sets `start_radius`. The ranges are those
/// [`Params::validate`] accepts (written as its error messages write them; a unit test probes
/// each bound).
pub const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "foxes",
        flag: Some("foxes"),
        unit: "foxes",
        doc: "Foxes at the start.",
        range: Range::Any,
    },
    ParamSpec {
        name: "rabbits",
        flag: Some("rabbits"),
        unit: "rabbits",
        doc: "Rabbits at the start.",
        range: Range::Any,
    },
    ParamSpec {
        name: "start_radius",
        flag: Some("start-radius"),
        unit: "cells",
        doc: "Radius of the start disc around the origin (its cells at least twice the animats).",
        range: int(0, R),
    },
    ParamSpec {
        name: "density",
        flag: Some("density"),
        unit: "animats per cell",
        doc: "Start density: sets start_radius to ceil(sqrt(animats / (pi density))).",
        range: Range::Real(End::Open(0.0), End::Closed(0.5)),
    },
    ParamSpec {
        name: "vision",
        flag: Some("vision"),
        unit: "cells",
        doc: "Vision radius, Euclidean.",
        range: int(1, R),
    },
    ParamSpec {
        name: "grid_box",
        flag: Some("grid-box"),
        unit: "cells",
        doc: "Grid-box side: speed only, every setting gives the same trajectory.",
        range: Range::Text("a positive integer, `vision` or `none`"),
    },
    ParamSpec {
        name: "hungry_at",
        flag: None,
        unit: "steps",
        doc: "A fox is hungry when its hunger (steps since it last ate) is at least this.",
        range: Range::Text("0..=`starve`"),
    },
    ParamSpec {
        name: "starve",
        flag: None,
        unit: "steps",
        doc: "A fox whose hunger exceeds this dies of starvation.",
        range: int(1, U32),
    },
    ParamSpec {
        name: "fox_max_age",
        flag: None,
        unit: "steps",
        doc: "A fox older than this dies.",
        range: int(1, U32),
    },
    ParamSpec {
        name: "rabbit_max_age",
        flag: None,
        unit: "steps",
        doc: "A rabbit older than this dies.",
        range: int(1, U32),
    },
    ParamSpec {
        name: "fox_breed_p",
        flag: None,
        unit: "",
        doc: "Probability that the fox breed rule, once its condition holds, produces a fox.",
        range: Range::Real(End::Closed(0.0), End::Closed(1.0)),
    },
    ParamSpec {
        name: "rabbit_breed_p",
        flag: None,
        unit: "",
        doc: "Probability that the rabbit breed rule, once its condition holds, produces a rabbit.",
        range: Range::Real(End::Closed(0.0), End::Closed(1.0)),
    },
    ParamSpec {
        name: "prey_needed",
        flag: None,
        unit: "rabbits",
        doc: "Rabbits needed within vision for a fox to breed.",
        range: int(0, U32),
    },
    ParamSpec {
        name: "crowd_max",
        flag: None,
        unit: "animats",
        doc: "More than this many animats within crowd_radius forbid breeding.",
        range: int(0, U32 - 1),
    },
    ParamSpec {
        name: "crowd_radius",
        flag: None,
        unit: "cells",
        doc: "Radius of the overcrowding count, Euclidean.",
        range: int(1, R),
    },
    ParamSpec {
        name: "fox_rules",
        flag: None,
        unit: "",
        doc: "Fox rules in priority order, each at most once.",
        range: Range::Choices(&FoxRule::NAMES),
    },
    ParamSpec {
        name: "rabbit_rules",
        flag: None,
        unit: "",
        doc: "Rabbit rules in priority order, each at most once.",
        range: Range::Choices(&RabbitRule::NAMES),
    },
];

/// The default of every parameter of [`PARAMS`], keyed by name, from [`Params::default`]
/// (`density`: `null`, the start radius is the default's).
pub fn defaults() -> serde_json::Map<String, serde_json::Value> {
    let mut m = match serde_json::to_value(Params::default()) {
        Ok(serde_json::Value::Object(m)) => m,
        _ => unreachable!("Params serialises to a JSON object"),
    };
    m.insert("density".into(), serde_json::Value::Null);
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::Value;

    #[test]
    fn the_table_names_every_field_once() {
        assert!(core_lattice::spec::duplicates(PARAMS).is_empty());
        let mut names: Vec<&str> = PARAMS.iter().map(|s| s.name).collect();
        let d = defaults();
        let mut keys: Vec<&str> = d.keys().map(String::as_str).collect();
        names.sort_unstable();
        keys.sort_unstable();
        assert_eq!(names, keys, "PARAMS against the fields of Params");
        for s in PARAMS {
            let flagged = super::super::FLAGS.contains(&s.name) || s.name == "density";
            assert_eq!(s.flag.is_some(), flagged, "{}", s.name);
            if let Some(f) = s.flag {
                assert_eq!(f, s.name.replace('_', "-"));
            }
        }
        assert_eq!(FoxRule::ALL.map(FoxRule::name), FoxRule::NAMES);
        assert_eq!(RabbitRule::ALL.map(RabbitRule::name), RabbitRule::NAMES);
    }

    /// Validation accepts each range's bounds and refuses the nearest values outside, naming
    /// the range as the table writes it.
    #[test]
    fn validation_refuses_just_outside_each_stated_range() {
        core_lattice::spec::check_range_probes(PARAMS, |name, value| {
            let v: Value = serde_json::from_str(value).unwrap();
            let mut p = Params::default();
            if name == "density" {
                return p.set_density(v.as_f64().unwrap());
            }
            let mut m = serde_json::to_value(&p).unwrap();
            // An empty world, so that any start radius holds it.
            if name == "start_radius" {
                m["foxes"] = 0.into();
                m["rabbits"] = 0.into();
            }
            // Never hungry before starving (the bound between the two is `hungry_at`'s).
            if name == "starve" {
                m["hungry_at"] = 0.into();
            }
            m[name] = v;
            serde_json::from_value::<Params>(m)
                .map_err(|e| format!("invalid: {e}"))
                .and_then(|q| {
                    p = q;
                    p.validate().map_err(|e| e.to_string())
                })
        });
    }
}
