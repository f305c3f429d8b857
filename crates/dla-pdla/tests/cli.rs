//! The `dla` binary: outputs, determinism, checkpoints (bad inputs: `tests/bad_input.rs`).

use std::process::Command;

fn dla() -> Command {
    Command::new(env!("CARGO_BIN_EXE_dla"))
}

#[test]
fn run_writes_every_output() {
    for (dim, fmt, file, header) in [
        ("2", "csv", "positions.csv", "x,y"),
        ("3", "csv", "positions.csv", "x,y,z"),
        ("2", "bin", "positions.bin", "DLAPOS02"),
        ("3", "xyz", "positions.xyz", "500"),
        ("3", "vtk", "positions.vtk", "# vtk DataFile Version 3.0"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let st = dla()
            .args([
                "--dim",
                dim,
                "--particles",
                "500",
                "--seed",
                "3",
                "--fit-from",
                "50",
                "--quiet",
                "--png",
            ])
            .args(["--positions", fmt, "--out"])
            .arg(&out)
            .status()
            .unwrap();
        assert!(st.success());
        let m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
        let r = &m["results"];
        for key in [
            "particles",
            "fractal_dimension",
            "fractal_dimension_stderr",
            "radius_of_gyration",
            "r_ext",
            "discarded_walkers",
            "bytes_per_particle",
            "state_hash",
        ] {
            assert!(!r[key].is_null(), "{key} missing: {r}");
        }
        assert_eq!(r["particles"], 500);
        let growth = std::fs::read_to_string(out.join("growth.csv")).unwrap();
        assert!(growth.starts_with("n,radius_of_gyration,r_ext,seconds"));
        let bytes = std::fs::read(out.join(file)).unwrap();
        assert!(bytes.starts_with(header.as_bytes()), "{file}");
        if fmt == "bin" {
            // The coordinates, then the parents (recorded with the positions).
            assert_eq!(bytes.len(), 8 + 4 + 8 + 500 * 2 * 8 + 500 * 8);
        }
        assert!(out.join("dla.png").exists());
    }
}

#[test]
fn same_seed_same_state_hash_through_the_cli() {
    let hash = |seed: &str| {
        let dir = tempfile::tempdir().unwrap();
        let st = dla()
            .args(["--particles", "800", "--quiet", "--seed", seed, "--out"])
            .arg(dir.path())
            .status()
            .unwrap();
        assert!(st.success());
        let m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join("run.json")).unwrap())
                .unwrap();
        m["results"]["state_hash"].as_str().unwrap().to_string()
    };
    assert_eq!(hash("9"), hash("9"));
    assert_ne!(hash("9"), hash("10"));
}

#[test]
fn checkpointed_and_resumed_runs_end_with_the_same_state_hash() {
    let run = |out: &std::path::Path, extra: &[&str]| {
        let st = dla()
            .args(["--particles", "1500", "--quiet", "--seed", "4", "--out"])
            .arg(out)
            .args(extra)
            .status()
            .unwrap();
        assert!(st.success(), "{extra:?}");
        let m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
        m["results"]["state_hash"].as_str().unwrap().to_string()
    };
    let dir = tempfile::tempdir().unwrap();
    let plain = run(&dir.path().join("a"), &[]);
    let ck = dir.path().join("b");
    assert_eq!(run(&ck, &["--checkpoint-every", "400"]), plain);
    assert!(ck.join("checkpoint.bin").exists());
    let resumed = run(&dir.path().join("c"), &["--resume", ck.to_str().unwrap()]);
    assert_eq!(resumed, plain);
    // A finished run extends, in place, to more particles: the state of a run made to that
    // size directly, and the positions of that run in positions.npy.
    let more = |out: &std::path::Path, extra: &[&str]| {
        let st = dla()
            .args(["--particles", "2500", "--quiet", "--seed", "4", "--out"])
            .arg(out)
            .args(extra)
            .status()
            .unwrap();
        assert!(st.success(), "{extra:?}");
        state_hash(out)
    };
    let direct = dir.path().join("d");
    let extended = more(
        &ck,
        &["--resume", ck.to_str().unwrap(), "--positions", "bin"],
    );
    assert_eq!(extended, more(&direct, &["--positions", "bin"]));
    assert_eq!(
        std::fs::read(ck.join("positions.bin")).unwrap(),
        std::fs::read(direct.join("positions.bin")).unwrap()
    );
    let npy = std::fs::read(ck.join("positions.npy")).unwrap();
    assert_eq!(npy.len(), 128 + 2500 * 16);
    assert!(String::from_utf8_lossy(&npy[..128]).contains("'shape': (2500, 2)"));
}

#[test]
fn a_run_removes_temporaries_an_interrupted_write_left() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let stale = out.join(".checkpoint.bin.Ab3xYz.tmp");
    std::fs::write(&stale, b"half a checkpoint").unwrap();
    let st = dla()
        .args(["--particles", "100", "--quiet", "--out"])
        .arg(&out)
        .status()
        .unwrap();
    assert!(st.success());
    assert!(!stale.exists());
    assert!(out.join("run.json").exists());
}

