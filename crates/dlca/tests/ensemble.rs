//! `dlca --seeds`: members run, fail alone, restart, and combine (`ensemble.json`), and
//! `--merge` rebuilds the combined result.

use std::path::Path;

#[test]
fn ensembles_run_combine_restart_and_merge() {
    let dir = tempfile::tempdir().unwrap();
    run_cli::testing::ensemble_contract(
        Path::new(env!("CARGO_BIN_EXE_dlca")),
        "dlca",
        dir.path(),
        &["--size", "32", "--fill", "0.1", "--target-clusters", "4"],
        "sweeps",
    );
}

/// With `--gyration` an ensemble reports the fractal dimension pooled over every member's
/// clusters (`pooled.fractal_dimension`, the library's `pooled_summary` of the members'
/// `clusters.csv`), beside the mean of the members' own fits; `--merge` rebuilds it. Without
/// `--gyration` there is nothing to pool.
#[test]
fn ensembles_with_gyration_pool_the_fractal_dimension() {
    let dir = tempfile::tempdir().unwrap();
    let run = |out: &Path, extra: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_dlca"))
            .args(["--size", "96", "--fill", "0.02", "--target-clusters", "8"])
            .args(["--seeds", "1..=3", "--jobs", "1", "-qq", "--out"])
            .arg(out)
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = std::fs::read_to_string(out.join("ensemble.json")).unwrap();
        serde_json::from_str::<serde_json::Value>(&text).unwrap()
    };
    let out = dir.path().join("g");
    let e = run(&out, &["--gyration"]);
    let pooled = &e["pooled"]["fractal_dimension"];
    let runs: Vec<_> = (1..=3)
        .map(|s| {
            dlca::output::read_clusters(&out.join(format!("seed-{s:04}/clusters.csv"))).unwrap()
        })
        .collect();
    assert_eq!(*pooled, dlca::output::pooled_summary(&runs, 10).unwrap());
    assert_eq!(pooled["members"], 3);
    assert!(pooled["fractal_dimension_stderr"].as_f64().unwrap() > 0.0);
    assert_eq!(
        pooled["per_member_mean"].as_f64().unwrap(),
        e["results"]["fractal_dimension"]["mean"].as_f64().unwrap()
    );
    let md = std::fs::read_to_string(out.join("ensemble.md")).unwrap();
    assert!(
        md.contains("## Fractal dimension pooled over the members"),
        "{md}"
    );
    // --merge rebuilds the same result from the members.
    std::fs::remove_file(out.join("ensemble.json")).unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_dlca"))
        .arg("--merge")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success());
    let text = std::fs::read_to_string(out.join("ensemble.json")).unwrap();
    let merged: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(merged["pooled"], e["pooled"]);

    let plain = run(&dir.path().join("p"), &[]);
    assert_eq!(plain["pooled"], serde_json::json!({}));
}
