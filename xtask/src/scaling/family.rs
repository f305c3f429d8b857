//! The DLA family beyond the plain model: the cluster as a tree (Horton-Strahler branch
//! orders from each particle's parent), beside the literature's values. Every number comes
//! from ensembles of the `dla` binary (`dla --seeds ...`), whose members stay on disk.

use super::Ctx;
use super::csvfile::Csv;
use super::ensemble::columns;
use crate::report::{Doc, Table, mean_stderr, pm, sig};
use anyhow::Result;
use figures::chart::{self, Chart, Series, Style};
use std::path::{Path, PathBuf};

/// `N_k` per order and size, averaged over the clusters: the data of `family_branches.png`.
pub const ORDERS_CSV: &str = "family_branches_orders.csv";

/// `family_branches.png` from [`ORDERS_CSV`] in `dir`: `N_k` against `k`, a line per size.
pub fn branches_chart(dir: &Path) -> Result<Vec<PathBuf>> {
    let csv = Csv::read(&dir.join(ORDERS_CSV))?;
    let (k, m, se) = (
        csv.num("order")?,
        csv.num("branches")?,
        csv.num("branches_stderr")?,
    );
    let clusters = csv.num("clusters")?;
    let mut series = Vec::new();
    for (key, rows) in csv.groups(&["N"])? {
        series.push(
            Series::new(
                format!("N = {}, {} clusters", key[0], clusters[rows[0]]),
                rows.iter().map(|&i| (k[i], m[i])).collect(),
                Style::LinePoints,
            )
            .with_y_errors(rows.iter().map(|&i| se[i]).collect()),
        );
    }
    let chart = Chart {
        title: "2D DLA: branches of each Horton-Strahler order".into(),
        x_label: "order k".into(),
        y_label: "N_k (mean over the clusters)".into(),
        log_x: false,
        log_y: true,
        series,
    };
    let path = dir.join("family_branches.png");
    chart::write_png(&chart, &path)?;
    Ok(vec![path])
}

/// Run the family's studies and write `family.md`.
pub fn run(ctx: &Ctx) -> Result<()> {
    let mut doc = ctx.doc("The DLA family: variants and the cluster as a tree");
    doc.p(
        "Studies of what `dla` offers beyond the plain Witten-Sander model. Each table comes \
         from ensembles of the `dla` binary run by this command; the sizes, the number of \
         clusters E and the seeds (from the base seed up) are in each table.",
    );
    branches(ctx, &mut doc)?;
    sticking(ctx, &mut doc)?;
    doc.write(&ctx.path("family.md"))
}

