//! The figures of a cluster: `dla.png` ([`write_png`]) and the animation of its growth,
//! `dla.gif` ([`write_animation`]). Both are drawn from the positions in arrival order (from
//! memory or read back from `positions.npy` row by row), on one frame: the square of side
//! `2 (R_ext + 1)` around the seed of the finished cluster, in particle diameters. A cluster
//! held only as its positions (the Python bindings') has the same figures through
//! [`of_positions`].
//!
//! While a pixel is at most a diameter wide, each particle is a disc of its true size coloured
//! by arrival order (a perceptual map, magma, restricted to the colours that stand out on the
//! white background), later particles over earlier; in 3D (4D and 5D: the projection on x, y,
//! z) each is a sphere seen from +z with a depth buffer, darkened where it is farther from the
//! viewer and where its surface turns away. When a pixel spans more than a diameter (a large
//! cluster), each pixel shows how many particles it holds on a log scale, projected on x, y.

use crate::sim::{Simulation, each_position};
use crate::space::{Dim, Space};
use figures::animation::Gif;
use figures::palette::{self, Sequential};
use figures::{Extent, Figure, Legend, Raster, group_digits};
use run_io::OutputError;
use std::path::Path;

/// How the raster shows particles at its scale and dimension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// 2D, a pixel at most a diameter: discs coloured by arrival.
    Discs,
    /// 3D to 5D, a pixel at most a diameter: shaded spheres seen from +z.
    Spheres,
    /// A pixel wider than a diameter: particles per pixel.
    Density,
}

/// The raster as particles are added: per pixel, the arrival fraction of the particle shown
/// (negative: none), its depth and lighting (spheres), or the particle count (density).
struct Canvas {
    side: u32,
    extent: f64,
    /// The frame's centre, `(x, y)` in the raster's plane.
    centre: (f64, f64),
    scale: f64,
    total: u64,
    mode: Mode,
    arrival: Vec<f32>,
    depth: Vec<f64>,
    light: Vec<f32>,
    counts: Vec<u32>,
}

impl Canvas {
    /// An empty raster of `side` pixels of a cluster of `total` particles whose centres lie
    /// within `r_ext` of the origin.
    fn new(side: u32, frame: Frame, total: u64, dim: usize) -> Self {
        // Every centre lies within `half` of the frame's centre; one radius more holds every
        // disc.
        let extent = frame.half + 1.0;
        let scale = f64::from(side) / (2.0 * extent);
        let mode = match (scale >= 1.0, dim >= 3) {
            (true, false) => Mode::Discs,
            (true, true) => Mode::Spheres,
            (false, _) => Mode::Density,
        };
        let n = side as usize * side as usize;
        let sized = |used: bool| if used { n } else { 0 };
        Canvas {
            side,
            extent,
            centre: frame.centre,
            scale,
            total,
            mode,
            arrival: vec![-1.0; sized(mode != Mode::Density)],
            depth: vec![f64::NEG_INFINITY; sized(mode == Mode::Spheres)],
            light: vec![0.0; sized(mode == Mode::Spheres)],
            counts: vec![0; sized(mode == Mode::Density)],
        }
    }

    /// The pixel ranges `(x0, x1, y0, y1)`, inclusive, that a disc of radius `rad` pixels
    /// centred at `(cx, cy)` can touch.
    fn disc_bounds(&self, cx: f64, cy: f64, rad: f64) -> (u32, u32, u32, u32) {
        let last = f64::from(self.side - 1);
        let lo = |v: f64| (v - rad).floor().clamp(0.0, last) as u32;
        let hi = |v: f64| (v + rad).ceil().clamp(0.0, last) as u32;
        (lo(cx), hi(cx), lo(cy), hi(cy))
    }

