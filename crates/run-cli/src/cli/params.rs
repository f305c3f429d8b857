//! A model's declared parameters as command-line flags: [`ParamFlags`] builds one flag per
//! parameter of a [`DeclaredParams`] table (its name, help, unit, range, default and the way
//! its value is read), so that a binary `#[command(flatten)]`s its model's parameters instead
//! of restating them, and config files and `--dump-config` (which work on the flags) follow.
//!
//! Values are read as the declaration's [`Kind`] says: reals (`inf` and values starting with
//! `-` allowed, so that the range check names the flag), counts (`1e6`), `on`/`off` switches and
//! the names of a choice. The parameters then come from the library's defaults with the given
//! values on top ([`DeclaredParams::set`]), and are checked by the model's own validation.

pub use crate::declared::{Annotated, FlagStyle, Plain};
use crate::declared::{accepted, cli_default, defaults_of, shown_default};
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::parser::ValueSource;
use clap::{Arg, ArgAction, ArgMatches, Args, Command, FromArgMatches};
use core_lattice::spec::{Declared, DeclaredParams, Input, Kind, help_text};
use serde::Serialize;
use serde_json::Value;
use std::marker::PhantomData;

/// The declared parameters of model `P` as flags (`#[command(flatten)]` it into a binary's
/// flags), and after parsing their values and which were given. `FROM..TO` selects the
/// parameters by their place in the declaration, so that a binary can show its flags in two
/// groups around its own (`ParamFlags<P, Plain, 0, 4>` and `ParamFlags<P, Plain, 4>`); the
/// style `S` is how the flags are shown.
#[derive(Debug, Clone)]
pub struct ParamFlags<P, S = Annotated, const FROM: usize = 0, const TO: usize = { usize::MAX }> {
    /// The value of every parameter with a value: given, from a config file, or the default.
    values: Vec<(&'static str, Input)>,
    /// Names of the parameters given on the command line or in a config file.
    given: Vec<&'static str>,
    _model: PhantomData<fn() -> (P, S)>,
}

/// The help of a declared parameter: its doc (`long`) or its first sentence, then its unit and
/// accepted values, and for an optional parameter the default it takes when not given.
pub fn flag_help(d: &Declared, default: &Value, long: bool) -> String {
    let mut h = if long {
        help_text(d.help)
    } else {
        help_text(d.spec.doc)
    };
    let acc = accepted(d);
    if !acc.is_empty() && d.kind != Kind::Switch && d.kind != Kind::Choice {
        let mut c = acc.chars();
        let first: String = c
            .next()
            .map(|f| f.to_uppercase().collect())
            .unwrap_or_default();
        h.push_str(&format!(" {first}{}", c.as_str()));
        if !h.ends_with('.') {
            h.push('.');
        }
    } else if !d.spec.unit.is_empty() {
        h.push_str(&format!(" In {}.", d.spec.unit));
    }
    if d.optional {
        h.push_str(&format!(" [default: {}]", cli_default(d, default)));
    }
    h
}

/// A real number as a flag's value: what `f64` parses (`inf`, `1e-6`), named in the error.
fn parse_real(s: &str) -> Result<f64, String> {
    s.trim()
        .parse::<f64>()
        .map_err(|_| format!("'{s}' is not a number"))
}

/// The flag of declared parameter `d` in the [`Annotated`] style, with `default` (the
/// library's) as its default value.
pub fn flag_arg(d: &Declared, default: &Value) -> Arg {
    styled_arg::<Annotated>(d, default, cli_default(d, default), |_| Ok(()))
}

/// The flag of declared parameter `d` in style `S`: `default` is the library's default,
/// `shown` the same as the command line writes it, and `check` reads a text value
/// ([`Kind::Text`], each item of a [`Kind::List`]), its error being clap's.
fn styled_arg<S: FlagStyle>(
    d: &Declared,
    default: &Value,
    shown: String,
    check: impl Fn(&str) -> Result<(), String> + Clone + Send + Sync + 'static,
) -> Arg {
    let long = d.spec.flag.expect("a declared parameter has a flag");
    let mut arg = Arg::new(d.spec.name).long(long).action(ArgAction::Set);
    arg = if S::PLAIN {
        // As clap's derive writes a doc comment: a final full stop goes (not that of `2..`).
        let mut text = help_text(d.help);
        if text.ends_with('.') && !text.ends_with("..") {
            text.pop();
        }
        arg.help(text).value_name(d.spec.name.to_uppercase())
    } else {
        arg.help(flag_help(d, default, false))
            .long_help(flag_help(d, default, true))
    };
    let named = |arg: Arg, name: &'static str| if S::PLAIN { arg } else { arg.value_name(name) };
    arg = match d.kind {
        Kind::Real if S::PLAIN => arg
            .value_parser(clap::value_parser!(f64))
            .allow_hyphen_values(true),
        Kind::Real => named(arg.value_parser(parse_real).allow_hyphen_values(true), "X"),
        Kind::Count => named(arg.value_parser(run_io::count::count::<u64>), "N"),
        Kind::Switch if S::PLAIN => arg.action(ArgAction::SetTrue),
        Kind::Switch => arg
            .value_parser(PossibleValuesParser::new(["on", "off"]).map(|s| s == "on"))
            .value_name("on|off"),
        Kind::Choice => {
            let values = d.spec.range.choices().iter().enumerate().map(|(i, &n)| {
                let v = PossibleValue::new(n);
                match d.choice_help.get(i) {
                    Some(&h) => v.help(h),
                    None => v,
                }
            });
            named(arg.value_parser(PossibleValuesParser::new(values)), "NAME")
        }
        Kind::Text | Kind::List => {
            let read = move |s: &str| check(s).map(|()| s.to_string());
            let arg = named(arg.value_parser(read), "TEXT");
            if d.kind == Kind::List {
                arg.value_delimiter(',')
            } else {
                arg
            }
        }
    };
    if d.required {
        arg.required(true)
    } else if d.optional || default.is_null() || matches!(arg.get_action(), ArgAction::SetTrue) {
        arg
    } else {
        arg.default_value(shown)
    }
}

impl<P: DeclaredParams, S, const FROM: usize, const TO: usize> ParamFlags<P, S, FROM, TO> {
    /// The parameters: the library's defaults with the values parsed on top. The model's
    /// validation (range checks and cross-field rules) is the caller's.
    pub fn params(&self) -> P {
        let mut p = P::default();
        self.apply(&mut p);
        p
    }

