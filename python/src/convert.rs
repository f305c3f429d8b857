//! Conversions shared by the models: `run.json` values to Python objects, a manifest onto a
//! result object's attributes, integer arguments, and columns to dicts of NumPy arrays.

use numpy::{Element, IntoPyArray};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use serde_json::Value;
use sim_run::io::RunManifest;

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

/// A count argument (`flag` as the CLI spells it): negative values are refused with a
/// `ValueError` naming the flag.
pub fn count(flag: &str, v: i64) -> PyResult<u64> {
    u64::try_from(v).map_err(|_| {
        PyValueError::new_err(format!(
            "{flag} {v} is outside the accepted range: it counts something and cannot be negative"
        ))
    })
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