    /// Adds particle `i` (arrival order, from 0) at `p`.
    fn add(&mut self, i: u64, p: &[f64]) {
        let s = self.side as usize;
        let (cx, cy) = (
            (p[0] - self.centre.0 + self.extent) * self.scale,
            (self.extent - (p[1] - self.centre.1)) * self.scale,
        );
        let frac = (i as f64 / (self.total.max(2) - 1) as f64) as f32;
        match self.mode {
            Mode::Density => {
                let x = (cx.max(0.0) as usize).min(s - 1);
                let y = (cy.max(0.0) as usize).min(s - 1);
                let c = &mut self.counts[y * s + x];
                *c = c.saturating_add(1);
            }
            Mode::Discs | Mode::Spheres => {
                let rad = 0.5 * self.scale;
                let (x0, x1, y0, y1) = self.disc_bounds(cx, cy, rad);
                let single = x1 == x0 && y1 == y0;
                for y in y0..=y1 {
                    for x in x0..=x1 {
                        let (dx, dy) = (f64::from(x) + 0.5 - cx, f64::from(y) + 0.5 - cy);
                        let r2 = (dx * dx + dy * dy) / (rad * rad);
                        if r2 > 1.0 && !single {
                            continue;
                        }
                        let at = y as usize * s + x as usize;
                        if self.mode == Mode::Discs {
                            self.arrival[at] = self.arrival[at].max(frac);
                            continue;
                        }
                        // The sphere's surface height above its centre, in diameters, and its
                        // normal's component towards the viewer.
                        let facing = (1.0 - r2.min(1.0)).sqrt();
                        let z = p[2] + 0.5 * facing;
                        if z > self.depth[at] {
                            self.depth[at] = z;
                            self.arrival[at] = frac;
                            let near = ((z + self.extent) / (2.0 * self.extent)).clamp(0.0, 1.0);
                            self.light[at] = ((0.45 + 0.55 * near) * (0.5 + 0.5 * facing)) as f32;
                        }
                    }
                }
            }
        }
    }

    /// The largest count of a pixel (density mode).
    fn max_count(&self) -> u32 {
        self.counts.iter().copied().max().unwrap_or(0)
    }

    /// The raster, colours from `map`; in density mode on a log scale up to `top` particles.
    fn raster(&self, map: &Sequential, top: u32) -> Raster {
        let mut r = Raster::new(self.side, self.side, palette::WHITE);
        let table = map.table(1024);
        let colour = |t: f64| table[((t.clamp(0.0, 1.0) * 1023.0).round()) as usize];
        let log_top = f64::from(top.max(2)).ln();
        for at in 0..self.side as usize * self.side as usize {
            let c = match self.mode {
                Mode::Density => match self.counts[at] {
                    0 => continue,
                    c => colour(f64::from(c).ln() / log_top),
                },
                Mode::Discs | Mode::Spheres => {
                    let a = self.arrival[at];
                    if a < 0.0 {
                        continue;
                    }
                    let c = colour(f64::from(a));
                    if self.mode == Mode::Spheres {
                        let l = self.light[at];
                        c.map(|v| (f32::from(v) * l).round() as u8)
                    } else {
                        c
                    }
                }
            };
            r.rgb[at * 3..at * 3 + 3].copy_from_slice(&c);
        }
        r
    }

    /// The figure of the raster: `shown` particles of `total`.
    fn figure<'a>(
        &self,
        raster: &'a Raster,
        dim: usize,
        deposit: bool,
        seed: u64,
        shown: u64,
        top: u32,
    ) -> Figure<'a> {
        let view = match (self.mode, dim, deposit) {
            (Mode::Density, 2, _) => ", particles per pixel",
            (Mode::Density, _, false) => ", projected on x, y",
            (Mode::Density, _, true) => ", projected on x and the height",
            (_, 2, _) => "",
            (_, 3, false) => ", seen from +z",
            (_, _, false) => ", x, y, z seen from +z",
            (_, _, true) => ", x and the height seen from -y",
        };
        let count = if shown < self.total {
            format!("{} of {}", group_digits(shown), group_digits(self.total))
        } else {
            group_digits(shown)
        };
        let legend = match self.mode {
            Mode::Density => Legend::ColourBar {
                map: Sequential::magma_on_white(),
                label: "particles per pixel".into(),
                lo: 1.0,
                hi: f64::from(top.max(2)),
                log: true,
            },
            _ => Legend::ColourBar {
                map: Sequential::magma_on_white(),
                label: "arrival order (particle number)".into(),
                lo: 1.0,
                hi: self.total.max(2) as f64,
                log: false,
            },
        };
        Figure {
            raster,
            extent: Extent {
                x: (self.centre.0 - self.extent, self.centre.0 + self.extent),
                y: (self.centre.1 - self.extent, self.centre.1 + self.extent),
            },
            unit: "diameters".into(),
            axes: ("x".into(), if deposit { "height" } else { "y" }.into()),
            header: format!(
                "{} {dim}D{view}: N = {count}, seed {seed}",
                if deposit { "Deposit" } else { "DLA" }
            ),
            legend,
        }
    }
}

