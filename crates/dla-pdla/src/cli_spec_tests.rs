//! The `dla` command line and `docs/dla.md`'s flag tables against the library's parameter
//! declaration ([`dla_pdla::params::PARAMS`]) and defaults: the model's flags are made from the
//! declaration, so this checks that they all reach the command line with the library's defaults
//! and ranges, that the docs' generated table is the declaration's, and that every other flag
//! is a run flag listed in the docs.

use super::Cli;
use clap::CommandFactory;
use dla_pdla::params::{PARAMS, Params, defaults};
use run_cli::declared::docs_table;
use run_cli::spec_check::CliSpec;

/// Flags of `dla` that are not model parameters, beyond the run flags every binary has
/// (`run_cli::spec_check::SHARED_RUN_FLAGS`).
const NOT_PARAMS: &[&str] = &[
    "paper-settings",
    "png",
    "png-size",
    "animate",
    "animate-every",
    "max-memory",
    "no-parents",
];

fn spec() -> CliSpec<'static> {
    CliSpec::new("dla", PARAMS, defaults(), NOT_PARAMS)
}

const DOC: &str = include_str!("../../../docs/dla.md");

#[test]
fn every_parameter_is_a_flag_with_the_library_default_and_choices() {
    spec().check_flags(&Cli::command());
}

#[test]
fn the_docs_parameter_table_is_the_declarations() {
    spec().check_generated_table("docs/dla.md", DOC, "dla-params", &docs_table::<Params>());
}

#[test]
fn the_docs_list_every_run_flag() {
    let header = &["flag", "default", "meaning"];
    spec().check_run_flags_listed(
        "docs/dla.md",
        DOC,
        "### Run flags",
        header,
        0,
        &Cli::command(),
    );
}
