//! The `animat` binary: outputs, config files, and one-line errors with exit code 2 and
//! nothing written.

use std::path::Path;
use std::process::{Command, Output};

fn animat(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_animat"))
        .args(args)
        .output()
        .expect("animat runs")
}

fn run_json(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("run.json")).unwrap()).unwrap()
}

const SMALL: [&str; 8] = [
    "--foxes",
    "30",
    "--rabbits",
    "300",
    "--start-radius",
    "40",
    "--steps",
    "40",
];

#[test]
fn writes_every_output_and_grids_agree() {
    let tmp = tempfile::tempdir().unwrap();
    let mut hashes = Vec::new();
    for grid in ["none", "15", "60", "vision"] {
        let out = tmp.path().join(format!("run-{grid}"));
        let mut args = SMALL.to_vec();
        args.extend([
            "--seed",
            "3",
            "--grid-box",
            grid,
            "--timing",
            "--snapshot-every",
            "25",
            "--positions",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ]);
        let o = animat(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let j = run_json(&out);
        let r = &j["results"];
        assert_eq!(j["model"], "animat");
        assert_eq!(j["seed"], 3);
        assert_eq!(r["steps"], 40);
        assert_eq!(r["state_hash"].as_str().unwrap().len(), 16);
        assert!(r["distance_evaluations"].as_u64().unwrap() > 0);
        let pops = std::fs::read_to_string(out.join("populations.csv")).unwrap();
        assert!(
            pops.starts_with("step,foxes,rabbits,search_seconds,distance_evaluations\n0,30,300,")
        );
        assert_eq!(pops.lines().count(), 42);
        let last: Vec<&str> = pops.lines().last().unwrap().split(',').collect();
        assert_eq!(last[1], r["foxes"].to_string());
        assert_eq!(last[2], r["rabbits"].to_string());
        let positions = std::fs::read_to_string(out.join("positions.csv")).unwrap();
        let live = r["foxes"].as_u64().unwrap() + r["rabbits"].as_u64().unwrap();
        assert_eq!(positions.lines().count() as u64, live + 1);
        for s in [
            "snapshot_000000.png",
            "snapshot_000025.png",
            "snapshot_000040.png",
        ] {
            assert!(
                std::fs::read(out.join(s)).unwrap().starts_with(b"\x89PNG"),
                "{s}"
            );
        }
        hashes.push((
            r["state_hash"].clone(),
            pops.lines()
                .map(|l| l.split(',').take(3).collect::<Vec<_>>().join(","))
                .collect::<Vec<_>>(),
        ));
    }
    assert!(hashes.windows(2).all(|w| w[0] == w[1]));
}

#[test]
fn default_config_file_reproduces_the_defaults() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/animat-default.toml");
    let a = tmp.path().join("a");
    let b = tmp.path().join("b");
    let o = animat(&["--steps", "5", "--quiet", "--out", a.to_str().unwrap()]);
    assert!(o.status.success());
    let o = animat(&[
        "--steps",
        "5",
        "--quiet",
        "--config",
        cfg.to_str().unwrap(),
        "--out",
        b.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(run_json(&a)["results"], run_json(&b)["results"]);
    assert_eq!(run_json(&a)["params"], run_json(&b)["params"]);
}

#[test]
fn bad_input_is_one_line_exit_2_nothing_written() {
    let tmp = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| {
        let p = tmp.path().join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let unknown_key = write("k.toml", "foxes = 3\n\nwolves = 2\n");
    let malformed = write("m.toml", "foxes = 3\nrabbits = = 4\n");
    let bad_rule = write("r.toml", "rabbit_rules = [\"flee\", \"dig\"]\n");
    let bad_p = write("p.toml", "fox_breed_p = 1.5\n");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (vec!["--grid-box".into(), "0".into()], "grid_box = 0"),
        (vec!["--grid-box".into(), "big".into()], "--grid-box"),
        (vec!["--vision".into(), "0".into()], "vision = 0"),
        (
            vec!["--config".into(), unknown_key],
            "line 3: unknown field `wolves`",
        ),
        (vec!["--config".into(), malformed], "line 2:"),
        (
            vec!["--config".into(), bad_rule],
            "unknown rabbit rule \"dig\"",
        ),
        (
            vec!["--config".into(), bad_p],
            "fox_breed_p = 1.5 is outside the accepted range [0, 1]",
        ),
        (vec!["--density".into(), "0.9".into()], "--density 0.9"),
        (vec!["--steps".into(), "many".into()], "invalid value"),
    ];
    for (i, (args, want)) in cases.into_iter().enumerate() {
        let out = tmp.path().join(format!("out{i}"));
        let mut all = args.clone();
        all.extend(["--out".into(), out.to_str().unwrap().into()]);
        let all: Vec<&str> = all.iter().map(String::as_str).collect();
        let o = animat(&all);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} wrote {}", out.display());
    }
}
