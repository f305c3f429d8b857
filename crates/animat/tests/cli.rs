//! The `animat` binary: outputs, config files, checkpoints and resume after kill -9 (bad
//! inputs: `tests/bad_input.rs`).

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

/// `populations.csv` and the state hash of a finished run in `dir`.
fn result(dir: &Path) -> (String, String) {
    let hash = run_json(dir)["results"]["state_hash"]
        .as_str()
        .unwrap()
        .to_string();
    (
        std::fs::read_to_string(dir.join("populations.csv")).unwrap(),
        hash,
    )
}

#[test]
fn a_run_killed_and_resumed_ends_like_the_uninterrupted_run() {
    let tmp = tempfile::tempdir().unwrap();
    let world = [
        "--foxes",
        "300",
        "--rabbits",
        "3000",
        "--start-radius",
        "100",
    ];
    let steps = ["--steps", "400", "--seed", "5", "-qq"];
    let whole = tmp.path().join("whole");
    let o = animat(&[&world[..], &steps[..], &["--out", whole.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    // The same run with a checkpoint every 5 steps, killed (SIGKILL) once a checkpoint exists.
    let cut = tmp.path().join("cut");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_animat"));
    cmd.args(world)
        .args(steps)
        .args(["--checkpoint-every", "5", "--out", cut.to_str().unwrap()]);
    if !run_cli::testing::kill_once_written(&mut cmd, &cut.join("checkpoint.bin")) {
        eprintln!("the run ended before it could be killed; resuming from its last checkpoint");
    }

    let resumed = tmp.path().join("resumed");
    let o = animat(
        &[
            &world[..],
            &steps[..],
            &[
                "--resume",
                cut.to_str().unwrap(),
                "--out",
                resumed.to_str().unwrap(),
            ],
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(result(&resumed), result(&whole));

    // SIGTERM: a checkpoint after the current step, exit code 130; resumed in place, the same
    // end.
    let term = tmp.path().join("term");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_animat"));
    cmd.args(world)
        .args(steps)
        .args(["--checkpoint-every", "5", "--out", term.to_str().unwrap()]);
    let (running, code) =
        run_cli::testing::terminate_once_written(&mut cmd, &term.join("checkpoint.bin"));
    if running {
        assert_eq!(code, Some(130));
    }
    let o = animat(
        &[
            &world[..],
            &steps[..],
            &[
                "--resume",
                term.to_str().unwrap(),
                "--out",
                term.to_str().unwrap(),
            ],
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(result(&term), result(&whole));

    // A finished run extends: 400 steps resumed to 450 equal 450 steps made at once.
    let ext = tmp.path().join("ext");
    let more = ["--steps", "450", "--seed", "5", "-qq"];
    let ck = tmp.path().join("ck");
    let o = animat(
        &[
            &world[..],
            &steps[..],
            &["--checkpoint-every", "100", "--out", ck.to_str().unwrap()],
        ]
        .concat(),
    );
    assert!(o.status.success());
    let o = animat(
        &[
            &world[..],
            &more[..],
            &[
                "--resume",
                ck.to_str().unwrap(),
                "--out",
                ext.to_str().unwrap(),
            ],
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let direct = tmp.path().join("direct");
    let o = animat(&[&world[..], &more[..], &["--out", direct.to_str().unwrap()]].concat());
    assert!(o.status.success());
    assert_eq!(result(&ext), result(&direct));
}

#[test]
fn a_run_removes_temporaries_an_interrupted_checkpoint_write_left() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    std::fs::create_dir(&out).unwrap();
    // What a kill during the atomic write of a checkpoint leaves: the temporary, not yet
    // renamed.
    let stale = out.join(".checkpoint.bin.k9Xq2Z.tmp");
    std::fs::write(&stale, b"half a checkpoint").unwrap();
    let o = animat(
        &[
            &SMALL[..],
            &[
                "--checkpoint-every",
                "10",
                "-q",
                "--out",
                out.to_str().unwrap(),
            ],
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.ends_with(".tmp")), "{names:?}");
    assert!(out.join("checkpoint.bin").exists());
}

#[test]
fn a_quiet_run_without_a_terminal_sends_a_heartbeat_and_qq_silences_it() {
    let tmp = tempfile::tempdir().unwrap();
    let run = |quiet: &str, out: &str| {
        let out = tmp.path().join(out);
        animat(
            &[
                &SMALL[..],
                &[
                    quiet,
                    "--heartbeat",
                    "0.001",
                    "--out",
                    out.to_str().unwrap(),
                ],
            ]
            .concat(),
        )
    };
    let o = run("-q", "a");
    assert!(o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.lines()
            .any(|l| l.starts_with("animat: ") && l.contains("/40 steps (")),
        "{err}"
    );
    let o = run("-qq", "b");
    assert!(o.status.success());
    assert_eq!(String::from_utf8_lossy(&o.stderr), "");
}

/// `run.json` records where the run came from; logs are plain text unless asked otherwise.
#[test]
fn run_json_has_provenance_and_redirected_logs_have_no_colour_codes() {
    let dir = tempfile::tempdir().unwrap();
    run_cli::testing::provenance_and_color_contract(
        Path::new(env!("CARGO_BIN_EXE_animat")),
        dir.path(),
        &["--steps", "5", "--seed", "2"],
    );
}

/// `--positions npy|vtk|xyz` hold the same animats as `--positions` (CSV).
#[test]
fn positions_in_every_format_hold_the_same_animats() {
    let tmp = tempfile::tempdir().unwrap();
    let run = |format: Option<&str>| {
        let out = tmp.path().join(format.unwrap_or("default"));
        let mut args = vec![
            "--steps",
            "8",
            "--seed",
            "5",
            "-q",
            "--out",
            out.to_str().unwrap(),
        ];
        args.push("--positions");
        args.extend(format);
        let o = animat(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        out
    };
    let csv = std::fs::read_to_string(run(None).join("positions.csv")).unwrap();
    assert_eq!(csv.lines().next(), Some("x,y,id,species,age,hunger"));
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert!(rows.len() > 100);

    let npy = run(Some("npy"));
    // Cells are int64, as in positions.csv and Python (docs/outputs.md).
    let cells = std::fs::read(npy.join("positions.npy")).unwrap();
    let header = String::from_utf8_lossy(&cells[..128]);
    assert!(
        header.contains("'descr': '<i8'")
            && header.contains(&format!("'shape': ({}, 2)", rows.len())),
        "{header}"
    );
    let species = std::fs::read(npy.join("positions_species.npy")).unwrap();
    let int =
        |b: &[u8], i: usize| i64::from_le_bytes(b[128 + 8 * i..136 + 8 * i].try_into().unwrap());
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(
            [
                int(&cells, 2 * i).to_string(),
                int(&cells, 2 * i + 1).to_string()
            ],
            [row[0], row[1]]
        );
        assert_eq!(["fox", "rabbit"][int(&species, i) as usize], row[3]);
    }
    for a in ["id", "age", "hunger"] {
        assert!(npy.join(format!("positions_{a}.npy")).exists(), "{a}");
    }

    let xyz = std::fs::read_to_string(run(Some("xyz")).join("positions.xyz")).unwrap();
    let first: Vec<&str> = xyz.lines().nth(2).unwrap().split(' ').collect();
    assert_eq!(first[0], rows[0][3], "the species is the element column");
    assert_eq!(&first[1..3], &rows[0][0..2]);

    let vtk = std::fs::read(run(Some("vtk")).join("positions.vtk")).unwrap();
    let has = |s: &str| vtk.windows(s.len()).any(|w| w == s.as_bytes());
    assert!(has(&format!("POINTS {} double\n", rows.len())));
    for a in ["id", "species", "age", "hunger"] {
        assert!(has(&format!("SCALARS {a} int 1\n")), "{a}");
    }
}

/// A run saves its flags as `config.toml`; `--dump-config` prints the same without `--out`;
/// `--config OUT/config.toml` alone repeats the run (its steps and seed are in it).
#[test]
fn config_files_repeat_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let a = tmp.path().join("a");
    let b = tmp.path().join("b");
    let flags = ["--steps", "6", "--seed", "3", "--vision", "25", "-q"];
    let o = animat(&[&flags[..], &["--out", a.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let saved = std::fs::read_to_string(a.join("config.toml")).unwrap();
    assert!(saved.contains("vision = 25"), "{saved}");
    let dump = animat(&[&flags[..], &["--dump-config"]].concat());
    assert!(
        dump.status.success(),
        "{}",
        String::from_utf8_lossy(&dump.stderr)
    );
    assert_eq!(String::from_utf8_lossy(&dump.stdout), saved);
    let config = a.join("config.toml");
    let o = animat(&[
        "-q",
        "--config",
        config.to_str().unwrap(),
        "--out",
        b.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let hash = |d: &Path| {
        let j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("run.json")).unwrap()).unwrap();
        j["results"]["state_hash"].clone()
    };
    assert_eq!(hash(&a), hash(&b));
}

/// Counts as physicists write them (`1e3`, `4.0e1`, `1_000`) are the same run as plain digits,
/// in every count flag and in a seed.
#[test]
fn counts_in_every_notation_are_the_same_run() {
    let hash = |args: &[&str]| {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("run");
        let mut all = vec!["--out", out.to_str().unwrap(), "-qq"];
        all.extend_from_slice(args);
        let o = animat(&all);
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        run_json(&out)["results"]["state_hash"]
            .as_str()
            .unwrap()
            .to_string()
    };
    let plain = hash(&[
        "--foxes",
        "30",
        "--rabbits",
        "300",
        "--start-radius",
        "40",
        "--steps",
        "40",
        "--checkpoint-every",
        "10",
        "--snapshot-every",
        "20",
        "--seed",
        "1000",
    ]);
    let written = hash(&[
        "--foxes",
        "3e1",
        "--rabbits",
        "3.0e2",
        "--start-radius",
        "40",
        "--steps",
        "4E1",
        "--checkpoint-every",
        "1e1",
        "--snapshot-every",
        "2_0",
        "--seed",
        "1e3",
    ]);
    assert_eq!(written, plain);
}

/// `--png-size` sizes the snapshots, every snapshot of a run has the same frame (the same
/// figure size, whatever the population's spread), and `--animate` writes a GIF with a frame
/// at the start, every `--animate-every` steps and at the end.
#[test]
fn snapshots_share_one_frame_and_the_animation_has_its_frames() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    let mut args = SMALL.to_vec();
    args.extend([
        "--seed",
        "3",
        "--snapshot-every",
        "20",
        "--png-size",
        "96",
        "--animate",
        "--animate-every",
        "15",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    let o = animat(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let size = |name: &str| {
        let png = std::fs::read(out.join(name)).unwrap();
        let side = |at: usize| u32::from_be_bytes(png[at..at + 4].try_into().unwrap());
        (side(16), side(20))
    };
    let first = size("snapshot_000000.png");
    assert!(first.0 > 96 && first.1 > 96, "{first:?}");
    assert_eq!(size("snapshot_000040.png"), first);
    let steps = run_json(&out)["results"]["steps"].as_u64().unwrap();
    assert_eq!(steps, 40);
    // Steps 0, 15, 30 and 40.
    let (gif_size, frames) = figures::animation::read_gif(&out.join("animat.gif")).unwrap();
    assert_eq!(frames, 4);
    assert_eq!(gif_size, first);
}
