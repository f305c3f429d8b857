//! Combining an ensemble's members: `ensemble.json`, `ensemble.md`, and each model's curves
//! averaged over the members with error bands (`ensemble_<name>.csv`, `ensemble_<name>.png`).

use anyhow::{Context, anyhow, bail};
use figures::chart::{Chart, Series, Style, write_png};
use run_io::{RunManifest, write_atomic};
use serde::Serialize;
use serde_json::{Map, Value, json};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A curve every member writes as CSV, averaged over the members.
#[derive(Debug, Clone, Copy)]
pub struct Curve {
    /// The member's file (`growth.csv`); the average goes to `ensemble_<stem>.csv` and `.png`.
    pub file: &'static str,
    /// The column of the abscissa.
    pub x: &'static str,
    /// The columns averaged.
    pub ys: &'static [&'static str],
    /// What a member without a row at some `x` contributes: `Some(0.0)` for counts (a size
    /// distribution), `None` to keep only the `x` every member has (a curve that ends when its
    /// run ends).
    pub missing: Option<f64>,
    /// Chart title.
    pub title: &'static str,
    /// Axis labels of the chart, with units (`particles N`, `R_g, R_ext (diameters)`).
    pub axes: (&'static str, &'static str),
    /// Logarithmic axes.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// The colour of each of `ys` in the chart, where a model fixes one (the animats'
    /// species); empty: the charts' palette in order.
    pub colours: &'static [[u8; 3]],
}

/// A result computed from every member's outputs together rather than averaged over the members
/// (a fit over the clusters of all members, say), written beside the per-member statistics:
/// `ensemble.json`'s `pooled.<name>` and a section of `ensemble.md`.
#[derive(Debug, Clone, Copy)]
pub struct Pooled {
    /// Key under `pooled` in `ensemble.json`.
    pub name: &'static str,
    /// Heading of its section in `ensemble.md`.
    pub title: &'static str,
    /// Computes it from the finished members: `Ok(None)` when the members hold nothing to pool
    /// (a flag that writes the input was not given); its `markdown` text, if any, is the
    /// section's body. An `Err` is reported in `ensemble.json` and `ensemble.md` instead of
    /// the result, and the rest of the merge goes on.
    pub compute: fn(&[MemberRun<'_>]) -> anyhow::Result<Option<PooledResult>>,
}

/// A pooled result: its JSON and its text for `ensemble.md`.
#[derive(Debug, Clone, PartialEq)]
pub struct PooledResult {
    /// Written as `ensemble.json`'s `pooled.<name>`.
    pub json: Value,
    /// The body of its section in `ensemble.md`.
    pub markdown: String,
}

/// One finished member as a [`Pooled`] result sees it.
#[derive(Debug, Clone, Copy)]
pub struct MemberRun<'a> {
    /// Its seed.
    pub seed: u64,
    /// Its directory (`DIR/seed-NNNN`).
    pub dir: &'a Path,
    /// Its `run.json`.
    pub manifest: &'a RunManifest,
}

/// What a model's ensemble combines: the curves averaged over the members and the results
/// pooled over them.
#[derive(Debug, Clone, Copy, Default)]
pub struct Combine<'a> {
    /// The curves averaged over the members.
    pub curves: &'a [Curve],
    /// The results computed from all members together.
    pub pooled: &'a [Pooled],
}

impl<'a> From<&'a [Curve]> for Combine<'a> {
    fn from(curves: &'a [Curve]) -> Self {
        Combine {
            curves,
            pooled: &[],
        }
    }
}

/// Mean, standard deviation (n - 1 in the denominator), standard error and count of one scalar
/// over the members.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ScalarStats {
    /// Mean over the members.
    pub mean: f64,
    /// Sample standard deviation (0 for one member).
    pub std: f64,
    /// Standard error of the mean, `std / sqrt(n)`.
    pub stderr: f64,
    /// Members that reported it.
    pub n: usize,
}

