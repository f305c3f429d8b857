//! A model's declared parameters as command-line flags: [`ParamFlags`] builds one flag per
//! parameter of a [`DeclaredParams`] table (its name, help, unit, range, default and the way
//! its value is read), so that a binary `#[command(flatten)]`s its model's parameters instead
//! of restating them, and config files and `--dump-config` (which work on the flags) follow.
//!
//! Values are read as the declaration's [`Kind`] says: reals (`inf` and values starting with
//! `-` allowed, so that the range check names the flag), counts (`1e6`), `on`/`off` switches and
//! the names of a choice. The parameters then come from the library's defaults with the given
//! values on top ([`DeclaredParams::set`]), and are checked by the model's own validation.

use crate::declared::{accepted, cli_default, defaults_of};
use clap::builder::{PossibleValuesParser, TypedValueParser};
use clap::parser::ValueSource;
use clap::{Arg, ArgAction, ArgMatches, Args, Command, FromArgMatches};
use core_lattice::spec::{Declared, DeclaredParams, Input, Kind, help_text};
use serde::Serialize;
use serde_json::Value;
use std::marker::PhantomData;

/// The declared parameters of model `P` as flags (`#[command(flatten)]` it into a binary's
/// flags), and after parsing their values and which were given.
#[derive(Debug, Clone)]
pub struct ParamFlags<P> {
    /// The value of every parameter with a value: given, from a config file, or the default.
    values: Vec<(&'static str, Input)>,
    /// Names of the parameters given on the command line or in a config file.
    given: Vec<&'static str>,
    _model: PhantomData<fn() -> P>,
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

/// The flag of declared parameter `d`, with `default` (the library's) as its default value.
pub fn flag_arg(d: &Declared, default: &Value) -> Arg {
    let long = d.spec.flag.expect("a declared parameter has a flag");
    let mut arg = Arg::new(d.spec.name)
        .long(long)
        .action(ArgAction::Set)
        .help(flag_help(d, default, false))
        .long_help(flag_help(d, default, true));
    arg = match d.kind {
        Kind::Real => arg
            .value_parser(parse_real)
            .allow_hyphen_values(true)
            .value_name("X"),
        Kind::Count => arg.value_parser(crate::count::count::<u64>).value_name("N"),
        Kind::Switch => arg
            .value_parser(PossibleValuesParser::new(["on", "off"]).map(|s| s == "on"))
            .value_name("on|off"),
        Kind::Choice => {
            let names: Vec<&'static str> = d.spec.range.choices().to_vec();
            arg.value_parser(PossibleValuesParser::new(names))
                .value_name("NAME")
        }
    };
    if d.required {
        arg.required(true)
    } else if d.optional || default.is_null() {
        arg
    } else {
        arg.default_value(cli_default(d, default))
    }
}

impl<P: DeclaredParams> ParamFlags<P> {
    /// The parameters: the library's defaults with the values parsed on top. The model's
    /// validation (range checks and cross-field rules) is the caller's.
    pub fn params(&self) -> P {
        let mut p = P::default();
        for (name, v) in &self.values {
            // The flags were made from the declaration, with its kinds: a value always fits.
            let set = p.set(name, v);
            debug_assert_eq!(set, Ok(true), "{name}");
        }
        p
    }

    /// Whether parameter `name` was given (command line or config file), not defaulted.
    pub fn given(&self, name: &str) -> bool {
        self.given.contains(&name)
    }
}

impl<P: DeclaredParams + Serialize> Args for ParamFlags<P> {
    fn augment_args(cmd: Command) -> Command {
        let defaults = defaults_of::<P>();
        P::DECLARED.iter().fold(cmd, |cmd, d| {
            cmd.arg(flag_arg(
                d,
                defaults.get(d.spec.name).unwrap_or(&Value::Null),
            ))
        })
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

impl<P: DeclaredParams> FromArgMatches for ParamFlags<P> {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let mut values = Vec::new();
        let mut given = Vec::new();
        for d in P::DECLARED {
            let id = d.spec.name;
            let v = match d.kind {
                Kind::Real => m.get_one::<f64>(id).map(|&x| Input::Real(x)),
                Kind::Count => m.get_one::<u64>(id).map(|&x| Input::Count(x)),
                Kind::Switch => m.get_one::<bool>(id).map(|&x| Input::Switch(x)),
                Kind::Choice => m.get_one::<String>(id).map(|x| Input::Choice(x.clone())),
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
}
