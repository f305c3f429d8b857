//! The `animat` command line, its config files and `docs/animat.md`'s flag tables against the
//! library's parameter declaration ([`animat::params::PARAMS`]) and defaults: the model's flags
//! are made from the declaration, so this checks that they all reach the command line with the
//! library's defaults and ranges, that the docs' generated table is the declaration's, and that
//! every other flag is a run flag listed in the docs.

use super::Cli;
use animat::params::{PARAMS, Params, defaults};
use clap::CommandFactory;
use run_cli::declared::docs_table;
use run_cli::spec_check::CliSpec;

/// Flags of `animat` that are not model parameters, beyond the run flags every binary has
/// (`run_cli::spec_check::SHARED_RUN_FLAGS`).
const NOT_PARAMS: &[&str] = &[
    "steps",
    "density",
    "timing",
    "max-memory",
    "snapshot-every",
    "frame-radius",
    "png-size",
    "animate",
    "animate-every",
];

fn spec() -> CliSpec<'static> {
    CliSpec::new("animat", PARAMS, defaults(), NOT_PARAMS)
}

const DOC: &str = include_str!("../../../docs/animat.md");

#[test]
fn every_parameter_is_a_flag_with_the_library_default_and_range() {
    spec().check_flags(&Cli::command());
}

/// The config file the repository ships spells out every parameter with its default.
#[test]
fn the_default_config_file_has_every_parameter() {
    let toml = include_str!("../../../data/animat-default.toml");
    for s in PARAMS {
        let key = format!("{} =", s.name);
        assert!(
            toml.lines().any(|l| l.starts_with(&key)),
            "data/animat-default.toml has no {}",
            s.name
        );
    }
}

#[test]
fn the_docs_parameter_table_is_the_declarations() {
    spec().check_generated_table(
        "docs/animat.md",
        DOC,
        "animat-params",
        &docs_table::<Params>(),
    );
}

#[test]
fn the_docs_list_every_run_flag() {
    let header = &["flag", "default", "meaning"];
    spec().check_run_flags_listed(
        "docs/animat.md",
        DOC,
        "## Run flags",
        header,
        0,
        &Cli::command(),
    );
}
