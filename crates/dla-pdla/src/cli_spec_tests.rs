//! The `dla` command line and `docs/dla.md`'s flag table against the library's parameter table
//! ([`dla_pdla::params::PARAMS`]) and defaults: a flag missing on either side, another
//! default, other choices or an unstated range fails here.

use super::Cli;
use clap::CommandFactory;
use core_lattice::spec::markdown_table;
use dla_pdla::params::{PARAMS, defaults};
use sim_run::spec_check::{CliSpec, DocColumns};

/// Flags of `dla` that are not model parameters, beyond the run flags every binary has
/// (`sim_run::spec_check::SHARED_RUN_FLAGS`).
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

#[test]
fn every_parameter_is_a_flag_with_the_library_default_and_choices() {
    spec().check_flags(&Cli::command());
}

#[test]
fn the_docs_flag_table_states_each_default_and_range() {
    let md = include_str!("../../../docs/dla.md");
    let rows = markdown_table(md, "## Parameters (flags; `Params` fields)");
    assert_eq!(rows[0], ["flag", "default", "meaning"]);
    let columns = DocColumns::new(0, 1, 2);
    spec().check_docs_table("docs/dla.md", &rows, columns, &Cli::command(), |s, r| {
        r[0] == format!("`--{}`", s.flag.unwrap())
    });
}
