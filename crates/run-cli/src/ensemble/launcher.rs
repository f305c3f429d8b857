//! What a process can tell about how it was started: by an MPI launcher as one of several
//! ranks (`mpirun`, `srun --mpi=...`, `mpiexec`), or by an ensemble as one of its members; and
//! how the ranks on one node share its CPUs. Both builds use it: a build without the feature
//! `mpi` refuses to run as one of several ranks ([`refuse_without_mpi`]), where every rank
//! would otherwise run the whole command in the same directory.

use crate::cli::MEMBER_OF;
use std::ffi::OsString;
use std::process::ExitCode;

/// Environment variables through which MPI launchers tell a process how many ranks its job
/// has: Open MPI (`mpirun`, also under Slurm), MPICH's and Intel MPI's Hydra (`PMI_SIZE`, also
/// `srun --mpi=pmi2`), MVAPICH2. A plain Slurm job or a single-task `srun` sets none of them,
/// so they never refuse an ordinary batch job.
pub const SIZE_VARS: [&str; 3] = ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "MV2_COMM_WORLD_SIZE"];

/// The launcher's claim that this process is one of several ranks: `(variable, ranks)`, from
/// [`SIZE_VARS`], or under `srun --mpi=pmix` (which sets `PMIX_RANK` but no size) from
/// `SLURM_STEP_NUM_TASKS`. `None` for a process started on its own or as the only rank.
pub fn launcher_ranks() -> Option<(String, u64)> {
    launcher_ranks_in(|k| std::env::var_os(k))
}

fn launcher_ranks_in(var: impl Fn(&str) -> Option<OsString>) -> Option<(String, u64)> {
    let number = |k: &str| {
        var(k)
            .and_then(|v| v.to_str().and_then(|s| s.trim().parse::<u64>().ok()))
            .map(|n| (format!("{k}={n}"), n))
    };
    let found = SIZE_VARS.iter().find_map(|k| number(k)).or_else(|| {
        var("PMIX_RANK")
            .is_some()
            .then(|| number("SLURM_STEP_NUM_TASKS"))
            .flatten()
    });
    found.filter(|(_, n)| *n > 1)
}

/// The Cargo package of a model binary, for the build command a refusal gives.
fn package(program: &str) -> &str {
    match program {
        "dla" => "dla-pdla",
        other => other,
    }
}

/// The command that builds `program` with MPI support, into a target directory of its own so
/// that a plain build never replaces it.
pub fn mpi_build_command(program: &str) -> String {
    format!(
        "CARGO_TARGET_DIR=target/mpi cargo build --release -p {} --features mpi",
        package(program)
    )
}

/// A build without the feature `mpi`, started as one of several ranks of an MPI job: one
/// line naming the launcher's variable and the build command, and exit code 2. `--version` and
/// `--help` still answer (they start nothing), so `mpirun -np 2 PROG --version` tells which
/// build it is. `None` (go on) for a build with MPI support or a process not under a launcher.
pub fn refuse_without_mpi(program: &str) -> Option<ExitCode> {
    if cfg!(feature = "mpi") {
        return None;
    }
    let (var, ranks) = launcher_ranks()?;
    let asks_only = std::env::args_os()
        .skip(1)
        .any(|a| ["--version", "-V", "--help", "-h"].iter().any(|f| a == *f));
    if asks_only {
        return None;
    }
    crate::cli::say(&format!(
        "{program}: error: started as one of {ranks} MPI ranks ({var}) but built without MPI support, so every rank would run the whole command; build with `{}` and run target/mpi/release/{program} (docs/ensembles.md)",
        mpi_build_command(program)
    ));
    Some(ExitCode::from(crate::cli::EXIT_USAGE))
}

/// In a member: asks the kernel to kill this process when the process that started it ends
/// (`PR_SET_PDEATHSIG`), so that a member never outlives its ensemble or MPI rank, however that
/// ends (a rank killed by the launcher, SIGKILL, a crash). Its last checkpoint, written
/// atomically, stays; the rerun resumes from it. If the ensemble has already gone (the window
/// between start and this call), the member stops at once. A member also ignores SIGUSR1,
/// which asks an ensemble to stop ([`super::run`]) and which a batch system may send to every
/// process of a job: its ensemble passes the request on as SIGTERM. Outside an ensemble,
/// nothing.
///
/// The kernel sends the signal when the *thread* that started the member ends: an ensemble
/// starts each member from the thread that then waits for it.
pub fn tie_member_to_ensemble() -> Option<ExitCode> {
    let parent: u32 = std::env::var(MEMBER_OF).ok()?.parse().ok()?;
    let ignored = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let _ = signal_hook::flag::register(signal_hook::consts::SIGUSR1, ignored);
    #[cfg(target_os = "linux")]
    {
        use nix::sys::signal::Signal;
        if nix::sys::prctl::set_pdeathsig(Signal::SIGKILL).is_err() {
            return None;
        }
        let ppid = nix::unistd::getppid().as_raw();
        if u32::try_from(ppid).ok() != Some(parent) {
            return Some(ExitCode::from(crate::cli::EXIT_RUN_FAILED));
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = parent;
    None
}

/// The share of a node's `cpus` that worker `index` of the `workers` ranks on that node sizes
/// its members by: an equal split, the remainder going to the first ranks, at least one each.
pub fn node_share(cpus: usize, workers: usize, index: usize) -> usize {
    let workers = workers.max(1);
    let (base, extra) = (cpus / workers, cpus % workers);
    (base + usize::from(index < extra)).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env<'a>(pairs: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<OsString> + 'a {
        move |k| {
            pairs
                .iter()
                .find(|(n, _)| *n == k)
                .map(|(_, v)| OsString::from(v))
        }
    }

    #[test]
    fn launchers_are_recognised_by_their_rank_counts_only() {
        let ranks = |p: &[(&str, &str)]| launcher_ranks_in(env(p));
        assert_eq!(
            ranks(&[("OMPI_COMM_WORLD_SIZE", "3")]),
            Some(("OMPI_COMM_WORLD_SIZE=3".into(), 3))
        );
        assert_eq!(ranks(&[("PMI_SIZE", "4"), ("PMI_RANK", "1")]).unwrap().1, 4);
        assert_eq!(
            ranks(&[("PMIX_RANK", "0"), ("SLURM_STEP_NUM_TASKS", "5")]).unwrap(),
            ("SLURM_STEP_NUM_TASKS=5".into(), 5)
        );
        // One rank, or a plain Slurm job or task without an MPI launcher: not refused.
        assert_eq!(ranks(&[("OMPI_COMM_WORLD_SIZE", "1")]), None);
        assert_eq!(
            ranks(&[("SLURM_STEP_NUM_TASKS", "4"), ("SLURM_PROCID", "2")]),
            None
        );
        assert_eq!(ranks(&[("SLURM_NTASKS", "8"), ("SLURM_JOB_ID", "7")]), None);
        assert_eq!(ranks(&[]), None);
    }

    #[test]
    fn a_node_is_shared_equally_by_its_worker_ranks() {
        assert_eq!(node_share(2, 1, 0), 2);
        let shares: Vec<usize> = (0..3).map(|i| node_share(64, 3, i)).collect();
        assert_eq!(shares, [22, 21, 21]);
        assert_eq!(node_share(2, 4, 3), 1);
        assert_eq!(
            mpi_build_command("dla"),
            "CARGO_TARGET_DIR=target/mpi cargo build --release -p dla-pdla --features mpi"
        );
    }
}
