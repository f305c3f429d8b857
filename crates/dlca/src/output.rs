//! Writing a finished run into its output directory (docs/dlca.md, "Outputs"). Every file is
//! written atomically.
//!
//! | file | content |
//! |---|---|
//! | `run.json` | manifest: parameters, seed, timings, peak memory, results |
//! | `sweeps.csv` | `sweep,clusters,largest` (and `seconds` with `--timing`), from sweep 0 |
//! | `sizes.csv` | `size,count`: the final cluster size distribution |
//! | `particles.csv` | `x1,..,xd,cluster`: every particle's final site and cluster id (`--positions csv`, the default; `npy`, `vtk` and `xyz` write `particles.npy` with `particles_cluster.npy`, `particles.vtk` or `particles.xyz` instead, see [`run_io::points`]) |
//! | `histogram.csv` | with `--histogram`: `sweep,candidates,moves` |
//! | `clusters.csv` | with `--gyration`: `cluster,size,radius_of_gyration,wraps` |
//! | `dlca.png` | with `--png`: the figure of the final state, touching clusters in different colours (feature `figures`, see [`crate::figure`]) |
//! | `dlca.gif` | with `--animate`: the aggregation, a frame every `--animate-every` sweeps |

use crate::analysis::{
    ClusterMeasure, fractal_dimension, gyration, pooled_fractal_dimension, size_distribution,
};
use crate::sim::Simulation;
use run_io::schema::{Axes, Column, Dtype, Form, Output, output};
use run_io::{
    Attribute, Coords, CsvWriter, OutputError, PointFormat, PointSet, RunClock, write_points,
};
use serde_json::json;
use spatial::lattice::ItemId;
use std::path::Path;

/// Every output of `dlca` with its columns, names, dtypes and units (`docs/outputs.md`; see
/// [`run_io::schema`]). The writers below take their headers and attribute names from it.
pub const SCHEMA: &[Output] = &[
    Output {
        file: "sweeps.csv",
        form: Form::Csv,
        python: "per_sweep",
        when: None,
        columns: &[
            Column::new("sweep", Dtype::Uint64, "sweeps"),
            Column::new("clusters", Dtype::Uint64, "clusters"),
            Column::new("largest", Dtype::Uint64, "particles"),
            Column::new("seconds", Dtype::Float64, "s (wall clock of the sweep)")
                .when("--timing")
                .measured(),
        ],
    },
    Output {
        file: "sizes.csv",
        form: Form::Csv,
        python: "sizes",
        when: None,
        columns: &[
            Column::new("size", Dtype::Uint64, "particles"),
            Column::new("count", Dtype::Uint64, "clusters"),
        ],
    },
    Output {
        file: "particles",
        form: Form::Points {
            axes: Axes::Numbered,
            dtype: Dtype::Int64,
            unit: "sites",
        },
        python: "positions",
        when: None,
        columns: &[Column::new("cluster", Dtype::Int64, "cluster id")],
    },
    Output {
        file: "histogram.csv",
        form: Form::Csv,
        python: "histogram",
        when: Some("--histogram"),
        columns: &[
            Column::new("sweep", Dtype::Uint64, "sweeps"),
            Column::new("candidates", Dtype::Uint64, "clusters examined by one move"),
            Column::new("moves", Dtype::Uint64, "moves"),
        ],
    },
    Output {
        file: "clusters.csv",
        form: Form::Csv,
        python: "gyration",
        when: Some("--gyration"),
        columns: &[
            Column::new("cluster", Dtype::Int64, "cluster id"),
            Column::new("size", Dtype::Uint64, "particles"),
            Column::new("radius_of_gyration", Dtype::Float64, "sites"),
            Column::new("wraps", Dtype::Bool, "spans a periodic axis"),
        ],
    },
];

