//! The figures of a lattice: `dlca.png` ([`write_png`]) and the animation of the aggregation,
//! `dlca.gif` ([`Animation`]). Both show the lattice's first two axes (a projection for
//! d >= 3, a strip for d = 1) on the whole lattice, in lattice cells, with the last axis up.
//!
//! Clusters are coloured so that neighbouring clusters in the raster (less than about a 16th of
//! its side apart, nothing between them) always differ: a greedy colouring of the graph of
//! neighbours
//! ([`figures::palette::colour_regions`]) over the Okabe-Ito colours other than black
//! plus a light grey, on black, every colour at least 4:1 against the background. In an
//! animation each cluster keeps its previous frame's colour whenever no neighbour has it, so
//! colours change only where clusters meet.

use crate::sim::Simulation;
use figures::animation::Gif;
use figures::palette::{self, ON_BLACK, colour_regions};
use figures::{Extent, Figure, Legend, Raster, group_digits};
use run_io::OutputError;
use std::collections::HashMap;
use std::path::Path;

/// Smallest default longer side of the raster: a small lattice is drawn with a square of
/// pixels per site.
pub const PNG_MIN_SIDE: u64 = 512;
/// Largest default longer side of the raster: a larger lattice is scaled down.
pub const PNG_MAX_SIDE: u64 = 8192;

/// What the figures show of a lattice's state: its sizes, the run's progress and seed, and a
/// pass over its particles in the order of `particles.csv` (clusters by increasing id, each
/// cluster's sites by increasing k-index), `each(f)` calling `f(x1, x2, cluster id)` with the
/// site's first two coordinates (`x2` 0 on a 1D lattice). Where sites share a pixel the last
/// one drawn shows, so the order is part of the raster.
pub struct View<'a, F> {
    /// The lattice's side along each axis.
    pub sizes: &'a [u64],
    /// Sweeps made.
    pub sweeps: u64,
    /// Live clusters.
    pub clusters: u64,
    /// Particles.
    pub particles: u64,
    /// The run's seed.
    pub seed: u64,
    /// The pass over the particles.
    pub each: F,
}

/// A callback over the particles of a [`View`]: site coordinates on the first two axes and
/// cluster id.
pub type Visit<'v> = dyn FnMut(u64, u64, u32) + 'v;

/// The view of `sim`'s state (its particles straight from the simulation).
pub fn view(sim: &Simulation, seed: u64) -> View<'_, impl Fn(&mut Visit<'_>) + '_> {
    let l = sim.lattice();
    View {
        sizes: l.sizes(),
        sweeps: sim.sweeps(),
        clusters: sim.clusters(),
        particles: sim.particles(),
        seed,
        each: move |f: &mut Visit<'_>| {
            let _ = sim.try_for_each_particle(|id, k| {
                f(
                    l.coord(k, 0),
                    if l.dim() >= 2 { l.coord(k, 1) } else { 0 },
                    id,
                );
                Ok::<(), std::convert::Infallible>(())
            });
        },
    }
}

/// The first two sides of a lattice (the second 1 on a 1D lattice).
fn plane(sizes: &[u64]) -> (u64, u64) {
    (sizes[0], sizes.get(1).copied().unwrap_or(1))
}

/// Width and height of the raster of a lattice of `sizes` whose longer side is `side` pixels
/// (default: a whole number of pixels per site, at least [`PNG_MIN_SIDE`], or one pixel per
/// site up to [`PNG_MAX_SIDE`]); the shorter side keeps the lattice's proportions.
pub fn raster_size(sizes: &[u64], side: Option<u32>) -> (u32, u32) {
    let (w0, h0) = plane(sizes);
    let long = w0.max(h0);
    let side = match side {
        Some(s) => u64::from(s),
        None if long < PNG_MIN_SIDE => long * PNG_MIN_SIDE.div_ceil(long),
        None => long.min(PNG_MAX_SIDE),
    };
    let scaled = |n: u64| ((n as f64 * side as f64 / long as f64).round() as u64).max(1) as u32;
    (scaled(w0), scaled(h0))
}

/// Memory the buffers of a figure of `w` x `h` pixels take while drawn: a cluster id (4 bytes)
/// and a colour (3) per pixel, and the figure around it (at most double the area: 6).
pub fn png_memory_bytes(w: u64, h: u64) -> u64 {
    w.saturating_mul(h).saturating_mul(13)
}

