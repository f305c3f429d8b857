//! Descriptions of model parameters: one table per model, declared beside its `Params`, from
//! which the front ends (the binaries' flags, the Python keyword arguments and stubs, the docs'
//! flag tables) are derived or against which their tests check them (`docs/architecture.md`,
//! "Parameters: one declaration").
//!
//! A [`ParamSpec`] says what a parameter is called (its `Params` field or keyword name and its
//! flag), what it means, its unit and its accepted [`Range`]. Defaults are not repeated here:
//! they come from the model's `Params::default()`. This module has no dependencies, so every
//! front end can use it.

use std::fmt;

mod declare;
mod value;
#[cfg(feature = "serde")]
pub use declare::as_text;
pub use declare::{
    Declared, DeclaredParams, Input, Kind, ParamValue, RangeError, first_sentence, help_text,
    spec_table, trim_doc,
};

/// One model parameter as the front ends see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamSpec {
    /// Name of the `Params` field, config-file key and Python keyword argument (`step_min`).
    pub name: &'static str,
    /// The command-line flag without its dashes (`step-min`), if the binary has one; `None`
    /// for parameters set only in config files.
    pub flag: Option<&'static str>,
    /// Unit of the value (`diameters`, `sites`, `bytes`), empty for pure numbers and names.
    pub unit: &'static str,
    /// What the parameter means, one plain-text sentence (no markup).
    pub doc: &'static str,
    /// Values accepted by the model's validation.
    pub range: Range,
}

impl ParamSpec {
    /// `--step-min`, or the name for a parameter without a flag.
    pub fn flag_or_name(&self) -> String {
        match self.flag {
            Some(f) => format!("--{f}"),
            None => self.name.to_string(),
        }
    }
}

/// One end of a real interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum End {
    /// The end value is accepted.
    Closed(f64),
    /// The end value is refused.
    Open(f64),
    /// No limit on this side (written `inf`; a closed `inf` accepts infinity).
    Unbounded,
}

/// The values a parameter accepts, written as the models' error messages write accepted
/// ranges (`outside the accepted range [1, 1e4]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Range {
    /// Any value of its type (a switch, a count without limit, a list checked elsewhere).
    Any,
    /// A real interval: `[1, 1e4]`, `(0.5, inf]`, `(0, 1)`.
    Real(End, End),
    /// An integer interval: `1..=1024`, `2..`.
    Int {
        /// Smallest accepted value.
        min: i128,
        /// Largest accepted value, if any.
        max: Option<i128>,
    },
    /// One of these numbers: `{2, 3, 4, 5}`.
    Values(&'static [usize]),
    /// One of these names: `return, jump`.
    Choices(&'static [&'static str]),
    /// Depends on other parameters; described in words.
    Text(&'static str),
}

/// A number as a user would type it and the error messages print it: `0.5`, `1000`, `1e4`
/// (from 1e3 up and below 1e-3 in exponent form).
pub fn show_number(v: f64) -> String {
    let a = v.abs();
    if v.is_infinite() {
        if v > 0.0 { "inf".into() } else { "-inf".into() }
    } else if a != 0.0 && !(1e-3..1e3).contains(&a) {
        format!("{v:e}")
    } else {
        v.to_string()
    }
}

impl fmt::Display for End {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            End::Closed(v) | End::Open(v) => f.write_str(&show_number(*v)),
            End::Unbounded => f.write_str("inf"),
        }
    }
}

impl fmt::Display for Range {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Range::Any => f.write_str("any"),
            Range::Real(lo, hi) => {
                let open = if matches!(lo, End::Closed(_)) {
                    '['
                } else {
                    '('
                };
                let close = if matches!(hi, End::Open(_)) { ')' } else { ']' };
                let lo = match lo {
                    End::Unbounded => "-inf".to_string(),
                    other => other.to_string(),
                };
                write!(f, "{open}{lo}, {hi}{close}")
            }
            Range::Int {
                min,
                max: Some(max),
            } => write!(f, "{min}..={max}"),
            Range::Int { min, max: None } => write!(f, "{min}.."),
            Range::Values(v) => {
                let v: Vec<String> = v.iter().map(usize::to_string).collect();
                write!(f, "{{{}}}", v.join(", "))
            }
            Range::Choices(c) => f.write_str(&c.join(", ")),
            Range::Text(t) => f.write_str(t),
        }
    }
}

