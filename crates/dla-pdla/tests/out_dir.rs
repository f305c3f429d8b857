//! `--out` belongs to one run: reruns, concurrent runs, stale locks, ensembles and
//! `--overwrite` (`run_cli::testing::ownership_contract`).

use std::path::Path;

#[test]
fn an_output_directory_belongs_to_one_run() {
    let dir = tempfile::tempdir().unwrap();
    run_cli::testing::ownership_contract(&run_cli::testing::Ownership {
        binary: Path::new(env!("CARGO_BIN_EXE_dla")),
        program: "dla",
        dir: dir.path(),
        flags: &["--threads", "1"],
        change: ("--particles", "200", "300"),
        long: &["--particles", "3000000"],
        checkpointed: &[
            "--particles",
            "150000",
            "--seed",
            "9",
            "--checkpoint-every",
            "20000",
        ],
    });
}
