//! The figures of a run (feature `figures`): the snapshots `snapshot_NNNNNN.png` and the
//! animation `animat.gif`, on the run's one [`SnapshotFrame`]. Re-exported by
//! [`crate::output`], where the binary and the Python bindings find them.

use super::OutputError;
use crate::params::Species;
use crate::world::World;
use figures::animation::Gif;
use figures::palette;
use figures::{Extent, Figure, Legend, Raster, group_digits};
use std::path::Path;

/// Largest default side of a snapshot's raster in pixels: a larger frame is scaled down.
pub const SNAPSHOT_MAX_SIDE: i64 = 1024;
/// Smallest default side of a snapshot's raster in pixels: a smaller frame is zoomed by a
/// whole number of pixels per cell.
pub const SNAPSHOT_MIN_SIDE: i64 = 512;

/// The one frame of every snapshot and animation frame of a run: the square of cells from
/// `-radius` to `radius` on both axes around the origin (where the animats start), drawn
/// `side` pixels wide. It depends on the parameters and flags only, so every raster of a run
/// (and of its resumed continuation) has the same scale; animats outside it are counted in the
/// header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SnapshotFrame {
    /// Half the frame's side in cells.
    pub radius: i64,
    /// The raster's side in pixels.
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

    /// The raster of `world`: foxes (drawn over rabbits where both share a pixel) and rabbits
    /// on white, and the number of animats outside the frame.
    pub fn raster(&self, world: &World) -> (Raster, u64) {
        self.raster_of(|| world.animats().map(|a| (a.pos, a.species)))
    }

    /// The raster of the animats `animats()` yields (cell and species; called twice, for
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

    /// The figure of a raster from [`SnapshotFrame::raster_of`], its header from `census`.
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
