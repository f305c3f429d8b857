//! [`ParamValue`] for the types of declared parameters: reals, whole numbers, switches,
//! lists of names and `Option`s of them (a parameter that may be left unset, `none` as text).

use super::declare::{Input, Kind, ParamValue};
use super::{End, Range, show_number};

impl ParamValue for f64 {
    const KIND: Kind = Kind::Real;
    fn from_input(v: &Input) -> Result<Self, String> {
        match v {
            Input::Real(x) => Ok(*x),
            Input::Count(n) => Ok(*n as f64),
            other => Err(format!("expected a number, not {other:?}")),
        }
    }
    fn parse_text(s: &str) -> Result<Self, String> {
        s.parse().map_err(|_| format!("'{s}' is not a number"))
    }
    fn in_range(&self, range: &Range) -> bool {
        let v = *self;
        match range {
            Range::Real(lo, hi) => {
                let above = match lo {
                    End::Closed(a) => v >= *a,
                    End::Open(a) => v > *a,
                    End::Unbounded => !v.is_nan(),
                };
                let below = match hi {
                    End::Closed(b) => v <= *b,
                    End::Open(b) => v < *b,
                    End::Unbounded => !v.is_nan(),
                };
                above && below
            }
            Range::Int { min, max } => {
                v.fract() == 0.0 && v >= *min as f64 && max.is_none_or(|m| v <= m as f64)
            }
            Range::Values(vals) => vals.iter().any(|&x| x as f64 == v),
            Range::Any | Range::Choices(_) | Range::Text(_) => !v.is_nan(),
        }
    }
    /// As a user would type it: `0.25`, `1001`, `1000000000`; the exponent form for the very
    /// small and large (`1e-300`, `1e300`).
    fn show(&self) -> String {
        let (v, a) = (*self, self.abs());
        if a != 0.0 && a.is_finite() && !(1e-4..1e15).contains(&a) {
            format!("{v:e}")
        } else if v.is_infinite() {
            show_number(v)
        } else {
            v.to_string()
        }
    }
}

macro_rules! whole_number {
    ($($t:ty),*) => {$(
        impl ParamValue for $t {
            const KIND: Kind = Kind::Count;
            fn from_input(v: &Input) -> Result<Self, String> {
                match v {
                    Input::Count(n) => <$t>::try_from(*n)
                        .map_err(|_| format!("{n} is too large (at most {})", <$t>::MAX)),
                    other => Err(format!("expected a whole number, not {other:?}")),
                }
            }
            fn parse_text(s: &str) -> Result<Self, String> {
                s.parse().map_err(|_| format!("'{s}' is not a whole number"))
            }
            fn in_range(&self, range: &Range) -> bool {
                let v = *self as i128;
                match range {
                    Range::Int { min, max } => v >= *min && max.is_none_or(|m| v <= m),
                    Range::Values(vals) => vals.iter().any(|&x| x as i128 == v),
                    Range::Real(..) => (*self as f64).in_range(range),
                    Range::Any | Range::Choices(_) | Range::Text(_) => true,
                }
            }
            fn show(&self) -> String {
                self.to_string()
            }
        }
    )*};
}
// `i64` for the parameters a model stores signed (radii it subtracts from coordinates); the
// front ends still read them as non-negative counts.
whole_number!(u32, u64, usize, i64);

impl ParamValue for bool {
    const KIND: Kind = Kind::Switch;
    fn from_input(v: &Input) -> Result<Self, String> {
        match v {
            Input::Switch(b) => Ok(*b),
            other => Err(format!("expected on or off, not {other:?}")),
        }
    }
    fn parse_text(s: &str) -> Result<Self, String> {
        match s {
            "on" => Ok(true),
            "off" => Ok(false),
            other => Err(format!("'{other}' is not on or off")),
        }
    }
    fn in_range(&self, _: &Range) -> bool {
        true
    }
    fn show(&self) -> String {
        if *self { "on".into() } else { "off".into() }
    }
}

/// A parameter that may be left unset: `None` by default in the front ends that can tell
/// (no value on the command line, `None` in Python), `none` as text.
impl<T: ParamValue> ParamValue for Option<T> {
    const KIND: Kind = T::KIND;
    const PYTHON: &'static str = T::PYTHON;
    const CHOICE_HELP: &'static [&'static str] = T::CHOICE_HELP;
    fn from_input(v: &Input) -> Result<Self, String> {
        T::from_input(v).map(Some)
    }
    fn parse_text(s: &str) -> Result<Self, String> {
        match s {
            "none" => Ok(None),
            s => T::parse_text(s).map(Some),
        }
    }
    fn in_range(&self, range: &Range) -> bool {
        self.as_ref().is_none_or(|v| v.in_range(range))
    }
    fn show(&self) -> String {
        self.as_ref()
            .map_or_else(|| "none".into(), ParamValue::show)
    }
}

/// A list of names (`eat,breed,wander`): each item is one of the declaration's
/// [`Range::Choices`], which the model's validation checks (with its own message for an unknown
/// or repeated name); the empty text is the empty list.
impl ParamValue for Vec<String> {
    const KIND: Kind = Kind::List;
    const PYTHON: &'static str = "Sequence[str]";
    fn from_input(v: &Input) -> Result<Self, String> {
        match v {
            Input::Text(s) => Self::parse_text(s),
            other => Err(format!("expected names separated by commas, not {other:?}")),
        }
    }
    fn parse_text(s: &str) -> Result<Self, String> {
        if s.trim().is_empty() {
            return Ok(Vec::new());
        }
        Ok(s.split(',').map(|x| x.trim().to_string()).collect())
    }
    fn in_range(&self, _: &Range) -> bool {
        true
    }
    fn show(&self) -> String {
        self.join(",")
    }
}