/// A finished cluster as its figures read it: dimension, R_ext (the frame), size, seed, and a
/// pass over its positions in arrival order. Made by [`of_positions`] (and, for a
/// simulation, by the free functions [`write_png`] and [`write_animation`]), it writes
/// `dla.png` ([`write_png`](Self::write_png)) and `dla.gif`
/// ([`write_animation`](Self::write_animation)).
pub struct ClusterFigure<'a> {
    dim: usize,
    frame: Frame,
    /// A deposit: the positions `each` gives are already in the raster's axes (`x`, the
    /// height, then `-y` as the depth).
    deposit: bool,
    total: u64,
    seed: u64,
    /// `each(f)` calls `f(i, position)` for every particle in arrival order (twice for a
    /// density animation).
    each: Box<Each<'a>>,
}

/// A callback over the positions of a cluster: arrival index and coordinates.
type Visit<'v> = dyn FnMut(u64, &[f64]) -> Result<(), OutputError> + 'v;

/// A pass over the positions of a cluster, calling its [`Visit`] for each.
type Each<'a> = dyn Fn(&mut Visit<'_>) -> Result<(), OutputError> + 'a;

impl ClusterFigure<'_> {
    /// Writes `dla.png` of `side` x `side` pixels of raster (plus axes and legend) to `path`.
    ///
    /// # Errors
    /// The positions cannot be read or the file cannot be written.
    pub fn write_png(&self, path: &Path, side: u32) -> Result<(), OutputError> {
        let mut canvas = Canvas::new(side, self.frame, self.total, self.dim);
        (self.each)(&mut |i, p| {
            canvas.add(i, p);
            Ok(())
        })?;
        let map = Sequential::magma_on_white();
        let top = canvas.max_count();
        let raster = canvas.raster(&map, top);
        canvas
            .figure(&raster, self.dim, self.deposit, self.seed, self.total, top)
            .write_png(path)?;
        Ok(())
    }

    /// Writes the growth of the cluster as an animated GIF to `path`: one frame every `every`
    /// particles and one of the whole cluster, each `side` x `side` pixels of raster on the
    /// finished cluster's frame (so the scale never changes), colours as in `dla.png`. Returns
    /// the number of frames.
    ///
    /// # Errors
    /// The positions cannot be read or the file cannot be written.
    pub fn write_animation(&self, path: &Path, side: u32, every: u64) -> Result<u64, OutputError> {
        let total = self.total;
        let mut canvas = Canvas::new(side, self.frame, total, self.dim);
        // A density raster's colours run to the finished cluster's densest pixel, so that a
        // colour means the same count in every frame: one pass first to find it.
        let top = if canvas.mode == Mode::Density {
            let mut full = Canvas::new(side, self.frame, total, self.dim);
            (self.each)(&mut |i, p| {
                full.add(i, p);
                Ok(())
            })?;
            full.max_count()
        } else {
            0
        };
        let map = Sequential::magma_on_white();
        let every = every.max(1);
        let mut gif: Option<Gif> = None;
        let mut frame = |canvas: &Canvas, shown: u64| -> Result<(), OutputError> {
            let raster = canvas.raster(&map, top);
            let image = canvas
                .figure(&raster, self.dim, self.deposit, self.seed, shown, top)
                .render()?;
            let g = match &mut gif {
                Some(g) => g,
                None => gif.insert(Gif::create(path, image.width, image.height)?),
            };
            g.push(&image)?;
            Ok(())
        };
        (self.each)(&mut |i, p| {
            canvas.add(i, p);
            let shown = i + 1;
            if shown % every == 0 && shown < total {
                frame(&canvas, shown)?;
            }
            Ok(())
        })?;
        frame(&canvas, total)?;
        Ok(gif.map(Gif::finish).transpose()?.unwrap_or(0))
    }
}

