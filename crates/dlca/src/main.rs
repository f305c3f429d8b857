//! `dlca`: diffusion-limited cluster-cluster aggregation on lattices of 1 to 5 dimensions
//! (Hawick, James & Scogings 2006, "Grid-Boxing for Spatial Simulation Performance
//! Optimisation"; docs/dlca.md). A thin layer over the `dlca` library: parse flags, validate,
//! run, write outputs.

use anyhow::Context;
use clap::{ArgGroup, Parser};
use dlca::params::{LATTICE_FLAGS, Settings};
use dlca::{Params, Simulation, Snapshot};
use run_cli::cli::{FigureArgs, FigureHelp, ParamFlags, Plain, flag_differences, usage};
use run_cli::ensemble::{Combine, Curve, MemberRun, Pooled, PooledResult};
use run_cli::model::{Model, Own, RunArgs};
use run_io::{Positions, RunClock};
use run_io::{read_checkpoint, write_checkpoint};

/// File name of checkpoints in the output directory.
const CHECKPOINT: &str = "checkpoint.bin";
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Diffusion-limited cluster-cluster aggregation (DLCA) on a periodic or walled lattice.
///
/// Particles are placed on distinct random sites; face-adjacent particles form clusters. Each
/// sweep visits every cluster in a fresh random order; a cluster moves one site in a random
/// direction and merges with every cluster it then touches. Stops at --target-clusters or
/// --max-sweeps. Outputs go into --out DIR (see docs/dlca.md).
// The model's flags are made from its one declaration (`dlca::params::Settings`), in two groups
// around the run flags; `cli_spec_tests` checks them and the docs' table against
// `dlca::params::PARAMS`.
#[derive(Parser, Debug)]
#[command(name = "dlca", version = run_cli::cli::version(), allow_negative_numbers = true, group(ArgGroup::new("amount").required(true).args(["fill", "particles"])))]
struct Cli {
    #[command(flatten)]
    lattice: ParamFlags<Settings, Plain, 0, LATTICE_FLAGS>,

    /// Also save the run's state to OUT/checkpoint.bin every N sweeps (atomically), and keep
    /// it at the end.
    #[arg(long, value_name = "N", value_parser = run_cli::cli::count_at_least_1::<u64>)]
    checkpoint_every: Option<u64>,

    /// Continue the run saved in DIR/checkpoint.bin (a checkpoint, or a stopped run) to the same final
    /// state as an uninterrupted run. The other flags must be those of the saved run, except
    /// --target-clusters and --max-sweeps.
    #[arg(long, value_name = "DIR")]
    resume: Option<PathBuf>,

    #[command(flatten)]
    model: ParamFlags<Settings, Plain, LATTICE_FLAGS>,

    // --png, --png-size, --animate and --animate-every, with dlca's help texts (`FigureHelp`).
    #[command(flatten)]
    figure: FigureArgs<Dlca>,

    /// Every particle's final site and cluster id: particles.csv (x1..xd,cluster), particles.npy
    /// with particles_cluster.npy (NumPy), particles.vtk (ParaView, cluster as a point scalar),
    /// particles.xyz (extended XYZ: OVITO, VMD), or none.
    #[arg(long, value_enum, value_name = "FORMAT", default_value_t = Positions::Csv)]
    positions: Positions,

    // Seed, --out and how the process runs: after the model's own flags in --help.
    #[command(flatten)]
    run: RunArgs,
}

