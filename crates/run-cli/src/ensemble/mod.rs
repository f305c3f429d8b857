//! Ensembles (feature `cli`): one run per seed, combined into one result with error bars.
//!
//! `PROG --seeds 1..=80 [flags] --out DIR` runs each member as an ordinary run of the model's
//! own binary, `PROG [flags] --seed S --out DIR/seed-NNNN -qq`, so a member has its own
//! `run.json`, outputs and checkpoint and can be rerun or inspected alone. Members run as child
//! processes, `--jobs` at a time: a member that fails or crashes cannot take the others down.
//!
//! - **Restartable.** Rerunning the same command skips members with a `run.json`, resumes those
//!   with a `checkpoint.bin` (`--resume`), and runs the rest. Only members made with the same
//!   parameters are continued: a member made with others (its `run.json`, or the `config.toml`
//!   of an unfinished one) refuses the whole rerun as a usage error naming each differing flag
//!   with both values; `--overwrite` starts the ensemble over.
//! - **Owned.** The ensemble locks its directory and each member its own
//!   ([`claim_out_dir`](crate::cli::claim_out_dir)), so two ensembles (or a run) cannot share
//!   one.
//! - **Failures.** A failed member is reported with its seed and the last line it printed
//!   (kept in `DIR/seed-NNNN/member.log`); the others go on; the exit code is 1 if any failed.
//! - **Signals.** SIGINT, SIGTERM, SIGUSR1 or SIGXCPU stop launching members and pass SIGTERM on
//!   to the running ones (which checkpoint, unless run with `--no-checkpoint`); the ensemble
//!   exits with code 130.
//! - **Combined result** ([`merge`]): `DIR/ensemble.json`, `DIR/ensemble.md` and averaged
//!   curves with error bands, rebuilt from whatever members exist by `PROG --merge DIR`.

mod launcher;
mod member;
mod merge;
#[cfg(feature = "mpi")]
mod ranks;
mod seeds;

pub use launcher::{
    SIZE_VARS, launcher_ranks, mpi_build_command, node_share, refuse_without_mpi,
    tie_member_to_ensemble,
};
pub use member::{MEMBER_LOG, member_dir};
pub use merge::{
    Combine, Curve, MemberRun, MergeReport, Pooled, PooledResult, ScalarStats, merge, merge_with,
};
pub use seeds::{Seeds, parse_seeds};

use crate::cli::{Interrupted, LogArgs, MEMBER_OF};
use anyhow::{Context, anyhow};
use member::{Ended, Member, Todo, member_args, run_member, todo};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// The ensemble flags every model's command line flattens in.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct EnsembleArgs {
    /// Run an ensemble: one run per seed, each in DIR/seed-NNNN/ (DIR = --out) with its own
    /// run.json and outputs, combined into DIR/ensemble.json and ensemble.md (mean, standard
    /// deviation and standard error of every result) and averaged curves. LIST: 1..=80, 1..81,
    /// 3,5,9 or a mix. Rerunning the command skips finished members and resumes checkpointed
    /// ones, if they were made with the same parameters (else it is refused; --overwrite starts
    /// over). `--merge DIR` alone rebuilds the combined result from the members in DIR.
    #[arg(long, value_name = "LIST", value_parser = seeds::parse_seeds_arg, conflicts_with_all = ["seed", "resume"])]
    pub seeds: Option<Seeds>,

    /// With --seeds: members run at once (default: the cores divided by each member's threads).
    #[arg(long, value_name = "J", requires = "seeds", value_parser = parse_jobs)]
    pub jobs: Option<u64>,

    /// Rebuild an ensemble's combined result (ensemble.json, ensemble.md, averaged curves) from
    /// the members in DIR, finished or not, and exit: `PROG --merge DIR`, with no other flag.
    #[arg(long, value_name = "DIR", exclusive = true)]
    pub merge: Option<PathBuf>,
}

/// Most members `--jobs` runs at once.
pub const MAX_JOBS: u64 = 4096;

/// `--jobs`: a count (any notation of [`run_io::count::count`]) in `1..=MAX_JOBS`.
fn parse_jobs(s: &str) -> Result<u64, String> {
    let j = run_io::count::count::<u64>(s)?;
    if (1..=MAX_JOBS).contains(&j) {
        Ok(j)
    } else {
        Err(format!("{j} is outside the accepted range 1..={MAX_JOBS}"))
    }
}

