//! # figures
//!
//! Figures of simulation runs, one word for every image the project draws:
//!
//! - a figure of a model's state (this module): a [`Raster`] the model draws, one pixel per
//!   pixel, never resampled, framed with axes in the model's units, a header naming the run
//!   (model, N or step, seed) with a scale bar, and a legend (a colour bar or a key). The same
//!   figure is a PNG ([`Figure::write_png`]) or a frame of an animation ([`animation::Gif`]);
//! - a chart ([`chart`]): curves with error bands, the figures of `cargo xtask` and of the
//!   ensembles;
//! - [`palette`]: colour-blind-safe palettes and perceptual colour maps;
//! - [`png`]: the PNG encoder every figure is written with, atomically.
//!
//! Layout of a figure of a state: the header strip above the raster, the axes left and below,
//! the legend right; nothing is drawn over the data. Text grows with the raster, so a
//! 4096-pixel figure is as legible as a 512-pixel one. Text uses the DejaVu Sans font committed
//! under `assets/fonts/`, so no system font library is needed.

/// `anyhow::ensure!` for this crate's [`Result`].
macro_rules! ensure {
    ($cond:expr, $($msg:tt)+) => {
        if !$cond {
            return Err(anyhow::anyhow!($($msg)+).into());
        }
    };
}

pub mod animation;
pub mod chart;
pub mod palette;
pub mod png;
mod text;

use crate::text::register_font;
use anyhow::{Context, anyhow};
use palette::{Rgb, Sequential};
use plotters::element::BitMapElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// Why a figure, chart or animation could not be drawn or written: the chain of causes,
/// shown in one line.
#[derive(Debug)]
pub struct Error(anyhow::Error);

/// A figure's result.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:#}", self.0)
    }
}

impl std::error::Error for Error {}

impl From<anyhow::Error> for Error {
    fn from(e: anyhow::Error) -> Self {
        Self(e)
    }
}

impl From<png::ImageError> for Error {
    fn from(e: png::ImageError) -> Self {
        Self(e.into())
    }
}

impl From<Error> for run_io::OutputError {
    fn from(e: Error) -> Self {
        run_io::OutputError::Figure(e.to_string())
    }
}

impl From<png::ImageError> for run_io::OutputError {
    fn from(e: png::ImageError) -> Self {
        run_io::OutputError::Figure(e.to_string())
    }
}

/// Smallest side of a figure's raster in pixels that may be asked for (`--png-size`).
pub const PNG_SIZE_MIN: u32 = 16;
/// Largest side of a figure's raster in pixels that may be asked for (`--png-size`; an
/// animation's is at most [`animation::ANIMATION_MAX_SIDE`]).
pub const PNG_SIZE_MAX: u32 = 65536;

/// An RGB image, row-major, top row first, three bytes a pixel.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Raster {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 3` bytes.
    pub rgb: Vec<u8>,
}

impl Raster {
    /// A `width` x `height` raster filled with `background`.
    pub fn new(width: u32, height: u32, background: Rgb) -> Self {
        let n = width as usize * height as usize;
        let mut rgb = Vec::with_capacity(n * 3);
        for _ in 0..n {
            rgb.extend_from_slice(&background);
        }
        Raster { width, height, rgb }
    }

    /// Sets pixel `(x, y)` (column, row from the top) to `c`.
    #[inline]
    pub fn put(&mut self, x: u32, y: u32, c: Rgb) {
        let at = (y as usize * self.width as usize + x as usize) * 3;
        self.rgb[at..at + 3].copy_from_slice(&c);
    }

    /// The colour of pixel `(x, y)`.
    #[inline]
    pub fn get(&self, x: u32, y: u32) -> Rgb {
        let at = (y as usize * self.width as usize + x as usize) * 3;
        [self.rgb[at], self.rgb[at + 1], self.rgb[at + 2]]
    }

    /// Writes the raster as it is (no axes) to a PNG, atomically.
    pub fn write_png(&self, path: &Path) -> Result<()> {
        png::write_png_rgb(path, self.width, self.height, &self.rgb)
            .with_context(|| format!("writing {}", path.display()))
            .map_err(Error::from)
    }
}

