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
//! | `figure` | the binaries' figures from a result's arrays, by the libraries' picture code |

mod animat;
mod checkpoint;
mod convert;
mod declared;
mod dla;
mod dlca;
mod figure;
mod run;

use pyo3::prelude::*;

/// The defaults of ``model`` (``"dla"``, ``"dlca"`` or ``"animat"``) as a dict: the binaries'
/// defaults, taken from the libraries, keyed by the keyword arguments' names.
#[pyfunction]
fn defaults<'py>(py: Python<'py>, model: &str) -> PyResult<Bound<'py, PyAny>> {
    match model {
        "dla" => dla::defaults_dict(py),
        "dlca" => dlca::defaults_dict(py),
        "animat" => animat::defaults_dict(py),
        other => Err(convert::value_error(format!(
            "unknown model {other:?}: expected \"dla\", \"dlca\" or \"animat\""
        ))),
    }
}

/// The parameter table of ``model`` (``"dla"``, ``"dlca"`` or ``"animat"``), from the library:
/// a list of dicts with ``name``, ``flag`` (None: config files only), ``unit``, ``doc``,
/// ``range`` (as the error messages write it), ``choices`` and ``default``. The consistency
/// tests check the keyword arguments and stubs against it.
#[pyfunction]
#[pyo3(name = "_params")]
fn params_table<'py>(py: Python<'py>, model: &str) -> PyResult<Bound<'py, PyAny>> {
    let (table, defaults) = match model {
        "dla" => (dla_pdla::params::PARAMS, dla_pdla::params::defaults()),
        "dlca" => (::dlca::params::PARAMS, ::dlca::params::defaults()),
        "animat" => (::animat::params::PARAMS, ::animat::params::defaults()),
        other => {
            return Err(convert::value_error(format!(
                "unknown model {other:?}: expected \"dla\", \"dlca\" or \"animat\""
            )));
        }
    };
    let rows = table
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
    convert::json(py, &serde_json::Value::Array(rows))
}

/// The declared parameters of ``model`` that ``aggsim`` builds keyword arguments from
/// (``"dla"``, ``"dlca"``): a list of dicts with ``name``, ``type`` (``float``, ``int``,
/// ``bool``, ``str``, ``list``), ``annotation`` (the stubs' type where the type does not say
/// it, else empty), ``help`` (the whole description), ``why`` (the reason for the range) and
/// ``optional`` (None by default), in declaration order, the names the function takes as its
/// own arguments (``positional``), and the parameter of its signature the keywords come before
/// (``before``; empty: at the end). Empty for a model whose keywords are not generated yet.
#[pyfunction]
#[pyo3(name = "_declared")]
fn declared_table<'py>(py: Python<'py>, model: &str) -> PyResult<Bound<'py, PyAny>> {
    let (rows, positional, before): (Vec<serde_json::Value>, &[&str], &str) = match model {
        "dla" => (
            declared::declared_rows::<dla_pdla::Params>(),
            dla::POSITIONAL,
            dla::KEYWORDS_BEFORE,
        ),
        "dlca" => (
            declared::declared_rows::<::dlca::params::Settings>(),
            dlca::POSITIONAL,
            dlca::KEYWORDS_BEFORE,
        ),
        "animat" => (Vec::new(), &[], ""),
        other => {
            return Err(convert::value_error(format!(
                "unknown model {other:?}: expected \"dla\", \"dlca\" or \"animat\""
            )));
        }
    };
    let v = serde_json::json!({ "params": rows, "positional": positional, "before": before });
    convert::json(py, &v)
}

/// The output schema of ``model`` (``"dla"``, ``"dlca"`` or ``"animat"``), from the library
/// (``sim_run::schema``): a list of dicts, one per file, with ``file`` (a positions set: its
/// stem), ``form`` (``kind`` ``"csv"`` or ``"points"``, with the coordinates' ``axes``, ``dtype``
/// and ``unit``), ``python`` (the result's attribute), ``when`` and ``columns`` (``name``,
/// ``dtype`` as NumPy names it, ``unit``, ``when``, ``labels``, ``measured``). The tests check
/// the binaries' files and the results against it.
#[pyfunction]
#[pyo3(name = "_schema")]
fn schema_table<'py>(py: Python<'py>, model: &str) -> PyResult<Bound<'py, PyAny>> {
    let schema = match model {
        "dla" => dla_pdla::output::SCHEMA,
        "dlca" => ::dlca::output::SCHEMA,
        "animat" => ::animat::output::SCHEMA,
        other => {
            return Err(convert::value_error(format!(
                "unknown model {other:?}: expected \"dla\", \"dlca\" or \"animat\""
            )));
        }
    };
    let v = serde_json::to_value(schema).map_err(convert::value_error)?;
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
