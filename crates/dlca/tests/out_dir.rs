//! `--out` belongs to one run: reruns, concurrent runs, stale locks, ensembles and
//! `--overwrite` (`run_cli::testing::ownership_contract`).

use std::path::Path;

#[test]
fn an_output_directory_belongs_to_one_run() {
    let dir = tempfile::tempdir().unwrap();
    run_cli::testing::ownership_contract(&run_cli::testing::Ownership {
        binary: Path::new(env!("CARGO_BIN_EXE_dlca")),
        program: "dlca",
        dir: dir.path(),
        flags: &["--size", "32", "--fill", "0.1"],
        change: ("--target-clusters", "4", "5"),
        long: &["--size", "2048", "--fill", "0.05", "--target-clusters", "1"],
        checkpointed: &[
            "--size",
            "512",
            "--fill",
            "0.03",
            "--target-clusters",
            "1",
            "--seed",
            "4",
            "--checkpoint-every",
            "50",
        ],
    });
}