/// The rectangle of model space a raster shows: x from its left to its right edge, y from its
/// bottom to its top edge (y points up), in the model's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extent {
    /// Left and right edges.
    pub x: (f64, f64),
    /// Bottom and top edges.
    pub y: (f64, f64),
}

/// What the legend right of the raster shows.
#[derive(Debug, Clone)]
pub enum Legend {
    /// A colour bar of a sequential map from `lo` (bottom) to `hi` (top), with its label.
    ColourBar {
        /// The map.
        map: Sequential,
        /// What the colour means (`arrival order`).
        label: String,
        /// Value at the bottom.
        lo: f64,
        /// Value at the top.
        hi: f64,
        /// The values are spaced logarithmically along the bar.
        log: bool,
    },
    /// Named colours (species).
    Key(Vec<(String, Rgb)>),
    /// Lines of text (how the colours were chosen, when they mean no value).
    Note(Vec<String>),
}

/// A figure: a figure of the state and what makes it readable.
#[derive(Debug, Clone)]
pub struct Figure<'a> {
    /// The raster.
    pub raster: &'a Raster,
    /// What the raster shows, in model units.
    pub extent: Extent,
    /// The unit of both axes and of the scale bar (`diameters`, `lattice cells`).
    pub unit: String,
    /// Names of the axes (`x`, `y`; the unit is appended).
    pub axes: (String, String),
    /// The header's text: model, N or step, seed.
    pub header: String,
    /// The legend.
    pub legend: Legend,
}

/// The text scale of a figure whose raster is `side` pixels: 1 up to 640 pixels, growing in
/// proportion beyond.
fn text_scale(side: u32) -> f64 {
    (f64::from(side) / 640.0).clamp(1.0, 8.0)
}

/// A "nice" length (1, 2 or 5 times a power of ten) of about a fifth of `span`.
pub fn scale_bar_length(span: f64) -> f64 {
    let target = span / 5.0;
    if !(target.is_finite() && target > 0.0) {
        return 1.0;
    }
    let p = 10f64.powf(target.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&l| l <= target)
        .unwrap_or(p)
}

/// The labelled ticks of a colour bar from `lo` to `hi`: `(fraction of the bar, value)` at
/// round values (1, 2 or 5 times a power of ten apart; powers of ten on a log bar), with both
/// ends labelled when no round value is near them.
pub fn colour_bar_ticks(lo: f64, hi: f64, log: bool) -> Vec<(f64, f64)> {
    if !(lo.is_finite() && hi.is_finite() && hi > lo) || (log && lo <= 0.0) {
        return vec![(0.0, lo), (1.0, hi)];
    }
    let frac = |v: f64| {
        if log {
            (v / lo).ln() / (hi / lo).ln()
        } else {
            (v - lo) / (hi - lo)
        }
    };
    let mut ticks: Vec<(f64, f64)> = if log {
        let (a, b) = (lo.log10().ceil() as i32, hi.log10().floor() as i32);
        (a..=b)
            .map(|k| 10f64.powi(k))
            .map(|v| (frac(v), v))
            .collect()
    } else {
        // The round step nearest a quarter of the range (on a log scale).
        let target = (hi - lo) / 4.0;
        let p = 10f64.powf(target.log10().floor());
        let step = [1.0, 2.0, 5.0, 10.0]
            .into_iter()
            .map(|m| m * p)
            .min_by(|a, b| (a / target).ln().abs().total_cmp(&(b / target).ln().abs()))
            .unwrap_or(p);
        let first = (lo / step).ceil() as i64;
        let last = (hi / step).floor() as i64;
        (first..=last)
            .map(|k| k as f64 * step)
            .map(|v| (frac(v), v))
            .collect()
    };
    // The ends, unless a round value is within an eighth of the bar of them.
    if ticks.first().is_none_or(|t| t.0 > 0.125) {
        ticks.insert(0, (0.0, lo));
    }
    if ticks.last().is_none_or(|t| t.0 < 0.875) {
        ticks.push((1.0, hi));
    }
    ticks
}

