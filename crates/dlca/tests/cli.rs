//! The `dlca` binary: outputs, strategies and resume (bad inputs: `tests/bad_input.rs`).

use std::path::Path;
use std::process::Command;

fn dlca(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_dlca"))
        .args(args)
        .output()
        .expect("dlca runs")
}

fn run_json(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("run.json")).unwrap()).unwrap()
}

#[test]
fn writes_every_output() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    let o = dlca(&[
        "--size",
        "64x48",
        "--fill",
        "0.05",
        "--seed",
        "4",
        "--target-clusters",
        "5",
        "--timing",
        "--histogram",
        "--gyration",
        "--png",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j = run_json(&out);
    let r = &j["results"];
    assert_eq!(j["model"], "dlca");
    assert_eq!(j["seed"], 4);
    assert_eq!(r["particles"], 154); // round(0.05 * 64 * 48)
    assert!(r["clusters"].as_u64().unwrap() <= 5);
    assert!(r["sweeps"].as_u64().unwrap() > 0);
    assert_eq!(r["strategy"], "lattice");
    assert_eq!(r["state_hash"].as_str().unwrap().len(), 16);
    assert!(r.get("fractal_dimension").is_some() && r.get("fractal_dimension_stderr").is_some());
    let sweeps = std::fs::read_to_string(out.join("sweeps.csv")).unwrap();
    assert!(sweeps.starts_with("sweep,clusters,largest,seconds\n0,"));
    assert_eq!(
        sweeps.lines().count() as u64,
        r["sweeps"].as_u64().unwrap() + 2
    );
    let particles = std::fs::read_to_string(out.join("particles.csv")).unwrap();
    assert!(particles.starts_with("x1,x2,cluster\n"));
    assert_eq!(particles.lines().count(), 155);
    let sizes = std::fs::read_to_string(out.join("sizes.csv")).unwrap();
    let total: u64 = sizes
        .lines()
        .skip(1)
        .map(|l| {
            let (s, c) = l.split_once(',').unwrap();
            s.parse::<u64>().unwrap() * c.parse::<u64>().unwrap()
        })
        .sum();
    assert_eq!(total, 154);
    assert!(
        std::fs::read_to_string(out.join("histogram.csv"))
            .unwrap()
            .starts_with("sweep,candidates,moves\n1,")
    );
    assert!(
        std::fs::read_to_string(out.join("clusters.csv"))
            .unwrap()
            .starts_with("cluster,size,radius_of_gyration,wraps\n")
    );
    let png = std::fs::read(out.join("dlca.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG"));
    // 64x48 sites drawn 8x8 pixels each (so a small lattice is legible), with axes and legend
    // around the raster.
    let side = |at: usize| u32::from_be_bytes(png[at..at + 4].try_into().unwrap());
    assert!(side(16) > 512 && side(20) > 384);
}

#[test]
fn strategies_agree_through_the_cli() {
    let tmp = tempfile::tempdir().unwrap();
    let hashes: Vec<String> = ["all-pairs", "grid", "grid-doubling", "lattice"]
        .iter()
        .map(|s| {
            let out = tmp.path().join(s);
            let o = dlca(&[
                "--dim",
                "3",
                "--size",
                "12",
                "--boundary",
                "periodic,wall,periodic",
                "--fill",
                "0.05",
                "--gravity",
                "0.3",
                "--search",
                s,
                "--target-clusters",
                "3",
                "-q",
                "--out",
                out.to_str().unwrap(),
            ]);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            run_json(&out)["results"]["state_hash"]
                .as_str()
                .unwrap()
                .to_string()
        })
        .collect();
    assert_eq!(hashes[0], hashes[1]);
    assert_eq!(hashes[0], hashes[2]);
}

#[test]
fn resume_from_a_checkpoint_ends_like_the_uninterrupted_run() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = |name: &str| tmp.path().join(name).to_str().unwrap().to_string();
    let common = [
        "--size",
        "96x64",
        "--fill",
        "0.04",
        "--seed",
        "3",
        "--target-clusters",
        "2",
        "--quiet",
    ];
    let with = |extra: &[&str]| {
        let mut args: Vec<&str> = common.to_vec();
        args.extend_from_slice(extra);
        let o = dlca(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    let (whole, cut, resumed) = (dir("whole"), dir("cut"), dir("resumed"));
    with(&["--out", &whole]);
    // Interrupted after 150 sweeps, with a checkpoint every 40 (the last at sweep 120).
    with(&[
        "--max-sweeps",
        "150",
        "--checkpoint-every",
        "40",
        "--out",
        &cut,
    ]);
    assert!(Path::new(&cut).join("checkpoint.bin").exists());
    with(&["--resume", &cut, "--out", &resumed]);
    let (a, b) = (run_json(Path::new(&whole)), run_json(Path::new(&resumed)));
    assert_eq!(a["results"]["state_hash"], b["results"]["state_hash"]);
    assert_eq!(a["results"]["sweeps"], b["results"]["sweeps"]);
    let sweeps = |d: &str| std::fs::read_to_string(Path::new(d).join("sweeps.csv")).unwrap();
    assert_eq!(sweeps(&whole), sweeps(&resumed));
    // A checkpoint of another run is refused.
    let mut args: Vec<&str> = common.to_vec();
    args[5] = "4";
    let other = dir("other");
    args.extend_from_slice(&["--resume", &cut, "--out", &other]);
    assert!(!dlca(&args).status.success());
}

#[test]
fn a_run_killed_mid_run_and_resumed_ends_like_the_uninterrupted_run() {
    let tmp = tempfile::tempdir().unwrap();
    let run = [
        "--size",
        "512",
        "--fill",
        "0.03",
        "--target-clusters",
        "1",
        "--seed",
        "4",
        "-qq",
    ];
    let whole = tmp.path().join("whole");
    let o = dlca(&[&run[..], &["--out", whole.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let cut = tmp.path().join("cut");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_dlca"));
    cmd.args(run)
        .args(["--checkpoint-every", "50", "--out", cut.to_str().unwrap()]);
    if !run_cli::testing::kill_once_written(&mut cmd, &cut.join("checkpoint.bin")) {
        eprintln!("the run ended before it could be killed; resuming from its last checkpoint");
    }
    let resumed = tmp.path().join("resumed");
    let o = dlca(
        &[
            &run[..],
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
    let (a, b) = (run_json(&whole), run_json(&resumed));
    assert_eq!(a["results"]["state_hash"], b["results"]["state_hash"]);
    assert_eq!(a["results"]["sweeps"], b["results"]["sweeps"]);

    // SIGTERM: a checkpoint after the current sweep, exit code 130; resumed in place, the same
    // end.
    let term = tmp.path().join("term");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_dlca"));
    cmd.args(run)
        .args(["--checkpoint-every", "50", "--out", term.to_str().unwrap()]);
    let (running, code) =
        run_cli::testing::terminate_once_written(&mut cmd, &term.join("checkpoint.bin"));
    if running {
        assert_eq!(code, Some(130));
    }
    let o = dlca(
        &[
            &run[..],
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
    assert_eq!(
        run_json(&term)["results"]["state_hash"],
        a["results"]["state_hash"]
    );
}

/// `run.json` records where the run came from; logs are plain text unless asked otherwise.
#[test]
fn run_json_has_provenance_and_redirected_logs_have_no_colour_codes() {
    let dir = tempfile::tempdir().unwrap();
    run_cli::testing::provenance_and_color_contract(
        Path::new(env!("CARGO_BIN_EXE_dlca")),
        dir.path(),
        &["--size", "32", "--fill", "0.05", "--seed", "2"],
    );
}

/// `--positions npy|vtk|xyz|none` write the same particles and cluster ids as the default CSV.
#[test]
fn positions_in_every_format_hold_the_same_particles() {
    let tmp = tempfile::tempdir().unwrap();
    let run = |format: &str| {
        let out = tmp.path().join(format);
        let o = dlca(&[
            "--size",
            "24x20",
            "--fill",
            "0.1",
            "--seed",
            "6",
            "--target-clusters",
            "4",
            "-q",
            "--positions",
            format,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        out
    };
    let csv = std::fs::read_to_string(run("csv").join("particles.csv")).unwrap();
    let rows: Vec<Vec<i64>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(csv.lines().next(), Some("x1,x2,cluster"));
    assert_eq!(rows.len(), 48);

    let npy = run("npy");
    // Lattice sites are int64, as in particles.csv and Python (docs/outputs.md).
    let sites = std::fs::read(npy.join("particles.npy")).unwrap();
    let header = String::from_utf8_lossy(&sites[..128]);
    assert!(
        header.contains("'descr': '<i8'") && header.contains("'shape': (48, 2)"),
        "{header}"
    );
    let ids = std::fs::read(npy.join("particles_cluster.npy")).unwrap();
    let int =
        |b: &[u8], i: usize| i64::from_le_bytes(b[128 + 8 * i..136 + 8 * i].try_into().unwrap());
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(
            [int(&sites, 2 * i), int(&sites, 2 * i + 1)],
            [row[0], row[1]]
        );
        assert_eq!(int(&ids, i), row[2]);
    }
    assert!(!npy.join("particles.csv").exists());

    let xyz = std::fs::read_to_string(run("xyz").join("particles.xyz")).unwrap();
    let lines: Vec<&str> = xyz.lines().collect();
    assert_eq!(lines[0], "48");
    assert!(lines[1].starts_with("Properties=species:S:1:pos:R:3:cluster:I:1"));
    assert_eq!(
        lines[2],
        format!("C {} {} 0 {}", rows[0][0], rows[0][1], rows[0][2])
    );

    let vtk = std::fs::read(run("vtk").join("particles.vtk")).unwrap();
    assert!(vtk.starts_with(b"# vtk DataFile Version 3.0\n"));
    let has = |s: &str| vtk.windows(s.len()).any(|w| w == s.as_bytes());
    assert!(has("POINTS 48 double\n") && has("SCALARS cluster int 1\n"));

    let none = run("none");
    assert!(none.join("run.json").exists());
    for f in [
        "particles.csv",
        "particles.npy",
        "particles.vtk",
        "particles.xyz",
    ] {
        assert!(!none.join(f).exists(), "{f}");
    }
}

/// `--config` files: the saved configuration repeats the run, flags override it.
#[test]
fn config_files_repeat_runs_and_flags_override_them() {
    let dir = tempfile::tempdir().unwrap();
    run_cli::testing::config_contract(
        Path::new(env!("CARGO_BIN_EXE_dlca")),
        dir.path(),
        &["--size", "32x16", "--fill", "0.05", "--seed", "4", "--png"],
    );
}

/// Counts as physicists write them (`1e3`, `6.4e1`, `1_000`) are the same run as plain digits,
/// in every count flag, in lattice sides and in a seed.
#[test]
fn counts_in_every_notation_are_the_same_run() {
    let hash = |args: &[&str]| {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("run");
        let mut all = vec!["--out", out.to_str().unwrap(), "-qq", "--histogram"];
        all.extend_from_slice(args);
        let o = dlca(&all);
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
        "--size",
        "64x32",
        "--particles",
        "100",
        "--target-clusters",
        "10",
        "--max-sweeps",
        "1000",
        "--checkpoint-every",
        "10",
        "--seed",
        "1000",
        "--histogram-sweeps",
        "1,10",
        "--search",
        "grid",
        "--grid-box",
        "8",
        "--fit-min-size",
        "2",
    ]);
    let written = hash(&[
        "--size",
        "6.4e1x32",
        "--particles",
        "1e2",
        "--target-clusters",
        "1_0",
        "--max-sweeps",
        "1e3",
        "--checkpoint-every",
        "1E1",
        "--seed",
        "1e3",
        "--histogram-sweeps",
        "1,1e1",
        "--search",
        "grid",
        "--grid-box",
        "8.0",
        "--fit-min-size",
        "2e0",
    ]);
    assert_eq!(written, plain);
}

/// `--png-size` sizes dlca.png, and `--animate` writes a GIF with a frame at the start, every
/// `--animate-every` sweeps and at the end.
#[test]
fn png_size_and_animation() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    let o = dlca(&[
        "--size",
        "32x16",
        "--fill",
        "0.1",
        "--seed",
        "2",
        "--target-clusters",
        "1",
        "--max-sweeps",
        "5",
        "--png",
        "--png-size",
        "64",
        "--animate",
        "--animate-every",
        "2",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(run_json(&out)["results"]["sweeps"], 5);
    let png = std::fs::read(out.join("dlca.png")).unwrap();
    let side = |at: usize| u32::from_be_bytes(png[at..at + 4].try_into().unwrap());
    // A 64 x 32 raster with axes and legend around it.
    assert!(side(16) > 64 && side(20) > 32);
    // Sweeps 0, 2, 4 and 5.
    let ((w, h), frames) = figures::animation::read_gif(&out.join("dlca.gif")).unwrap();
    assert_eq!(frames, 4);
    assert_eq!((w, h), (side(16), side(20)));
}
