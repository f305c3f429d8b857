//! Checks that a front end agrees with a model's parameter table (features `test-support` and
//! `cli`, for the binaries' tests): the command line (every parameter a flag with the
//! library's default, unit, range and choices; every other flag a known run flag; no rustdoc
//! markup in the help) and the flag table of the model's document. One implementation for the
//! three binaries, each of which states only what differs: its run flags and its table's
//! columns.

use clap::Command;
use core_lattice::spec::{ParamSpec, Range, markdown_table, same_default};
use serde_json::{Map, Value};

/// The flags every binary has that are not model parameters: the run, output, config,
/// logging and ensemble flags of [`crate::cli`] and [`crate::ensemble`], and clap's own.
pub const SHARED_RUN_FLAGS: &[&str] = &[
    "seed",
    "out",
    "positions",
    "checkpoint-every",
    "checkpoint-interval",
    "no-checkpoint",
    "resume",
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

/// A library default as the front ends spell it (lists joined by `, `, `none` for null).
pub fn show(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Array(a) => a.iter().map(show).collect::<Vec<_>>().join(", "),
        Value::Null => "none".into(),
        other => other.to_string(),
    }
}

/// One binary against its model's parameter table.
pub struct CliSpec<'a> {
    /// The binary's name, for messages.
    pub program: &'a str,
    /// The model's parameter table.
    pub params: &'a [ParamSpec],
    /// The library's defaults by parameter name.
    pub defaults: Map<String, Value>,
    /// Long flags of this binary that are not model parameters, beyond [`SHARED_RUN_FLAGS`].
    pub run_flags: &'a [&'a str],
}

