//! The scaling harness at a tiny size: every report, CSV and chart is produced and well formed,
//! the papers' values appear beside ours, and the fit code recovers known slopes.

use core_lattice::Fit;
use core_lattice::rng::{stream, uniform01};
use std::path::{Path, PathBuf};
use xtask::scaling::replot::{CHARTS, replot};
use xtask::scaling::{Experiment, Options, Scale, run};

fn read(dir: &Path, file: &str) -> String {
    std::fs::read_to_string(dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"))
}

/// Fields of one CSV line, honouring RFC 4180 quotes.
fn fields(line: &str) -> usize {
    let (mut n, mut quoted) = (1, false);
    for c in line.chars() {
        match c {
            '"' => quoted = !quoted,
            ',' if !quoted => n += 1,
            _ => {}
        }
    }
    n
}

/// Every CSV: a header and at least one row, every row as wide as the header, no NaN cell.
fn check_csv(dir: &Path, file: &str) {
    let text = read(dir, file);
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_else(|| panic!("{file} is empty"));
    let width = fields(header);
    let rows: Vec<&str> = lines.collect();
    assert!(!rows.is_empty(), "{file} has no rows");
    for r in &rows {
        assert_eq!(fields(r), width, "{file}: row {r:?}");
        assert!(!r.contains("NaN"), "{file}: NaN in {r:?}");
    }
}

fn check_png(dir: &Path, file: &str) {
    let bytes = std::fs::read(dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{file} is not a PNG");
    // Width and height from the IHDR chunk.
    let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    assert_eq!((w, h), (960, 640), "{file}");
    assert!(
        bytes.len() > 10_000,
        "{file} looks blank ({} bytes)",
        bytes.len()
    );
}

#[test]
fn tiny_run_produces_every_table_csv_and_plot() {
    let dir = tempfile::tempdir().unwrap();
    let runs = tempfile::tempdir().unwrap();
    let times = run(&Options {
        scale: Scale::Tiny,
        only: Vec::new(),
        out: dir.path().to_path_buf(),
        seed: 1,
        command: "cargo xtask scaling --scale tiny".into(),
        bin_dir: xtask::model_binaries_for_tests(),
        runs: runs.path().to_path_buf(),
    })
    .unwrap();
    assert_eq!(times.len(), Experiment::ALL.len());
    let d = dir.path();

    for md in [
        "index.md",
        "dlca.md",
        "animat.md",
        "dla.md",
        "accuracy.md",
        "family.md",
    ] {
        let text = read(d, md);
        assert!(
            text.contains("cargo xtask scaling --scale tiny"),
            "{md} lacks its command"
        );
    }
    for csv in [
        "dlca_fig5.csv",
        "dlca_fig5_mean.csv",
        "dlca_fig5_summary.csv",
        "dlca_fig6.csv",
        "dlca_fig6_summary.csv",
        "dlca_histograms.csv",
        "dlca_histograms_summary.csv",
        "dlca_cost.csv",
        "dlca_cost_summary.csv",
        "animat_fig9.csv",
        "animat_table1.csv",
        "animat_throughput.csv",
        "dla_fig3.csv",
        "dla_fig3_summary.csv",
        "dla_table2.csv",
        "dla_table2_runs.csv",
        "dla_speedup.csv",
        "dla_by_dimension.csv",
        "dlca_by_dimension.csv",
        "accuracy.csv",
        "accuracy_vpdist.csv",
        "accuracy_vpdist_hist.csv",
        "accuracy_vpdist_ccdf.csv",
        "family_branches.csv",
        "family_branches_orders.csv",
        "family_sticking.csv",
        "family_sticking_summary.csv",
    ] {
        check_csv(d, csv);
    }
    for png in [
        "dlca_fig5.png",
        "dlca_fig6.png",
        "dlca_histogram_1pct.png",
        "dlca_histogram_5pct.png",
        "dlca_cost.png",
        "animat_fig9.png",
        "dla_fig3.png",
        "accuracy_pareto.png",
        "accuracy_pareto_prefactor.png",
        "accuracy_vpdist.png",
        "family_branches.png",
        "family_sticking.png",
    ] {
        check_png(d, png);
    }

    // The papers' values sit beside ours, labelled.
    let animat = read(d, "animat.md");
    assert!(
        animat.contains("1.354 ± 0.058"),
        "Table I's 60-cell gradient"
    );
    assert!(
        animat.contains("1.964 ± 0.011"),
        "Table I's no-grid gradient"
    );
    let dlca = read(d, "dlca.md");
    assert!(
        dlca.contains("about 30"),
        "the grid-boxing paper's grid speed-up"
    );
    let dla = read(d, "dla.md");
    assert!(
        dla.contains("3e-5 N - 6.9"),
        "the variable-precision paper's Fig. 3 fit"
    );
    assert!(
        dla.contains("97.5%"),
        "the variable-precision paper's parallel fraction"
    );
    let acc = read(d, "accuracy.md");
    assert!(acc.contains("reference (most exact)") && acc.contains("| default |"));

    // Strategies gave identical trajectories (the harness refuses otherwise) and the table
    // says so; every strategy row of Fig. 6 is present (four strategies, two fills).
    let fig6 = read(d, "dlca_fig6_summary.csv");
    assert_eq!(fig6.lines().filter(|l| l.contains(",yes,")).count(), 8);
    // Table 2 has the four (d, P) rows; D_f by dimension one row per dimension, 2D to 5D,
    // beside the literature's values.
    assert_eq!(read(d, "dla_table2.csv").lines().count(), 5);
    let by_dim = read(d, "dla_by_dimension.csv");
    let dims: Vec<&str> = by_dim
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap())
        .collect();
    assert_eq!(dims, ["2", "3", "4", "5"], "{by_dim}");
    assert!(
        dla.contains("3.40 (Tolman & Meakin 1989)") && dla.contains("4.33 (Tolman & Meakin 1989)")
    );
    // DLCA's D_f by dimension likewise, 2D to 5D, with the literature's values.
    let dlca_dims = read(d, "dlca_by_dimension.csv");
    let dims: Vec<&str> = dlca_dims
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap())
        .collect();
    assert_eq!(dims, ["2", "3", "4", "5"], "{dlca_dims}");
    assert!(dlca_dims.contains("2.25-2.30 ± 0.2"), "{dlca_dims}");

    // --replot draws every chart from the CSVs with the run's own functions: each PNG again,
    // byte for byte, and none left out.
    let before: Vec<(String, Vec<u8>)> = pngs(d)
        .into_iter()
        .map(|p| (p.clone(), std::fs::read(d.join(&p)).unwrap()))
        .collect();
    for (p, _) in &before {
        std::fs::remove_file(d.join(p)).unwrap();
    }
    let done = replot(d).unwrap();
    assert!(done.missing.is_empty(), "{:?}", done.missing);
    assert_eq!(done.written.len(), before.len());
    for (p, bytes) in &before {
        let again = std::fs::read(d.join(p)).unwrap_or_else(|e| panic!("{p} not replotted: {e}"));
        assert!(again == *bytes, "{p} replotted differently");
    }
}

