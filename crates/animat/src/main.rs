//! `animat`: the predator-prey animat model of Hawick, James & Scogings (2006), "Grid-Boxing
//! for Spatial Simulation Performance Optimisation", section II.B (see `docs/animat.md`). A thin
//! layer over the `animat` library: parse flags and the config file, validate, run, write
//! outputs. Built with the `cli` feature (on by default).

use animat::checkpoint::Saved;
use animat::output::{self, PopulationRow};
use animat::{Params, World};
use anyhow::Context;
use clap::Parser;
use run_cli::cli::{FigureArgs, FigureHelp, ParamFlags, flag_differences, usage};
use run_cli::ensemble::{Combine, Curve};
use run_cli::model::{Model, Own, RunArgs};
use run_io::{Positions, RunClock, read_checkpoint, show_bytes, write_checkpoint};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Foxes and rabbits on an unbounded plane, each running its rule list in priority order.
///
/// Parameters come from the defaults, then --config FILE.toml, then the flags below (flags
/// win); every model parameter is a flag and a config key. Outputs go into --out DIR: run.json,
/// populations.csv, and on request PNG snapshots and positions.csv (see docs/animat.md).
#[derive(Parser, Debug)]
#[command(name = "animat", version = run_cli::cli::version(), allow_negative_numbers = true)]
struct Cli {
    /// Steps to run.
    #[arg(long, value_parser = run_cli::cli::count::<u64>, default_value_t = animat::params::DEFAULT_STEPS)]
    steps: u64,

    #[command(flatten)]
    params: ParamFlags<Params>,

    // Float flags take values starting with `-` (`-inf`), so that validation names the flag;
    // clap would read `-inf` as an unknown short flag.
    /// Start density in animats per cell, in (0, 0.5]: sets the start radius to
    /// ceil(sqrt(animats / (pi density))).
    #[arg(long, allow_hyphen_values = true, conflicts_with = "start_radius")]
    density: Option<f64>,

    /// Record neighbour-search seconds and distance evaluations per step in populations.csv.
    #[arg(long)]
    timing: bool,

    /// Memory the run may take, in bytes; suffixes K, M, G, T (powers of 1024). The world is
    /// estimated as 256 bytes per animat plus 36 KiB for each 64 x 64 square of cells holding
    /// one (a dilute world takes 36 KiB per animat): a start that needs more is refused, a run
    /// that grows past it stops with an error. Default: 4 GiB, or the memory available
    /// (MemAvailable, or a lower cgroup limit) if less.
    #[arg(long, value_name = "BYTES", value_parser = run_io::memory::parse_bytes)]
    max_memory: Option<u64>,

    /// Write a PNG snapshot every K steps (and of the start and the end): a figure of the world
    /// on the run's fixed frame (axes in cells, scale bar, step, populations, seed, key).
    #[arg(long, value_parser = run_cli::cli::count::<u64>)]
    snapshot_every: Option<u64>,

    /// Half the side of the one frame of every snapshot and animation frame, in cells around
    /// the origin, 1.. (default: 3 start radii); animats outside it are counted in the header.
    #[arg(long, value_name = "CELLS", value_parser = run_cli::cli::count::<i64>)]
    frame_radius: Option<i64>,

    // --png-size, --animate and --animate-every (animat has no --png: its still figures are
    // --snapshot-every's), with animat's help texts (`FigureHelp`).
    #[command(flatten)]
    figure: FigureArgs<Animat>,

    /// Write every live animat at the end (id, species, x, y, age, hunger): positions.csv
    /// (`--positions` alone), positions.npy with one positions_<attribute>.npy per attribute
    /// (NumPy), positions.vtk (ParaView), positions.xyz (extended XYZ: OVITO, VMD), or none.
    #[arg(long, value_enum, value_name = "FORMAT", num_args = 0..=1, default_value_t = Positions::None, default_missing_value = "csv")]
    positions: Positions,

    /// Also save the run to OUT/checkpoint.bin every N steps, and keep one at the end
    /// (atomically), so that --resume with a larger --steps goes on from there.
    #[arg(long, value_name = "N", value_parser = run_cli::cli::count_at_least_1::<u64>)]
    checkpoint_every: Option<u64>,

