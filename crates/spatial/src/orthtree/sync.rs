//! The orthtree's atomics: `std`'s, or loom's under `cfg(loom)`, so that the model-checked
//! test (`tests/loom_shared.rs`, `RUSTFLAGS="--cfg loom"`) runs the real shared-insert code
//! with every load and store seen by loom. Loom's atomics have no `const fn new` and no
//! `get_mut`; the orthtree creates its atomics at run time only, and reads or writes one
//! through `&mut` with [`load_mut`], [`store_mut`] and [`increment_mut`].
//!
//! The writer's mutex stays `std`'s under loom: it only serialises writers, and the loom test
//! has one writer; readers never take it.

#[cfg(loom)]
pub(super) use loom::sync::atomic::{AtomicU32, AtomicU64, AtomicUsize};
pub(super) use std::sync::atomic::Ordering;
#[cfg(not(loom))]
pub(super) use std::sync::atomic::{AtomicU32, AtomicU64, AtomicUsize};

/// The value of an atomic the caller holds exclusively.
#[inline(always)]
pub(super) fn load_mut(a: &mut AtomicU64) -> u64 {
    #[cfg(not(loom))]
    return *a.get_mut();
    #[cfg(loom)]
    return a.with_mut(|v| *v);
}

/// Sets an atomic the caller holds exclusively.
#[inline(always)]
pub(super) fn store_mut(a: &mut AtomicU64, value: u64) {
    #[cfg(not(loom))]
    {
        *a.get_mut() = value;
    }
    #[cfg(loom)]
    a.with_mut(|v| *v = value);
}

/// Adds one to a counter the caller holds exclusively.
#[inline(always)]
pub(super) fn increment_mut(a: &mut AtomicUsize) {
    #[cfg(not(loom))]
    {
        *a.get_mut() += 1;
    }
    #[cfg(loom)]
    a.with_mut(|v| *v += 1);
}