/// The state hash in `DIR/run.json`.
#[test]
fn no_parents_records_none_and_grows_the_same_cluster() {
    let run = |extra: &[&str]| {
        let dir = tempfile::tempdir().unwrap();
        let st = dla()
            .args([
                "--particles",
                "800",
                "--quiet",
                "--positions",
                "csv",
                "--out",
            ])
            .arg(dir.path())
            .args(extra)
            .output()
            .unwrap();
        assert!(st.status.success());
        let csv = std::fs::read_to_string(dir.path().join("positions.csv")).unwrap();
        let header = csv.lines().next().unwrap().to_string();
        let parents = dir.path().join("positions_parent.npy").exists();
        let branches = dir.path().join("branches.csv").exists();
        (state_hash(dir.path()), header, parents, branches)
    };
    let (hash, header, parents, branches) = run(&[]);
    assert!(header.contains("parent") && parents && branches, "{header}");
    let (bare_hash, header, parents, branches) = run(&["--no-parents"]);
    assert_eq!(bare_hash, hash);
    assert!(
        !header.contains("parent") && !parents && !branches,
        "{header}"
    );
    // A run refused for memory names the flag while it would help.
    let out = dla()
        .args(["--particles", "1e7", "--max-memory", "10M", "--out"])
        .arg(tempfile::tempdir().unwrap().path())
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{e}");
    assert!(
        e.contains("add --no-parents (5 bytes a particle less)"),
        "{e}"
    );
}

fn state_hash(dir: &std::path::Path) -> String {
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run.json")).unwrap()).unwrap();
    m["results"]["state_hash"].as_str().unwrap().to_string()
}

#[test]
fn a_run_killed_mid_growth_and_resumed_ends_like_the_uninterrupted_run() {
    let dir = tempfile::tempdir().unwrap();
    let run = ["--particles", "150000", "--seed", "9", "-qq"];
    let whole = dir.path().join("whole");
    assert!(
        dla()
            .args(run)
            .arg("--out")
            .arg(&whole)
            .status()
            .unwrap()
            .success()
    );
    let cut = dir.path().join("cut");
    let mut cmd = dla();
    cmd.args(run)
        .args(["--checkpoint-every", "20000", "--out"])
        .arg(&cut);
    if !run_cli::testing::kill_once_written(&mut cmd, &cut.join("checkpoint.bin")) {
        eprintln!("the run ended before it could be killed; resuming from its last checkpoint");
    }
    let resumed = dir.path().join("resumed");
    let o = dla()
        .args(run)
        .arg("--resume")
        .arg(&cut)
        .arg("--out")
        .arg(&resumed)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(state_hash(&resumed), state_hash(&whole));

    // SIGTERM: a final checkpoint, exit code 130, a line saying how to continue; resumed in
    // place, the run ends as the uninterrupted one.
    let term = dir.path().join("term");
    let mut child = dla()
        .args(run)
        .args(["--checkpoint-every", "20000", "--out"])
        .arg(&term)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    while !term.join("checkpoint.bin").exists() && child.try_wait().unwrap().is_none() {
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    let running = child.try_wait().unwrap().is_none();
    run_cli::testing::send_sigterm(child.id());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    if running {
        assert_eq!(o.status.code(), Some(130), "{err}");
        assert!(
            err.contains("interrupted at") && err.contains("--resume"),
            "{err}"
        );
        assert!(!term.join("run.json").exists());
    }
    let o = dla()
        .args(run)
        .args(["--checkpoint-every", "20000", "--resume"])
        .arg(&term)
        .arg("--out")
        .arg(&term)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(state_hash(&term), state_hash(&whole));
}

#[cfg(unix)]
#[test]
fn outputs_are_created_with_the_umask_0644_and_0755_under_022() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out/nested");
    let st = Command::new("sh")
        .arg("-c")
        .arg("umask 022 && exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_dla"))
        .args(["--particles", "300", "--png", "--positions", "csv"])
        .args(["--checkpoint-every", "100", "-qq", "--out"])
        .arg(&out)
        .status()
        .unwrap();
    assert!(st.success());
    let mode = |p: &std::path::Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode(&out), 0o755);
    assert_eq!(mode(out.parent().unwrap()), 0o755);
    let mut files = 0;
    for e in std::fs::read_dir(&out).unwrap() {
        let p = e.unwrap().path();
        assert_eq!(mode(&p), 0o644, "{}", p.display());
        files += 1;
    }
    assert_eq!(
        files, 10,
        "run.json, config.toml, growth.csv, positions.npy, positions_parent.npy, positions.csv, dla.png, \
         branches.csv, branches.png, checkpoint.bin"
    );
}

