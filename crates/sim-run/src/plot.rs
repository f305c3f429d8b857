//! PNG charts with plotters (feature `plot`), drawn into a memory buffer and written with the
//! project's atomic PNG writer: the figures of `cargo xtask` and of the models' ensembles.
//! Text uses the DejaVu Sans font committed under `crates/sim-run/assets/fonts/` and
//! registered with plotters' `ab_glyph` backend, so no system font library is needed.

use crate::figure::palette::{OKABE_ITO, Rgb};
use crate::text::{register_font, tick};
use anyhow::{Context, Result, anyhow};
use plotters::prelude::*;
use std::path::Path;

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

/// A rectangle of pixels: left, top, right, bottom (right and bottom exclusive).
pub type Rect = (i32, i32, i32, i32);

fn overlaps(a: Rect, b: Rect) -> bool {
    a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3
}

/// Places labels of `sizes` (width, height in pixels) near their `anchors` (the points they
/// name) inside `area`, so that no two labels overlap and no label overlaps an `obstacle` (the
/// markers, the legend). Each label takes the first free spot: beside its point (upper right,
/// lower right, upper left, lower left), then on rings of growing radius around it (16 spots a
/// ring, the last ring a quarter of the area's larger side away). A label with no free spot is
/// left out (`None`) rather than drawn over another.
pub fn place_labels(
    anchors: &[(i32, i32)],
    sizes: &[(i32, i32)],
    obstacles: &[Rect],
    area: Rect,
) -> Vec<Option<Rect>> {
    let mut placed: Vec<Rect> = Vec::new();
    let inside = |r: Rect| r.0 >= area.0 && r.1 >= area.1 && r.2 <= area.2 && r.3 <= area.3;
    let reach = (area.2 - area.0).max(area.3 - area.1) / 4;
    anchors
        .iter()
        .zip(sizes)
        .map(|(&(ax, ay), &(w, h))| {
            let beside = [
                (ax + 6, ay - h - 2),
                (ax + 6, ay + 2),
                (ax - 6 - w, ay - h - 2),
                (ax - 6 - w, ay + 2),
            ];
            let step = h + 6;
            let rings = (1..)
                .map(|k| k * step)
                .take_while(|&r| r <= reach.max(step));
            let around = rings.flat_map(|r| {
                (0..16).map(move |j| {
                    let t = f64::from(j) * std::f64::consts::PI / 8.0;
                    let (cx, cy) = (
                        ax + (1.6 * f64::from(r) * t.cos()) as i32,
                        ay - (f64::from(r) * t.sin()) as i32,
                    );
                    (cx - w / 2, cy - h / 2)
                })
            });
            let spot = beside
                .into_iter()
                .chain(around)
                .map(|(x, y)| (x, y, x + w, y + h))
                .find(|&r| {
                    let padded = (r.0 - 2, r.1 - 2, r.2 + 2, r.3 + 2);
                    inside(r)
                        && !obstacles.iter().any(|&o| overlaps(padded, o))
                        && !placed.iter().any(|&p| overlaps(padded, p))
                });
            if let Some(r) = spot {
                placed.push(r);
            }
            spot
        })
        .collect()
}

