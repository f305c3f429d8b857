//! Long runs are safe without a flag: a signal at a random moment of a `dlca` run started with
//! no checkpoint flag checkpoints it (exit code 130), memory about to run out does too (exit
//! code 1), and `--resume` ends it with the uninterrupted run's state hash; a run that ends
//! normally leaves no `checkpoint.bin`.

use run_cli::testing::stop_contract;
use std::path::Path;

#[test]
fn every_stop_is_a_checkpoint_and_resumes_to_the_uninterrupted_run() {
    let dir = tempfile::tempdir().unwrap();
    let failures = stop_contract(
        Path::new(env!("CARGO_BIN_EXE_dlca")),
        "dlca",
        dir.path(),
        &[
            "--size",
            "512",
            "--fill",
            "0.05",
            "--target-clusters",
            "1",
            "-qq",
        ],
        &[],
    );
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
