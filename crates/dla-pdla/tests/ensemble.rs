//! `dla --seeds`: members run, fail alone, restart, and combine (`ensemble.json`), and
//! `--merge` rebuilds the combined result.

use std::path::Path;

#[test]
fn ensembles_run_combine_restart_and_merge() {
    let dir = tempfile::tempdir().unwrap();
    run_cli::testing::ensemble_contract(
        Path::new(env!("CARGO_BIN_EXE_dla")),
        "dla",
        dir.path(),
        &["--particles", "300"],
        "radius_of_gyration",
    );
}

/// Members that checkpoint: an ensemble killed (with its members) while the first member runs
/// leaves that member with a checkpoint and no `run.json`; run again, the ensemble resumes it
/// (`--resume`), and it ends as the plain run with its seed.
#[test]
fn checkpointed_members_are_resumed() {
    use std::process::Command;
    let dir = tempfile::tempdir().unwrap();
    let dla = env!("CARGO_BIN_EXE_dla");
    let flags = ["--particles", "20000", "--checkpoint-every", "500"];
    let ens = dir.path().join("ens");
    let mut cmd = Command::new(dla);
    cmd.args(["--seeds", "1..=2", "--jobs", "1", "-qq", "--out"])
        .arg(&ens)
        .args(flags);
    let running =
        run_cli::testing::kill_group_once_written(&mut cmd, &ens.join("seed-0001/checkpoint.bin"));
    assert!(running, "the ensemble ended before it could be killed");
    assert!(
        !ens.join("seed-0001/run.json").exists(),
        "member 1 finished before the kill"
    );
    let o = Command::new(dla)
        .args(["--seeds", "1..=2", "--out"])
        .arg(&ens)
        .args(flags)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("(0 already, 1 resumed from a checkpoint)"),
        "{err}"
    );
    let o = Command::new(dla)
        .args(["--seed", "1", "-qq", "--out"])
        .arg(dir.path().join("plain"))
        .args(flags)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let hash = |p: &Path| -> serde_json::Value {
        let m: serde_json::Value =
            serde_json::from_slice(&std::fs::read(p.join("run.json")).unwrap()).unwrap();
        m["results"]["state_hash"].clone()
    };
    assert_eq!(
        hash(&ens.join("seed-0001")),
        hash(&dir.path().join("plain"))
    );
}

/// A member directory that a live process holds (its `run.lock`: a member of an earlier job
/// still stopping, a run started by hand) is never shared: the ensemble waits for it, then
/// reports that member failed naming the holder, without touching its files; the others
/// finish. Once the holder has gone, the same command finishes the ensemble.
#[test]
fn a_member_directory_held_by_a_live_process_is_not_shared() {
    use std::process::Command;
    let dir = tempfile::tempdir().unwrap();
    let ens = dir.path().join("ens");
    let held = ens.join("seed-0002");
    let lock = run_cli::cli::claim_out_dir(&run_cli::cli::Claim::single(&held, &[], None, false))
        .expect("the test holds member 2's directory");
    std::fs::write(held.join("member.log"), "the holder's log\n").unwrap();
    let run = || {
        Command::new(env!("CARGO_BIN_EXE_dla"))
            .args(["--seeds", "1..=2", "--particles", "300", "--out"])
            .arg(&ens)
            .output()
            .unwrap()
    };
    let o = run();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("seed 2:")
            && err.contains(&format!(
                "in use by another run (pid {}",
                std::process::id()
            )),
        "{err}"
    );
    assert!(ens.join("seed-0001/run.json").exists(), "{err}");
    assert_eq!(
        std::fs::read_to_string(held.join("member.log")).unwrap(),
        "the holder's log\n"
    );
    drop(lock);
    let o = run();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(held.join("run.json").exists());
}

/// `mpirun -np 3 dla --seeds ...` (feature `mpi`, Open MPI installed): rank 0 hands the members
/// out, ranks 1 and 2 run them; the combined result and every member are those of a local
/// ensemble, and a member that cannot run is reported by seed.
#[cfg(feature = "mpi")]
#[test]
fn ensembles_over_mpi_ranks() {
    use std::process::Command;
    let dir = tempfile::tempdir().unwrap();
    let dla = env!("CARGO_BIN_EXE_dla");
    let run = |args: &[&str]| {
        Command::new("mpirun")
            .args(["--allow-run-as-root", "--oversubscribe", "-np", "3", dla])
            .args(args)
            .args(["--particles", "500", "--jobs", "1", "-qq"])
            .current_dir(dir.path())
            .output()
            .expect("mpirun starts (Open MPI installed)")
    };
    std::fs::create_dir_all(dir.path().join("mpi")).unwrap();
    std::fs::write(dir.path().join("mpi/seed-0004"), b"in the way").unwrap();
    let o = run(&["--seeds", "1..=6", "--out", "mpi"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("seed 4:"), "{err}");
    let o = Command::new(dla)
        .args([
            "--seeds",
            "1..=6",
            "--particles",
            "500",
            "--out",
            "local",
            "-qq",
        ])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json = |p: &str| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(dir.path().join(p)).unwrap()).unwrap()
    };
    for seed in [1, 2, 3, 5, 6] {
        let m = format!("seed-{seed:04}/run.json");
        assert_eq!(
            json(&format!("mpi/{m}"))["results"]["state_hash"],
            json(&format!("local/{m}"))["results"]["state_hash"]
        );
    }
    assert_eq!(json("mpi/ensemble.json")["members"], 5);
    std::fs::remove_file(dir.path().join("mpi/seed-0004")).unwrap();
    let o = run(&["--seeds", "1..=6", "--out", "mpi"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The physics is the same; the time and memory of the members are not.
    for key in ["radius_of_gyration", "r_ext", "particles"] {
        assert_eq!(
            json("mpi/ensemble.json")["results"][key],
            json("local/ensemble.json")["results"][key],
            "{key}"
        );
    }
    assert_eq!(json("mpi/ensemble.json")["members"], 6);
}
