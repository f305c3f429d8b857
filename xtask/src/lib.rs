//! Library behind `cargo xtask`: the scaling experiments that regenerate the papers' tables and
//! figures (`scaling`), the headline benchmarks (`bench`), DLA at the papers' scale (`scale`),
//! and the tables and plots they write.
//! The binary (`src/main.rs`) parses the command line and calls in here; the harness's own
//! test (`tests/scaling.rs`) runs it at a tiny size.

pub mod bench;
pub mod plot;
pub mod report;
pub mod scale;
pub mod scaling;

use std::path::PathBuf;

/// The workspace root (`xtask/` is one level below it).
pub fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask has a parent")
        .to_path_buf()
}

/// The cargo that runs us (`$CARGO`), or `cargo` from the path.
pub fn cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string())
}
