//! Recording a run and writing it into its output directory (`docs/animat.md`, "Outputs").
//! Every file is written atomically: a failed write leaves no partial file behind.
//!
//! | file | content |
//! |---|---|
//! | `run.json` | manifest: parameters, seed, timings, peak memory, results (`steps`, `foxes`, `rabbits`, `state_hash`, `distance_evaluations`, `queries`) |
//! | `populations.csv` | `step,foxes,rabbits` from step 0 (with `--timing` also `search_seconds,distance_evaluations`) |
//! | `snapshot_NNNNNN.png` | with `--snapshot-every K` (feature `figures`): a figure of the world on the run's fixed frame ([`SnapshotFrame`]), foxes vermillion, rabbits blue (Okabe-Ito), on white |
//! | `animat.gif` | with `--animate` (feature `figures`): the world every `--animate-every` steps, on the same frame |
//! | `positions.csv` | with `--positions`: `x,y,id,species,age,hunger` of every live animat at the end (the columns of [`SCHEMA`]) |

use crate::params::Species;
use crate::world::{StepStats, World};
use run_io::{
    Attribute, Coords, CsvWriter, PointFormat, PointSet, RunClock, RunManifest, write_points,
};
use std::path::Path;

pub use run_io::OutputError;
use run_io::schema::{Axes, Column, Dtype, Form, Output, output};

// The snapshots and the animation draw with `figures` (charts, colour maps, GIF):
// behind feature `figures`, so that the library alone builds without them.
#[cfg(feature = "figures")]
mod figures;
#[cfg(feature = "figures")]
pub use figures::{
    Animation, Census, SNAPSHOT_MAX_SIDE, SNAPSHOT_MIN_SIDE, SnapshotFrame, default_animate_every,
    write_snapshot,
};

/// Species names by code: `species` is 0 for foxes, 1 for rabbits in `.npy`, VTK and Python,
/// and these names in CSV and XYZ.
pub const SPECIES_NAMES: [&str; 2] = [Species::Fox.name(), Species::Rabbit.name()];

/// Every output of `animat` with its columns, names, dtypes and units (`docs/outputs.md`; see
/// [`run_io::schema`]). The writers below take their headers and attribute names from it.
pub const SCHEMA: &[Output] = &[
    Output {
        file: "populations.csv",
        form: Form::Csv,
        python: "populations",
        when: None,
        columns: &[
            Column::new("step", Dtype::Uint64, "steps"),
            Column::new("foxes", Dtype::Uint64, "animats"),
            Column::new("rabbits", Dtype::Uint64, "animats"),
            Column::new("search_seconds", Dtype::Float64, "s in perception queries")
                .when("--timing")
                .measured(),
            Column::new("distance_evaluations", Dtype::Uint64, "evaluations").when("--timing"),
        ],
    },
    Output {
        file: "positions",
        form: Form::Points {
            axes: Axes::Plane,
            dtype: Dtype::Int64,
            unit: "cells",
        },
        python: "positions",
        when: Some("--positions"),
        columns: &[
            Column::new("id", Dtype::Int64, "animat id"),
            Column::new("species", Dtype::Int64, "species").labels(&SPECIES_NAMES),
            Column::new("age", Dtype::Int64, "steps"),
            Column::new(
                "hunger",
                Dtype::Int64,
                "steps since the last meal (0 for rabbits)",
            ),
        ],
    },
];

/// One row of `populations.csv`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PopulationRow {
    /// Step number (0 = the start).
    pub step: u64,
    /// Live foxes.
    pub foxes: u64,
    /// Live rabbits.
    pub rabbits: u64,
    /// Seconds in perception queries during the step (with timing on).
    pub search_seconds: f64,
    /// Distance evaluations during the step.
    pub distance_evals: u64,
}

impl PopulationRow {
    /// The row of `world` as it is now, before any step or after one whose counters are
    /// `stats` (zero at the start).
    pub fn of(world: &World, stats: StepStats) -> Self {
        PopulationRow {
            step: world.steps(),
            foxes: world.foxes(),
            rabbits: world.rabbits(),
            search_seconds: stats.search_seconds,
            distance_evals: stats.distance_evals,
        }
    }
}

