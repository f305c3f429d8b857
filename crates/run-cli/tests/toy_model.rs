//! "Adding a model" (`docs/architecture.md`), followed to the letter by a test: a toy model
//! (a biased one-dimensional random walk) declares its parameters once
//! (`core_lattice::declare_params!`), implements `run_cli::model::Model` and runs
//! `run_cli::model::main`, and gets every front end of the contract without a line of its
//! own: flags with their help and ranges, `--config`, `--dump-config`, usage errors that exit 2
//! and write nothing, the claim of `--out`, `config.toml` that repeats the run, and ensembles.
//!
//! This file is its own `main` (`harness = false`): run with `TOY_MODEL_CHILD` set, it is the
//! toy's binary; without, it runs the checks on itself.

use core_lattice::rng::{RngExt, stream};
use core_lattice::spec::{End, Range};
use run_cli::cli::ParamFlags;
use run_cli::ensemble::{Combine, Curve};
use run_cli::model::{Model, Own, RunArgs};
use run_io::RunClock;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Output};

core_lattice::declare_params! {
    /// The toy's parameters: a walk of `steps` unit steps, each +1 with probability `bias`.
    #[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
    #[serde(default)]
    pub struct ToyParams {
        /// Steps of the walk.
        steps: u64 = 100 => {
            flag: "steps", unit: "steps", range: Range::Int { min: 1, max: Some(1_000_000) },
        },
        /// Probability of a step to the right.
        bias: f64 = 0.5 => {
            flag: "bias", unit: "", range: Range::Real(End::Closed(0.0), End::Closed(1.0)),
            why: "a probability",
        },
    }
    internal {}
}

/// A biased random walk.
#[derive(clap::Parser, Debug)]
#[command(name = "toy", allow_negative_numbers = true)]
struct Cli {
    #[command(flatten)]
    params: ParamFlags<ToyParams>,

    #[command(flatten)]
    run: RunArgs,

    /// Continue the run saved in DIR (the toy keeps no checkpoints: refused).
    #[arg(long, value_name = "DIR")]
    resume: Option<PathBuf>,
}

struct Toy;

/// The files of a run besides run.json and config.toml.
const RUN_FILES: &[&str] = &["walk.csv"];

impl Model for Toy {
    const NAME: &'static str = "toy";
    const RUN_FILES: &'static [&'static str] = RUN_FILES;
    const COMBINE: Combine<'static> = Combine {
        curves: &[Curve {
            file: "walk.csv",
            x: "step",
            ys: &["x"],
            missing: None,
            title: "Position against steps",
            axes: ("step", "x"),
            log_x: false,
            log_y: false,
            colours: &[],
        }],
        pooled: &[],
    };
    type Cli = Cli;
    type Params = ToyParams;

    fn run_args(cli: &Cli) -> &RunArgs {
        &cli.run
    }

    fn params(cli: &Cli) -> Result<ToyParams, String> {
        let p = cli.params.params();
        use core_lattice::spec::DeclaredParams;
        p.check_ranges().map_err(|e| e.to_string())?;
        Ok(p)
    }

    fn resume_dir(cli: &Cli) -> Option<&Path> {
        cli.resume.as_deref()
    }

    fn run(cli: &Cli, p: ToyParams, own: Own<'_>) -> anyhow::Result<()> {
        let clock = RunClock::start();
        if cli.resume.is_some() {
            return Err(run_cli::cli::usage(
                "--resume: the toy keeps no checkpoints",
            ));
        }
        let _lock = own.take()?;
        let mut rng = stream(cli.run.seed, 0);
        let mut x = 0i64;
        let mut csv = String::from("step,x\n0,0\n");
        for step in 1..=p.steps {
            x += if rng.random_bool(p.bias) { 1 } else { -1 };
            csv.push_str(&format!("{step},{x}\n"));
        }
        run_io::write_atomic(cli.run.out.join("walk.csv"), csv.as_bytes())?;
        let mut m = clock.finish("toy", "0", cli.run.seed, 1, &p)?;
        m.set_result("final_x", x);
        m.write(&cli.run.out)?;
        Ok(())
    }
}

fn toy(args: &[&str], dir: &Path) -> Output {
    Command::new(std::env::current_exe().unwrap())
        .args(args)
        .current_dir(dir)
        .env("TOY_MODEL_CHILD", "1")
        .output()
        .unwrap()
}

fn json(path: PathBuf) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn checks() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let stderr = |o: &Output| String::from_utf8_lossy(&o.stderr).to_string();

    // The declared parameters are flags, with their ranges in the help.
    let o = toy(&["--help"], dir);
    let help = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        help.contains("--steps") && help.contains("--bias"),
        "{help}"
    );
    assert!(
        help.contains("Probability of a step to the right. Accepted [0, 1]"),
        "{help}"
    );
    assert!(
        help.contains("--seeds") && help.contains("--checkpoint-interval"),
        "{help}"
    );

    // A value outside its range: one line, exit code 2, nothing written.
    let o = toy(&["--bias", "2", "--out", "bad", "-q"], dir);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(
        stderr(&o).trim(),
        "toy: error: --bias 2 is outside the accepted range [0, 1] (a probability)"
    );
    assert!(!dir.join("bad").exists());

    // A run: run.json with the parameters, the model's file, and config.toml.
    let o = toy(
        &[
            "--steps", "50", "--bias", "0.75", "--seed", "7", "--out", "a", "-q",
        ],
        dir,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let a = json(dir.join("a/run.json"));
    assert_eq!(a["params"]["steps"], 50);
    assert_eq!(a["params"]["bias"], 0.75);
    let rows = std::fs::read_to_string(dir.join("a/walk.csv")).unwrap();
    assert_eq!(rows.lines().count(), 52);
    let config = std::fs::read_to_string(dir.join("a/config.toml")).unwrap();
    assert!(config.contains("bias = 0.75"), "{config}");

    // config.toml repeats the run; --dump-config prints it.
    let o = toy(&["--config", "a/config.toml", "--out", "b", "-q"], dir);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        json(dir.join("b/run.json"))["results"]["final_x"],
        a["results"]["final_x"]
    );
    let o = toy(&["--config", "a/config.toml", "--dump-config"], dir);
    assert!(String::from_utf8_lossy(&o.stdout).contains("seed = 7"));

    // The directory is the earlier run's: refused without --overwrite.
    let o = toy(&["--out", "a", "-q"], dir);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--overwrite"), "{}", stderr(&o));

    // An ensemble of seeds, with the curve averaged over its members.
    let o = toy(
        &["--seeds", "1..=3", "--jobs", "2", "--out", "e", "-q"],
        dir,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let e = json(dir.join("e/ensemble.json"));
    assert_eq!(e["results"]["final_x"]["n"], 3, "{e}");
    assert!(dir.join("e/ensemble_walk.csv").exists());
}

fn main() -> ExitCode {
    if std::env::var_os("TOY_MODEL_CHILD").is_some() {
        return run_cli::model::main::<Toy>();
    }
    checks();
    println!("toy model: every front end of the contract from one declaration: ok");
    ExitCode::SUCCESS
}
