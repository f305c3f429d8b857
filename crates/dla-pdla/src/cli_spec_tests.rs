//! The `dla` command line and `docs/dla.md`'s flag tables against the library's parameter
//! declaration ([`dla_pdla::params::PARAMS`]) and defaults: the model's flags are made from the
//! declaration, so this checks that they all reach the command line with the library's defaults
//! and ranges, that the docs' generated table is the declaration's, and that every other flag
//! is a run flag listed in the docs.

use super::Cli;
use clap::CommandFactory;
use core_lattice::spec::markdown_table;
use dla_pdla::params::{PARAMS, Params, defaults};
use run_cli::declared::{check_generated, docs_table};
use run_cli::spec_check::{CliSpec, DocColumns};

/// Flags of `dla` that are not model parameters, beyond the run flags every binary has
/// (`run_cli::spec_check::SHARED_RUN_FLAGS`).
const NOT_PARAMS: &[&str] = &[
    "paper-settings",
    "png",
    "png-size",
    "animate",
    "animate-every",
    "max-memory",
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
    let table = docs_table::<Params>();
    check_generated("docs/dla.md", DOC, "dla-params", "<!--", &table).unwrap();
    // And it states each default and range as the command line does.
    let rows = markdown_table(&format!("#\n{table}"), "#");
    spec().check_params_table("docs/dla.md", &rows, DocColumns::new(0, 1, 2), |s, r| {
        r[0] == format!("`--{}`", s.flag.unwrap())
    });
}

#[test]
fn the_docs_list_every_run_flag() {
    let rows = markdown_table(DOC, "### Run flags");
    assert_eq!(rows[0], ["flag", "default", "meaning"]);
    let mut listed: Vec<String> = rows[1..]
        .iter()
        .flat_map(|r| run_cli::spec_check::flags_of(&r[0]))
        .collect();
    listed.extend(PARAMS.iter().map(|s| format!("--{}", s.flag.unwrap())));
    for a in Cli::command().get_arguments() {
        if let Some(long) = a.get_long().filter(|l| *l != "help") {
            assert!(
                listed.contains(&format!("--{long}")),
                "--{long} is missing from docs/dla.md's flag tables"
            );
        }
    }
}