impl EnsembleArgs {
    /// Runs the ensemble these flags ask for, if they ask for one (`--seeds`): the branch every
    /// model binary takes before its own run. `member_threads` is each member's `--threads`.
    pub fn run<'c>(
        &self,
        program: &str,
        member_threads: usize,
        out: &Path,
        combine: impl Into<Combine<'c>>,
        log: &LogArgs,
        owner: &Owner<'_>,
    ) -> Option<anyhow::Result<()>> {
        let seeds = self.seeds.as_ref()?;
        Some(run(&Ensemble {
            program,
            seeds: &seeds.0,
            jobs: self.jobs,
            member_threads,
            out,
            combine: combine.into(),
            log,
            owner,
        }))
    }
}

/// One ensemble to run.
#[derive(Debug, Clone, Copy)]
pub struct Ensemble<'a> {
    /// The model binary's name (`dla`, `dlca`, `animat`), as in `run.json`'s `model`.
    pub program: &'a str,
    /// The members' seeds.
    pub seeds: &'a [u64],
    /// `--jobs`, if given.
    pub jobs: Option<u64>,
    /// Threads each member uses (`--threads` of the model, 1 if it has none).
    pub member_threads: usize,
    /// The ensemble's directory (`--out`).
    pub out: &'a Path,
    /// The curves to average and the results to pool.
    pub combine: Combine<'a>,
    /// The logging flags.
    pub log: &'a LogArgs,
    /// What the members must agree on, and `--overwrite`.
    pub owner: &'a Owner<'a>,
}

/// What makes an ensemble's members its own: the parameters they must have been made with.
#[derive(Debug, Clone)]
pub struct Owner<'a> {
    /// The model's output files (as [`Claim::run_files`](crate::cli::Claim::run_files)).
    pub run_files: &'a [&'a str],
    /// The model's parameters as `run.json` records them (`params`), compared with each
    /// finished member's.
    pub params: serde_json::Value,
    /// The configuration a member saves as `config.toml` (less its `seed`), compared with each
    /// unfinished member's; `None` to skip that comparison.
    pub config: Option<String>,
    /// Run flags that change the result but are not parameters (animat's `--steps`), as
    /// `(flag, value given, default)`: compared with the flag on each finished member's
    /// recorded command line (`provenance.command_line` of its `run.json`).
    pub run_flags: Vec<(&'a str, String, String)>,
    /// `--overwrite`: start the ensemble over.
    pub overwrite: bool,
}

/// The value of `flag` on a recorded command line (`--flag V` or `--flag=V`), if given.
fn flag_value(line: &[String], flag: &str) -> Option<String> {
    let eq = format!("{flag}=");
    line.iter().enumerate().find_map(|(i, a)| {
        if a == flag {
            line.get(i + 1).cloned()
        } else {
            a.strip_prefix(&eq).map(str::to_owned)
        }
    })
}

