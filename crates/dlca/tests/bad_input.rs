//! The usage-error contract of `dlca`: every bad flag, checkpoint or output location is
//! refused before any work with exit code 2, one line on stderr naming the culprit, and nothing
//! created.

use run_cli::testing::refusals;
use std::path::Path;
use std::process::Command;

const DLCA: &str = env!("CARGO_BIN_EXE_dlca");

/// Fixtures: a regular file, an empty directory, a checkpoint of a 32x32 run (fill 0.1, seed
/// 1) in `ck/`, and broken copies: truncated, one byte flipped, another model's.
fn fixtures(dir: &Path) {
    std::fs::write(dir.join("file"), b"not a directory").unwrap();
    // Config files: an unknown key on line 2, malformed TOML on line 1.
    std::fs::write(dir.join("unknown.toml"), b"seed = 3\nwalkers = 3\n").unwrap();
    std::fs::write(dir.join("broken.toml"), b"seed = [\n").unwrap();
    std::fs::create_dir(dir.join("empty")).unwrap();
    let o = Command::new(DLCA)
        .args(["--size", "32", "--fill", "0.1", "--target-clusters", "1"])
        .args(["--checkpoint-every", "2", "--out", "ck", "-qq"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    run_cli::testing::broken_checkpoints(dir, "dla");
}

#[test]
fn bad_inputs_are_refused_before_any_work() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    fixtures(dir);
    let base = ["--size", "32", "--fill", "0.1", "--out", "out"];
    let with = |extra: &[&'static str]| -> Vec<&'static str> {
        let mut v: Vec<&'static str> = base.to_vec();
        v.extend_from_slice(extra);
        v
    };
    let owned: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--size", "32", "--out", "out"], "required"),
        (vec!["--fill", "0.1", "--out", "out"], "--size is required"),
        (vec!["--size", "32", "--fill", "0.1"], "--out"),
        (with(&["--dim", "0"]), "--dim 0"),
        (
            with(&["--config", "missing.toml"]),
            "--config missing.toml: cannot read it",
        ),
        (
            with(&["--config", "unknown.toml"]),
            "line 2: unknown key `walkers`",
        ),
        (
            with(&["--config", "broken.toml"]),
            "--config broken.toml, line",
        ),
        (with(&["--dim", "6"]), "--dim 6"),
        (
            vec!["--size", "0", "--fill", "0.1", "--out", "out"],
            "length on axis 0 is 0",
        ),
        (
            vec!["--size", "32x0.5", "--fill", "0.1", "--out", "out"],
            "32x0.5",
        ),
        (
            vec!["--size", "16x16x16", "--fill", "0.1", "--out", "out"],
            "--size has 3 axes",
        ),
        (
            vec!["--size", "32", "--fill", "0", "--out", "out"],
            "--fill 0 is outside",
        ),
        (
            vec!["--size", "32", "--fill", "1", "--out", "out"],
            "--fill 1 is outside",
        ),
        (
            vec!["--size", "32", "--fill", "1e-9", "--out", "out"],
            "places no particle",
        ),
        (
            vec!["--size", "16", "--particles", "257", "--out", "out"],
            "--particles 257",
        ),
        (
            vec!["--size", "16", "--particles", "0", "--out", "out"],
            "--particles 0",
        ),
        (with(&["--particles", "5"]), "--particles"),
        (with(&["--temperature", "0"]), "--temperature 0"),
        (with(&["--gravity", "1"]), "--gravity 1"),
        (with(&["--gravity", "-0.2"]), "--gravity -0.2"),
        (
            with(&["--mobility-exponent", "-1"]),
            "--mobility-exponent -1",
        ),
        (with(&["--target-clusters", "0"]), "--target-clusters 0"),
        (
            with(&["--grid-box", "3"]),
            "--grid-box 3 is not a power of two",
        ),
        (
            with(&["--grid-box", "16"]),
            "--grid-box 16 does not split the lattice",
        ),
        (
            with(&["--grid-box", "4", "--search", "all-pairs"]),
            "--grid-box is used by",
        ),
        (with(&["--fit-min-size", "0"]), "--fit-min-size 0"),
        (with(&["--boundary", "sticky"]), "unknown boundary"),
        (
            with(&["--boundary", "periodic,wall,wall"]),
            "--boundary has 3 entries",
        ),
        (with(&["--search", "magic"]), "magic"),
        (with(&["--max-memory", "4X"]), "4X"),
        (
            vec![
                "--size",
                "100000",
                "--particles",
                "10",
                "--search",
                "lattice",
                "--out",
                "out",
            ],
            "--max-memory",
        ),
        (with(&["--histogram", "--histogram-sweeps", "1,x"]), "x"),
        (with(&["--histogram-sweeps", "1,2"]), "--histogram"),
        (
            with(&["--checkpoint-every", "0"]),
            "0 is outside the accepted range 1..",
        ),
        (
            with(&["--checkpoint-every", "2.5"]),
            "2.5 is not a whole number",
        ),
        (with(&["--checkpoint-every", "1e30"]), "1e30 is too large"),
        (with(&["--grid-box", "1.5"]), "1.5 is not a whole number"),
        (
            with(&["--histogram", "--histogram-sweeps", "1,2.5"]),
            "2.5 is not a whole number",
        ),
        (
            with(&["--target-cluster", "3"]),
            "tip: a similar argument exists: '--target-clusters'",
        ),
        (with(&["--seed", "1..=4"]), "use --seeds 1..=4"),
        (with(&["--png", "--png-size", "8"]), "8"),
        (with(&["--png", "--png-size", "65537"]), "65537"),
        (with(&["--png-size", "512"]), "--png and --animate"),
        (
            with(&["--animate", "--png-size", "20000"]),
            "--png-size 20000 with --animate",
        ),
        (
            with(&["--animate", "--animate-every", "0"]),
            "--animate-every 0",
        ),
        (with(&["--animate-every", "3"]), "--animate"),
        (with(&["--heartbeat", "soon"]), "soon"),
        (with(&["--frobnicate"]), "--frobnicate"),
        (
            vec!["--size", "32", "--fill", "0.1", "--out", "file"],
            "--out file",
        ),
        (
            vec!["--size", "32", "--fill", "0.1", "--out", "file/sub"],
            "--out file/sub",
        ),
        (with(&["--resume", "empty"]), "empty/checkpoint.bin"),
        (with(&["--resume", "trunc"]), "truncated"),
        (with(&["--resume", "flip"]), "corrupted"),
        (with(&["--resume", "other"]), "'dla', not 'dlca'"),
        (
            with(&["--resume", "ck", "--seed", "2"]),
            "--seed 1 in the checkpoint, 2 given",
        ),
        (
            vec![
                "--size", "32", "--fill", "0.2", "--out", "out", "--resume", "ck",
            ],
            "--fill/--particles fill 0.1 in the checkpoint, fill 0.2 given",
        ),
        (
            with(&["--resume", "ck", "--gravity", "0.5"]),
            "--gravity 0.0 in the checkpoint, 0.5 given",
        ),
    ];
    let cases: Vec<(&[&str], &str)> = owned.iter().map(|(a, c)| (a.as_slice(), *c)).collect();
    assert!(cases.len() >= 30);
    let failures = refusals(Path::new(DLCA), "dlca", dir, &cases);
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
