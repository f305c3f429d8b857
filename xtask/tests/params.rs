//! The flags xtask passes to the model binaries against the libraries' parameter tables: a
//! renamed or removed parameter fails here rather than in a long experiment.

use core_lattice::spec::ParamSpec;
use xtask::bench::WORKLOADS;

/// Flags of every binary that are not model parameters.
const RUN_FLAGS: &[&str] = &[
    "seed",
    "seeds",
    "jobs",
    "out",
    "heartbeat",
    "quiet",
    "positions",
    "png",
    "timing",
    "steps",
    "paper-settings",
    "checkpoint-every",
    "resume",
    "config",
    // animat's: sets the declared start_radius from the start population.
    "density",
];

fn params(bin: &str) -> &'static [ParamSpec] {
    match bin {
        "dla" => dla_pdla::params::PARAMS,
        "dlca" => dlca::params::PARAMS,
        "animat" => animat::params::PARAMS,
        other => panic!("unknown binary {other}"),
    }
}

fn check(bin: &str, arg: &str, origin: &str) {
    let Some(flag) = arg.strip_prefix("--") else {
        return;
    };
    let flag = flag.split('=').next().unwrap_or_default();
    assert!(
        RUN_FLAGS.contains(&flag) || params(bin).iter().any(|s| s.flag == Some(flag)),
        "{origin} passes --{flag} to `{bin}`, which is not one of its parameters"
    );
}

#[test]
fn benchmark_workloads_pass_parameters_the_binaries_have() {
    for w in WORKLOADS {
        for a in w.arg_list() {
            check(w.bin, a, w.name);
        }
    }
}

/// Every `"--flag` literal in the experiments that drive one binary.
#[test]
fn experiments_pass_parameters_the_binaries_have() {
    let sources = [
        (
            "dla",
            "scaling/dla.rs",
            include_str!("../src/scaling/dla.rs"),
        ),
        (
            "dla",
            "scaling/accuracy/sweep.rs",
            include_str!("../src/scaling/accuracy/sweep.rs"),
        ),
        (
            "dla",
            "scaling/accuracy/setting.rs",
            include_str!("../src/scaling/accuracy/setting.rs"),
        ),
        ("dla", "scale.rs", include_str!("../src/scale.rs")),
        (
            "dlca",
            "scaling/dlca.rs",
            include_str!("../src/scaling/dlca.rs"),
        ),
    ];
    for (bin, file, text) in sources {
        let mut found = 0;
        for piece in text.split("\"--").skip(1) {
            let flag: String = piece
                .chars()
                .take_while(|c| c.is_ascii_lowercase() || *c == '-')
                .collect();
            check(bin, &format!("--{flag}"), file);
            found += 1;
        }
        assert!(found > 0, "{file}: no flags found");
    }
}