/// Runs the ensemble and writes its combined result; see the module documentation.
pub fn run(e: &Ensemble<'_>) -> anyhow::Result<()> {
    let exe = std::env::current_exe().context("locating the model's binary for the members")?;
    let args = member_args(std::env::args_os().skip(1));
    let stop = crate::cli::stop_on_signals().context("installing signal handlers")?;
    // SIGUSR1 asks for the same stop: Open MPI's mpirun passes it on to every rank, while it
    // turns SIGTERM and SIGINT into an abort of its own (exit code 1, SIGKILL after a second).
    signal_hook::flag::register(signal_hook::consts::SIGUSR1, std::sync::Arc::clone(&stop))
        .context("installing signal handlers")?;
    #[cfg_attr(not(feature = "mpi"), allow(unused_mut))]
    let mut member = Member {
        exe: &exe,
        args: &args,
        out: e.out,
        env: vec![(MEMBER_OF, std::process::id().to_string())],
    };
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let jobs_for = |cpus: usize| {
        e.jobs
            .map_or((cpus / e.member_threads.max(1)).max(1), |j| j as usize)
    };
    // Under mpirun (feature `mpi`), rank 0 hands out the members and every other rank only
    // runs them.
    #[cfg(feature = "mpi")]
    let universe = mpi::initialize();
    #[cfg(feature = "mpi")]
    let world = universe.as_ref().map(|u| u.world()).filter(|w| {
        use mpi::traits::Communicator;
        w.size() > 1
    });
    #[cfg(feature = "mpi")]
    if let (None, Some((var, n))) = (&world, launcher_ranks()) {
        return Err(crate::cli::usage(format!(
            "started as one of {n} MPI ranks ({var}), but this build's MPI library sees a job of one rank: it was built against another MPI than the launcher's (use the mpirun of the MPI it was built with)"
        )));
    }
    #[cfg(feature = "mpi")]
    let placed = world.as_ref().map(ranks::place);
    #[cfg(feature = "mpi")]
    if let Some(place) = &placed {
        tracing::info!(
            "MPI rank {} on {}: bound by the launcher to {} CPUs; its members may use the node's {} CPUs, {} of them its share ({} ranks there): {} members at a time",
            place.mpi.rank,
            run_io::provenance::host_name(),
            place.bound,
            place.node_cpus,
            place.mpi.cpus,
            place.node_workers,
            jobs_for(place.mpi.cpus as usize)
        );
        member
            .env
            .push((run_io::provenance::MPI_PLACE_VAR, place.mpi.env_value()));
    }
    #[cfg(feature = "mpi")]
    if let (Some(w), Some(place)) = (&world, &placed) {
        use mpi::traits::Communicator;
        if w.rank() != 0 {
            if ranks::work(w, &member, jobs_for(place.mpi.cpus as usize), &stop) {
                return Err(Interrupted(format!(
                    "MPI rank {} stopped its members (each at a safe point); run the same command again to continue",
                    place.mpi.rank
                ))
                .into());
            }
            return Ok(());
        }
    }
    // Rank 0 (or the only process) owns the directory; members lock their own.
    let owned = own(e);
    // Refused under mpirun: the other ranks are told there is nothing to run, so they end.
    #[cfg(feature = "mpi")]
    if let (Err(_), Some(w)) = (&owned, &world) {
        ranks::dispatch(w, e.out, &[], None, &stop, &crate::cli::Progress::silent());
    }
    let _lock = owned?;
    let work: Vec<(u64, Todo)> = e
        .seeds
        .iter()
        .map(|&s| (s, todo(&member_dir(e.out, s))))
        .filter(|(_, t)| *t != Todo::Finished)
        .collect();
    let skipped = e.seeds.len() - work.len();
    let resumed = work.iter().filter(|(_, t)| *t == Todo::Resume).count();
    if skipped > 0 {
        tracing::info!("{skipped} members finished already");
    }
    let jobs = jobs_for(cores).min(work.len().max(1));
    let progress = e.log.progress(
        e.program,
        work.len() as u64,
        "members",
        "{elapsed_precise} [{bar:40}] {pos}/{len} members (eta {eta})",
    );
    let ended: Mutex<Vec<(u64, Ended)>> = Mutex::new(Vec::new());
    #[cfg(feature = "mpi")]
    let distributed = world;
    #[cfg(not(feature = "mpi"))]
    let distributed: Option<()> = None;
    #[cfg_attr(not(feature = "mpi"), allow(unused_mut))]
    let mut dispatched: Option<String> = None;
    match distributed {
        #[cfg(feature = "mpi")]
        Some(world) => {
            use mpi::traits::Communicator;
            let local = placed.as_ref().map(|p| jobs_for(p.mpi.cpus as usize));
            let (wall, cpu) = (std::time::Instant::now(), ranks::cpu_seconds());
            let done = ranks::dispatch(
                &world,
                e.out,
                &work,
                local.map(|jobs| (&member, jobs)),
                &stop,
                &progress,
            );
            dispatched = Some(ranks::dispatch_line(
                e.program,
                work.len(),
                world.size(),
                wall,
                cpu,
            ));
            *ended.lock().unwrap_or_else(|p| p.into_inner()) = done;
        }
        #[cfg(not(feature = "mpi"))]
        Some(()) => {}
        None => run_local(&member, &work, jobs, &stop, &progress, &ended),
    }
    progress.finish();
    let mut ended = ended.into_inner().unwrap_or_else(|p| p.into_inner());
    ended.sort_by_key(|(s, _)| *s);
    let report = merge_with(e.out, e.program, e.combine);
    let failed: Vec<String> = ended
        .iter()
        .filter_map(|(s, end)| match end {
            Ended::Failed(why) => Some(format!("seed {s}: {why}")),
            _ => None,
        })
        .collect();
    let unfinished =
        e.seeds.len() - skipped - ended.iter().filter(|(_, x)| *x == Ended::Ok).count();
    if !e.log.is_quiet() {
        if let Some(line) = &dispatched {
            crate::cli::say(line);
        }
        if let Ok(r) = &report {
            crate::cli::say(&format!(
                "{}: ensemble of {} members in {}: {} finished ({} already, {} resumed from a checkpoint), {} failed; {}",
                e.program,
                e.seeds.len(),
                e.out.display(),
                r.members,
                skipped,
                resumed,
                failed.len(),
                e.out.join("ensemble.json").display()
            ));
        }
    }
    // Stopped by a signal here, or (under MPI) on a rank that ran members.
    let interrupted = ended.iter().any(|(_, x)| *x == Ended::Interrupted);
    if stop.load(Ordering::Relaxed) || interrupted {
        return Err(Interrupted(format!(
            "interrupted with {} of {} members unfinished; run the same command again to continue",
            unfinished.saturating_sub(failed.len()),
            e.seeds.len()
        ))
        .into());
    }
    if !failed.is_empty() {
        return Err(anyhow!(
            "{} of {} members failed ({}); the others are combined in {}",
            failed.len(),
            e.seeds.len(),
            failed.join("; "),
            e.out.join("ensemble.json").display()
        ));
    }
    report.map(drop)
}