/// Write every output of `sim` into `dir` (which must exist) and return the manifest written;
/// the particles' sites and cluster ids go into `particles.<format>` if `positions` names one,
/// and `dlca.png` is drawn if `png` is `Some` (the longer side of its raster, or `None` inside
/// for the default, see [`crate::figure::raster_size`]; feature `figures`: without it, asking
/// for one is an error and nothing is written).
pub fn write_outputs(
    sim: &Simulation,
    seed: u64,
    clock: &RunClock,
    dir: &Path,
    png: Option<Option<u32>>,
    positions: Option<PointFormat>,
) -> Result<run_io::RunManifest, OutputError> {
    // Without feature `figures` the library cannot draw: refused before any file is written.
    if png.is_some() && !cfg!(feature = "figures") {
        let e = std::io::Error::new(
            std::io::ErrorKind::Unsupported,
            "dlca.png needs feature `figures`",
        );
        return Err(e.into());
    }
    let params = sim.params();
    let dim = sim.lattice().dim();

    // sweeps.csv
    let header = output(SCHEMA, "sweeps.csv").header(params.timing);
    let mut w = CsvWriter::create(dir.join("sweeps.csv"), &header)?;
    for r in sim.records().sweeps() {
        if params.timing {
            w.row(&[&r.sweep, &r.clusters, &r.largest, &r.seconds.unwrap_or(0.0)])?;
        } else {
            w.row(&[&r.sweep, &r.clusters, &r.largest])?;
        }
    }
    w.finish()?;

    // sizes.csv
    let sizes = size_distribution(sim);
    let mut w = CsvWriter::create(
        dir.join("sizes.csv"),
        &output(SCHEMA, "sizes.csv").header(false),
    )?;
    for (size, count) in sizes.iter() {
        w.row(&[&size, &count])?;
    }
    w.finish()?;

    // particles: every site of every cluster, clusters in id order, sites in index order.
    if let Some(format) = positions {
        let axes = Axes::Numbered.names(dim);
        let axes: Vec<&str> = axes.iter().map(String::as_str).collect();
        let title = format!(
            "DLCA lattice {}, seed {seed}, {} particles in {} clusters",
            sim.lattice()
                .sizes()
                .iter()
                .map(u64::to_string)
                .collect::<Vec<_>>()
                .join("x"),
            sim.particles(),
            sim.sets().live().len()
        );
        let set = PointSet {
            n: sim.particles(),
            axes: &axes,
            integer_coordinates: true,
            attributes: &[Attribute {
                name: output(SCHEMA, "particles").column("cluster").name,
                labels: None,
            }],
            index: None,
            title: &title,
            parent: None,
        };
        write_points(dir, "particles", format, &set, &mut |f| {
            let mut p = vec![0i64; dim];
            each_particle(sim, |id, k| -> Result<(), OutputError> {
                let x = sim.lattice().decode(k)?;
                for (c, v) in p.iter_mut().zip(x.iter()) {
                    // A coordinate is below its axis' length, which a lattice in memory
                    // keeps far below i64::MAX.
                    *c = i64::try_from(*v).map_err(std::io::Error::other)?;
                }
                f(Coords::Int(&p), &[i64::from(id)])?;
                Ok(())
            })
        })?;
    }

    // histogram.csv
    if !params.histogram_sweeps.is_empty() {
        let mut w = CsvWriter::create(
            dir.join("histogram.csv"),
            &output(SCHEMA, "histogram.csv").header(false),
        )?;
        for (sweep, h) in sim.records().histograms() {
            for (candidates, moves) in h.iter() {
                w.row(&[sweep, &candidates, &moves])?;
            }
        }
        w.finish()?;
    }

    // clusters.csv
    let measures = params.gyration.then(|| gyration(sim));
    if let Some(measures) = &measures {
        write_clusters(dir, measures)?;
    }

    #[cfg(feature = "figures")]
    if let Some(side) = png {
        crate::figure::write_png(sim, seed, &dir.join("dlca.png"), side)?;
    }

    let m = manifest(sim, seed, clock, measures.as_deref())?;
    m.write(dir)?;
    Ok(m)
}

/// The run's manifest, `run.json` as [`write_outputs`] writes it: parameters, seed, the
/// measurements of `clock` taken now, and every result (`clusters`, `sweeps`, `state_hash`,
/// the search used, and with `--gyration` the fractal dimension or `fit_error`). `measures` are
/// the final clusters' [`gyration`] measures when the parameters ask for them. The one place
/// these results are assembled, for the `dlca` binary and the Python bindings.
pub fn manifest(
    sim: &Simulation,
    seed: u64,
    clock: &RunClock,
    measures: Option<&[ClusterMeasure]>,
) -> Result<run_io::RunManifest, OutputError> {
    let params = sim.params();
    let mut fit_results = serde_json::Map::new();
    if let Some(measures) = measures {
        let wrapping = measures.iter().filter(|c| c.wraps).count();
        match fractal_dimension(measures, params.fit_min_size) {
            Ok(fit) => {
                fit_results.insert("fractal_dimension".into(), json!(fit.slope));
                fit_results.insert("fractal_dimension_stderr".into(), json!(fit.slope_stderr));
                fit_results.insert("fit_clusters".into(), json!(fit.n));
                fit_results.insert("fit_r2".into(), json!(fit.r2));
            }
            Err(e) => {
                tracing::warn!("no fractal dimension: {e}");
                fit_results.insert("fractal_dimension".into(), serde_json::Value::Null);
                fit_results.insert("fractal_dimension_stderr".into(), serde_json::Value::Null);
                fit_results.insert("fit_error".into(), json!(e.to_string()));
            }
        }
        fit_results.insert("wrapping_clusters".into(), json!(wrapping));
    }

    let mut m = clock.finish("dlca", env!("CARGO_PKG_VERSION"), seed, 1, params)?;
    m.set_result("particles", sim.particles())
        .set_result("clusters", sim.clusters())
        .set_result("largest_cluster", sim.largest())
        .set_result("sweeps", sim.sweeps())
        .set_result("strategy", sim.strategy().name())
        .set_result("strategy_requested", params.search.name())
        .set_result("strategy_reason", sim.strategy_reason())
        .set_result("state_hash", sim.state_hash())
        .set_result("moves", sim.records().moves())
        .set_result("mean_candidates_examined", sim.records().mean_examined())
        .set_result(
            "search_events",
            sim.events()
                .iter()
                .map(|e| json!({"sweep": e.sweep, "what": e.what}))
                .collect::<Vec<_>>(),
        );
    for (k, v) in fit_results {
        m.results.insert(k, v);
    }
    Ok(m)
}

