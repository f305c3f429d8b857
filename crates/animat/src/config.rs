//! Reading parameters from a TOML config file (`--config FILE.toml`, `data/animat-default.toml`).
//! Library functionality rather than part of the binary, so every front end reads the same
//! format with the same errors.
//!
//! Invariants: keys not given keep their defaults ([`Params::default`]); unknown keys and
//! values of the wrong type are errors naming the line; nothing here validates ranges (that is
//! [`Params::validate`]).

use crate::params::Params;
use std::path::Path;

/// Errors reading a config file; each displays as one line.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The file could not be read.
    #[error("cannot read config {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// Malformed TOML, an unknown key or a value of the wrong type.
    #[error("config {path}, line {line}: {message}")]
    Parse {
        /// The file.
        path: String,
        /// 1-based line of the error (0 when unknown).
        line: usize,
        /// The parser's message, folded onto one line.
        message: String,
    },
}

/// Parses config text; `path` names it in errors. Keys not given keep their defaults.
///
/// # Errors
/// [`ConfigError::Parse`] with the 1-based line number of the problem.
pub fn parse_config(text: &str, path: &str) -> Result<Params, ConfigError> {
    toml::from_str::<Params>(text).map_err(|e| {
        let line = e.span().map_or(0, |s| {
            text[..s.start.min(text.len())].matches('\n').count() + 1
        });
        ConfigError::Parse {
            path: path.to_string(),
            line,
            message: e.message().split_whitespace().collect::<Vec<_>>().join(" "),
        }
    })
}

/// `params` as a config file that [`parse_config`] reads back to the same parameters, with a
/// header saying what it is.
///
/// # Errors
/// A parameter TOML cannot represent (none of the current ones).
pub fn to_toml(params: &Params) -> Result<String, toml::ser::Error> {
    Ok(format!(
        "# animat model parameters (read with --config; --steps and --seed are flags)\n{}",
        toml::to_string(params)?
    ))
}

/// Reads and parses a config file (not validated: call [`Params::validate`]).
///
/// # Errors
/// [`ConfigError`] if the file cannot be read or parsed.
pub fn read_config(path: &Path) -> Result<Params, ConfigError> {
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Io {
        path: shown.clone(),
        source,
    })?;
    parse_config(&text, &shown)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partial_config_keeps_defaults() {
        let p = parse_config(
            "foxes = 7\ngrid_box = \"none\"\nfox_rules = [\"wander\"]\n",
            "t",
        )
        .unwrap();
        assert_eq!(p.foxes, 7);
        assert_eq!(p.grid_box, crate::GridBox::None);
        assert_eq!(p.rabbits, Params::default().rabbits);
    }

    #[test]
    fn errors_have_line_numbers_and_one_line() {
        let e = parse_config("foxes = 7\n\nwolves = 3\n", "t")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("config t, line 3: unknown field `wolves`"),
            "{e}"
        );
        assert!(!e.contains('\n'));
        let e = parse_config("foxes = 7\nrabbits = = 2\n", "t")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("config t, line 2:"), "{e}");
        assert!(!e.contains('\n'));
    }

    #[test]
    fn shipped_config_reproduces_the_defaults() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/animat-default.toml");
        assert_eq!(read_config(&path).unwrap(), Params::default());
    }
}
