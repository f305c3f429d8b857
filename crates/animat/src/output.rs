//! Recording a run and writing it into its output directory (`docs/animat.md`, "Outputs").
//! Every file is written atomically: a failed write leaves no partial file behind.
//!
//! | file | content |
//! |---|---|
//! | `run.json` | manifest: parameters, seed, timings, peak memory, results (`steps`, `foxes`, `rabbits`, `state_hash`, `distance_evaluations`, `queries`) |
//! | `populations.csv` | `step,foxes,rabbits` from step 0 (with `--timing` also `search_seconds,distance_evaluations`) |
//! | `snapshot_NNNNNN.png` | with `--snapshot-every K`: a figure of the world on the run's fixed frame ([`SnapshotFrame`]), foxes vermillion, rabbits blue (Okabe-Ito), on white |
//! | `animat.gif` | with `--animate`: the world every `--animate-every` steps, on the same frame |
//! | `positions.csv` | with `--positions`: `x,y,id,species,age,hunger` of every live animat at the end (the columns of [`SCHEMA`]) |

use crate::params::Species;
use crate::world::{StepStats, World};
use sim_run::figure::animation::Gif;
use sim_run::figure::palette;
use sim_run::figure::{Extent, Figure, Legend, Raster, group_digits};
use sim_run::io::{
    Attribute, Coords, CsvWriter, PointFormat, PointSet, RunClock, RunManifest, write_points,
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

/// Largest default side of a snapshot's picture in pixels: a larger frame is scaled down.
pub const SNAPSHOT_MAX_SIDE: i64 = 1024;
/// Smallest default side of a snapshot's picture in pixels: a smaller frame is zoomed by a
/// whole number of pixels per cell.
pub const SNAPSHOT_MIN_SIDE: i64 = 512;

/// The one frame of every snapshot and animation frame of a run: the square of cells from
/// `-radius` to `radius` on both axes around the origin (where the animats start), drawn
/// `side` pixels wide. It depends on the parameters and flags only, so every picture of a run
/// (and of its resumed continuation) has the same scale; animats outside it are counted in the
/// header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SnapshotFrame {
    /// Half the frame's side in cells.
    pub radius: i64,
    /// The picture's side in pixels.
    pub side: u32,
}

/// What a snapshot's header names: the step, the populations and the seed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Census {
    /// Steps made.
    pub steps: u64,
    /// Live foxes.
    pub foxes: u64,
    /// Live rabbits.
    pub rabbits: u64,
    /// The run's seed.
    pub seed: u64,
}

impl Census {
    /// The census of `world` now.
    pub fn of(world: &World) -> Self {
        Census {
            steps: world.steps(),
            foxes: world.foxes(),
            rabbits: world.rabbits(),
            seed: world.seed(),
        }
    }
}

impl SnapshotFrame {
    /// The frame for `params`: `radius` cells (default: three start radii, as a population
    /// spreads) and `side` pixels (default: a whole number of pixels per cell and at least
    /// [`SNAPSHOT_MIN_SIDE`], or one pixel per cell up to [`SNAPSHOT_MAX_SIDE`]).
    pub fn new(params: &crate::Params, radius: Option<i64>, side: Option<u32>) -> Self {
        Self::for_start_radius(params.start_radius, radius, side)
    }

    /// [`SnapshotFrame::new`] for a run whose start radius is `start_radius` cells.
    pub fn for_start_radius(start_radius: i64, radius: Option<i64>, side: Option<u32>) -> Self {
        let radius = radius.unwrap_or(start_radius.saturating_mul(3)).max(1);
        let cells = i128::from(radius) * 2 + 1;
        let side = side.unwrap_or_else(|| {
            let min = i128::from(SNAPSHOT_MIN_SIDE);
            if cells < min {
                (cells * ((min + cells - 1) / cells)) as u32
            } else {
                cells.min(i128::from(SNAPSHOT_MAX_SIDE)) as u32
            }
        });
        SnapshotFrame { radius, side }
    }

    /// The picture of `world`: foxes (drawn over rabbits where both share a pixel) and rabbits
    /// on white, and the number of animats outside the frame.
    pub fn raster(&self, world: &World) -> (Raster, u64) {
        self.raster_of(|| world.animats().map(|a| (a.pos, a.species)))
    }

    /// The picture of the animats `animats()` yields (cell and species; called twice, for
    /// the rabbits and then the foxes over them), as [`SnapshotFrame::raster`].
    pub fn raster_of<I: Iterator<Item = ([i64; 2], Species)>>(
        &self,
        animats: impl Fn() -> I,
    ) -> (Raster, u64) {
        let mut r = Raster::new(self.side, self.side, palette::WHITE);
        let cells = i128::from(self.radius) * 2 + 1;
        let side = i128::from(self.side);
        // The pixels of cell `c` (from 0 at the frame's low edge): at least one each.
        let span = |c: i128| {
            let a = c * side / cells;
            let b = ((c + 1) * side / cells).max(a + 1).min(side);
            a as u32..b as u32
        };
        let mut outside = 0;
        for species in [Species::Rabbit, Species::Fox] {
            let colour = match species {
                Species::Fox => palette::FOX,
                Species::Rabbit => palette::RABBIT,
            };
            for (pos, _) in animats().filter(|a| a.1 == species) {
                let x = i128::from(pos[0]) + i128::from(self.radius);
                let y = i128::from(self.radius) - i128::from(pos[1]);
                if !(0..cells).contains(&x) || !(0..cells).contains(&y) {
                    outside += 1;
                    continue;
                }
                for py in span(y) {
                    for px in span(x) {
                        r.put(px, py, colour);
                    }
                }
            }
        }
        (r, outside)
    }