    /// Continue the run saved in DIR/checkpoint.bin (a checkpoint, or a stopped run) to the same state
    /// as an uninterrupted run: the model parameters and --seed must be those of the saved run
    /// (--steps may grow; output flags may change).
    #[arg(long, value_name = "DIR")]
    resume: Option<PathBuf>,

    // Seed, --out and how the process runs: after the model's own flags in --help.
    #[command(flatten)]
    run: RunArgs,
}

/// The default cap of `--max-memory` on the world.
const DEFAULT_MAX_MEMORY: u64 = 4 << 30;

/// The memory the run may take: `--max-memory`, else 4 GiB or the memory available if less.
fn memory_limit(cli: &Cli) -> run_io::memory::Limit {
    run_io::memory::Limit::with_default_cap(cli.max_memory, DEFAULT_MAX_MEMORY)
}

/// The files of a run in --out besides run.json, checkpoint.bin and config.toml: what makes a directory an
/// earlier run's and what --overwrite deletes.
const RUN_FILES: &[&str] = &[
    "populations.csv",
    "snapshot_*.png",
    "animat.gif",
    "positions.*",
    "positions_*",
];

/// What an ensemble (`--seeds`) averages over its members.
const CURVES: &[Curve] = &[Curve {
    file: "populations.csv",
    x: "step",
    ys: &["foxes", "rabbits"],
    missing: None,
    title: "Populations against steps",
    axes: ("step", "animats"),
    log_x: false,
    log_y: false,
    // The species' colours of the snapshots.
    colours: &[figures::palette::FOX, figures::palette::RABBIT],
}];

/// The animat model as the run machinery sees it.
struct Animat;

// The help texts of the figure flags, as `--help` shows them (clap would take them from doc
// comments on the fields; `FigureArgs` is shared, so they are given here).
impl FigureHelp for Animat {
    const PNG: Option<&'static str> = None;
    const PNG_SIZE: &'static str = "Side of the raster in the snapshots and animat.gif in pixels \
         (the axes and legend come on top), 16 to 65536, at most 16384 with --animate (default: a \
         whole number of pixels per cell and at least 512, or one per cell up to 1024)";
    const ANIMATE: &'static str = "Write animat.gif: the world at the start, every --animate-every \
         steps and at the end";
    const ANIMATE_EVERY: &'static str = "Steps between frames of animat.gif, 1.. (default: a \
         hundredth of --steps)";
}

impl Model for Animat {
    const NAME: &'static str = "animat";
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

    /// Builds validated parameters: the defaults, then the flags (those of `--config` first).
    fn params(cli: &Cli) -> Result<Params, String> {
        let mut p = cli.params.params();
        if let Some(d) = cli.density {
            p.set_density(d)?;
        }
        if cli.snapshot_every == Some(0) {
            return Err("--snapshot-every 0 is outside the accepted range 1..".into());
        }
        if cli.frame_radius == Some(0) {
            return Err("--frame-radius 0 is outside the accepted range 1..".into());
        }
        cli.figure
            .check_with(cli.snapshot_every.is_some(), "--snapshot-every")?;
        let figures = cli.snapshot_every.is_some() || cli.figure.animate;
        if cli.frame_radius.is_some() && !figures {
            return Err(
                "--frame-radius frames the figures of --snapshot-every and --animate; give one"
                    .into(),
            );
        }
        p.validate().map_err(|e| e.to_string())?;
        if cli.resume.is_none() {
            let what = format!(
                "{} animats in a disc of radius {}: a 36 KiB tile of the cell index for each \
                 64 x 64 square holding an animat, 256 bytes per animat",
                p.foxes.saturating_add(p.rabbits),
                p.start_radius
            );
            // The world's memory, as the cap on a growing world counts it (the program's own
            // few MiB, in `peak_memory_bytes`, aside).
            memory_limit(cli).check(
                p.start_memory_bytes(),
                &what,
                "raise --density (or lower --start-radius)",
            )?;
        }
        cli.run.checkpoints.check(cli.checkpoint_every)?;
        Ok(p)
    }