/// The next representable `f64` above (`up`) or below `v` (finite `v`).
fn next_f64(v: f64, up: bool) -> f64 {
    if v == 0.0 {
        let tiny = f64::from_bits(1);
        return if up { tiny } else { -tiny };
    }
    let bits = v.to_bits();
    let away = (v > 0.0) == up;
    f64::from_bits(if away { bits + 1 } else { bits - 1 })
}

/// A real number spelled so that parsing it gives back exactly `v`.
fn exact(v: f64) -> String {
    format!("{v:?}")
}

impl Range {
    /// Values at the edges of the range as a user would type them (JSON numbers), each with
    /// whether validation must accept it: every closed bound accepted and the nearest value
    /// beyond it refused, every open bound refused. Empty for ranges without numeric edges.
    pub fn probes(&self) -> Vec<(String, bool)> {
        let mut out = Vec::new();
        match self {
            Range::Real(lo, hi) => {
                for (end, up) in [(lo, false), (hi, true)] {
                    match *end {
                        // Infinity is no number a user types; `f64::MAX` would not be refused.
                        End::Closed(v) | End::Open(v) if v.is_infinite() => {}
                        End::Closed(v) => {
                            out.push((exact(v), true));
                            out.push((exact(next_f64(v, up)), false));
                        }
                        // No accepted value is next to an open end in general (`--fill` just
                        // above 0 places no particle): only the end itself is probed.
                        End::Open(v) => out.push((exact(v), false)),
                        End::Unbounded => {}
                    }
                }
            }
            Range::Int { min, max } => {
                out.push((min.to_string(), true));
                out.push(((min - 1).to_string(), false));
                if let Some(max) = max {
                    out.push((max.to_string(), true));
                    out.push(((max + 1).to_string(), false));
                }
            }
            Range::Values(v) => {
                for &x in v.iter() {
                    out.push((x.to_string(), true));
                    for y in [x.checked_sub(1), x.checked_add(1)].into_iter().flatten() {
                        if !v.contains(&y) {
                            out.push((y.to_string(), false));
                        }
                    }
                }
            }
            Range::Any | Range::Choices(_) | Range::Text(_) => {}
        }
        out
    }

    /// The accepted names of a [`Range::Choices`], else none.
    pub fn choices(&self) -> &'static [&'static str] {
        match self {
            Range::Choices(c) => c,
            _ => &[],
        }
    }
}

/// The rows of the first Markdown table after the heading line `heading` (`## Parameters`), each
/// as its cells (trimmed; the header row first, the `|---|` line left out). Empty if there is
/// no such heading or table. The docs' flag tables are checked against the parameter tables
/// with this.
pub fn markdown_table(text: &str, heading: &str) -> Vec<Vec<String>> {
    let mut lines = text.lines().skip_while(|l| l.trim() != heading).skip(1);
    let mut rows = Vec::new();
    for line in lines.by_ref() {
        let t = line.trim();
        if t.starts_with('|') {
            if !t.starts_with("|---") {
                // `\|` is a pipe inside a cell.
                let inner = t.trim_start_matches('|').trim_end_matches('|');
                let inner = inner.replace("\\|", "\u{0}");
                let cells = inner.split('|');
                rows.push(cells.map(|c| c.trim().replace('\u{0}', "|")).collect());
            }
        } else if !rows.is_empty() || t.starts_with('#') {
            break;
        }
    }
    rows
}

