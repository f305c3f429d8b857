//! Fuzz targets of `dla`'s readers of user files (`run_cli::fuzz`): `--resume DIR` reads
//! `checkpoint.bin` (the envelope and the model's state) and `positions.npy`. Arbitrary bytes
//! and mutations of a valid run's files (with the checkpoint's checksum made right again, so
//! the state's decoding and checks are reached) give a typed error or a valid run, never a
//! panic, a hang or an allocation sized by a corrupted field. `cargo xtask fuzz` runs many
//! more cases.

use dla_pdla::{Params, Simulation};
use proptest::prelude::*;
use run_cli::fuzz::{cases, checkpoint_payload, mutate, seal_checkpoint};
use std::path::Path;
use std::sync::OnceLock;

/// `checkpoint.bin` and `positions.npy` of a 2D run of 300 particles checkpointed at 200.
fn valid_files() -> &'static (Vec<u8>, Vec<u8>) {
    static FILES: OnceLock<(Vec<u8>, Vec<u8>)> = OnceLock::new();
    FILES.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let params = Params {
            particles: 300,
            ..Params::default()
        };
        let mut sim = Simulation::<2>::new(params, 5).unwrap();
        sim.stream_into(dir.path(), true).unwrap();
        let stop = std::sync::atomic::AtomicBool::new(false);
        sim.run_checkpointed(200, &stop, &|_| {}).unwrap();
        (
            std::fs::read(dir.path().join("checkpoint.bin")).unwrap(),
            std::fs::read(dir.path().join("positions.npy")).unwrap(),
        )
    })
}

fn resume(dir: &Path, checkpoint: &[u8], positions: &[u8]) {
    std::fs::write(dir.join("checkpoint.bin"), checkpoint).unwrap();
    std::fs::write(dir.join("positions.npy"), positions).unwrap();
    let _ = Simulation::<2>::resume(dir, None);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    /// `--resume`: the checkpoint envelope, the state inside it, and `positions.npy`.
    #[test]
    fn fuzz_dla_resume(raw in proptest::collection::vec(any::<u8>(), 0..256), seed in any::<u64>()) {
        case(&raw, seed);
    }
}

/// One case of [`fuzz_dla_resume`]: one damaged input, chosen by `seed`, resumed.
fn case(raw: &[u8], seed: u64) {
    // One damaged input per case (a resume that succeeds builds the cluster's maps).
    let (ck, npy) = valid_files();
    let dir = tempfile::tempdir().unwrap();
    match seed % 4 {
        0 => resume(dir.path(), raw, npy),
        1 => resume(dir.path(), &mutate(ck, seed), npy),
        2 => {
            let payload = mutate(&checkpoint_payload(ck, "dla"), seed);
            resume(dir.path(), &seal_checkpoint("dla", &payload), npy);
        }
        _ => resume(dir.path(), ck, &mutate(npy, seed)),
    }
}

/// Crashes the fuzz target found, kept as regression tests.
#[test]
fn crashes_found_by_fuzzing() {
    // A string length in the checkpoint's payload corrupted to a huge value: bincode sized a
    // buffer by it ("capacity overflow"); now the checkpoint reader's limit refuses it.
    case(&[], 6840429268870901006);
    // The elapsed seconds of the checkpoint decoded as NaN: `Duration::from_secs_f64`
    // panicked; now they count as none.
    case(&[], 7625011912345379594);
}

#[test]
fn the_valid_files_resume() {
    let (ck, npy) = valid_files();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("checkpoint.bin"), ck).unwrap();
    std::fs::write(dir.path().join("positions.npy"), npy).unwrap();
    assert!(Simulation::<2>::resume(dir.path(), None).is_ok());
}
