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
}