impl ScalarStats {
    /// The statistics of `values` (not empty), by Welford's update
    /// ([`core_lattice::stats::Welford`], as every mean and error in the workspace).
    pub fn of(values: &[f64]) -> Self {
        let mut w = core_lattice::stats::Welford::new();
        values.iter().for_each(|&v| w.push(v));
        let n = values.len();
        let (std, stderr) = if n > 1 {
            (w.std_dev(), w.std_error())
        } else {
            (0.0, 0.0)
        };
        ScalarStats {
            mean: w.mean(),
            std,
            stderr,
            n,
        }
    }
}

/// What [`merge`] combined.
#[derive(Debug, Clone, PartialEq)]
pub struct MergeReport {
    /// Members with a `run.json`.
    pub members: usize,
    /// Member directories without one (unfinished or failed).
    pub unfinished: Vec<String>,
    /// Members left out because their `run.json` cannot be read, with the reason.
    pub invalid: Vec<String>,
    /// Files written.
    pub files: Vec<PathBuf>,
}

/// A finished member.
struct Member {
    seed: u64,
    dir: PathBuf,
    manifest: RunManifest,
}

/// Reads every `seed-*` member of `dir` and writes the combined result (see the module docs).
/// Fails when no member has finished, when a member is another model's, or when the members
/// were run with different parameters (an average over them would mean nothing).
pub fn merge(dir: &Path, program: &str, curves: &[Curve]) -> anyhow::Result<MergeReport> {
    merge_with(dir, program, Combine::from(curves))
}

