//! The checkpoint envelope behind the models' `--checkpoint-every` and `--resume` flags.
//!
//! Layout, all integers little-endian:
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `AGGSIMCK` |
//! | 4 | format version (`u32`, currently [`FORMAT_VERSION`]) |
//! | 2 | length `m` of the model name (`u16`) |
//! | m | model name, UTF-8 |
//! | 8 | length `p` of the payload (`u64`) |
//! | p | payload: the model's state, serde through bincode 2 (standard configuration) |
//! | 8 | XXH3-64 checksum of every preceding byte |
//!
//! The reader checks, in order: magic, version, that the file holds every byte its header
//! announces, the checksum, the model name, then decodes. Each failure is a typed
//! [`CheckpointError`]; no input makes it panic or allocate more than the file's size.

use super::atomic::AtomicFile;
use super::hash::xxh3_64;
use serde::Serialize;
use serde::de::DeserializeOwned;
use std::io::Write;
use std::path::Path;

/// The magic bytes that open every checkpoint.
pub const MAGIC: [u8; 8] = *b"AGGSIMCK";
/// The envelope format this version writes and reads.
pub const FORMAT_VERSION: u32 = 1;

/// Why a checkpoint could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// The file could not be read or written.
    #[error("checkpoint I/O: {0}")]
    Io(#[from] std::io::Error),
    /// The file does not start with the checkpoint magic: not a checkpoint.
    #[error("not a checkpoint file (bad magic bytes)")]
    BadMagic,
    /// The envelope format version is not one this build reads.
    #[error(
        "checkpoint format version {found} is not supported (this build reads version {supported})"
    )]
    UnsupportedVersion {
        /// Version in the file.
        found: u32,
        /// Version this build reads.
        supported: u32,
    },
    /// The file ends before the bytes its header announces.
    #[error("checkpoint is truncated: {found} bytes, at least {needed} expected")]
    Truncated {
        /// Bytes needed.
        needed: u64,
        /// Bytes present.
        found: u64,
    },
    /// The checksum does not match the content: the file is corrupted.
    #[error("checkpoint is corrupted: checksum {stored:016x} stored, {computed:016x} computed")]
    ChecksumMismatch {
        /// Checksum in the file.
        stored: u64,
        /// Checksum of the content.
        computed: u64,
    },
    /// The checkpoint belongs to another model.
    #[error("checkpoint is for model '{found}', not '{expected}'")]
    WrongModel {
        /// Model in the file.
        found: String,
        /// Model asked for.
        expected: String,
    },
    /// Bytes after the checksum, or a model name that is not UTF-8.
    #[error("checkpoint is malformed: {0}")]
    Malformed(String),
    /// The payload could not be decoded into the requested state type.
    #[error("checkpoint payload does not decode: {0}")]
    Decode(String),
    /// The state could not be encoded.
    #[error("checkpoint state does not encode: {0}")]
    Encode(String),
}

/// Encode `state` of `model` into checkpoint bytes.
pub fn encode_checkpoint<T: Serialize>(model: &str, state: &T) -> Result<Vec<u8>, CheckpointError> {
    let name = model.as_bytes();
    let name_len = u16::try_from(name.len())
        .map_err(|_| CheckpointError::Encode(format!("model name of {} bytes", name.len())))?;
    let payload = bincode::serde::encode_to_vec(state, bincode::config::standard())
        .map_err(|e| CheckpointError::Encode(e.to_string()))?;
    let mut out = Vec::with_capacity(8 + 4 + 2 + name.len() + 8 + payload.len() + 8);
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&name_len.to_le_bytes());
    out.extend_from_slice(name);
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&payload);
    let checksum = xxh3_64(&out);
    out.extend_from_slice(&checksum.to_le_bytes());
    Ok(out)
}

/// A cursor that reports truncation instead of panicking.
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: u64) -> Result<&'a [u8], CheckpointError> {
        let have = (self.bytes.len() - self.pos) as u64;
        if n > have {
            return Err(CheckpointError::Truncated {
                needed: (self.pos as u64).saturating_add(n),
                found: self.bytes.len() as u64,
            });
        }
        let s = &self.bytes[self.pos..self.pos + n as usize];
        self.pos += n as usize;
        Ok(s)
    }
    fn array<const N: usize>(&mut self) -> Result<[u8; N], CheckpointError> {
        Ok(self.take(N as u64)?.try_into().expect("length checked"))
    }
}

