//! The table of animat parameters ([`PARAMS`]): name, flag, unit, meaning and accepted range
//! of every [`Params`] field, from [`Params`]'s one declaration, beside the defaults of
//! [`Params::default`] ([`defaults`]). `--density`, which sets `start_radius` from the start
//! population, is the front ends' own ([`Params::set_density`]).

use super::Params;
use core_lattice::spec::{DeclaredParams, ParamSpec, spec_table};

/// Every parameter, in declaration order: the table of [`Params`]'s declaration (its names are
/// the config files' keys and the Python keywords; the flags are `--` and the name with
/// dashes).
pub const PARAMS: &[ParamSpec] = &spec_table::<{ Params::DECLARED.len() }>(Params::DECLARED);

/// The default of every parameter of [`PARAMS`], keyed by name, from [`Params::default`].
#[cfg(feature = "files")]
pub fn defaults() -> serde_json::Map<String, serde_json::Value> {
    run_io::params_json::defaults_of::<Params>()
}

#[cfg(test)]
mod tests {
    use super::super::{FoxRule, RabbitRule};
    use super::*;
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
}
