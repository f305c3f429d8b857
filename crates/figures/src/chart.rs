//! PNG charts with plotters , drawn into a memory buffer and written with the
//! project's atomic PNG writer: the figures of `cargo xtask` and of the models' ensembles.
//! Text uses the DejaVu Sans font committed under `crates/figures/assets/fonts/` and
//! registered with plotters' `ab_glyph` backend, so no system font library is needed.
//!
//! Here: the charts' description and their axes' ranges; the drawing is in `draw`, the
//! placing of point labels in `labels` and the legend's corner in `legend`.

use crate::palette::{OKABE_ITO, Rgb};
use crate::{Error, Result};
use anyhow::Context;
use plotters::prelude::*;
use std::path::Path;

mod draw;
mod labels;
mod legend;
use draw::render;
pub use labels::{Rect, place_labels};
use legend::{headroom, legend_corner};

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// A line through the points.
    Line,
    /// A dashed-looking thin line (fits, reference curves).
    Thin,
    /// Markers only.
    Points,
    /// Line and markers.
    LinePoints,
    /// Large hollow markers (to mark a special point, e.g. the default setting).
    Highlight,
}

/// One data series.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// `(x, y)` points.
    pub points: Vec<(f64, f64)>,
    /// Drawing style.
    pub style: Style,
    /// Optional text drawn next to each point (same length as `points`).
    pub labels: Option<Vec<String>>,
    /// Optional error band `(x, low, high)`, shaded in the series' colour under it.
    pub band: Option<Vec<(f64, f64, f64)>>,
    /// Optional symmetric error bars on y, one per point (a standard error, say).
    pub y_errors: Option<Vec<f64>>,
    /// The series' colour (default: the chart's palette, in the order of the series).
    pub colour: Option<[u8; 3]>,
}

impl Series {
    /// A series from its name, points and style.
    pub fn new(name: impl Into<String>, points: Vec<(f64, f64)>, style: Style) -> Self {
        Series {
            name: name.into(),
            points,
            style,
            labels: None,
            band: None,
            y_errors: None,
            colour: None,
        }
    }

    /// The same series in colour `c` (a species' colour, say) instead of the palette's.
    pub fn with_colour(mut self, c: [u8; 3]) -> Self {
        self.colour = Some(c);
        self
    }

    /// The same series with an error bar of half-length `errors[i]` on point `i`.
    pub fn with_y_errors(mut self, errors: Vec<f64>) -> Self {
        assert_eq!(errors.len(), self.points.len(), "one error per point");
        self.y_errors = Some(errors);
        self
    }

    /// The same series with an error band `(x, low, high)` (mean +- standard error, say).
    pub fn with_band(mut self, band: Vec<(f64, f64, f64)>) -> Self {
        self.band = Some(band);
        self
    }

    /// The same series with a text label beside each point.
    pub fn with_labels(mut self, labels: Vec<String>) -> Self {
        assert_eq!(labels.len(), self.points.len(), "one label per point");
        self.labels = Some(labels);
        self
    }
}

/// A chart: title, axis labels, log or linear axes, series.
#[derive(Debug, Clone)]
pub struct Chart {
    /// Caption.
    pub title: String,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// The data.
    pub series: Vec<Series>,
}

impl Chart {
    /// A chart with both axes logarithmic, the form of every scaling law the reports plot.
    pub fn log_log(
        title: impl Into<String>,
        x_label: &str,
        y_label: &str,
        series: Vec<Series>,
    ) -> Self {
        Chart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            log_x: true,
            log_y: true,
            series,
        }
    }
}

/// The colours of series without their own, in order: Okabe-Ito blue, vermillion, bluish
/// green, reddish purple, orange, sky blue ([`OKABE_ITO`]), a grey, and black.
const PALETTE: [RGBColor; 8] = [
    rgb(OKABE_ITO[5]),
    rgb(OKABE_ITO[6]),
    rgb(OKABE_ITO[3]),
    rgb(OKABE_ITO[7]),
    rgb(OKABE_ITO[1]),
    rgb(OKABE_ITO[2]),
    RGBColor(120, 120, 120),
    rgb(OKABE_ITO[0]),
];

/// A palette colour as plotters' colour.
const fn rgb(c: Rgb) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

const WIDTH: u32 = 960;
const HEIGHT: u32 = 640;

/// Axis range covering `values` (positive values only on a log axis), with a margin.
fn range(values: impl Iterator<Item = f64>, log: bool) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return None;
    }
    Some(if log {
        let (a, b) = (lo.log10(), hi.log10());
        let m = ((b - a) * 0.05).max(0.05);
        (10f64.powf(a - m), 10f64.powf(b + m))
    } else {
        let m = ((hi - lo) * 0.05).max(hi.abs().max(1e-12) * 0.05);
        (lo - m, hi + m)
    })
}

