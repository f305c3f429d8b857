//! The charts of `cargo xtask scaling` as functions of the CSVs the experiments write: each
//! experiment writes its data and calls its chart's function on the output directory, and
//! `--replot` calls the same functions on a directory of committed results, so a change of
//! the charts' style (say, the label placement of `sim_run::plot::place_labels`) redraws every
//! chart without running anything.

use anyhow::{Context, Result};
use csv::StringRecord;
use std::path::{Path, PathBuf};

/// A CSV read whole, its columns looked up by name.
#[derive(Debug)]
pub struct Csv {
    path: PathBuf,
    head: StringRecord,
    /// The data rows.
    pub rows: Vec<StringRecord>,
}

impl Csv {
    /// Reads `path`.
    pub fn read(path: &Path) -> Result<Self> {
        let mut r =
            csv::Reader::from_path(path).with_context(|| format!("reading {}", path.display()))?;
        let head = r.headers()?.clone();
        let rows = r
            .records()
            .collect::<Result<Vec<_>, _>>()
            .with_context(|| format!("reading {}", path.display()))?;
        anyhow::ensure!(!rows.is_empty(), "{}: no data rows", path.display());
        Ok(Csv {
            path: path.to_path_buf(),
            head,
            rows,
        })
    }

    /// The index of column `name`.
    fn col(&self, name: &str) -> Result<usize> {
        self.head
            .iter()
            .position(|h| h == name)
            .with_context(|| format!("{}: no column {name}", self.path.display()))
    }

    /// Column `name` as text.
    pub fn text(&self, name: &str) -> Result<Vec<String>> {
        let c = self.col(name)?;
        Ok(self
            .rows
            .iter()
            .map(|r| r.get(c).unwrap_or("").to_string())
            .collect())
    }

    /// Column `name` as numbers (`NaN` included).
    pub fn num(&self, name: &str) -> Result<Vec<f64>> {
        let c = self.col(name)?;
        self.rows
            .iter()
            .map(|r| {
                let s = r.get(c).unwrap_or("");
                s.parse::<f64>().with_context(|| {
                    format!("{}: {name} {s:?} is not a number", self.path.display())
                })
            })
            .collect()
    }

    /// The rows grouped by the values of the columns `keys`, groups in the order of their
    /// first row: `(key values, row indices)`.
    pub fn groups(&self, keys: &[&str]) -> Result<Vec<(Vec<String>, Vec<usize>)>> {
        let cols: Vec<Vec<String>> = keys.iter().map(|k| self.text(k)).collect::<Result<_>>()?;
        let mut out: Vec<(Vec<String>, Vec<usize>)> = Vec::new();
        for i in 0..self.rows.len() {
            let key: Vec<String> = cols.iter().map(|c| c[i].clone()).collect();
            match out.iter_mut().find(|g| g.0 == key) {
                Some(g) => g.1.push(i),
                None => out.push((key, vec![i])),
            }
        }
        Ok(out)
    }

    /// The one value of column `name` (a summary's lattice, say), or an error if the rows
    /// disagree.
    pub fn single(&self, name: &str) -> Result<String> {
        let v = self.text(name)?;
        anyhow::ensure!(
            v.iter().all(|x| *x == v[0]),
            "{}: the rows differ in {name}",
            self.path.display()
        );
        Ok(v[0].clone())
    }
}

/// A chart drawn from CSVs in the results directory: the CSV whose presence means the chart
/// can be drawn, and the function that draws it (returning the PNGs written).
#[derive(Debug, Clone, Copy)]
pub struct CsvChart {
    /// The chart's data, in the results directory.
    pub csv: &'static str,
    /// Draws the chart (or charts) from the CSVs in the directory.
    pub draw: fn(&Path) -> Result<Vec<PathBuf>>,
}

/// Every chart of the experiments besides the accuracy sweeps' (which
/// [`super::accuracy::replot`] draws).
pub const CHARTS: &[CsvChart] = &[
    CsvChart {
        csv: "dla_fig3.csv",
        draw: super::dla::fig3_chart,
    },
    CsvChart {
        csv: "dlca_fig5_mean.csv",
        draw: super::dlca::fig5_chart,
    },
    CsvChart {
        csv: "dlca_fig6.csv",
        draw: super::dlca::fig6_chart,
    },
    CsvChart {
        csv: "dlca_histograms.csv",
        draw: super::dlca::histogram_charts,
    },
    CsvChart {
        csv: "dlca_cost.csv",
        draw: super::dlca::cost_chart,
    },
    CsvChart {
        csv: "animat_fig9.csv",
        draw: super::animat::fig9_chart,
    },
    CsvChart {
        csv: "accuracy_vpdist_ccdf.csv",
        draw: super::accuracy::vpdist_chart,
    },
];

/// What [`replot`] did: the charts written, and the charts' CSVs that were not in the
/// directory (their charts left as they are).
#[derive(Debug, Default)]
pub struct Replotted {
    /// PNGs written.
    pub written: Vec<PathBuf>,
    /// CSVs of [`CHARTS`] not found.
    pub missing: Vec<&'static str>,
}

/// Draws every chart whose CSV is in `dir` again, the accuracy sweeps' and [`CHARTS`], with
/// the functions the experiments draw them with; runs nothing.
pub fn replot(dir: &Path) -> Result<Replotted> {
    let mut out = Replotted {
        written: super::accuracy::replot(dir)?,
        ..Replotted::default()
    };
    for chart in CHARTS {
        if dir.join(chart.csv).exists() {
            out.written.extend((chart.draw)(dir)?);
        } else {
            out.missing.push(chart.csv);
        }
    }
    Ok(out)
}
