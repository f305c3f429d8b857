//! The `dla` command line and `docs/dla.md`'s flag table against the library's parameter table
//! ([`dla_pdla::params::PARAMS`]) and defaults: a flag missing on either side, another
//! default, other choices or an unstated range fails here.

use super::Cli;
use clap::CommandFactory;
use core_lattice::spec::{Range, markdown_table, same_default};
use dla_pdla::params::{PARAMS, defaults};
use serde_json::Value;

/// Flags of the binary that are not model parameters (run, output and logging flags).
const NOT_PARAMS: &[&str] = &[
    "seed",
    "out",
    "paper-settings",
    "positions",
    "checkpoint-every",
    "resume",
    "png",
    "png-size",
    "config",
    "dump-config",
    "quiet",
    "verbose",
    "heartbeat",
    "color",
    "seeds",
    "jobs",
    "merge",
    "help",
    "version",
    "max-memory",
];

/// A library default as the front ends spell it.
fn show(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Array(a) => a.iter().map(show).collect::<Vec<_>>().join(", "),
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
        let flag = s.flag.expect("every DLA parameter has a flag");
        let arg = cmd
            .get_arguments()
            .find(|a| a.get_long() == Some(flag))
            .unwrap_or_else(|| panic!("`dla` has no --{flag} ({})", s.name));
        let library = show(&defaults[s.name]);
        let given = arg.get_default_values();
        let help = arg.get_long_help().or(arg.get_help()).unwrap().to_string();
        match given {
            [v] => assert!(
                same_default(&v.to_string_lossy(), &library),
                "--{flag}: default {v:?} in the CLI, {library} in the library"
            ),
            [] if arg.is_required_set() => {}
            // An optional flag (`--death-ratio`, refused where it is unused) states the
            // library's default in its help.
            [] => {
                let stated = help
                    .split("[default: ")
                    .nth(1)
                    .and_then(|t| t.split(']').next());
                assert!(
                    stated.is_some_and(|d| same_default(d, &library)),
                    "--{flag}: no default in the CLI, {library} in the library: {help}"
                )
            }
            many => panic!("--{flag}: defaults {many:?}"),
        }
        // The help states the accepted range as validation words it.
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
            assert_eq!(shown, choices, "--{flag}: possible values");
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
            "--{long} is neither in dla_pdla::params::PARAMS nor a run flag"
        );
    }
}

#[test]
fn help_has_no_rustdoc_markup() {
    let mut cmd = Cli::command();
    let help = cmd.render_long_help().to_string();
    assert!(!help.contains("[`"), "{help}");
}

#[test]
fn the_docs_flag_table_states_each_default_and_range() {
    let md = include_str!("../../../docs/dla.md");
    let rows = markdown_table(md, "## Parameters (flags; `Params` fields)");
    assert_eq!(rows[0], ["flag", "default", "meaning"]);
    let cmd = Cli::command();
    let defaults = defaults();
    for s in PARAMS {
        let flag = format!("`--{}`", s.flag.unwrap());
        let row = rows
            .iter()
            .find(|r| r[0] == flag)
            .unwrap_or_else(|| panic!("docs/dla.md has no row for {flag}"));
        let library = show(&defaults[s.name]);
        let required = row[1] == "(required)";
        assert!(
            same_default(&row[1], &library) || required,
            "{flag}: default {} in docs/dla.md, {library} in the library",
            row[1]
        );
        match s.range {
            Range::Any => {}
            Range::Choices(c) => {
                for name in c {
                    assert!(row[2].contains(&format!("`{name}`")), "{flag}: {name}");
                }
            }
            r => assert!(
                row[2].contains(&r.to_string()),
                "{flag}: docs/dla.md does not state the range {r}: {}",
                row[2]
            ),
        }
    }
    // Every flag the table lists exists.
    for r in &rows[1..] {
        for f in r[0].split(", ") {
            let f = f.trim_matches('`');
            if let Some(long) = f.strip_prefix("--") {
                // `--merge` is read before the parser (`sim_run::ensemble::merge_main`).
                assert!(
                    long == "merge" || cmd.get_arguments().any(|a| a.get_long() == Some(long)),
                    "docs/dla.md lists {f}, which `dla` does not have"
                );
            }
        }
    }
}
