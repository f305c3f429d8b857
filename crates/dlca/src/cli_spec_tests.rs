//! The `dlca` command line and `docs/dlca.md`'s flag tables against the library's parameter
//! declaration ([`dlca::params::PARAMS`]) and defaults: the model's flags are made from the
//! declaration, so this checks that they all reach the command line with the library's defaults
//! and ranges, that the docs' generated table is the declaration's, and that every other flag
//! is a run flag listed in the docs.

use super::Cli;
use clap::CommandFactory;
use dlca::params::{PARAMS, Settings, defaults};
use run_cli::declared::{Plain, docs_table_in};
use run_cli::spec_check::CliSpec;

/// Flags of `dlca` that are not model parameters, beyond the run flags every binary has
/// (`run_cli::spec_check::SHARED_RUN_FLAGS`).
const NOT_PARAMS: &[&str] = &["png", "png-size", "animate", "animate-every"];

fn spec() -> CliSpec<'static> {
    CliSpec::new("dlca", PARAMS, defaults(), NOT_PARAMS)
}

const DOC: &str = include_str!("../../../docs/dlca.md");

#[test]
fn every_parameter_is_a_flag_with_the_library_default_and_choices() {
    spec().check_flags(&Cli::command());
}

#[test]
fn the_docs_parameter_table_is_the_declarations() {
    let table = docs_table_in::<Settings, Plain>();
    spec().check_generated_table("docs/dlca.md", DOC, "dlca-params", &table);
}

#[test]
fn the_docs_list_every_run_flag() {
    let header = &["purpose", "flag", "default", "meaning"];
    spec().check_run_flags_listed(
        "docs/dlca.md",
        DOC,
        "### Run flags",
        header,
        1,
        &Cli::command(),
    );
}