/// Decodes `payload` with bincode's standard configuration and a limit on the memory its
/// containers may claim: 1024 times the power of two at or above the payload's length
/// ([`CLAIM_FACTOR_BITS`]; a container in memory takes more than its encoding, 8 bytes for a
/// one-byte varint). bincode sizes a string's buffer by the length read from the payload
/// before reading it, so without the limit a corrupted length (2^60) would be an allocation
/// of that size and an abort; with it, an error. The limit is a type parameter of bincode's
/// configuration, hence the table of powers.
fn decode_limited<T: DeserializeOwned>(
    payload: &[u8],
) -> Result<(T, usize), bincode::error::DecodeError> {
    use bincode::config::standard;
    use bincode::serde::decode_from_slice;
    let bits = payload.len().max(1).next_power_of_two().trailing_zeros() + CLAIM_FACTOR_BITS;
    macro_rules! limited {
        ($($b:literal)+) => {
            match bits {
                $($b => decode_from_slice(payload, standard().with_limit::<{ 1usize << $b }>()),)+
                _ => decode_from_slice(payload, standard()),
            }
        };
    }
    limited!(10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31 32 33 34 35 36
        37 38 39 40 41 42 43 44 45 46 47 48 49 50 51 52 53 54 55 56 57 58)
}

/// The memory a checkpoint's decoding may claim is `2^CLAIM_FACTOR_BITS` times its payload's
/// length (rounded up to a power of two).
const CLAIM_FACTOR_BITS: u32 = 10;

/// Decode checkpoint bytes written by [`encode_checkpoint`] for `model`.
pub fn decode_checkpoint<T: DeserializeOwned>(
    bytes: &[u8],
    model: &str,
) -> Result<T, CheckpointError> {
    let mut r = Reader { bytes, pos: 0 };
    let magic_len = MAGIC.len().min(bytes.len());
    if bytes[..magic_len] != MAGIC[..magic_len] {
        return Err(CheckpointError::BadMagic);
    }
    r.array::<8>()?;
    let version = u32::from_le_bytes(r.array()?);
    if version != FORMAT_VERSION {
        return Err(CheckpointError::UnsupportedVersion {
            found: version,
            supported: FORMAT_VERSION,
        });
    }
    let name_len = u16::from_le_bytes(r.array()?);
    let name = r.take(u64::from(name_len))?;
    let payload_len = u64::from_le_bytes(r.array()?);
    let payload = r.take(payload_len)?;
    let body_end = r.pos;
    let stored = u64::from_le_bytes(r.array()?);
    if r.pos != bytes.len() {
        return Err(CheckpointError::Malformed(format!(
            "{} bytes after the checksum",
            bytes.len() - r.pos
        )));
    }
    let computed = xxh3_64(&bytes[..body_end]);
    if stored != computed {
        return Err(CheckpointError::ChecksumMismatch { stored, computed });
    }
    let name = std::str::from_utf8(name)
        .map_err(|_| CheckpointError::Malformed("model name is not UTF-8".into()))?;
    if name != model {
        return Err(CheckpointError::WrongModel {
            found: name.into(),
            expected: model.into(),
        });
    }
    let (state, used) =
        decode_limited(payload).map_err(|e| CheckpointError::Decode(e.to_string()))?;
    if used != payload.len() {
        return Err(CheckpointError::Decode(format!(
            "{} of {} payload bytes left over",
            payload.len() - used,
            payload.len()
        )));
    }
    Ok(state)
}

/// Write a checkpoint of `state` for `model` to `path`, atomically.
pub fn write_checkpoint<T: Serialize>(
    path: impl AsRef<Path>,
    model: &str,
    state: &T,
) -> Result<(), CheckpointError> {
    let bytes = encode_checkpoint(model, state)?;
    let mut f = AtomicFile::create(path)?;
    f.write_all(&bytes)?;
    f.commit()?;
    Ok(())
}

/// Read the checkpoint at `path`, which must be one of `model`'s. A file that cannot be read is
/// a [`CheckpointError::Io`] naming the path.
pub fn read_checkpoint<T: DeserializeOwned>(
    path: impl AsRef<Path>,
    model: &str,
) -> Result<T, CheckpointError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path)
        .map_err(|e| std::io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
    decode_checkpoint(&bytes, model)
}