/// [`merge`] with the model's pooled results too ([`Combine`]).
pub fn merge_with(dir: &Path, program: &str, combine: Combine<'_>) -> anyhow::Result<MergeReport> {
    let curves = combine.curves;
    let mut members = Vec::new();
    let mut unfinished = Vec::new();
    let mut invalid = Vec::new();
    let entries = std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))?;
    for entry in entries {
        let entry = entry.with_context(|| format!("reading {}", dir.display()))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if !name.starts_with("seed-") || !entry.path().is_dir() {
            continue;
        }
        let path = entry.path().join("run.json");
        if !path.exists() {
            unfinished.push(name);
            continue;
        }
        let manifest = match RunManifest::read(&path) {
            Ok(m) => m,
            Err(e) => {
                // A truncated or foreign file: reported, and the other members combined.
                invalid.push(format!("{name}: {}: {e}", path.display()));
                continue;
            }
        };
        if manifest.model != program {
            bail!(
                "{} is a {} run, not a {program} run",
                path.display(),
                manifest.model
            );
        }
        members.push(Member {
            seed: manifest.seed,
            dir: entry.path(),
            manifest,
        });
    }
    if members.is_empty() {
        bail!("no finished member (seed-*/run.json) in {}", dir.display());
    }
    members.sort_by_key(|m| m.seed);
    unfinished.sort();
    invalid.sort();
    for why in &invalid {
        tracing::warn!("member left out: {why}");
    }
    let first = &members[0];
    for m in &members[1..] {
        let differ = crate::cli::labelled_differences(
            &first.manifest.params,
            &m.manifest.params,
            (
                &format!("for seed {}", first.seed),
                &format!("for seed {}", m.seed),
            ),
            &[],
        );
        if !differ.is_empty() {
            bail!(
                "the members were run with different parameters ({}); an ensemble needs one set",
                differ.join("; ")
            );
        }
    }

    // Scalars: every number in `results`, and the run's time and memory.
    let mut scalars: BTreeMap<String, Vec<(u64, f64)>> = BTreeMap::new();
    for m in &members {
        let mut add = |k: &str, v: Option<f64>| {
            if let Some(v) = v.filter(|v| v.is_finite()) {
                scalars.entry(k.to_owned()).or_default().push((m.seed, v));
            }
        };
        for (k, v) in &m.manifest.results {
            add(k, v.as_f64().filter(|_| v.is_number()));
        }
        add("wall_seconds", Some(m.manifest.wall_seconds));
        add("cpu_seconds", m.manifest.cpu_seconds);
        add(
            "peak_rss_bytes",
            m.manifest.peak_rss_bytes.map(|b| b as f64),
        );
    }
    let results: BTreeMap<&str, ScalarStats> = scalars
        .iter()
        .map(|(k, v)| {
            let values: Vec<f64> = v.iter().map(|p| p.1).collect();
            (k.as_str(), ScalarStats::of(&values))
        })
        .collect();

    let mut files = Vec::new();
    let mut curve_files = Map::new();
    for c in curves {
        if let Some(path) = average_curve(dir, &members, c)? {
            let stem = Path::new(c.file)
                .file_stem()
                .map_or_else(|| c.file.to_owned(), |s| s.to_string_lossy().into_owned());
            curve_files.insert(
                stem,
                json!({"csv": path.file_name().map(|f| f.to_string_lossy().into_owned()),
                       "png": path.with_extension("png").file_name().map(|f| f.to_string_lossy().into_owned())}),
            );
            files.push(path.with_extension("png"));
            files.push(path);
        }
    }

    let per_member: Vec<Value> = members
        .iter()
        .map(|m| {
            let mut r = Map::new();
            for (k, v) in &scalars {
                if let Some((_, x)) = v.iter().find(|(s, _)| *s == m.seed) {
                    r.insert(k.clone(), json!(x));
                }
            }
            json!({
                "seed": m.seed,
                "dir": m.dir.file_name().map(|f| f.to_string_lossy().into_owned()),
                "results": r,
            })
        })
        .collect();
    let runs: Vec<MemberRun<'_>> = members
        .iter()
        .map(|m| MemberRun {
            seed: m.seed,
            dir: &m.dir,
            manifest: &m.manifest,
        })
        .collect();
    let mut pooled_json = Map::new();
    let mut pooled_md = Vec::new();
    for p in combine.pooled {
        match (p.compute)(&runs) {
            Ok(None) => {}
            Ok(Some(r)) => {
                pooled_json.insert(p.name.to_owned(), r.json);
                pooled_md.push((p.title, r.markdown));
            }
            Err(e) => {
                let why = format!("{e:#}");
                tracing::warn!("{}: {why}", p.name);
                pooled_json.insert(p.name.to_owned(), json!({ "error": why }));
                pooled_md.push((p.title, format!("Not computed: {why}.")));
            }
        }
    }
    let doc = json!({
        "model": program,
        "version": first.manifest.version,
        "params": first.manifest.params,
        "members": members.len(),
        "seeds": members.iter().map(|m| m.seed).collect::<Vec<_>>(),
        "unfinished": unfinished,
        "invalid": invalid,
        "results": results,
        "per_member": per_member,
        "curves": curve_files,
        "pooled": pooled_json,
    });
    let mut bytes = serde_json::to_vec_pretty(&doc)?;
    bytes.push(b'\n');
    let json_path = dir.join("ensemble.json");
    write_atomic(&json_path, &bytes).with_context(|| format!("writing {}", json_path.display()))?;
    files.push(json_path);

    let md_path = dir.join("ensemble.md");
    write_atomic(
        &md_path,
        markdown(
            program,
            &members,
            &unfinished,
            &invalid,
            &results,
            curves,
            &doc,
            &pooled_md,
        )
        .as_bytes(),
    )
    .with_context(|| format!("writing {}", md_path.display()))?;
    files.push(md_path);
    Ok(MergeReport {
        members: members.len(),
        unfinished,
        invalid,
        files,
    })
}