/// The run saved in `DIR/checkpoint.bin`, if it is one these flags continue (only
/// --target-clusters and --max-sweeps may change); anything else is a usage error naming the
/// file, or the flags that differ with both values.
fn resume(dir: &Path, params: Params, seed: u64) -> anyhow::Result<Simulation> {
    let path = dir.join(CHECKPOINT);
    let at = || format!("--resume {}", path.display());
    let mut snapshot: Snapshot =
        read_checkpoint(&path, "dlca").map_err(|e| usage(format!("{}: {e}", at())))?;
    snapshot.set_stop(params.target_clusters, params.max_sweeps);
    let mut differ = flag_differences(snapshot.params(), &params, dlca::params::COMBINED_FLAGS);
    if snapshot.seed() != seed {
        differ.push(format!(
            "--seed {} in the checkpoint, {seed} given",
            snapshot.seed()
        ));
    }
    if !differ.is_empty() {
        return Err(usage(format!(
            "{}: the flags differ from the saved run's (only --target-clusters and --max-sweeps may change): {}",
            at(),
            differ.join("; ")
        )));
    }
    tracing::info!("resuming after sweep {}", snapshot.sweeps());
    Simulation::restore(snapshot).map_err(|e| usage(format!("{}: {e}", at())))
}

/// What an ensemble (`--seeds`) averages over its members.
const CURVES: &[Curve] = &[
    Curve {
        file: "sweeps.csv",
        x: "sweep",
        ys: &["clusters", "largest"],
        missing: None,
        title: "Clusters and largest cluster against sweeps",
        axes: ("sweep", "clusters; particles in the largest"),
        log_x: true,
        log_y: true,
        colours: &[],
    },
    Curve {
        file: "sizes.csv",
        x: "size",
        ys: &["count"],
        missing: Some(0.0),
        title: "Cluster size distribution at the end",
        axes: ("cluster size (particles)", "clusters of that size"),
        log_x: true,
        log_y: true,
        colours: &[],
    },
];

/// What an ensemble (`--seeds`) pools over its members: with `--gyration`, the fractal
/// dimension fitted over the clusters of every member, as the literature measures it.
const POOLED: &[Pooled] = &[Pooled {
    name: "fractal_dimension",
    title: "Fractal dimension pooled over the members",
    compute: pooled_fractal_dimension,
}];

/// The pooled fit over the members' `clusters.csv` (none without `--gyration`).
fn pooled_fractal_dimension(members: &[MemberRun<'_>]) -> anyhow::Result<Option<PooledResult>> {
    if members.iter().any(|m| !m.dir.join("clusters.csv").exists()) {
        return Ok(None);
    }
    let min_size = members[0].manifest.params["fit_min_size"]
        .as_u64()
        .context("run.json has no fit_min_size")?;
    let runs = members
        .iter()
        .map(|m| dlca::output::read_clusters(&m.dir.join("clusters.csv")))
        .collect::<Result<Vec<_>, _>>()?;
    let json = dlca::output::pooled_summary(&runs, min_size)?;
    let num = |k: &str| {
        json[k]
            .as_f64()
            .map_or_else(|| "n/a".to_string(), |v| format!("{v:.4}"))
    };
    let markdown = format!(
        "D = {} +- {} (jackknife over the {} members) from one fit of log s = D log R_g + c \
         over the {} clusters of at least {min_size} particles of every member; the regression's \
         own error, which takes the clusters as independent, is {}. The mean of the members' own \
         fits is {} +- {} (standard error over {} fits). ensemble.json: \
         `pooled.fractal_dimension`.",
        num("fractal_dimension"),
        num("fractal_dimension_stderr"),
        json["members"],
        json["fit_clusters"],
        num("fit_stderr"),
        num("per_member_mean"),
        num("per_member_stderr"),
        json["per_member_fits"],
    );
    Ok(Some(PooledResult { json, markdown }))
}

/// What an ensemble combines.
const COMBINE: Combine<'static> = Combine {
    curves: CURVES,
    pooled: POOLED,
};

/// The files of a run in --out besides run.json, checkpoint.bin and config.toml: what makes a directory an
/// earlier run's and what --overwrite deletes.
const RUN_FILES: &[&str] = &[
    "sweeps.csv",
    "sizes.csv",
    "clusters.csv",
    "histogram.csv",
    "positions.*",
    "positions_*",
    "dlca.png",
    "dlca.gif",
];