impl<'a> CliSpec<'a> {
    /// A binary's name, its model's parameter table and defaults, and its own run flags.
    pub fn new(
        program: &'a str,
        params: &'a [ParamSpec],
        defaults: Map<String, Value>,
        run_flags: &'a [&'a str],
    ) -> Self {
        CliSpec {
            program,
            params,
            defaults,
            run_flags,
        }
    }

    /// The parameter spec of a long flag, if it is a parameter's.
    fn param_of(&self, long: &str) -> Option<&ParamSpec> {
        self.params.iter().find(|s| s.flag == Some(long))
    }

    /// Every parameter with a flag is a flag of `cmd` whose help states its unit and range and
    /// whose possible values are its choices; its default is the library's, as clap's default
    /// or, for a flag without one (its value may come from a config file), stated in its help
    /// as `[default: X]`; every other long flag of `cmd` is a run flag.
    pub fn check_flags(&self, cmd: &Command) {
        let mut unitless = Vec::new();
        for s in self.params {
            let Some(flag) = s.flag else { continue };
            let program = self.program;
            let arg = cmd
                .get_arguments()
                .find(|a| a.get_long() == Some(flag))
                .unwrap_or_else(|| panic!("`{program}` has no --{flag} ({})", s.name));
            let help = arg.get_long_help().or(arg.get_help()).unwrap().to_string();
            let library = &self.defaults[s.name];
            match arg.get_default_values() {
                [v] => assert!(
                    same_default(&v.to_string_lossy(), &show(library)),
                    "--{flag}: default {v:?} in the CLI, {library} in the library"
                ),
                [] => {
                    // A switch is off unless given; a required flag or a library without a
                    // default has none; an optional flag refused where unused states the
                    // library's default in its help.
                    let stated = help
                        .split("[default: ")
                        .nth(1)
                        .and_then(|t| t.split(']').next());
                    let ok = (matches!(arg.get_action(), clap::ArgAction::SetTrue)
                        && library == &Value::Bool(false))
                        || arg.is_required_set()
                        || library.is_null()
                        || stated.is_some_and(|d| same_default(d, &show(library)));
                    assert!(
                        ok,
                        "--{flag}: no default in the CLI, {library} in the library"
                    );
                }
                other => panic!("--{flag}: defaults {other:?} in the CLI"),
            }
            if !help.to_lowercase().contains(s.unit) {
                unitless.push(format!("--{flag} ({})", s.unit));
            }
            match s.range {
                Range::Any => {}
                Range::Choices(choices) => {
                    let shown: Vec<String> = arg
                        .get_possible_values()
                        .iter()
                        .map(|p| p.get_name().to_string())
                        .collect();
                    // A free-form list (`--boundary periodic,wall`) names its choices in the
                    // help instead.
                    if shown.is_empty() {
                        for c in choices {
                            assert!(help.contains(c), "--{flag}: {c} not in the help: {help}");
                        }
                    } else {
                        assert_eq!(shown, choices, "--{flag}: possible values");
                    }
                }
                r => assert!(
                    help.contains(&r.to_string()),
                    "--{flag}: the help does not state the range {r}: {help}"
                ),
            }
        }
        assert!(
            unitless.is_empty(),
            "help texts without their unit: {unitless:?}"
        );
        for arg in cmd.get_arguments() {
            let Some(long) = arg.get_long() else { continue };
            assert!(
                SHARED_RUN_FLAGS.contains(&long)
                    || self.run_flags.contains(&long)
                    || self.param_of(long).is_some(),
                "--{long} of `{}` is neither a parameter of the library's table nor a run flag",
                self.program
            );
        }
        let help = cmd.clone().render_long_help().to_string();
        assert!(
            !help.contains("[`") && !help.contains("crate::"),
            "rustdoc markup in the help: {help}"
        );
        let foreign = foreign_flags(cmd, &help);
        assert!(
            foreign.is_empty(),
            "`{} --help` names flags it does not have (another model's?): {foreign:?}",
            self.program
        );
    }

    /// A docs table (`rows`, header first, as `core_lattice::spec::markdown_table` reads it)
    /// against the table: for each parameter, the row `find_row` picks states the library's
    /// default in column `default` (unless the row names several flags or the library has no
    /// default) and the range or choices in column `range`; every flag the column `flags`
    /// names exists in `cmd`, and every long flag of `cmd` is in that column of some row.
    /// `doc` names the file in messages.
    pub fn check_docs_table(
        &self,
        doc: &str,
        rows: &[Vec<String>],
        columns: DocColumns,
        cmd: &Command,
        find_row: impl Fn(&ParamSpec, &[String]) -> bool,
    ) {
        self.check_params_table(doc, rows, columns, find_row);
        self.check_listed_flags(doc, rows, columns, cmd);
    }

    /// The parameter half of [`check_docs_table`](Self::check_docs_table): each parameter's
    /// row states the library's default and the range or choices.
    pub fn check_params_table(
        &self,
        doc: &str,
        rows: &[Vec<String>],
        columns: DocColumns,
        find_row: impl Fn(&ParamSpec, &[String]) -> bool,
    ) {
        for s in self.params {
            let row = rows[1..]
                .iter()
                .find(|r| find_row(s, r))
                .unwrap_or_else(|| panic!("{doc} has no row for {}", s.name));
            let library = &self.defaults[s.name];
            let one_flag = flags_of(&row[columns.flags]).len() <= 1;
            let cell = &row[columns.default];
            if one_flag && !library.is_null() && cell != "(required)" {
                assert!(
                    same_default(cell, &show(library)),
                    "{}: default {cell} in {doc}, {library} in the library",
                    s.name
                );
            }
            match s.range {
                Range::Any => {}
                Range::Choices(c) => {
                    let line = row.join(" ");
                    for name in c {
                        assert!(line.contains(name), "{}: {name} not in {doc}", s.name);
                    }
                }
                r => assert!(
                    row[columns.range].contains(&r.to_string()),
                    "{}: {doc} does not state the range {r}: {}",
                    s.name,
                    row[columns.range]
                ),
            }
        }
    }

    /// The generated parameter table of a model's document: `doc` (the document's text,
    /// `path` its name in messages) holds `table` (from the declaration, as
    /// [`crate::declared::docs_table`] makes it) between the marker lines of block `block`, and
    /// that table states each parameter's default and range as the command line does (its
    /// columns: flag, default, meaning).
    pub fn check_generated_table(&self, path: &str, doc: &str, block: &str, table: &str) {
        crate::declared::check_generated(path, doc, block, "<!--", table).unwrap();
        let rows = markdown_table(&format!("#\n{table}"), "#");
        self.check_params_table(path, &rows, DocColumns::new(0, 1, 2), |s, r| {
            s.flag.is_some_and(|f| r[0] == format!("`--{f}`"))
        });
    }

    /// Every long flag of `cmd` (but `--help`) is a parameter's or is named in the table of
    /// run flags of a model's document `doc` (`path` its name in messages): the table under
    /// the line `heading`, whose header row is `header` and whose column `flags` names the
    /// flags.
    pub fn check_run_flags_listed(
        &self,
        path: &str,
        doc: &str,
        heading: &str,
        header: &[&str],
        flags: usize,
        cmd: &Command,
    ) {
        let rows = markdown_table(doc, heading);
        assert_eq!(rows[0], header, "{path}: the header of {heading}");
        let mut listed: Vec<String> = rows[1..].iter().flat_map(|r| flags_of(&r[flags])).collect();
        listed.extend(
            self.params
                .iter()
                .filter_map(|s| s.flag.map(|f| format!("--{f}"))),
        );
        for a in cmd.get_arguments() {
            if let Some(long) = a.get_long().filter(|l| *l != "help") {
                assert!(
                    listed.contains(&format!("--{long}")),
                    "--{long} is missing from {path}'s flag tables"
                );
            }
        }
    }

    /// The flag half of [`check_docs_table`](Self::check_docs_table): every flag the table
    /// names exists in `cmd`, and every long flag of `cmd` is in the table.
    fn check_listed_flags(
        &self,
        doc: &str,
        rows: &[Vec<String>],
        columns: DocColumns,
        cmd: &Command,
    ) {
        let listed: Vec<String> = rows[1..]
            .iter()
            .flat_map(|r| flags_of(&r[columns.flags]))
            .collect();
        for f in &listed {
            if let Some(long) = f.strip_prefix("--") {
                assert!(
                    cmd.get_arguments().any(|a| a.get_long() == Some(long)),
                    "{doc} lists {f}, which `{}` does not have",
                    self.program
                );
            }
        }
        let unlisted: Vec<&str> = cmd
            .get_arguments()
            .filter_map(|a| a.get_long())
            .filter(|long| *long != "help" && !listed.contains(&format!("--{long}")))
            .collect();
        assert!(
            unlisted.is_empty(),
            "flags of `{}` missing from {doc}'s option list: {unlisted:?}",
            self.program
        );
    }
}

