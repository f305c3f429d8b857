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
use run_cli::declared::key_line;
use std::path::Path;

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

/// What [`read_config`] read besides the parameters it set.
pub struct ConfigRead {
    /// The parameters the file set.
    pub given: Vec<&'static str>,
    /// The numbers of the front end's own keys (`extra`), by name.
    pub extras: Vec<(String, f64)>,
}

/// Reads the TOML file `path` of a model's parameters onto `p`, as the binaries' `--config`
/// reads one (keys are the declared names, with dashes or underscores; flags that are not
/// declared parameters, such as `steps`, are the function's own arguments), and returns the
/// names set, and the numbers of the keys in `extra` (parameters of the front end's own, such
/// as `density`).
///
/// # Errors
/// `ValueError` naming the file and the line: unreadable, malformed, an unknown key, a value of
/// the wrong type.
pub fn read_config<P: DeclaredParams>(
    p: &mut P,
    path: &Path,
    extra: &[&str],
) -> PyResult<ConfigRead> {
    let shown = path.display();
    let text = std::fs::read_to_string(path)
        .map_err(|e| PyValueError::new_err(format!("config {shown}: cannot read it: {e}")))?;
    let table: toml::Table = toml::from_str(&text).map_err(|e| {
        let line = e.span().map_or(0, |s| {
            text[..s.start.min(text.len())].matches('\n').count() + 1
        });
        let msg = e.message().split_whitespace().collect::<Vec<_>>().join(" ");
        PyValueError::new_err(format!("config {shown}, line {line}: {msg}"))
    })?;
    let mut entries: Vec<(&String, &toml::Value)> = table.iter().collect();
    entries.sort_by_key(|(k, _)| key_line(&text, k));
    let (mut given, mut extras) = (Vec::new(), Vec::new());
    for (key, value) in entries {
        let at = format!("config {shown}, line {}", key_line(&text, key));
        let name = key.replace('-', "_");
        let number = |v: &toml::Value| match v {
            toml::Value::Float(x) => Some(*x),
            toml::Value::Integer(i) => Some(*i as f64),
            _ => None,
        };
        if extra.contains(&name.as_str()) {
            let x = number(value)
                .ok_or_else(|| PyValueError::new_err(format!("{at}: `{key}` is a number")))?;
            extras.push((name, x));
            continue;
        }
        let Some(d) = P::DECLARED.iter().find(|d| d.spec.name == name) else {
            let keys: Vec<&str> = P::DECLARED.iter().map(|d| d.spec.name).collect();
            return Err(PyValueError::new_err(format!(
                "{at}: unknown key `{key}`; the keys are the model's parameters: {}{}",
                keys.join(", "),
                extra.iter().map(|e| format!(", {e}")).collect::<String>()
            )));
        };
        let scalar = |v: &toml::Value| match v {
            toml::Value::String(s) => Some(s.clone()),
            toml::Value::Integer(i) => Some(i.to_string()),
            _ => None,
        };
        let input = match (d.kind, value) {
            (Kind::Real, v) => number(v).map(Input::Real),
            (Kind::Count, toml::Value::Integer(i)) => u64::try_from(*i).ok().map(Input::Count),
            // `1e6` in TOML is a float: a count if it is a whole number.
            (Kind::Count, toml::Value::Float(x))
                if x.fract() == 0.0 && *x >= 0.0 && *x < 2f64.powi(64) =>
            {
                Some(Input::Count(*x as u64))
            }
            (Kind::Switch, toml::Value::Boolean(b)) => Some(Input::Switch(*b)),
            (Kind::Choice, toml::Value::String(s)) => Some(Input::Choice(s.clone())),
            (Kind::Text | Kind::List, toml::Value::Array(items)) => items
                .iter()
                .map(scalar)
                .collect::<Option<Vec<_>>>()
                .map(|v| Input::Text(v.join(","))),
            (Kind::Text | Kind::List, v) => scalar(v).map(Input::Text),
            _ => None,
        };
        let Some(input) = input else {
            return Err(PyValueError::new_err(format!(
                "{at}: `{key}` = {value}: expected {}",
                d.kind.python_type()
            )));
        };
        p.set(d.spec.name, &input)
            .map_err(|e| PyValueError::new_err(format!("{at}: `{key}` = {value}: {e}")))?;
        given.push(d.spec.name);
    }
    Ok(ConfigRead { given, extras })
}