macro_rules! draw_chart {
    ($root:expr, $chart:expr, $xr:expr, $yr:expr, $corner:expr, $legend_box:expr, $placed:expr) => {{
        let spec: &Chart = $chart;
        let mut ctx = ChartBuilder::on($root)
            .caption(&spec.title, ("sans-serif", 24))
            .margin(16)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d($xr, $yr)
            .map_err(|e| anyhow!("{e}"))?;
        // At most about 10 labels per axis and 4 light lines between them, so a log axis
        // spanning less than a decade does not label (and grid) every minor tick.
        ctx.configure_mesh()
            .x_labels(10)
            .y_labels(8)
            .max_light_lines(4)
            .x_desc(&spec.x_label)
            .y_desc(&spec.y_label)
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 17))
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        for (i, s) in spec.series.iter().enumerate() {
            let color = s.colour.map_or(PALETTE[i % PALETTE.len()], rgb);
            let pts: Vec<(f64, f64)> = s
                .points
                .iter()
                .copied()
                .filter(|(x, y)| {
                    x.is_finite()
                        && y.is_finite()
                        && (!spec.log_x || *x > 0.0)
                        && (!spec.log_y || *y > 0.0)
                })
                .collect();
            let legend_color = color;
            if let Some(band) = &s.band {
                let ok = |x: f64, y: f64| {
                    x.is_finite()
                        && y.is_finite()
                        && (!spec.log_x || x > 0.0)
                        && (!spec.log_y || y > 0.0)
                };
                let band: Vec<_> = band
                    .iter()
                    .copied()
                    .filter(|&(x, lo, hi)| ok(x, lo) && ok(x, hi))
                    .collect();
                let outline: Vec<(f64, f64)> = band
                    .iter()
                    .map(|&(x, lo, _)| (x, lo))
                    .chain(band.iter().rev().map(|&(x, _, hi)| (x, hi)))
                    .collect();
                if outline.len() >= 3 {
                    ctx.draw_series(std::iter::once(Polygon::new(
                        outline,
                        color.mix(0.25).filled(),
                    )))
                    .map_err(|e| anyhow!("{e}"))?;
                }
            }
            if let Some(errors) = &s.y_errors {
                let ok = |x: f64, y: f64| {
                    x.is_finite()
                        && y.is_finite()
                        && (!spec.log_x || x > 0.0)
                        && (!spec.log_y || y > 0.0)
                };
                let bars: Vec<((f64, f64), (f64, f64))> = s
                    .points
                    .iter()
                    .zip(errors)
                    .filter(|((x, y), e)| ok(*x, *y) && e.is_finite() && **e > 0.0)
                    .map(|(&(x, y), &e)| {
                        // On a log axis a bar reaching zero or below is cut at a tenth of y.
                        let lo = if spec.log_y && y - e <= 0.0 {
                            y / 10.0
                        } else {
                            y - e
                        };
                        ((x, lo), (x, y + e))
                    })
                    .collect();
                ctx.draw_series(
                    bars.iter()
                        .map(|&(a, b)| PathElement::new(vec![a, b], color.stroke_width(1))),
                )
                .map_err(|e| anyhow!("{e}"))?;
                // Caps: short horizontal ticks in pixels at both ends.
                ctx.draw_series(bars.iter().flat_map(|&(a, b)| {
                    [a, b].map(|p| {
                        EmptyElement::at(p)
                            + PathElement::new(vec![(-4, 0), (4, 0)], color.stroke_width(1))
                    })
                }))
                .map_err(|e| anyhow!("{e}"))?;
            }
            match s.style {
                Style::Line | Style::Thin | Style::LinePoints => {
                    let width = if s.style == Style::Thin { 1 } else { 2 };
                    ctx.draw_series(LineSeries::new(pts.clone(), color.stroke_width(width)))
                        .map_err(|e| anyhow!("{e}"))?
                        .label(&s.name)
                        .legend(move |(x, y)| {
                            PathElement::new(
                                vec![(x, y), (x + 20, y)],
                                legend_color.stroke_width(2),
                            )
                        });
                    if s.style == Style::LinePoints {
                        ctx.draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled())))
                            .map_err(|e| anyhow!("{e}"))?;
                    }
                }
                Style::Points => {
                    ctx.draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled())))
                        .map_err(|e| anyhow!("{e}"))?
                        .label(&s.name)
                        .legend(move |(x, y)| Circle::new((x + 10, y), 4, legend_color.filled()));
                }
                Style::Highlight => {
                    ctx.draw_series(
                        pts.iter()
                            .map(|&p| Circle::new(p, 9, color.stroke_width(3))),
                    )
                    .map_err(|e| anyhow!("{e}"))?
                    .label(&s.name)
                    .legend(move |(x, y)| {
                        Circle::new((x + 10, y), 6, legend_color.stroke_width(2))
                    });
                }
            }
        }
        // Point labels, placed where they overlap no other label, no marker and no legend
        // (see `place_labels`), with a leader line when away from their point.
        let (px, py) = ctx.plotting_area().get_pixel_range();
        let area: Rect = (px.start, py.start, px.end, py.end);
        let label_font = ("sans-serif", 12).into_font();
        let ok = |x: f64, y: f64| {
            x.is_finite() && y.is_finite() && (!spec.log_x || x > 0.0) && (!spec.log_y || y > 0.0)
        };
        let mut markers: Vec<Rect> = Vec::new();
        for s in spec.series.iter() {
            // A highlight's hollow circle has radius 9 and a 3-pixel stroke.
            let m = if s.style == Style::Highlight { 11 } else { 5 };
            for &(x, y) in s.points.iter().filter(|(x, y)| ok(*x, *y)) {
                let (cx, cy) = ctx.backend_coord(&(x, y));
                markers.push((cx - m, cy - m, cx + m + 1, cy + m + 1));
            }
        }
        markers.push($legend_box(area));
        let mut anchors = Vec::new();
        let mut texts = Vec::new();
        for s in spec.series.iter() {
            if let Some(labels) = &s.labels {
                for (&(x, y), l) in s.points.iter().zip(labels) {
                    if ok(x, y) && !l.is_empty() {
                        anchors.push(ctx.backend_coord(&(x, y)));
                        texts.push(l.clone());
                    }
                }
            }
        }
        let sizes: Vec<(i32, i32)> = texts
            .iter()
            .map(|t| {
                let (w, h) = label_font.box_size(t).unwrap_or((7 * t.len() as u32, 12));
                (w as i32 + 2, h as i32 + 2)
            })
            .collect();
        let placed = place_labels(&anchors, &sizes, &markers, area);
        for ((&(ax, ay), text), spot) in anchors.iter().zip(&texts).zip(&placed) {
            let Some((x0, y0, x1, y1)) = *spot else {
                continue;
            };
            // A leader line from the point to the nearest point of a label set apart.
            let (nx, ny) = (ax.clamp(x0, x1), ay.clamp(y0, y1));
            if (nx - ax).abs().max((ny - ay).abs()) > 8 {
                $root
                    .draw(&PathElement::new(
                        vec![(ax, ay), (nx, ny)],
                        RGBColor(120, 120, 120).stroke_width(1),
                    ))
                    .map_err(|e| anyhow!("{e}"))?;
            }
            $root
                .draw(&Text::new(
                    text.clone(),
                    (x0 + 1, y0 + 1),
                    label_font.clone(),
                ))
                .map_err(|e| anyhow!("{e}"))?;
        }
        $placed.extend(placed);
        ctx.configure_series_labels()
            .label_font(("sans-serif", 15))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position($corner)
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
    }};
}