/// `1234567` as `1,234,567`.
pub fn group_digits(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::with_capacity(s.len() + s.len() / 3);
    for (i, ch) in s.chars().enumerate() {
        if i > 0 && (s.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(ch);
    }
    out
}

fn rgb(c: Rgb) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

impl Figure<'_> {
    /// The figure's margins for its raster, header and legend, from the widths of the text
    /// as the font lays it out.
    fn layout(&self) -> Layout {
        register_font();
        let u = text_scale(self.raster.width.max(self.raster.height));
        let px = |v: f64| (v * u).round() as u32;
        // Width in units of `u` (a tenth more than laid out, for the rasteriser's rounding).
        let text_w = |s: &str, size: f64| {
            let w = ("sans-serif", size * u)
                .into_font()
                .box_size(s)
                .map_or(s.chars().count() as f64 * 0.62 * size * u, |b| {
                    f64::from(b.0)
                });
            1.1 * w / u
        };
        let legend_w = match &self.legend {
            Legend::ColourBar { .. } => 120.0,
            Legend::Key(entries) => {
                24.0 + entries
                    .iter()
                    .map(|e| text_w(&e.0, 15.0))
                    .fold(0.0, f64::max)
            }
            Legend::Note(lines) => lines.iter().map(|l| text_w(l, 13.0)).fold(0.0, f64::max),
        };
        // The layout depends on the raster's size and the legend only, never on the
        // header's text, so that every frame of an animation has the same size: the header
        // has a line of its own above the scale bar's, and may run over the legend's column.
        let raster_w = f64::from(self.raster.width) / u;
        let right = legend_w + 32.0;
        let header_w = text_w(&self.header, 16.0);
        // A header wider than the figure is set smaller (small figures only).
        let header_size = 16.0 * ((raster_w + right - 8.0) / header_w).min(1.0);
        Layout {
            u,
            top: px(66.0),
            header_size,
            left: px(90.0),
            bottom: px(58.0),
            right: px(right),
        }
    }

    /// The figure as an RGB image.
    pub fn render(&self) -> Result<Raster> {
        register_font();
        let r = self.raster;
        ensure!(
            r.width > 0 && r.height > 0 && r.rgb.len() == r.width as usize * r.height as usize * 3,
            "a figure's raster must be non-empty and {}x{}x3 bytes",
            r.width,
            r.height
        );
        let l = self.layout();
        let (w, h) = (l.left + r.width + l.right, l.top + r.height + l.bottom);
        let mut out = Raster::new(w, h, palette::WHITE);
        {
            let root = BitMapBackend::with_buffer(&mut out.rgb, (w, h)).into_drawing_area();
            self.draw(&root, &l)
                .map_err(|e| anyhow!("drawing a figure: {e}"))?;
            root.present().map_err(|e| anyhow!("{e}"))?;
        }
        Ok(out)
    }

    /// Writes the figure to a PNG at `path`, atomically.
    pub fn write_png(&self, path: &Path) -> Result<()> {
        self.render()?.write_png(path)
    }

    fn draw(
        &self,
        root: &DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>,
        l: &Layout,
    ) -> std::result::Result<(), Box<dyn std::error::Error>> {
        let r = self.raster;
        let u = l.u;
        let font = |size: f64| TextStyle::from(("sans-serif", size * u).into_font());
        let e = self.extent;
        let mut chart = ChartBuilder::on(root)
            .margin_top(l.top)
            .margin_right(l.right)
            .margin_left(l.left / 6)
            .margin_bottom(0)
            .x_label_area_size(l.bottom)
            .y_label_area_size(l.left - l.left / 6)
            .build_cartesian_2d(e.x.0..e.x.1, e.y.0..e.y.1)?;
        let (xs, ys) = chart.plotting_area().get_pixel_range();
        debug_assert_eq!(
            (xs.end - xs.start, ys.end - ys.start),
            (r.width as i32, r.height as i32)
        );
        chart
            .configure_mesh()
            .disable_mesh()
            // About one label per 100 pixels (in text units) across, per 60 up.
            .x_labels((f64::from(r.width) / (100.0 * u)).clamp(2.0, 8.0) as usize)
            .y_labels((f64::from(r.height) / (60.0 * u)).clamp(2.0, 8.0) as usize)
            .x_desc(format!("{} ({})", self.axes.0, self.unit))
            .y_desc(format!("{} ({})", self.axes.1, self.unit))
            .x_label_formatter(&|v| text::tick(*v))
            .y_label_formatter(&|v| text::tick(*v))
            .label_style(font(14.0))
            .axis_desc_style(font(16.0))
            .set_all_tick_mark_size((5.0 * u) as u32)
            .draw()?;
        root.draw(
            &BitMapElement::with_ref((xs.start, ys.start), (r.width, r.height), &r.rgb)
                .ok_or("raster size")?,
        )?;
        // The raster's frame.
        root.draw(&Rectangle::new(
            [(xs.start - 1, ys.start - 1), (xs.end, ys.end)],
            BLACK.stroke_width(1),
        ))?;

        // Header: the run on the first line, the scale bar right-aligned on the second.
        let (first, mid) = ((20.0 * u) as i32, (46.0 * u) as i32);
        root.draw(&Text::new(
            self.header.clone(),
            (xs.start, first),
            font(l.header_size).pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
        let span = e.x.1 - e.x.0;
        let length = scale_bar_length(span);
        let bar_px = ((length / span) * f64::from(r.width)).round().max(1.0) as i32;
        let half = ((3.0 * u).round() as i32).max(2);
        root.draw(&Rectangle::new(
            [(xs.end - bar_px, mid - half), (xs.end, mid + half)],
            BLACK.filled(),
        ))?;
        let tick = (5.0 * u) as i32;
        root.draw(&Text::new(
            format!("{} {}", text::tick(length), self.unit),
            (xs.end - bar_px - (8.0 * u) as i32, mid),
            font(15.0).pos(Pos::new(HPos::Right, VPos::Center)),
        ))?;

        // Legend, right of the raster.
        let x0 = xs.end + (16.0 * u) as i32;
        match &self.legend {
            Legend::ColourBar {
                map,
                label,
                lo,
                hi,
                log,
            } => {
                let bar_w = (18.0 * u) as i32;
                let (top, bottom) = (ys.start, ys.end);
                let n = (bottom - top).max(1);
                for j in 0..n {
                    let c = map.at(1.0 - f64::from(j) / f64::from((n - 1).max(1)));
                    root.draw(&Rectangle::new(
                        [(x0, top + j), (x0 + bar_w, top + j + 1)],
                        rgb(c).filled(),
                    ))?;
                }
                root.draw(&Rectangle::new(
                    [(x0, top), (x0 + bar_w, bottom)],
                    BLACK.stroke_width(1),
                ))?;
                for (f, v) in colour_bar_ticks(*lo, *hi, *log) {
                    let y = bottom - (f * f64::from(n)).round() as i32;
                    let text = if v.fract() == 0.0 && v.abs() < 1e15 {
                        group_digits(v.abs() as u64)
                    } else {
                        text::tick(v)
                    };
                    root.draw(&PathElement::new(
                        vec![(x0 + bar_w, y), (x0 + bar_w + tick, y)],
                        BLACK.stroke_width(1),
                    ))?;
                    root.draw(&Text::new(
                        text,
                        (x0 + bar_w + tick + (3.0 * u) as i32, y),
                        font(13.0).pos(Pos::new(HPos::Left, VPos::Center)),
                    ))?;
                }
                let lx = x0 + (100.0 * u) as i32;
                root.draw(&Text::new(
                    label.clone(),
                    (lx, (top + bottom) / 2),
                    TextStyle::from(
                        ("sans-serif", 15.0 * u)
                            .into_font()
                            .transform(FontTransform::Rotate270),
                    )
                    .pos(Pos::new(HPos::Center, VPos::Center)),
                ))?;
            }
            Legend::Key(entries) => {
                let side = (16.0 * u) as i32;
                for (i, (name, c)) in entries.iter().enumerate() {
                    let y = ys.start + (i as f64 * 26.0 * u) as i32;
                    root.draw(&Rectangle::new(
                        [(x0, y), (x0 + side, y + side)],
                        rgb(*c).filled(),
                    ))?;
                    root.draw(&Text::new(
                        name.clone(),
                        (x0 + side + (8.0 * u) as i32, y + side / 2),
                        font(15.0).pos(Pos::new(HPos::Left, VPos::Center)),
                    ))?;
                }
            }
            Legend::Note(lines) => {
                for (i, line) in lines.iter().enumerate() {
                    root.draw(&Text::new(
                        line.clone(),
                        (x0, ys.start + (i as f64 * 20.0 * u) as i32),
                        font(13.0).pos(Pos::new(HPos::Left, VPos::Top)),
                    ))?;
                }
            }
        }
        Ok(())
    }
}

/// Margins around the raster, in pixels, and the text scale.
struct Layout {
    u: f64,
    top: u32,
    header_size: f64,
    left: u32,
    bottom: u32,
    right: u32,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figure(raster: &Raster, legend: Legend) -> Figure<'_> {
        Figure {
            raster,
            extent: Extent {
                x: (-10.0, 10.0),
                y: (-10.0, 10.0),
            },
            unit: "diameters".into(),
            axes: ("x".into(), "y".into()),
            header: "test, N = 1,000, seed 1".into(),
            legend,
        }
    }

    #[test]
    fn the_raster_is_copied_unchanged_into_the_figure() {
        let mut r = Raster::new(200, 150, palette::WHITE);
        for y in 0..150 {
            for x in 0..200 {
                r.put(x, y, [(x % 256) as u8, (y % 256) as u8, 7]);
            }
        }
        let f = figure(&r, Legend::Key(vec![("fox".into(), palette::FOX)]));
        let out = f.render().unwrap();
        let l = f.layout();
        assert_eq!(out.width, l.left + 200 + l.right);
        assert_eq!(out.height, l.top + 150 + l.bottom);
        for y in 0..150 {
            for x in 0..200 {
                assert_eq!(out.get(l.left + x, l.top + y), r.get(x, y), "({x}, {y})");
            }
        }
    }

    #[test]
    fn rendering_is_deterministic_and_draws_every_legend() {
        let r = Raster::new(64, 64, palette::BLACK);
        let legends = [
            Legend::ColourBar {
                map: Sequential::magma_on_white(),
                label: "arrival order".into(),
                lo: 0.0,
                hi: 999.0,
                log: false,
            },
            Legend::ColourBar {
                map: Sequential::viridis_on_black(),
                label: "particles per pixel".into(),
                lo: 1.0,
                hi: 1000.0,
                log: true,
            },
            Legend::Key(vec![
                ("a".into(), palette::FOX),
                ("b".into(), palette::RABBIT),
            ]),
            Legend::Note(vec!["one colour".into(), "per cluster".into()]),
        ];
        for legend in legends {
            let f = figure(&r, legend);
            let a = f.render().unwrap();
            let b = f.render().unwrap();
            assert_eq!(a, b);
            // Text and axes are drawn: the margins are not all white.
            assert!(a.rgb.iter().filter(|&&v| v < 128).count() > 500);
        }
    }

    #[test]
    fn scale_bars_are_nice_numbers() {
        assert_eq!(scale_bar_length(100.0), 20.0);
        assert_eq!(scale_bar_length(1000.0), 200.0);
        assert_eq!(scale_bar_length(30.0), 5.0);
        assert_eq!(scale_bar_length(7.0), 1.0);
        assert_eq!(group_digits(1234567), "1,234,567");
        assert_eq!(group_digits(999), "999");
        let values = |t: Vec<(f64, f64)>| t.into_iter().map(|t| t.1).collect::<Vec<_>>();
        assert_eq!(
            values(colour_bar_ticks(1.0, 20000.0, false)),
            [1.0, 5000.0, 10000.0, 15000.0, 20000.0]
        );
        assert_eq!(
            values(colour_bar_ticks(1.0, 5000.0, true)),
            [1.0, 10.0, 100.0, 1000.0, 5000.0]
        );
        assert_eq!(values(colour_bar_ticks(1.0, 3.0, true)), [1.0, 3.0]);
    }

    #[test]
    fn the_size_never_depends_on_the_header() {
        let r = Raster::new(40, 40, palette::WHITE);
        let mut f = figure(&r, Legend::Note(vec!["a note".into()]));
        let a = f.render().unwrap();
        f.header = "a much longer header, N = 1,000,000 of 10,000,000, seed 12345678".into();
        let b = f.render().unwrap();
        assert_eq!((a.width, a.height), (b.width, b.height));
    }

    #[test]
    fn bad_rasters_are_refused() {
        let r = Raster {
            width: 3,
            height: 3,
            rgb: vec![0; 5],
        };
        assert!(figure(&r, Legend::Note(vec![])).render().is_err());
    }
}

/// The README's examples, compiled and run as doctests so that they stay true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
