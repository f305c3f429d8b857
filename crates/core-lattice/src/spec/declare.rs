//! One declaration per parameter: [`declare_params!`](crate::declare_params) writes a model's
//! `Params` struct, its `Default`, its parameter table ([`Declared`], [`ParamSpec`]) and the
//! range checks with their error messages from a single list, so that a parameter is named,
//! documented, defaulted and bounded in one place. The front ends (the binaries' flags and config
//! files, the Python keyword arguments, their stubs and the docs' flag tables) are generated
//! from the table at run time or checked against it.

use super::{ParamSpec, Range};
use std::fmt;

/// How a front end reads a parameter's value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A real number (`5`, `1e-6`, `inf`).
    Real,
    /// A non-negative whole number, written as an integer or in exponent form (`1e6`).
    Count,
    /// On or off (`on`/`off` on the command line, `true`/`false` in files and Python).
    Switch,
    /// One of the names of its [`Range::Choices`].
    Choice,
    /// Text the type reads itself (`1024x512`, `periodic,wall`, `4G`).
    Text,
    /// A list of values separated by commas (`1,2,5`): on the command line one flag, its
    /// values split at the commas; in files and Python a list.
    List,
}

impl Kind {
    /// The word the docs and the Python stubs use for the type (`float`, `int`, `bool`, `str`).
    pub fn python_type(self) -> &'static str {
        match self {
            Kind::Real => "float",
            Kind::Count => "int",
            Kind::Switch => "bool",
            Kind::Choice | Kind::Text => "str",
            Kind::List => "list",
        }
    }
}

/// A value as a front end read it, before it becomes a field of `Params`.
#[derive(Debug, Clone, PartialEq)]
pub enum Input {
    /// A real number.
    Real(f64),
    /// A whole number.
    Count(u64),
    /// On or off.
    Switch(bool),
    /// A name.
    Choice(String),
    /// Text the parameter's type reads ([`Kind::Text`], [`Kind::List`]).
    Text(String),
}

/// A parameter's type as the declarations see it: its [`Kind`], whether a value lies in a
/// [`Range`], the value as the error messages print it, and the value from a front end's
/// [`Input`].
pub trait ParamValue: Sized {
    /// How the front ends read it.
    const KIND: Kind;
    /// The type as the Python stubs write it, where the [`Kind`] does not say it (`Size`,
    /// `Sequence[Count]`); empty for the kind's.
    const PYTHON: &'static str = "";
    /// A line of help for each name of a [`Kind::Choice`], in the order of its
    /// [`Range::Choices`]; empty for none.
    const CHOICE_HELP: &'static [&'static str] = &[];
    /// The value of a front end's input; the error says what was expected.
    fn from_input(v: &Input) -> Result<Self, String>;
    /// The value from its [`show`](Self::show) text, exactly (the self-describing form
    /// checkpoints keep parameters in).
    fn parse_text(s: &str) -> Result<Self, String>;
    /// Whether the value is one `range` accepts.
    fn in_range(&self, range: &Range) -> bool;
    /// The value as a user would type it; [`parse_text`](Self::parse_text) reads it back
    /// exactly.
    fn show(&self) -> String;
}

/// One declared parameter: its [`ParamSpec`] (name, flag, unit, one-line meaning, range) and
/// what the front ends need beyond it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Declared {
    /// Name, flag, unit, meaning and accepted range.
    pub spec: ParamSpec,
    /// How the front ends read the value.
    pub kind: Kind,
    /// The full description for `--help` and the Python docstrings, plain text (the field's
    /// doc comment; its first sentence is [`ParamSpec::doc`]).
    pub help: &'static str,
    /// Why the range is what it is, added to the error message of a value outside it (empty
    /// for none).
    pub why: &'static str,
    /// Whether the command line requires the flag (the library's default is then only a
    /// library's convenience, not the binary's).
    pub required: bool,
    /// Whether the front ends leave the parameter unset by default (no value on the command
    /// line and in `--dump-config`, `None` in Python) so that giving it can be told from not
    /// giving it: for a parameter only some settings use, refused where it would be ignored.
    pub optional: bool,
    /// The Python stubs' type ([`ParamValue::PYTHON`]); empty for the kind's.
    pub python: &'static str,
    /// Help for each choice ([`ParamValue::CHOICE_HELP`]).
    pub choice_help: &'static [&'static str],
}