/// The cluster of a simulation: its positions from memory, or read back from
/// `dir/positions.npy`.
fn of_sim<'s, const D: usize>(sim: &'s Simulation<D>, dir: &'s Path) -> ClusterFigure<'s>
where
    Dim<D>: Space<D>,
{
    let substrate = sim.params().substrate();
    ClusterFigure {
        dim: D,
        frame: match substrate {
            // The strip and the deposit's height, in a square.
            Some(_) => Frame {
                centre: (0.0, 0.5 * sim.r_ext()),
                half: sim.figure_half(),
            },
            None => Frame::around_origin(sim.r_ext()),
        },
        deposit: substrate.is_some(),
        total: sim.particles(),
        seed: sim.seed(),
        each: Box::new(move |f: &mut Visit<'_>| {
            each_position(sim, dir, |i, p: &[f64; D]| {
                if substrate.is_none() || D == 2 {
                    return f(i, p);
                }
                // Seen from -y: x across, the height up, -y the depth.
                let mut q = *p;
                q[1] = p[D - 1];
                q[2] = -p[1];
                f(i, &q)
            })
        }),
    }
}

/// The square a raster shows: every centre lies within `half` of `centre` along both axes.
#[derive(Debug, Clone, Copy)]
struct Frame {
    centre: (f64, f64),
    half: f64,
}

impl Frame {
    /// A radial cluster's frame: centred on the seed, `R_ext` wide.
    fn around_origin(r_ext: f64) -> Self {
        Frame {
            centre: (0.0, 0.0),
            half: r_ext,
        }
    }
}

/// The figures of a cluster held as `positions`: `dim` coordinates a particle, in arrival
/// order, row-major (as the Python bindings hold them); `r_ext` and `seed` are the run's (its
/// `run.json`'s). For the same cluster, `side` and `every` its files are byte for byte the
/// binary's `dla.png` and `dla.gif`.
///
/// # Errors
/// The positions are not whole particles of 2 to 5 coordinates.
pub fn of_positions(
    positions: &[f64],
    dim: usize,
    r_ext: f64,
    seed: u64,
) -> Result<ClusterFigure<'_>, OutputError> {
    if !(2..=5).contains(&dim) || positions.len() % dim != 0 || positions.is_empty() {
        return Err(std::io::Error::other(format!(
            "positions of {} numbers do not hold whole particles of {dim} coordinates (2 to 5)",
            positions.len()
        ))
        .into());
    }
    Ok(ClusterFigure {
        dim,
        frame: Frame::around_origin(r_ext),
        deposit: false,
        total: (positions.len() / dim) as u64,
        seed,
        each: Box::new(move |f: &mut Visit<'_>| {
            for (i, p) in positions.chunks_exact(dim).enumerate() {
                f(i as u64, p)?;
            }
            Ok(())
        }),
    })
}

/// Writes `dla.png` of the simulation's cluster to `path` ([`ClusterFigure::write_png`]), its
/// positions from memory or read back from `dir/positions.npy`.
///
/// # Errors
/// The positions cannot be read or the file cannot be written.
pub fn write_png<const D: usize>(
    sim: &Simulation<D>,
    dir: &Path,
    path: &Path,
    side: u32,
) -> Result<(), OutputError>
where
    Dim<D>: Space<D>,
{
    of_sim(sim, dir).write_png(path, side)
}

/// Side of the raster in `dla.gif` when none is asked for (`--png-size`).
pub const ANIMATION_DEFAULT_SIDE: u32 = 512;

/// Particles between frames of the animation when none is asked for: about 100 frames.
pub fn default_animation_every(particles: u64) -> u64 {
    particles.div_ceil(100).max(1)
}