/// Writes `populations.csv`; `timing` adds the search columns.
///
/// # Errors
/// [`OutputError`] if a file cannot be written.
pub fn write_populations(
    dir: &Path,
    rows: &[PopulationRow],
    timing: bool,
) -> Result<(), OutputError> {
    let header = output(SCHEMA, "populations.csv").header(timing);
    let mut w = CsvWriter::create(dir.join("populations.csv"), &header)?;
    for r in rows {
        if timing {
            w.row(&[
                &r.step,
                &r.foxes,
                &r.rabbits,
                &r.search_seconds,
                &r.distance_evals,
            ])?;
        } else {
            w.row(&[&r.step, &r.foxes, &r.rabbits])?;
        }
    }
    w.finish()?;
    Ok(())
}

/// Writes `positions.<format>` (see [`run_io::points`]): every live animat at the
/// end, in id order, with its `id`, `species` (0 fox, 1 rabbit in `.npy` and VTK; the name in
/// CSV and XYZ), `age` and `hunger`.
///
/// # Errors
/// [`OutputError`] if a file cannot be written.
pub fn write_positions(dir: &Path, world: &World, format: PointFormat) -> Result<(), OutputError> {
    let schema = output(SCHEMA, "positions");
    let attributes: Vec<Attribute<'_>> = schema
        .columns
        .iter()
        .map(|c| Attribute {
            name: c.name,
            labels: c.labels,
        })
        .collect();
    let title = format!(
        "animats after {} steps: {} foxes, {} rabbits",
        world.steps(),
        world.foxes(),
        world.rabbits()
    );
    let set = PointSet {
        n: world.foxes() + world.rabbits(),
        axes: &["x", "y"],
        integer_coordinates: true,
        attributes: &attributes,
        index: None,
        title: &title,
        parent: None,
    };
    write_points(dir, "positions", format, &set, &mut |f| {
        for a in world.animats() {
            let species = a.species.code() as i64;
            f(
                Coords::Int(&a.pos),
                &[a.id as i64, species, i64::from(a.age), i64::from(a.hunger)],
            )?;
        }
        Ok(())
    })?;
    Ok(())
}

/// Writes `run.json` with the headline results and returns it.
///
/// # Errors
/// [`OutputError`] if the manifest cannot be serialised or written.
pub fn write_manifest(
    dir: &Path,
    world: &World,
    seed: u64,
    clock: &RunClock,
) -> Result<RunManifest, OutputError> {
    let m = manifest(world, seed, clock)?;
    m.write(dir)?;
    Ok(m)
}

/// The run's manifest, `run.json` as [`write_manifest`] writes it: parameters, seed, the
/// measurements of `clock` taken now, and the headline results (`steps`, `foxes`, `rabbits`,
/// `state_hash`, `distance_evaluations`, `grid_box`, `queries`). The one place these results
/// are assembled, for the `animat` binary and the Python bindings.
///
/// # Errors
/// [`OutputError`] if the parameters cannot be serialised.
pub fn manifest(world: &World, seed: u64, clock: &RunClock) -> Result<RunManifest, OutputError> {
    let mut m = clock.finish("animat", env!("CARGO_PKG_VERSION"), seed, 1, world.params())?;
    let q = world.queries();
    m.set_result("steps", world.steps())
        .set_result("foxes", world.foxes())
        .set_result("rabbits", world.rabbits())
        .set_result("state_hash", world.state_hash())
        .set_result("distance_evaluations", world.distance_evals())
        .set_result("grid_box", world.box_size().to_string())
        .set_result(
            "queries",
            serde_json::json!({"adjacent": q.adjacent, "nearest": q.nearest, "count": q.count}),
        );
    Ok(m)
}

#[cfg(test)]
mod schema_tests {
    use super::*;

    #[test]
    fn the_outputs_document_lists_the_schema() {
        let doc = include_str!("../../../docs/outputs.md");
        run_io::schema::check_doc(doc, "## `animat`", SCHEMA);
    }

    #[test]
    fn species_names_are_indexed_by_code() {
        for s in [Species::Fox, Species::Rabbit] {
            assert_eq!(SPECIES_NAMES[s.code() as usize], s.name());
        }
    }
}
