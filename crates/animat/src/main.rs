//! `animat`: the predator-prey animat model of Hawick, James & Scogings (2006), "Grid-Boxing
//! for Spatial Simulation Performance Optimisation", section II.B (see `docs/animat.md`). A thin
//! layer over the `animat` library: parse flags and the config file, validate, run, write
//! outputs. Built with the `cli` feature (on by default).

use animat::output::{self, PopulationRow};
use animat::{GridBox, Params, World};
use anyhow::Context;
use clap::Parser;
use core_lattice::cli::LogArgs;
use core_lattice::io::RunClock;
use std::path::PathBuf;
use std::process::ExitCode;

/// Foxes and rabbits on an unbounded plane, each running its rule list in priority order.
///
/// Parameters come from the defaults, then --config FILE.toml, then the flags below (flags
/// win). Outputs go into --out DIR: run.json, populations.csv, and on request PNG snapshots
/// and positions.csv (see docs/animat.md).
#[derive(Parser, Debug)]
#[command(name = "animat", version, allow_negative_numbers = true)]
struct Cli {
    /// Steps to run.
    #[arg(long, default_value_t = 1000)]
    steps: u64,

    /// Seed of every random stream of the run: same seed and parameters, same run.
    #[arg(long, default_value_t = 1)]
    seed: u64,

    /// Output directory (created if missing; nothing is written on bad input).
    #[arg(long)]
    out: PathBuf,

    /// TOML file with any model parameters (see data/animat-default.toml); unknown keys are
    /// errors.
    #[arg(long)]
    config: Option<PathBuf>,

    /// Foxes at the start.
    #[arg(long)]
    foxes: Option<u64>,

    /// Rabbits at the start.
    #[arg(long)]
    rabbits: Option<u64>,

    /// Radius of the start disc around the origin, in cells.
    #[arg(long, conflicts_with = "density")]
    start_radius: Option<i64>,

    /// Start density in animats per cell, in (0, 0.5]: sets the start radius.
    #[arg(long)]
    density: Option<f64>,

    /// Vision radius in cells (>= 1).
    #[arg(long)]
    vision: Option<i64>,

    /// Grid-box side: a positive integer, `vision` (the default) or `none` (exhaustive).
    /// Changes only the speed, never the result.
    #[arg(long)]
    grid_box: Option<String>,

    /// Record neighbour-search seconds and distance evaluations per step in populations.csv.
    #[arg(long)]
    timing: bool,

    /// Write a PNG snapshot every K steps (and of the start and the end).
    #[arg(long)]
    snapshot_every: Option<u64>,

    /// Write positions.csv: every live animat at the end.
    #[arg(long)]
    positions: bool,

    #[command(flatten)]
    log: LogArgs,
}

/// Builds validated parameters: defaults, then the config file, then the flags.
fn params(cli: &Cli) -> Result<Params, String> {
    let mut p = match &cli.config {
        Some(path) => animat::config::read_config(path).map_err(|e| e.to_string())?,
        None => Params::default(),
    };
    if let Some(v) = cli.foxes {
        p.foxes = v;
    }
    if let Some(v) = cli.rabbits {
        p.rabbits = v;
    }
    if let Some(v) = cli.start_radius {
        p.start_radius = v;
    }
    if let Some(d) = cli.density {
        if !(d > 0.0 && d <= 0.5) {
            return Err(format!(
                "--density {d} is outside the accepted range (0, 0.5]"
            ));
        }
        p.start_radius = Params::radius_for_density(p.foxes.saturating_add(p.rabbits), d);
    }
    if let Some(v) = cli.vision {
        p.vision = v;
    }
    if let Some(g) = &cli.grid_box {
        p.grid_box = g
            .parse::<GridBox>()
            .map_err(|e| format!("--grid-box: {e}"))?;
    }
    if cli.snapshot_every == Some(0) {
        return Err("--snapshot-every 0 is outside the accepted range 1..".into());
    }
    p.validate().map_err(|e| e.to_string())?;
    core_lattice::cli::check_out_dir(&cli.out)?;
    Ok(p)
}

fn main() -> ExitCode {
    core_lattice::cli::main_with("animat", |c: &Cli| c.log, params, run)
}

fn run(cli: &Cli, params: Params) -> anyhow::Result<()> {
    let clock = RunClock::start();
    let mut world = World::new(params, cli.seed).context("setting up the run")?;
    world.set_timing(cli.timing);
    core_lattice::cli::prepare_out_dir(&cli.out)
        .with_context(|| format!("creating output directory {}", cli.out.display()))?;
    tracing::info!(
        foxes = world.foxes(),
        rabbits = world.rabbits(),
        grid = %world.grid().box_size(),
        "start"
    );
    let snapshot = |w: &World| -> anyhow::Result<()> {
        let path = cli.out.join(format!("snapshot_{:06}.png", w.steps()));
        output::write_snapshot(&path, w)?;
        Ok(())
    };
    let bar = cli.log.progress_bar(
        cli.steps,
        "{elapsed_precise} [{bar:40}] {pos}/{len} steps, {msg}",
    );
    let mut rows = vec![PopulationRow {
        step: 0,
        foxes: world.foxes(),
        rabbits: world.rabbits(),
        search_seconds: 0.0,
        distance_evals: 0,
    }];
    if cli.snapshot_every.is_some() {
        snapshot(&world)?;
    }
    for _ in 0..cli.steps {
        if world.foxes() + world.rabbits() == 0 {
            tracing::info!(step = world.steps(), "every animat has died");
            break;
        }
        let s = world.step();
        rows.push(PopulationRow {
            step: world.steps(),
            foxes: world.foxes(),
            rabbits: world.rabbits(),
            search_seconds: s.search_seconds,
            distance_evals: s.distance_evals,
        });
        if let Some(k) = cli.snapshot_every {
            if world.steps() % k == 0 {
                snapshot(&world)?;
            }
        }
        if let Some(bar) = &bar {
            bar.inc(1);
            if world.steps() % 16 == 0 {
                bar.set_message(format!(
                    "{} foxes, {} rabbits",
                    world.foxes(),
                    world.rabbits()
                ));
            }
        }
    }
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    if let Some(k) = cli.snapshot_every {
        if world.steps() % k != 0 {
            snapshot(&world)?;
        }
    }
    output::write_populations(&cli.out, &rows, cli.timing)?;
    if cli.positions {
        output::write_positions(&cli.out, &world)?;
    }
    let m = output::write_manifest(&cli.out, &world, cli.seed, &clock)?;
    if !cli.log.quiet {
        eprintln!(
            "animat: {} foxes, {} rabbits after {} steps in {:.2} s (state {}); outputs in {}",
            world.foxes(),
            world.rabbits(),
            world.steps(),
            m.wall_seconds,
            world.state_hash(),
            cli.out.display()
        );
    }
    Ok(())
}