/// Writes `dla.gif`, the growth of the simulation's cluster, to `path`
/// ([`ClusterFigure::write_animation`]), its positions as [`write_png`] reads them. Returns the
/// number of frames.
///
/// # Errors
/// The positions cannot be read or the file cannot be written.
pub fn write_animation<const D: usize>(
    sim: &Simulation<D>,
    dir: &Path,
    path: &Path,
    side: u32,
    every: u64,
) -> Result<u64, OutputError>
where
    Dim<D>: Space<D>,
{
    of_sim(sim, dir).write_animation(path, side, every)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cluster of `n` particles in `D` dimensions, its positions kept, and them flattened.
    fn grown<const D: usize>(n: u64) -> (Simulation<D>, Vec<f64>)
    where
        Dim<D>: Space<D>,
    {
        let p = crate::Params {
            dim: D,
            particles: n,
            keep_positions: true,
            ..crate::Params::default()
        };
        let mut sim = Simulation::<D>::new(p, 5).unwrap();
        sim.run().unwrap();
        let flat = sim.positions().unwrap().iter().flatten().copied().collect();
        (sim, flat)
    }

    #[test]
    fn figures_of_positions_are_the_simulations_byte_for_byte() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
        let (sim2, flat2) = grown::<2>(300);
        let (sim3, flat3) = grown::<3>(200);
        // Discs, spheres and density (a raster narrower than the cluster).
        for (side, dim) in [(64, 2), (512, 2), (48, 3), (16, 2)] {
            if dim == 2 {
                write_png(&sim2, dir.path(), &a, side).unwrap();
                let of2 = of_positions(&flat2, 2, sim2.r_ext(), sim2.seed()).unwrap();
                of2.write_png(&b, side).unwrap();
            } else {
                write_png(&sim3, dir.path(), &a, side).unwrap();
                let of3 = of_positions(&flat3, 3, sim3.r_ext(), sim3.seed()).unwrap();
                of3.write_png(&b, side).unwrap();
            }
            assert_eq!(
                std::fs::read(&a).unwrap(),
                std::fs::read(&b).unwrap(),
                "{side}"
            );
        }
        let (ga, gb) = (dir.path().join("a.gif"), dir.path().join("b.gif"));
        assert_eq!(write_animation(&sim2, dir.path(), &ga, 24, 50).unwrap(), 6);
        let of2 = of_positions(&flat2, 2, sim2.r_ext(), sim2.seed()).unwrap();
        assert_eq!(of2.write_animation(&gb, 24, 50).unwrap(), 6);
        assert_eq!(std::fs::read(&ga).unwrap(), std::fs::read(&gb).unwrap());
        // Positions that are not whole particles are refused.
        assert!(of_positions(&flat2[1..], 2, 1.0, 1).is_err());
        assert!(of_positions(&[], 2, 1.0, 1).is_err());
    }

    #[test]
    fn the_mode_follows_the_scale_and_dimension() {
        assert_eq!(
            Canvas::new(512, Frame::around_origin(100.0), 10, 2).mode,
            Mode::Discs
        );
        assert_eq!(
            Canvas::new(512, Frame::around_origin(100.0), 10, 3).mode,
            Mode::Spheres
        );
        assert_eq!(
            Canvas::new(64, Frame::around_origin(100.0), 10, 2).mode,
            Mode::Density
        );
    }

    #[test]
    fn later_particles_are_drawn_over_earlier_ones_in_their_colour() {
        let mut c = Canvas::new(40, Frame::around_origin(9.0), 3, 2);
        c.add(0, &[0.0, 0.0]);
        c.add(2, &[0.0, 0.0]);
        c.add(1, &[0.0, 0.0]);
        let map = Sequential::magma_on_white();
        let r = c.raster(&map, 0);
        // The centre pixel shows the last particle; an empty corner stays white.
        assert_eq!(r.get(20, 20), map.at(1.0));
        assert_eq!(r.get(0, 0), palette::WHITE);
    }

    #[test]
    fn density_is_log_scaled_to_the_top_count() {
        let mut c = Canvas::new(16, Frame::around_origin(100.0), 100, 2);
        for i in 0..100 {
            c.add(i, &[0.0, 0.0]);
        }
        c.add(0, &[50.0, 50.0]);
        let map = Sequential::magma_on_white();
        let r = c.raster(&map, c.max_count());
        assert_eq!(c.max_count(), 100);
        assert_eq!(r.get(8, 8), map.table(1024)[1023]);
        // (50, 50) is at pixel (151 * 16 / 202, 51 * 16 / 202) = (11, 4).
        assert_eq!(r.get(11, 4), map.table(1024)[0]);
    }
}
