//! Memory checked before the work (`sim_run::memory`): a `dla` run whose estimated peak does
//! not fit `--max-memory`, or the memory available, is refused with exit code 2 and one line;
//! the estimate bounds the measured peak RSS from above.

use dla_pdla::Params;
use sim_run::testing::{memory_contract, refusals};
use std::path::Path;

const DLA: &str = env!("CARGO_BIN_EXE_dla");

#[test]
fn a_run_that_cannot_fit_is_refused_and_the_estimate_bounds_the_peak() {
    let tmp = tempfile::tempdir().unwrap();
    let p = Params {
        particles: 300_000,
        ..Params::default()
    };
    let failures = memory_contract(
        Path::new(DLA),
        "dla",
        tmp.path(),
        &["--particles", "300000"],
        p.peak_memory_bytes(),
        2.0,
    );
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn a_run_larger_than_any_machine_is_refused_naming_the_memory_available() {
    let tmp = tempfile::tempdir().unwrap();
    // 2.5e9 particles in 5D: about 1.1 TB by the estimate, more than any test machine has.
    let cases: &[(&[&str], &str)] = &[
        (
            &["--dim", "5", "--particles", "2500000000", "--out", "o"],
            "of memory available",
        ),
        (
            &["--dim", "5", "--particles", "2500000000", "--out", "o"],
            "give --max-memory BYTES",
        ),
        (
            &[
                "--particles",
                "2900000000",
                "--max-memory",
                "24G",
                "--out",
                "o",
            ],
            "over --max-memory 24.0 GiB",
        ),
        (
            &["--particles", "1000", "--max-memory", "lots", "--out", "o"],
            "lots",
        ),
    ];
    let failures = refusals(Path::new(DLA), "dla", tmp.path(), cases);
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
