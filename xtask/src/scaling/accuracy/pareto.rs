//! The Pareto fronts of a sweep: which settings no other beats in both cost and error, their
//! charts, and the charts drawn again from a sweep's CSV.

use super::Setting;
use anyhow::{Context, Result};
use dla_pdla::{FarField, Params};
use figures::chart::{self, Chart, Series, Style};
use std::path::{Path, PathBuf};

/// The first columns of a sweep's `<stem>.csv` (the run's size, the setting and its cost), as
/// [`Sweep::run`](super::Sweep::run) writes them and [`replot`] reads them back.
pub(super) const CSV_LEAD: [&str; 8] = [
    "dim",
    "particles",
    "precision",
    "step_min",
    "far_field",
    "death_ratio",
    "distance_map",
    "us_per_particle",
];

/// Cost against error for every setting, the Pareto front as a line, the default and the
/// reference marked (a zero error is drawn at 1e-4 on the log axis).
#[allow(clippy::too_many_arguments)]
pub(super) fn pareto_chart(
    path: &Path,
    title: &str,
    y_label: &str,
    pts: &[(f64, f64)],
    errors: &[f64],
    labels: &[String],
    default: Option<usize>,
) -> Result<()> {
    const FLOOR: f64 = 1e-4;
    let at = |i: usize| (pts[i].0, pts[i].1.max(FLOOR));
    let mut fp: Vec<(f64, f64)> = pareto(pts).into_iter().map(at).collect();
    fp.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut series = vec![
        Series::new(
            "settings (± standard error)",
            (0..pts.len()).map(at).collect(),
            Style::Points,
        )
        .with_labels(labels.to_vec())
        .with_y_errors(errors.to_vec()),
        Series::new("Pareto front", fp, Style::Line),
    ];
    if let Some(i) = default.filter(|&i| i != 0) {
        let d = Params::default();
        series.push(Series::new(
            format!(
                "default (precision {}, step {}, return)",
                d.precision, d.step_min
            ),
            vec![at(i)],
            Style::Highlight,
        ));
    }
    series.push(Series::new(
        if default == Some(0) {
            "reference = default (error 0, drawn at 1e-4)"
        } else {
            "reference (error 0, drawn at 1e-4)"
        },
        vec![at(0)],
        Style::Highlight,
    ));
    chart::write_png(
        &Chart {
            title: title.into(),
            x_label: "microseconds per particle".into(),
            y_label: y_label.into(),
            log_x: false,
            log_y: true,
            series,
        },
        path,
    )?;
    Ok(())
}

/// The accuracy sweeps' stems and the titles of their charts (`{dim}` and `{n}` filled in from
/// the CSV), as [`super::run`] names them.
const REPLOTTED: [(&str, &str); 3] = [
    ("accuracy", "{dim}D DLA, N = {n}"),
    ("accuracy_farfield", "{dim}D DLA far field, N = {n}"),
    ("accuracy_3d", "{dim}D DLA, N = {n}"),
];

/// Draws the Pareto charts of every accuracy sweep again from its CSV in `dir` (as written by
/// [`Sweep::run`](super::Sweep::run)), without running anything: for a change of the charts'
/// style. Returns the charts written.
pub fn replot(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    for (stem, title) in REPLOTTED {
        let csv_path = dir.join(format!("{stem}.csv"));
        if !csv_path.exists() {
            continue;
        }
        let mut r = csv::Reader::from_path(&csv_path)
            .with_context(|| format!("reading {}", csv_path.display()))?;
        let head = r.headers()?.clone();
        let col = |name: &str| {
            head.iter()
                .position(|h| h == name)
                .with_context(|| format!("{}: no column {name}", csv_path.display()))
        };
        let cols = CSV_LEAD
            .into_iter()
            .chain([
                "d_minus_ref",
                "d_minus_ref_se",
                "prefactor_rel_err",
                "prefactor_rel_err_se",
                "default",
            ])
            .map(col)
            .collect::<Result<Vec<usize>>>()?;
        let mut rows = Vec::new();
        for rec in r.records() {
            let rec = rec?;
            let mut f = [""; 13];
            for (k, &c) in cols.iter().enumerate() {
                f[k] = rec.get(c).unwrap_or("");
            }
            let num = |s: &str| -> Result<f64> {
                s.parse::<f64>()
                    .with_context(|| format!("{}: {s:?} is not a number", csv_path.display()))
            };
            let setting = Setting {
                precision: num(f[2])?,
                step_min: num(f[3])?,
                far_field: if f[4] == "jump" {
                    FarField::Jump
                } else {
                    FarField::Return
                },
                death_ratio: num(f[5])?,
                distance_map: f[6] == "true",
            };
            rows.push((
                f[0].to_string(),
                f[1].to_string(),
                setting.short(),
                num(f[7])?,
                [num(f[8])?, num(f[9])?, num(f[10])?, num(f[11])?],
                f[12] == "true",
            ));
        }
        let Some(first) = rows.first() else {
            continue;
        };
        let title = title.replace("{dim}", &first.0).replace("{n}", &first.1);
        let short: Vec<String> = rows.iter().map(|r| r.2.clone()).collect();
        let default = rows.iter().position(|r| r.5);
        for (what, y_label, value, se, file) in [
            ("D", "|D - D_ref|", 0, 1, format!("{stem}_pareto.png")),
            (
                "the R_g prefactor",
                "|relative error of the R_g prefactor|",
                2,
                3,
                format!("{stem}_pareto_prefactor.png"),
            ),
        ] {
            let pts: Vec<(f64, f64)> = rows.iter().map(|r| (r.3, r.4[value].abs())).collect();
            // The reference's own error is zero by definition.
            let errors: Vec<f64> = rows
                .iter()
                .enumerate()
                .map(|(i, r)| if i == 0 { 0.0 } else { r.4[se] })
                .collect();
            let path = dir.join(&file);
            pareto_chart(
                &path,
                &format!("{title}: cost against error of {what}"),
                y_label,
                &pts,
                &errors,
                &short,
                default,
            )?;
            written.push(path);
        }
    }
    Ok(written)
}

/// Indices of the points not dominated in (cost, error): sorted by cost, keep each point whose
/// error is below every cheaper point's.
pub fn pareto(points: &[(f64, f64)]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..points.len()).collect();
    idx.sort_by(|&a, &b| {
        points[a]
            .0
            .total_cmp(&points[b].0)
            .then(points[a].1.total_cmp(&points[b].1))
    });
    let mut best = f64::INFINITY;
    let mut front = Vec::new();
    for i in idx {
        if points[i].1 < best {
            best = points[i].1;
            front.push(i);
        }
    }
    front.sort_unstable();
    front
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pareto_front() {
        let pts = [(1.0, 0.5), (2.0, 0.1), (3.0, 0.2), (0.5, 0.9), (4.0, 0.0)];
        assert_eq!(pareto(&pts), vec![0, 1, 3, 4]);
    }
}
