//! The charts of `cargo xtask scaling` as functions of the CSVs the experiments write: each
//! experiment writes its data and calls its chart's function on the output directory, and
//! `--replot` calls the same functions on a directory of committed results, so a change of
//! the charts' style (say, the label placement of `figures::chart::place_labels`) redraws every
//! chart without running anything.

use anyhow::Result;
use std::path::{Path, PathBuf};

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
    CsvChart {
        csv: super::family::ORDERS_CSV,
        draw: super::family::branches_chart,
    },
    CsvChart {
        csv: super::family::STICKING_CSV,
        draw: super::family::sticking_chart,
    },
    CsvChart {
        csv: super::deposit::PROFILES_CSV,
        draw: super::deposit::charts,
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
