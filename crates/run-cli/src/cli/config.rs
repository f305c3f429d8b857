//! Config files keyed by a binary's own long flags (`dla`, `dlca`): `--config FILE.toml` reads
//! `particles = 1000000`, `step-min = 0.1`, `png = true`, ... as if they were flags given
//! before the command line's, so flags on the command line win; `--dump-config` prints the
//! effective configuration (every flag with its value, defaults included) and each run saves
//! it as `OUT/config.toml`, so `--config OUT/config.toml --out NEW` repeats the run.
//!
//! Keys may be written with dashes or underscores. Flags that say where or how a process runs
//! rather than what it computes (`--out`, `--resume`, `--seeds`, `--jobs`, logging,
//! `--checkpoint-interval`, `--no-checkpoint`) are not
//! config keys. An unknown key, a key that is not allowed or a value of the wrong kind is a
//! usage error naming the file and the line.

use crate::declared::key_line;
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The flags `--config` and `--dump-config`, flattened into a binary's flags.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ConfigArgs {
    /// TOML file of flags, one NAME = VALUE per line with the long flag's name (--dump-config
    /// prints every one): read as if given before the command line's flags, which win. A run saves its own
    /// as OUT/config.toml, so `--config OUT/config.toml` repeats it.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,

    /// Print the effective configuration (every flag's value, defaults included, as TOML for
    /// --config) and exit without running.
    #[arg(long)]
    pub dump_config: bool,
}

/// Argument ids that are never config keys: where and how the process runs, not what it
/// computes.
const NOT_CONFIG: [&str; 16] = [
    "help",
    "checkpoint_interval",
    "no_checkpoint",
    "overwrite",
    "version",
    "out",
    "resume",
    "seeds",
    "jobs",
    "config",
    "dump_config",
    "quiet",
    "verbose",
    "heartbeat",
    "color",
    "merge",
];

/// The effective configuration of the run being parsed, kept for [`save`].
static EFFECTIVE: OnceLock<String> = OnceLock::new();

/// Argument ids given on the command line or by the config file (not defaults), kept for
/// [`given`].
static GIVEN: OnceLock<Vec<String>> = OnceLock::new();

/// Whether the flag with argument id `id` (`max_memory`) was given, on the command line or in
/// the `--config` file, rather than left at its default; false if the binary did not parse
/// with [`parse_with_config`].
pub fn given(id: &str) -> bool {
    GIVEN.get().is_some_and(|g| g.iter().any(|x| x == id))
}

fn config_path(args: &[OsString]) -> Result<Option<(usize, usize, PathBuf)>, String> {
    for (i, a) in args.iter().enumerate() {
        let s = a.to_string_lossy();
        if s == "--config" {
            return match args.get(i + 1) {
                Some(p) => Ok(Some((i, 2, PathBuf::from(p)))),
                None => Err("--config needs a FILE".into()),
            };
        }
        if let Some(p) = s.strip_prefix("--config=") {
            return Ok(Some((i, 1, PathBuf::from(p))));
        }
        if s == "--" {
            break;
        }
    }
    Ok(None)
}

/// The config arguments of `cmd` by long name (dashes), with whether each is a plain switch.
fn keys(cmd: &clap::Command) -> Vec<(String, String, bool)> {
    cmd.get_arguments()
        .filter(|a| !NOT_CONFIG.contains(&a.get_id().as_str()))
        .filter_map(|a| {
            let long = a.get_long()?;
            let switch = matches!(a.get_action(), clap::ArgAction::SetTrue);
            Some((a.get_id().to_string(), long.to_string(), switch))
        })
        .collect()
}

fn line_of(text: &str, span: Option<std::ops::Range<usize>>) -> usize {
    span.map_or(0, |s| {
        text[..s.start.min(text.len())].matches('\n').count() + 1
    })
}

