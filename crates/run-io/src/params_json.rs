//! A model's parameters as `run.json` and the front ends record them: the JSON object of the
//! values a front end sets, keyed by name.

use core_lattice::spec::DeclaredParams;
use serde::Serialize;
use serde_json::{Map, Value};

/// The library's default of every parameter of `P` a front end sets (not the
/// [`DeclaredParams::INTERNAL`] fields), by name, as JSON.
pub fn defaults_of<P: DeclaredParams + Serialize>() -> Map<String, Value> {
    let mut m = match serde_json::to_value(P::default()) {
        Ok(Value::Object(m)) => m,
        _ => panic!("a declared Params serialises to a JSON object"),
    };
    for k in P::INTERNAL {
        m.remove(*k);
    }
    m
}
