//! The usage-error contract of `animat`: every bad flag, config file, checkpoint or output
//! location is refused before any work with exit code 2, one line on stderr naming the culprit,
//! and nothing created.

use run_cli::testing::refusals;
use std::path::Path;
use std::process::Command;

const ANIMAT: &str = env!("CARGO_BIN_EXE_animat");

/// The small world of the fixtures' checkpoint.
const SMALL: [&str; 6] = ["--foxes", "20", "--rabbits", "200", "--start-radius", "20"];

/// Fixtures: a regular file, an empty directory, config files each with one mistake, a
/// checkpoint of a 20-step run of [`SMALL`] (seed 1) in `ck/`, and broken copies of it:
/// truncated, one byte flipped, another model's.
fn fixtures(dir: &Path) {
    std::fs::write(dir.join("file"), b"not a directory").unwrap();
    std::fs::create_dir(dir.join("empty")).unwrap();
    for (name, text) in [
        ("unknown.toml", "foxes = 10\nwings = 2\n"),
        ("broken.toml", "foxes = [10\n"),
        ("typed.toml", "foxes = \"many\"\n"),
        ("norules.toml", "fox_rules = []\n"),
        ("hungry.toml", "hungry_at = 40\nstarve = 30\n"),
        ("prob.toml", "fox_breed_p = 2.0\n"),
        ("rule.toml", "rabbit_rules = [\"flee\", \"fly\"]\n"),
        ("twice.toml", "fox_rules = [\"eat\", \"eat\"]\n"),
        ("crowd.toml", "crowd_radius = 0\n"),
    ] {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let o = Command::new(ANIMAT)
        .args(SMALL)
        .args([
            "--steps",
            "20",
            "--checkpoint-every",
            "10",
            "--out",
            "ck",
            "-qq",
        ])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    run_cli::testing::broken_checkpoints(dir, "dlca");
}

#[test]
fn bad_inputs_are_refused_before_any_work() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    fixtures(dir);
    let with = |extra: &[&'static str]| -> Vec<&'static str> {
        let mut v = vec!["--out", "out"];
        v.extend_from_slice(extra);
        v
    };
    let small = |extra: &[&'static str]| -> Vec<&'static str> {
        let mut v = with(&SMALL);
        v.extend_from_slice(extra);
        v
    };
    let owned: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--steps", "10"], "--out"),
        (with(&["--steps", "-1"]), "-1"),
        (with(&["--foxes", "many"]), "many"),
        (with(&["--vision", "0"]), "--vision 0 is outside"),
        (with(&["--grid-box", "0"]), "--grid-box 0 is outside"),
        (with(&["--grid-box", "huge"]), "huge"),
        (with(&["--start-radius", "5"]), "start disc of radius 5"),
        (
            with(&["--start-radius", "-3"]),
            "'-3' for '--start-radius <N>': -3 is negative",
        ),
        (with(&["--density", "0"]), "--density 0 is outside"),
        (with(&["--density", "0.6"]), "--density 0.6 is outside"),
        (with(&["--density", "1e-300"]), "--density 1e-300"),
        (
            with(&["--density", "0.1", "--start-radius", "9"]),
            "--start-radius",
        ),
        (with(&["--snapshot-every", "0"]), "--snapshot-every 0"),
        (
            with(&["--checkpoint-every", "0"]),
            "0 is outside the accepted range 1..",
        ),
        (
            with(&["--checkpoint-every", "1.5"]),
            "1.5 is not a whole number",
        ),
        (with(&["--snapshot-every", "1e-1"]), "not a whole number"),
        (
            with(&["--step", "10"]),
            "tip: a similar argument exists: '--steps'",
        ),
        (with(&["--seed", "1-10"]), "use --seeds 1..=10"),
        (with(&["--snapshot-every", "5", "--png-size", "8"]), "8"),
        (
            with(&["--snapshot-every", "5", "--png-size", "65537"]),
            "65537",
        ),
        (
            with(&["--png-size", "512"]),
            "--snapshot-every and --animate",
        ),
        (
            with(&["--frame-radius", "50"]),
            "--snapshot-every and --animate",
        ),
        (
            with(&["--snapshot-every", "5", "--frame-radius", "0"]),
            "--frame-radius 0",
        ),
        (
            with(&["--animate", "--png-size", "20000"]),
            "--png-size 20000 with --animate",
        ),
        (
            with(&["--animate", "--animate-every", "0"]),
            "--animate-every 0",
        ),
        (with(&["--animate-every", "3"]), "--animate"),
        (with(&["--heartbeat", "-5"]), "-5"),
        (with(&["--wings", "2"]), "--wings"),
        (with(&["--config", "missing.toml"]), "missing.toml"),
        (with(&["--config", "unknown.toml"]), "wings"),
        (with(&["--config", "broken.toml"]), "broken.toml, line 1"),
        (
            with(&["--config", "typed.toml"]),
            "'many' for '--foxes <N>'",
        ),
        (with(&["--config", "norules.toml"]), "fox_rules is empty"),
        (
            with(&["--config", "hungry.toml"]),
            "hungry_at = 40 is above starve = 30",
        ),
        (
            with(&["--config", "prob.toml"]),
            "--fox-breed-p 2 is outside",
        ),
        (
            with(&["--config", "rule.toml"]),
            "unknown rabbit rule \"fly\"",
        ),
        (with(&["--config", "twice.toml"]), "listed twice"),
        (
            with(&["--config", "crowd.toml"]),
            "--crowd-radius 0 is outside",
        ),
        (vec!["--out", "file"], "--out file"),
        (vec!["--out", "file/sub"], "--out file/sub"),
        (small(&["--resume", "empty"]), "empty/checkpoint.bin"),
        (small(&["--resume", "trunc"]), "truncated"),
        (small(&["--resume", "flip"]), "corrupted"),
        (small(&["--resume", "other"]), "'dlca', not 'animat'"),
        (
            small(&["--resume", "ck", "--seed", "2"]),
            "--seed 1 in the checkpoint, 2 given",
        ),
        (
            small(&["--resume", "ck", "--vision", "30"]),
            "--vision 60 in the checkpoint, 30 given",
        ),
        (
            small(&["--resume", "ck", "--steps", "10"]),
            "has done 20 steps, more than --steps 10",
        ),
    ];
    let cases: Vec<(&[&str], &str)> = owned.iter().map(|(a, c)| (a.as_slice(), *c)).collect();
    assert!(cases.len() >= 30);
    let failures = refusals(Path::new(ANIMAT), "animat", dir, &cases);
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