/// `ensemble.md`: the parameters, the members, the results table, the curves.
#[allow(clippy::too_many_arguments)]
fn markdown(
    program: &str,
    members: &[Member],
    unfinished: &[String],
    invalid: &[String],
    results: &BTreeMap<&str, ScalarStats>,
    curves: &[Curve],
    doc: &Value,
    pooled: &[(&str, String)],
) -> String {
    let mut s = String::new();
    let seeds: Vec<String> = members.iter().map(|m| m.seed.to_string()).collect();
    let _ = writeln!(s, "# {program} ensemble of {} members\n", members.len());
    let _ = writeln!(s, "Seeds: {}.", seeds.join(", "));
    if !unfinished.is_empty() {
        let _ = writeln!(s, "Not finished (not included): {}.", unfinished.join(", "));
    }
    for why in invalid {
        let _ = writeln!(s, "Left out, unreadable: {why}.");
    }
    let _ = writeln!(
        s,
        "\nParameters (the same for every member):\n\n```json\n{}\n```\n",
        serde_json::to_string_pretty(&doc["params"]).unwrap_or_default()
    );
    let _ = writeln!(
        s,
        "| result | mean | std | stderr | n |\n|---|---|---|---|---|"
    );
    for (k, r) in results {
        let _ = writeln!(
            s,
            "| {k} | {} | {} | {} | {} |",
            num(r.mean),
            num(r.std),
            num(r.stderr),
            r.n
        );
    }
    let _ = writeln!(
        s,
        "\nstd is the sample standard deviation over the members, stderr = std / sqrt(n) the \
         standard error of the mean; per-member values are in ensemble.json."
    );
    for (title, body) in pooled {
        let _ = writeln!(s, "\n## {title}\n\n{body}");
    }
    for c in curves {
        if let Some(stem) = Path::new(c.file).file_stem().map(|s| s.to_string_lossy()) {
            if doc["curves"].get(stem.as_ref()).is_some() {
                let _ = writeln!(
                    s,
                    "\n## {}\n\nMean over the members with a band of +- one standard error: \
                     `ensemble_{stem}.csv`.\n\n![{}](ensemble_{stem}.png)",
                    c.title, c.title
                );
            }
        }
    }
    s
}

/// A number for the table: enough digits for a mean and its error.
fn num(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 1e6 || v.abs() < 1e-3 {
        format!("{v:.4e}")
    } else {
        format!("{v:.6}")
    }
}

