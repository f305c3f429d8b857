//! Accuracy against speed for 2D DLA: a sweep of `--precision`, `--step-min` and the far-field
//! mode, measuring microseconds per particle against the error of the fractal dimension and of
//! the R_g prefactor (both against the most exact setting), the Pareto front, and the
//! distribution of `vpdist` errors against the exact nearest distance.

use super::Ctx;
use super::dla::fit_from;
use super::ensemble::columns;
use crate::plot::{self, Chart, Series, Style};
use crate::report::{Doc, Table, mean_stderr, pm, sig};
use anyhow::Result;
use core_lattice::rng::{stream, uniform01};
use dla_pdla::{FarField, Params, Simulation};

/// One point of the sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setting {
    /// `--precision`.
    pub precision: f64,
    /// `--step-min`.
    pub step_min: f64,
    /// `--far-field`.
    pub far_field: FarField,
    /// `--distance-map`.
    pub distance_map: bool,
}

impl Setting {
    /// `k2 s0.5 ret`: a point label for the plots.
    fn short(&self) -> String {
        let k = if self.precision.is_finite() {
            format!("{}", self.precision)
        } else {
            "inf".into()
        };
        let ff = match self.far_field {
            FarField::Return => "",
            FarField::Jump => " jump",
        };
        let map = if self.distance_map { "" } else { " no map" };
        format!("k{k} s{}{ff}{map}", self.step_min)
    }

    fn label(&self) -> String {
        let k = if self.precision.is_finite() {
            format!("{}", self.precision)
        } else {
            "inf".into()
        };
        format!(
            "precision {k}, step {}, {}{}",
            self.step_min,
            self.far_field.name(),
            if self.distance_map {
                ""
            } else {
                ", distance map off"
            }
        )
    }
}

/// The settings swept; the first is the reference (most exact).
pub fn settings() -> Vec<Setting> {
    let s = |precision, step_min, far_field| Setting {
        precision,
        step_min,
        far_field,
        distance_map: true,
    };
    let (ret, jump) = (FarField::Return, FarField::Jump);
    vec![
        s(f64::INFINITY, 0.05, ret),
        s(f64::INFINITY, 0.1, ret),
        s(1.0, 0.5, ret),
        s(2.0, 0.5, ret),
        s(4.0, 0.5, ret),
        s(8.0, 0.5, ret),
        s(f64::INFINITY, 0.5, ret),
        s(2.0, 1.0, ret),
        s(2.0, 0.25, ret),
        s(2.0, 0.1, ret),
        s(1.0, 1.0, ret),
        s(2.0, 0.5, jump),
        Setting {
            distance_map: false,
            ..s(2.0, 0.5, ret)
        },
    ]
}

fn is_default(s: &Setting) -> bool {
    let d = Params::default();
    s.precision == d.precision
        && s.step_min == d.step_min
        && s.far_field == d.far_field
        && s.distance_map == d.distance_map
}

/// Per setting: time and the two accuracy measures, from an ensemble of runs.
struct Measured {
    setting: Setting,
    us_per_particle: (f64, f64),
    d: Vec<f64>,
    /// `ln R_g - ln N / D_ref` averaged over the fitted samples, per run.
    ln_prefactor: Vec<f64>,
}

/// What the sweep takes from one member of a setting's ensemble.
struct Run {
    /// Wall microseconds of the run per particle.
    us_per_particle: f64,
    /// Its fitted fractal dimension.
    fractal_dimension: f64,
    /// Its growth samples: N and R_g (`growth.csv`).
    n: Vec<f64>,
    radius_of_gyration: Vec<f64>,
}

/// Mean of `ln R_g - ln N / d_ref` over the samples used in the fit.
fn ln_prefactor(g: &Run, from: u64, d_ref: f64) -> f64 {
    let v: Vec<f64> =
        g.n.iter()
            .zip(&g.radius_of_gyration)
            .filter(|(n, _)| **n >= from as f64)
            .map(|(n, rg)| rg.ln() - n.ln() / d_ref)
            .collect();
    v.iter().sum::<f64>() / v.len() as f64
}

