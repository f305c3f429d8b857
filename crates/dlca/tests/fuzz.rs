//! Fuzz target of `dlca`'s reader of user files (`run_cli::fuzz`): `--resume DIR` reads
//! `checkpoint.bin` (the envelope, the snapshot and its checks in `Simulation::restore`).
//! Arbitrary bytes and mutations of a valid checkpoint (its checksum made right again, so the
//! state's decoding is reached) give a typed error or a valid simulation, never a panic, a
//! hang or an allocation sized by a corrupted field. `cargo xtask fuzz` runs many more cases.

use core_lattice::Boundary;
use dlca::params::Init;
use dlca::{Params, Simulation, Snapshot};
use proptest::prelude::*;
use run_cli::fuzz::{cases, checkpoint_payload, mutate, seal_checkpoint};
use run_io::checkpoint::{decode_checkpoint, encode_checkpoint};
use std::sync::OnceLock;

fn valid_checkpoint() -> &'static Vec<u8> {
    static CK: OnceLock<Vec<u8>> = OnceLock::new();
    CK.get_or_init(|| {
        let p = Params {
            size: vec![32, 32],
            boundary: vec![Boundary::Periodic; 2],
            init: Init::Fill(0.1),
            target_clusters: 1,
            ..Params::default()
        };
        let mut sim = Simulation::new(p, 1).unwrap();
        for _ in 0..3 {
            sim.sweep();
        }
        encode_checkpoint("dlca", &sim.snapshot()).unwrap()
    })
}

fn restore(bytes: &[u8]) {
    if let Ok(snapshot) = decode_checkpoint::<Snapshot>(bytes, "dlca") {
        if let Ok(mut sim) = Simulation::restore(snapshot) {
            // A restored run must be one that sweeps.
            sim.sweep();
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    /// `--resume`: the checkpoint envelope and the run inside it.
    #[test]
    fn fuzz_dlca_checkpoint(raw in proptest::collection::vec(any::<u8>(), 0..256), seed in any::<u64>()) {
        case(&raw, seed);
    }
}

/// One case of [`fuzz_dlca_checkpoint`]: `raw` as a checkpoint, and the valid checkpoint
/// mutated by `seed` (envelope, and payload with the checksum made right).
fn case(raw: &[u8], seed: u64) {
    let ck = valid_checkpoint();
    restore(raw);
    restore(&mutate(ck, seed));
    let payload = mutate(&checkpoint_payload(ck, "dlca"), seed);
    restore(&seal_checkpoint("dlca", &payload));
}

/// Crashes the fuzz target found, kept as regression tests.
#[test]
fn crashes_found_by_fuzzing() {
    // A string length in the payload corrupted to about 2^60: bincode sized a buffer by it
    // ("capacity overflow"); now the checkpoint reader's limit refuses it.
    case(&[], 1658920118555556181);
    // A cluster with a site outside the lattice (SiteSets::push asserted, found with the
    // default cases): now refused by the snapshot's check. Every byte of the payload in turn
    // set to bincode's marker of a wider varint, which makes one number larger.
    let mut bytes = checkpoint_payload(valid_checkpoint(), "dlca");
    for i in 0..bytes.len() {
        let keep = bytes[i];
        bytes[i] = 0xFB; // bincode's varint marker of a u16: a larger number than was there
        restore(&seal_checkpoint("dlca", &bytes));
        bytes[i] = keep;
    }
}

#[test]
fn the_valid_checkpoint_restores() {
    let snapshot = decode_checkpoint::<Snapshot>(valid_checkpoint(), "dlca").unwrap();
    assert!(Simulation::restore(snapshot).is_ok());
}
