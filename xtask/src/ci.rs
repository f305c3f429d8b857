//! The one definition of what CI checks (`cargo xtask ci`). `.ci/run` only installs what these
//! steps need on a fresh machine (rustfmt and clippy, Python's venv, Open MPI and libclang)
//! and then runs `cargo xtask ci`; a developer runs the same list locally.
//!
//! Steps run in order and stop at the first failure. Steps that need something a machine may
//! lack say so and are skipped with a line (the Python package needs `python3 -m venv`; the
//! `mpi` feature needs Open MPI and libclang).

use crate::{cargo, workspace_root};
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// What a step needs beyond the Rust toolchain.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Needs {
    /// Nothing more.
    Rust,
    /// Python 3 with `venv` (the step runs in a virtual environment under `target/ci-venv`).
    Python,
    /// Open MPI (`mpirun`, `mpicc`) and libclang, for feature `mpi`.
    Mpi,
}

/// How a step runs.
#[derive(Debug, Clone, Copy)]
pub enum Run {
    /// `cargo ARGS` (words separated by spaces) with extra environment variables.
    Cargo(&'static str, &'static [(&'static str, &'static str)]),
    /// `cargo package` of the library crates, after removing cargo's unpacked copies of them
    /// from the last packaging (see `forget_packaged_sources`).
    Package,
    /// `pip install` of the Python package and its test tools into the CI virtual environment.
    PythonInstall,
    /// `pytest` on `python/tests` against the debug binaries the test step built.
    PythonTests,
}

/// One CI step.
#[derive(Debug, Clone, Copy)]
pub struct Step {
    /// Short name, for `--skip` and the log.
    pub name: &'static str,
    /// What it needs.
    pub needs: Needs,
    /// What it runs.
    pub run: Run,
}

/// The README's test command (the `tests` step), kept in one place.
pub const TEST_ARGS: &str = "test --workspace";

/// Every CI step, in order.
pub const STEPS: &[Step] = &[
    Step {
        name: "format",
        needs: Needs::Rust,
        run: Run::Cargo("fmt --all -- --check", &[]),
    },
    Step {
        name: "clippy",
        needs: Needs::Rust,
        run: Run::Cargo("clippy --workspace --all-targets -- -D warnings", &[]),
    },
    // The model libraries build alone, without their command line, figures and files (the
    // simulation alone); run-io without its files; core-lattice without serde, as spatial
    // uses it.
    Step {
        name: "libraries-alone",
        needs: Needs::Rust,
        run: Run::Cargo(
            concat!(
                "clippy -p dlca -p dla-pdla -p animat -p spatial -p core-lattice -p run-io",
                " --no-default-features -- -D warnings"
            ),
            &[],
        ),
    },
    // ... and with their figures (feature `figures`, with their files) but still without the
    // command line, as the Python bindings build them. How many packages each library alone
    // needs is held by xtask/tests/library_deps.rs (the tests step).
    Step {
        name: "libraries-figures",
        needs: Needs::Rust,
        run: Run::Cargo(
            concat!(
                "clippy -p dlca -p dla-pdla -p animat",
                " --no-default-features --features figures -- -D warnings"
            ),
            &[],
        ),
    },
    Step {
        name: "rustdoc",
        needs: Needs::Rust,
        run: Run::Cargo(
            "doc --workspace --no-deps",
            &[("RUSTDOCFLAGS", "-D warnings")],
        ),
    },
    Step {
        name: "tests",
        needs: Needs::Rust,
        run: Run::Cargo(TEST_ARGS, &[]),
    },
    // The orthtree's shared-insert protocol, model-checked with loom on the real code
    // (docs/spatial.md), in a target directory of its own so the ordinary build is not redone.
    Step {
        name: "loom",
        needs: Needs::Rust,
        run: Run::Cargo(
            "test -p spatial --test loom_shared --release",
            &[
                ("RUSTFLAGS", "--cfg loom"),
                ("CARGO_TARGET_DIR", "target/loom"),
                ("LOOM_MAX_PREEMPTIONS", "2"),
            ],
        ),
    },
    // Each library crate as it would be published (nothing is published): packaged, then
    // built on its own from the package, with its workspace dependencies packaged beside it.
    Step {
        name: "package",
        needs: Needs::Rust,
        run: Run::Package,
    },
    // The Python package (python/, its own Cargo workspace): formatted, linted, built and
    // installed by pip (maturin, release) into a fresh virtual environment, and its tests run
    // against the debug binaries the test step built.
    Step {
        name: "python-format",
        needs: Needs::Rust,
        run: Run::Cargo("fmt --manifest-path python/Cargo.toml -- --check", &[]),
    },
    Step {
        name: "python-clippy",
        needs: Needs::Rust,
        run: Run::Cargo(
            "clippy --manifest-path python/Cargo.toml --all-targets -- -D warnings",
            &[],
        ),
    },
    Step {
        name: "python-install",
        needs: Needs::Python,
        run: Run::PythonInstall,
    },
    Step {
        name: "python-tests",
        needs: Needs::Python,
        run: Run::PythonTests,
    },
    // Feature `mpi` (ensembles over the ranks of an MPI job): built, linted and tested where
    // Open MPI and libclang are installed, in a target directory of its own (as
    // docs/ensembles.md builds it), so that the MPI binaries and the plain ones do not replace
    // each other in target/debug. The plain build's refusal under `mpirun` is tested by the
    // test step (tests/mpi.rs without the feature).
    Step {
        name: "mpi-clippy",
        needs: Needs::Mpi,
        run: Run::Cargo(
            "clippy -p dla-pdla -p dlca -p animat --features mpi --all-targets -- -D warnings",
            &[("CARGO_TARGET_DIR", "target/mpi")],
        ),
    },
    Step {
        name: "mpi-tests",
        needs: Needs::Mpi,
        run: Run::Cargo(
            "test -p dla-pdla --features mpi --test ensemble --test mpi",
            &[("CARGO_TARGET_DIR", "target/mpi")],
        ),
    },
];

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|dir| dir.join(program).is_file()))
}