/// Whether a front end's spelling of a default (`declared`: clap's `default_value`, a docs
/// table cell, a Python default) is the library's (`library`, as JSON prints it, lists as
/// `a, b`): equal numbers (`5` and `5.0`; byte counts with a suffix K, M, G or T, powers of
/// 1024), `on`/`off` for booleans, otherwise equal text. Backticks, quotes and spaces after
/// commas are ignored, and so is a remark after the value (`60 (the paper's)`).
pub fn same_default(declared: &str, library: &str) -> bool {
    let clean = |s: &str| {
        s.replace(['`', '"'], "")
            .replace(", ", ",")
            .trim()
            .to_string()
    };
    let declared = clean(declared);
    let declared = declared.split(" (").next().unwrap_or_default().trim();
    let library = clean(library);
    if let (Some(a), Some(b)) = (number(declared), number(&library)) {
        return a == b;
    }
    match (declared, library.as_str()) {
        ("on", "true") | ("off", "false") => true,
        (a, b) => a == b,
    }
}

/// `s` as a number, allowing a byte suffix K, M, G or T (powers of 1024).
fn number(s: &str) -> Option<f64> {
    let (digits, scale) = match s.char_indices().last() {
        Some((i, c @ ('K' | 'M' | 'G' | 'T'))) => {
            let k = "KMGT".find(c).unwrap_or(0) as i32 + 1;
            (&s[..i], 1024f64.powi(k))
        }
        _ => (s, 1.0),
    };
    digits.parse::<f64>().ok().map(|v| v * scale)
}

/// Checks that validation accepts each closed bound of every range in `params` and refuses the
/// nearest value outside it, naming the range as the table writes it (`accepted range ...`),
/// with the probes of [`Range::probes`]. `validate(name, value)` sets parameter `name` to the
/// JSON text `value` on top of the defaults and validates: `Err` with the message when the
/// value does not parse (a message containing `invalid`) or is refused.
///
/// # Panics
/// On the first probe whose answer is wrong, naming the parameter, the value and the message.
pub fn check_range_probes(
    params: &[ParamSpec],
    validate: impl Fn(&str, &str) -> Result<(), String>,
) {
    for s in params {
        for (value, accept) in s.range.probes() {
            match (accept, validate(s.name, &value)) {
                (true, Err(e)) => panic!("{} {value} refused: {e}", s.name),
                (false, Ok(())) => panic!("{} {value} accepted, outside {}", s.name, s.range),
                (false, Err(e)) if !e.contains("invalid") => assert!(
                    e.contains(&format!("accepted range {}", s.range)),
                    "{} {value}: {e}",
                    s.name
                ),
                _ => {}
            }
        }
    }
}

/// Checks a model's parameter table against the fields of its parameters (`fields`: the keys
/// of its defaults), as every model's unit tests do: each field has one entry, no name or flag
/// occurs twice, and every flag is the name with dashes (`step_min`: `--step-min`).
///
/// # Panics
/// On the first check that fails, naming what differs.
pub fn check_table<'a>(params: &[ParamSpec], fields: impl IntoIterator<Item = &'a str>) {
    let twice = duplicates(params);
    assert!(twice.is_empty(), "in the table more than once: {twice:?}");
    let mut names: Vec<&str> = params.iter().map(|s| s.name).collect();
    let mut fields: Vec<&str> = fields.into_iter().collect();
    names.sort_unstable();
    fields.sort_unstable();
    assert_eq!(
        names, fields,
        "the table against the fields of the parameters"
    );
    for s in params {
        let dashed = s.name.replace('_', "-");
        assert_eq!(s.flag, Some(dashed.as_str()), "the flag of {}", s.name);
    }
}

