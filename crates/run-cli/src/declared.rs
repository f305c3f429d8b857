//! What is generated from a model's parameter declaration (`core_lattice::declare_params!`)
//! into files people read: the docs' flag table and the Python stub's keyword arguments. Each
//! sits in its file between two marker lines, written by `cargo xtask generate` and checked
//! by the models' tests ([`check_generated`]), so a declaration and its documentation cannot
//! drift apart.

use core_lattice::spec::{Declared, DeclaredParams, Kind, Range, help_text, show_number};
use serde::Serialize;
use serde_json::Value;

pub use run_io::params_json::defaults_of;

/// The 1-based line where `key` is set in the TOML text `text` (0 if not found): where a config
/// file's error is reported, by the binaries' `--config` and by Python's `config=`.
pub fn key_line(text: &str, key: &str) -> usize {
    text.lines()
        .position(|l| {
            l.trim_start()
                .strip_prefix(key)
                .is_some_and(|rest| rest.trim_start().starts_with('='))
        })
        .map_or(0, |i| i + 1)
}

/// How a binary shows its declared parameters as flags: [`Annotated`] or [`Plain`].
pub trait FlagStyle: 'static {
    /// Whether the help is the declaration's doc as written ([`Plain`]).
    const PLAIN: bool;
}

/// The help of each flag is its doc's first sentence (the whole doc with `--help`) followed by
/// the unit and accepted range from the declaration; values are named `X`, `N`, `NAME`, and
/// switches take `on` or `off` (`--near-cache off`). The `dla` binary's flags.
#[derive(Debug, Clone, Copy)]
pub struct Annotated;

impl FlagStyle for Annotated {
    const PLAIN: bool = false;
}

/// The help of each flag is its doc as written (which states the unit and range in its own
/// words), values are named after the parameter (`--fill <FILL>`) and switches are bare flags
/// (`--gyration`), as clap's derive writes flags. The `dlca` binary's flags.
#[derive(Debug, Clone, Copy)]
pub struct Plain;

impl FlagStyle for Plain {
    const PLAIN: bool = true;
}

/// A default as the command line and the docs spell it: `5`, `1e-6`, `on`, `return`.
pub fn cli_default(d: &Declared, v: &Value) -> String {
    match (d.kind, v) {
        (Kind::Switch, Value::Bool(b)) => if *b { "on" } else { "off" }.into(),
        (Kind::Real, Value::Number(n)) => n.as_f64().map_or_else(|| n.to_string(), show_number),
        (_, Value::String(s)) => s.clone(),
        (_, Value::Null) => "none".into(),
        (_, v) => v.to_string(),
    }
}

/// The default of a declared parameter as the command line writes it: the text of the typed
/// default for a [`Kind::Text`] or [`Kind::List`] (`4G`, `1,2,5`), else from its JSON.
pub fn shown_default<P: DeclaredParams>(d: &Declared, default: &Value) -> String {
    if matches!(d.kind, Kind::Text | Kind::List) {
        if let Some((_, text)) = P::default()
            .to_text()
            .into_iter()
            .find(|(n, _)| *n == d.spec.name)
        {
            return text;
        }
    }
    cli_default(d, default)
}

/// The unit and accepted values of a parameter as one phrase: `in diameters, accepted [1,
/// 1e4]`, `one of return, jump`, `on or off`; empty when there is nothing to say.
pub fn accepted(d: &Declared) -> String {
    accepted_in::<Annotated>(d)
}

/// [`accepted`] for flags shown in style `S`: a [`Plain`] switch is a bare flag, with nothing
/// to say.
fn accepted_in<S: FlagStyle>(d: &Declared) -> String {
    let mut parts = Vec::new();
    if !d.spec.unit.is_empty() {
        parts.push(format!("in {}", d.spec.unit));
    }
    match (d.kind, d.spec.range) {
        (Kind::Switch, _) if S::PLAIN => {}
        (Kind::Switch, _) => parts.push("on or off".into()),
        (Kind::Text | Kind::List, Range::Choices(c)) => {
            parts.push(format!("each one of {}", c.join(", ")))
        }
        (_, Range::Choices(c)) => parts.push(format!("one of {}", c.join(", "))),
        (_, Range::Any) => {}
        (_, r) => parts.push(format!("accepted {r}")),
    }
    parts.join("; ")
}

/// The markdown flag table of `P`'s declared parameters: flag, default and meaning (the whole
/// help, its unit and range, and the reason for the range), for flags in the [`Annotated`]
/// style.
pub fn docs_table<P: DeclaredParams + Serialize>() -> String {
    docs_table_in::<P, Annotated>()
}

