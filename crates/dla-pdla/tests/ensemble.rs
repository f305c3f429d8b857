//! `dla --seeds`: members run, fail alone, restart, and combine (`ensemble.json`), and
//! `--merge` rebuilds the combined result.

use std::path::Path;

#[test]
fn ensembles_run_combine_restart_and_merge() {
    let dir = tempfile::tempdir().unwrap();
    core_lattice::testing::ensemble_contract(
        Path::new(env!("CARGO_BIN_EXE_dla")),
        "dla",
        dir.path(),
        &["--particles", "300"],
        "radius_of_gyration",
    );
}