/// Run the sweep and write `accuracy.md`.
pub fn run(ctx: &Ctx) -> Result<()> {
    let n = ctx.scale.pick(1_500, 10_000, 100_000);
    let e = ctx.scale.pick(2u64, 4, 8);
    let from = fit_from(n);
    let mut doc = ctx.doc("Accuracy against speed: 2D DLA");
    doc.p(&format!(
        "Every setting grows {e} clusters of N = {n} particles in 2D (seeds {}..{}), the same \
         seeds for every setting. The reference is the most exact setting: exact nearest-\
         distance search (`--precision inf`), the shortest near-field step (`--step-min 0.05`) \
         and the exact far-field return. Each setting is one ensemble of the `dla` binary \
         (`dla --seeds ...`), its members two at a time, one per core, so every setting is \
         timed under the same load; the time is the member's wall time per particle.",
        ctx.seed,
        ctx.seed + e - 1
    ));
    let settings = settings();
    ctx.log(&format!(
        "{} settings x {e} runs of N = {n}",
        settings.len()
    ));
    // One ensemble of the `dla` binary per setting (members two at a time, one per core); the
    // seeds are the same for every setting.
    let mut per: Vec<Vec<Run>> = Vec::new();
    for (i, st) in settings.iter().enumerate() {
        let ens = ctx.ensemble(
            "dla",
            &format!("accuracy/setting-{i:02}"),
            e,
            &[
                format!("--particles={n}"),
                format!("--precision={}", st.precision),
                format!("--step-min={}", st.step_min),
                format!("--far-field={}", st.far_field.name()),
                format!(
                    "--distance-map={}",
                    if st.distance_map { "on" } else { "off" }
                ),
                format!("--fit-from={from}"),
            ],
        )?;
        let mut runs = Vec::new();
        for m in &ens.members {
            let growth = columns(
                &ens.member_dir(m).join("growth.csv"),
                &["n", "radius_of_gyration"],
            )?;
            let get = |k: &str| m.results.get(k).copied().unwrap_or(f64::NAN);
            runs.push(Run {
                us_per_particle: get("wall_seconds") / get("particles") * 1e6,
                fractal_dimension: get("fractal_dimension"),
                n: growth[0].clone(),
                radius_of_gyration: growth[1].clone(),
            });
        }
        per.push(runs);
    }
    let d_ref = mean_stderr(
        &per[0]
            .iter()
            .map(|g| g.fractal_dimension)
            .collect::<Vec<_>>(),
    )
    .0;
    let measured: Vec<Measured> = settings
        .iter()
        .zip(&per)
        .map(|(s, gs)| Measured {
            setting: *s,
            us_per_particle: mean_stderr(&gs.iter().map(|g| g.us_per_particle).collect::<Vec<_>>()),
            d: gs.iter().map(|g| g.fractal_dimension).collect(),
            ln_prefactor: gs.iter().map(|g| ln_prefactor(g, from, d_ref)).collect(),
        })
        .collect();
    let (_, d_ref_se) = mean_stderr(&measured[0].d);
    let (a_ref, a_ref_se) = mean_stderr(&measured[0].ln_prefactor);

    let mut table = Table::new(&[
        "setting",
        "microseconds per particle",
        "D",
        "D - D_ref",
        "R_g prefactor relative error",
        "Pareto front for D",
        "Pareto front for the prefactor",
        "note",
    ]);
    let mut points = Vec::new();
    for m in &measured {
        let (dm, dse) = mean_stderr(&m.d);
        let (am, ase) = mean_stderr(&m.ln_prefactor);
        let dd = dm - d_ref;
        let dd_se = (dse * dse + d_ref_se * d_ref_se).sqrt();
        // ln A - ln A_ref is the relative error of A to first order.
        let da = am - a_ref;
        let da_se = (ase * ase + a_ref_se * a_ref_se).sqrt();
        points.push((
            m.us_per_particle.0,
            dd.abs(),
            da.abs(),
            dd,
            dd_se,
            da,
            da_se,
        ));
    }
    let front = pareto(&points.iter().map(|p| (p.0, p.1)).collect::<Vec<_>>());
    let front_a = pareto(&points.iter().map(|p| (p.0, p.2)).collect::<Vec<_>>());
    let mut data = Table::new(&[
        "precision",
        "step_min",
        "far_field",
        "distance_map",
        "us_per_particle",
        "us_per_particle_se",
        "d",
        "d_se",
        "d_minus_ref",
        "d_minus_ref_se",
        "prefactor_rel_err",
        "prefactor_rel_err_se",
        "pareto_d",
        "pareto_prefactor",
        "default",
    ]);
    for (i, (m, p)) in measured.iter().zip(&points).enumerate() {
        let (dm, dse) = mean_stderr(&m.d);
        let paper = m.setting.precision == 2.0
            && m.setting.step_min == 0.5
            && m.setting.far_field == FarField::Return
            && m.setting.distance_map;
        let note = match (i, is_default(&m.setting), paper) {
            (0, _, _) => "reference (most exact)",
            (_, true, _) => "default",
            (_, _, true) => "the paper's near-field step (the default before it was measured)",
            _ => "",
        };
        table.row(vec![
            m.setting.label(),
            pm(m.us_per_particle.0, m.us_per_particle.1),
            pm(dm, dse),
            if i == 0 { "0".into() } else { pm(p.3, p.4) },
            if i == 0 { "0".into() } else { pm(p.5, p.6) },
            if front.contains(&i) { "yes" } else { "" }.into(),
            if front_a.contains(&i) { "yes" } else { "" }.into(),
            note.into(),
        ]);
        data.row(vec![
            m.setting.precision.to_string(),
            m.setting.step_min.to_string(),
            m.setting.far_field.name().into(),
            m.setting.distance_map.to_string(),
            m.us_per_particle.0.to_string(),
            m.us_per_particle.1.to_string(),
            dm.to_string(),
            dse.to_string(),
            p.3.to_string(),
            p.4.to_string(),
            p.5.to_string(),
            p.6.to_string(),
            front.contains(&i).to_string(),
            front_a.contains(&i).to_string(),
            is_default(&m.setting).to_string(),
        ]);
    }
    doc.h2("Run time against error");
    doc.table(&table);
    data.write_csv(&ctx.path("accuracy.csv"))?;
    doc.p(&format!(
        "D is fitted per cluster over N >= {from}; D - D_ref and the prefactor error are \
         differences of ensemble means, ± the combined standard error, so a difference smaller \
         than about twice its error is not significant at this ensemble size. The R_g \
         prefactor is A in R_g = A N^(1/D_ref), taken per cluster as the mean of \
         ln R_g - ln N / D_ref over the fitted samples with the reference's D, so it measures \
         the clusters' size at fixed N without the noise of a free intercept; its relative \
         error is ln A - ln A_ref. The Pareto front is over (microseconds per particle, |D - \
         D_ref|) and over (microseconds per particle, |prefactor error|): no other setting is both \
         faster and closer. Data: \
         [`accuracy.csv`](accuracy.csv)."
    ));
    let default = measured.iter().position(|m| is_default(&m.setting));
    let short: Vec<String> = measured.iter().map(|m| m.setting.short()).collect();
    pareto_chart(
        ctx,
        &format!("2D DLA, N = {n}: cost against error of D"),
        "|D - D_ref|",
        &points.iter().map(|p| (p.0, p.1)).collect::<Vec<_>>(),
        // The reference's own error is zero by definition.
        &points
            .iter()
            .enumerate()
            .map(|(i, p)| if i == 0 { 0.0 } else { p.4 })
            .collect::<Vec<_>>(),
        &short,
        default,
        "accuracy_pareto.png",
    )?;
    pareto_chart(
        ctx,
        &format!("2D DLA, N = {n}: cost against error of the R_g prefactor"),
        "|relative error of the R_g prefactor|",
        &points.iter().map(|p| (p.0, p.2)).collect::<Vec<_>>(),
        // The reference's own error is zero by definition.
        &points
            .iter()
            .enumerate()
            .map(|(i, p)| if i == 0 { 0.0 } else { p.6 })
            .collect::<Vec<_>>(),
        &short,
        default,
        "accuracy_pareto_prefactor.png",
    )?;
    doc.image("Pareto front for D", "accuracy_pareto.png");
    doc.image(
        "Pareto front for the R_g prefactor",
        "accuracy_pareto_prefactor.png",
    );
    vpdist_errors(ctx, &mut doc, n)?;
    doc.write(&ctx.path("accuracy.md"))
}