    /// Sets the values parsed on `p` (the parameters of another group of flags of the same
    /// model, for a binary that shows them in two groups).
    pub fn apply(&self, p: &mut P) {
        for (name, v) in &self.values {
            // The flags were made from the declaration, with its kinds and its types' checks:
            // a value always fits.
            let set = p.set(name, v);
            debug_assert_eq!(set, Ok(true), "{name}");
        }
    }

    /// Whether parameter `name` was given (command line or config file), not defaulted.
    pub fn given(&self, name: &str) -> bool {
        self.given.contains(&name)
    }

    /// The declared parameters of this group of flags.
    fn selected() -> &'static [Declared] {
        &P::DECLARED[FROM.min(P::DECLARED.len())..TO.min(P::DECLARED.len())]
    }
}

impl<P, S, const FROM: usize, const TO: usize> Args for ParamFlags<P, S, FROM, TO>
where
    P: DeclaredParams + Serialize + 'static,
    S: FlagStyle,
{
    fn augment_args(cmd: Command) -> Command {
        let defaults = defaults_of::<P>();
        Self::selected().iter().fold(cmd, |cmd, d| {
            let default = defaults.get(d.spec.name).unwrap_or(&Value::Null);
            let name = d.spec.name;
            // A text value is the type's to read: the declaration's setter reads it.
            let check = move |s: &str| {
                P::default()
                    .set(name, &Input::Text(s.to_string()))
                    .map(drop)
            };
            cmd.arg(styled_arg::<S>(
                d,
                default,
                shown_default::<P>(d, default),
                check,
            ))
        })
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

impl<P: DeclaredParams, S, const FROM: usize, const TO: usize> FromArgMatches
    for ParamFlags<P, S, FROM, TO>
{
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let mut values = Vec::new();
        let mut given = Vec::new();
        for d in Self::selected() {
            let id = d.spec.name;
            let v = match d.kind {
                Kind::Real => m.get_one::<f64>(id).map(|&x| Input::Real(x)),
                Kind::Count => m.get_one::<u64>(id).map(|&x| Input::Count(x)),
                Kind::Switch => m.get_one::<bool>(id).map(|&x| Input::Switch(x)),
                Kind::Choice => m.get_one::<String>(id).map(|x| Input::Choice(x.clone())),
                Kind::Text => m.get_one::<String>(id).map(|x| Input::Text(x.clone())),
                Kind::List => m.get_many::<String>(id).map(|xs| {
                    let items: Vec<&str> = xs.map(String::as_str).collect();
                    Input::Text(items.join(","))
                }),
            };
            if let Some(v) = v {
                values.push((id, v));
            }
            if matches!(
                m.value_source(id),
                Some(ValueSource::CommandLine | ValueSource::EnvVariable)
            ) {
                given.push(id);
            }
        }
        Ok(ParamFlags {
            values,
            given,
            _model: PhantomData,
        })
    }

    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::{CommandFactory, Parser};
    use core_lattice::spec::{End, Range};

    /// A choice parameter's type, as a model declares one.
    #[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
    #[serde(rename_all = "lowercase")]
    enum Shape {
        Ball,
        Cube,
    }

    impl core_lattice::spec::ParamValue for Shape {
        const KIND: Kind = Kind::Choice;
        fn from_input(v: &Input) -> Result<Self, String> {
            match v {
                Input::Choice(s) if s == "ball" => Ok(Shape::Ball),
                Input::Choice(s) if s == "cube" => Ok(Shape::Cube),
                other => Err(format!("not a shape: {other:?}")),
            }
        }
        fn parse_text(s: &str) -> Result<Self, String> {
            Self::from_input(&Input::Choice(s.into()))
        }
        fn in_range(&self, _: &Range) -> bool {
            true
        }
        fn show(&self) -> String {
            format!("{self:?}").to_lowercase()
        }
    }

    core_lattice::declare_params! {
        /// A model with one parameter of each kind: what "adding a parameter" adds.
        #[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
        #[serde(default)]
        pub struct Toy {
            /// Particles of the cluster.
            particles: u64 = 100 => {
                flag: "particles", unit: "particles", range: Range::Int { min: 1, max: None },
                required: true,
            },
            /// Probability that a walker sticks at a contact.
            sticking: f64 = 1.0 => {
                flag: "sticking", unit: "", range: Range::Real(End::Open(0.0), End::Closed(1.0)),
                why: "a probability",
            },
            /// Shape of a particle.
            shape: Shape = Shape::Ball => {
                flag: "shape", unit: "", range: Range::Choices(&["ball", "cube"]),
            },
            /// Whether to cache.
            cache: bool = true => { flag: "cache", unit: "", range: Range::Any },
            /// Death radius, used by some far fields only.
            death: f64 = 100.0 => {
                flag: "death", unit: "radii", range: Range::Real(End::Open(1.0), End::Unbounded),
                optional: true,
            },
        }
        internal {}
    }

    #[derive(Parser, Debug)]
    struct Cli {
        #[command(flatten)]
        params: ParamFlags<Toy>,
        #[arg(long, default_value_t = 1)]
        seed: u64,
    }

    fn parse(args: &[&str]) -> Result<Cli, clap::Error> {
        Cli::try_parse_from(std::iter::once("toy").chain(args.iter().copied()))
    }

    #[test]
    fn a_declared_parameter_is_a_flag_with_its_help_default_and_checks() {
        Cli::command().debug_assert();
        let c = parse(&[
            "--particles",
            "1e3",
            "--sticking",
            "0.25",
            "--shape",
            "cube",
        ])
        .unwrap();
        let p = c.params.params();
        assert_eq!(p.particles, 1000);
        assert_eq!(p.sticking, 0.25);
        assert_eq!(p.shape, Shape::Cube);
        assert!(p.cache);
        assert_eq!(p.death, 100.0);
        assert!(c.params.given("sticking") && !c.params.given("death"));
        assert!(!c.params.given("cache"));
        let c = parse(&["--particles", "5", "--cache", "off", "--death", "50"]).unwrap();
        let p = c.params.params();
        assert!(!p.cache && p.death == 50.0 && c.params.given("death"));
        // The range check and its message come from the declaration.
        let c = parse(&["--particles", "5", "--sticking", "-0.5"]).unwrap();
        assert_eq!(
            c.params.params().check_ranges().unwrap_err().to_string(),
            "--sticking -0.5 is outside the accepted range (0, 1] (a probability)"
        );
        // A required flag, an unknown choice and a non-number are clap's errors.
        assert!(parse(&[]).is_err());
        assert!(parse(&["--particles", "5", "--shape", "cone"]).is_err());
        assert!(parse(&["--particles", "5", "--sticking", "often"]).is_err());
        assert!(parse(&["--particles", "1.5"]).is_err());
        // The help says what the declaration says.
        let help = Cli::command().render_long_help().to_string();
        assert!(help.contains("Probability that a walker sticks at a contact. Accepted (0, 1]."));
        assert!(
            help.contains("In radii; accepted (1, inf]. [default: 100]"),
            "{help}"
        );
        assert!(help.contains("[default: on]") && help.contains("[default: ball]"));
        assert!(help.contains("[possible values: ball, cube]"));
    }

    #[test]
    fn the_effective_configuration_lists_every_declared_parameter() {
        let cmd = Cli::command();
        let m = cmd
            .clone()
            .try_get_matches_from(["toy", "--particles", "7", "--sticking", "0.5"])
            .unwrap();
        let text = crate::cli::config::effective(&cmd, &m);
        assert!(text.contains("\nparticles = 7\n"), "{text}");
        assert!(text.contains("\nsticking = 0.5\n"), "{text}");
        assert!(text.contains("# cache = \"on\"  (default)"), "{text}");
        // An optional parameter has no value until given.
        assert!(!text.contains("death"), "{text}");
    }

    /// A list of counts, as a model declares one ([`Kind::List`]).
    #[derive(Debug, Clone, PartialEq, serde::Serialize)]
    #[serde(transparent)]
    struct Counts(Vec<u64>);

    impl core_lattice::spec::ParamValue for Counts {
        const KIND: Kind = Kind::List;
        fn from_input(v: &Input) -> Result<Self, String> {
            match v {
                Input::Text(s) => Self::parse_text(s),
                other => Err(format!("not a list: {other:?}")),
            }
        }
        fn parse_text(s: &str) -> Result<Self, String> {
            s.split(',')
                .map(|x| x.parse().map_err(|_| format!("'{x}' is not a count")))
                .collect::<Result<_, _>>()
                .map(Counts)
        }
        fn in_range(&self, _: &Range) -> bool {
            true
        }
        fn show(&self) -> String {
            let v: Vec<String> = self.0.iter().map(u64::to_string).collect();
            v.join(",")
        }
    }

    core_lattice::declare_params! {
        /// A model shown in the plain style, in two groups.
        #[derive(Debug, Clone, PartialEq, serde::Serialize)]
        pub struct Flat {
            /// Side length in sites, 1..
            side: u64 = 8 => { flag: "side", unit: "sites", range: Range::Int { min: 1, max: None } },
            /// Fraction filled, in (0, 1).
            fill: Option<f64> = None => {
                flag: "fill", unit: "", range: Range::Real(End::Open(0.0), End::Open(1.0)),
                optional: true,
            },
            /// Record the times.
            timing: bool = false => { flag: "timing", unit: "", range: Range::Any },
            /// Sweeps to record at, comma separated.
            at: Counts = Counts(vec![1, 10]) => { flag: "at", unit: "", range: Range::Any },
        }
        internal {}
    }

    #[derive(Parser, Debug)]
    struct FlatCli {
        #[command(flatten)]
        first: ParamFlags<Flat, Plain, 0, 2>,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        #[command(flatten)]
        rest: ParamFlags<Flat, Plain, 2>,
    }

    #[test]
    fn the_plain_style_writes_flags_as_clap_derive_does_in_groups() {
        FlatCli::command().debug_assert();
        let parse = |args: &[&str]| {
            FlatCli::try_parse_from(std::iter::once("flat").chain(args.iter().copied()))
        };
        let c = parse(&["--fill", "0.5", "--timing", "--at", "2,3", "--side", "1e2"]).unwrap();
        let mut p = c.rest.params();
        c.first.apply(&mut p);
        assert_eq!((p.side, p.fill, p.timing), (100, Some(0.5), true));
        assert_eq!(p.at, Counts(vec![2, 3]));
        assert!(c.first.given("fill") && c.rest.given("at") && !c.first.given("at"));
        let p = parse(&[]).unwrap().rest.params();
        assert_eq!((p.fill, p.timing, p.at), (None, false, Counts(vec![1, 10])));
        // A text value is read by its type, and its error is clap's.
        let e = parse(&["--at", "2,x"]).unwrap_err().to_string();
        assert!(e.contains("'x' is not a count"), "{e}");
        assert!(parse(&["--timing", "on"]).is_err());
        // The help is the doc as written, the groups in their places.
        let help = FlatCli::command().render_help().to_string();
        let at = |s: &str| help.find(s).unwrap_or_else(|| panic!("{s}: {help}"));
        assert!(at("--side <SIDE>") < at("--fill <FILL>") && at("--fill") < at("--seed"));
        assert!(at("--seed") < at("--timing") && at("--timing") < at("--at <AT>"));
        assert!(
            help.contains("Side length in sites, 1.. [default: 8]"),
            "{help}"
        );
        assert!(help.contains("Fraction filled, in (0, 1)\n"), "{help}");
        assert!(help.contains("comma separated [default: 1,10]"), "{help}");
    }
}
