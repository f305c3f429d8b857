//! The `dlca` command line and `docs/dlca.md`'s flag table against the library's parameter
//! table ([`dlca::params::PARAMS`]) and defaults: a flag missing on either side, another
//! default, other choices or an unstated range fails here.

use super::Cli;
use clap::CommandFactory;
use core_lattice::spec::markdown_table;
use dlca::params::{PARAMS, defaults};
use sim_run::spec_check::{CliSpec, DocColumns, flags_of};

/// Flags of `dlca` that are not model parameters, beyond the run flags every binary has
/// (`sim_run::spec_check::SHARED_RUN_FLAGS`).
const NOT_PARAMS: &[&str] = &["png", "png-size", "animate", "animate-every"];

fn spec() -> CliSpec<'static> {
    CliSpec::new("dlca", PARAMS, defaults(), NOT_PARAMS)
}

#[test]
fn every_parameter_is_a_flag_with_the_library_default_and_choices() {
    spec().check_flags(&Cli::command());
}

#[test]
fn the_docs_flag_table_states_each_default_and_range() {
    let md = include_str!("../../../docs/dlca.md");
    let rows = markdown_table(md, "## Flags by purpose");
    assert_eq!(rows[0], ["purpose", "flag", "default", "meaning"]);
    let columns = DocColumns::new(1, 2, 3);
    spec().check_docs_table("docs/dlca.md", &rows, columns, &Cli::command(), |s, r| {
        flags_of(&r[1]).contains(&format!("--{}", s.flag.unwrap()))
    });
}
