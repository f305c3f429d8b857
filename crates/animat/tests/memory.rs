//! Memory checked before the work (`run_io::memory`): an `animat` run whose estimated start
//! does not fit `--max-memory` (4 GiB, or the memory available if less, by default) is refused
//! with exit code 2 and one line; the estimate bounds the measured peak RSS from above.

use animat::Params;
use run_cli::testing::memory_contract;
use std::path::Path;

const ANIMAT: &str = env!("CARGO_BIN_EXE_animat");

#[test]
fn a_run_that_cannot_fit_is_refused_and_the_estimate_bounds_the_peak() {
    let tmp = tempfile::tempdir().unwrap();
    // A dilute start (one tile of the cell index per animat), short enough not to grow.
    let mut p = Params {
        foxes: 1000,
        rabbits: 9000,
        ..Params::default()
    };
    p.set_density(0.001).unwrap();
    let failures = memory_contract(
        Path::new(ANIMAT),
        "animat",
        tmp.path(),
        &[
            "--foxes",
            "1000",
            "--rabbits",
            "9000",
            "--density",
            "0.001",
            "--steps",
            "5",
        ],
        p.peak_memory_bytes(),
        2.0,
    );
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