/// The cluster id shown at each pixel of a `w` x `h` raster (`u32::MAX`: no particle), row 0
/// at the top. Sites map to the pixels of their share of the raster (at least one each).
fn labels<F: Fn(&mut Visit<'_>)>(view: &View<'_, F>, (w, h): (u32, u32)) -> Vec<u32> {
    let (w0, h0) = plane(view.sizes);
    let span = |c: u64, n: u64, px: u32| {
        let a = (c as f64 * f64::from(px) / n as f64) as u32;
        let b = ((((c + 1) as f64 * f64::from(px) / n as f64) as u32).max(a + 1)).min(px);
        a.min(px - 1)..b
    };
    let mut ids = vec![u32::MAX; w as usize * h as usize];
    (view.each)(&mut |x, y, id| {
        // Row 0 at the top: flip y so the last axis points up, as gravity pulls down.
        for py in span(h0 - 1 - y, h0, h) {
            for px in span(x, w0, w) {
                ids[py as usize * w as usize + px as usize] = id;
            }
        }
    });
    ids
}

/// How far (in pixels) clusters are grown to find their neighbours in a figure of `size`: a
/// 32nd of its longer side, at least 3 pixels, so clusters less than about a 16th of the
/// raster apart differ in colour.
fn reach((w, h): (u32, u32)) -> usize {
    (w.max(h) as usize / 32).max(3)
}

/// The raster of `view` and the colour (index into [`ON_BLACK`]) of each cluster in it, each
/// cluster keeping its colour in `previous` where no neighbour has it; the last value counts
/// clusters that had to share a colour with a neighbour (none on a 2D lattice in practice).
fn draw<F: Fn(&mut Visit<'_>)>(
    view: &View<'_, F>,
    size: (u32, u32),
    previous: &HashMap<u32, usize>,
) -> (Raster, HashMap<u32, usize>, usize) {
    let ids = labels(view, size);
    let (colours, clashes) = colour_regions(
        &ids,
        size.0 as usize,
        u32::MAX,
        reach(size),
        ON_BLACK.len(),
        |id| previous.get(&id).copied(),
    );
    let mut r = Raster::new(size.0, size.1, palette::BLACK);
    for (at, id) in ids.iter().enumerate() {
        if *id != u32::MAX {
            r.rgb[at * 3..at * 3 + 3].copy_from_slice(&ON_BLACK[colours[id]]);
        }
    }
    (r, colours, clashes)
}

/// The figure of a figure of `view`.
fn figure<'a, F>(view: &View<'_, F>, raster: &'a Raster) -> Figure<'a> {
    let sizes: Vec<String> = view.sizes.iter().map(u64::to_string).collect();
    let (w0, h0) = plane(view.sizes);
    let mut note = vec![
        "one colour per cluster;".to_string(),
        "neighbouring clusters".to_string(),
        "always differ".to_string(),
    ];
    if view.sizes.len() >= 3 {
        note.push(String::new());
        note.push("projection on x1, x2".into());
    }
    Figure {
        raster,
        extent: Extent {
            x: (0.0, w0 as f64),
            y: (0.0, h0 as f64),
        },
        unit: "lattice cells".into(),
        axes: ("x1".into(), "x2".into()),
        header: format!(
            "DLCA {}, sweep {}: {} clusters, {} particles, seed {}",
            sizes.join("x"),
            group_digits(view.sweeps),
            group_digits(view.clusters),
            group_digits(view.particles),
            view.seed,
        ),
        legend: Legend::Note(note),
    }
}

/// Writes `dlca.png`, the figure of `sim`'s state with a raster whose longer side is `side`
/// pixels (default: see [`raster_size`]).
///
/// # Errors
/// The file cannot be written.
pub fn write_png(
    sim: &Simulation,
    seed: u64,
    path: &Path,
    side: Option<u32>,
) -> Result<(), OutputError> {
    png(&view(sim, seed), path, side)
}

