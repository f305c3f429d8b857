//! The tests of the table of DLA/PDLA parameters ([`PARAMS`], written by [`Params`]'s
//! declaration): it names every field once, validation accepts each stated range's bounds and
//! refuses the nearest values outside, and the dimension dispatch and `--paper-settings` keep
//! to their rules.

use super::{FarField, PARAMS, Params, defaults};
use crate::space::DIMENSIONS;

#[test]
fn the_table_names_every_field_once() {
    core_lattice::spec::check_table(PARAMS, defaults().keys().map(String::as_str));
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
        // Drift has a meaning on a substrate only.
        if name == "drift" {
            m.insert("substrate_width".into(), 100.0.into());
        }
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
        if !super::PAPER_SETTINGS.contains(&k.as_str()) {
            assert_eq!(&b[k], v, "{k}");
        }
    }
}