/// Averages curve `c` over the members that wrote it; writes its CSV and PNG and returns the
/// CSV's path (`None` if no member wrote the file).
fn average_curve(dir: &Path, members: &[Member], c: &Curve) -> anyhow::Result<Option<PathBuf>> {
    // x (as bits, ordered by value) -> per y column, the members' values.
    let mut table: BTreeMap<OrdF64, Vec<Vec<f64>>> = BTreeMap::new();
    let mut with_file = 0usize;
    for m in members {
        let path = m.dir.join(c.file);
        if !path.exists() {
            continue;
        }
        with_file += 1;
        let mut rdr =
            csv::Reader::from_path(&path).with_context(|| format!("reading {}", path.display()))?;
        let headers = rdr.headers()?.clone();
        let col = |name: &str| {
            headers
                .iter()
                .position(|h| h == name)
                .ok_or_else(|| anyhow!("{} has no column `{name}`", path.display()))
        };
        let xi = col(c.x)?;
        let yi: Vec<usize> = c.ys.iter().map(|y| col(y)).collect::<Result<_, _>>()?;
        let mut seen = std::collections::BTreeSet::new();
        for row in rdr.records() {
            let row = row.with_context(|| format!("reading {}", path.display()))?;
            let parse = |i: usize| -> anyhow::Result<f64> {
                row.get(i).unwrap_or("").parse::<f64>().with_context(|| {
                    format!(
                        "{}: `{}` is not a number",
                        path.display(),
                        row.get(i).unwrap_or("")
                    )
                })
            };
            let x = OrdF64(parse(xi)?);
            if !seen.insert(x) {
                continue;
            }
            let entry = table
                .entry(x)
                .or_insert_with(|| vec![Vec::new(); c.ys.len()]);
            for (k, &i) in yi.iter().enumerate() {
                entry[k].push(parse(i)?);
            }
        }
        // Members without a row here count as `missing` (filled below).
        if let Some(fill) = c.missing {
            for (x, cols) in table.iter_mut() {
                if !seen.contains(x) {
                    for v in cols.iter_mut() {
                        v.push(fill);
                    }
                }
            }
        }
    }
    if with_file == 0 {
        return Ok(None);
    }
    if let Some(fill) = c.missing {
        // x values first met in a later member lack the earlier members' fill.
        for cols in table.values_mut() {
            for v in cols.iter_mut() {
                while v.len() < with_file {
                    v.push(fill);
                }
            }
        }
    } else {
        table.retain(|_, cols| cols[0].len() == with_file);
    }
    let stem = Path::new(c.file)
        .file_stem()
        .map_or_else(|| c.file.to_owned(), |s| s.to_string_lossy().into_owned());
    let csv_path = dir.join(format!("ensemble_{stem}.csv"));
    let mut header = vec![c.x.to_owned()];
    for y in c.ys {
        header.extend([
            format!("{y}_mean"),
            format!("{y}_std"),
            format!("{y}_stderr"),
        ]);
    }
    header.push("members".into());
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(&header)?;
    let mut series: Vec<(Points, Band)> = vec![Default::default(); c.ys.len()];
    for (x, cols) in &table {
        let mut rec = vec![x.0.to_string()];
        for (k, v) in cols.iter().enumerate() {
            let s = ScalarStats::of(v);
            rec.extend([s.mean.to_string(), s.std.to_string(), s.stderr.to_string()]);
            series[k].0.push((x.0, s.mean));
            series[k]
                .1
                .push((x.0, s.mean - s.stderr, s.mean + s.stderr));
        }
        rec.push(with_file.to_string());
        w.write_record(&rec)?;
    }
    let bytes = w.into_inner().map_err(|e| anyhow!("{e}"))?;
    write_atomic(&csv_path, &bytes).with_context(|| format!("writing {}", csv_path.display()))?;
    if !table.is_empty() {
        let chart = Chart {
            title: format!(
                "{} ({} members, mean +- standard error)",
                c.title, with_file
            ),
            x_label: c.axes.0.into(),
            y_label: c.axes.1.into(),
            log_x: c.log_x,
            log_y: c.log_y,
            series: c
                .ys
                .iter()
                .zip(series)
                .enumerate()
                .map(|(i, (y, (pts, band)))| {
                    let s = Series::new(*y, pts, Style::Line).with_band(band);
                    match c.colours.get(i) {
                        Some(&c) => s.with_colour(c),
                        None => s,
                    }
                })
                .collect(),
        };
        write_png(&chart, &csv_path.with_extension("png"))?;
    }
    Ok(Some(csv_path))
}

/// A curve's `(x, mean)` points.
type Points = Vec<(f64, f64)>;
/// A curve's `(x, mean - stderr, mean + stderr)` band.
type Band = Vec<(f64, f64, f64)>;

/// An `f64` ordered by value (curve abscissas are finite).
#[derive(Debug, Clone, Copy, PartialEq)]
struct OrdF64(f64);

impl Eq for OrdF64 {}

impl PartialOrd for OrdF64 {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for OrdF64 {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalar_stats_match_hand_values() {
        let s = ScalarStats::of(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(s.mean, 2.5);
        assert!((s.std - (5.0f64 / 3.0).sqrt()).abs() < 1e-15);
        assert!((s.stderr - s.std / 2.0).abs() < 1e-15);
        assert_eq!(s.n, 4);
        let one = ScalarStats::of(&[7.0]);
        assert_eq!((one.mean, one.std, one.stderr, one.n), (7.0, 0.0, 0.0, 1));
    }

