//! The `dlca` command line and `docs/dlca.md`'s flag table against the library's parameter
//! table ([`dlca::params::PARAMS`]) and defaults: a flag missing on either side, another
//! default, other choices or an unstated range fails here.

use super::Cli;
use clap::CommandFactory;
use core_lattice::spec::{Range, markdown_table, same_default};
use dlca::params::{PARAMS, defaults};
use serde_json::Value;

/// Flags of the binary that are not model parameters (run, output and logging flags).
const NOT_PARAMS: &[&str] = &[
    "seed",
    "out",
    "positions",
    "checkpoint-every",
    "resume",
    "png",
    "config",
    "dump-config",
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
fn every_parameter_is_a_flag_with_the_library_default_and_choices() {
    let cmd = Cli::command();
    let defaults = defaults();
    let mut unitless = Vec::new();
    for s in PARAMS {
        let flag = s.flag.expect("every DLCA parameter has a flag");
        let arg = cmd
            .get_arguments()
            .find(|a| a.get_long() == Some(flag))
            .unwrap_or_else(|| panic!("`dlca` has no --{flag} ({})", s.name));
        let library = &defaults[s.name];
        let help = arg.get_long_help().or(arg.get_help()).unwrap().to_string();
        match arg.get_default_values() {
            // A switch (`--gyration`) is off unless given.
            [] if matches!(arg.get_action(), clap::ArgAction::SetTrue) => {
                assert_eq!(
                    library,
                    &Value::Bool(false),
                    "--{flag}: a switch, off by default"
                )
            }
            [v] => assert!(
                same_default(&v.to_string_lossy(), &show(library)),
                "--{flag}: default {v:?} in the CLI, {library} in the library"
            ),
            // No default: required, or none in the library either.
            [] => assert!(
                library.is_null(),
                "--{flag}: no default, {library} in the library"
            ),
            many => panic!("--{flag}: defaults {many:?}"),
        }
        if !help.to_lowercase().contains(s.unit) {
            unitless.push(format!("--{flag} ({})", s.unit));
        }
        if !matches!(s.range, Range::Any | Range::Choices(_)) {
            assert!(
                help.contains(&s.range.to_string()),
                "--{flag}: the help does not state the range {}: {help}",
                s.range
            );
        }
        if let Range::Choices(choices) = s.range {
            let shown: Vec<String> = arg
                .get_possible_values()
                .iter()
                .map(|p| p.get_name().to_string())
                .collect();
            // A free-form list (`--boundary periodic,wall`) names its choices in the help.
            if shown.is_empty() {
                for c in choices {
                    assert!(help.contains(&format!("`{c}`")), "--{flag}: {c}: {help}");
                }
            } else {
                assert_eq!(shown, choices, "--{flag}: possible values");
            }
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
            "--{long} is neither in dlca::params::PARAMS nor a run flag"
        );
    }
}

#[test]
fn help_has_no_rustdoc_markup() {
    let help = Cli::command().render_long_help().to_string();
    assert!(!help.contains("[`"), "{help}");
}

/// The flags a docs table cell names: "`--fill` or `--particles`", "`--config FILE`".
fn flags_of(cell: &str) -> Vec<String> {
    cell.split(", ")
        .flat_map(|c| c.split(" or "))
        .map(|f| {
            f.trim_matches('`')
                .split(' ')
                .next()
                .unwrap_or_default()
                .to_string()
        })
        .collect()
}

#[test]
fn the_docs_flag_table_states_each_default_and_range() {
    let md = include_str!("../../../docs/dlca.md");
    let rows = markdown_table(md, "## Flags by purpose");
    assert_eq!(rows[0], ["purpose", "flag", "default", "meaning"]);
    let cmd = Cli::command();
    let defaults = defaults();
    for s in PARAMS {
        let flag = format!("--{}", s.flag.unwrap());
        let row = rows
            .iter()
            .find(|r| flags_of(&r[1]).contains(&flag))
            .unwrap_or_else(|| panic!("docs/dlca.md has no row for {flag}"));
        let library = &defaults[s.name];
        // A row of one flag states its default (none in the library: any words).
        if flags_of(&row[1]).len() == 1 && !library.is_null() {
            assert!(
                same_default(&row[2], &show(library)),
                "{flag}: default {} in docs/dlca.md, {library} in the library",
                row[2]
            );
        }
        match s.range {
            Range::Any => {}
            Range::Choices(c) => {
                for name in c {
                    assert!(row[3].contains(&format!("`{name}`")), "{flag}: {name}");
                }
            }
            r => assert!(
                row[3].contains(&r.to_string()),
                "{flag}: docs/dlca.md does not state the range {r}: {}",
                row[3]
            ),
        }
    }
    for r in &rows[1..] {
        for f in flags_of(&r[1]) {
            if let Some(long) = f.strip_prefix("--") {
                // `--merge` is read before the parser (`sim_run::ensemble::merge_main`).
                assert!(
                    long == "merge" || cmd.get_arguments().any(|a| a.get_long() == Some(long)),
                    "docs/dlca.md lists {f}, which `dlca` does not have"
                );
            }
        }
    }
}
