//! The table of DLA/PDLA parameters ([`PARAMS`]): name, flag, unit, meaning and accepted range
//! of every [`Params`] field a front end sets, beside the defaults of [`Params::default`]
//! ([`defaults`]). The `dla` binary, the Python bindings, xtask and `docs/dla.md` are checked
//! against it (`docs/architecture.md`, "Parameters: one declaration").

use super::{FarField, Params};
use crate::space::DIMENSIONS;
use core_lattice::spec::{End, ParamSpec, Range};

/// Every parameter a front end sets, in the order of `docs/dla.md`'s flag table. The ranges
/// are those [`Params::validate`] accepts (written as its error messages write them; a unit
/// test probes each bound).
pub const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "dim",
        flag: Some("dim"),
        unit: "",
        doc: "Space dimension.",
        range: Range::Values(DIMENSIONS),
    },
    ParamSpec {
        name: "particles",
        flag: Some("particles"),
        unit: "particles",
        doc: "Particles of the final cluster, seed included (at most 2.5e9 in 4D and 5D).",
        range: Range::Int {
            min: 1,
            max: Some(super::MAX_PARTICLES as i128),
        },
    },
    ParamSpec {
        name: "birth_gap",
        flag: Some("birth-gap"),
        unit: "diameters",
        doc: "R_b - R_ext, the distance of the birth sphere outside the cluster.",
        range: Range::Real(End::Closed(1.0), End::Closed(super::MAX_BIRTH_GAP)),
    },
    ParamSpec {
        name: "far_field",
        flag: Some("far-field"),
        unit: "",
        doc: "What happens to a walker outside the birth sphere.",
        range: Range::Choices(&FarField::NAMES),
    },
    ParamSpec {
        name: "death_ratio",
        flag: Some("death-ratio"),
        unit: "birth radii",
        doc: "R_d / R_b, the death radius of the jump far field.",
        range: Range::Real(End::Open(1.0), End::Closed(super::MAX_DEATH_RATIO)),
    },
    ParamSpec {
        name: "sticking_probability",
        flag: Some("sticking-probability"),
        unit: "",
        doc: "Probability that a walker sticks at a contact; one that does not walks on from there.",
        range: Range::Real(End::Open(0.0), End::Closed(1.0)),
    },
    ParamSpec {
        name: "noise_reduction",
        flag: Some("noise-reduction"),
        unit: "diameters",
        doc: "Distance f of a stuck particle from the one it touched (fastDLA's noise reduction).",
        range: Range::Real(End::Open(0.0), End::Closed(1.0)),
    },
    ParamSpec {
        name: "step_min",
        flag: Some("step-min"),
        unit: "diameters",
        doc: "Near-field step length.",
        range: Range::Real(End::Closed(super::MIN_STEP_MIN), End::Closed(1e3)),
    },
    ParamSpec {
        name: "precision",
        flag: Some("precision"),
        unit: "",
        doc: "Precision kappa of the variable-precision distance (inf: exact search).",
        range: Range::Real(End::Open(0.5), End::Unbounded),
    },
    ParamSpec {
        name: "leaf_side",
        flag: Some("leaf-side"),
        unit: "diameters",
        doc: "Side of the orthtree's leaf cells: speed and memory only.",
        range: Range::Values(&[1, 2, 4, 8, 16, 32, 64]),
    },
    ParamSpec {
        name: "near_cache",
        flag: Some("near-cache"),
        unit: "",
        doc: "Each walker's exact near cache: speed only, the same trajectory.",
        range: Range::Any,
    },
    ParamSpec {
        name: "distance_map",
        flag: Some("distance-map"),
        unit: "",
        doc: "The coarse distance maps in front of the orthtree: speed only, another trajectory.",
        range: Range::Any,
    },
    ParamSpec {
        name: "threads",
        flag: Some("threads"),
        unit: "walkers",
        doc: "Walkers moving at once (PDLA); 1 is DLA.",
        range: Range::Int {
            min: 1,
            max: Some(1024),
        },
    },
    ParamSpec {
        name: "serial_until",
        flag: Some("serial-until"),
        unit: "particles",
        doc: "With threads > 1, grow with one walker up to this size.",
        range: Range::Any,
    },
    ParamSpec {
        name: "fit_from",
        flag: Some("fit-from"),
        unit: "particles",
        doc: "Smallest N in the fractal-dimension fit.",
        range: Range::Int { min: 2, max: None },
    },
];

