//! Deposits on a substrate with drift, and ballistic aggregation: the density profile of 2D
//! and 3D deposits from diffusion-limited deposition (Péclet number 0) through growing drift
//! to ballistic deposition, and the fractal dimension of radial ballistic clusters. Every
//! number comes from ensembles of the `dla` binary (`dla --seeds ...`).

use super::Ctx;
use super::csvfile::Csv;
use super::ensemble::columns;
use crate::report::{Doc, Table, mean_stderr, pm, sig};
use anyhow::Result;
use figures::chart::{self, Chart, Series, Style};
use std::path::{Path, PathBuf};

/// The density profiles, log-binned, per dimension and drift: the data of the charts.
pub const PROFILES_CSV: &str = "deposit_profiles.csv";

/// Log bins of the height: 10 per decade from 1 diameter.
const BINS_PER_DECADE: f64 = 10.0;

/// Run the study and write `deposit.md`.
pub fn run(ctx: &Ctx) -> Result<()> {
    let mut doc = ctx.doc("Deposits, drift and ballistic aggregation");
    doc.p(
        "Growth on a substrate (`dla --substrate-width W`) from diffusion-limited deposition \
         through drift towards the substrate (`--drift`, the Péclet number Pe = v d / D_w) to \
         ballistic deposition (`--ballistic on`), and radial ballistic aggregation. Each table \
         comes from ensembles of the `dla` binary run by this command; sizes, widths, the \
         number of deposits E and the seeds (from the base seed up) are in the tables.",
    );
    let mut profiles = Table::new(&["dim", "drift", "height", "deposits", "density", "stderr"]);
    deposits(ctx, &mut doc, 2, &mut profiles)?;
    deposits(ctx, &mut doc, 3, &mut profiles)?;
    profiles.write_csv(&ctx.path(PROFILES_CSV))?;
    charts(&ctx.out)?;
    doc.image("density profiles of 2D deposits", "deposit_2d.png");
    doc.image("density profiles of 3D deposits", "deposit_3d.png");
    doc.p(&format!(
        "Data of the charts: [`{PROFILES_CSV}`]({PROFILES_CSV}) (density in log bins of the \
         height, {BINS_PER_DECADE} per decade, mean and standard error over the deposits)."
    ));
    ballistic(ctx, &mut doc)?;
    doc.write(&ctx.path("deposit.md"))
}

/// The drifts of a study: Péclet numbers, then the ballistic limit (`None`).
fn drifts(dim: usize) -> Vec<Option<f64>> {
    if dim == 2 {
        vec![Some(0.0), Some(0.03), Some(0.3), Some(3.0), None]
    } else {
        vec![Some(0.0), Some(0.3), None]
    }
}

fn drift_name(d: Option<f64>) -> String {
    d.map_or_else(|| "ballistic".into(), |pe| pe.to_string())
}

/// One deposit's density profile in log bins of the height: `(bin centre, density)` for the
/// bins from 1 diameter up to `top`.
fn log_binned(height: &[f64], density: &[f64], top: f64) -> Vec<(f64, f64)> {
    let mut bins: Vec<(f64, f64, u32)> = Vec::new();
    for (&h, &rho) in height.iter().zip(density) {
        let mid = h + 0.5;
        if mid < 1.0 || mid > top {
            continue;
        }
        let k = (mid.log10() * BINS_PER_DECADE).floor() as usize;
        if bins.len() <= k {
            bins.resize(k + 1, (0.0, 0.0, 0));
        }
        bins[k].0 += mid.ln();
        bins[k].1 += rho;
        bins[k].2 += 1;
    }
    bins.into_iter()
        .filter(|b| b.2 > 0)
        .map(|(lh, rho, c)| ((lh / f64::from(c)).exp(), rho / f64::from(c)))
        .collect()
}

/// `d + ln(rho_2 / rho_1) / ln(h_2 / h_1)` between the bins at `lo` and `hi` (the nearest).
fn local_dimension(dim: usize, profile: &[(f64, f64)], lo: f64, hi: f64) -> f64 {
    let near = |x: f64| {
        profile
            .iter()
            .min_by(|a, b| (a.0 / x).ln().abs().total_cmp(&(b.0 / x).ln().abs()))
            .copied()
            .unwrap_or((f64::NAN, f64::NAN))
    };
    let (a, b) = (near(lo), near(hi));
    dim as f64 + (b.1 / a.1).ln() / (b.0 / a.0).ln()
}

