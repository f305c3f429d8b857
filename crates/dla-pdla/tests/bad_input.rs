//! The usage-error contract of `dla`: every bad flag, checkpoint or output location is refused
//! before any work with exit code 2, one line on stderr naming the culprit, and nothing created.

use run_cli::testing::{permissions_are_bypassed, refusals};
use std::path::Path;
use std::process::Command;

const DLA: &str = env!("CARGO_BIN_EXE_dla");

/// A run of `args` in `dir` that must succeed (fixtures).
fn run_ok(dir: &Path, args: &[&str]) {
    let o = Command::new(DLA)
        .args(args)
        .arg("-qq")
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Fixtures: a regular file, an empty directory, a good 2D checkpoint of 300 particles (seed
/// 1, defaults) in `ck/`, a 3D one in `ck3/`, and broken copies: truncated, one byte flipped,
/// another model's, without its positions log, with another run's log.
fn fixtures(dir: &Path) {
    std::fs::write(dir.join("file"), b"not a directory").unwrap();
    // Config files: an unknown key on line 2, malformed TOML on line 1.
    std::fs::write(dir.join("unknown.toml"), b"seed = 3\nwalkers = 3\n").unwrap();
    std::fs::write(dir.join("broken.toml"), b"seed = [\n").unwrap();
    std::fs::create_dir(dir.join("empty")).unwrap();
    run_ok(
        dir,
        &[
            "--particles",
            "300",
            "--checkpoint-every",
            "100",
            "--out",
            "ck",
        ],
    );
    run_ok(
        dir,
        &[
            "--dim",
            "3",
            "--particles",
            "300",
            "--checkpoint-every",
            "100",
            "--out",
            "ck3",
        ],
    );
    run_cli::testing::broken_checkpoints(dir, "animat");
    // A checkpoint without its positions log, and one with another run's log.
    std::fs::create_dir(dir.join("nolog")).unwrap();
    std::fs::copy(
        dir.join("ck/checkpoint.bin"),
        dir.join("nolog/checkpoint.bin"),
    )
    .unwrap();
    run_ok(
        dir,
        &[
            "--particles",
            "300",
            "--seed",
            "2",
            "--positions",
            "npy",
            "--out",
            "seed2",
        ],
    );
    std::fs::create_dir(dir.join("badlog")).unwrap();
    std::fs::copy(
        dir.join("ck/checkpoint.bin"),
        dir.join("badlog/checkpoint.bin"),
    )
    .unwrap();
    std::fs::copy(
        dir.join("seed2/positions.npy"),
        dir.join("badlog/positions.npy"),
    )
    .unwrap();
}

#[test]
fn bad_inputs_are_refused_before_any_work() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    fixtures(dir);
    // Every case but the first two names --particles and --out where it needs them.
    let p = ["--particles", "300", "--out", "out"];
    let with = |extra: &[&'static str]| -> Vec<&'static str> {
        let mut v: Vec<&'static str> = p.to_vec();
        v.extend_from_slice(extra);
        v
    };
    let owned: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--out", "out"], "--particles"),
        (vec!["--particles", "300"], "--out"),
        (vec!["--particles", "0", "--out", "out"], "--particles 0"),
        (vec!["--particles", "abc", "--out", "out"], "abc"),
        (vec!["--particles", "-5", "--out", "out"], "-5"),
        // Counts as physicists write them are exact whole numbers or nothing.
        (
            vec!["--particles", "1.5", "--out", "out"],
            "1.5 is not a whole number",
        ),
        (
            vec!["--particles", "2.5e-1", "--out", "out"],
            "not a whole number",
        ),
        (
            vec!["--particles", "1e30", "--out", "out"],
            "1e30 is too large",
        ),
        (
            vec!["--particles", "1__000", "--out", "out"],
            "1__000 is not a count",
        ),
        (
            vec!["--threads", "2.5", "--particles", "300", "--out", "out"],
            "--threads",
        ),
        (with(&["--dim", "6"]), "--dim 6"),
        // The variants' ranges and the combinations without a meaning.
        (with(&["--drift", "1"]), "--drift needs --substrate-width"),
        (
            with(&["--substrate-width", "100", "--drift", "2e6"]),
            "accepted range [0, 1e6]",
        ),
        (
            with(&["--substrate-width", "5"]),
            "--substrate-width 5 is outside the accepted values",
        ),
        (
            with(&["--ballistic", "on", "--sticking-probability", "0.5"]),
            "--sticking-probability below 1 has no effect with --ballistic",
        ),
        (
            with(&[
                "--substrate-width",
                "100",
                "--ballistic",
                "on",
                "--drift",
                "2",
            ]),
            "--ballistic is the limit of infinite --drift",
        ),
        (
            with(&["--substrate-width", "100", "--far-field", "jump"]),
            "--far-field jump is the radial diffusive walk's",
        ),
        (
            with(&["--substrate-width", "100", "--threads", "2"]),
            "--threads 2: deposits",
        ),
        (
            with(&["--substrate-width", "20", "--step-min", "9.5"]),
            "--step-min 9.5 is too long for --substrate-width 20",
        ),
        (
            with(&["--seed-set", "missing.npy"]),
            "--seed-set missing.npy: ",
        ),
        (
            with(&["--seed-set", "unknown.toml"]),
            "not a positions file",
        ),
        (
            with(&["--dim", "4", "--positions", "vtk"]),
            "--positions vtk holds three coordinates, not the 4 of --dim 4",
        ),
        (
            with(&["--dim", "5", "--positions", "xyz"]),
            "--positions xyz holds three coordinates",
        ),
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
        (with(&["--dim", "1"]), "--dim 1"),
        (with(&["--step-min", "0"]), "--step-min 0"),
        (
            with(&["--paper-settings", "--step-min", "0.1"]),
            "'--paper-settings' cannot be used with '--step-min",
        ),
        (with(&["--step-min", "NaN"]), "--step-min NaN"),
        (with(&["--step-min", "1e-300"]), "[1e-6, 1e3]"),
        (
            with(&["--particles", "2000000000", "--positions", "vtk"]),
            "--positions vtk holds at most",
        ),
        (with(&["--precision", "0.5"]), "--precision 0.5"),
        (with(&["--birth-gap", "0.5"]), "--birth-gap 0.5"),
        (with(&["--death-ratio", "1"]), "--death-ratio 1"),
        (
            with(&["--death-ratio", "50"]),
            "--death-ratio is used by --far-field jump",
        ),
        (with(&["--serial-until", "100"]), "--serial-until 100"),
        (with(&["--leaf-side", "3"]), "--leaf-side 3"),
        (with(&["--threads", "0"]), "--threads 0"),
        (with(&["--far-field", "teleport"]), "teleport"),
        (with(&["--positions", "pdf"]), "pdf"),
        (with(&["--png", "--png-size", "8"]), "8"),
        (with(&["--png-size", "1024"]), "--png"),
        (with(&["--png", "--png-size", "65537"]), "65537"),
        (
            with(&["--animate", "--png-size", "20000"]),
            "--png-size 20000 with --animate",
        ),
        (
            with(&["--animate", "--animate-every", "0"]),
            "--animate-every 0",
        ),
        (with(&["--animate-every", "10"]), "--animate"),
        (with(&["--distance-map", "maybe"]), "maybe"),
        (with(&["--fit-from", "0"]), "--fit-from 0"),
        (with(&["--checkpoint-every", "0"]), "--checkpoint-every 0"),
        (
            with(&["--checkpoint-every", "1.5"]),
            "1.5 is not a whole number",
        ),
        // clap's tip for a misspelt flag survives the one-line message.
        (
            vec!["--particle", "300", "--out", "out"],
            "tip: a similar argument exists: '--particles'",
        ),
        // A list of seeds given to --seed points to --seeds, in its own syntax.
        (
            with(&["--seed", "1..=10"]),
            "several seeds, --seed takes one; for one run per seed (an ensemble) use --seeds 1..=10",
        ),
        (with(&["--seed", "1-10"]), "use --seeds 1..=10"),
        (with(&["--seed", "2.5"]), "not a whole number"),
        (
            with(&["--seeds", "1-10"]),
            "`1-10` is not a seed range; write 1..=10 for seeds 1 to 10",
        ),
        (with(&["--seeds", "1..=1e30"]), "`1e30` is not a seed"),
        (
            with(&["--seeds", "1..=2", "--jobs", "0"]),
            "0 is outside the accepted range 1..=4096",
        ),
        (
            with(&["--seeds", "1..=2", "--jobs", "1e4"]),
            "10000 is outside the accepted range 1..=4096",
        ),
        (
            with(&["--seeds", "1..=2", "--jobs", "1.5"]),
            "not a whole number",
        ),
        (with(&["--heartbeat", "-1"]), "-1"),
        (with(&["--no-such-flag"]), "--no-such-flag"),
        (vec!["--particles", "300", "--out", "file"], "--out file"),
        (
            vec!["--particles", "300", "--out", "file/sub"],
            "--out file/sub",
        ),
        (with(&["--resume", "empty"]), "empty/checkpoint.bin"),
        (with(&["--resume", "nowhere"]), "nowhere/checkpoint.bin"),
        (with(&["--resume", "trunc"]), "truncated"),
        (with(&["--resume", "flip"]), "corrupted"),
        (with(&["--resume", "other"]), "'animat', not 'dla'"),
        (
            with(&["--resume", "ck3"]),
            "--dim 3 in the checkpoint, 2 given",
        ),
        (
            with(&["--resume", "ck", "--seed", "2"]),
            "--seed 1 in the checkpoint, 2 given",
        ),
        (
            with(&["--resume", "ck", "--step-min", "0.25"]),
            "--step-min 0.1 in the checkpoint, 0.25 given",
        ),
        (
            vec!["--particles", "200", "--out", "out", "--resume", "ck"],
            "--particles 200 is below the 300 particles the checkpoint holds",
        ),
        (with(&["--resume", "nolog"]), "nolog/positions.npy"),
        (
            with(&["--resume", "badlog"]),
            "does not belong to the checkpoint",
        ),
    ];
    let cases: Vec<(&[&str], &str)> = owned.iter().map(|(a, c)| (a.as_slice(), *c)).collect();
    assert!(cases.len() >= 30);
    let failures = refusals(Path::new(DLA), "dla", dir, &cases);
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[cfg(unix)]
#[test]
fn an_unwritable_out_is_refused_before_any_work() {
    use std::os::unix::fs::PermissionsExt;
    if permissions_are_bypassed() {
        eprintln!("skipped: this user writes into read-only directories (root)");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let ro = tmp.path().join("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::create_dir(ro.join("existing")).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    std::fs::set_permissions(ro.join("existing"), std::fs::Permissions::from_mode(0o555)).unwrap();
    let cases: [(&[&str], &str); 2] = [
        (&["--particles", "300", "--out", "ro/new"], "--out ro/new"),
        (
            &["--particles", "300", "--out", "ro/existing"],
            "--out ro/existing",
        ),
    ];
    let failures = refusals(Path::new(DLA), "dla", tmp.path(), &cases);
    std::fs::set_permissions(ro.join("existing"), std::fs::Permissions::from_mode(0o755)).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