/// Calls `f(cluster id, site k-index)` for every particle in the order of `particles.csv`:
/// clusters in increasing id, each cluster's sites in increasing k-index.
///
/// # Errors
/// The first error of `f`.
pub fn each_particle<E>(
    sim: &Simulation,
    f: impl FnMut(ItemId, u64) -> Result<(), E>,
) -> Result<(), E> {
    sim.try_for_each_particle(f)
}

/// The header of `clusters.csv`, from [`SCHEMA`].
pub const CLUSTER_COLUMNS: [&str; 4] = {
    let c = SCHEMA[4].columns;
    assert!(c.len() == 4, "clusters.csv's columns are these four");
    [c[0].name, c[1].name, c[2].name, c[3].name]
};

/// Reads a `clusters.csv` written by [`write_outputs`] (with `--gyration`).
///
/// # Errors
/// The file does not read, or is not a `clusters.csv` (its header, a row that does not parse).
pub fn read_clusters(path: &Path) -> Result<Vec<ClusterMeasure>, OutputError> {
    let bad = |why: String| {
        OutputError::from(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("{}: {why}", path.display()),
        ))
    };
    let text = std::fs::read_to_string(path)?;
    let mut lines = text.lines();
    let header = lines.next().unwrap_or("");
    if header != CLUSTER_COLUMNS.join(",") {
        return Err(bad(format!(
            "header `{header}`, not `{}`",
            CLUSTER_COLUMNS.join(",")
        )));
    }
    lines
        .enumerate()
        .filter(|(_, l)| !l.is_empty())
        .map(|(i, l)| {
            let f: Vec<&str> = l.split(',').collect();
            let row = || bad(format!("line {}: `{l}` is not a cluster row", i + 2));
            if f.len() != 4 {
                return Err(row());
            }
            Ok(ClusterMeasure {
                id: f[0].parse().map_err(|_| row())?,
                size: f[1].parse().map_err(|_| row())?,
                radius_of_gyration: f[2].parse().map_err(|_| row())?,
                wraps: f[3].parse().map_err(|_| row())?,
            })
        })
        .collect()
}

/// An ensemble's fractal dimension both ways (docs/dlca.md, "Validation"): pooled over the
/// clusters of every member (`runs`, each member's [`ClusterMeasure`]s), with the jackknife
/// error over members ([`pooled_fractal_dimension`]), beside the mean and standard error of
/// the members' own fits. Its keys are those of `ensemble.json`'s `pooled.fractal_dimension`
/// and of `aggsim.dlca_pooled_fit`.
///
/// # Errors
/// The pooled fit fails (fewer than 3 clusters of at least `min_size`).
pub fn pooled_summary(
    runs: &[Vec<ClusterMeasure>],
    min_size: u64,
) -> Result<serde_json::Value, core_lattice::stats::StatsError> {
    let pooled = pooled_fractal_dimension(runs, min_size)?;
    let own: Vec<f64> = runs
        .iter()
        .filter_map(|r| fractal_dimension(r, min_size).ok().map(|f| f.slope))
        .collect();
    let mut w = core_lattice::stats::Welford::new();
    own.iter().for_each(|&d| w.push(d));
    let m = own.len();
    Ok(json!({
        "fractal_dimension": pooled.slope,
        "fractal_dimension_stderr": pooled.jackknife_stderr,
        "stderr_method": "jackknife over members",
        "fit_stderr": pooled.fit_stderr,
        "fit_clusters": pooled.clusters,
        "fit_min_size": min_size,
        "members": pooled.runs,
        "per_member_mean": (m > 0).then(|| w.mean()),
        "per_member_stderr": (m > 1).then(|| w.std_error()),
        "per_member_fits": m,
    }))
}

fn write_clusters(dir: &Path, measures: &[ClusterMeasure]) -> Result<(), OutputError> {
    let mut w = CsvWriter::create(dir.join("clusters.csv"), &CLUSTER_COLUMNS)?;
    for c in measures {
        w.row(&[&c.id, &c.size, &c.radius_of_gyration, &c.wraps])?;
    }
    w.finish()?;
    Ok(())
}

#[cfg(test)]
mod schema_tests {
    use super::*;

    #[test]
    fn the_outputs_document_lists_the_schema() {
        let doc = include_str!("../../../docs/outputs.md");
        run_io::schema::check_doc(doc, "## `dlca`", SCHEMA);
    }
}
