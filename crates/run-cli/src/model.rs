//! The model contract (feature `cli`): what a model binary tells the run machinery ([`Model`]),
//! the flags every model binary shares ([`RunArgs`]) and the one `main` they all run ([`main`]). The machinery
//! owns the life of a process (the ensemble's and the merge's command lines, parsing with
//! `--config` and `--dump-config`, logging, the usage-error contract, `--seeds` over child
//! processes or MPI ranks, the claim of `--out` and its `config.toml`); the model owns its
//! parameters, its run (new or resumed, under the guard of timed checkpoints, signals and the
//! memory watch), its result files, curves and figures. A new model is a library with a
//! `Params` declaration and a binary that implements [`Model`] and calls [`main`].

use crate::cli::config::{self, ConfigArgs};
use crate::cli::{CheckpointArgs, Claim, LogArgs, OutDirLock, OverwriteArgs, main_with_config};
use crate::ensemble::{Combine, EnsembleArgs, Owner};
use anyhow::Context;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The flags every model binary shares, `#[command(flatten)]`ed into its flags: where the run
/// writes, its seed, and how the process runs (checkpoints on the clock, config files, logging,
/// ensembles, replacing an earlier run). The flattened groups carry no doc comment of their
/// own (clap would read one as their help), hence `allow(missing_docs)`.
#[derive(Debug, Clone, clap::Args)]
#[allow(missing_docs)]
pub struct RunArgs {
    /// Seed of every random stream of the run: the same seed and flags give the same run (on
    /// one thread).
    #[arg(long, default_value_t = 1, value_parser = run_io::count::seed)]
    pub seed: u64,

    /// Output directory (created if missing; nothing is written on bad input). It is this run's
    /// while it runs (locked in DIR/run.lock); one in use by another run, or holding an earlier
    /// run (run.json, a checkpoint or partial outputs), is refused: continue it with --resume,
    /// or replace it with --overwrite.
    #[arg(long)]
    pub out: PathBuf,

    #[command(flatten)]
    pub checkpoints: CheckpointArgs,

    #[command(flatten)]
    pub config: ConfigArgs,

    #[command(flatten)]
    pub log: LogArgs,

    #[command(flatten)]
    pub ensemble: EnsembleArgs,

    #[command(flatten)]
    pub overwrite: OverwriteArgs,
}

/// A model as the run machinery sees it: implemented by each model binary on a unit type, which
/// then runs `run_cli::model::main::<ItsModel>()`.
pub trait Model {
    /// The binary's name: in messages, progress lines and the ensemble's files.
    const NAME: &'static str;
    /// The files of a run in `--out` besides `run.json`, `checkpoint.bin` and `config.toml`
    /// (as [`Claim::run_files`]): what makes a directory an earlier run's and what
    /// `--overwrite` deletes.
    const RUN_FILES: &'static [&'static str];
    /// What an ensemble (`--seeds`) combines over its members: curves with error bands and
    /// results pooled over all members.
    const COMBINE: Combine<'static>;
    /// The binary's flags: its model's declared parameters (`ParamFlags`), its own output
    /// flags, [`RunArgs`], and `--resume DIR` (with the model's own help: what may change when
    /// a run is continued), which `--seeds` refuses beside it.
    type Cli: clap::Parser;
    /// The validated parameters, as `run.json` records them.
    type Params: serde::Serialize;

    /// The shared flags of `cli`.
    fn run_args(cli: &Self::Cli) -> &RunArgs;

    /// The flags as validated parameters, every check that needs no work made (ranges, rules
    /// between flags, the memory estimate); an `Err` is a usage error. `--out` is checked after
    /// it, so that a bad flag is named first.
    ///
    /// # Errors
    /// One line naming the flag and what it accepts.
    fn params(cli: &Self::Cli) -> Result<Self::Params, String>;

    /// `--resume DIR`, if given: a run continued in its own directory keeps it.
    fn resume_dir(cli: &Self::Cli) -> Option<&Path>;

    /// Threads each ensemble member runs on.
    fn threads(_params: &Self::Params) -> usize {
        1
    }

    /// Run flags that change the result but are not parameters, as `(flag, value, default)`
    /// ([`Owner::run_flags`]: animat's `--steps`).
    fn run_flags(_cli: &Self::Cli) -> Vec<(&'static str, String, String)> {
        Vec::new()
    }

    /// One run: set up (new or resumed; everything that can refuse the run happens before
    /// [`Own::take`]), take `--out` with `own`, run under the guard, write the outputs.
    ///
    /// # Errors
    /// A [`UsageError`](crate::cli::UsageError) (see [`usage`](crate::cli::usage)) before `--out` is
    /// taken, an interruption ([`stopped`](crate::cli::stopped)), or a failed run.
    fn run(cli: &Self::Cli, params: Self::Params, own: Own<'_>) -> anyhow::Result<()>;
}

/// The claim of `--out` a [`Model::run`] takes once nothing can refuse the run any more.
#[must_use = "a run takes --out with Own::take before it writes anything"]
pub struct Own<'a> {
    claim: Claim<'a>,
}

impl Own<'_> {
    /// Takes `--out` for this run (refused if another run holds it, or it holds an earlier run
    /// without `--overwrite`) and writes the effective flags there as `config.toml`, so that
    /// `--config OUT/config.toml` repeats the run. The lock holds until it is dropped.
    ///
    /// # Errors
    /// A usage error for a directory another run owns; an I/O error writing `config.toml`.
    pub fn take(self) -> anyhow::Result<OutDirLock> {
        let lock = crate::cli::own_out_dir(&self.claim)?;
        config::save(self.claim.out)
            .with_context(|| format!("writing {}/config.toml", self.claim.out.display()))?;
        Ok(lock)
    }
}

/// The whole life of model `M`'s binary: the ensemble's and the merge's command lines, then
/// parsing (with `--config` and `--dump-config`), logging, [`Model::params`] and the check of
/// `--out`, then either an ensemble of `--seeds` or one [`Model::run`]. Exit codes as in
/// [`crate::cli::main_with`].
pub fn main<M: Model>() -> ExitCode {
    if let Some(code) = crate::ensemble::before_parsing(M::NAME, M::COMBINE) {
        return code;
    }
    main_with_config(
        M::NAME,
        |cli: &M::Cli| M::run_args(cli).log,
        |cli| {
            let params = M::params(cli)?;
            crate::cli::check_out_dir(&M::run_args(cli).out)?;
            Ok(params)
        },
        |cli, params| {
            let r = M::run_args(cli);
            let owner = Owner {
                run_files: M::RUN_FILES,
                params: serde_json::to_value(&params)?,
                config: config::effective_text().map(str::to_owned),
                run_flags: M::run_flags(cli),
                overwrite: r.overwrite.overwrite,
            };
            let threads = M::threads(&params);
            r.ensemble
                .run(M::NAME, threads, &r.out, M::COMBINE, &r.log, &owner)
                .unwrap_or_else(|| {
                    let claim = Claim::single(
                        &r.out,
                        M::RUN_FILES,
                        M::resume_dir(cli),
                        r.overwrite.overwrite,
                    );
                    M::run(cli, params, Own { claim })
                })
        },
    )
}
