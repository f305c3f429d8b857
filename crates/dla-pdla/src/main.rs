//! `dla`: off-lattice diffusion-limited aggregation (DLA) and parallel DLA (PDLA) in 2D to 5D
//! (Sosa-Herrera & Rodriguez-Romo, "Variable precision distance search for random fractal
//! cluster simulations"). A thin layer over the `dla_pdla` library: parse flags, validate,
//! turn `--dim` into a type (the one run-time dimension dispatch), run, write outputs.

use anyhow::Context;
use clap::Parser;
use dla_pdla::output::{PositionsFormat, default_png_side_of, write_outputs};
use dla_pdla::{Dim, Params, ParamsError, SimError, Simulation, Space};
use run_cli::cli::{FigureArgs, FigureHelp, ParamFlags, flag_differences, stopped, usage};
use run_cli::ensemble::{Combine, Curve};
use run_cli::model::{Model, Own, RunArgs};
use run_io::RunClock;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Off-lattice diffusion-limited aggregation (DLA) and parallel DLA (PDLA), 2D to 5D.
///
/// A seed particle sits at the origin. Walkers (balls of diameter 1) are born on a sphere just
/// outside the cluster, jump by the variable-precision distance to the cluster when far from
/// it, take short steps near it, and stick at exact contact. Outputs go into
/// --out DIR (see docs/dla.md).
// The model's flags are made from its one declaration (`ParamFlags<Params>`); `cli_spec_tests`
// checks them and the docs' table against `dla_pdla::params::PARAMS`.
#[derive(Parser, Debug)]
#[command(name = "dla", version = run_cli::cli::version(), allow_negative_numbers = true)]
struct Cli {
    #[command(flatten)]
    params: ParamFlags<Params>,

    // Its help names what it sets, from the declaration.
    #[arg(long, conflicts_with_all = dla_pdla::params::PAPER_SETTINGS, help = paper_settings_help())]
    paper_settings: bool,

    /// Write the positions in arrival order. They stream to positions.npy (float64, shape
    /// (N, D), NumPy's format) as the cluster grows, never held in memory; csv, bin, xyz
    /// (extended XYZ: OVITO, VMD) and vtk (legacy VTK with the arrival index: ParaView) are made
    /// from it at the end (csv and xyz take about 50 bytes per particle on disk). xyz and vtk
    /// hold three coordinates, so they are refused in 4D and 5D.
    #[arg(long, value_enum, default_value_t = PositionsFormat::None)]
    positions: PositionsFormat,

    /// Record no parents. A run whose positions stream (the default, for its checkpoints)
    /// records each particle's parent, the particle it stuck to: about 5 bytes a particle at
    /// the peak (4.7 GiB at 1e9). Without them the positions files have no parent column and
    /// there are no branch orders (branches.csv); the walk and the state hash are the same.
    #[arg(long)]
    no_parents: bool,

    /// Also write DIR/checkpoint.bin (DIR = --out) every N particles, and keep one at the end
    /// (so that --resume with a larger --particles grows the finished cluster further). A
    /// checkpoint is a few kilobytes: the positions stream to positions.npy, which it refers
    /// to. With one thread a run continued with --resume ends with the same state_hash; with
    /// more (PDLA), a checkpoint ends a parallel phase at a quiescent point, and a resumed run
    /// is a valid PDLA cluster.
    #[arg(long, value_parser = run_cli::cli::count::<u64>, value_name = "N")]
    checkpoint_every: Option<u64>,

    /// Continue the run checkpointed in DIR (checkpoint.bin and positions.npy). The run flags
    /// (and --seed) must be those of the checkpointed run, except --particles, which may grow:
    /// the run then ends as one made to that size directly. Outputs go to --out as usual (the
    /// same DIR continues in place; another copies positions.npy).
    #[arg(long, value_name = "DIR")]
    resume: Option<PathBuf>,

    // --png, --png-size, --animate and --animate-every, with dla's help texts (`FigureHelp`).
    #[command(flatten)]
    figure: FigureArgs<Dla>,

    /// Memory the run may take, in bytes; suffixes K, M, G, T (powers of 1024). A run whose
    /// estimated peak (docs/dla.md, "Memory") is larger is refused before it starts. Default:
    /// the memory available (MemAvailable, or a lower cgroup limit).
    #[arg(long, value_name = "BYTES", value_parser = run_io::memory::parse_bytes)]
    max_memory: Option<u64>,