/// The corner of the plot where the legend covers the least data: the share of the plot a
/// legend of this chart's entries takes is estimated from their number and length, and the
/// points (and the lines between them, sampled) that fall under it are counted in each corner.
/// Returns the corner, how many samples it still covers, and the share of the plot's height
/// the legend takes.
fn legend_corner(
    chart: &Chart,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> (SeriesLabelPosition, usize, f64) {
    let unit = |v: f64, lo: f64, hi: f64, log: bool| {
        if log {
            (v.log10() - lo.log10()) / (hi.log10() - lo.log10())
        } else {
            (v - lo) / (hi - lo)
        }
    };
    // Plot area in pixels: the chart less its margins, caption and label areas.
    let (plot_w, plot_h) = (f64::from(WIDTH) - 112.0, f64::from(HEIGHT) - 130.0);
    let longest = chart
        .series
        .iter()
        .map(|s| s.name.chars().count())
        .max()
        .unwrap_or(0);
    let w = ((longest as f64 * 8.0 + 50.0) / plot_w).min(1.0);
    let h = ((chart.series.len() as f64 * 21.0 + 12.0) / plot_h).min(1.0);
    let mut samples: Vec<(f64, f64)> = Vec::new();
    for s in &chart.series {
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .filter(|(x, y)| {
                x.is_finite()
                    && y.is_finite()
                    && (!chart.log_x || *x > 0.0)
                    && (!chart.log_y || *y > 0.0)
            })
            .map(|&(x, y)| (unit(x, x0, x1, chart.log_x), unit(y, y0, y1, chart.log_y)))
            .collect();
        samples.extend(&pts);
        if matches!(s.style, Style::Line | Style::Thin | Style::LinePoints) {
            for pair in pts.windows(2) {
                let ((ax, ay), (bx, by)) = (pair[0], pair[1]);
                samples.extend((1..8).map(|k| {
                    let t = f64::from(k) / 8.0;
                    (ax + t * (bx - ax), ay + t * (by - ay))
                }));
            }
        }
    }
    let covered = |left: bool, top: bool| {
        samples
            .iter()
            .filter(|&&(x, y)| {
                let in_x = if left { x <= w } else { x >= 1.0 - w };
                let in_y = if top { y >= 1.0 - h } else { y <= h };
                in_x && in_y
            })
            .count()
    };
    [
        (SeriesLabelPosition::UpperLeft, true, true),
        (SeriesLabelPosition::UpperRight, false, true),
        (SeriesLabelPosition::LowerRight, false, false),
        (SeriesLabelPosition::LowerLeft, true, false),
    ]
    .into_iter()
    .map(|(p, left, top)| (p, covered(left, top), h))
    .min_by_key(|&(_, c, _)| c)
    .unwrap_or((SeriesLabelPosition::UpperLeft, 0, h))
}

/// The y range with room above the data for a legend taking `h` of the height.
fn headroom((y0, y1): (f64, f64), h: f64, log: bool) -> (f64, f64) {
    let grow = 1.0 / (1.0 - h - 0.03).max(0.2);
    if log {
        let (a, b) = (y0.log10(), y1.log10());
        (y0, 10f64.powf(a + (b - a) * grow))
    } else {
        (y0, y0 + (y1 - y0) * grow)
    }
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
    crate::io::write_png_rgb(path, WIDTH, HEIGHT, &buf)
        .with_context(|| format!("writing {}", path.display()))
}

/// Where [`write_png`] puts the point labels of `chart`, in pixels (`None`: left out for want
/// of room); for checking that they never overlap.
pub fn label_boxes(chart: &Chart) -> Result<Vec<Option<Rect>>> {
    let ranges = ranges(chart, Path::new("chart"))?;
    let (corner, (x0, x1), (y0, y1)) = ranges;
    Ok(render(chart, corner, (x0, x1), (y0, y1))?.1)
}

/// The legend's box for a legend in `corner` of the plotting `area`: the size plotters gives a
/// legend of these entries, with room to spare.
fn legend_box(chart: &Chart, corner: &SeriesLabelPosition, area: Rect) -> Rect {
    let longest = chart
        .series
        .iter()
        .map(|s| s.name.chars().count())
        .max()
        .unwrap_or(0) as i32;
    let (w, h) = (longest * 9 + 60, chart.series.len() as i32 * 22 + 20);
    match corner {
        SeriesLabelPosition::UpperLeft => (area.0, area.1, area.0 + w, area.1 + h),
        SeriesLabelPosition::UpperRight => (area.2 - w, area.1, area.2, area.1 + h),
        SeriesLabelPosition::LowerLeft => (area.0, area.3 - h, area.0 + w, area.3),
        _ => (area.2 - w, area.3 - h, area.2, area.3),
    }
}

/// Draws `chart` into an RGB buffer; returns it and where the point labels went.
fn render(
    chart: &Chart,
    corner: SeriesLabelPosition,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> Result<(Vec<u8>, Vec<Option<Rect>>)> {
    register_font();
    let mut buf = vec![0u8; (WIDTH * HEIGHT * 3) as usize];
    let mut placed: Vec<Option<Rect>> = Vec::new();
    {
        let root = BitMapBackend::with_buffer(&mut buf, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let lb = |area: Rect| legend_box(chart, &corner, area);
        match (chart.log_x, chart.log_y) {
            (false, false) => draw_chart!(&root, chart, x0..x1, y0..y1, corner, lb, placed),
            (true, false) => {
                draw_chart!(
                    &root,
                    chart,
                    (x0..x1).log_scale(),
                    y0..y1,
                    corner,
                    lb,
                    placed
                )
            }
            (false, true) => {
                draw_chart!(
                    &root,
                    chart,
                    x0..x1,
                    (y0..y1).log_scale(),
                    corner,
                    lb,
                    placed
                )
            }
            (true, true) => {
                draw_chart!(
                    &root,
                    chart,
                    (x0..x1).log_scale(),
                    (y0..y1).log_scale(),
                    corner,
                    lb,
                    placed
                )
            }
        }
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    Ok((buf, placed))
}

#[cfg(test)]
mod tests {
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