/// The largest default side of a raster, for the memory estimate before the run.
const RASTER_MAX_DEFAULT_SIDE: u32 = dlca::figure::PNG_MAX_SIDE as u32;

/// DLCA as the run machinery sees it.
struct Dlca;

// The help texts of the figure flags, as `--help` shows them (clap would take them from doc
// comments on the fields; `FigureArgs` is shared, so they are given here).
impl FigureHelp for Dlca {
    const PNG: Option<&'static str> = Some(
        "Write dlca.png: a figure of the final state on the first two axes (axes in lattice \
         cells, scale bar, sweep, clusters and seed), touching clusters in different colours",
    );
    const PNG_SIZE: &'static str = "Longer side of the raster in dlca.png and dlca.gif in pixels \
         (the axes and legend come on top), 16 to 65536, at most 16384 with --animate (default: \
         dlca.png a whole number of pixels per site and at least 512, or one per site up to 8192; \
         dlca.gif 512)";
    const ANIMATE: &'static str = "Write dlca.gif: the aggregation, a frame of the start, one \
         every --animate-every sweeps and one of the end";
    const ANIMATE_EVERY: &'static str = "Sweeps between frames of dlca.gif, 1.. (default 10)";
}

impl Model for Dlca {
    const NAME: &'static str = "dlca";
    const RUN_FILES: &'static [&'static str] = RUN_FILES;
    const COMBINE: Combine<'static> = COMBINE;
    type Cli = Cli;
    type Params = Params;

    fn run_args(cli: &Cli) -> &RunArgs {
        &cli.run
    }

    /// Turn the flags into validated parameters.
    fn params(cli: &Cli) -> Result<Params, String> {
        let mut settings = cli.model.params();
        cli.lattice.apply(&mut settings);
        let p = settings.to_params(|name| cli.lattice.given(name) || cli.model.given(name))?;
        cli.figure.check()?;
        // The default 4G is the occupancy lattice's budget only; the run's limit is then the memory
        // available.
        let given = cli.model.given("max_memory").then_some(p.max_memory);
        let n = p.particles().unwrap_or(0);
        let raster = if cli.figure.png || cli.figure.animate {
            let side = u64::from(cli.figure.png_size.unwrap_or(RASTER_MAX_DEFAULT_SIDE));
            dlca::figure::png_memory_bytes(side, side)
        } else {
            0
        };
        run_io::memory::Limit::from_flag(given).check(
            dlca::sim::peak_memory_bytes(&p).saturating_add(raster),
            &format!(
                "{n} particles on {} sites with the {} search",
                p.size.iter().product::<u64>(),
                dlca::sim::chosen_search_name(&p)
            ),
            "lower --size or --fill/--particles",
        )?;
        cli.run.checkpoints.check(cli.checkpoint_every)?;
        Ok(p)
    }

    fn resume_dir(cli: &Cli) -> Option<&Path> {
        cli.resume.as_deref()
    }

    fn run(cli: &Cli, params: Params, own: Own<'_>) -> anyhow::Result<()> {
        run(cli, params, own)
    }
}

fn main() -> ExitCode {
    run_cli::model::main::<Dlca>()
}