/// Takes the ensemble's directory: locks it, refuses it if it holds a single run or members
/// made with other parameters (unless `--overwrite`, which starts over).
fn own(e: &Ensemble<'_>) -> anyhow::Result<crate::cli::OutDirLock> {
    let lock = crate::cli::own_out_dir(&crate::cli::Claim {
        out: e.out,
        run_files: e.owner.run_files,
        resume: None,
        overwrite: e.owner.overwrite,
        ensemble: true,
    })?;
    let differ = foreign_members(e.out, e.program, e.owner)
        .with_context(|| format!("reading the members in {}", e.out.display()))?;
    if !differ.is_empty() {
        return Err(crate::cli::usage(format!(
            "--out {} holds members made with other parameters ({}); rerun with their flags, use another --out, or add --overwrite to start the ensemble over",
            e.out.display(),
            differ.join("; ")
        )));
    }
    Ok(lock)
}

/// The members in `dir` made with parameters other than `owner`'s, each as `seed-NNNN:` and
/// the differing flags with both values (empty when all agree). A finished member is compared
/// by its `run.json`, an unfinished one by its `config.toml` (where it has one).
fn foreign_members(dir: &Path, program: &str, owner: &Owner<'_>) -> anyhow::Result<Vec<String>> {
    let mut out = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(out);
    };
    let mut members: Vec<(String, PathBuf)> = Vec::new();
    for entry in entries {
        let entry = entry?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if name.starts_with("seed-") && entry.file_type()?.is_dir() {
            members.push((name, entry.path()));
        }
    }
    members.sort();
    let config: Option<toml::Table> = owner.config.as_deref().and_then(|c| c.parse().ok());
    // Members that differ alike are named together.
    let mut groups: Vec<(Vec<String>, String)> = Vec::new();
    for (name, path) in members {
        let there = "there".to_string();
        let differ = match run_io::RunManifest::read(path.join("run.json")) {
            Ok(m) if m.model != program => vec![format!("a {} run, not {program}", m.model)],
            Ok(m) => {
                let mut d = crate::cli::labelled_differences(
                    &m.params,
                    &owner.params,
                    (&there, "given"),
                    &[],
                );
                let line = m
                    .provenance
                    .as_ref()
                    .map_or(&[][..], |p| &p.command_line[..]);
                for (flag, given, default) in &owner.run_flags {
                    let was = flag_value(line, flag).unwrap_or_else(|| default.clone());
                    if was != *given {
                        d.push(format!("{flag} {was} {there}, {given} given"));
                    }
                }
                d
            }
            Err(_) => match (&config, std::fs::read_to_string(path.join("config.toml"))) {
                (Some(given), Ok(text)) => match text.parse::<toml::Table>() {
                    Ok(saved) => config_differences(&saved, given, &there),
                    Err(e) => vec![format!("{}/config.toml: {e}", path.display())],
                },
                _ => Vec::new(),
            },
        };
        if differ.is_empty() {
            continue;
        }
        let differ = differ.join(", ");
        match groups.iter_mut().find(|(_, d)| *d == differ) {
            Some((names, _)) => names.push(name),
            None => groups.push((vec![name], differ)),
        }
    }
    for (names, differ) in groups {
        out.push(format!("{}: {differ}", names.join(", ")));
    }
    Ok(out)
}

/// The keys of two saved configurations that differ, less `seed`, as flags with both values.
fn config_differences(saved: &toml::Table, given: &toml::Table, label: &str) -> Vec<String> {
    let mut keys: Vec<&String> = saved.keys().chain(given.keys()).collect();
    keys.sort();
    keys.dedup();
    let show = |v: Option<&toml::Value>| match v {
        None => "none".to_string(),
        Some(toml::Value::String(s)) => s.clone(),
        Some(v) => v.to_string(),
    };
    keys.into_iter()
        .filter(|k| k.as_str() != "seed" && saved.get(*k) != given.get(*k))
        .map(|k| {
            format!(
                "--{} {} {label}, {} given",
                k.replace('_', "-"),
                show(saved.get(k)),
                show(given.get(k))
            )
        })
        .collect()
}