fn have_libclang() -> bool {
    let found_in = |dir: &Path| {
        std::fs::read_dir(dir).is_ok_and(|entries| {
            entries.flatten().any(|e| {
                let name = e.file_name().to_string_lossy().into_owned();
                name.starts_with("libclang") && name.contains(".so")
            })
        })
    };
    let mut dirs: Vec<PathBuf> = Vec::new();
    for base in ["/usr/lib", "/usr/lib64", "/usr/local/lib"] {
        dirs.push(base.into());
        if let Ok(entries) = std::fs::read_dir(base) {
            for e in entries.flatten() {
                dirs.push(e.path());
                dirs.push(e.path().join("lib"));
            }
        }
    }
    dirs.iter().any(|d| found_in(d))
}

/// Why a step cannot run on this machine, or `None` when it can.
pub fn missing(needs: Needs) -> Option<String> {
    match needs {
        Needs::Rust => None,
        Needs::Python => {
            let ok = Command::new("python3")
                .args(["-c", "import venv, ensurepip"])
                .output()
                .is_ok_and(|o| o.status.success());
            (!ok).then(|| "Python 3 with venv and ensurepip is not installed".to_string())
        }
        Needs::Mpi => (!(on_path("mpirun") && on_path("mpicc") && have_libclang()))
            .then(|| "Open MPI (mpirun, mpicc) or libclang is not installed".to_string()),
    }
}

fn venv_python() -> PathBuf {
    workspace_root().join("target/ci-venv/bin/python")
}

/// The target directory of the package step, apart from the ordinary one: the verification
/// builds compile our crates as registry crates, which cargo never rebuilds for changed
/// sources, so each packaging starts from an empty one.
const PACKAGE_TARGET: &str = "target/package-check";

/// Removes what an earlier `cargo package` left that a new one would take for current: the
/// unpacked copies of the workspace's own crates from its local registry
/// (`$CARGO_HOME/registry/src/-<hash>/<crate>-<version>`), which cargo unpacks once per name
/// and version, and the verification builds ([`PACKAGE_TARGET`]), which cargo reuses for a
/// registry crate of the same version without looking at its sources. Otherwise a second
/// packaging verifies a crate against the first one's dependencies (seen here: `animat`
/// against a `spatial` from before `spatial::cells` existed). Crates from crates.io are not
/// touched: their registry directories are named after the index, never starting with `-`.
fn forget_packaged_sources() -> Result<()> {
    let builds = workspace_root().join(PACKAGE_TARGET);
    if builds.exists() {
        std::fs::remove_dir_all(&builds)
            .with_context(|| format!("removing {}", builds.display()))?;
    }
    let home = std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cargo")));
    let Some(src) = home.map(|h| h.join("registry/src")) else {
        return Ok(());
    };
    let ours: Vec<String> = crate::codemap::workspace_crates(&workspace_root())
        .into_iter()
        .map(|(name, _)| format!("{name}-"))
        .collect();
    let Ok(registries) = std::fs::read_dir(&src) else {
        return Ok(());
    };
    for reg in registries.flatten() {
        if !reg.file_name().to_string_lossy().starts_with('-') {
            continue;
        }
        for entry in std::fs::read_dir(reg.path())?.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            if ours.iter().any(|o| name.starts_with(o.as_str())) {
                std::fs::remove_dir_all(entry.path())
                    .with_context(|| format!("removing {}", entry.path().display()))?;
            }
        }
    }
    Ok(())
}

