//! The `animat` command line, its config files and `docs/animat.md`'s parameter table against
//! the library's parameter table ([`animat::params::PARAMS`]) and defaults: a parameter
//! missing on either side, another default or range fails here.

use super::Cli;
use animat::params::{PARAMS, defaults};
use clap::CommandFactory;
use core_lattice::spec::{Range, markdown_table, same_default};
use serde_json::Value;

/// Flags of the binary that are not model parameters (run, output and logging flags).
const NOT_PARAMS: &[&str] = &[
    "steps",
    "seed",
    "out",
    "config",
    "dump-config",
    "timing",
    "max-memory",
    "snapshot-every",
    "positions",
    "checkpoint-every",
    "resume",
    "quiet",
    "verbose",
    "heartbeat",
    "color",
    "seeds",
    "jobs",
    "merge",
    "overwrite",
    "help",
    "version",
];

/// A library default as the front ends spell it.
fn show(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Array(a) => a.iter().map(show).collect::<Vec<_>>().join(","),
        Value::Null => "none".into(),
        other => other.to_string(),
    }
}

#[test]
fn every_flagged_parameter_is_a_flag_stating_its_range() {
    let cmd = Cli::command();
    let mut unitless = Vec::new();
    for s in PARAMS {
        let Some(flag) = s.flag else { continue };
        let arg = cmd
            .get_arguments()
            .find(|a| a.get_long() == Some(flag))
            .unwrap_or_else(|| panic!("`animat` has no --{flag} ({})", s.name));
        // The value comes from the config file or the library unless the flag is given.
        assert!(
            arg.get_default_values().is_empty(),
            "--{flag} has a default"
        );
        let help = arg.get_long_help().or(arg.get_help()).unwrap().to_string();
        if !help.to_lowercase().contains(s.unit) {
            unitless.push(format!("--{flag} ({})", s.unit));
        }
        if !matches!(s.range, Range::Any) {
            assert!(
                help.contains(&s.range.to_string()),
                "--{flag}: the help does not state the range {}: {help}",
                s.range
            );
        }
    }
    assert!(
        unitless.is_empty(),
        "help texts without their unit: {unitless:?}"
    );
    for arg in cmd.get_arguments() {
        let Some(long) = arg.get_long() else { continue };
        assert!(
            NOT_PARAMS.contains(&long) || PARAMS.iter().any(|s| s.flag == Some(long)),
            "--{long} is neither in animat::params::PARAMS nor a run flag"
        );
    }
}

#[test]
fn help_has_no_rustdoc_markup() {
    let help = Cli::command().render_long_help().to_string();
    assert!(!help.contains("[`"), "{help}");
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
    let defaults = defaults();
    for s in PARAMS {
        let name = format!("`{}`", s.name);
        let flag = s.flag.map(|f| format!("`--{f}`")).unwrap_or_default();
        let row = rows
            .iter()
            .find(|r| r[0] == name || (s.flag.is_some() && r[1] == flag))
            .unwrap_or_else(|| panic!("docs/animat.md has no row for {}", s.name));
        assert_eq!(row[1], flag, "{}: the flag", s.name);
        let library = &defaults[s.name];
        if !library.is_null() {
            assert!(
                same_default(&row[2], &show(library)),
                "{}: default {} in docs/animat.md, {library} in the library",
                s.name,
                row[2]
            );
        }
        match s.range {
            Range::Any => {}
            Range::Choices(c) => {
                for n in c {
                    assert!(row.join(" ").contains(n), "{}: {n}", s.name);
                }
            }
            r => assert!(
                row[3].contains(&r.to_string()),
                "{}: docs/animat.md does not state the range {r}: {}",
                s.name,
                row[3]
            ),
        }
    }
    // Every row is a parameter of the table.
    for r in &rows[1..] {
        let known = PARAMS.iter().any(|s| {
            r[0] == format!("`{}`", s.name) || s.flag.is_some_and(|f| r[1] == format!("`--{f}`"))
        });
        assert!(
            known,
            "docs/animat.md lists {} {}, not a parameter",
            r[0], r[1]
        );
    }
}