impl Declared {
    /// Whether a Python keyword of this parameter is None by default: an optional parameter,
    /// or one whose values Python takes in several forms (text, a number or a sequence: a
    /// [`Kind::Text`] or [`Kind::List`]), where None stands for its default.
    pub fn python_none(&self) -> bool {
        self.optional || matches!(self.kind, Kind::Text | Kind::List)
    }
}

/// The [`ParamSpec`]s of a declaration, as an array (`N` = `declared.len()`): the table
/// [`declare_params!`](crate::declare_params)'s `tables` clause writes,
/// `&spec_table::<{ Params::DECLARED.len() }>(Params::DECLARED)`.
pub const fn spec_table<const N: usize>(declared: &[Declared]) -> [ParamSpec; N] {
    assert!(N == declared.len() && N > 0);
    let mut out = [declared[0].spec; N];
    let mut i = 0;
    while i < N {
        out[i] = declared[i].spec;
        i += 1;
    }
    out
}

/// The first sentence of `text` (up to and including the first `. ` or the end).
pub const fn first_sentence(text: &'static str) -> &'static str {
    let b = text.as_bytes();
    let mut i = 0;
    while i + 1 < b.len() {
        if b[i] == b'.' && (b[i + 1] == b' ' || b[i + 1] == b'\n') {
            let (head, _) = b.split_at(i + 1);
            return ascii_cut(head);
        }
        i += 1;
    }
    text
}

/// A declared parameter's value outside its range, with the message every front end prints:
/// `--birth-gap 0.5 is outside the accepted range [1, 1e4] (why)`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RangeError {
    /// `--birth-gap` (or the name, for a parameter without a flag).
    pub flag: String,
    /// The value given, as a user would type it.
    pub value: String,
    /// The accepted range as the table writes it.
    pub range: String,
    /// The declaration's reason, possibly empty.
    pub why: &'static str,
}

impl RangeError {
    /// The error of `value` for parameter `d`.
    pub fn new(d: &Declared, value: String) -> Self {
        RangeError {
            flag: d.spec.flag_or_name(),
            value,
            range: d.spec.range.to_string(),
            why: d.why,
        }
    }
}

impl fmt::Display for RangeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} {} is outside the accepted range {}",
            self.flag, self.value, self.range
        )?;
        if !self.why.is_empty() {
            write!(f, " ({})", self.why)?;
        }
        Ok(())
    }
}

impl std::error::Error for RangeError {}

/// A model's declared parameters, implemented by [`declare_params!`](crate::declare_params):
/// what a generic front end needs to build its flags, keyword arguments and tables.
pub trait DeclaredParams: Default {
    /// Every parameter a front end sets, in declaration order.
    const DECLARED: &'static [Declared];
    /// Fields of the struct that are not parameters of a front end (set by the front end
    /// itself).
    const INTERNAL: &'static [&'static str];
    /// The first parameter outside its declared range, if any.
    fn check_ranges(&self) -> Result<(), RangeError>;
    /// Sets parameter `name` from a front end's input; `Ok(false)` if there is no such
    /// parameter.
    ///
    /// # Errors
    /// The input is not of the parameter's type (the message says what was expected).
    fn set(&mut self, name: &str, value: &Input) -> Result<bool, String>;
    /// Every field (internal ones too) as `(name, text)`, in declaration order: the
    /// self-describing form of [`as_text`] (checkpoints), which [`set_text`](Self::set_text)
    /// reads back exactly.
    fn to_text(&self) -> Vec<(&'static str, String)>;
    /// Sets field `name` (internal ones too) from its text; `Ok(false)` if there is no such
    /// field.
    ///
    /// # Errors
    /// The text is not a value of the field's type.
    fn set_text(&mut self, name: &str, text: &str) -> Result<bool, String>;
}

