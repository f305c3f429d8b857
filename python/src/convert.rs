//! Conversions shared by the models: `run.json` values to Python objects, a manifest onto a
//! result object's attributes, count arguments, and columns to dicts of NumPy arrays.

use numpy::{Element, IntoPyArray};
use pyo3::exceptions::{PyOverflowError, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyFloat, PyList};
use run_io::RunManifest;
use serde_json::Value;

/// A JSON value as the Python object `json.loads` would give.
pub fn json<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
        Value::Number(n) => {
            if let Some(u) = n.as_u64() {
                u.into_pyobject(py)?.into_any()
            } else if let Some(i) = n.as_i64() {
                i.into_pyobject(py)?.into_any()
            } else {
                n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any()
            }
        }
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Array(a) => {
            let list = PyList::empty(py);
            for x in a {
                list.append(json(py, x)?)?;
            }
            list.into_any()
        }
        Value::Object(o) => {
            let dict = PyDict::new(py);
            for (k, x) in o {
                dict.set_item(k, json(py, x)?)?;
            }
            dict.into_any()
        }
    })
}

/// Sets every scalar of `m` (`model`, `version`, `seed`, `threads`, `wall_seconds`,
/// `cpu_seconds`, `peak_rss_bytes`) and every result as an attribute of `obj`, `params` as a
/// dict, and `run_json`: the whole manifest as the CLI's `run.json` holds it.
pub fn set_manifest(obj: &Bound<'_, PyAny>, m: &RunManifest) -> PyResult<()> {
    let py = obj.py();
    let v = serde_json::to_value(m).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    let Value::Object(top) = &v else {
        return Err(PyRuntimeError::new_err("run.json is not an object"));
    };
    for (k, x) in top {
        if k != "results" {
            obj.setattr(k.as_str(), json(py, x)?)?;
        }
    }
    for (k, x) in &m.results {
        obj.setattr(k.as_str(), json(py, x)?)?;
    }
    obj.setattr("run_json", json(py, &v)?)?;
    Ok(())
}

/// A count argument as Python code writes it: an int (or anything with `__index__`, NumPy
/// integers included), or a float holding a whole number (`1e4`, `2.5e5`), as the binaries
/// take `--particles 1e4`. [`count`] checks it, naming the parameter.
#[derive(Debug, Clone, PartialEq)]
pub enum Count {
    /// An int.
    Int(i128),
    /// An int beyond 128 bits (its sign: `true` for negative).
    Huge(bool),
    /// A float, whole or not.
    Float(f64),
    /// Not a number: the name of its type (refused by [`count`] with the parameter's name).
    NotANumber(String),
}

impl From<i64> for Count {
    fn from(v: i64) -> Self {
        Count::Int(i128::from(v))
    }
}

impl std::fmt::Display for Count {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Count::Int(v) => write!(f, "{v}"),
            Count::Huge(neg) => {
                write!(f, "{}(an int beyond 128 bits)", if *neg { "-" } else { "" })
            }
            Count::Float(v) => write!(f, "{}", core_lattice::spec::show_number(*v)),
            Count::NotANumber(t) => write!(f, "a {t}"),
        }
    }
}

impl<'a, 'py> FromPyObject<'a, 'py> for Count {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if let Ok(f) = obj.cast::<PyFloat>() {
            return Ok(Count::Float(f.value()));
        }
        match obj.extract::<i128>() {
            Ok(v) => Ok(Count::Int(v)),
            Err(e) if e.is_instance_of::<PyOverflowError>(obj.py()) => {
                let negative = obj.lt(0).unwrap_or(false);
                Ok(Count::Huge(negative))
            }
            Err(_) => Ok(Count::NotANumber(
                obj.get_type()
                    .name()
                    .map_or_else(|_| "value of another type".into(), |n| n.to_string()),
            )),
        }
    }
}

/// A count argument `name` (the keyword argument; `table` is the model's parameter table, for
/// the accepted range): an int, or a float holding a whole number, that fits `T`. Anything else
/// (`1.5`, `nan`, `1e30`, `-1`) is a `ValueError` naming the parameter and its range:
/// `particles = 1.5 is not a whole number; the accepted range is 1..=3000000000`. The range
/// itself (at least one particle, say) is the model's validation, as for the binary.
pub fn count<T: TryFrom<i128> + Into<u64>>(
    table: &[core_lattice::spec::ParamSpec],
    name: &str,
    v: Count,
) -> PyResult<T> {
    let range = table
        .iter()
        .find(|s| s.name == name)
        .map(|s| s.range)
        .filter(|r| !matches!(r, core_lattice::spec::Range::Any))
        .map_or_else(|| format!("0..={}", max::<T>()), |r| r.to_string());
    let whole = match v {
        Count::Int(i) => Some(i),
        // Exactly: a float beyond 2^53 is still a whole number, and is converted exactly.
        Count::Float(f) if f.is_finite() && f.fract() == 0.0 && f.abs() < 1.7e38 => Some(f as i128),
        Count::Float(f) if f.is_finite() && f.fract() == 0.0 => None,
        Count::Float(_) => {
            return Err(PyValueError::new_err(format!(
                "{name} = {v} is not a whole number; a count is, in the accepted range {range}"
            )));
        }
        Count::Huge(_) => None,
        Count::NotANumber(_) => {
            return Err(PyTypeError::new_err(format!(
                "{name} = {v}: a count is an int, or a float holding a whole number (1e4)"
            )));
        }
    };
    whole.and_then(|i| T::try_from(i).ok()).ok_or_else(|| {
        PyValueError::new_err(format!(
            "{name} = {v} is outside the accepted range {range}"
        ))
    })
}

/// The largest value of `T`, for messages.
fn max<T: TryFrom<i128> + Into<u64>>() -> u64 {
    let mut hi = u64::MAX;
    while T::try_from(i128::from(hi)).is_err() {
        hi >>= 1;
    }
    hi
}

/// A `ValueError` with `message`: the message the CLI prints for the same bad value.
pub fn value_error(message: impl ToString) -> PyErr {
    PyValueError::new_err(message.to_string())
}

/// A `RuntimeError` for a run that failed after it started.
pub fn run_error(message: impl ToString) -> PyErr {
    PyRuntimeError::new_err(format!("run failed: {}", message.to_string()))
}

/// A dict of columns: each a 1-D NumPy array made from its vector without a copy.
#[derive(Default)]
pub struct Columns<'py> {
    items: Vec<(&'static str, Bound<'py, PyAny>)>,
}

impl<'py> Columns<'py> {
    /// Adds column `name`.
    pub fn add<T: Element>(mut self, py: Python<'py>, name: &'static str, v: Vec<T>) -> Self {
        self.items.push((name, v.into_pyarray(py).into_any()));
        self
    }

    /// The dict, columns in the order added.
    pub fn into_dict(self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in self.items {
            d.set_item(k, v)?;
        }
        Ok(d)
    }
}
