//! Memory checked before the work (`run_io::memory`): a `dla` run whose estimated peak does
//! not fit `--max-memory`, or the memory available, is refused with exit code 2 and one line;
//! the estimate bounds the measured peak RSS from above.

use dla_pdla::Params;
use run_cli::testing::{memory_contract, refusals};
use std::path::Path;

const DLA: &str = env!("CARGO_BIN_EXE_dla");

#[test]
fn a_run_that_cannot_fit_is_refused_and_the_estimate_bounds_the_peak() {
    let tmp = tempfile::tempdir().unwrap();
    // The binary's default streams the positions for its checkpoints, and the parents with
    // them.
    let p = Params {
        particles: 300_000,
        connectivity: true,
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
            "than the machine's",
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

/// An allocation the system refuses while the cluster grows (the check waved through with
/// `--max-memory`, the process's address space capped at 32 MiB with `ulimit -v`) ends the run
/// with exit code 1 and one line `dla: run failed: ... cannot allocate N bytes ...`, not an
/// abort.
#[cfg(unix)]
#[test]
fn a_refused_allocation_while_growing_is_one_line_and_exit_code_1() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let o = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v 32768 && exec '{DLA}' --particles 1e8 --max-memory 1T -q --out '{}'",
            out.display()
        ))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(
        lines[0].starts_with("dla: run failed: ") && lines[0].contains("cannot allocate"),
        "{stderr}"
    );
}