/// Declared parameters in a serde format as `[(name, text)]` pairs instead of a struct
/// (`#[serde(with = "core_lattice::spec::as_text")]`): in a positional format such as
/// bincode, a struct's layout changes with every added field, while these pairs still read
/// when parameters are added (they take their defaults) or reordered. Infinity and NaN keep
/// their values, which JSON would not. A name this build does not know is an error.
#[cfg(feature = "serde")]
pub mod as_text {
    use super::DeclaredParams;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Writes `p` as its `(name, text)` pairs.
    pub fn serialize<P: DeclaredParams, S: Serializer>(p: &P, s: S) -> Result<S::Ok, S::Error> {
        p.to_text().serialize(s)
    }

    /// Reads `(name, text)` pairs onto the defaults.
    pub fn deserialize<'de, P: DeclaredParams, D: Deserializer<'de>>(d: D) -> Result<P, D::Error> {
        let pairs = Vec::<(String, String)>::deserialize(d)?;
        let mut p = P::default();
        for (name, text) in &pairs {
            match p.set_text(name, text) {
                Ok(true) => {}
                Ok(false) => {
                    return Err(serde::de::Error::custom(format!(
                        "parameter {name} = {text} is not one this version knows (written by a newer one?)"
                    )));
                }
                Err(e) => return Err(serde::de::Error::custom(format!("{name}: {e}"))),
            }
        }
        Ok(p)
    }
}

/// `Some(x)` for one token tree, `None` for none (optional parts of a declaration).
#[doc(hidden)]
#[macro_export]
macro_rules! __declare_opt {
    () => {
        ""
    };
    ($x:expr) => {
        $x
    };
}

/// `false` for nothing, else the given value (optional parts of a declaration).
#[doc(hidden)]
#[macro_export]
macro_rules! __declare_flag {
    () => {
        false
    };
    ($x:expr) => {
        $x
    };
}

