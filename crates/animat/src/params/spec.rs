//! The tests of the table of animat parameters ([`PARAMS`], written by [`Params`]'s
//! declaration): it names every field once, and validation accepts each stated range's bounds
//! and refuses the nearest values outside.

use super::{FoxRule, PARAMS, Params, RabbitRule, defaults};
use serde_json::Value;

#[test]
fn the_table_names_every_field_once() {
    core_lattice::spec::check_table(PARAMS, defaults().keys().map(String::as_str));
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