/// The PNG files in `dir`, sorted.
fn pngs(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".png"))
        .collect();
    v.sort();
    v
}

/// `cargo xtask scaling --replot` on the committed results (their CSVs copied into a temporary
/// directory): every chart whose CSV is committed is drawn, a well-formed PNG, and every chart
/// committed in docs/results is one of them unless its CSV is missing there.
#[test]
fn the_committed_results_replot() {
    let results = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/results");
    let dir = tempfile::tempdir().unwrap();
    for e in std::fs::read_dir(&results).unwrap() {
        let e = e.unwrap();
        if e.file_name().to_string_lossy().ends_with(".csv") {
            std::fs::copy(e.path(), dir.path().join(e.file_name())).unwrap();
        }
    }
    let done = replot(dir.path()).unwrap();
    for chart in CHARTS {
        assert_eq!(
            results.join(chart.csv).exists(),
            !done.missing.contains(&chart.csv),
            "{}",
            chart.csv
        );
    }
    let drawn = pngs(dir.path());
    assert_eq!(drawn.len(), done.written.len());
    for png in &drawn {
        check_png(dir.path(), png);
    }
    // Committed charts not drawn are those whose CSV is not committed (drawn before their
    // CSV existed).
    let not_drawn: Vec<String> = pngs(&results)
        .into_iter()
        .filter(|p| !drawn.contains(p))
        .collect();
    assert!(
        not_drawn
            .iter()
            .all(|p| ["dlca_fig5.png", "accuracy_vpdist.png"].contains(&p.as_str())),
        "{not_drawn:?}"
    );
    assert!(drawn.contains(&"dla_fig3.png".to_string()));
    assert!(drawn.contains(&"dlca_histogram_5pct.png".to_string()));
}

