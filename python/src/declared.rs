//! A model's declared parameters as Python keyword arguments: each keyword of the declaration
//! (`core_lattice::spec::DeclaredParams`) is read as its kind says (a float, a count, a bool, a
//! name) and set on the library's defaults, so that a parameter declared in its library is a
//! keyword argument without a line here. The package's Python layer builds the signature and
//! the docstring's parameter list from the same table (`aggsim._declared`).

use crate::convert::{Count, count};
use core_lattice::spec::{DeclaredParams, Input, Kind, ParamSpec};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

/// Sets the declared parameters given as keyword arguments `kwargs` of `function` on `p`,
/// and returns the names given (a keyword given as None, allowed for the parameters that are
/// None by default only, counts as not given). `positional` are declared parameters the function takes as
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
            if d.python_none() {
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
            Kind::Text | Kind::List => match text(table, &name, &value)? {
                Some(input) => input,
                None => return Err(wrong()),
            },
            _ => return Err(wrong()),
        };
        p.set(&name, &input)
            .map_err(|e| PyValueError::new_err(format!("{name} = {value}: {e}")))?;
        given.push(name);
    }
    Ok(given)
}

/// The value of a text or list parameter ([`Kind::Text`], [`Kind::List`]): a str as the
/// command line writes it (`"1024x512"`, `"periodic,wall"`, `"4G"`), a count, or a sequence of
/// strs and counts, which the command line writes separated by commas; `None` for another type.
fn text(table: &[ParamSpec], name: &str, value: &Bound<'_, PyAny>) -> PyResult<Option<Input>> {
    let item = |v: &Bound<'_, PyAny>| -> PyResult<Option<String>> {
        if v.is_instance_of::<PyString>() {
            Ok(Some(v.extract()?))
        } else if v.is_instance_of::<PyBool>() {
            Ok(None)
        } else if v.is_instance_of::<PyInt>() || v.is_instance_of::<PyFloat>() {
            Ok(Some(count::<u64>(table, name, v.extract()?)?.to_string()))
        } else {
            Ok(None)
        }
    };
    if let Some(one) = item(value)? {
        return Ok(Some(Input::Text(one)));
    }
    if !(value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>()) {
        return Ok(None);
    }
    let mut parts = Vec::new();
    for v in value.try_iter()? {
        match item(&v?)? {
            Some(t) => parts.push(t),
            None => return Ok(None),
        }
    }
    Ok(Some(Input::Text(parts.join(","))))
}

/// The declaration of a model as Python sees it: for each parameter, the kind's Python type,
/// its stubs' type where the kind does not say it (`annotation`, empty otherwise), the default
/// of a text or list value as the command line writes it (`text`, empty otherwise), the whole
/// help text, and whether it is None by default (`optional`) — beside the table of
/// `aggsim._params`, for the signatures and docstrings `aggsim` builds.
pub fn declared_rows<P: DeclaredParams>() -> Vec<serde_json::Value> {
    let texts = P::default().to_text();
    P::DECLARED
        .iter()
        .map(|d| {
            // A text or list default as the command line writes it (`4G`).
            let text = match d.kind {
                Kind::Text | Kind::List => texts
                    .iter()
                    .find(|(n, _)| *n == d.spec.name)
                    .map_or("", |(_, t)| t.as_str()),
                _ => "",
            };
            serde_json::json!({
                "name": d.spec.name,
                "type": d.kind.python_type(),
                "annotation": d.python,
                "text": text,
                "help": core_lattice::spec::help_text(d.help),
                "why": d.why,
                "optional": d.python_none(),
            })
        })
        .collect()
}