/// Horton-Strahler analysis of 2D DLA: the bifurcation and length ratios over an ensemble,
/// and `N_k` per order averaged over it.
fn branches(ctx: &Ctx, doc: &mut Doc) -> Result<()> {
    doc.h2("Branch orders of 2D DLA (Horton-Strahler)");
    let sizes: Vec<u64> = ctx.scale.pick(
        vec![10_000, 20_000],
        vec![30_000, 200_000],
        vec![100_000, 1_000_000, 10_000_000],
    );
    let e = ctx.scale.pick(2u64, 6, 16);
    let mut table = Table::new(&[
        "N",
        "E",
        "orders fitted",
        "R_B (bifurcation ratio)",
        "R_L (length ratio)",
        "highest order",
        "Ossadnik (1992), off-lattice",
        "branched-growth theory",
    ]);
    let mut orders = Table::new(&["N", "order", "clusters", "branches", "branches_stderr"]);
    for &n in &sizes {
        // 1e7 clusters take about a minute each: fewer of them.
        let count = if n >= 10_000_000 { e.min(6) } else { e };
        ctx.log(&format!("branches: 2D N = {n}, {count} clusters"));
        let ens = ctx.ensemble(
            "dla",
            &format!("family_branches/n{n}"),
            count,
            &[format!("--particles={n}")],
        )?;
        let rb = ens.stat("bifurcation_ratio")?;
        let rl = ens.stat("length_ratio")?;
        let top = ens.stat("strahler_order")?;
        // N_k per order, averaged over the members (orders every member reached).
        let mut per_order: Vec<Vec<f64>> = Vec::new();
        for m in &ens.members {
            let cols = columns(
                &ens.member_dir(m).join("branches.csv"),
                &["order", "branches"],
            )?;
            for (&k, &nk) in cols[0].iter().zip(&cols[1]) {
                let k = k as usize;
                if per_order.len() < k {
                    per_order.resize(k, Vec::new());
                }
                per_order[k - 1].push(nk);
            }
        }
        let members = ens.members.len();
        // The orders each member's fit used: from 1 to its highest with at least 50
        // branches (`dla_pdla::branches::FIT_MIN_BRANCHES`).
        let highest: Vec<usize> = ens
            .members
            .iter()
            .map(|m| {
                columns(&ens.member_dir(m).join("branches.csv"), &["branches"]).map(|c| {
                    c[0].iter()
                        .take_while(|&&b| b >= dla_pdla::branches::FIT_MIN_BRANCHES as f64)
                        .count()
                })
            })
            .collect::<Result<_>>()?;
        let (lo, hi) = (
            highest.iter().min().copied().unwrap_or(0),
            highest.iter().max().copied().unwrap_or(0),
        );
        table.row(vec![
            n.to_string(),
            rb.n.to_string(),
            if lo == hi {
                format!("1 to {hi}")
            } else {
                format!("1 to {lo}-{hi}")
            },
            pm(rb.mean, rb.stderr),
            pm(rl.mean, rl.stderr),
            sig(top.mean, 3),
            "5.2".into(),
            "about 4.9".into(),
        ]);
        for (k, v) in per_order.iter().enumerate() {
            // Orders every member reached.
            if v.len() == members {
                let (m, se) = mean_stderr(v);
                orders.row(vec![
                    n.to_string(),
                    (k + 1).to_string(),
                    members.to_string(),
                    m.to_string(),
                    se.to_string(),
                ]);
            }
        }
    }
    ctx.table(doc, &table, "family_branches.csv")?;
    orders.write_csv(&ctx.path(ORDERS_CSV))?;
    branches_chart(&ctx.out)?;
    doc.image("N_k against k", "family_branches.png");
    doc.p(&format!(
        "Data of the chart: [`{ORDERS_CSV}`]({ORDERS_CSV}) (N_k per order, mean and standard \
         error over the clusters)."
    ));
    doc.p(
        "Each particle's parent is the particle its walker touched; a tip has order 1, and a \
         particle whose children's highest order k is held by two or more children has order \
         k + 1 (Horton 1945, Strahler 1957). N_k counts the branches (maximal chains) of order \
         k and L_k is their mean length in particles. R_B and R_L are exp of the slopes of ln \
         N_k and ln L_k against k over the orders holding at least 50 branches in each \
         cluster, then averaged over the clusters (± the standard error). Ossadnik (\"Branch \
         order and ramification analysis of large diffusion-limited-aggregation clusters\", \
         1992) measured R_B of about 5.2 on large off-lattice clusters; the branched-growth \
         theory of Ball, Nauenberg and Witten gives about 4.9. Error bars in the chart are \
         standard errors over the clusters.",
    );
    Ok(())
}

/// The local dimension of the sticking-probability study: `D(N)` per `p` and window.
pub const STICKING_CSV: &str = "family_sticking.csv";

/// A local-dimension curve: `(N at the window's centre, mean D, its standard error)` per
/// window.
type Curve = Vec<(f64, f64, f64)>;