/// Declares a model's parameters once. From
///
/// ```
/// use core_lattice::spec::{End, Range};
/// core_lattice::declare_params! {
///     /// Parameters of a toy model.
///     #[derive(Debug, Clone, PartialEq)]
///     pub struct Toy {
///         /// Distance of the birth circle outside the cluster. Larger only wastes time.
///         birth_gap: f64 = 5.0 => {
///             flag: "birth-gap", unit: "diameters",
///             range: Range::Real(End::Closed(1.0), End::Closed(1e4)),
///             why: "a walker born closer could overlap the cluster",
///         },
///         /// Walkers moving at once.
///         threads: usize = 1 => { flag: "threads", unit: "walkers",
///             range: Range::Int { min: 1, max: Some(1024) } },
///     }
///     internal {
///         /// Kept by the front end.
///         keep: bool = false,
///     }
/// }
/// use core_lattice::spec::DeclaredParams;
/// assert_eq!(Toy::default().birth_gap, 5.0);
/// assert_eq!(Toy::DECLARED[0].spec.doc, "Distance of the birth circle outside the cluster.");
/// let bad = Toy { birth_gap: 0.5, ..Toy::default() };
/// assert_eq!(
///     bad.check_ranges().unwrap_err().to_string(),
///     "--birth-gap 0.5 is outside the accepted range [1, 1e4] (a walker born closer could overlap the cluster)"
/// );
/// ```
///
/// it writes the struct `Toy` (public fields with their doc comments, the attributes given),
/// `impl Default for Toy`, and [`DeclaredParams`] for `Toy`: the table
/// [`DECLARED`](DeclaredParams::DECLARED) (each field's name, flag, unit, range, the first
/// sentence of its doc as the one-line meaning and the whole doc as help, its [`Kind`] from
/// its type's [`ParamValue`]) and [`check_ranges`](DeclaredParams::check_ranges). Optional
/// per-field keys, in this order: `why` (the reason added to the range error), `required: true`
/// (the command line requires the flag) and `optional: true` ([`Declared::optional`]). Fields under `internal` are set by front ends, not
/// parameters of one. Doc comments are plain text: every front end shows them.
///
/// A model's library ends its declaration with `tables { const PARAMS; fn defaults; }`, which
/// writes, beside the struct and with its visibility, what the front ends read of the model
/// (the Python module, xtask, the binary's tests):
/// - `const PARAMS: &[ParamSpec]`, the [`ParamSpec`] of every parameter in declaration order
///   ([`DECLARED`](DeclaredParams::DECLARED) without what only the front ends need);
/// - `fn defaults() -> serde_json::Map<String, serde_json::Value>`, the default of every
///   parameter by name, compiled with the calling crate's feature `files`, which must bring
///   the crates `run_io` (with its feature `files`) and `serde_json`, and the struct must
///   implement `Serialize`.
///
/// The two names are the caller's.
#[macro_export]
macro_rules! declare_params {
    (
        $(#[$smeta:meta])*
        $vis:vis struct $name:ident {
            $(
                $(#[doc = $doc:literal])+
                $field:ident : $ty:ty = $default:expr => {
                    flag: $flag:literal, unit: $unit:literal, range: $range:expr
                    $(, why: $why:expr)?
                    $(, required: $required:expr)?
                    $(, optional: $optional:expr)?
                    $(,)?
                }
            ),+ $(,)?
        }
        internal {
            $(
                $(#[doc = $idoc:literal])+
                $ifield:ident : $ity:ty = $idefault:expr
            ),* $(,)?
        }
        $(tables { const $table:ident; fn $defaults:ident; })?
    ) => {
        $(#[$smeta])*
        $vis struct $name {
            $(
                $(#[doc = $doc])+
                pub $field: $ty,
            )+
            $(
                $(#[doc = $idoc])+
                pub $ifield: $ity,
            )*
        }

        impl ::core::default::Default for $name {
            fn default() -> Self {
                $name {
                    $($field: $default,)+
                    $($ifield: $idefault,)*
                }
            }
        }

        impl $crate::spec::DeclaredParams for $name {
            const DECLARED: &'static [$crate::spec::Declared] = &[
                $(
                    $crate::spec::Declared {
                        spec: $crate::spec::ParamSpec {
                            name: stringify!($field),
                            flag: Some($flag),
                            unit: $unit,
                            doc: $crate::spec::first_sentence(
                                $crate::spec::trim_doc(concat!($($doc, "\n"),+))
                            ),
                            range: $range,
                        },
                        kind: <$ty as $crate::spec::ParamValue>::KIND,
                        help: $crate::spec::trim_doc(concat!($($doc, "\n"),+)),
                        why: $crate::__declare_opt!($($why)?),
                        required: $crate::__declare_flag!($($required)?),
                        optional: $crate::__declare_flag!($($optional)?),
                        python: <$ty as $crate::spec::ParamValue>::PYTHON,
                        choice_help: <$ty as $crate::spec::ParamValue>::CHOICE_HELP,
                    },
                )+
            ];
            const INTERNAL: &'static [&'static str] = &[$(stringify!($ifield)),*];

            fn check_ranges(&self) -> ::core::result::Result<(), $crate::spec::RangeError> {
                let mut i = 0;
                $(
                    let d = &Self::DECLARED[i];
                    if !$crate::spec::ParamValue::in_range(&self.$field, &d.spec.range) {
                        return Err($crate::spec::RangeError::new(
                            d,
                            $crate::spec::ParamValue::show(&self.$field),
                        ));
                    }
                    i += 1;
                )+
                let _ = i;
                Ok(())
            }

            fn set(
                &mut self,
                name: &str,
                value: &$crate::spec::Input,
            ) -> ::core::result::Result<bool, String> {
                $(
                    if name == stringify!($field) {
                        self.$field = <$ty as $crate::spec::ParamValue>::from_input(value)?;
                        return Ok(true);
                    }
                )+
                Ok(false)
            }

            fn to_text(&self) -> Vec<(&'static str, String)> {
                vec![
                    $((stringify!($field), $crate::spec::ParamValue::show(&self.$field)),)+
                    $((stringify!($ifield), $crate::spec::ParamValue::show(&self.$ifield)),)*
                ]
            }

            fn set_text(
                &mut self,
                name: &str,
                text: &str,
            ) -> ::core::result::Result<bool, String> {
                $(
                    if name == stringify!($field) {
                        self.$field = <$ty as $crate::spec::ParamValue>::parse_text(text)?;
                        return Ok(true);
                    }
                )+
                $(
                    if name == stringify!($ifield) {
                        self.$ifield = <$ity as $crate::spec::ParamValue>::parse_text(text)?;
                        return Ok(true);
                    }
                )*
                Ok(false)
            }
        }

        $(
            #[doc = concat!(
                "Every parameter a front end sets, in declaration order: name, flag, unit, ",
                "meaning and accepted range, from [`", stringify!($name), "`]'s declaration ",
                "(its names are the config files' keys and the Python keywords)."
            )]
            $vis const $table: &[$crate::spec::ParamSpec] = &$crate::spec::spec_table::<
                { <$name as $crate::spec::DeclaredParams>::DECLARED.len() },
            >(<$name as $crate::spec::DeclaredParams>::DECLARED);

            #[doc = concat!(
                "The default of every parameter of [`", stringify!($table), "`], keyed by ",
                "name, from [`", stringify!($name), "::default`] (`null` for one unset by ",
                "default)."
            )]
            #[cfg(feature = "files")]
            $vis fn $defaults() -> ::serde_json::Map<::std::string::String, ::serde_json::Value> {
                ::run_io::params_json::defaults_of::<$name>()
            }
        )?
    };
}