/// Cost against error for every setting, the Pareto front as a line, the default and the
/// reference marked (the reference's zero error is drawn at 1e-4 on the log axis).
#[allow(clippy::too_many_arguments)]
fn pareto_chart(
    ctx: &Ctx,
    title: &str,
    y_label: &str,
    pts: &[(f64, f64)],
    errors: &[f64],
    labels: &[String],
    default: Option<usize>,
    file: &str,
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
    if let Some(i) = default {
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
        "reference (error 0, drawn at 1e-4)",
        vec![at(0)],
        Style::Highlight,
    ));
    plot::write_png(
        &Chart {
            title: title.into(),
            x_label: "microseconds per particle".into(),
            y_label: y_label.into(),
            log_x: false,
            log_y: true,
            series,
        },
        &ctx.path(file),
    )
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

/// The distribution of `(d - vpdist) / d` over query points around a grown cluster.
fn vpdist_errors(ctx: &Ctx, doc: &mut Doc, n: u64) -> Result<()> {
    let queries = ctx.scale.pick(2_000u64, 50_000, 200_000);
    let mut sim = Simulation::<2>::new(
        Params {
            particles: n,
            ..Params::default()
        },
        ctx.seed,
    )?;
    sim.run()?;
    let tree = sim.tree();
    let r_b = sim.r_ext() + sim.params().birth_gap;
    let mut rng = stream(ctx.seed, 0x7664_6973_7465_7272); // "vpdisterr"
    // Query points uniform in the birth disc, outside contact distance of the cluster: where
    // walkers ask for vpdist.
    let mut pts = Vec::new();
    while (pts.len() as u64) < queries {
        let r = r_b * uniform01(&mut rng).sqrt();
        let a = std::f64::consts::TAU * uniform01(&mut rng);
        let p = [r * a.cos(), r * a.sin()];
        let d = tree.nearest_distance(&p).expect("non-empty cluster");
        if d > 1.0 {
            pts.push((p, d));
        }
    }
    let edges = [0.0, 1e-6, 1e-3, 0.01, 0.05, 0.1, 0.2, 0.3, 0.5, 1.0];
    let mut table = Table::new(&[
        "precision kappa",
        "queries",
        "exact answers",
        "mean relative error",
        "99th percentile",
        "max",
        "bound 2/(2 kappa + 1)",
    ]);
    let mut hist = Table::new(&["kappa", "bin_low", "bin_high", "fraction"]);
    let mut series = Vec::new();
    for kappa in [1.0, 2.0, 4.0, 8.0] {
        let mut errs: Vec<f64> = pts
            .iter()
            .map(|(p, d)| {
                let v = tree.vpdist(p, kappa).expect("non-empty cluster");
                ((d - v) / d).max(0.0)
            })
            .collect();
        errs.sort_by(f64::total_cmp);
        let exact = errs.iter().filter(|&&e| e <= 1e-12).count();
        let mean = errs.iter().sum::<f64>() / errs.len() as f64;
        let p99 = errs[(errs.len() * 99 / 100).min(errs.len() - 1)];
        table.row(vec![
            sig(kappa, 2),
            errs.len().to_string(),
            format!("{:.1}%", 100.0 * exact as f64 / errs.len() as f64),
            sig(mean, 3),
            sig(p99, 3),
            sig(*errs.last().expect("non-empty"), 3),
            sig(2.0 / (2.0 * kappa + 1.0), 3),
        ]);
        let mut pts_cdf = Vec::new();
        for w in edges.windows(2) {
            let c = errs.iter().filter(|&&e| e > w[0] && e <= w[1]).count();
            let frac = c as f64 / errs.len() as f64;
            hist.row(vec![
                kappa.to_string(),
                w[0].to_string(),
                w[1].to_string(),
                frac.to_string(),
            ]);
        }
        // The complementary CDF at log-spaced error levels, for the plot.
        for k in 0..=40 {
            let level = 10f64.powf(-4.0 + 4.0 * k as f64 / 40.0);
            let above = errs.len() - errs.partition_point(|&e| e <= level);
            pts_cdf.push((level, above as f64 / errs.len() as f64));
        }
        series.push(Series::new(
            format!("kappa = {kappa}"),
            pts_cdf,
            Style::Line,
        ));
    }
    doc.h2("Distribution of vpdist errors");
    doc.p(&format!(
        "{queries} query points uniform in the birth disc of a {n}-particle cluster, keeping \
         those farther than one diameter from every particle (where walkers query). The \
         relative error is (d - vpdist) / d with d the exact nearest distance; vpdist never \
         overestimates. Listing 1 of Sosa-Herrera & Rodriguez-Romo returns a node-centre estimate when the node is \
         far enough; our bound is the proven one (`docs/spatial.md`)."
    ));
    ctx.table(doc, &table, "accuracy_vpdist.csv")?;
    hist.write_csv(&ctx.path("accuracy_vpdist_hist.csv"))?;
    plot::write_png(
        &Chart {
            title: "vpdist: fraction of queries with relative error above a level".into(),
            x_label: "relative error (d - vpdist) / d".into(),
            y_label: "fraction of queries above".into(),
            log_x: true,
            log_y: false,
            series,
        },
        &ctx.path("accuracy_vpdist.png"),
    )?;
    doc.image("vpdist error distribution", "accuracy_vpdist.png");
    doc.p("Binned distribution: [`accuracy_vpdist_hist.csv`](accuracy_vpdist_hist.csv).");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pareto_front() {
        let pts = [(1.0, 0.5), (2.0, 0.1), (3.0, 0.2), (0.5, 0.9), (4.0, 0.0)];
        assert_eq!(pareto(&pts), vec![0, 1, 3, 4]);
    }

    #[test]
    fn reference_is_first_and_default_is_swept() {
        let s = settings();
        assert!(s[0].precision.is_infinite());
        assert!(s.iter().any(is_default));
    }
}
