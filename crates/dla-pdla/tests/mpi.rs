//! `dla --seeds` under an MPI launcher, as an HPC user meets it: with the feature `mpi`, under
//! Open MPI's `mpirun` (CI's `mpi-tests` step): members get every core of the job whatever the
//! launcher's binding, rank 0 dispatches without burning a core, a killed rank takes its members
//! along, and SIGTERM to the ranks (or SIGUSR1 to `mpirun`) stops the job with exit code 130.
//! Without the feature: a start under a launcher is refused with the build command.

use std::process::{Command, Output};

const DLA: &str = env!("CARGO_BIN_EXE_dla");

#[cfg(feature = "mpi")]
mod under_mpirun {
    use super::*;
    use std::path::{Path, PathBuf};
    use std::time::{Duration, Instant};

    /// Waits until `ok()` or `secs` have passed; returns whether `ok()` held.
    fn wait_for(secs: u64, mut ok: impl FnMut() -> bool) -> bool {
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(secs) {
            if ok() {
                return true;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        ok()
    }

    fn json(p: &Path) -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display())))
            .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
    }

    /// The process holding `dir/run.lock` (a run, or an ensemble's rank 0), from the lock file.
    fn holder(dir: &Path) -> Option<u32> {
        let v: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join("run.lock")).ok()?).ok()?;
        v["pid"].as_u64().and_then(|p| u32::try_from(p).ok())
    }

    /// `/proc/PID/stat`: the state and the parent of a live process.
    fn stat(pid: u32) -> Option<(char, u32)> {
        let text = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
        // `pid (comm) state ppid ...`; comm may hold spaces, so read after its last `)`.
        let mut rest = text[text.rfind(')')? + 1..].split_whitespace();
        let state = rest.next()?.chars().next()?;
        let ppid = rest.next()?.parse().ok()?;
        Some((state, ppid))
    }

    fn alive(pid: u32) -> bool {
        stat(pid).is_some_and(|(state, _)| state != 'Z' && state != 'X')
    }

    /// Sends `sig` (`KILL`, `TERM`, `USR1`) to `pid`.
    fn signal(pid: u32, sig: &str) {
        let _ = Command::new("kill")
            .arg(format!("-{sig}"))
            .arg(pid.to_string())
            .status();
    }

    /// The state hash of the plain run of `seed` with `flags`.
    fn plain_hash(dir: &Path, seed: u64, flags: &[&str]) -> serde_json::Value {
        let out = dir.join(format!("plain-{seed}"));
        let o = Command::new(DLA)
            .args(["--seed", &seed.to_string(), "-qq", "--out"])
            .arg(&out)
            .args(flags)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        json(&out.join("run.json"))["results"]["state_hash"].clone()
    }

    fn member(ens: &Path, seed: u64) -> PathBuf {
        ens.join(format!("seed-{seed:04}"))
    }

    fn mpirun(np: usize, launcher: &[&str], args: &[&str], ens: &Path) -> Command {
        let mut cmd = Command::new("mpirun");
        cmd.args([
            "--allow-run-as-root",
            "--oversubscribe",
            "-np",
            &np.to_string(),
        ])
        .args(launcher)
        .arg(DLA)
        .args(args)
        .arg("--out")
        .arg(ens)
        // Read at the end only (`mpirun` says little), or by `output()`.
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped());
        cmd
    }

    fn finish(cmd: &mut Command) -> Output {
        cmd.output().expect("mpirun starts (Open MPI installed)")
    }

    /// A job bound as Open MPI binds two ranks by default (`--bind-to core`): each rank is
    /// bound to one core, yet its members get every CPU the job has here (`provenance.cpus`),
    /// each `run.json` names its rank and the share of the node's CPUs its rank sized `--jobs`
    /// by. Rank 0, which hands out the members besides running its own, reports its CPU time
    /// over the job: near zero (a blocking MPI receive would keep it near the wall time).
    #[test]
    fn members_get_the_jobs_cores_under_default_binding_and_rank_0_rests() {
        let dir = tempfile::tempdir().unwrap();
        let ens = dir.path().join("ens");
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        let o = finish(&mut mpirun(
            2,
            &["--bind-to", "core"],
            &[
                "--seeds",
                "1..=4",
                "--particles",
                "20000",
                "--checkpoint-every",
                "500",
                "-v",
                "--heartbeat",
                "0",
            ],
            &ens,
        ));
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        if cpus > 1 {
            // The launcher did bind the ranks; their members were widened anyway.
            assert!(err.contains("bound by the launcher to 1 CPUs"), "{err}");
        }
        for seed in 1..=4 {
            let p = &json(&member(&ens, seed).join("run.json"))["provenance"];
            assert_eq!(p["cpus"], cpus, "seed {seed}: {p}");
            let rank = p["mpi"]["rank"].as_u64().unwrap_or_else(|| panic!("{p}"));
            assert!(rank < 2, "{p}");
            let share = run_cli::ensemble::node_share(cpus, 2, rank as usize);
            assert_eq!(
                p["mpi"],
                serde_json::json!({"rank": rank, "ranks": 2, "cpus": share}),
                "seed {seed}"
            );
            assert_eq!(p["host"], run_io::provenance::host_name());
        }
        // `dla: MPI rank 0 dispatched 4 members over 2 ranks in W s of wall time, using C s of
        // CPU itself`
        let line = err
            .lines()
            .find(|l| l.contains("MPI rank 0 dispatched 4 members"))
            .unwrap_or_else(|| panic!("{err}"));
        let numbers: Vec<f64> = line
            .split_whitespace()
            .filter_map(|w| w.parse().ok())
            .collect();
        let [_, _, _, wall, cpu] = numbers[..] else {
            panic!("{line}")
        };
        assert!(
            cpu <= 0.1 * wall + 0.1,
            "rank 0 used {cpu} s of CPU over {wall} s: {line}"
        );
    }

    /// A rank killed (SIGKILL) while its member runs: Open MPI aborts the job, and the member dies
    /// with its rank rather than running on as an orphan. Run again at once, the ensemble resumes
    /// the member from its checkpoint and both members end as the plain runs of their seeds.
    #[test]
    fn a_killed_rank_leaves_no_member_and_the_rerun_matches_plain_runs() {
        let dir = tempfile::tempdir().unwrap();
        let ens = dir.path().join("ens");
        let flags = ["--particles", "20000", "--checkpoint-every", "500"];
        let args = [&["--seeds", "1..=2", "--jobs", "1", "-qq"][..], &flags].concat();
        let mut job = mpirun(2, &[], &args, &ens).spawn().expect("mpirun starts");
        let first = member(&ens, 1);
        assert!(
            wait_for(120, || first.join("checkpoint.bin").exists()),
            "no checkpoint from member 1"
        );
        let pid = holder(&first).expect("the member's lock names it");
        let (_, rank) = stat(pid).expect("the member runs");
        signal(rank, "KILL");
        let status = job.wait().unwrap();
        assert!(!status.success(), "{status}");
        assert!(
            wait_for(5, || !alive(pid)),
            "member {pid} outlived its rank {rank}: {:?}",
            stat(pid)
        );
        assert!(!first.join("run.json").exists(), "member 1 finished first");
        let o = finish(&mut mpirun(2, &[], &args, &ens));
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        for seed in [1, 2] {
            assert_eq!(
                json(&member(&ens, seed).join("run.json"))["results"]["state_hash"],
                plain_hash(dir.path(), seed, &flags),
                "seed {seed}"
            );
        }
    }

    /// SIGTERM to every rank (what Slurm sends at a time limit or `scancel`, and `srun` passes
    /// on), then SIGUSR1 to `mpirun` (which Open MPI passes on to every rank): each stops the job
    /// with exit code 130, the running members stopped at a safe point (a checkpoint, no
    /// `run.json`, a log whose every line is whole and whose last says how to continue). The
    /// third run finishes the ensemble as plain runs.
    #[test]
    fn signals_stop_the_job_with_130_and_members_at_a_safe_point() {
        let dir = tempfile::tempdir().unwrap();
        let ens = dir.path().join("ens");
        // Members long enough (about a second each) that the signals always find some running,
        // however fast the machine.
        let flags = ["--particles", "200000", "--checkpoint-every", "5000"];
        let args = [&["--seeds", "1..=4", "--jobs", "1", "-qq"][..], &flags].concat();
        let check_stopped = |o: &Output, how: &str| {
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(130), "{how}: {err}");
            let mut stopped = 0;
            for seed in 1..=4 {
                let m = member(&ens, seed);
                let Ok(log) = std::fs::read_to_string(m.join("member.log")) else {
                    continue;
                };
                if m.join("run.json").exists() {
                    continue;
                }
                stopped += 1;
                assert!(m.join("checkpoint.bin").exists(), "{how}: seed {seed}");
                assert!(log.ends_with('\n'), "{how}: seed {seed}: {log:?}");
                let last = log.lines().last().unwrap_or_default();
                assert!(last.contains("interrupted"), "{how}: seed {seed}: {log:?}");
            }
            assert!(stopped > 0, "{how}: no member was stopped: {err}");
        };
        // Both workers run a member (each has a checkpoint), then every rank gets SIGTERM.
        let running = |seeds: &[u64]| {
            let ens = ens.clone();
            let seeds = seeds.to_vec();
            move || {
                seeds
                    .iter()
                    .filter(|&&s| {
                        let m = member(&ens, s);
                        m.join("checkpoint.bin").exists() && !m.join("run.json").exists()
                    })
                    .count()
                    >= 2
            }
        };
        let job = mpirun(3, &[], &args, &ens).spawn().expect("mpirun starts");
        assert!(wait_for(120, running(&[1, 2, 3, 4])), "no two members ran");
        let mut ranks = vec![holder(&ens).expect("rank 0 holds the ensemble's lock")];
        for seed in 1..=4 {
            if let Some((_, rank)) = holder(&member(&ens, seed)).and_then(stat) {
                ranks.push(rank);
            }
        }
        // Once each: rank 0 holds the lock and runs a member too.
        ranks.sort_unstable();
        ranks.dedup();
        for &r in &ranks {
            signal(r, "TERM");
        }
        check_stopped(&job.wait_with_output().unwrap(), "SIGTERM to the ranks");
        // The same command continues; SIGUSR1 to mpirun once a member runs again.
        let job = mpirun(3, &[], &args, &ens).spawn().unwrap();
        let logs: Vec<_> = (1..=4)
            .map(|s| {
                std::fs::metadata(member(&ens, s).join("member.log"))
                    .and_then(|m| m.modified())
                    .ok()
            })
            .collect();
        let restarted = || {
            (1..=4).any(|s| {
                let now = std::fs::metadata(member(&ens, s).join("member.log"))
                    .and_then(|m| m.modified())
                    .ok();
                now.is_some() && now != logs[s as usize - 1]
            })
        };
        assert!(wait_for(120, restarted), "the rerun started no member");
        std::thread::sleep(Duration::from_millis(300));
        signal(job.id(), "USR1");
        check_stopped(&job.wait_with_output().unwrap(), "SIGUSR1 to mpirun");
        let o = finish(&mut mpirun(3, &[], &args, &ens));
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        for seed in [1, 2] {
            assert_eq!(
                json(&member(&ens, seed).join("run.json"))["results"]["state_hash"],
                plain_hash(dir.path(), seed, &flags),
                "seed {seed}"
            );
        }
    }
}