/// Which columns of a docs table hold the flags, the default and the accepted range.
#[derive(Debug, Clone, Copy)]
pub struct DocColumns {
    /// The flag or flags (`--fill` or `--particles`).
    pub flags: usize,
    /// The default.
    pub default: usize,
    /// The meaning or accepted range, which states the range.
    pub range: usize,
}

impl DocColumns {
    /// The columns of the flags, the default and the range, in that order.
    pub const fn new(flags: usize, default: usize, range: usize) -> Self {
        DocColumns {
            flags,
            default,
            range,
        }
    }
}

/// The flags a docs table cell names: "`--fill` or `--particles`", "`--config FILE`".
pub fn flags_of(cell: &str) -> Vec<String> {
    cell.split(", ")
        .flat_map(|c| c.split(" or "))
        .map(|f| {
            f.trim_matches('`')
                .split(' ')
                .next()
                .unwrap_or_default()
                .to_string()
        })
        .filter(|f| !f.is_empty())
        .collect()
}

/// The flags `help` names that are not long flags of `cmd`, written `--flag` or as a config
/// key in backquotes (`` `flag = 1` ``): a help text that names another model's flag (or a
/// renamed one) misleads whoever follows it.
pub fn foreign_flags(cmd: &Command, help: &str) -> Vec<String> {
    // clap adds --help and --version when it builds the command.
    let own: Vec<String> = cmd
        .get_arguments()
        .filter_map(|a| a.get_long())
        .chain(["help", "version"])
        .map(str::to_string)
        .collect();
    let name_at = |rest: &str| -> String {
        let name: String = rest
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '-' || *c == '_')
            .collect();
        name.trim_end_matches(['-', '_']).replace('_', "-")
    };
    let dashed = help.split("--").skip(1).map(name_at);
    let keys = help.split('`').skip(1).filter_map(|rest| {
        let name = name_at(rest);
        rest[name.len()..].starts_with(" = ").then_some(name)
    });
    let mut foreign: Vec<String> = dashed
        .chain(keys)
        .filter(|n| n.starts_with(|c: char| c.is_ascii_lowercase()) && !own.contains(n))
        .collect();
    foreign.sort();
    foreign.dedup();
    foreign
}

#[cfg(test)]
mod tests {
    use super::foreign_flags;
    use clap::{Arg, Command};

    #[test]
    fn foreign_flags_are_found_as_flags_and_as_config_keys() {
        let cmd = Command::new("m")
            .arg(Arg::new("size").long("size"))
            .arg(Arg::new("fill").long("fill"));
        let help = "Use --size and --fill, `size = 4` or `step-min = 0.1`; see --particles. \
                    Also -q, -- and --help.";
        assert_eq!(foreign_flags(&cmd, help), ["particles", "step-min"]);
    }
}
