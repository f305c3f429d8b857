//! `aggsim._aggsim`, the compiled part of the Python package `aggsim`: the three models of the
//! workspace (`dla_pdla`, `dlca`, `animat`) called from Python, results as NumPy arrays. The
//! parameters are built and validated by the same library code as the binaries', and the
//! results assembled by the functions that write the binaries' `run.json`, so a run from Python
//! equals the binary's for the same seed (the same `state_hash`). See `docs/python.md`.
//!
//! | module | owns |
//! |---|---|
//! | `run` | running on a worker thread without the GIL: Ctrl-C, progress |
//! | `checkpoint` | `checkpoint=DIR`: the guard, SIGTERM, resuming, cleaning up |
//! | `convert` | `run.json` onto result attributes, count arguments, columns as arrays |
//! | `dla`, `dlca`, `animat` | one model each: its function, result class and step-wise class |
//! | `figure` | the binaries' figures from a result's arrays, by the libraries' raster code |

mod animat;
mod checkpoint;
mod convert;
mod declared;
mod dla;
mod dlca;
mod figure;
mod run;

use core_lattice::spec::ParamSpec;
use pyo3::prelude::*;
use serde_json::{Map, Value};

/// A model as the package registers it: what the functions over every model (`defaults`,
/// `_params`, `_declared`, `_schema`) read of it. A model module adds its own functions and
/// classes to the module (`register`); this row is the rest.
struct Registered {
    /// The name the functions take (`"dla"`).
    name: &'static str,
    /// The library's parameter table.
    params: &'static [ParamSpec],
    /// The library's defaults, keyed by parameter.
    defaults: fn() -> Map<String, Value>,
    /// The defaults of the Python functions (the library's, with the functions' own).
    python_defaults: for<'py> fn(Python<'py>) -> PyResult<Bound<'py, PyAny>>,
    /// The declaration as Python sees it (`declared::declared_rows`).
    declared: fn() -> Vec<Value>,
    /// Declared parameters the functions take as their own arguments.
    positional: &'static [&'static str],
    /// The argument of the signatures the declared keywords come before (empty: at the end).
    before: &'static str,
    /// The output schema (`run_io::schema`).
    schema: &'static [run_io::schema::Output],
}

/// Every model of the package.
const MODELS: &[Registered] = &[
    Registered {
        name: "dla",
        params: dla_pdla::params::PARAMS,
        defaults: dla_pdla::params::defaults,
        python_defaults: dla::defaults_dict,
        declared: declared::declared_rows::<dla_pdla::Params>,
        positional: dla::POSITIONAL,
        before: dla::KEYWORDS_BEFORE,
        schema: dla_pdla::output::SCHEMA,
    },
    Registered {
        name: "dlca",
        params: ::dlca::params::PARAMS,
        defaults: ::dlca::params::defaults,
        python_defaults: dlca::defaults_dict,
        declared: declared::declared_rows::<::dlca::params::Settings>,
        positional: dlca::POSITIONAL,
        before: dlca::KEYWORDS_BEFORE,
        schema: ::dlca::output::SCHEMA,
    },
    Registered {
        name: "animat",
        params: ::animat::params::PARAMS,
        defaults: ::animat::params::defaults,
        python_defaults: animat::defaults_dict,
        declared: declared::declared_rows::<::animat::Params>,
        positional: animat::POSITIONAL,
        before: animat::KEYWORDS_BEFORE,
        schema: ::animat::output::SCHEMA,
    },
];

/// The registered model `name`; a `ValueError` naming the models for another.
fn model(name: &str) -> PyResult<&'static Registered> {
    MODELS.iter().find(|m| m.name == name).ok_or_else(|| {
        let names: Vec<String> = MODELS.iter().map(|m| format!("\"{}\"", m.name)).collect();
        convert::value_error(format!(
            "unknown model {name:?}: expected {}",
            names.join(", ")
        ))
    })
}

/// The defaults of ``model`` (``"dla"``, ``"dlca"`` or ``"animat"``) as a dict: the binaries'
/// defaults, taken from the libraries, keyed by the keyword arguments' names.
#[pyfunction]
fn defaults<'py>(py: Python<'py>, model: &str) -> PyResult<Bound<'py, PyAny>> {
    (self::model(model)?.python_defaults)(py)
}