/// A doc comment's text without the space each line starts with and the final newline: doc
/// comments reach a macro as `" line one"`, `" line two"`. Only the leading space of the first
/// line and trailing whitespace can be removed at compile time; the front ends read the text
/// with [`help_text`], which joins the lines.
pub const fn trim_doc(text: &'static str) -> &'static str {
    let b = text.as_bytes();
    let mut start = 0;
    while start < b.len() && b[start] == b' ' {
        start += 1;
    }
    let mut end = b.len();
    while end > start && (b[end - 1] == b'\n' || b[end - 1] == b' ') {
        end -= 1;
    }
    let (_, tail) = b.split_at(start);
    let (mid, _) = tail.split_at(end - start);
    ascii_cut(mid)
}

/// A piece of a `str` cut at ASCII characters back as a `str` (always valid UTF-8).
const fn ascii_cut(bytes: &'static [u8]) -> &'static str {
    match std::str::from_utf8(bytes) {
        Ok(s) => s,
        Err(_) => panic!("cut at an ASCII character"),
    }
}

/// A declaration's doc text as one paragraph: the lines joined by single spaces.
pub fn help_text(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::End;

    crate::declare_params! {
        /// A test model.
        #[derive(Debug, Clone, PartialEq)]
        pub struct Test {
            /// Gap in diameters. Second sentence
            /// on two lines.
            gap: f64 = 5.0 => {
                flag: "gap", unit: "diameters",
                range: Range::Real(End::Closed(1.0), End::Closed(1e4)), why: "because",
            },
            /// Walkers.
            threads: usize = 1 => { flag: "threads", unit: "", range: Range::Int { min: 1, max: Some(8) } },
            /// Side.
            side: f64 = 8.0 => { flag: "side", unit: "", range: Range::Values(&[1, 2, 4, 8]), required: true },
            /// On or off.
            on: bool = true => { flag: "on", unit: "", range: Range::Any },
        }
        internal {
            /// Hidden.
            keep: bool = false,
        }
    }

    #[test]
    fn a_declaration_gives_the_struct_the_table_and_the_checks() {
        let t = Test::default();
        assert_eq!(
            (t.gap, t.threads, t.side, t.on, t.keep),
            (5.0, 1, 8.0, true, false)
        );
        let names: Vec<&str> = Test::DECLARED.iter().map(|d| d.spec.name).collect();
        assert_eq!(names, ["gap", "threads", "side", "on"]);
        assert_eq!(Test::INTERNAL, ["keep"]);
        let g = &Test::DECLARED[0];
        assert_eq!(g.spec.doc, "Gap in diameters.");
        assert_eq!(
            help_text(g.help),
            "Gap in diameters. Second sentence on two lines."
        );
        assert_eq!((g.kind, g.why, g.required), (Kind::Real, "because", false));
        assert_eq!(Test::DECLARED[1].kind, Kind::Count);
        assert!(Test::DECLARED[2].required);
        assert_eq!(Test::DECLARED[3].kind, Kind::Switch);
        assert_eq!(t.check_ranges(), Ok(()));
        let e = Test {
            gap: 0.5,
            ..t.clone()
        }
        .check_ranges()
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "--gap 0.5 is outside the accepted range [1, 1e4] (because)"
        );
        let e = Test {
            threads: 9,
            ..t.clone()
        }
        .check_ranges()
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "--threads 9 is outside the accepted range 1..=8"
        );
        let e = Test {
            side: 3.0,
            ..t.clone()
        }
        .check_ranges()
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "--side 3 is outside the accepted range {1, 2, 4, 8}"
        );
        assert!(
            Test {
                gap: f64::NAN,
                ..t.clone()
            }
            .check_ranges()
            .is_err()
        );
        let mut u = t;
        assert_eq!(u.set("gap", &Input::Real(2.5)), Ok(true));
        assert_eq!(u.set("threads", &Input::Count(3)), Ok(true));
        assert_eq!(u.set("nothing", &Input::Count(3)), Ok(false));
        assert!(u.set("on", &Input::Count(3)).is_err());
        assert_eq!((u.gap, u.threads), (2.5, 3));
        // The text form reads back exactly, internal fields included.
        u.gap = f64::INFINITY;
        u.keep = true;
        let mut back = Test::default();
        for (name, text) in u.to_text() {
            assert_eq!(back.set_text(name, &text), Ok(true), "{name} = {text}");
        }
        assert_eq!(back, u);
        for x in [0.1, 1e-300, 1.0 / 3.0, 123456789.123, 1e300, -0.0] {
            assert_eq!(
                f64::parse_text(&x.show()).unwrap().to_bits(),
                x.to_bits(),
                "{x}"
            );
        }
    }

    #[test]
    fn values_are_checked_against_every_range_shape() {
        let open = Range::Real(End::Open(0.0), End::Closed(1.0));
        assert!(!0.0.in_range(&open) && 1.0.in_range(&open) && !1.0000001.in_range(&open));
        assert!(!f64::NAN.in_range(&Range::Real(End::Open(0.5), End::Unbounded)));
        assert!(f64::INFINITY.in_range(&Range::Real(End::Open(0.5), End::Unbounded)));
        assert!(2u64.in_range(&Range::Int { min: 2, max: None }));
        assert!(!1u64.in_range(&Range::Int { min: 2, max: None }));
        assert_eq!(first_sentence("One. Two."), "One.");
        assert_eq!(first_sentence("No stop"), "No stop");
        assert_eq!(
            first_sentence("R_b - R_ext, e.g.x. Then"),
            "R_b - R_ext, e.g.x."
        );
    }
}