/// `--version` names the features built in.
#[test]
fn version_names_the_features() {
    let o = Command::new(DLA).arg("--version").output().unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{out}");
    let want = if cfg!(feature = "mpi") {
        "features: mpi;"
    } else {
        "features: none"
    };
    assert!(out.contains(want), "{out}");
}

/// A build without MPI support, started as one of several ranks (the launcher's environment,
/// and under Open MPI's `mpirun` where it is installed), refuses with exit code 2 and one line
/// giving the build command, creating nothing; `--version` still answers.
#[cfg(not(feature = "mpi"))]
#[test]
fn a_build_without_mpi_refuses_to_run_as_one_of_several_ranks() {
    let dir = tempfile::tempdir().unwrap();
    let args = ["--seeds", "1..=2", "--particles", "300", "--out", "ens"];
    let refused = |o: &Output, how: &str| {
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{how}: {err}");
        let line = err
            .lines()
            .find(|l| l.starts_with("dla: error:"))
            .unwrap_or_else(|| panic!("{how}: {err}"));
        assert!(
            line.contains("built without MPI support")
                && line.contains("cargo build --release -p dla-pdla --features mpi"),
            "{how}: {line}"
        );
        assert!(!dir.path().join("ens").exists(), "{how}");
    };
    for (var, value) in [("OMPI_COMM_WORLD_SIZE", "3"), ("PMI_SIZE", "2")] {
        let o = Command::new(DLA)
            .args(args)
            .env(var, value)
            .current_dir(dir.path())
            .output()
            .unwrap();
        refused(&o, var);
        assert_eq!(String::from_utf8_lossy(&o.stderr).lines().count(), 1);
    }
    let o = Command::new(DLA)
        .arg("--version")
        .env("OMPI_COMM_WORLD_SIZE", "3")
        .output()
        .unwrap();
    assert!(o.status.success());
    // One rank, or none: runs.
    let o = Command::new(DLA)
        .args(["--seed", "1", "--particles", "50", "-qq", "--out", "one"])
        .env("OMPI_COMM_WORLD_SIZE", "1")
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let have_mpirun = std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|d| d.join("mpirun").is_file()));
    if have_mpirun {
        let o = Command::new("mpirun")
            .args(["--allow-run-as-root", "--oversubscribe", "-np", "2", DLA])
            .args(args)
            .current_dir(dir.path())
            .output()
            .unwrap();
        refused(&o, "mpirun -np 2");
    }
}