/// Writes the figure of `view` as [`write_png`] does: for the view of a state (its particles
/// in the order of `particles.csv`, as the Python bindings hold them), the binary's `dlca.png`
/// byte for byte.
///
/// # Errors
/// The view has no axis or a site outside the lattice, or the file cannot be written.
pub fn write_png_of<F: Fn(&mut Visit<'_>)>(
    view: &View<'_, F>,
    path: &Path,
    side: Option<u32>,
) -> Result<(), OutputError> {
    if view.sizes.is_empty() || view.sizes.contains(&0) {
        return Err(std::io::Error::other("a lattice raster needs sides of 1 or more").into());
    }
    let (w0, h0) = plane(view.sizes);
    let mut outside = None;
    (view.each)(&mut |x, y, _| {
        if x >= w0 || y >= h0 {
            outside.get_or_insert((x, y));
        }
    });
    if let Some((x, y)) = outside {
        return Err(std::io::Error::other(format!(
            "site ({x}, {y}) is outside the {w0}x{h0} lattice"
        ))
        .into());
    }
    png(view, path, side)
}

/// [`write_png_of`] without the checks of the view (a simulation's always passes them).
fn png<F: Fn(&mut Visit<'_>)>(
    view: &View<'_, F>,
    path: &Path,
    side: Option<u32>,
) -> Result<(), OutputError> {
    let (raster, _, clashes) = draw(view, raster_size(view.sizes, side), &HashMap::new());
    if clashes > 0 {
        tracing::warn!("{clashes} clusters in dlca.png share a colour with a neighbour");
    }
    figure(view, &raster).write_png(path)?;
    Ok(())
}

/// Longer side of the figures in `dlca.gif` without `--png-size`.
pub const ANIMATION_DEFAULT_SIDE: u32 = 512;
/// Sweeps between frames of `dlca.gif` without `--animate-every`.
pub const ANIMATION_DEFAULT_EVERY: u64 = 10;

/// `dlca.gif` being written: one frame per call of [`Animation::frame`], each cluster keeping its
/// colour from frame to frame where it can.
#[derive(Debug)]
pub struct Animation {
    gif: Gif,
    size: (u32, u32),
    seed: u64,
    colours: HashMap<u32, usize>,
}

impl Animation {
    /// Starts an animation of `sim` at `path` with figures whose longer side is `side` pixels,
    /// and adds its first frame.
    ///
    /// # Errors
    /// The file cannot be created or the frame not drawn.
    pub fn start(sim: &Simulation, seed: u64, path: &Path, side: u32) -> Result<Self, OutputError> {
        let view = view(sim, seed);
        let size = raster_size(view.sizes, Some(side));
        let (raster, colours, _) = draw(&view, size, &HashMap::new());
        let image = figure(&view, &raster).render()?;
        let mut gif = Gif::create(path, image.width, image.height)?;
        gif.push(&image)?;
        Ok(Animation {
            gif,
            size,
            seed,
            colours,
        })
    }

    /// Whether a run that frames every `every` sweeps adds a frame after the sweep `sim` just
    /// made: on every multiple of `every`, and at the end.
    pub fn due(sim: &Simulation, every: u64) -> bool {
        sim.sweeps() % every.max(1) == 0 || sim.is_done()
    }

    /// Adds a frame of `sim` as it is now.
    ///
    /// # Errors
    /// The frame cannot be drawn or written.
    pub fn frame(&mut self, sim: &Simulation) -> Result<(), OutputError> {
        let view = view(sim, self.seed);
        let (raster, colours, _) = draw(&view, self.size, &self.colours);
        self.colours = colours;
        let image = figure(&view, &raster).render()?;
        self.gif.push(&image)?;
        Ok(())
    }