/// [`docs_table`] for flags shown in style `S`.
pub fn docs_table_in<P: DeclaredParams + Serialize, S: FlagStyle>() -> String {
    let defaults = defaults_of::<P>();
    let mut out = String::from("| flag | default | meaning |\n|---|---|---|\n");
    for d in P::DECLARED {
        let flag = d.spec.flag.expect("a declared parameter has a flag");
        let default = if d.required {
            "(required)".to_string()
        } else {
            shown_default::<P>(d, &defaults[d.spec.name])
        };
        let mut meaning = help_text(d.help);
        let acc = accepted_in::<S>(d);
        if !acc.is_empty() {
            meaning.push_str(&format!(" ({acc}"));
            if !d.why.is_empty() {
                meaning.push_str(&format!(": {}", d.why));
            }
            meaning.push(')');
        }
        let meaning = meaning.replace('|', "\\|");
        out.push_str(&format!("| `--{flag}` | {default} | {meaning} |\n"));
    }
    out
}

/// The Python type of a declared parameter as the stubs write it: its type's own
/// ([`Declared::python`]), else `float`, `Count` for counts, `bool`, `Literal["return",
/// "jump"]` for choices; in `Optional[...]` when None by default ([`Declared::python_none`]).
pub fn python_annotation(d: &Declared) -> String {
    let kind = match (d.kind, d.spec.range) {
        _ if !d.python.is_empty() => d.python.into(),
        (_, Range::Choices(c)) => {
            let names: Vec<String> = c.iter().map(|n| format!("\"{n}\"")).collect();
            format!("Literal[{}]", names.join(", "))
        }
        (Kind::Count, _) => "Count".into(),
        (k, _) => k.python_type().into(),
    };
    if d.python_none() {
        format!("Optional[{kind}]")
    } else {
        kind
    }
}

/// The keyword arguments of `P`'s declared parameters as the lines of a Python stub's
/// signature (`    birth_gap: float = ...,`), leaving out the `positional` ones.
pub fn pyi_keywords<P: DeclaredParams>(positional: &[&str]) -> String {
    P::DECLARED
        .iter()
        .filter(|d| !positional.contains(&d.spec.name))
        .map(|d| {
            let default = if d.python_none() { "None" } else { "..." };
            format!(
                "    {}: {} = {default},\n",
                d.spec.name,
                python_annotation(d)
            )
        })
        .collect()
}

/// The two marker lines around generated block `name` in a file whose comments start with
/// `comment` (`#`) or, for Markdown, are HTML comments (`comment` = `<!--`).
fn markers(name: &str, comment: &str) -> (String, String) {
    let tool = "written by `cargo xtask generate` from the declaration; do not edit";
    if comment == "<!--" {
        (
            format!("<!-- BEGIN GENERATED {name}: {tool} -->"),
            format!("<!-- END GENERATED {name} -->"),
        )
    } else {
        (
            format!("{comment} BEGIN GENERATED {name}: {tool}"),
            format!("{comment} END GENERATED {name}"),
        )
    }
}

/// `text` with the block `name` between its markers replaced by `block`; `None` if the
/// markers are missing.
pub fn replace_generated(text: &str, name: &str, comment: &str, block: &str) -> Option<String> {
    let (begin, end) = markers(name, comment);
    let a = text.find(&begin)? + begin.len();
    let b = a + text[a..].find(&end)?;
    // The end marker's line keeps its indentation.
    let b = text[a..b].rfind('\n').map_or(b, |i| a + i + 1);
    let mut out = String::with_capacity(text.len() + block.len());
    out.push_str(&text[..a]);
    out.push('\n');
    out.push_str(block);
    out.push_str(&text[b..]);
    Some(out)
}

/// Whether the block `name` of `text` is `block`: the check of the tests. The message of a
/// stale or missing block says how to regenerate it.
pub fn check_generated(
    file: &str,
    text: &str,
    name: &str,
    comment: &str,
    block: &str,
) -> Result<(), String> {
    match replace_generated(text, name, comment, block) {
        None => Err(format!(
            "{file} has no generated block {name} (its marker lines are missing)"
        )),
        Some(t) if t == text => Ok(()),
        Some(_) => Err(format!(
            "{file}: the generated block {name} is not the declaration's; run `cargo xtask generate`"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generated_blocks_are_replaced_between_their_markers() {
        let (b, e) = markers("t", "#");
        let text = format!("head\n{b}\nold\n  {e}\ntail\n");
        let new = replace_generated(&text, "t", "#", "new\n").unwrap();
        assert_eq!(new, format!("head\n{b}\nnew\n  {e}\ntail\n"));
        assert!(check_generated("f", &new, "t", "#", "new\n").is_ok());
        let stale = check_generated("f", &text, "t", "#", "new\n").unwrap_err();
        assert!(stale.contains("cargo xtask generate"), "{stale}");
        assert!(check_generated("f", "no markers", "t", "#", "x").is_err());
    }
}
