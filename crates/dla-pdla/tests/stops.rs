//! Long runs are safe without a flag: a signal at a random moment of a `dla` run started with
//! no checkpoint flag checkpoints it (exit code 130), memory about to run out does too (exit
//! code 1), and `--resume` ends it with the uninterrupted run's state hash; a run that ends
//! normally leaves neither `checkpoint.bin` nor the `positions.npy` only the checkpoints needed.

use run_cli::testing::stop_contract;
use std::path::Path;

#[test]
fn every_stop_is_a_checkpoint_and_resumes_to_the_uninterrupted_run() {
    let dir = tempfile::tempdir().unwrap();
    let failures = stop_contract(
        Path::new(env!("CARGO_BIN_EXE_dla")),
        "dla",
        dir.path(),
        &["--particles", "150000", "--seed", "7", "-qq"],
        &["positions.npy"],
    );
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// An ensemble started without a checkpoint flag and stopped by SIGTERM mid-member (its
/// member checkpoints) exits with code 130; the same command then resumes that member and
/// each member ends with the state hash of the same seed run alone.
#[cfg(unix)]
#[test]
fn an_ensemble_signalled_mid_member_continues_to_the_same_members() {
    use run_cli::testing::state_hash;
    use std::process::{Command, Stdio};
    let dla = env!("CARGO_BIN_EXE_dla");
    let dir = tempfile::tempdir().unwrap();
    // A member takes about 0.7 s on a 2026 server core: the signal 100 ms into the first
    // finds it growing on any host.
    let flags = ["--particles", "300000", "-qq"];
    let ens = dir.path().join("ens");
    let ensemble = || {
        let mut c = Command::new(dla);
        c.args(flags)
            .args(["--seeds", "1,2", "--jobs", "1", "--out"])
            .arg(&ens)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped());
        c
    };
    let mut child = ensemble().spawn().unwrap();
    // Until the first member is under way.
    let first = ens.join("seed-0001").join("growth.csv");
    while !first.exists() && child.try_wait().unwrap().is_none() {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    std::thread::sleep(std::time::Duration::from_millis(100));
    assert!(
        child.try_wait().unwrap().is_none() && !ens.join("seed-0002").exists(),
        "the first member ended before the signal"
    );
    run_cli::testing::send_sigterm(child.id());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(
        ens.join("seed-0001/checkpoint.bin").exists(),
        "the signalled member left no checkpoint: {err}"
    );
    let o = ensemble().output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    for seed in ["1", "2"] {
        let alone = dir.path().join(format!("alone-{seed}"));
        let st = Command::new(dla)
            .args(flags)
            .args(["--seed", seed, "--out"])
            .arg(&alone)
            .status()
            .unwrap();
        assert!(st.success());
        let member = ens.join(format!("seed-000{seed}"));
        assert_eq!(state_hash(&member), state_hash(&alone), "seed {seed}");
        assert!(!member.join("checkpoint.bin").exists(), "seed {seed}");
    }
}

/// PDLA started without a checkpoint flag and stopped by SIGTERM mid-run checkpoints at a
/// quiescent point (exit code 130); `--resume` ends it as a valid cluster of the full size.
/// The run is large enough (about a second on two threads of a 2026 server core) that the
/// signal, sent 300 ms after the start, finds it growing on any host.
#[cfg(unix)]
#[test]
fn a_pdla_run_signalled_mid_growth_resumes_to_a_full_cluster() {
    use std::process::{Command, Stdio};
    let dla = env!("CARGO_BIN_EXE_dla");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pdla");
    let flags = [
        "--particles",
        "600000",
        "--threads",
        "2",
        "--serial-until",
        "1000",
        "-qq",
    ];
    let mut child = Command::new(dla)
        .args(flags)
        .arg("--out")
        .arg(&out)
        .stdin(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(300));
    assert!(
        child.try_wait().unwrap().is_none(),
        "the run ended before the signal"
    );
    run_cli::testing::send_sigterm(child.id());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(err.starts_with("dla: SIGTERM: interrupted at "), "{err}");
    assert!(out.join("checkpoint.bin").exists());
    let o = Command::new(dla)
        .args(flags)
        .arg("--resume")
        .arg(&out)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(m["results"]["particles"], 600000, "{m}");
    assert!(!out.join("checkpoint.bin").exists());
    assert!(!out.join("positions.npy").exists());
}
