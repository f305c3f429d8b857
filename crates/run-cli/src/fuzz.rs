//! Fuzzing the readers of files a user can hand the programs (checkpoints, `.npy`, configs,
//! ensemble members): the inputs (arbitrary bytes, and mutations of a valid file) and the
//! number of cases. Each reader's fuzz target is one proptest test (`fuzz_*`): `cargo test`
//! runs [`DEFAULT_CASES`] of each, `cargo xtask fuzz` many more (through
//! `AGGSIM_FUZZ_CASES`). Compiled for tests and with feature `test-support`.
use core_lattice::rng::{RngExt, stream};

/// Cases per fuzz target under `cargo test`: a few seconds for all of them.
pub const DEFAULT_CASES: u32 = 64;

/// Cases per fuzz target: `AGGSIM_FUZZ_CASES` if set (by `cargo xtask fuzz`), else
/// [`DEFAULT_CASES`].
pub fn cases() -> u32 {
    std::env::var("AGGSIM_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(DEFAULT_CASES)
}

/// Values a corrupted length or count field takes: huge, so that a reader that allocates
/// by it without checking it against the file's size aborts the test.
pub const HUGE: [u64; 6] = [
    1 << 60,
    u64::MAX,
    u64::MAX / 2,
    u32::MAX as u64,
    1 << 40,
    1 << 31,
];

/// `valid` changed by one to four mutations drawn from `seed`: bit flips, random bytes,
/// truncation, insertion and deletion of bytes, a duplicated chunk, and 1, 2, 4 or 8
/// bytes overwritten with a huge value (as a length field set huge would be).
pub fn mutate(valid: &[u8], seed: u64) -> Vec<u8> {
    let mut rng = stream(seed, 0xF022);
    let mut b = valid.to_vec();
    let ops = 1 + rng.random_range(0..4u32);
    for _ in 0..ops {
        let len = b.len();
        let at = if len == 0 {
            0
        } else {
            rng.random_range(0..len)
        };
        match rng.random_range(0..8u32) {
            0 if len > 0 => b[at] ^= 1 << rng.random_range(0..8u32),
            1 if len > 0 => b[at] = rng.random(),
            2 => b.truncate(at),
            3 => {
                let n = rng.random_range(1..16usize);
                let bytes: Vec<u8> = (0..n).map(|_| rng.random()).collect();
                b.splice(at..at, bytes);
            }
            4 if len > 0 => {
                let end = (at + rng.random_range(1..16usize)).min(len);
                b.drain(at..end);
            }
            5 if len > 0 => {
                let end = (at + rng.random_range(1..64usize)).min(len);
                let chunk = b[at..end].to_vec();
                b.splice(at..at, chunk);
            }
            _ => {
                let v = HUGE[rng.random_range(0..HUGE.len())];
                let width = [1usize, 2, 4, 8][rng.random_range(0..4usize)];
                let bytes = v.to_le_bytes();
                for (k, &x) in bytes[..width].iter().enumerate() {
                    if let Some(slot) = b.get_mut(at + k) {
                        *slot = x;
                    }
                }
            }
        }
    }
    b
}

/// A checkpoint envelope (`run_io::checkpoint`) of `model` around `payload` with a
/// correct checksum, so that a mutated payload reaches the model's decoding.
pub fn seal_checkpoint(model: &str, payload: &[u8]) -> Vec<u8> {
    use run_io::checkpoint::{FORMAT_VERSION, MAGIC};
    let mut out = Vec::new();
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&(model.len() as u16).to_le_bytes());
    out.extend_from_slice(model.as_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(payload);
    let sum = run_io::hash::xxh3_64(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}

/// The payload of a valid checkpoint of `model` (the bytes [`seal_checkpoint`] wraps).
pub fn checkpoint_payload(checkpoint: &[u8], model: &str) -> Vec<u8> {
    let start = 8 + 4 + 2 + model.len() + 8;
    checkpoint[start..checkpoint.len() - 8].to_vec()
}

#[cfg(test)]
mod tests {
    //! The fuzz targets of the readers in `run_cli` (`fuzz_*`); see the module docs.
    use super::*;
    use proptest::prelude::*;
    use run_io::checkpoint::{decode_checkpoint, encode_checkpoint};
    use run_io::{NpyReader, NpyWriter, RunManifest};

    fn proptest_config() -> ProptestConfig {
        ProptestConfig {
            cases: cases(),
            ..ProptestConfig::default()
        }
    }

    #[derive(Debug, serde::Serialize, serde::Deserialize)]
    struct State {
        step: u64,
        positions: Vec<[f64; 2]>,
        label: String,
        nested: Vec<Vec<u32>>,
        maybe: Option<Box<State>>,
    }

    fn valid_checkpoint() -> Vec<u8> {
        let s = State {
            step: 7,
            positions: (0..20).map(|i| [f64::from(i), -1.0]).collect(),
            label: "run".into(),
            nested: vec![vec![1, 2, 3], vec![], vec![9]],
            maybe: Some(Box::new(State {
                step: 1,
                positions: vec![],
                label: String::new(),
                nested: vec![],
                maybe: None,
            })),
        };
        encode_checkpoint("dla", &s).unwrap()
    }

    fn npy_file(dir: &std::path::Path) -> Vec<u8> {
        let path = dir.join("valid.npy");
        let mut w = NpyWriter::create(&path, 3).unwrap();
        for i in 0..10 {
            w.push(&[f64::from(i), 0.5, -2.0]).unwrap();
        }
        w.sync().unwrap();
        drop(w);
        std::fs::read(&path).unwrap()
    }

    /// Opens `bytes` as an `.npy` file and reads every row, counted and beyond.
    fn read_npy(path: &std::path::Path, bytes: &[u8]) {
        std::fs::write(path, bytes).unwrap();
        if let Ok(mut r) = NpyReader::open(path) {
            let mut row = vec![0.0; r.cols()];
            while let Ok(true) = r.next_row(&mut row) {}
            while let Ok(true) = r.read_beyond(&mut row) {}
        }
    }

    fn manifest_bytes() -> Vec<u8> {
        let mut m = RunManifest {
            model: "dla".into(),
            version: "0.1.0".into(),
            seed: 3,
            threads: 1,
            params: serde_json::json!({"particles": 100, "dim": 2}),
            wall_seconds: 1.5,
            cpu_seconds: Some(1.4),
            peak_rss_bytes: Some(1 << 20),
            provenance: None,
            results: serde_json::Map::new(),
        };
        m.set_result("fractal_dimension", 1.7)
            .set_result("state_hash", "00ff");
        serde_json::to_vec_pretty(&m).unwrap()
    }

    proptest! {
        #![proptest_config(proptest_config())]

        /// The checkpoint envelope: arbitrary bytes, mutated checkpoints, and mutated
        /// payloads with a correct checksum (so they reach bincode).
        #[test]
        fn fuzz_checkpoint_envelope(
            raw in proptest::collection::vec(any::<u8>(), 0..256),
            seed in any::<u64>(),
        ) {
            let valid = valid_checkpoint();
            let _ = decode_checkpoint::<State>(&raw, "dla");
            let _ = decode_checkpoint::<State>(&mutate(&valid, seed), "dla");
            let payload = mutate(&checkpoint_payload(&valid, "dla"), seed);
            let _ = decode_checkpoint::<State>(&seal_checkpoint("dla", &payload), "dla");
        }

        /// The `.npy` reader (`positions.npy` of dla's `--resume`).
        #[test]
        fn fuzz_npy_reader(
            raw in proptest::collection::vec(any::<u8>(), 0..256),
            seed in any::<u64>(),
        ) {
            let dir = tempfile::tempdir().unwrap();
            let valid = npy_file(dir.path());
            let path = dir.path().join("x.npy");
            read_npy(&path, &raw);
            read_npy(&path, &mutate(&valid, seed));
            // Only the header changed: shapes of every size.
            let mut header = valid.clone();
            let m = mutate(&valid[..128], seed);
            header.splice(..128, m);
            read_npy(&path, &header);
        }

        /// `run.json` of an ensemble member (`--merge`).
        #[test]
        fn fuzz_run_manifest(
            raw in proptest::collection::vec(any::<u8>(), 0..256),
            seed in any::<u64>(),
        ) {
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("run.json");
            std::fs::write(&path, &raw).unwrap();
            let _ = RunManifest::read(&path);
            std::fs::write(&path, mutate(&manifest_bytes(), seed)).unwrap();
            let _ = RunManifest::read(&path);
        }
    }

    /// Crash found by `fuzz_checkpoint_envelope`: a string length in the payload set to 2^60
    /// made bincode allocate that much and abort; the reader's limit makes it an error.
    #[test]
    fn a_string_length_of_2_pow_60_is_an_error_not_an_allocation() {
        // bincode's varint: 0xFD then a little-endian u64.
        let mut payload = vec![0xFD];
        payload.extend_from_slice(&(1u64 << 60).to_le_bytes());
        payload.extend_from_slice(b"abc");
        let ck = seal_checkpoint("dla", &payload);
        assert!(matches!(
            decode_checkpoint::<String>(&ck, "dla"),
            Err(run_io::CheckpointError::Decode(_))
        ));
        assert!(decode_checkpoint::<State>(&ck, "dla").is_err());
    }

    #[test]
    fn a_huge_npy_shape_sizes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let valid = npy_file(dir.path());
        let text = std::str::from_utf8(&valid[10..128]).unwrap();
        let path = dir.path().join("huge.npy");
        for (shape, opens) in [
            ("(10, 1152921504606846976)", false),
            ("(1152921504606846976, 3)", true),
        ] {
            let mut header = text.replace("(10, 3)", shape).into_bytes();
            header.truncate(118);
            let mut bytes = valid.clone();
            bytes.splice(10..128, header);
            std::fs::write(&path, &bytes).unwrap();
            match NpyReader::open(&path) {
                Ok(mut r) => {
                    assert!(opens, "{shape}");
                    let mut row = vec![0.0; r.cols()];
                    let mut n = 0;
                    while let Ok(true) = r.next_row(&mut row) {
                        n += 1;
                    }
                    assert_eq!(n, 10, "the rows present are read, then an error");
                }
                Err(e) => assert!(!opens, "{shape}: {e}"),
            }
        }
    }

    /// A member of an ensemble directory: `run.json` and `growth.csv`.
    fn member(dir: &std::path::Path, seed: u64, manifest: &[u8], csv: &[u8]) {
        let m = dir.join(format!("seed-{seed:04}"));
        std::fs::create_dir_all(&m).unwrap();
        std::fs::write(m.join("run.json"), manifest).unwrap();
        std::fs::write(m.join("growth.csv"), csv).unwrap();
    }

    const CURVES: &[crate::ensemble::Curve] = &[crate::ensemble::Curve {
        file: "growth.csv",
        x: "n",
        ys: &["r"],
        missing: Some(0.0),
        title: "r against n",
        axes: ("n", "r"),
        log_x: true,
        log_y: true,
        colours: &[],
    }];

    const GROWTH: &[u8] = b"n,r\n1,0.5\n2,1.0\n4,1.5\n8,2.5\n";

    /// The config file of `--config` (`run_cli::cli::config::expand`) against a command with
    /// a number, a list, a switch and a text flag.
    fn expand_config(path: &std::path::Path, bytes: &[u8]) {
        std::fs::write(path, bytes).unwrap();
        let cmd = clap::Command::new("prog")
            .arg(clap::Arg::new("particles").long("particles"))
            .arg(
                clap::Arg::new("sizes")
                    .long("sizes")
                    .num_args(1..)
                    .value_delimiter(','),
            )
            .arg(
                clap::Arg::new("png")
                    .long("png")
                    .action(clap::ArgAction::SetTrue),
            )
            .arg(clap::Arg::new("out").long("out"))
            .arg(clap::Arg::new("config").long("config"));
        let args = vec![
            "prog".into(),
            "--config".into(),
            path.as_os_str().to_owned(),
        ];
        if let Ok(args) = crate::cli::config::expand(&cmd, args) {
            let _ = cmd.try_get_matches_from(args);
        }
    }

    proptest! {
        #![proptest_config(proptest_config())]

        /// `--config FILE` of `dla` and `dlca` (TOML keyed by the long flags).
        #[test]
        fn fuzz_config_file(
            raw in proptest::collection::vec(any::<u8>(), 0..256),
            seed in any::<u64>(),
        ) {
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("c.toml");
            expand_config(&path, &raw);
            let valid = b"particles = 1000\nsizes = [1, 2, 3]\npng = true\n# c\n";
            expand_config(&path, &mutate(valid, seed));
        }

        /// `--merge DIR`: members' `run.json` and curve files, one of them damaged.
        #[test]
        fn fuzz_merge_members(
            raw in proptest::collection::vec(any::<u8>(), 0..256),
            seed in any::<u64>(),
        ) {
            let dir = tempfile::tempdir().unwrap();
            let good = manifest_bytes();
            member(dir.path(), 1, &good, GROWTH);
            let which = seed % 3;
            let (m, c) = match which {
                0 => (mutate(&good, seed), GROWTH.to_vec()),
                1 => (good.clone(), mutate(GROWTH, seed)),
                _ => (good.clone(), raw),
            };
            member(dir.path(), 2, &m, &c);
            let _ = crate::ensemble::merge(dir.path(), "dla", CURVES);
        }
    }
}