    /// The figure of `world` on this frame (`raster` from [`SnapshotFrame::raster`]).
    pub fn figure<'a>(&self, world: &World, raster: &'a Raster, outside: u64) -> Figure<'a> {
        self.figure_of(Census::of(world), raster, outside)
    }

    /// The figure of a picture from [`SnapshotFrame::raster_of`], its header from `census`.
    pub fn figure_of<'a>(&self, census: Census, raster: &'a Raster, outside: u64) -> Figure<'a> {
        let edge = self.radius as f64 + 0.5;
        let mut header = format!(
            "Animats, step {}: {} foxes, {} rabbits, seed {}",
            group_digits(census.steps),
            group_digits(census.foxes),
            group_digits(census.rabbits),
            census.seed
        );
        if outside > 0 {
            header.push_str(&format!("; {} outside", group_digits(outside)));
        }
        Figure {
            raster,
            extent: Extent {
                x: (-edge, edge),
                y: (-edge, edge),
            },
            unit: "cells".into(),
            axes: ("x".into(), "y".into()),
            header,
            legend: Legend::Key(vec![
                ("foxes".into(), palette::FOX),
                ("rabbits".into(), palette::RABBIT),
            ]),
        }
    }

    /// The figure of `world` as an image (a frame of an animation).
    ///
    /// # Errors
    /// The figure cannot be drawn.
    pub fn render(&self, world: &World) -> Result<Raster, OutputError> {
        let (r, outside) = self.raster(world);
        Ok(self.figure(world, &r, outside).render()?)
    }
}

/// Steps between frames of `animat.gif` without `--animate-every`: a hundredth of the run's
/// `steps`, at least 1.
pub fn default_animate_every(steps: u64) -> u64 {
    steps.div_ceil(100).max(1)
}

/// `animat.gif` being written: the world at the start, after every `every`-th step, and at the
/// end, all on one [`SnapshotFrame`]. The `animat` binary's `--animate` and Python's
/// `aggsim.animat(animate=...)` both write through it, so their files agree byte for byte.
#[derive(Debug)]
pub struct Animation {
    gif: Gif,
    frame: SnapshotFrame,
    every: u64,
}

impl Animation {
    /// Starts an animation of `world` at `path` on `frame`, a frame every `every` steps (at
    /// least 1), and adds the frame of `world` as it is now.
    ///
    /// # Errors
    /// The file cannot be created or the frame not drawn.
    pub fn start(
        world: &World,
        path: &Path,
        frame: SnapshotFrame,
        every: u64,
    ) -> Result<Self, OutputError> {
        let image = frame.render(world)?;
        let mut gif = Gif::create(path, image.width, image.height)?;
        gif.push(&image)?;
        Ok(Animation {
            gif,
            frame,
            every: every.max(1),
        })
    }

    /// After a step of `world`: adds its frame if the step is a multiple of `every`.
    ///
    /// # Errors
    /// The frame cannot be drawn or written.
    pub fn step(&mut self, world: &World) -> Result<(), OutputError> {
        if world.steps() % self.every == 0 {
            self.gif.push(&self.frame.render(world)?)?;
        }
        Ok(())
    }

    /// Adds the last frame of `world` (unless [`Animation::step`] just added it) and writes the
    /// file; returns the number of frames.
    ///
    /// # Errors
    /// The frame cannot be drawn or the file not written.
    pub fn finish(mut self, world: &World) -> Result<u64, OutputError> {
        if world.steps() % self.every != 0 {
            self.gif.push(&self.frame.render(world)?)?;
        }
        Ok(self.gif.finish()?)
    }
}

/// Writes a snapshot of the world: a figure of the animats in `frame` (axes in cells, scale
/// bar, step, populations and seed, species key), foxes Okabe-Ito vermillion, rabbits
/// Okabe-Ito blue, on white; y points up.
///
/// # Errors
/// [`OutputError`] if the PNG cannot be encoded or written.
pub fn write_snapshot(
    path: &Path,
    world: &World,
    frame: &SnapshotFrame,
) -> Result<(), OutputError> {
    let (r, outside) = frame.raster(world);
    frame.figure(world, &r, outside).write_png(path)?;
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

#[cfg(test)]
mod snapshot_tests {
    use super::*;

    #[test]
    fn a_snapshot_of_columns_is_the_worlds() {
        let mut w = World::new(crate::Params::default(), 3).unwrap();
        w.run(20);
        // The animats as the Python bindings hold them: cells and species codes.
        let rows: Vec<([i64; 2], u64)> = w.animats().map(|a| (a.pos, a.species.code())).collect();
        // The default frame, and one with several cells a pixel and animats outside.
        for frame in [
            SnapshotFrame::new(w.params(), None, None),
            SnapshotFrame::for_start_radius(w.params().start_radius, Some(40), Some(30)),
        ] {
            let (a, out_a) = frame.raster(&w);
            let (b, out_b) = frame.raster_of(|| {
                rows.iter()
                    .map(|&(p, c)| (p, Species::from_code(c).unwrap()))
            });
            assert_eq!((a.clone(), out_a), (b.clone(), out_b));
            let fa = frame.figure(&w, &a, out_a).render().unwrap();
            let fb = frame.figure_of(Census::of(&w), &b, out_b).render().unwrap();
            assert_eq!(fa, fb);
        }
        assert_eq!(Species::from_code(2), None);
    }
}
