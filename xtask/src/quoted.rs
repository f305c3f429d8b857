//! Numbers the docs quote, held to the committed results they come from: a table in a doc is
//! rebuilt here from its file in `docs/results/`, and a test fails when the doc says otherwise.

/// The table of `docs/dlca.md` ("Validation", finite size) from `docs/results/dlca_pooled_df.csv`
/// (written by `docs/results/dlca_pooled_df.sh`): per lattice, the pooled fractal dimension
/// with its jackknife error and the mean of the members' own fits.
///
/// # Errors
/// The CSV lacks a column or a row is short.
pub fn dlca_pooled_table(csv: &str) -> Result<String, String> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| format!("dlca_pooled_df.csv has no column `{name}`"))
    };
    let cols = [
        "size",
        "seeds",
        "target_clusters",
        "pooled_clusters",
        "pooled_d",
        "pooled_stderr",
        "per_member_mean",
        "per_member_stderr",
    ]
    .map(col);
    let mut out = String::from(
        "| lattice (1% fill) | seeds | ended at | clusters fitted | D pooled (jackknife) | D, mean of members' fits |\n\
         |---|---|---|---|---|---|\n",
    );
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let f: Vec<&str> = line.split(',').collect();
        let get = |i: &Result<usize, String>| -> Result<&str, String> {
            let i = *i.as_ref().map_err(Clone::clone)?;
            f.get(i)
                .copied()
                .ok_or_else(|| format!("short row `{line}`"))
        };
        let [size, seeds, target, fitted, d, e, m, me] = [
            get(&cols[0])?,
            get(&cols[1])?,
            get(&cols[2])?,
            get(&cols[3])?,
            get(&cols[4])?,
            get(&cols[5])?,
            get(&cols[6])?,
            get(&cols[7])?,
        ];
        out.push_str(&format!(
            "| {size}^2 | {seeds} | {target} clusters | {fitted} | {d} ± {e} | {m} ± {me} |\n"
        ));
    }
    Ok(out)
}

/// The headline figures of a long DLA run as its report quotes them, from its `run.json`: the
/// wall time in hours, the peak memory in GiB and GB, the fractal dimension and R_g.
///
/// # Errors
/// The manifest is not JSON or lacks a figure.
pub fn dla_run_figures(run_json: &str) -> Result<Vec<String>, String> {
    let v: serde_json::Value = serde_json::from_str(run_json).map_err(|e| e.to_string())?;
    let num = |path: &[&str]| {
        path.iter()
            .try_fold(&v, |v, k| v.get(k))
            .and_then(serde_json::Value::as_f64)
            .ok_or_else(|| format!("run.json has no {}", path.join(".")))
    };
    let wall = num(&["wall_seconds"])?;
    let peak = num(&["peak_rss_bytes"])?;
    let d = num(&["results", "fractal_dimension"])?;
    let rg = num(&["results", "radius_of_gyration"])?;
    let rg = rg.round() as u64;
    Ok(vec![
        format!("{:.2} h", wall / 3600.0),
        format!("{:.1} GiB", peak / (1u64 << 30) as f64),
        format!("{:.2} GB", peak / 1e9),
        format!("{d:.4}"),
        format!("{} {:03}", rg / 1000, rg % 1000),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dlca_md_quotes_the_committed_pooled_fractal_dimensions() {
        let root = crate::workspace_root();
        let csv = std::fs::read_to_string(root.join("docs/results/dlca_pooled_df.csv")).unwrap();
        let doc = std::fs::read_to_string(root.join("docs/dlca.md")).unwrap();
        let table = dlca_pooled_table(&csv).unwrap();
        assert!(
            doc.contains(&table),
            "docs/dlca.md does not hold the table of docs/results/dlca_pooled_df.csv:\n{table}"
        );
    }

    #[test]
    fn the_1e9_report_quotes_its_run() {
        let root = crate::workspace_root();
        let dir = root.join("docs/results/dla_1e9");
        let run = std::fs::read_to_string(dir.join("run.json")).unwrap();
        let report = std::fs::read_to_string(dir.join("README.md")).unwrap();
        for figure in dla_run_figures(&run).unwrap() {
            assert!(
                report.contains(&figure),
                "docs/results/dla_1e9/README.md does not quote `{figure}` from its run.json"
            );
        }
    }
}
