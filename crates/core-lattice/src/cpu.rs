//! The processor features a build relies on, checked at run time.
//!
//! On x86-64 the workspace builds for the `x86-64-v3` level (AVX2, FMA, BMI1/2, LZCNT, MOVBE;
//! Intel from Haswell, 2013, AMD from Excavator and Zen), set in `.cargo/config.toml`: the DLA
//! kernels then execute about 0.8 times the instructions of a baseline build, with identical
//! results (Rust does not contract or reorder floating-point operations, so the state hashes do
//! not change). A binary run on a processor without those features would die of an illegal
//! instruction somewhere in a run; [`unsupported`] lets the binaries and the Python module
//! refuse to start instead, with a message saying how to rebuild
//! (`RUSTFLAGS="-C target-cpu=native"` replaces the configured level).

/// The features this build was compiled to use that the running processor lacks (empty on
/// any other architecture, and whenever the build targets the baseline).
pub fn missing_features() -> Vec<&'static str> {
    #[allow(unused_mut)]
    let mut missing = Vec::new();
    #[cfg(target_arch = "x86_64")]
    {
        macro_rules! need {
            ($($f:tt),*) => {$(
                if cfg!(target_feature = $f) && !std::arch::is_x86_feature_detected!($f) {
                    missing.push($f);
                }
            )*};
        }
        need!(
            "sse3", "ssse3", "sse4.1", "sse4.2", "popcnt", "avx", "avx2", "fma", "bmi1", "bmi2",
            "lzcnt", "movbe", "f16c"
        );
    }
    missing
}

/// `None` when the processor runs this build; else a one-line explanation naming the missing
/// features and how to rebuild for this processor.
pub fn unsupported() -> Option<String> {
    let missing = missing_features();
    (!missing.is_empty()).then(|| explain(&missing))
}

/// The message for the `missing` features.
fn explain(missing: &[&str]) -> String {
    format!(
        "this build uses processor features this CPU lacks ({}); rebuild for it with \
         RUSTFLAGS=\"-C target-cpu=native\" (README, \"Install\")",
        missing.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_build_runs_on_the_machine_that_tests_it() {
        // The tests run on the machine that built them; a missing feature here means the
        // configured level is wrong for it, and the test binary would already have been at risk.
        assert_eq!(missing_features(), Vec::<&str>::new());
        assert_eq!(unsupported(), None);
    }

    #[test]
    fn the_message_names_the_features_and_the_fix() {
        let m = explain(&["avx2", "fma"]);
        assert!(m.contains("(avx2, fma)"), "{m}");
        assert!(m.contains("target-cpu=native"), "{m}");
        assert!(!m.contains('\n'), "{m}");
    }
}