/// `Params` fields that are not parameters of a front end: set by the front end itself
/// (`keep_positions`: the binary streams positions to a file, Python keeps them).
pub const INTERNAL: &[&str] = &["keep_positions"];

/// The default of every parameter of [`PARAMS`], keyed by name, from [`Params::default`].
pub fn defaults() -> serde_json::Map<String, serde_json::Value> {
    let mut m = match serde_json::to_value(Params::default()) {
        Ok(serde_json::Value::Object(m)) => m,
        _ => unreachable!("Params serialises to a JSON object"),
    };
    for k in INTERNAL {
        m.remove(*k);
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_names_every_field_once() {
        assert!(core_lattice::spec::duplicates(PARAMS).is_empty());
        let names: Vec<&str> = PARAMS.iter().map(|s| s.name).collect();
        let mut fields: Vec<String> = defaults().keys().cloned().collect();
        let mut sorted = names.clone();
        sorted.sort_unstable();
        fields.sort_unstable();
        assert_eq!(sorted, fields, "PARAMS against the fields of Params");
        for s in PARAMS {
            assert_eq!(s.flag, Some(s.name.replace('_', "-")).as_deref());
        }
        assert_eq!(FarField::ALL.map(FarField::name), FarField::NAMES);
        for f in FarField::ALL {
            assert_eq!(f.name().parse::<FarField>(), Ok(f));
        }
        assert_eq!(
            "sideways".parse::<FarField>().unwrap_err(),
            "invalid value 'sideways' for '--far-field': possible values are return, jump"
        );
    }

    /// Validation accepts each range's bounds and refuses the nearest values outside, naming
    /// the range as the table writes it.
    #[test]
    fn validation_refuses_just_outside_each_stated_range() {
        let d = defaults();
        core_lattice::spec::check_range_probes(PARAMS, |name, value| {
            let mut m = d.clone();
            m.insert(name.into(), serde_json::from_str(value).unwrap());
            m.insert("keep_positions".into(), false.into());
            serde_json::from_value::<Params>(m.into())
                .map_err(|e| e.to_string())
                .and_then(|p| p.validate().map_err(|e| e.to_string()))
        });
    }

    #[test]
    fn the_dimension_dispatch_covers_exactly_the_dimensions() {
        for d in 0..10usize {
            let got = crate::with_dim!(d, D => Some(D), _ => None);
            assert_eq!(got.is_some(), DIMENSIONS.contains(&d), "{d}");
            assert!(got.is_none_or(|g| g == d));
        }
    }

    #[test]
    fn paper_settings_refuse_what_they_set() {
        let p = Params::default().with_paper_settings(|_| false).unwrap();
        assert_eq!(p, Params::default().paper_settings());
        let e = Params::default()
            .with_paper_settings(|n| n == "step_min")
            .unwrap_err();
        assert!(
            e.to_string()
                .starts_with("--step-min cannot be given with --paper-settings"),
            "{e}"
        );
        // It sets fields of PAPER_SETTINGS only.
        let (a, b) = (
            serde_json::to_value(Params::default()).unwrap(),
            serde_json::to_value(p).unwrap(),
        );
        for (k, v) in a.as_object().unwrap() {
            if !super::super::PAPER_SETTINGS.contains(&k.as_str()) {
                assert_eq!(&b[k], v, "{k}");
            }
        }
    }
}
