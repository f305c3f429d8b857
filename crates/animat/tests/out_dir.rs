//! `--out` belongs to one run: reruns, concurrent runs, stale locks, ensembles and
//! `--overwrite` (`run_cli::testing::ownership_contract`).

use std::path::Path;

#[test]
fn an_output_directory_belongs_to_one_run() {
    let dir = tempfile::tempdir().unwrap();
    run_cli::testing::ownership_contract(&run_cli::testing::Ownership {
        binary: Path::new(env!("CARGO_BIN_EXE_animat")),
        program: "animat",
        dir: dir.path(),
        flags: &[
            "--foxes",
            "30",
            "--rabbits",
            "300",
            "--start-radius",
            "30",
            "--steps",
            "20",
        ],
        change: ("--vision", "20", "30"),
        long: &[
            "--foxes",
            "300",
            "--rabbits",
            "3000",
            "--start-radius",
            "100",
            "--steps",
            "100000",
        ],
        checkpointed: &[
            "--foxes",
            "300",
            "--rabbits",
            "3000",
            "--start-radius",
            "100",
            "--steps",
            "400",
            "--seed",
            "5",
            "--checkpoint-every",
            "5",
        ],
    });
}
