//! Where a chart's legend goes: the corner that covers the least data, the headroom the y axis
//! gets when every corner holds data, and the box the legend takes there.

use super::labels::Rect;
use super::{Chart, HEIGHT, Style, WIDTH};
use plotters::prelude::SeriesLabelPosition;

/// The corner of the chart where the legend covers the least data: the share of the chart a
/// legend of this chart's entries takes is estimated from their number and length, and the
/// points (and the lines between them, sampled) that fall under it are counted in each corner.
/// Returns the corner, how many samples it still covers, and the share of the chart's height
/// the legend takes.
pub(super) fn legend_corner(
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
    // Drawing area in pixels: the chart less its margins, caption and label areas.
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
pub(super) fn headroom((y0, y1): (f64, f64), h: f64, log: bool) -> (f64, f64) {
    let grow = 1.0 / (1.0 - h - 0.03).max(0.2);
    if log {
        let (a, b) = (y0.log10(), y1.log10());
        (y0, 10f64.powf(a + (b - a) * grow))
    } else {
        (y0, y0 + (y1 - y0) * grow)
    }
}

/// The legend's box for a legend in `corner` of the plotting `area`: the size plotters gives a
/// legend of these entries, with room to spare.
pub(super) fn legend_box(chart: &Chart, corner: &SeriesLabelPosition, area: Rect) -> Rect {
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
