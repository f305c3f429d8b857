//! Memory checked before the work (`run_io::memory`): a `dlca` run whose estimated peak does
//! not fit `--max-memory` (when given), or the memory available, is refused with exit code 2
//! and one line; the estimate bounds the measured peak RSS from above.

use core_lattice::Boundary;
use dlca::Params;
use dlca::params::Init;
use run_cli::testing::{memory_contract, refusals};
use std::path::Path;

const DLCA: &str = env!("CARGO_BIN_EXE_dlca");

#[test]
fn a_run_that_cannot_fit_is_refused_and_the_estimate_bounds_the_peak() {
    let tmp = tempfile::tempdir().unwrap();
    let p = Params {
        size: vec![1024, 1024],
        boundary: vec![Boundary::Periodic; 2],
        init: Init::Fill(0.05),
        max_sweeps: Some(3),
        ..Params::default()
    };
    let failures = memory_contract(
        Path::new(DLCA),
        "dlca",
        tmp.path(),
        &["--size", "1024", "--fill", "0.05", "--max-sweeps", "3"],
        dlca::sim::peak_memory_bytes(&p),
        2.0,
    );
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn a_run_larger_than_any_machine_is_refused_naming_the_memory_available() {
    let tmp = tempfile::tempdir().unwrap();
    // The lattice of 3.6e9 sites half filled: about 400 GB by the estimate (it used to abort
    // with "memory allocation of 36507222032 bytes failed" and a backtrace).
    let cases: &[(&[&str], &str)] = &[
        (
            &["--size", "60000", "--fill", "0.5", "--out", "o"],
            "of memory available",
        ),
        (
            &["--size", "60000", "--fill", "0.5", "--out", "o"],
            "than the machine's",
        ),
    ];
    let failures = refusals(Path::new(DLCA), "dlca", tmp.path(), cases);
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