fn status(cmd: &mut Command, what: &str) -> Result<()> {
    crate::run_checked(cmd.current_dir(workspace_root()), what)
}

fn run_step(step: &Step) -> Result<()> {
    match step.run {
        Run::Cargo(args, env) => {
            eprintln!("==> {}: cargo {args}", step.name);
            status(
                Command::new(cargo())
                    .args(args.split_whitespace())
                    .envs(env.iter().copied()),
                &format!("cargo {args}"),
            )
        }
        Run::Package => {
            forget_packaged_sources()?;
            let args = "package --workspace --exclude xtask --allow-dirty";
            eprintln!("==> {}: cargo {args}", step.name);
            status(
                Command::new(cargo())
                    .args(args.split_whitespace())
                    .env("CARGO_TARGET_DIR", PACKAGE_TARGET),
                &format!("cargo {args}"),
            )
        }
        Run::PythonInstall => {
            let venv = workspace_root().join("target/ci-venv");
            eprintln!(
                "==> {}: a fresh virtual environment in {}",
                step.name,
                venv.display()
            );
            if venv.exists() {
                std::fs::remove_dir_all(&venv)
                    .with_context(|| format!("removing {}", venv.display()))?;
            }
            status(
                Command::new("python3").arg("-m").arg("venv").arg(&venv),
                "python3 -m venv",
            )?;
            let py = venv_python();
            status(
                Command::new(&py).args(["-m", "pip", "install", "-q", "--upgrade", "pip"]),
                "pip install --upgrade pip",
            )?;
            status(
                Command::new(&py).args([
                    "-m", "pip", "install", "-q", "./python", "pytest", "numpy", "meshio",
                ]),
                "pip install ./python pytest numpy meshio",
            )
        }
        Run::PythonTests => {
            eprintln!("==> {}: pytest python/tests", step.name);
            status(
                Command::new(venv_python())
                    .args([
                        "-m",
                        "pytest",
                        "python/tests",
                        "-q",
                        "-p",
                        "no:cacheprovider",
                    ])
                    .env("AGGSIM_BIN_DIR", workspace_root().join("target/debug")),
                "pytest python/tests",
            )
        }
    }
}

/// Runs every step not in `skip`, in order; a step whose needs are missing is skipped with a
/// line saying why.
pub fn run(skip: &[String]) -> Result<()> {
    for name in skip {
        if !STEPS.iter().any(|s| s.name == name) {
            bail!(
                "no CI step named `{name}`; the steps are: {}",
                STEPS.iter().map(|s| s.name).collect::<Vec<_>>().join(", ")
            );
        }
    }
    let start = Instant::now();
    for step in STEPS {
        if skip.iter().any(|s| s == step.name) {
            eprintln!("==> {}: skipped (--skip)", step.name);
            continue;
        }
        if let Some(why) = missing(step.needs) {
            eprintln!("==> {}: skipped: {why}", step.name);
            continue;
        }
        let t = Instant::now();
        run_step(step).with_context(|| format!("CI step `{}`", step.name))?;
        eprintln!(
            "    {} passed in {:.1} s",
            step.name,
            t.elapsed().as_secs_f64()
        );
    }
    eprintln!(
        "==> all CI checks passed in {:.0} s",
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_names_are_unique_and_the_tests_step_is_the_readmes_command() {
        let mut names: Vec<_> = STEPS.iter().map(|s| s.name).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), STEPS.len());
        let readme = std::fs::read_to_string(workspace_root().join("README.md")).unwrap();
        let command = format!("cargo {TEST_ARGS}");
        assert!(
            readme.contains(&format!("{command} ")) || readme.contains(&format!("{command}\n")),
            "README does not give `{command}` as its test command"
        );
    }

    /// `.ci/run` runs this list, and holds no list of its own.
    #[test]
    fn ci_script_runs_cargo_xtask_ci_and_nothing_else_of_cargo() {
        let script = std::fs::read_to_string(workspace_root().join(".ci/run")).unwrap();
        let code: Vec<&str> = script
            .lines()
            .map(str::trim)
            .filter(|l| !l.starts_with('#'))
            .collect();
        let runs_ci = |l: &str| l.starts_with("cargo run") && l.ends_with("--package xtask -- ci");
        assert!(
            code.iter().any(|l| runs_ci(l)),
            ".ci/run does not run xtask's `ci`"
        );
        let other: Vec<&&str> = code
            .iter()
            .filter(|l| (l.starts_with("cargo ") || l.contains(" cargo ")) && !runs_ci(l))
            .collect();
        assert!(
            other.is_empty(),
            ".ci/run runs cargo commands of its own (they belong in xtask/src/ci.rs): {other:?}"
        );
    }
}