/// The legend's corner and the axes' ranges of `chart` (named `path` in errors).
type Ranges = (SeriesLabelPosition, (f64, f64), (f64, f64));

fn ranges(chart: &Chart, path: &Path) -> Result<Ranges> {
    let all = || chart.series.iter().flat_map(|s| s.points.iter());
    let bands = || chart.series.iter().flat_map(|s| s.band.iter().flatten());
    let (x0, x1) = range(all().map(|p| p.0), chart.log_x)
        .with_context(|| format!("no plottable x values for {}", path.display()))?;
    let bars = || {
        chart.series.iter().flat_map(|s| {
            s.points
                .iter()
                .zip(s.y_errors.iter().flatten())
                .flat_map(|(p, e)| [p.1 - e, p.1 + e])
        })
    };
    let ys = all()
        .map(|p| p.1)
        .chain(bands().flat_map(|b| [b.1, b.2]))
        .chain(bars());
    let (y0, y1) = range(ys, chart.log_y)
        .with_context(|| format!("no plottable y values for {}", path.display()))?;
    // Where every corner holds data, the y axis gets room above the data for the legend.
    let (corner, covered, h) = legend_corner(chart, (x0, x1), (y0, y1));
    let (corner, (y0, y1)) = if covered > 0 {
        let (y0, y1) = headroom((y0, y1), h, chart.log_y);
        (legend_corner(chart, (x0, x1), (y0, y1)).0, (y0, y1))
    } else {
        (corner, (y0, y1))
    };
    Ok((corner, (x0, x1), (y0, y1)))
}

/// Draw `chart` to a PNG at `path` (written atomically).
pub fn write_png(chart: &Chart, path: &Path) -> Result<()> {
    let (corner, (x0, x1), (y0, y1)) = ranges(chart, path)?;
    let (buf, _) = render(chart, corner, (x0, x1), (y0, y1))?;
    crate::png::write_png_rgb(path, WIDTH, HEIGHT, &buf)
        .with_context(|| format!("writing {}", path.display()))
        .map_err(Error::from)
}

/// [`write_png`] for a model's outputs (the charts of its analyses), with the error as an
/// [`OutputError`](run_io::OutputError).
///
/// # Errors
/// The chart cannot be drawn or the file written.
pub fn write_chart(chart: &Chart, path: &Path) -> std::result::Result<(), run_io::OutputError> {
    write_png(chart, path).map_err(|e| std::io::Error::other(format!("{e:#}")).into())
}

/// Where [`write_png`] puts the point labels of `chart`, in pixels (`None`: left out for want
/// of room); for checking that they never overlap.
pub fn label_boxes(chart: &Chart) -> Result<Vec<Option<Rect>>> {
    let ranges = ranges(chart, Path::new("chart"))?;
    let (corner, (x0, x1), (y0, y1)) = ranges;
    Ok(render(chart, corner, (x0, x1), (y0, y1))?.1)
}

#[cfg(test)]
mod tests {
    use super::labels::overlaps;
    use super::*;

    #[test]
    fn the_legend_goes_where_it_covers_least_data() {
        let line = |pts: Vec<(f64, f64)>| Chart {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            log_x: false,
            log_y: false,
            series: vec![Series::new("a long legend entry", pts, Style::Line)],
        };
        let corner = |c: &Chart| legend_corner(c, (0.0, 1.0), (0.0, 1.0)).0;
        // Falling from the upper left: the upper right is free.
        let falling = line(vec![(0.0, 1.0), (1.0, 0.0)]);
        assert!(matches!(corner(&falling), SeriesLabelPosition::UpperRight));
        // Rising from the lower left: the upper left is free.
        let rising = line(vec![(0.0, 0.0), (1.0, 1.0)]);
        assert!(matches!(corner(&rising), SeriesLabelPosition::UpperLeft));
        // Along the top edge: a lower corner.
        let top = line(vec![(0.0, 0.98), (0.5, 0.97), (1.0, 0.98)]);
        assert!(matches!(
            corner(&top),
            SeriesLabelPosition::LowerLeft | SeriesLabelPosition::LowerRight
        ));
        // Through every corner: none is free until the y axis gets headroom.
        let zigzag = line(vec![(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0)]);
        let (_, covered, h) = legend_corner(&zigzag, (0.0, 1.0), (0.0, 1.0));
        assert!(covered > 0);
        let roomy = headroom((0.0, 1.0), h, false);
        let (_, covered, _) = legend_corner(&zigzag, (0.0, 1.0), roomy);
        assert_eq!(covered, 0, "{roomy:?}");
    }

