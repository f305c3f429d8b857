//! Drawing a chart with plotters: the series in their styles, error bands and bars, the point
//! labels and the legend, into an RGB buffer.

use super::labels::{Rect, place_labels};
use super::legend::legend_box;
use super::{Chart, HEIGHT, PALETTE, Style, WIDTH, rgb};
use crate::text::{register_font, tick};
use anyhow::{Result, anyhow};
use plotters::prelude::*;

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

/// Draws `chart` into an RGB buffer; returns it and where the point labels went.
pub(super) fn render(
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