    fn resume_dir(cli: &Cli) -> Option<&Path> {
        cli.resume.as_deref()
    }

    fn run_flags(cli: &Cli) -> Vec<(&'static str, String, String)> {
        vec![(
            "--steps",
            cli.steps.to_string(),
            animat::params::DEFAULT_STEPS.to_string(),
        )]
    }

    fn run(cli: &Cli, params: Params, own: Own<'_>) -> anyhow::Result<()> {
        run(cli, params, own)
    }
}

fn main() -> ExitCode {
    run_cli::model::main::<Animat>()
}

/// File name of checkpoints in the output directory.
const CHECKPOINT: &str = "checkpoint.bin";
/// Model name in the checkpoint envelope.
const CHECKPOINT_MODEL: &str = "animat";

/// The run saved in `DIR/checkpoint.bin`, if it is one these flags continue; anything else is
/// a usage error naming the file, or the parameters that differ with both values.
fn resume(
    dir: &Path,
    params: &Params,
    seed: u64,
    steps: u64,
) -> anyhow::Result<(World, Vec<PopulationRow>)> {
    let path = dir.join(CHECKPOINT);
    let at = || format!("--resume {}", path.display());
    let saved: Saved =
        read_checkpoint(&path, CHECKPOINT_MODEL).map_err(|e| usage(format!("{}: {e}", at())))?;
    let mut differ = flag_differences(saved.world.params(), params, &[]);
    if saved.world.seed() != seed {
        differ.push(format!(
            "--seed {} in the checkpoint, {seed} given",
            saved.world.seed()
        ));
    }
    if !differ.is_empty() {
        return Err(usage(format!(
            "{}: the parameters differ from the saved run's: {}",
            at(),
            differ.join("; ")
        )));
    }
    if saved.world.steps() > steps {
        return Err(usage(format!(
            "{}: the saved run has done {} steps, more than --steps {steps}",
            at(),
            saved.world.steps()
        )));
    }
    let world = World::restore(saved.world).map_err(|e| usage(format!("{}: {e}", at())))?;
    if saved.rows.last().map(|r| r.step) != Some(world.steps()) {
        return Err(usage(format!(
            "{}: the population rows do not end at step {}",
            at(),
            world.steps()
        )));
    }
    tracing::info!(step = world.steps(), "resumed");
    Ok((world, saved.rows))
}