fn run(cli: &Cli, params: Params, own: Own<'_>) -> anyhow::Result<()> {
    let clock = RunClock::start();
    let target = params.target_clusters;
    // Everything that can refuse the run happens before --out is created.
    let mut sim = match &cli.resume {
        Some(dir) => resume(dir, params, cli.run.seed)?,
        // Every error of the set-up is a parameter the run cannot take, except an allocation
        // the system refused: a failed run.
        None => Simulation::new(params, cli.run.seed).map_err(|e| match e {
            dlca::params::ParamError::Alloc(a) => anyhow::Error::from(a),
            other => usage(other.to_string()),
        })?,
    };
    // Created before the run so a long run cannot end with nowhere to write.
    // Ours until the run ends: refused if another run holds it or it holds an earlier run.
    let _lock = own.take()?;
    tracing::info!("{}", sim.strategy_reason());
    let initial = sim.clusters();
    let progress = cli.run.log.progress(
        "dlca",
        initial.saturating_sub(target),
        "merges",
        "{elapsed_precise} [{bar:40}] {pos}/{len} merged, {msg}",
    );
    // Timed checkpoints, signals and the memory watch, which keeps room for a checkpoint.
    let reserve = dlca::sim::checkpoint_reserve_bytes(sim.particles());
    let enabled = cli.run.checkpoints.enabled();
    let (guard, _watch, _) = cli
        .run
        .checkpoints
        .start(reserve)
        .context("installing signal handlers")?;
    let save = |s: &Simulation| {
        write_checkpoint(cli.run.out.join(CHECKPOINT), "dlca", &s.snapshot())
            .context("writing a checkpoint")
    };
    let mut animation = if cli.figure.animate {
        let side = cli
            .figure
            .png_size
            .unwrap_or(dlca::figure::ANIMATION_DEFAULT_SIDE);
        Some(dlca::figure::Animation::start(
            &sim,
            cli.run.seed,
            &cli.run.out.join("dlca.gif"),
            side,
        )?)
    } else {
        None
    };
    let every = cli
        .figure
        .animate_every
        .unwrap_or(dlca::figure::ANIMATION_DEFAULT_EVERY);
    while !sim.is_done() {
        sim.sweep();
        let s = &sim;
        if let Some(a) = animation.as_mut()
            && dlca::figure::Animation::due(s, every)
        {
            a.frame(s)?;
        }
        if let Some(n) = cli.checkpoint_every
            && s.sweeps() % n == 0
            && !s.is_done()
        {
            save(s)?;
        }
        if s.sweeps() % 16 == 0 || s.is_done() {
            progress.set_message(format!("sweep {}, {} clusters", s.sweeps(), s.clusters()));
            progress.set_position(initial - s.clusters().max(target).min(initial));
        }
        if !s.is_done() && guard.is_set() {
            let at = || format!("after sweep {} ({} clusters)", s.sweeps(), s.clusters());
            run_cli::cli::checkpoints::honour(&guard, enabled, &cli.run.out, || save(s), at)
                .inspect_err(|_| progress.finish())?;
        }
    }
    progress.finish();
    if sim.is_frozen() {
        tracing::warn!(
            "no cluster can move any more (temperature * s^-gamma is 0 for the smallest cluster, \
             s = {}): stopped after sweep {} with {} clusters, above --target-clusters {target}",
            sim.sets()
                .live()
                .iter()
                .map(|&id| sim.sets().sites(id).len())
                .min()
                .unwrap_or(0),
            sim.sweeps(),
            sim.clusters()
        );
    }
    if let Some(a) = animation {
        let frames = a.finish()?;
        tracing::info!(frames, "dlca.gif");
    }
    // A checkpoint the run did not ask for (a timed one, or the one it was resumed from) goes.
    run_cli::cli::checkpoints::remove_unasked_checkpoint(
        &cli.run.out,
        cli.checkpoint_every.is_some(),
    )
    .context("removing checkpoint.bin")?;
    let m = dlca::output::write_outputs(
        &sim,
        cli.run.seed,
        &clock,
        &cli.run.out,
        cli.figure.png.then_some(cli.figure.png_size),
        cli.positions.format(),
    )?;
    if !cli.run.log.is_quiet() {
        eprintln!(
            "dlca: {} clusters (largest {}) after {} sweeps in {:.2} s with {}; outputs in {}",
            sim.clusters(),
            sim.largest(),
            sim.sweeps(),
            m.wall_seconds,
            sim.strategy().name(),
            cli.run.out.display()
        );
    }
    Ok(())
}

#[cfg(test)]
#[path = "cli_spec_tests.rs"]
mod cli_spec_tests;