/// Runs `work` on this machine, `jobs` members at a time, recording how each ended.
fn run_local(
    member: &Member<'_>,
    work: &[(u64, Todo)],
    jobs: usize,
    stop: &AtomicBool,
    progress: &crate::cli::Progress,
    ended: &Mutex<Vec<(u64, Ended)>>,
) {
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    std::thread::scope(|s| {
        for _ in 0..jobs {
            // Each thread starts its members and waits for them: a member dies when the thread
            // that started it ends (`tie_member_to_ensemble`).
            s.spawn(|| {
                loop {
                    if stop.load(Ordering::Relaxed) {
                        return;
                    }
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&(seed, todo)) = work.get(i) else {
                        return;
                    };
                    let end = run_member(member, seed, todo, stop);
                    ended
                        .lock()
                        .unwrap_or_else(|p| p.into_inner())
                        .push((seed, end));
                    let n = done.fetch_add(1, Ordering::Relaxed) + 1;
                    progress.set_position(n as u64);
                }
            });
        }
    });
}

/// What every binary does before it parses its flags: refuses a processor the build cannot
/// run on ([`crate::cli::refuse_unsupported_cpu`]), refuses to run as one of several MPI ranks
/// without MPI support ([`refuse_without_mpi`]), ties an ensemble's member to its ensemble
/// ([`tie_member_to_ensemble`]) and handles `PROG --merge DIR` ([`merge_main`]).
/// `Some(exit code)` when one of them ended the program.
pub fn before_parsing<'a>(program: &str, combine: impl Into<Combine<'a>>) -> Option<ExitCode> {
    crate::cli::refuse_unsupported_cpu(program)
        .or_else(|| refuse_without_mpi(program))
        .or_else(tie_member_to_ensemble)
        .or_else(|| merge_main(program, combine))
}

/// Handles `PROG --merge DIR` (exactly those arguments) before the model parses its flags:
/// rebuilds the combined result of the members in `DIR`. `None` for any other command line.
pub fn merge_main<'a>(program: &str, combine: impl Into<Combine<'a>>) -> Option<ExitCode> {
    let args: Vec<OsString> = std::env::args_os().skip(1).collect();
    let dir = match args.as_slice() {
        [flag, dir] if flag == "--merge" => PathBuf::from(dir),
        [flag] => PathBuf::from(flag.to_str()?.strip_prefix("--merge=")?),
        _ => return None,
    };
    Some(match merge_with(&dir, program, combine.into()) {
        Ok(r) => {
            for why in &r.invalid {
                crate::cli::say(&format!("{program}: warning: left out {why}"));
            }
            crate::cli::say(&format!(
                "{program}: combined {} members of {} into {}{}",
                r.members,
                dir.display(),
                dir.join("ensemble.json").display(),
                if r.unfinished.is_empty() {
                    String::new()
                } else {
                    format!("; not finished: {}", r.unfinished.join(", "))
                }
            ));
            ExitCode::SUCCESS
        }
        Err(e) => {
            crate::cli::say(&format!(
                "{program}: error: --merge {}: {e:#}",
                dir.display()
            ));
            ExitCode::from(crate::cli::EXIT_USAGE)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn os(v: &[&str]) -> Vec<OsString> {
        v.iter().map(OsString::from).collect()
    }

    #[test]
    fn recorded_flags_and_saved_configurations_are_compared_as_flags() {
        let line: Vec<String> = ["animat", "--steps", "40", "--seed=3"]
            .map(str::to_owned)
            .to_vec();
        assert_eq!(flag_value(&line, "--steps").as_deref(), Some("40"));
        assert_eq!(flag_value(&line, "--seed").as_deref(), Some("3"));
        assert_eq!(flag_value(&line, "--vision"), None);
        let saved: toml::Table = "particles = 200\nseed = 1\nfar-field = \"return\""
            .parse()
            .unwrap();
        let given: toml::Table = "particles = 300\nseed = 2\nfar-field = \"jump\""
            .parse()
            .unwrap();
        assert_eq!(
            config_differences(&saved, &given, "there"),
            [
                "--far-field return there, jump given",
                "--particles 200 there, 300 given"
            ]
        );
    }

    #[test]
    fn members_get_the_run_flags_only() {
        let got = member_args(os(&[
            "--seeds",
            "1..=4",
            "--particles",
            "100",
            "--out",
            "d",
            "--jobs=2",
            "-qq",
            "-v",
            "--heartbeat",
            "5",
            "--quiet",
            "--seed=3",
            "--threads",
            "2",
        ]));
        assert_eq!(got, os(&["--particles", "100", "--threads", "2"]));
    }
}