#[test]
fn only_runs_the_chosen_experiment() {
    let dir = tempfile::tempdir().unwrap();
    let times = run(&Options {
        scale: Scale::Tiny,
        only: vec![Experiment::Animat],
        out: dir.path().to_path_buf(),
        seed: 3,
        command: "test".into(),
        // Animats run no ensemble: no binaries are needed.
        bin_dir: PathBuf::from("/nonexistent"),
        runs: dir.path().join("runs"),
    })
    .unwrap();
    assert_eq!(times.len(), 1);
    assert!(dir.path().join("animat.md").exists());
    assert!(!dir.path().join("dlca.md").exists());
}

/// The fit code behind every gradient in the reports recovers known slopes: exactly from exact
/// power laws, and within its own standard error (3 sigma) from noisy ones, where the reported
/// error must also match the scatter it was given.
#[test]
fn fits_recover_known_slopes() {
    // The grid-boxing paper, Table I style: cost = 2.5e-7 N^1.35.
    let n: Vec<f64> = (0..12).map(|i| 1000.0 * 2f64.powi(i)).collect();
    let exact: Vec<f64> = n.iter().map(|x| 2.5e-7 * x.powf(1.35)).collect();
    let f = Fit::log_log(&n, &exact).unwrap();
    assert!((f.slope - 1.35).abs() < 1e-12);
    assert!((f.prefactor() / 2.5e-7 - 1.0).abs() < 1e-9);

    // With 5% multiplicative noise, over many synthetic data sets: the slope is unbiased and
    // its standard error matches the spread of the fitted slopes.
    let mut rng = stream(99, 1);
    let mut slopes = Vec::new();
    let mut errs = Vec::new();
    for _ in 0..400 {
        let y: Vec<f64> = exact
            .iter()
            .map(|v| {
                // A normal deviate from Box-Muller.
                let (u1, u2) = (uniform01(&mut rng).max(1e-300), uniform01(&mut rng));
                let g = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
                v * (0.05 * g).exp()
            })
            .collect();
        let f = Fit::log_log(&n, &y).unwrap();
        slopes.push(f.slope);
        errs.push(f.slope_stderr);
    }
    let mean = slopes.iter().sum::<f64>() / slopes.len() as f64;
    let sd =
        (slopes.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (slopes.len() - 1) as f64).sqrt();
    let mean_err = errs.iter().sum::<f64>() / errs.len() as f64;
    assert!(
        (mean - 1.35).abs() < 3.0 * sd / (slopes.len() as f64).sqrt(),
        "biased: {mean}"
    );
    assert!(
        (mean_err / sd - 1.0).abs() < 0.15,
        "stderr {mean_err} vs spread {sd}"
    );

    // The variable-precision paper, Fig. 3 style: T = 3e-5 N - 6.9.
    let t: Vec<f64> = n.iter().map(|x| 3e-5 * x - 6.9).collect();
    let f = Fit::linear(&n, &t).unwrap();
    assert!((f.slope - 3e-5).abs() < 1e-15 && (f.intercept + 6.9).abs() < 1e-9);
}