    // Seed, --out and how the process runs: after the model's own flags in --help.
    #[command(flatten)]
    run: RunArgs,
}

/// The help of `--paper-settings`.
fn paper_settings_help() -> String {
    format!(
        "The variable-precision paper's walk, to reproduce its numbers: {} (its near-field step \
         biases the R_g prefactor about 5 % low against the default; docs/dla.md, \"Accuracy\")",
        Params::paper_settings_flags()
    )
}

/// Whether the run's outputs need the positions (files, figures, or checkpoints every N
/// particles, which are kept).
fn asked_positions(cli: &Cli) -> bool {
    cli.figure.png
        || cli.figure.animate
        || cli.positions != PositionsFormat::None
        || cli.checkpoint_every.is_some()
}

/// Whether the positions stream to positions.npy: when asked for, and for the checkpoints,
/// which refer to them; a run that ends normally removes what was not asked for.
fn streams_positions(cli: &Cli) -> bool {
    asked_positions(cli) || cli.run.checkpoints.enabled()
}

/// Refuses a run whose estimated peak memory (the cluster, and the raster's buffers with
/// `--png`) does not fit `--max-memory` or the memory available. An ensemble runs its members
/// one per job, so each member must fit.
fn check_memory(cli: &Cli, p: &Params) -> Result<(), String> {
    let side = u64::from(
        cli.figure
            .png_size
            .unwrap_or(dla_pdla::output::PNG_MAX_SIDE),
    );
    let png = if cli.figure.png || cli.figure.animate {
        dla_pdla::output::png_memory_bytes(side)
    } else {
        0
    };
    let what = format!(
        "{} particles in {}D at {} bytes each{}",
        p.particles,
        p.dim,
        p.peak_bytes_per_particle(),
        if cli.figure.png || cli.figure.animate {
            " and the raster"
        } else {
            ""
        }
    );
    let smaller = if p.connectivity {
        format!(
            "lower --particles, or add --no-parents ({} bytes a particle less)",
            dla_pdla::params::CONNECTIVITY_BYTES_PER_PARTICLE
        )
    } else {
        "lower --particles".to_string()
    };
    run_io::memory::Limit::from_flag(cli.max_memory).check(
        p.peak_memory_bytes().saturating_add(png),
        &what,
        &smaller,
    )
}

/// The progress bar of a run on a terminal.
const PROGRESS_TEMPLATE: &str =
    "{elapsed_precise} [{bar:40}] {pos}/{len} particles ({per_sec}, eta {eta})";

/// The run checkpointed in `DIR` (`checkpoint.bin`, `positions.npy`), if it is one these flags
/// continue; anything else is a usage error naming the file, or the flags that differ with both
/// values.
fn resume<const D: usize>(dir: &Path, params: &Params, seed: u64) -> anyhow::Result<Simulation<D>>
where
    Dim<D>: Space<D>,
{
    let sim = Simulation::<D>::resume(dir, Some(params.particles))
        .map_err(|e| usage(format!("--resume {}: {e}", dir.display())))?;
    // --particles may grow (checked by `resume`).
    // `connectivity` follows the positions' streaming; a resumed run records parents as the
    // checkpointed one did (it cannot name the parents of the particles already stored).
    let mut differ = flag_differences(
        sim.params(),
        params,
        &[("keep_positions", None), ("connectivity", None)],
    );
    if params.connectivity && !sim.params().connectivity {
        tracing::warn!(
            "the checkpointed run recorded no parents (an earlier version, --no-checkpoint or --no-parents): the outputs have none"
        );
    }
    if !params.connectivity && sim.params().connectivity {
        tracing::warn!(
            "the checkpointed run records parents, and its particles carry them: the resumed run records them too"
        );
    }
    if sim.seed() != seed {
        differ.push(format!(
            "--seed {} in the checkpoint, {seed} given",
            sim.seed()
        ));
    }
    if !differ.is_empty() {
        return Err(usage(format!(
            "--resume {}: the flags differ from the checkpointed run's: {}",
            dir.display(),
            differ.join("; ")
        )));
    }
    tracing::info!(particles = sim.particles(), "resumed");
    Ok(sim)
}