/// Half-decade windows of the local dimension: `D = ln(N_2 / N_1) / ln(R_g(N_2) / R_g(N_1))`
/// with `N_2 >= N_1 sqrt(10)`, from the growth samples of one cluster, as `(sqrt(N_1 N_2), D)`.
fn local_dimensions(n: &[f64], rg: &[f64]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut i = n.iter().position(|&x| x >= 30.0).unwrap_or(n.len());
    while i < n.len() {
        let Some(j) = (i..n.len()).find(|&j| n[j] >= n[i] * 10f64.sqrt()) else {
            break;
        };
        out.push((
            (n[i] * n[j]).sqrt(),
            (n[j] / n[i]).ln() / (rg[j] / rg[i]).ln(),
        ));
        i = j;
    }
    out
}

/// Sticking probability: the local dimension of 2D DLA against N for several `p`, the
/// crossover from compact growth at small N to DLA, and `D_f` well beyond it.
fn sticking(ctx: &Ctx, doc: &mut Doc) -> Result<()> {
    doc.h2("Sticking probability: the crossover to DLA");
    // Small p is slow: a walker is refused about 1/p times (2D 1e5 takes 0.6 s at p = 1,
    // 5 s at p = 0.01 and 16 s at p = 0.003 on one core).
    let n = ctx.scale.pick(5_000u64, 30_000, 1_000_000);
    let e = ctx.scale.pick(2u64, 4, 8);
    let ps = [1.0, 0.1, 0.03, 0.01, 0.003];
    let mut csv = Table::new(&["p", "N", "clusters", "local_dimension", "stderr"]);
    let mut curves: Vec<(f64, Curve)> = Vec::new();
    let mut table = Table::new(&[
        "p",
        "N",
        "E",
        "D_f (fit from N = 1000)",
        "D(N), last half decade",
        "largest D(N) (at N)",
        "R_g(N) / R_g(N) at p = 1",
        "crossover N_x",
    ]);
    let mut rg_plain = f64::NAN;
    for &p in &ps {
        ctx.log(&format!("sticking: 2D N = {n}, p = {p}, {e} clusters"));
        let ens = ctx.ensemble(
            "dla",
            &format!("family_sticking/p{p}"),
            e,
            &[
                format!("--particles={n}"),
                format!("--sticking-probability={p}"),
                format!("--fit-from={}", super::dla::fit_from(n)),
            ],
        )?;
        // Local dimensions per cluster, then their mean and standard error per window (the
        // windows are the same for every cluster: the sampling schedule depends on N only).
        let mut per_window: Vec<(f64, Vec<f64>)> = Vec::new();
        for m in &ens.members {
            let cols = columns(
                &ens.member_dir(m).join("growth.csv"),
                &["n", "radius_of_gyration"],
            )?;
            for (k, (centre, d)) in local_dimensions(&cols[0], &cols[1]).into_iter().enumerate() {
                if per_window.len() <= k {
                    per_window.push((centre, Vec::new()));
                }
                per_window[k].1.push(d);
            }
        }
        let curve: Curve = per_window
            .iter()
            .map(|(c, v)| {
                let (m, se) = mean_stderr(v);
                (*c, m, se)
            })
            .collect();
        for &(c, m, se) in &curve {
            csv.row(vec![
                p.to_string(),
                format!("{c:.0}"),
                ens.members.len().to_string(),
                m.to_string(),
                se.to_string(),
            ]);
        }
        let rg = ens.stat("radius_of_gyration")?;
        if p == 1.0 {
            rg_plain = rg.mean;
        }
        let df = ens.stat("fractal_dimension")?;
        let last = curve
            .last()
            .copied()
            .unwrap_or((f64::NAN, f64::NAN, f64::NAN));
        // The compact regime's peak, past the first window's few particles.
        let peak =
            curve
                .iter()
                .skip(1)
                .copied()
                .fold((f64::NAN, f64::NEG_INFINITY, 0.0), |a, c| {
                    if c.1 > a.1 { c } else { a }
                });
        let crossover = match curves.first() {
            Some((_, plain)) if p < 1.0 => crossover(plain, &curve),
            _ => "—".into(),
        };
        table.row(vec![
            p.to_string(),
            n.to_string(),
            ens.members.len().to_string(),
            pm(df.mean, df.stderr),
            pm(last.1, last.2),
            format!("{} ({:.0})", pm(peak.1, peak.2), peak.0),
            sig(rg.mean / rg_plain, 3),
            crossover,
        ]);
        curves.push((p, curve));
    }
    ctx.table(doc, &table, "family_sticking_summary.csv")?;
    csv.write_csv(&ctx.path(STICKING_CSV))?;
    sticking_chart(&ctx.out)?;
    doc.image("local dimension against N", "family_sticking.png");
    doc.p(&format!(
        "Each walker that ends a move in contact sticks with probability p, else walks on from \
         the contact point (docs/dla.md). D(N) is the local dimension of each cluster over a \
         half decade of N, ln(N_2/N_1) / ln(R_g(N_2)/R_g(N_1)) with N_2 = N_1 sqrt(10), averaged \
         over the clusters (± standard error; data: [`{STICKING_CSV}`]({STICKING_CSV})). Below \
         1 the small clusters are compact (D near 2: a walker explores the surface before it \
         sticks, as in reaction-limited growth); beyond a crossover size the growth is DLA \
         again. N_x is the first window from which on D(N) stays within 0.05 of the p = 1 \
         curve's, or within two standard errors of the difference where those are wider \
         (\"beyond N\" if it does not within the sizes run); the largest D(N) leaves out the \
         first window (N below 100). D_f is the fit of ln N \
         against ln R_g from N = 1000, which for small p still mixes the compact regime in; \
         the last window's D(N) is the one to set beside the 1.71 of DLA. The clusters are \
         denser (smaller R_g at the same N) the smaller p is."
    ));
    Ok(())
}

