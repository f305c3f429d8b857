//! One sweep of DLA settings: an ensemble of the `dla` binary per setting (the same seeds for
//! every setting), microseconds per particle against the error of the fractal dimension and of
//! the R_g prefactor (both against the sweep's first setting, its reference), the Pareto
//! fronts, and where the defaults sit on them.

use super::Setting;
use super::pareto::{CSV_LEAD, pareto, pareto_chart};
use crate::report::{Doc, Table, mean_stderr, pm, sig};
use crate::scaling::Ctx;
use crate::scaling::dla::fit_from;
use crate::scaling::ensemble::columns;
use anyhow::Result;
use dla_pdla::FarField;

/// A sweep: its settings (the first is the reference), the runs' size and where it writes.
pub struct Sweep {
    /// `2D DLA, N = 100000`: the charts' title.
    pub title: String,
    /// Space dimension.
    pub dim: usize,
    /// Particles per cluster.
    pub n: u64,
    /// Clusters per setting (seeds `ctx.seed..`).
    pub members: u64,
    /// The settings; the first is the reference.
    pub settings: Vec<Setting>,
    /// Stem of the CSV and PNG files (`accuracy` writes `accuracy.csv`,
    /// `accuracy_pareto.png` and `accuracy_pareto_prefactor.png`).
    pub stem: &'static str,
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
    /// CPU microseconds of the run per particle (user and system time of the member's process).
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

/// One row of a sweep's results: cost and the errors against the reference.
struct Point {
    us: f64,
    dd: f64,
    dd_se: f64,
    da: f64,
    da_se: f64,
}

impl Sweep {
    /// The `dla --seeds` ensemble of every setting; one vector of runs per setting.
    fn measure(&self, ctx: &Ctx, from: u64) -> Result<Vec<Vec<Run>>> {
        ctx.log(&format!(
            "{}: {} settings x {} runs of N = {}",
            self.stem,
            self.settings.len(),
            self.members,
            self.n
        ));
        let mut per = Vec::new();
        for (i, st) in self.settings.iter().enumerate() {
            let mut flags = vec![
                format!("--dim={}", self.dim),
                format!("--particles={}", self.n),
                format!("--fit-from={from}"),
            ];
            flags.extend(st.flags());
            let ens = ctx.ensemble(
                "dla",
                &format!("{}/setting-{i:02}", self.stem),
                self.members,
                &flags,
            )?;
            let mut runs = Vec::new();
            for m in &ens.members {
                let growth = columns(
                    &ens.member_dir(m).join("growth.csv"),
                    &["n", "radius_of_gyration"],
                )?;
                let get = |k: &str| m.results.get(k).copied().unwrap_or(f64::NAN);
                runs.push(Run {
                    us_per_particle: get("cpu_seconds") / get("particles") * 1e6,
                    fractal_dimension: get("fractal_dimension"),
                    n: growth[0].clone(),
                    radius_of_gyration: growth[1].clone(),
                });
            }
            per.push(runs);
        }
        Ok(per)
    }

    /// Run the sweep and add its section to `doc`: the table, where the defaults sit, the
    /// charts and `<stem>.csv`.
    pub fn run(&self, ctx: &Ctx, doc: &mut Doc) -> Result<()> {
        let from = fit_from(self.n);
        let per = self.measure(ctx, from)?;
        let d_ref = mean_stderr(
            &per[0]
                .iter()
                .map(|g| g.fractal_dimension)
                .collect::<Vec<_>>(),
        )
        .0;
        let measured: Vec<Measured> = self
            .settings
            .iter()
            .zip(&per)
            .map(|(s, gs)| Measured {
                setting: *s,
                us_per_particle: mean_stderr(
                    &gs.iter().map(|g| g.us_per_particle).collect::<Vec<_>>(),
                ),
                d: gs.iter().map(|g| g.fractal_dimension).collect(),
                ln_prefactor: gs.iter().map(|g| ln_prefactor(g, from, d_ref)).collect(),
            })
            .collect();
        let (_, d_ref_se) = mean_stderr(&measured[0].d);
        let (a_ref, a_ref_se) = mean_stderr(&measured[0].ln_prefactor);
        let points: Vec<Point> = measured
            .iter()
            .map(|m| {
                let (dm, dse) = mean_stderr(&m.d);
                let (am, ase) = mean_stderr(&m.ln_prefactor);
                // ln A - ln A_ref is the relative error of A to first order.
                Point {
                    us: m.us_per_particle.0,
                    dd: dm - d_ref,
                    dd_se: (dse * dse + d_ref_se * d_ref_se).sqrt(),
                    da: am - a_ref,
                    da_se: (ase * ase + a_ref_se * a_ref_se).sqrt(),
                }
            })
            .collect();
        let cost_d: Vec<(f64, f64)> = points.iter().map(|p| (p.us, p.dd.abs())).collect();
        let cost_a: Vec<(f64, f64)> = points.iter().map(|p| (p.us, p.da.abs())).collect();
        let front = pareto(&cost_d);
        let front_a = pareto(&cost_a);
        self.tables(ctx, doc, &measured, &points, (&front, &front_a))?;
        self.where_defaults_sit(doc, &measured, &points, (&front, &front_a));
        let default = measured.iter().position(|m| m.setting.is_default());
        let short: Vec<String> = measured.iter().map(|m| m.setting.short()).collect();
        // The reference's own error is zero by definition.
        let err = |f: fn(&Point) -> f64| -> Vec<f64> {
            points
                .iter()
                .enumerate()
                .map(|(i, p)| if i == 0 { 0.0 } else { f(p) })
                .collect()
        };
        for (what, y_label, pts, errors, file) in [
            (
                "D",
                "|D - D_ref|",
                &cost_d,
                err(|p| p.dd_se),
                format!("{}_pareto.png", self.stem),
            ),
            (
                "the R_g prefactor",
                "|relative error of the R_g prefactor|",
                &cost_a,
                err(|p| p.da_se),
                format!("{}_pareto_prefactor.png", self.stem),
            ),
        ] {
            pareto_chart(
                &ctx.path(&file),
                &format!("{}: cost against error of {what}", self.title),
                y_label,
                pts,
                &errors,
                &short,
                default,
            )?;
            doc.image(&format!("Pareto front for {what}"), &file);
        }
        Ok(())
    }