/// The parameter table of ``model`` (``"dla"``, ``"dlca"`` or ``"animat"``), from the library:
/// a list of dicts with ``name``, ``flag``, ``unit``, ``doc``, ``range`` (as the error messages
/// write it), ``choices`` and ``default``. The consistency tests check the keyword arguments and
/// stubs against it.
#[pyfunction]
#[pyo3(name = "_params")]
fn params_table<'py>(py: Python<'py>, model: &str) -> PyResult<Bound<'py, PyAny>> {
    let m = self::model(model)?;
    let defaults = (m.defaults)();
    let rows = m
        .params
        .iter()
        .map(|s| {
            serde_json::json!({
                "name": s.name,
                "flag": s.flag,
                "unit": s.unit,
                "doc": s.doc,
                "range": s.range.to_string(),
                "choices": s.range.choices(),
                "default": defaults.get(s.name),
            })
        })
        .collect();
    convert::json(py, &Value::Array(rows))
}

/// The declared parameters of ``model`` that ``aggsim`` builds keyword arguments from: a list
/// of dicts with ``name``, ``type`` (``float``, ``int``, ``bool``, ``str``, ``list``),
/// ``annotation`` (the stubs' type where the type does not say it, else empty), ``help`` (the
/// whole description), ``why`` (the reason for the range) and ``optional`` (None by default),
/// in declaration order, the names the function takes as its own arguments (``positional``),
/// and the parameter of its signature the keywords come before (``before``; empty: at the end).
#[pyfunction]
#[pyo3(name = "_declared")]
fn declared_table<'py>(py: Python<'py>, model: &str) -> PyResult<Bound<'py, PyAny>> {
    let m = self::model(model)?;
    let v = serde_json::json!({
        "params": (m.declared)(),
        "positional": m.positional,
        "before": m.before,
    });
    convert::json(py, &v)
}

/// The output schema of ``model`` (``"dla"``, ``"dlca"`` or ``"animat"``), from the library
/// (``run_io::schema``): a list of dicts, one per file, with ``file`` (a positions set: its
/// stem), ``form`` (``kind`` ``"csv"`` or ``"points"``, with the coordinates' ``axes``, ``dtype``
/// and ``unit``), ``python`` (the result's attribute), ``when`` and ``columns`` (``name``,
/// ``dtype`` as NumPy names it, ``unit``, ``when``, ``labels``, ``measured``). The tests check
/// the binaries' files and the results against it.
#[pyfunction]
#[pyo3(name = "_schema")]
fn schema_table<'py>(py: Python<'py>, model: &str) -> PyResult<Bound<'py, PyAny>> {
    let v = serde_json::to_value(self::model(model)?.schema).map_err(convert::value_error)?;
    convert::json(py, &v)
}

/// The aggsim models (DLA/PDLA, DLCA, animats) at native speed, results as NumPy arrays.
#[pymodule]
fn _aggsim(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // A build for a newer instruction set than this processor's fails the import with a
    // message, not with an illegal instruction in the middle of a run.
    if let Some(why) = core_lattice::cpu::unsupported() {
        return Err(pyo3::exceptions::PyImportError::new_err(format!(
            "aggsim: {why}"
        )));
    }
    m.add_function(wrap_pyfunction!(declared_table, m)?)?;
    m.add_function(wrap_pyfunction!(dla::dla, m)?)?;
    m.add_function(wrap_pyfunction!(dlca::dlca, m)?)?;
    m.add_function(wrap_pyfunction!(dlca::dlca_pooled_fit, m)?)?;
    m.add_function(wrap_pyfunction!(animat::animat, m)?)?;
    m.add_function(wrap_pyfunction!(defaults, m)?)?;
    m.add_function(wrap_pyfunction!(params_table, m)?)?;
    m.add_function(wrap_pyfunction!(schema_table, m)?)?;
    m.add_class::<dla::DlaResult>()?;
    m.add_class::<dlca::DlcaResult>()?;
    m.add_class::<dlca::DlcaLattice>()?;
    m.add_class::<animat::AnimatResult>()?;
    m.add_class::<animat::AnimatWorld>()?;
    m.add("FOX", ::animat::Species::Fox.code())?;
    m.add("RABBIT", ::animat::Species::Rabbit.code())?;
    m.add("SPECIES", ::animat::output::SPECIES_NAMES.to_vec())?;
    // The default of `checkpoint_interval`, which the signatures show as `...`.
    m.add("_CHECKPOINT_INTERVAL", checkpoint::DEFAULT_INTERVAL)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