/// The files of a run in --out besides run.json, checkpoint.bin and config.toml: what makes a directory an
/// earlier run's and what --overwrite deletes.
const RUN_FILES: &[&str] = &[
    "growth.csv",
    "positions.*",
    "positions_parent.npy",
    "branches.csv",
    "branches.png",
    "dla.png",
    "dla.gif",
];

/// What an ensemble (`--seeds`) averages over its members.
const CURVES: &[Curve] = &[Curve {
    file: "growth.csv",
    x: "n",
    ys: &["radius_of_gyration", "r_ext"],
    missing: None,
    title: "Radius of gyration and extent against N",
    axes: ("particles N", "R_g and R_ext (particle diameters)"),
    log_x: true,
    log_y: true,
    colours: &[],
}];

/// DLA and PDLA as the run machinery sees them.
struct Dla;

// The help texts of the figure flags, as `--help` shows them (clap would take them from doc
// comments on the fields; `FigureArgs` is shared, so they are given here).
impl FigureHelp for Dla {
    const PNG: Option<&'static str> = Some(
        "Write dla.png: a figure of the cluster (axes in diameters, scale bar, N and seed, colour \
         bar), coloured by arrival order (3D: shaded spheres seen from +z; 4D and 5D: the same \
         raster of the projection on x, y, z), or, when a pixel spans more than a diameter, by \
         the number of particles per pixel on a log scale (projected on x, y)",
    );
    const PNG_SIZE: &'static str = "Side of the raster in dla.png and dla.gif in pixels (the axes \
         and legend come on top), 16 to 65536, at most 16384 with --animate (default: dla.png one \
         pixel per diameter, 512 to 4096; dla.gif 512)";
    const ANIMATE: &'static str = "Write dla.gif: the growth of the cluster, one frame every \
         --animate-every particles and one of the whole cluster, all on the finished cluster's \
         frame and colours";
    const ANIMATE_EVERY: &'static str = "Particles between frames of dla.gif, 1.. (default: a \
         hundredth of --particles)";
}

impl Model for Dla {
    const NAME: &'static str = "dla";
    const RUN_FILES: &'static [&'static str] = RUN_FILES;
    const COMBINE: Combine<'static> = Combine {
        curves: CURVES,
        pooled: &[],
    };
    type Cli = Cli;
    type Params = Params;

    fn run_args(cli: &Cli) -> &RunArgs {
        &cli.run
    }

    fn params(cli: &Cli) -> Result<Params, String> {
        // Positions stream to positions.npy instead of `keep_positions` (see `run`).
        let p = cli.params.params();
        let p = if cli.paper_settings {
            // clap has refused the flags it sets (`conflicts_with_all`, the same list).
            p.with_paper_settings(|_| false)
                .map_err(|e| e.to_string())?
        } else {
            p
        };
        // Flags that would be silently ignored are refused too.
        p.validate_given(|name| cli.params.given(name))
            .map_err(|e| e.to_string())?;
        // Wherever the positions stream, each particle's parent goes with them (unless
        // --no-parents): into the positions files, and to resume with.
        let p = Params {
            connectivity: streams_positions(cli) && !cli.no_parents,
            ..p
        };
        if p.dim > 3 && matches!(cli.positions, PositionsFormat::Xyz | PositionsFormat::Vtk) {
            return Err(format!(
                "--positions {} holds three coordinates, not the {} of --dim {}; use npy, csv or bin",
                cli.positions.name(),
                p.dim,
                p.dim
            ));
        }
        cli.run.checkpoints.check(cli.checkpoint_every)?;
        cli.figure.check()?;
        if cli.positions == PositionsFormat::Vtk && p.particles > run_io::points::VTK_MAX_POINTS {
            return Err(format!(
                "--positions vtk holds at most {} points (legacy VTK's 32-bit cell list), not {}; \
                 use --positions npy",
                run_io::points::VTK_MAX_POINTS,
                p.particles
            ));
        }
        check_memory(cli, &p)?;
        Ok(p)
    }

    fn resume_dir(cli: &Cli) -> Option<&Path> {
        cli.resume.as_deref()
    }

    fn threads(params: &Params) -> usize {
        params.threads
    }

    // The one run-time dimension dispatch (`with_dim!`, shared with Python and xtask).
    fn run(cli: &Cli, params: Params, own: Own<'_>) -> anyhow::Result<()> {
        dla_pdla::with_dim!(params.dim, D => run::<D>(cli, params, own), d => Err(ParamsError::dim(d).into()))
    }
}