    /// The markdown table and `<stem>.csv`.
    fn tables(
        &self,
        ctx: &Ctx,
        doc: &mut Doc,
        measured: &[Measured],
        points: &[Point],
        (front, front_a): (&[usize], &[usize]),
    ) -> Result<()> {
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
        let mut data = Table::new(
            &[
                &CSV_LEAD[..],
                &[
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
                    "paper_settings",
                ],
            ]
            .concat(),
        );
        let yes = |b: bool| if b { "yes" } else { "" }.to_string();
        for (i, (m, p)) in measured.iter().zip(points).enumerate() {
            let (dm, dse) = mean_stderr(&m.d);
            let s = &m.setting;
            let note = match (i, s.is_default(), s.is_paper()) {
                (0, true, _) => "reference (the default)",
                (0, _, _) => "reference (most exact)",
                (_, true, _) => "default",
                (_, _, true) => "the paper's walk (`--paper-settings`)",
                _ if s.far_field == FarField::Return
                    && s.step_min == 0.5
                    && s.precision == 2.0
                    && s.distance_map =>
                {
                    "the paper's near-field step"
                }
                _ => "",
            };
            table.row(vec![
                s.label(),
                pm(m.us_per_particle.0, m.us_per_particle.1),
                pm(dm, dse),
                if i == 0 {
                    "0".into()
                } else {
                    pm(p.dd, p.dd_se)
                },
                if i == 0 {
                    "0".into()
                } else {
                    pm(p.da, p.da_se)
                },
                yes(front.contains(&i)),
                yes(front_a.contains(&i)),
                note.into(),
            ]);
            data.row(vec![
                self.dim.to_string(),
                self.n.to_string(),
                s.precision.to_string(),
                s.step_min.to_string(),
                s.far_field.name().into(),
                s.death_ratio.to_string(),
                s.distance_map.to_string(),
                m.us_per_particle.0.to_string(),
                m.us_per_particle.1.to_string(),
                dm.to_string(),
                dse.to_string(),
                p.dd.to_string(),
                p.dd_se.to_string(),
                p.da.to_string(),
                p.da_se.to_string(),
                front.contains(&i).to_string(),
                front_a.contains(&i).to_string(),
                s.is_default().to_string(),
                s.is_paper().to_string(),
            ]);
        }
        doc.table(&table);
        data.write_csv(&ctx.path(&format!("{}.csv", self.stem)))?;
        doc.p(&format!(
            "D is fitted per cluster over N >= {}; D - D_ref and the prefactor error are \
             differences of ensemble means, ± the combined standard error, so a difference \
             smaller than about twice its error is not significant at this ensemble size. \
             Data: [`{stem}.csv`]({stem}.csv).",
            fit_from(self.n),
            stem = self.stem
        ));
        Ok(())
    }

    /// A paragraph on the default: its errors in standard errors, its cost against the
    /// reference's, and whether it is on each front or within the errors of a setting that is.
    fn where_defaults_sit(
        &self,
        doc: &mut Doc,
        measured: &[Measured],
        points: &[Point],
        (front, front_a): (&[usize], &[usize]),
    ) {
        let Some(i) = measured.iter().position(|m| m.setting.is_default()) else {
            return;
        };
        let p = &points[i];
        let on = |f: &[usize]| {
            if f.contains(&i) {
                "on the front"
            } else {
                "off the front"
            }
        };
        let text = if i == 0 {
            format!(
                "**Where the default sits.** The default is this sweep's reference, at {} \
                 microseconds per particle.",
                sig(p.us, 3)
            )
        } else {
            format!(
                "**Where the default sits.** The default costs {} of the reference's time per \
                 particle; its D differs from the reference's by {} ({} standard errors; {} \
                 for D) and its R_g prefactor by {} ({} standard errors; {} for the \
                 prefactor). {}",
                sig(p.us / points[0].us, 2),
                pm(p.dd, p.dd_se),
                sig(p.dd.abs() / p.dd_se, 2),
                on(front),
                pm(p.da, p.da_se),
                sig(p.da.abs() / p.da_se, 2),
                on(front_a),
                converged(p),
            )
        };
        doc.p(&text);
    }
}

/// Whether both errors of `p` are within two standard errors of zero, in words.
fn converged(p: &Point) -> &'static str {
    match (p.dd.abs() <= 2.0 * p.dd_se, p.da.abs() <= 2.0 * p.da_se) {
        (true, true) => {
            "Both are within two standard errors of the reference: converged at this ensemble size."
        }
        (false, true) => "Its D differs from the reference's by more than two standard errors.",
        (true, false) => {
            "Its R_g prefactor differs from the reference's by more than two standard errors."
        }
        (false, false) => "Both differ from the reference's by more than two standard errors.",
    }
}