    fn member(dir: &Path, seed: u64, model: &str, x: f64, rows: &str) {
        let d = dir.join(format!("seed-{seed:04}"));
        std::fs::create_dir_all(&d).unwrap();
        let mut results = Map::new();
        results.insert("x".into(), json!(x));
        results.insert("label".into(), json!("text is skipped"));
        let m = RunManifest {
            model: model.into(),
            version: "0".into(),
            seed,
            threads: 1,
            params: json!({"size": 8}),
            wall_seconds: 1.0,
            cpu_seconds: None,
            peak_rss_bytes: None,
            provenance: None,
            results,
        };
        m.write(&d).unwrap();
        std::fs::write(d.join("sizes.csv"), rows).unwrap();
    }

    const SIZES: Curve = Curve {
        file: "sizes.csv",
        x: "size",
        ys: &["count"],
        missing: Some(0.0),
        title: "sizes",
        axes: ("size", "clusters"),
        log_x: false,
        log_y: false,
        colours: &[],
    };

    #[test]
    fn merge_averages_scalars_and_curves() {
        let dir = tempfile::tempdir().unwrap();
        member(dir.path(), 1, "m", 1.0, "size,count\n1,4\n2,2\n");
        member(dir.path(), 2, "m", 3.0, "size,count\n1,2\n3,1\n");
        std::fs::create_dir_all(dir.path().join("seed-0003")).unwrap();
        std::fs::create_dir_all(dir.path().join("seed-0004")).unwrap();
        std::fs::write(
            dir.path().join("seed-0004/run.json"),
            b"{\"model\": \"m\", ",
        )
        .unwrap();
        let r = merge(dir.path(), "m", &[SIZES]).unwrap();
        assert_eq!(r.members, 2);
        assert_eq!(r.unfinished, vec!["seed-0003".to_string()]);
        assert_eq!(r.invalid.len(), 1);
        assert!(r.invalid[0].starts_with("seed-0004: "), "{:?}", r.invalid);
        let doc: Value =
            serde_json::from_slice(&std::fs::read(dir.path().join("ensemble.json")).unwrap())
                .unwrap();
        assert_eq!(doc["results"]["x"]["mean"], json!(2.0));
        assert_eq!(doc["results"]["x"]["n"], json!(2));
        assert!(doc["results"].get("label").is_none());
        let csv = std::fs::read_to_string(dir.path().join("ensemble_sizes.csv")).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[0], "size,count_mean,count_std,count_stderr,members");
        // Size 2 is missing from member 2 and size 3 from member 1: they count as 0.
        assert!(lines[1].starts_with("1,3,"), "{csv}");
        assert!(lines[2].starts_with("2,1,"), "{csv}");
        assert!(lines[3].starts_with("3,0.5,"), "{csv}");
        assert!(dir.path().join("ensemble_sizes.png").exists());
        assert!(
            std::fs::read_to_string(dir.path().join("ensemble.md"))
                .unwrap()
                .contains("| x | 2")
        );
    }

    #[test]
    fn mixed_parameters_models_or_no_members_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        assert!(
            merge(dir.path(), "m", &[])
                .unwrap_err()
                .to_string()
                .contains("no finished member")
        );
        member(dir.path(), 1, "m", 1.0, "size,count\n");
        member(dir.path(), 2, "other", 1.0, "size,count\n");
        assert!(
            merge(dir.path(), "m", &[])
                .unwrap_err()
                .to_string()
                .contains("not a m run")
        );
        std::fs::remove_dir_all(dir.path().join("seed-0002")).unwrap();
        member(dir.path(), 2, "m", 1.0, "size,count\n");
        let p = dir.path().join("seed-0002/run.json");
        let mut m = RunManifest::read(&p).unwrap();
        m.params = json!({"size": 16});
        m.write(dir.path().join("seed-0002")).unwrap();
        let e = merge(dir.path(), "m", &[]).unwrap_err().to_string();
        assert!(
            e.contains("different parameters") && e.contains("size"),
            "{e}"
        );
    }
}