#[test]
fn a_failure_after_the_start_is_one_line_with_exit_code_1() {
    // A directory where run.json should go: the run works, then cannot write its manifest.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir_all(out.join("run.json")).unwrap();
    let o = dla()
        .args(["--particles", "300", "-q", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("dla: run failed: ") && err.contains("run.json"),
        "{err}"
    );
}

/// `run.json` records where the run came from; logs are plain text unless asked otherwise.
#[test]
fn run_json_has_provenance_and_redirected_logs_have_no_colour_codes() {
    let dir = tempfile::tempdir().unwrap();
    run_cli::testing::provenance_and_color_contract(
        std::path::Path::new(env!("CARGO_BIN_EXE_dla")),
        dir.path(),
        &["--particles", "200", "--seed", "2"],
    );
}

/// `--config` files: the saved configuration repeats the run, flags override it.
#[test]
fn config_files_repeat_runs_and_flags_override_them() {
    let dir = tempfile::tempdir().unwrap();
    run_cli::testing::config_contract(
        std::path::Path::new(env!("CARGO_BIN_EXE_dla")),
        dir.path(),
        &["--particles", "300", "--seed", "4", "--step-min", "0.2"],
    );
}

#[test]
fn paper_settings_run_the_papers_walk() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let st = dla()
        .args(["--particles", "300", "--paper-settings", "-q", "--out"])
        .arg(&out)
        .status()
        .unwrap();
    assert!(st.success());
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    let p = &m["params"];
    assert_eq!(p["far_field"], "jump");
    assert_eq!(p["death_ratio"], 100.0);
    assert_eq!(p["step_min"], 0.5);
    assert_eq!(p["precision"], 2.0);
    assert_eq!(p["distance_map"], false);
    // The saved configuration repeats the preset, not its expansion.
    let config = std::fs::read_to_string(out.join("config.toml")).unwrap();
    assert!(
        config.lines().any(|l| l == "paper-settings = true"),
        "{config}"
    );
}

/// Counts as physicists write them: `1e3`, `1_000`, `1.0e3` and `1000` are the same run.
#[test]
fn counts_in_every_notation_are_the_same_run() {
    let hash = |particles: &str| {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let st = dla()
            .args([
                "--particles",
                particles,
                "--fit-from",
                "1e2",
                "-qq",
                "--out",
            ])
            .arg(&out)
            .status()
            .unwrap();
        assert!(st.success(), "--particles {particles}");
        let m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
        assert_eq!(m["results"]["particles"], 1000, "--particles {particles}");
        m["results"]["state_hash"].as_str().unwrap().to_string()
    };
    let plain = hash("1000");
    for notation in ["1e3", "1E3", "1_000", "1.0e3", "0.1e4"] {
        assert_eq!(hash(notation), plain, "--particles {notation}");
    }
}

/// `bytes_per_particle` is the simulation's peak memory per particle, measured before the
/// output stage (writing files, rendering `dla.png`); the output stage's peak is
/// `output_peak_rss_bytes`, apart. Peak memory is a high-water mark, so the output stage's is
/// at least the simulation's, and the process's (`peak_rss_bytes`) is the output stage's.
#[test]
fn bytes_per_particle_measures_the_simulation_not_the_output_stage() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let st = dla()
        .args([
            "--particles",
            "500",
            "-qq",
            "--png",
            "--png-size",
            "2048",
            "--out",
        ])
        .arg(&out)
        .status()
        .unwrap();
    assert!(st.success());
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    let r = &m["results"];
    let sim = r["simulation_peak_rss_bytes"].as_u64().unwrap();
    let output = r["output_peak_rss_bytes"].as_u64().unwrap();
    assert!(sim > 0);
    assert_eq!(
        r["bytes_per_particle"].as_f64().unwrap(),
        sim as f64 / 500.0
    );
    assert!(output >= sim, "simulation {sim}, output {output}");
    assert_eq!(m["peak_rss_bytes"].as_u64().unwrap(), output);
}

/// `--png-size` sizes dla.png, and `--animate` writes dla.gif with a frame every
/// `--animate-every` particles and one of the whole cluster, all of one size.
#[test]
fn png_size_and_animation() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    let o = dla()
        .args([
            "--particles",
            "300",
            "--seed",
            "2",
            "--png",
            "--png-size",
            "64",
        ])
        .args(["--animate", "--animate-every", "100", "--quiet", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let png = std::fs::read(out.join("dla.png")).unwrap();
    let side = |at: usize| u32::from_be_bytes(png[at..at + 4].try_into().unwrap());
    assert!(side(16) > 64 && side(20) > 64);
    // 100, 200 and the whole cluster of 300.
    let ((w, h), frames) = figures::animation::read_gif(&out.join("dla.gif")).unwrap();
    assert_eq!(frames, 3);
    assert_eq!((w, h), (side(16), side(20)));
}