/// `args` with the flags `--config FILE` stands for put first, right after the program name,
/// so every flag on the command line wins over the file. `args` starts with the program name.
///
/// # Errors
/// One line naming the file and, where known, the line: unreadable, malformed TOML, an unknown
/// or excluded key, or a value that is not a string, number, boolean or array of them.
pub fn expand(cmd: &clap::Command, args: Vec<OsString>) -> Result<Vec<OsString>, String> {
    let Some((at, width, path)) = config_path(&args)? else {
        return Ok(args);
    };
    let shown = path.display();
    let text = std::fs::read_to_string(&path)
        .map_err(|e| format!("--config {shown}: cannot read it: {e}"))?;
    let table: toml::Table = toml::from_str(&text).map_err(|e| {
        let msg = e.message().split_whitespace().collect::<Vec<_>>().join(" ");
        format!("--config {shown}, line {}: {msg}", line_of(&text, e.span()))
    })?;
    let known = keys(cmd);
    // A key that conflicts with a flag on the command line gives way to it (`seed` in the file
    // and `--seeds` on the command line: the ensemble's members get their own seeds).
    let given: Vec<&clap::Arg> = args[1..]
        .iter()
        .filter_map(|a| {
            let s = a.to_str()?.strip_prefix("--")?;
            let name = s.split('=').next()?;
            cmd.get_arguments().find(|x| x.get_long() == Some(name))
        })
        .collect();
    let overruled = |id: &str| {
        cmd.get_arguments()
            .find(|a| a.get_id() == id)
            .is_some_and(|a| {
                cmd.get_arg_conflicts_with(a)
                    .iter()
                    .any(|c| given.iter().any(|g| g.get_id() == c.get_id()))
                    || given.iter().any(|g| {
                        cmd.get_arg_conflicts_with(g)
                            .iter()
                            .any(|c| c.get_id() == id)
                    })
            })
    };
    let mut flags = Vec::new();
    // The file's keys in their order in the file, so an error names the first bad one.
    let mut entries: Vec<(&String, &toml::Value)> = table.iter().collect();
    entries.sort_by_key(|(k, _)| key_line(&text, k));
    for (key, value) in entries {
        let line = key_line(&text, key);
        let dashed = key.replace('_', "-");
        let Some((id, long, switch)) = known.iter().find(|(_, l, _)| *l == dashed) else {
            let excluded = NOT_CONFIG.contains(&key.replace('-', "_").as_str());
            return Err(if excluded {
                format!(
                    "--config {shown}, line {line}: `{key}` is not a config key (give --{dashed} on the command line)"
                )
            } else {
                format!(
                    "--config {shown}, line {line}: unknown key `{key}`; the keys are the long flags: {}",
                    known
                        .iter()
                        .map(|(_, l, _)| l.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            });
        };
        if overruled(id) {
            continue;
        }
        let scalar = |v: &toml::Value| -> Result<String, String> {
            match v {
                toml::Value::String(s) => Ok(s.clone()),
                toml::Value::Integer(i) => Ok(i.to_string()),
                toml::Value::Float(f) => Ok(f.to_string()),
                toml::Value::Boolean(b) => Ok(b.to_string()),
                _ => Err(format!(
                    "--config {shown}, line {line}: `{key}` must be a string, number or boolean"
                )),
            }
        };
        match (value, switch) {
            (toml::Value::Boolean(true), true) => flags.push(format!("--{long}")),
            (toml::Value::Boolean(false), true) => {}
            (_, true) => {
                return Err(format!(
                    "--config {shown}, line {line}: `{key}` is a switch: true or false"
                ));
            }
            (toml::Value::Array(items), false) => {
                let parts = items.iter().map(scalar).collect::<Result<Vec<_>, _>>()?;
                flags.push(format!("--{long}={}", parts.join(",")));
            }
            (v, false) => flags.push(format!("--{long}={}", scalar(v)?)),
        }
    }
    let mut out: Vec<OsString> = args[..1].to_vec();
    out.extend(flags.into_iter().map(OsString::from));
    out.extend(args[1..at].iter().cloned());
    out.extend(args[at + width..].iter().cloned());
    Ok(out)
}

/// The effective configuration of parsed `matches` as TOML, in the order of `cmd`'s flags:
/// the flags that were given (on the command line or by a config file) as keys, and every other
/// flag's default as a comment, so the file both repeats the run and shows every value it used
/// (a default given explicitly could trip a flag's `requires`). Numbers stay numbers, switches
/// booleans.
pub fn effective(cmd: &clap::Command, matches: &clap::ArgMatches) -> String {
    let mut text = String::from(
        "# The configuration of a run: the flags it was given, and every default as a comment.\n\
         # Repeat the run with `--config config.toml --out DIR`; flags on the command line win.\n",
    );
    for (id, long, switch) in keys(cmd) {
        let value = if switch {
            toml::Value::Boolean(matches.get_flag(&id))
        } else {
            let Some(raw) = matches.get_raw(&id) else {
                continue;
            };
            let values: Vec<toml::Value> = raw.map(|v| toml_value(&v.to_string_lossy())).collect();
            match <[toml::Value; 1]>::try_from(values) {
                Ok([one]) => one,
                Err(many) => toml::Value::Array(many),
            }
        };
        let given = matches!(
            matches.value_source(&id),
            Some(clap::parser::ValueSource::CommandLine | clap::parser::ValueSource::EnvVariable)
        );
        let mut one = toml::Table::new();
        one.insert(long, value);
        let line = toml::to_string(&one).unwrap_or_default();
        if given {
            text.push_str(&line);
        } else {
            text.push_str("# ");
            text.push_str(line.trim_end());
            text.push_str("  (default)\n");
        }
    }
    text
}

/// A flag's value as `config.toml` writes it: whole numbers as integers, also where they were
/// typed as physicists write counts (`1e6`, `1_000_000`), so that the file shows
/// `particles = 1000000`; other finite numbers as floats (`0.1`, `5.0` as typed); words such as
/// `inf` or `1..=10` as strings. Every value reads back to the flag's own value.
fn toml_value(s: &str) -> toml::Value {
    if let Ok(i) = s.parse::<i64>() {
        return toml::Value::Integer(i);
    }
    let digits = s.strip_prefix(['-', '+']).unwrap_or(s);
    let grouped = digits.contains('_')
        && !digits.starts_with('_')
        && !digits.ends_with('_')
        && digits.chars().all(|c| c.is_ascii_digit() || c == '_');
    if grouped && let Ok(i) = s.replace('_', "").parse::<i64>() {
        return toml::Value::Integer(i);
    }
    match s.parse::<f64>() {
        // 2^53: every whole float up to it is an exact integer.
        Ok(f)
            if s.contains(['e', 'E']) && f.fract() == 0.0 && f.abs() <= 9_007_199_254_740_992.0 =>
        {
            toml::Value::Integer(f as i64)
        }
        Ok(f) if f.is_finite() => toml::Value::Float(f),
        _ => toml::Value::String(s.to_owned()),
    }
}

/// Parses the command line of `C` with `--config` expanded (flags given more than once: the
/// last wins, so the command line overrides the file), remembers the effective configuration
/// for [`save`], and prints it and exits on `--dump-config`. Errors are one line, as in
/// [`super::parse_or_exit`].
pub fn parse_with_config<C: clap::Parser>(program: &str) -> Result<C, std::process::ExitCode> {
    let mut cmd = C::command().args_override_self(true);
    let args: Vec<OsString> = std::env::args_os().collect();
    let dumping = args.iter().any(|a| a == "--dump-config");
    if dumping {
        // Printing the configuration needs no output directory or other required flag.
        cmd = cmd.mut_args(|a| a.required(false));
        let groups: Vec<clap::Id> = cmd.get_groups().map(|g| g.get_id().clone()).collect();
        for g in groups {
            cmd = cmd.mut_group(g, |g| g.required(false));
        }
    }
    let args = match expand(&cmd, args) {
        Ok(a) => a,
        Err(msg) => return Err(super::usage_error(program, &msg)),
    };
    let matches = match cmd.clone().try_get_matches_from(args) {
        Ok(m) => m,
        Err(e) => return Err(super::clap_error(program, e)),
    };
    let text = effective(&cmd, &matches);
    if dumping {
        print!("{text}");
        return Err(std::process::ExitCode::SUCCESS);
    }
    let cli = match <C as clap::FromArgMatches>::from_arg_matches(&matches) {
        Ok(c) => c,
        Err(e) => return Err(super::clap_error(program, e)),
    };
    let _ = EFFECTIVE.set(text);
    let _ = GIVEN.set(
        matches
            .ids()
            .filter(|id| {
                matches!(
                    matches.value_source(id.as_str()),
                    Some(
                        clap::parser::ValueSource::CommandLine
                            | clap::parser::ValueSource::EnvVariable
                    )
                )
            })
            .map(|id| id.to_string())
            .collect(),
    );
    Ok(cli)
}

/// The effective configuration of this run (from [`parse_with_config`]), as saved by [`save`].
pub fn effective_text() -> Option<&'static str> {
    EFFECTIVE.get().map(String::as_str)
}

/// Writes the effective configuration of this run (from [`parse_with_config`]) as
/// `dir/config.toml`, atomically; nothing if the binary did not parse with it.
///
/// # Errors
/// The file cannot be written.
pub fn save(dir: &Path) -> std::io::Result<()> {
    match EFFECTIVE.get() {
        Some(text) => run_io::write_atomic(dir.join("config.toml"), text.as_bytes()),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::{CommandFactory, Parser};

    #[derive(Parser, Debug)]
    struct T {
        #[arg(long, default_value_t = 10, value_parser = crate::cli::count::<u64>)]
        particles: u64,
        #[arg(long, default_value_t = 0.5)]
        step_min: f64,
        #[arg(long)]
        size: Option<String>,
        #[arg(long)]
        png: bool,
        #[arg(long, value_delimiter = ',')]
        sweeps: Vec<u64>,
        #[arg(long)]
        out: Option<PathBuf>,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        #[arg(long, conflicts_with = "seed")]
        seeds: Option<String>,
        #[command(flatten)]
        config: ConfigArgs,
    }

    fn parse(args: &[&str], file: &str) -> Result<(T, String), String> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.toml");
        std::fs::write(&path, file).unwrap();
        let mut all: Vec<OsString> = vec!["t".into()];
        for a in args {
            all.push(a.replace("FILE", path.to_str().unwrap()).into());
        }
        let cmd = T::command().args_override_self(true);
        let expanded = expand(&cmd, all)?;
        let m = cmd
            .clone()
            .try_get_matches_from(expanded)
            .map_err(|e| e.to_string())?;
        let t = <T as clap::FromArgMatches>::from_arg_matches(&m).map_err(|e| e.to_string())?;
        Ok((t, effective(&cmd, &m)))
    }

    #[test]
    fn the_file_sets_flags_and_the_command_line_wins() {
        let file =
            "particles = 500\nstep_min = 0.1\npng = true\nsize = \"64x32\"\nsweeps = [1, 5]\n";
        let (t, _) = parse(&["--config", "FILE"], file).unwrap();
        assert_eq!((t.particles, t.step_min, t.png), (500, 0.1, true));
        assert_eq!(
            (t.size.as_deref(), t.sweeps.as_slice()),
            (Some("64x32"), &[1, 5][..])
        );
        let (t, _) = parse(&["--config", "FILE", "--particles", "7"], file).unwrap();
        assert_eq!(t.particles, 7);
        // Before --config too: the file's flags go first, so the command line always wins.
        let (t, _) = parse(&["--particles", "7", "--config=FILE"], file).unwrap();
        assert_eq!(t.particles, 7);
    }

    #[test]
    fn a_key_gives_way_to_a_conflicting_flag() {
        let (t, _) = parse(&["--config", "FILE", "--seeds", "1..=4"], "seed = 9\n").unwrap();
        assert_eq!(t.seeds.as_deref(), Some("1..=4"));
        let (t, _) = parse(&["--config", "FILE"], "seed = 9\n").unwrap();
        assert_eq!(t.seed, 9);
    }

    #[test]
    fn the_effective_configuration_round_trips() {
        let (t, text) = parse(&["--particles", "42", "--png", "--sweeps", "3,4"], "").unwrap();
        assert!(
            text.contains("particles = 42") && text.contains("step-min = 0.5"),
            "{text}"
        );
        assert!(
            !text.contains("\nout =") && !text.contains("config ="),
            "{text}"
        );
        let (u, again) = parse(&["--config", "FILE"], &text).unwrap();
        assert_eq!(
            (u.particles, u.step_min, u.png, u.sweeps),
            (t.particles, t.step_min, t.png, t.sweeps)
        );
        assert_eq!(text, again);
    }

    #[test]
    fn counts_as_typed_are_written_as_integers() {
        for (typed, written) in [
            ("1e6", "particles = 1000000\n"),
            ("2.5e5", "particles = 250000\n"),
            ("1_000_000", "particles = 1000000\n"),
            ("42", "particles = 42\n"),
        ] {
            let (t, text) = parse(&["--particles", typed], "").unwrap();
            assert!(text.contains(written), "{typed}: {text}");
            let (u, again) = parse(&["--config", "FILE"], &text).unwrap();
            assert_eq!((u.particles, &again), (t.particles, &text));
        }
        // Other numbers as typed, words as strings; all read back.
        let (t, text) = parse(&["--step-min", "1e-1", "--size", "1..=10"], "").unwrap();
        assert!(
            text.contains("step-min = 0.1\n") && text.contains("size = \"1..=10\"\n"),
            "{text}"
        );
        let (u, _) = parse(&["--config", "FILE"], &text).unwrap();
        assert_eq!((u.step_min, u.size), (t.step_min, t.size));
        assert_eq!(toml_value("5.0"), toml::Value::Float(5.0));
        assert_eq!(toml_value("inf"), toml::Value::String("inf".into()));
        assert_eq!(toml_value("1e30"), toml::Value::Float(1e30));
        assert_eq!(toml_value("_1"), toml::Value::String("_1".into()));
        assert_eq!(toml_value("-1_0"), toml::Value::Integer(-10));
    }

    #[test]
    fn bad_files_name_the_file_and_line() {
        let e = parse(&["--config", "FILE"], "particles = 5\nwalkers = 3\n").unwrap_err();
        assert!(
            e.contains("line 2") && e.contains("unknown key `walkers`"),
            "{e}"
        );
        let e = parse(&["--config", "FILE"], "out = \"x\"\n").unwrap_err();
        assert!(e.contains("not a config key"), "{e}");
        let e = parse(&["--config", "FILE"], "png = 3\n").unwrap_err();
        assert!(e.contains("switch"), "{e}");
        let e = parse(&["--config", "FILE"], "particles = [\n").unwrap_err();
        assert!(e.contains("line"), "{e}");
        let e = parse(&["--config", "FILE"], "particles = \"many\"\n").unwrap_err();
        assert!(e.contains("many"), "{e}");
        let e = parse(&["--config", "/nonexistent/c.toml"], "").unwrap_err();
        assert!(e.contains("cannot read"), "{e}");
    }
}
