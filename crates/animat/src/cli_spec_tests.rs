//! The `animat` command line, its config files and `docs/animat.md`'s parameter table against
//! the library's parameter table ([`animat::params::PARAMS`]) and defaults: a parameter
//! missing on either side, another default or range fails here.

use super::Cli;
use animat::params::{PARAMS, defaults};
use clap::CommandFactory;
use core_lattice::spec::markdown_table;
use sim_run::spec_check::{CliSpec, DocColumns};

/// Flags of `animat` that are not model parameters, beyond the run flags every binary has
/// (`sim_run::spec_check::SHARED_RUN_FLAGS`).
const NOT_PARAMS: &[&str] = &[
    "steps",
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

/// The flags have no clap defaults (the value comes from the config file or the library unless
/// the flag is given), so each help text states the library's default as `[default: X]`.
#[test]
fn every_flagged_parameter_is_a_flag_stating_its_range() {
    spec().check_flags(&Cli::command());
}

/// The config file the repository ships spells out every parameter with its default.
#[test]
fn the_default_config_file_has_every_parameter() {
    let toml = include_str!("../../../data/animat-default.toml");
    for s in PARAMS {
        let key = format!("{} =", s.name);
        assert!(
            s.flag == Some("density") || toml.lines().any(|l| l.starts_with(&key)),
            "data/animat-default.toml has no {}",
            s.name
        );
    }
}

#[test]
fn the_docs_table_states_each_default_and_range() {
    let md = include_str!("../../../docs/animat.md");
    let rows = markdown_table(md, "## Parameters and defaults");
    assert_eq!(rows[0], ["parameter", "flag", "default", "accepted"]);
    let columns = DocColumns::new(1, 2, 3);
    let row_of = |s: &core_lattice::spec::ParamSpec, r: &[String]| {
        r[0] == format!("`{}`", s.name) || s.flag.is_some_and(|f| r[1] == format!("`--{f}`"))
    };
    // The option list is both tables: the model's parameters and, laid out as parameter rows
    // without a parameter name, the run flags.
    let run_flags = markdown_table(md, "## Run flags");
    assert_eq!(run_flags[0], ["flag", "default", "meaning"]);
    let options: Vec<Vec<String>> = rows
        .iter()
        .cloned()
        .chain(run_flags[1..].iter().map(|r| {
            let mut row = vec![String::new()];
            row.extend(r.iter().cloned());
            row
        }))
        .collect();
    spec().check_docs_table("docs/animat.md", &options, columns, &Cli::command(), row_of);
    for s in PARAMS {
        let row = rows.iter().find(|r| row_of(s, r)).unwrap();
        let flag = s.flag.map(|f| format!("`--{f}`")).unwrap_or_default();
        assert_eq!(row[1], flag, "{}: the flag", s.name);
    }
    // Every row is a parameter of the table.
    for r in &rows[1..] {
        assert!(
            PARAMS.iter().any(|s| row_of(s, r)),
            "docs/animat.md lists {} {}, not a parameter",
            r[0],
            r[1]
        );
    }
}
