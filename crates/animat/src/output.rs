//! Recording a run and writing it into its output directory (`docs/animat.md`, "Outputs").
//! Every file is written atomically: a failed write leaves no partial file behind.
//!
//! | file | content |
//! |---|---|
//! | `run.json` | manifest: parameters, seed, timings, peak memory, results (`steps`, `foxes`, `rabbits`, `state_hash`, `distance_evaluations`, `queries`) |
//! | `populations.csv` | `step,foxes,rabbits` from step 0 (with `--timing` also `search_seconds,distance_evaluations`) |
//! | `snapshot_NNNNNN.png` | with `--snapshot-every K`: foxes red, rabbits green, on black, framing the population |
//! | `positions.csv` | with `--positions`: `x,y,id,species,age,hunger` of every live animat at the end (the columns of [`SCHEMA`]) |

use crate::params::Species;
use crate::world::{StepStats, World};
use sim_run::io::{
    Attribute, Coords, CsvWriter, PointFormat, PointSet, RunClock, RunManifest, write_png_rgb,
    write_points,
};
use std::path::Path;

pub use sim_run::io::OutputError;
use sim_run::schema::{Axes, Column, Dtype, Form, Output, output};

/// Species names by code: `species` is 0 for foxes, 1 for rabbits in `.npy`, VTK and Python,
/// and these names in CSV and XYZ.
pub const SPECIES_NAMES: [&str; 2] = [Species::Fox.name(), Species::Rabbit.name()];

/// Every output of `animat` with its columns, names, dtypes and units (`docs/outputs.md`; see
/// [`sim_run::schema`]). The writers below take their headers and attribute names from it.
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

/// Writes `positions.<format>` (see [`sim_run::io::points`]): every live animat at the
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

/// Largest side of a snapshot in cells (one pixel each, or a block of pixels when zoomed).
pub const SNAPSHOT_MAX_SIDE: i64 = 1024;
/// Smallest side of a snapshot in pixels: a smaller world is zoomed by an integer factor.
pub const SNAPSHOT_MIN_SIDE: i64 = 512;

/// Writes a PNG of the world: foxes red, rabbits green, on black. The frame is the bounding
/// box of the live animats plus a margin, one pixel per cell, scaled down by an integer factor
/// when it would exceed [`SNAPSHOT_MAX_SIDE`], or zoomed (a square of pixels per cell) to at
/// least [`SNAPSHOT_MIN_SIDE`]; y points up.
///
/// # Errors
/// [`OutputError`] if the PNG cannot be encoded or written.
pub fn write_snapshot(path: &Path, world: &World) -> Result<(), OutputError> {
    let (mut x0, mut y0, mut x1, mut y1) = (i64::MAX, i64::MAX, i64::MIN, i64::MIN);
    for a in world.animats() {
        x0 = x0.min(a.pos[0]);
        y0 = y0.min(a.pos[1]);
        x1 = x1.max(a.pos[0]);
        y1 = y1.max(a.pos[1]);
    }
    if x0 > x1 {
        (x0, y0, x1, y1) = (0, 0, 0, 0);
    }
    let margin = 5;
    let (x0, y0) = (x0.saturating_sub(margin), y0.saturating_sub(margin));
    // In i128: animats at both ends of the plane span more than an i64 holds.
    let wide = |lo: i64, hi: i64| i128::from(hi.saturating_add(margin)) - i128::from(lo) + 1;
    let span = wide(x0, x1).max(wide(y0, y1));
    let factor = (span + i128::from(SNAPSHOT_MAX_SIDE) - 1) / i128::from(SNAPSHOT_MAX_SIDE);
    // At most SNAPSHOT_MAX_SIDE.
    let cells = ((span + factor - 1) / factor) as i64;
    // A small world is drawn with `zoom` x `zoom` pixels per cell, so the picture is readable.
    let zoom = ((SNAPSHOT_MIN_SIDE + cells - 1) / cells).max(1);
    let side = cells * zoom;
    let mut pixels = vec![0u8; (side * side * 3) as usize];
    let cell = |p: i64, lo: i64| ((i128::from(p) - i128::from(lo)) / factor) as i64;
    for a in world.animats() {
        let cx = cell(a.pos[0], x0);
        let cy = cells - 1 - cell(a.pos[1], y0);
        let c: [u8; 3] = match a.species {
            Species::Fox => [255, 60, 40],
            Species::Rabbit => [80, 220, 80],
        };
        for py in cy * zoom..(cy + 1) * zoom {
            for px in cx * zoom..(cx + 1) * zoom {
                let at = ((py * side + px) * 3) as usize;
                // A fox drawn over a rabbit in a shared scaled pixel stays visible.
                if a.species == Species::Fox || pixels[at] != 255 {
                    pixels[at..at + 3].copy_from_slice(&c);
                }
            }
        }
    }
    write_png_rgb(path, side as u32, side as u32, &pixels)?;
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
        sim_run::schema::check_doc(doc, "## `animat`", SCHEMA);
    }

    #[test]
    fn species_names_are_indexed_by_code() {
        for s in [Species::Fox, Species::Rabbit] {
            assert_eq!(SPECIES_NAMES[s.code() as usize], s.name());
        }
    }
}