/// Deposits in `dim` dimensions at every drift of [`drifts`].
fn deposits(ctx: &Ctx, doc: &mut Doc, dim: usize, profiles: &mut Table) -> Result<()> {
    let (w, n, e) = if dim == 2 {
        (
            ctx.scale.pick(64.0, 256.0, 1000.0),
            ctx.scale.pick(5_000u64, 100_000, 1_000_000),
            ctx.scale.pick(2u64, 3, 4),
        )
    } else {
        (
            ctx.scale.pick(16.0, 64.0, 200.0),
            ctx.scale.pick(3_000u64, 100_000, 1_000_000),
            ctx.scale.pick(2u64, 2, 3),
        )
    };
    doc.h2(&format!(
        "{dim}D deposits: from diffusion-limited to ballistic"
    ));
    let mut table = Table::new(&[
        "drift Pe",
        "W",
        "N",
        "E",
        "height",
        "density dimension (fit 8 to W/4)",
        "D(h), h 3 to 10",
        "D(h), h W/40 to W/4",
        "tree mass exponent x (M ~ H^x)",
        "trees on the substrate",
        "trees still growing",
    ]);
    // The local dimension's windows: a short one near the substrate, where drift has not yet
    // acted at small Pe, and the widest one below the width's scale.
    let (near, far) = ((3.0, 10.0), (w / 40.0, w / 4.0));
    for drift in drifts(dim) {
        let name = drift_name(drift);
        ctx.log(&format!(
            "deposit: {dim}D W = {w}, N = {n}, drift {name}, {e} deposits"
        ));
        let mut args = vec![
            format!("--dim={dim}"),
            format!("--particles={n}"),
            format!("--substrate-width={w}"),
        ];
        match drift {
            Some(pe) if pe > 0.0 => args.push(format!("--drift={pe}")),
            Some(_) => {}
            None => args.push("--ballistic=on".into()),
        }
        let ens = ctx.ensemble("dla", &format!("deposit/{dim}d_{name}"), e, &args)?;
        let mut per_bin: Vec<(f64, Vec<f64>)> = Vec::new();
        let (mut d_near, mut d_far) = (Vec::new(), Vec::new());
        for m in &ens.members {
            let cols = columns(
                &ens.member_dir(m).join("deposit.csv"),
                &["height", "density"],
            )?;
            let profile = log_binned(&cols[0], &cols[1], w / 4.0);
            d_near.push(local_dimension(dim, &profile, near.0, near.1));
            d_far.push(local_dimension(dim, &profile, far.0, far.1));
            for (k, &(h, rho)) in profile.iter().enumerate() {
                if per_bin.len() <= k {
                    per_bin.push((h, Vec::new()));
                }
                per_bin[k].1.push(rho);
            }
        }
        for (h, v) in &per_bin {
            let (m, se) = mean_stderr(v);
            profiles.row(vec![
                dim.to_string(),
                name.clone(),
                format!("{h:.3}"),
                v.len().to_string(),
                m.to_string(),
                se.to_string(),
            ]);
        }
        // No fit in deposits lower than 4 x 8 diameters over W/4 (tiny scale).
        let dd = ens
            .stat("density_dimension")
            .map_or_else(|_| "—".to_string(), |d| pm(d.mean, d.stderr));
        let tree_d = ens
            .stat("tree_mass_exponent")
            .map_or_else(|_| "—".to_string(), |d| pm(d.mean, d.stderr));
        let height = ens.stat("deposit_height")?;
        let trees = ens.stat("deposit_trees")?;
        let growing = ens.stat("deposit_growing_trees")?;
        let (dn, dn_se) = mean_stderr(&d_near);
        let (df, df_se) = mean_stderr(&d_far);
        table.row(vec![
            name,
            w.to_string(),
            n.to_string(),
            ens.members.len().to_string(),
            sig(height.mean, 4),
            dd,
            pm(dn, dn_se),
            pm(df, df_se),
            tree_d,
            sig(trees.mean, 4),
            sig(growing.mean, 3),
        ]);
    }
    ctx.table(doc, &table, &format!("deposit_{dim}d.csv"))?;
    let dla = if dim == 2 { "1.71" } else { "2.50" };
    doc.p(&format!(
        "The density is the particles per unit volume in layers of one diameter; in \
         diffusion-limited deposition it falls as h^(D - {dim}) with D the trees' fractal \
         dimension, DLA's {dla} (Meakin, \"Diffusion-controlled deposition on fibers and \
         surfaces\", 1983), up to heights of about the width W, where the trees compete at the \
         strip's scale and it levels off. The density dimension is {dim} plus the slope of ln \
         density against ln h fitted from 8 diameters to W/4 (`run.json`'s \
         `density_dimension`), averaged over the deposits (± standard error). D(h) is the \
         same slope between two log bins of the height ({} to {} and {} to {} diameters). The tree \
         mass exponent x is the slope of ln mass against ln height across the trees from 8 \
         diameters to W/4 tall (`tree_mass_exponent`). It is not the trees' fractal \
         dimension: a tree stops growing when its neighbours screen it, while it is still \
         thinner than the trees that go on, so short trees are not small copies of tall ones \
         and x falls below D; the density profile, to which the surviving trees give its \
         power law, measures D. A \
         drift of Pe carries a walker straight down over lengths beyond about 2 / Pe \
         diameters, so the deposit is diffusion-limited below that height and ballistic above \
         it: D(h) crosses over from the DLA value towards {dim} as Pe grows, and at fixed Pe as \
         h grows past 2 / Pe. The ballistic limit is compact (D = {dim}). Trees are the \
         particles on the substrate with everything grown on them; the trees still growing \
         received a particle among the last W^{} particles.",
        near.0,
        near.1,
        far.0,
        far.1,
        dim - 1
    ));
    Ok(())
}

