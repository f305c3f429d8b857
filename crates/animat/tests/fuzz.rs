//! Fuzz targets of `animat`'s reader of checkpoints (`run_cli::fuzz`): `--resume DIR`
//! (`checkpoint.bin`: the envelope, the world's snapshot and its checks in `World::restore`);
//! `--config FILE` is the binaries' one config reader, fuzzed in `run_cli`. Arbitrary bytes and mutations of
//! valid files (the checkpoint's checksum made right again, so the state's decoding is
//! reached) give a typed error or a valid world, never a panic, a hang or an allocation sized
//! by a corrupted field. `cargo xtask fuzz` runs many more cases.

use animat::output::PopulationRow;
use animat::{Params, Snapshot, World};
use proptest::prelude::*;
use run_cli::fuzz::{cases, checkpoint_payload, mutate, seal_checkpoint};
use run_io::checkpoint::{decode_checkpoint, encode_checkpoint};
use std::sync::OnceLock;

/// What the binary's checkpoint holds (its `Saved`: the world, then the population rows;
/// bincode writes a struct as the tuple of its fields).
type Saved = (Snapshot, Vec<PopulationRow>);

fn valid_checkpoint() -> &'static Vec<u8> {
    static CK: OnceLock<Vec<u8>> = OnceLock::new();
    CK.get_or_init(|| {
        let p = Params {
            foxes: 30,
            rabbits: 200,
            start_radius: 20,
            ..Params::default()
        };
        let mut world = World::new(p, 3).unwrap();
        let mut rows = vec![PopulationRow::of(&world, Default::default())];
        for _ in 0..5 {
            let s = world.step();
            rows.push(PopulationRow::of(&world, s));
        }
        encode_checkpoint("animat", &(world.snapshot(), rows)).unwrap()
    })
}

fn restore(bytes: &[u8]) {
    if let Ok((snapshot, _rows)) = decode_checkpoint::<Saved>(bytes, "animat") {
        if let Ok(mut world) = World::restore(snapshot) {
            // A restored world must be one that steps.
            world.step();
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    /// `--resume`: the checkpoint envelope and the world inside it.
    #[test]
    fn fuzz_animat_checkpoint(raw in proptest::collection::vec(any::<u8>(), 0..256), seed in any::<u64>()) {
        // One damaged input per case (a restore that succeeds steps the world).
        let ck = valid_checkpoint();
        match seed % 3 {
            0 => restore(&raw),
            1 => restore(&mutate(ck, seed)),
            _ => {
                let payload = mutate(&checkpoint_payload(ck, "animat"), seed);
                restore(&seal_checkpoint("animat", &payload));
            }
        }
    }
}

#[test]
fn the_valid_files_read() {
    let (snapshot, rows) = decode_checkpoint::<Saved>(valid_checkpoint(), "animat").unwrap();
    assert_eq!(rows.len(), 6);
    assert!(World::restore(snapshot).is_ok());
}