    /// Writes the file; returns the number of frames.
    ///
    /// # Errors
    /// The file cannot be written.
    pub fn finish(self) -> Result<u64, OutputError> {
        Ok(self.gif.finish()?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{Init, Params};

    fn small_run() -> Simulation {
        let p = Params {
            size: vec![48, 32],
            init: Init::Fill(0.2),
            target_clusters: 12,
            ..Params::default()
        };
        let mut sim = Simulation::new(p, 7).unwrap();
        sim.run();
        sim
    }

    #[test]
    fn neighbouring_clusters_have_different_colours() {
        let sim = small_run();
        let size = raster_size(sim.lattice().sizes(), Some(96));
        assert_eq!(size, (96, 64));
        let ids = labels(&view(&sim, 7), size);
        let (r, colours, clashes) = draw(&view(&sim, 7), size, &HashMap::new());
        assert_eq!(clashes, 0);
        assert!(
            colours
                .values()
                .collect::<std::collections::HashSet<_>>()
                .len()
                >= 3
        );
        // Clusters whose pixels are 4 pixels (2 sites) apart or closer: DLCA clusters never
        // touch (they merge on contact), so these are the nearest neighbours there are.
        let (w, h) = (size.0 as i64, size.1 as i64);
        let mut near = 0;
        for y in 0..h {
            for x in 0..w {
                let a = ids[(y * w + x) as usize];
                if a == u32::MAX {
                    continue;
                }
                for dy in -4..=4 {
                    for dx in -4..=4 {
                        let (nx, ny) = (x + dx, y + dy);
                        if nx < 0 || ny < 0 || nx >= w || ny >= h {
                            continue;
                        }
                        let b = ids[(ny * w + nx) as usize];
                        if b != u32::MAX && b != a {
                            near += 1;
                            assert_ne!(colours[&a], colours[&b], "clusters {a} and {b}");
                        }
                    }
                }
            }
        }
        assert!(near > 0, "the test run has clusters close together");
        // Every site is drawn, in a colour that stands out from the background.
        for y in 0..size.1 {
            for x in 0..size.0 {
                let c = r.get(x, y);
                if ids[(y * size.0 + x) as usize] != u32::MAX {
                    assert!(palette::contrast(c, palette::BLACK) >= palette::MIN_CONTRAST);
                } else {
                    assert_eq!(c, palette::BLACK);
                }
            }
        }
    }

    #[test]
    fn figures_of_a_view_from_arrays_are_the_simulations_byte_for_byte() {
        let mut sim3 = Simulation::new(
            Params {
                size: vec![12, 10, 8],
                boundary: vec![core_lattice::Boundary::Periodic; 3],
                init: Init::Fill(0.1),
                target_clusters: 20,
                ..Params::default()
            },
            4,
        )
        .unwrap();
        sim3.run();
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
        for (sim, seed) in [(small_run(), 7), (sim3, 4)] {
            // The particles as the Python bindings hold them: (x1, x2, id) in the order of
            // particles.csv.
            let mut rows = Vec::new();
            (view(&sim, seed).each)(&mut |x, y, id| rows.push((x, y, id)));
            let arrays = View {
                sizes: sim.lattice().sizes(),
                sweeps: sim.sweeps(),
                clusters: sim.clusters(),
                particles: sim.particles(),
                seed,
                each: |f: &mut Visit<'_>| {
                    for &(x, y, id) in &rows {
                        f(x, y, id);
                    }
                },
            };
            // The default size, and one with several sites a pixel.
            for side in [None, Some(20)] {
                write_png(&sim, seed, &a, side).unwrap();
                write_png_of(&arrays, &b, side).unwrap();
                assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
            }
        }
        let outside = View {
            sizes: &[4, 4],
            sweeps: 0,
            clusters: 1,
            particles: 1,
            seed: 1,
            each: |f: &mut Visit<'_>| f(1, 4, 0),
        };
        assert!(write_png_of(&outside, &b, None).is_err());
    }

    #[test]
    fn the_default_size_keeps_the_proportions() {
        let sim = small_run();
        // 48 x 32 sites: 11 pixels a site, so the longer side reaches 512.
        assert_eq!(raster_size(sim.lattice().sizes(), None), (528, 352));
    }

    #[test]
    fn an_animation_has_one_frame_per_call() {
        let p = Params {
            size: vec![24, 24],
            init: Init::Fill(0.1),
            target_clusters: 1,
            max_sweeps: Some(6),
            ..Params::default()
        };
        let mut sim = Simulation::new(p, 3).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("dlca.gif");
        let mut a = Animation::start(&sim, 3, &path, 48).unwrap();
        let first = a.colours.clone();
        while !sim.is_done() {
            sim.sweep();
            a.frame(&sim).unwrap();
        }
        // Clusters untouched by merges keep their colours.
        let kept = first
            .iter()
            .filter(|(id, c)| a.colours.get(id) == Some(c))
            .count();
        assert!(kept > 0);
        assert_eq!(a.finish().unwrap(), 7);
        let ((w, h), frames) = figures::animation::read_gif(&path).unwrap();
        assert_eq!(frames, 7);
        assert!(w > 48 && h > 48);
    }
}