fn main() -> ExitCode {
    run_cli::model::main::<Dla>()
}

fn run<const D: usize>(cli: &Cli, params: Params, own: Own<'_>) -> anyhow::Result<()>
where
    Dim<D>: Space<D>,
{
    let clock = RunClock::start();
    let total = params.particles;
    tracing::info!(?params, seed = cli.run.seed, "starting growth");
    // Everything that can refuse the run happens before --out is created.
    let mut sim = match &cli.resume {
        None => Simulation::<D>::new(params, cli.run.seed).map_err(|e| match e {
            SimError::Params(e) => usage(e.to_string()),
            other => anyhow::Error::from(other).context("setting up the run"),
        })?,
        Some(dir) => resume::<D>(dir, &params, cli.run.seed)?,
    };
    // Ours until the run ends: refused if another run holds it or it holds an earlier run.
    let _lock = own.take()?;
    let asked_positions = asked_positions(cli);
    let checkpoints = cli.run.checkpoints.enabled();
    if matches!(cli.positions, PositionsFormat::Csv | PositionsFormat::Xyz) && total > 10_000_000 {
        tracing::warn!(
            "--positions {} for {total} particles writes about {} GB of text; positions.npy holds them in {} GB",
            cli.positions.name(),
            total * 25 * D as u64 / 1_000_000_000,
            total * 8 * D as u64 / 1_000_000_000
        );
    }
    sim.stream_into(&cli.run.out, streams_positions(cli))?;
    let progress = cli
        .run
        .log
        .progress("dla", total, "particles", PROGRESS_TEMPLATE);
    let report = |n| progress.set_position(n);
    // Timed checkpoints, signals and the memory watch; a checkpoint needs a few kilobytes
    // beyond the buffers already flushed.
    let (guard, watch, _) = cli
        .run
        .checkpoints
        .start(dla_pdla::params::CHECKPOINT_RESERVE_BYTES)
        .context("installing signal handlers")?;
    let end = sim.run_guarded(cli.checkpoint_every, &guard, checkpoints, &report)?;
    drop(watch);
    if let Some(reason) = end {
        progress.finish();
        let at = format!("at {} of {total} particles", sim.particles());
        return Err(stopped(&reason, &at, &cli.run.out, checkpoints));
    }
    progress.finish();
    // Positions streamed only for the checkpoints are not synced: they go at the end.
    // ... unless an output reads them back (a deposit's profile): then they are synced and
    // removed after the outputs.
    let read_back = dla_pdla::output::reads_positions(sim.params());
    let discard = !asked_positions && !read_back && sim.discard_positions();
    let remove = discard || (!asked_positions && read_back && sim.streams_positions());
    sim.sync_streams()?;
    let png = cli.figure.png.then(|| {
        cli.figure
            .png_size
            .unwrap_or_else(|| default_png_side_of(&sim))
    });
    if cli.figure.animate {
        let side = cli
            .figure
            .png_size
            .unwrap_or(dla_pdla::figure::ANIMATION_DEFAULT_SIDE);
        let every = cli
            .figure
            .animate_every
            .unwrap_or_else(|| dla_pdla::figure::default_animation_every(total));
        let frames = dla_pdla::figure::write_animation(
            &sim,
            &cli.run.out,
            &cli.run.out.join("dla.gif"),
            side,
            every,
        )?;
        tracing::info!(frames, "dla.gif");
    }
    let m = write_outputs(&sim, &clock, &cli.run.out, cli.positions, png)?;
    // What only the checkpoints needed goes, the checkpoint first (it refers to the
    // positions); what was asked for stays.
    run_cli::cli::checkpoints::remove_unasked_checkpoint(
        &cli.run.out,
        cli.checkpoint_every.is_some(),
    )
    .context("removing checkpoint.bin")?;
    if remove {
        sim.remove_positions_file()?;
    }
    if let Some(e) = m.results.get("fit_error").and_then(|v| v.as_str())
        && sim.params().substrate().is_none()
    {
        tracing::warn!("no fractal dimension: {e}");
    }
    tracing::info!(discarded = sim.discarded_walkers(), "done");
    if !cli.run.log.is_quiet() {
        eprintln!("{}", dla_pdla::output::summary(&sim, &m, &cli.run.out));
    }
    Ok(())
}

#[cfg(test)]
#[path = "cli_spec_tests.rs"]
mod cli_spec_tests;