/// The first window of `curve` from which on its local dimension stays within 0.05 of the
/// plain curve's at the same window, or within two standard errors of the difference where
/// those are wider, as text.
fn crossover(plain: &Curve, curve: &Curve) -> String {
    let close: Vec<bool> = curve
        .iter()
        .zip(plain)
        .map(|(a, b)| (a.1 - b.1).abs() < 0.05f64.max(2.0 * a.2.hypot(b.2)))
        .collect();
    match (0..close.len()).find(|&i| close[i..].iter().all(|&c| c)) {
        Some(i) => format!("{:.0}", curve[i].0),
        None => format!("beyond {:.0}", curve.last().map_or(0.0, |c| c.0)),
    }
}

/// `family_sticking.png` from [`STICKING_CSV`] in `dir`: the local dimension against N, a line
/// per sticking probability, and DLA's asymptotic 1.71.
pub fn sticking_chart(dir: &Path) -> Result<Vec<PathBuf>> {
    let csv = Csv::read(&dir.join(STICKING_CSV))?;
    let (n, d, se) = (
        csv.num("N")?,
        csv.num("local_dimension")?,
        csv.num("stderr")?,
    );
    let mut series = Vec::new();
    let (mut lo, mut hi) = (f64::INFINITY, 0f64);
    for (key, rows) in csv.groups(&["p"])? {
        series.push(
            Series::new(
                format!("p = {}", key[0]),
                rows.iter().map(|&i| (n[i], d[i])).collect(),
                Style::LinePoints,
            )
            .with_y_errors(rows.iter().map(|&i| se[i]).collect()),
        );
        for &i in &rows {
            lo = lo.min(n[i]);
            hi = hi.max(n[i]);
        }
    }
    series.push(Series::new(
        "DLA, asymptotic 1.71",
        vec![(lo, 1.71), (hi, 1.71)],
        Style::Thin,
    ));
    let chart = Chart {
        title: "2D DLA with sticking probability p: local dimension".into(),
        x_label: "particles N".into(),
        y_label: "D(N) over a half decade".into(),
        log_x: true,
        log_y: false,
        series,
    };
    let path = dir.join("family_sticking.png");
    chart::write_png(&chart, &path)?;
    Ok(vec![path])
}
