//! The checkpoint reader against corrupted, truncated and foreign files: always a typed error,
//! never a panic, never a wrong state.

use core_lattice::SimRng;
use core_lattice::rng::{RngExt, stream};
use proptest::prelude::*;
use run_io::checkpoint::{
    CheckpointError, FORMAT_VERSION, MAGIC, decode_checkpoint, encode_checkpoint,
};
use run_io::{read_checkpoint, write_checkpoint};
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct State {
    step: u64,
    rng: SimRng,
    positions: Vec<[f64; 2]>,
    label: String,
}

fn sample_state() -> State {
    let mut rng = stream(99, 3);
    let positions = (0..50).map(|i| [i as f64 * 0.5, -(i as f64)]).collect();
    let _: u64 = rng.random();
    State {
        step: 1234,
        rng,
        positions,
        label: "dla run".into(),
    }
}

#[test]
fn round_trip_through_a_file_restores_the_rng_stream() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("state.ckpt");
    let mut state = sample_state();
    write_checkpoint(&path, "dla", &state).unwrap();
    let mut back: State = read_checkpoint(&path, "dla").unwrap();
    assert_eq!(back, state);
    for _ in 0..10 {
        assert_eq!(back.rng.random::<u64>(), state.rng.random::<u64>());
    }
}

#[test]
fn typed_errors_for_each_kind_of_bad_file() {
    let good = encode_checkpoint("dla", &sample_state()).unwrap();

    // Foreign files.
    let png = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR";
    assert!(matches!(
        decode_checkpoint::<State>(png, "dla"),
        Err(CheckpointError::BadMagic)
    ));
    assert!(matches!(
        decode_checkpoint::<State>(b"{\"model\":1}", "dla"),
        Err(CheckpointError::BadMagic)
    ));
    assert!(matches!(
        decode_checkpoint::<State>(b"", "dla"),
        Err(CheckpointError::Truncated { .. })
    ));

    // Another model's checkpoint.
    match decode_checkpoint::<State>(&good, "dlca") {
        Err(CheckpointError::WrongModel { found, expected }) => {
            assert_eq!((found.as_str(), expected.as_str()), ("dla", "dlca"));
        }
        other => panic!("expected WrongModel, got {other:?}"),
    }

    // A future format version.
    let mut v2 = good.clone();
    v2[8..12].copy_from_slice(&(FORMAT_VERSION + 1).to_le_bytes());
    assert!(matches!(
        decode_checkpoint::<State>(&v2, "dla"),
        Err(CheckpointError::UnsupportedVersion { found, supported })
            if found == FORMAT_VERSION + 1 && supported == FORMAT_VERSION
    ));

    // One flipped payload bit.
    let mut flipped = good.clone();
    let mid = good.len() / 2;
    flipped[mid] ^= 0x10;
    assert!(matches!(
        decode_checkpoint::<State>(&flipped, "dla"),
        Err(CheckpointError::ChecksumMismatch { .. })
    ));

    // Truncated by one byte, and to just the header.
    assert!(matches!(
        decode_checkpoint::<State>(&good[..good.len() - 1], "dla"),
        Err(CheckpointError::Truncated { .. })
    ));
    assert!(matches!(
        decode_checkpoint::<State>(&good[..20], "dla"),
        Err(CheckpointError::Truncated { .. })
    ));

    // Trailing garbage.
    let mut long = good.clone();
    long.extend_from_slice(b"xx");
    assert!(matches!(
        decode_checkpoint::<State>(&long, "dla"),
        Err(CheckpointError::Malformed(_))
    ));

    // A valid envelope around a payload of another type.
    let other = encode_checkpoint("dla", &(1u8, 2u8)).unwrap();
    assert!(matches!(
        decode_checkpoint::<State>(&other, "dla"),
        Err(CheckpointError::Decode(_))
    ));

    // A header announcing an enormous payload: truncated, without trying to allocate it.
    let mut huge = good.clone();
    let at = 8 + 4 + 2 + 3;
    huge[at..at + 8].copy_from_slice(&u64::MAX.to_le_bytes());
    assert!(matches!(
        decode_checkpoint::<State>(&huge, "dla"),
        Err(CheckpointError::Truncated { .. })
    ));

    // A missing file is an I/O error.
    assert!(matches!(
        read_checkpoint::<State>("/nonexistent/x.ckpt", "dla"),
        Err(CheckpointError::Io(_))
    ));
    assert_eq!(&good[..8], &MAGIC);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    /// Any single corrupted byte is detected (an error, never a panic or a different state).
    #[test]
    fn any_corrupted_byte_is_rejected(pos in any::<prop::sample::Index>(), xor in 1u8..=255) {
        let good = encode_checkpoint("dla", &sample_state()).unwrap();
        let mut bad = good.clone();
        let i = pos.index(bad.len());
        bad[i] ^= xor;
        prop_assert!(decode_checkpoint::<State>(&bad, "dla").is_err());
    }

    /// Every truncation is an error.
    #[test]
    fn any_truncation_is_rejected(len in any::<prop::sample::Index>()) {
        let good = encode_checkpoint("dla", &sample_state()).unwrap();
        let cut = len.index(good.len());
        let r = decode_checkpoint::<State>(&good[..cut], "dla");
        prop_assert!(matches!(r, Err(CheckpointError::Truncated { .. }) | Err(CheckpointError::BadMagic)), "{:?}", r);
    }

    /// Random bytes, with or without the magic in front, never panic.
    #[test]
    fn random_files_never_panic(mut bytes in prop::collection::vec(any::<u8>(), 0..200), magic in any::<bool>()) {
        if magic {
            let mut v = MAGIC.to_vec();
            v.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
            v.append(&mut bytes);
            bytes = v;
        }
        prop_assert!(decode_checkpoint::<State>(&bytes, "dla").is_err());
    }
}