/// Radial ballistic aggregation in 2D and 3D: the fractal dimension.
fn ballistic(ctx: &Ctx, doc: &mut Doc) -> Result<()> {
    doc.h2("Ballistic aggregation around a seed");
    let mut table = Table::new(&[
        "dim",
        "N",
        "E",
        "D_f (fit from N = 1000)",
        "R_g",
        "compact limit",
    ]);
    for dim in [2usize, 3] {
        let n = if dim == 2 {
            ctx.scale.pick(5_000u64, 100_000, 1_000_000)
        } else {
            ctx.scale.pick(3_000u64, 30_000, 300_000)
        };
        let e = ctx.scale.pick(2u64, 3, 4);
        ctx.log(&format!("ballistic: {dim}D N = {n}, {e} clusters"));
        let ens = ctx.ensemble(
            "dla",
            &format!("deposit/ballistic_{dim}d"),
            e,
            &[
                format!("--dim={dim}"),
                format!("--particles={n}"),
                "--ballistic=on".into(),
                format!("--fit-from={}", super::dla::fit_from(n)),
            ],
        )?;
        let df = ens.stat("fractal_dimension")?;
        let rg = ens.stat("radius_of_gyration")?;
        table.row(vec![
            dim.to_string(),
            n.to_string(),
            ens.members.len().to_string(),
            pm(df.mean, df.stderr),
            pm(rg.mean, rg.stderr),
            dim.to_string(),
        ]);
    }
    ctx.table(doc, &table, "deposit_ballistic.csv")?;
    doc.p(
        "Each walker comes from a uniformly random direction along a straight line whose \
         impact parameter is uniform over the birth sphere's cross-section, and sticks where \
         the line first touches the cluster (Vold 1963, Sutherland 1966; Meakin's ballistic \
         particle-cluster aggregation). The clusters are compact in the limit of large N \
         (D_f = d), which the fitted D_f approaches from below: the surface layer of loose \
         branches thins slowly as the cluster grows. D_f is the slope of ln N against ln R_g \
         from the run's growth samples, averaged over the clusters (± standard error).",
    );
    Ok(())
}

/// `deposit_2d.png` and `deposit_3d.png` from [`PROFILES_CSV`] in `dir`: the density against
/// the height, log-log, a line per drift.
pub fn charts(dir: &Path) -> Result<Vec<PathBuf>> {
    let csv = Csv::read(&dir.join(PROFILES_CSV))?;
    let (h, rho, se) = (csv.num("height")?, csv.num("density")?, csv.num("stderr")?);
    let dims = csv.text("dim")?;
    let mut out = Vec::new();
    for dim in ["2", "3"] {
        let mut series = Vec::new();
        for (key, rows) in csv.groups(&["dim", "drift"])? {
            if key[0] != dim {
                continue;
            }
            let label = if key[1] == "ballistic" {
                "ballistic".to_string()
            } else {
                format!("Pe = {}", key[1])
            };
            series.push(
                Series::new(
                    label,
                    rows.iter().map(|&i| (h[i], rho[i])).collect(),
                    Style::LinePoints,
                )
                .with_y_errors(rows.iter().map(|&i| se[i]).collect()),
            );
        }
        if series.is_empty() || !dims.iter().any(|d| d == dim) {
            continue;
        }
        // DLA's power law through the diffusion-limited deposit's bin nearest h = 10.
        let (d_dla, d) = if dim == "2" { (1.71, 2.0) } else { (2.50, 3.0) };
        if let Some(plain) = series.first()
            && let Some(&(h0, rho0)) = plain
                .points
                .iter()
                .min_by(|a, b| (a.0 / 10.0).ln().abs().total_cmp(&(b.0 / 10.0).ln().abs()))
        {
            let (lo, hi) = plain
                .points
                .iter()
                .fold((f64::INFINITY, 0f64), |(lo, hi), p| {
                    (lo.min(p.0), hi.max(p.0))
                });
            let at = |h: f64| (h, rho0 * (h / h0).powf(d_dla - d));
            series.push(Series::new(
                format!("h^(D - {d}), DLA's D = {d_dla}"),
                vec![at(lo), at(hi)],
                Style::Thin,
            ));
        }
        let chart = Chart::log_log(
            format!("{dim}D deposits: density against height, by drift"),
            "height h (diameters)",
            "particles per unit volume",
            series,
        );
        let path = dir.join(format!("deposit_{dim}d.png"));
        chart::write_png(&chart, &path)?;
        out.push(path);
    }
    Ok(out)
}