    fn assert_disjoint(boxes: &[Option<Rect>], obstacles: &[Rect], area: Rect) {
        let placed: Vec<Rect> = boxes.iter().flatten().copied().collect();
        for (i, &a) in placed.iter().enumerate() {
            assert!(a.0 >= area.0 && a.1 >= area.1 && a.2 <= area.2 && a.3 <= area.3);
            for &b in &placed[i + 1..] {
                assert!(!overlaps(a, b), "{a:?} {b:?}");
            }
            for &o in obstacles {
                assert!(!overlaps(a, o), "{a:?} over {o:?}");
            }
        }
    }

    #[test]
    fn labels_never_overlap_each_other_markers_or_the_legend() {
        let area = (100, 50, 900, 550);
        // Adversarial: 40 labels on one point, 30 on a tight row, a legend in the corner.
        let mut anchors = vec![(500, 300); 40];
        anchors.extend((0..30).map(|i| (200 + i * 3, 500)));
        let sizes: Vec<(i32, i32)> = (0..anchors.len())
            .map(|i| (40 + (i as i32 % 7) * 9, 14))
            .collect();
        let mut obstacles: Vec<Rect> = anchors
            .iter()
            .map(|&(x, y)| (x - 5, y - 5, x + 6, y + 6))
            .collect();
        obstacles.push((700, 50, 900, 150));
        let boxes = place_labels(&anchors, &sizes, &obstacles, area);
        assert_disjoint(&boxes, &obstacles, area);
        // There is room for all of them here.
        assert!(boxes.iter().all(Option::is_some));
        // No room at all: every label is left out, none drawn over another.
        let tiny = (0, 0, 30, 30);
        let boxes = place_labels(&[(15, 15); 3], &[(40, 14); 3], &[], tiny);
        assert!(boxes.iter().all(Option::is_none));
    }

    #[test]
    fn chart_labels_are_placed_apart() {
        // Points bunched together as in the accuracy charts, labels of similar length.
        let pts: Vec<(f64, f64)> = (0..14)
            .map(|i| (4.6 + 0.01 * f64::from(i % 5), 0.04 + 0.001 * f64::from(i)))
            .chain([(7.9, 0.04), (8.6, 0.03)])
            .collect();
        let labels: Vec<String> = (0..pts.len())
            .map(|i| format!("k{i} s0.5 jump100"))
            .collect();
        let chart = Chart {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            log_x: false,
            log_y: true,
            series: vec![
                Series::new("settings", pts, Style::Points).with_labels(labels),
                Series::new("front", vec![(4.4, 0.04), (4.7, 1e-4)], Style::Line),
            ],
        };
        let boxes = label_boxes(&chart).unwrap();
        assert!(boxes.iter().all(Option::is_some), "{boxes:?}");
        assert_disjoint(&boxes, &[], (0, 0, WIDTH as i32, HEIGHT as i32));
    }

    #[test]
    fn draws_every_axis_kind() {
        let dir = tempfile::tempdir().unwrap();
        for (log_x, log_y) in [(false, false), (true, false), (false, true), (true, true)] {
            let chart = Chart {
                title: "test ± μ".into(),
                x_label: "N".into(),
                y_label: "seconds".into(),
                log_x,
                log_y,
                series: vec![
                    Series::new(
                        "a",
                        vec![(1.0, 2.0), (10.0, 20.0), (100.0, 150.0)],
                        Style::LinePoints,
                    ),
                    Series::new("b", vec![(2.0, 1.0), (20.0, 0.0)], Style::Points),
                    Series::new("c", vec![(5.0, 5.0)], Style::Highlight),
                    Series::new("d", vec![(1.0, 3.0), (100.0, 30.0)], Style::Line)
                        .with_band(vec![(1.0, 2.5, 3.5), (100.0, 25.0, 35.0)]),
                    Series::new("e", vec![(3.0, 4.0), (30.0, 40.0)], Style::Points)
                        .with_y_errors(vec![1.0, 50.0]),
                ],
            };
            let path = dir.path().join(format!("{log_x}{log_y}.png"));
            write_png(&chart, &path).unwrap();
            let bytes = std::fs::read(&path).unwrap();
            assert_eq!(&bytes[1..4], b"PNG");
            assert!(bytes.len() > 5_000, "a chart with text and lines");
        }
    }
}
