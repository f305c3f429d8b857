//! The DLA family beyond the plain model: the cluster as a tree (Horton-Strahler branch
//! orders from each particle's parent), beside the literature's values. Every number comes
//! from ensembles of the `dla` binary (`dla --seeds ...`), whose members stay on disk.

use super::Ctx;
use super::csvfile::Csv;
use super::ensemble::columns;
use crate::plot::{self, Chart, Series, Style};
use crate::report::{Doc, Table, mean_stderr, pm, sig};
use anyhow::Result;
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
    plot::write_png(&chart, &path)?;
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
