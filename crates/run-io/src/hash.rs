//! The `state_hash` every model reports in `run.json`: a 64-bit XXH3 hash of the final state,
//! fed in a documented order. It is stable across platforms and versions of this crate (XXH3 is
//! a fixed algorithm and values are fed as little-endian bytes), so two runs agree exactly
//! when their hashes agree, and a reader can compare runs made on different machines.

use xxhash_rust::xxh3::Xxh3Default;

/// Incremental XXH3-64 hasher for model states. Feed values in a fixed, documented order.
#[derive(Clone, Default)]
pub struct StateHasher(Xxh3Default);

impl std::fmt::Debug for StateHasher {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("StateHasher")
            .field(&self.finish_hex())
            .finish()
    }
}

impl StateHasher {
    /// A fresh hasher.
    pub fn new() -> Self {
        Self::default()
    }
    /// Feed raw bytes.
    pub fn bytes(&mut self, b: &[u8]) -> &mut Self {
        self.0.update(b);
        self
    }
    /// Feed a `u64` (little-endian).
    pub fn u64(&mut self, v: u64) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }
    /// Feed an `i64` (little-endian).
    pub fn i64(&mut self, v: i64) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }
    /// Feed an `f64` by its exact bit pattern (so `-0.0` and `0.0` differ, as they should for
    /// a bit-identity check).
    pub fn f64(&mut self, v: f64) -> &mut Self {
        self.u64(v.to_bits())
    }
    /// Feed up to eight `f64`s as [`f64`](Self::f64) feeds them one after the other (the same
    /// hash), in one update of the hasher: one call for a point's coordinates instead of one
    /// per coordinate.
    ///
    /// # Panics
    ///
    /// If `vs` holds more than eight values.
    pub fn f64s(&mut self, vs: &[f64]) -> &mut Self {
        let mut buf = [0u8; 64];
        for (chunk, v) in buf.chunks_exact_mut(8).zip(vs) {
            chunk.copy_from_slice(&v.to_bits().to_le_bytes());
        }
        self.bytes(&buf[..8 * vs.len()])
    }
    /// The hash so far.
    pub fn finish(&self) -> u64 {
        self.0.digest()
    }
    /// The hash as 16 lower-case hex digits, the form written to `run.json`.
    pub fn finish_hex(&self) -> String {
        format!("{:016x}", self.finish())
    }
}

/// XXH3-64 of a byte slice.
pub fn xxh3_64(bytes: &[u8]) -> u64 {
    xxhash_rust::xxh3::xxh3_64(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn order_and_content_matter() {
        let mut a = StateHasher::new();
        a.u64(1).u64(2);
        let mut b = StateHasher::new();
        b.u64(2).u64(1);
        assert_ne!(a.finish(), b.finish());
        let mut c = StateHasher::new();
        c.bytes(&1u64.to_le_bytes()).bytes(&2u64.to_le_bytes());
        assert_eq!(a.finish(), c.finish());
        assert_eq!(a.finish_hex().len(), 16);
        // Pinned: the empty input hash of XXH3-64 (reference value from the xxHash suite).
        assert_eq!(StateHasher::new().finish(), 0x2D06800538D394C2);
        let xs = [1.5, -0.0, f64::MAX, 3e-310, 7.0];
        let mut one_by_one = StateHasher::new();
        for x in xs {
            one_by_one.f64(x);
        }
        assert_eq!(StateHasher::new().f64s(&xs).finish(), one_by_one.finish());
        assert_ne!(
            StateHasher::new().f64(0.0).finish(),
            StateHasher::new().f64(-0.0).finish()
        );
    }

    #[test]
    #[should_panic]
    fn more_than_eight_values_at_once_are_refused() {
        StateHasher::new().f64s(&[0.0; 9]);
    }
}
