//! Helpers shared by the property tests of this directory.

// Each test crate that includes this module uses only part of it.
#![allow(dead_code)]

use proptest::test_runner::Config;

/// Proptest configuration: `cases` per property; no regression files are written (the
/// failing input is printed instead).
pub fn config(cases: u32) -> Config {
    Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    }
}

/// Far-away and extreme coordinates: the ends of `i64` and `+-2^40`, where a difference or a
/// square of coordinates overflows unless computed wide.
pub const EXTREME: [i64; 6] = [
    i64::MIN,
    i64::MIN + 1,
    i64::MAX,
    i64::MAX - 1,
    -(1i64 << 40),
    1i64 << 40,
];
