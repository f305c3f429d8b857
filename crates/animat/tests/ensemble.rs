//! `animat --seeds`: members run, fail alone, restart, and combine (`ensemble.json`), and
//! `--merge` rebuilds the combined result.

use std::path::Path;

#[test]
fn ensembles_run_combine_restart_and_merge() {
    let dir = tempfile::tempdir().unwrap();
    run_cli::testing::ensemble_contract(
        Path::new(env!("CARGO_BIN_EXE_animat")),
        "animat",
        dir.path(),
        &[
            "--foxes",
            "20",
            "--rabbits",
            "200",
            "--start-radius",
            "20",
            "--steps",
            "20",
        ],
        "rabbits",
    );
}
