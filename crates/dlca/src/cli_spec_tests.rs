//! The `dlca` command line and `docs/dlca.md`'s flag tables against the library's parameter
//! declaration ([`dlca::params::PARAMS`]) and defaults: the model's flags are made from the
//! declaration, so this checks that they all reach the command line with the library's defaults
//! and ranges, that the docs' generated table is the declaration's, and that every other flag
//! is a run flag listed in the docs.

use super::Cli;
use clap::CommandFactory;
use core_lattice::spec::markdown_table;
use dlca::params::{PARAMS, Settings, defaults};
use run_cli::declared::{Plain, check_generated, docs_table_in};
use run_cli::spec_check::{CliSpec, DocColumns, flags_of};

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
    check_generated("docs/dlca.md", DOC, "dlca-params", "<!--", &table).unwrap();
    // And it states each default and range as the command line does.
    let rows = markdown_table(&format!("#\n{table}"), "#");
    spec().check_params_table("docs/dlca.md", &rows, DocColumns::new(0, 1, 2), |s, r| {
        r[0] == format!("`--{}`", s.flag.unwrap())
    });
}

#[test]
fn the_docs_list_every_run_flag() {
    let rows = markdown_table(DOC, "### Run flags");
    assert_eq!(rows[0], ["purpose", "flag", "default", "meaning"]);
    let mut listed: Vec<String> = rows[1..].iter().flat_map(|r| flags_of(&r[1])).collect();
    listed.extend(PARAMS.iter().map(|s| format!("--{}", s.flag.unwrap())));
    for a in Cli::command().get_arguments() {
        if let Some(long) = a.get_long().filter(|l| *l != "help") {
            assert!(
                listed.contains(&format!("--{long}")),
                "--{long} is missing from docs/dlca.md's flag tables"
            );
        }
    }
}
