//! A model's declared parameters as Python keyword arguments: each keyword of the declaration
//! (`core_lattice::spec::DeclaredParams`) is read as its kind says (a float, a count, a bool, a
//! name) and set on the library's defaults, so that a parameter declared in its library is a
//! keyword argument without a line here. The package's Python layer builds the signature and
//! the docstring's parameter list from the same table (`aggsim._declared`).

use crate::convert::{Count, count};
use core_lattice::spec::{DeclaredParams, Input, Kind, ParamSpec};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyString};

/// Sets the declared parameters given as keyword arguments `kwargs` of `function` on `p`,
/// and returns the names given (a keyword given as None, allowed for optional parameters
/// only, counts as not given). `positional` are declared parameters the function takes as
/// its own arguments, so not as keywords here.
///
/// # Errors
/// `TypeError` for an unknown keyword or a value of the wrong type, `ValueError` for a count
/// that is not a whole number, naming the keyword.
pub fn set_keywords<P: DeclaredParams>(
    p: &mut P,
    table: &[ParamSpec],
    function: &str,
    positional: &[&str],
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<String>> {
    let mut given = Vec::new();
    let Some(kwargs) = kwargs else {
        return Ok(given);
    };
    for (key, value) in kwargs.iter() {
        let name: String = key.extract()?;
        let Some(d) = P::DECLARED
            .iter()
            .find(|d| d.spec.name == name && !positional.contains(&d.spec.name))
        else {
            return Err(PyTypeError::new_err(format!(
                "{function}() got an unexpected keyword argument '{name}'"
            )));
        };
        if value.is_none() {
            if d.optional {
                continue;
            }
            return Err(PyTypeError::new_err(format!(
                "{name} = None: expected {}",
                d.kind.python_type()
            )));
        }
        let wrong = || {
            let ty = value
                .get_type()
                .name()
                .map_or_else(|_| "another type".into(), |n| n.to_string());
            PyTypeError::new_err(format!(
                "{name} = {value}: expected {}, not {ty}",
                d.kind.python_type()
            ))
        };
        let input = match d.kind {
            // A bool is an int in Python: refused where a number is meant.
            Kind::Real if value.is_instance_of::<PyBool>() => return Err(wrong()),
            Kind::Real if value.is_instance_of::<PyFloat>() || value.is_instance_of::<PyInt>() => {
                Input::Real(value.extract::<f64>()?)
            }
            Kind::Count if value.is_instance_of::<PyBool>() => return Err(wrong()),
            Kind::Count => Input::Count(count::<u64>(table, &name, value.extract::<Count>()?)?),
            Kind::Switch if value.is_instance_of::<PyBool>() => Input::Switch(value.extract()?),
            Kind::Choice if value.is_instance_of::<PyString>() => Input::Choice(value.extract()?),
            _ => return Err(wrong()),
        };
        p.set(&name, &input)
            .map_err(|e| PyValueError::new_err(format!("{name} = {value}: {e}")))?;
        given.push(name);
    }
    Ok(given)
}

/// The declaration of a model as Python sees it: for each parameter, the kind's Python type,
/// the whole help text, and whether it is optional (None by default) — beside the table of
/// `aggsim._params`, for the signatures and docstrings `aggsim` builds.
pub fn declared_rows<P: DeclaredParams>() -> Vec<serde_json::Value> {
    P::DECLARED
        .iter()
        .map(|d| {
            serde_json::json!({
                "name": d.spec.name,
                "type": d.kind.python_type(),
                "help": core_lattice::spec::help_text(d.help),
                "why": d.why,
                "optional": d.optional,
            })
        })
        .collect()
}