/// Parameter names that occur more than once in `specs`, and flags likewise.
pub fn duplicates(specs: &[ParamSpec]) -> Vec<String> {
    let mut seen = std::collections::BTreeSet::new();
    let mut out = Vec::new();
    for s in specs {
        if !seen.insert(format!("name {}", s.name)) {
            out.push(s.name.to_string());
        }
        if let Some(f) = s.flag {
            if !seen.insert(format!("flag {f}")) {
                out.push(format!("--{f}"));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A list of names reads and writes its text exactly (the empty text is the empty list),
    /// and a signed whole number is read as a count, refusing what does not fit.
    #[test]
    fn name_lists_and_signed_counts_read_their_inputs() {
        let v = Vec::<String>::from_input(&Input::Text("eat, hunt,wander".into())).unwrap();
        assert_eq!(v, ["eat", "hunt", "wander"]);
        assert_eq!(v.show(), "eat,hunt,wander");
        assert_eq!(Vec::<String>::parse_text(&v.show()), Ok(v));
        assert_eq!(Vec::<String>::parse_text(""), Ok(Vec::new()));
        assert!(Vec::<String>::from_input(&Input::Count(3)).is_err());
        assert_eq!(i64::from_input(&Input::Count(60)), Ok(60));
        assert!(i64::from_input(&Input::Count(u64::MAX)).is_err());
        let r = Range::Int {
            min: 1,
            max: Some(1 << 30),
        };
        assert!(60i64.in_range(&r) && !0i64.in_range(&r) && !(1i64 << 31).in_range(&r));
    }

    #[test]
    fn ranges_are_written_as_the_error_messages_write_them() {
        let r = Range::Real(End::Closed(1.0), End::Closed(1e4));
        assert_eq!(r.to_string(), "[1, 1e4]");
        let r = Range::Real(End::Open(0.5), End::Unbounded);
        assert_eq!(r.to_string(), "(0.5, inf]");
        let r = Range::Real(End::Closed(1e-6), End::Closed(1e3));
        assert_eq!(r.to_string(), "[1e-6, 1e3]");
        let r = Range::Real(End::Closed(0.0), End::Open(1.0));
        assert_eq!(r.to_string(), "[0, 1)");
        assert_eq!(
            Range::Int {
                min: 1,
                max: Some(1024)
            }
            .to_string(),
            "1..=1024"
        );
        assert_eq!(Range::Int { min: 2, max: None }.to_string(), "2..");
        assert_eq!(Range::Values(&[2, 3, 4, 5]).to_string(), "{2, 3, 4, 5}");
        assert_eq!(
            Range::Choices(&["return", "jump"]).to_string(),
            "return, jump"
        );
    }

    #[test]
    fn probes_straddle_every_bound() {
        let r = Range::Real(End::Open(1.0), End::Closed(1e100));
        let p = r.probes();
        assert!(p.contains(&("1.0".into(), false)));
        assert!(p.contains(&("1e100".into(), true)));
        assert!(
            p.iter()
                .any(|(v, ok)| !ok && v.parse::<f64>().unwrap() > 1e100)
        );
        let r = Range::Real(End::Closed(0.0), End::Open(1.0));
        let p = r.probes();
        assert!(p.contains(&("0.0".into(), true)));
        assert!(p.contains(&("-5e-324".into(), false)));
        assert!(p.contains(&("1.0".into(), false)));
        let p = Range::Int {
            min: 1,
            max: Some(3),
        }
        .probes();
        assert_eq!(
            p,
            [("1", true), ("0", false), ("3", true), ("4", false)].map(|(v, ok)| (v.into(), ok))
        );
        let p = Range::Values(&[1, 2, 4]).probes();
        assert!(p.contains(&("3".into(), false)) && p.contains(&("0".into(), false)));
        assert!(p.contains(&("5".into(), false)) && p.contains(&("4".into(), true)));
    }

    #[test]
    fn defaults_compare_across_spellings() {
        assert!(same_default("5", "5.0"));
        assert!(same_default("`periodic`", "\"periodic\""));
        assert!(same_default("4G", "4294967296"));
        assert!(same_default("60 (the paper's)", "60"));
        assert!(same_default("on", "true") && same_default("off", "false"));
        assert!(!same_default("0.5", "0.1") && !same_default("on", "false"));
        assert!(same_default("eat, breed", "eat, breed"));
    }

    #[test]
    fn markdown_tables_are_read_under_their_heading() {
        let md = "# T\n\n## Flags\n\ntext\n\n| flag | default |\n|---|---|\n| `--a` | 1 |\n| `--b` | x \\| y |\n\nafter\n| z | z |\n";
        let rows = markdown_table(md, "## Flags");
        assert_eq!(rows.len(), 3);
        assert_eq!(rows[0], ["flag", "default"]);
        assert_eq!(rows[1], ["`--a`", "1"]);
        assert_eq!(rows[2], ["`--b`", "x | y"]);
        assert!(markdown_table(md, "## None").is_empty());
    }
}
