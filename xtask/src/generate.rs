//! `cargo xtask generate`: the files written from the models' parameter declarations
//! (`core_lattice::declare_params!`): each model's flag table in its docs and its keyword
//! arguments in the Python stub (for DLCA and the animats twice: `aggsim.dlca` and
//! `aggsim.DlcaLattice`, `aggsim.animat` and `aggsim.AnimatWorld`),
//! between their marker lines. `xtask/tests/generated.rs` (in
//! the test suite, so in CI) fails when a file is not what this would write.

use anyhow::{Context, Result};
use run_cli::declared::{Plain, docs_table, docs_table_in, pyi_keywords, replace_generated};
use std::path::Path;

/// Parameters `aggsim.dla` takes as its own arguments (by position too), not among the
/// keywords generated from the declaration (`python/src/dla.rs`, `POSITIONAL`; the Python tests
/// compare the stub with the real signature).
pub const DLA_PYTHON_POSITIONAL: &[&str] = &["dim", "particles", "threads"];

/// Parameters `aggsim.dlca` and `aggsim.DlcaLattice` take as their own arguments
/// (`python/src/dlca/mod.rs`, `POSITIONAL`).
pub const DLCA_PYTHON_POSITIONAL: &[&str] = &["dim", "size", "fill", "particles"];

/// One generated block: the file (from the workspace root), the block's name, the file's
/// comment leader (`<!--` for Markdown) and the text.
pub struct Block {
    /// File, relative to the workspace root.
    pub file: &'static str,
    /// Name on the marker lines.
    pub name: &'static str,
    /// `#` or `<!--`.
    pub comment: &'static str,
    /// What belongs between the markers.
    pub text: String,
}

/// Parameters `aggsim.animat` and `aggsim.AnimatWorld` take as their own arguments: none (the
/// model's are all keywords; `steps`, `seed` and `density` are not declared parameters).
pub const ANIMAT_PYTHON_POSITIONAL: &[&str] = &[];

/// Keyword arguments as a method's, one level further in.
fn method(keywords: String) -> String {
    keywords.lines().map(|l| format!("    {l}\n")).collect()
}

/// Every generated block of the workspace.
pub fn blocks() -> Vec<Block> {
    vec![
        Block {
            file: "docs/dla.md",
            name: "dla-params",
            comment: "<!--",
            text: docs_table::<dla_pdla::Params>(),
        },
        Block {
            file: "python/aggsim/__init__.pyi",
            name: "dla-keywords",
            comment: "#",
            text: pyi_keywords::<dla_pdla::Params>(DLA_PYTHON_POSITIONAL),
        },
        Block {
            file: "docs/dlca.md",
            name: "dlca-params",
            comment: "<!--",
            text: docs_table_in::<dlca::params::Settings, Plain>(),
        },
        Block {
            file: "python/aggsim/__init__.pyi",
            name: "dlca-keywords",
            comment: "#",
            text: pyi_keywords::<dlca::params::Settings>(DLCA_PYTHON_POSITIONAL),
        },
        Block {
            file: "python/aggsim/__init__.pyi",
            name: "dlca-lattice-keywords",
            comment: "#",
            text: method(pyi_keywords::<dlca::params::Settings>(
                DLCA_PYTHON_POSITIONAL,
            )),
        },
        Block {
            file: "docs/animat.md",
            name: "animat-params",
            comment: "<!--",
            text: docs_table::<animat::Params>(),
        },
        Block {
            file: "python/aggsim/__init__.pyi",
            name: "animat-keywords",
            comment: "#",
            text: pyi_keywords::<animat::Params>(ANIMAT_PYTHON_POSITIONAL),
        },
        Block {
            file: "python/aggsim/__init__.pyi",
            name: "animat-world-keywords",
            comment: "#",
            text: method(pyi_keywords::<animat::Params>(ANIMAT_PYTHON_POSITIONAL)),
        },
    ]
}

/// Rewrites every generated block under `root`; returns the files that changed.
pub fn run(root: &Path) -> Result<Vec<&'static str>> {
    let mut changed = Vec::new();
    for b in blocks() {
        let path = root.join(b.file);
        let text = std::fs::read_to_string(&path).with_context(|| b.file.to_string())?;
        let new = replace_generated(&text, b.name, b.comment, &b.text)
            .with_context(|| format!("{}: no marker lines for {}", b.file, b.name))?;
        if new != text {
            std::fs::write(&path, new).with_context(|| b.file.to_string())?;
            changed.push(b.file);
        }
    }
    Ok(changed)
}