fn run(cli: &Cli, params: Params, own: Own<'_>) -> anyhow::Result<()> {
    let clock = RunClock::start();
    let limit = memory_limit(cli);
    // Everything that can refuse the run happens before --out is created.
    let (mut world, mut rows) = match &cli.resume {
        Some(dir) => resume(dir, &params, cli.run.seed, cli.steps)?,
        None => {
            // Every error of the set-up is a parameter the run cannot take.
            let world = World::new(params, cli.run.seed).map_err(|e| usage(e.to_string()))?;
            let start = PopulationRow::of(&world, Default::default());
            (world, vec![start])
        }
    };
    world.set_timing(cli.timing);
    // Ours until the run ends: refused if another run holds it or it holds an earlier run.
    let _lock = own.take()?;
    tracing::info!(
        foxes = world.foxes(),
        rabbits = world.rabbits(),
        grid = %world.box_size(),
        "start"
    );
    let save = |world: &World, rows: &[PopulationRow]| -> anyhow::Result<()> {
        let saved = Saved {
            world: world.snapshot(),
            rows: rows.to_vec(),
        };
        write_checkpoint(cli.run.out.join(CHECKPOINT), CHECKPOINT_MODEL, &saved)
            .context("writing a checkpoint")?;
        Ok(())
    };
    let frame = output::SnapshotFrame::new(world.params(), cli.frame_radius, cli.figure.png_size);
    let snapshot = |w: &World| -> anyhow::Result<()> {
        let path = cli.run.out.join(format!("snapshot_{:06}.png", w.steps()));
        output::write_snapshot(&path, w, &frame)?;
        Ok(())
    };
    let mut animation = if cli.figure.animate {
        let every = cli
            .figure
            .animate_every
            .unwrap_or_else(|| output::default_animate_every(cli.steps));
        Some(output::Animation::start(
            &world,
            &cli.run.out.join("animat.gif"),
            frame,
            every,
        )?)
    } else {
        None
    };
    let progress = cli.run.log.progress(
        "animat",
        cli.steps,
        "steps",
        "{elapsed_precise} [{bar:40}] {pos}/{len} steps, {msg}",
    );
    if cli.snapshot_every.is_some() && cli.resume.is_none() {
        snapshot(&world)?;
    }
    progress.set_position(world.steps().min(cli.steps));
    // Timed checkpoints, signals and the memory watch, which keeps room for a checkpoint.
    let enabled = cli.run.checkpoints.enabled();
    let (guard, _watch, memory) = cli
        .run
        .checkpoints
        .start(animat::checkpoint::reserve_bytes(&world, rows.len()))
        .context("installing signal handlers")?;
    while world.steps() < cli.steps {
        if guard.is_set() {
            let at = || format!("after step {}", world.steps());
            run_cli::cli::checkpoints::honour(
                &guard,
                enabled,
                &cli.run.out,
                || save(&world, &rows),
                at,
            )
            .inspect_err(|_| progress.finish())?;
        }
        if world.foxes() + world.rabbits() == 0 {
            tracing::info!(step = world.steps(), "every animat has died");
            break;
        }
        let s = world.step();
        if world.memory_bytes() > limit.bytes {
            progress.finish();
            let then = if enabled {
                rows.push(PopulationRow::of(&world, s));
                save(&world, &rows)?;
                format!(
                    "raise --max-memory and continue with --resume {} (checkpointed at this step)",
                    cli.run.out.display()
                )
            } else {
                "raise --max-memory".to_string()
            };
            anyhow::bail!(
                "after step {} the world holds {} animats and takes about {}, over {}; {then}",
                world.steps(),
                world.foxes() + world.rabbits(),
                show_bytes(world.memory_bytes()),
                limit.describe()
            );
        }
        memory.reserve.store(
            animat::checkpoint::reserve_bytes(&world, rows.len()),
            std::sync::atomic::Ordering::Relaxed,
        );
        rows.push(PopulationRow::of(&world, s));
        if let Some(a) = animation.as_mut() {
            a.step(&world)?;
        }
        if let Some(k) = cli.snapshot_every {
            if world.steps() % k == 0 {
                snapshot(&world)?;
            }
        }
        if let Some(n) = cli.checkpoint_every
            && world.steps() % n == 0
            && world.steps() < cli.steps
        {
            save(&world, &rows)?;
        }
        if world.steps() % 16 == 0 {
            progress.set_message(format!(
                "{} foxes, {} rabbits",
                world.foxes(),
                world.rabbits()
            ));
        }
        progress.inc(1);
    }
    progress.finish();
    if cli.checkpoint_every.is_some() {
        save(&world, &rows)?;
    } else {
        // A checkpoint the run did not ask for (a timed one, or the one it was resumed from)
        // goes.
        run_cli::cli::checkpoints::remove_unasked_checkpoint(&cli.run.out, false)
            .context("removing checkpoint.bin")?;
    }
    if let Some(k) = cli.snapshot_every {
        if world.steps() % k != 0 {
            snapshot(&world)?;
        }
    }
    if let Some(a) = animation {
        let frames = a.finish(&world)?;
        tracing::info!(frames, "animat.gif");
    }
    output::write_populations(&cli.run.out, &rows, cli.timing)?;
    if let Some(format) = cli.positions.format() {
        output::write_positions(&cli.run.out, &world, format)?;
    }
    let m = output::write_manifest(&cli.run.out, &world, cli.run.seed, &clock)?;
    if !cli.run.log.is_quiet() {
        eprintln!(
            "animat: {} foxes, {} rabbits after {} steps in {:.2} s (state {}); outputs in {}",
            world.foxes(),
            world.rabbits(),
            world.steps(),
            m.wall_seconds,
            world.state_hash(),
            cli.run.out.display()
        );
    }
    Ok(())
}

#[cfg(test)]
#[path = "cli_spec_tests.rs"]
mod cli_spec_tests;
