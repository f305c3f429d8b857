//! The orthtree's three arrays (child slots, leaf records, point records) as buffers that one
//! writer can append to while other threads read them: what lets PDLA share one tree between
//! its walkers instead of giving each thread a replica ([`Orthtree::insert_shared`]).
//!
//! An [`Arena`] is an allocation of `cap` elements and nothing else: the number of elements in
//! use is kept by the tree's writer state, so that the cache lines readers touch (the arena's
//! pointer and capacity) are never written while they read. Growth reallocates (`realloc`,
//! which moves large buffers by remapping pages, so it neither copies nor doubles the peak) and
//! needs `&mut`; a shared writer only appends within the capacity reserved beforehand.
//!
//! Invariants the tree keeps (and the reason the `unsafe` blocks here are sound):
//!
//! - an element is written with [`Arena::init`] before anything that leads a reader to it
//!   (a child slot, a leaf record) is published with a `Release` store, and readers follow such
//!   links with `Acquire` loads, so a reader only ever reads initialised elements;
//! - child slots and leaf records, which are overwritten while readers look, are atomics; point
//!   records are plain integers and are only written while no reader can reach them: fresh
//!   slots beyond a leaf's published length, and blocks a shared writer has retired are only
//!   reused once every reader has passed a quiescent point (see `pool.rs`).
//!
//! This module and `animat`'s prefetch hint are the workspace's only `unsafe` code: a
//! growable buffer that readers index while a writer appends is exactly what `Vec` cannot offer
//! (its length would be written under the readers' feet).
//!
//! [`Orthtree::insert_shared`]: super::Orthtree::insert_shared
#![allow(unsafe_code)]

use std::alloc::{self, Layout};
use std::ptr::NonNull;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};

/// Element types an [`Arena`] holds: plain old data without drop glue, copied by value.
pub(super) trait Element: Send + Sync + Sized {
    /// A copy of the element's current value (used by `Clone` of the tree).
    fn duplicate(&self) -> Self;
}

impl Element for AtomicU32 {
    fn duplicate(&self) -> Self {
        AtomicU32::new(self.load(Ordering::Relaxed))
    }
}

impl Element for AtomicU64 {
    fn duplicate(&self) -> Self {
        AtomicU64::new(self.load(Ordering::Relaxed))
    }
}

impl<const D: usize> Element for [u32; D] {
    fn duplicate(&self) -> Self {
        *self
    }
}

/// A raw buffer of `cap` elements of `T`, of which a prefix (tracked by the owner) is
/// initialised.
pub(super) struct Arena<T: Element> {
    ptr: NonNull<T>,
    cap: usize,
}

// SAFETY: the arena owns its buffer; `T` is Send + Sync and access follows the invariants of
// the module documentation.
unsafe impl<T: Element> Send for Arena<T> {}
// SAFETY: as above; shared access only reads initialised elements or writes unreachable ones.
unsafe impl<T: Element> Sync for Arena<T> {}

impl<T: Element> Arena<T> {
    /// An arena with no buffer.
    pub(super) const fn new() -> Self {
        const { assert!(!std::mem::needs_drop::<T>() && size_of::<T>() > 0) };
        Arena {
            ptr: NonNull::dangling(),
            cap: 0,
        }
    }

    /// Elements the buffer has room for.
    #[inline]
    pub(super) fn capacity(&self) -> usize {
        self.cap
    }

    /// Element `i`, which must be initialised (bounds-checked against the capacity).
    #[inline(always)]
    pub(super) fn get(&self, i: usize) -> &T {
        assert!(i < self.cap, "arena index {i} out of capacity {}", self.cap);
        // SAFETY: in bounds; initialised by the tree's invariants (module docs).
        unsafe { &*self.ptr.as_ptr().add(i) }
    }

    /// Elements `start..start + len`, which must be initialised and not written while the
    /// slice lives (a leaf's published block; module docs).
    #[inline(always)]
    pub(super) fn slice(&self, start: usize, len: usize) -> &[T] {
        assert!(start <= self.cap && len <= self.cap - start);
        // SAFETY: in bounds; initialised and not written concurrently (module docs).
        unsafe { std::slice::from_raw_parts(self.ptr.as_ptr().add(start), len) }
    }

    /// Writes element `i` (fresh, or one no reader can reach: module docs).
    #[inline]
    pub(super) fn init(&self, i: usize, value: T) {
        assert!(i < self.cap, "arena index {i} out of capacity {}", self.cap);
        // SAFETY: in bounds; no reader holds a reference to element i (module docs), and `T`
        // has no drop glue, so overwriting an initialised element leaks nothing.
        unsafe { self.ptr.as_ptr().add(i).write(value) }
    }

    /// The first `len` elements, mutably (exclusive access).
    pub(super) fn prefix_mut(&mut self, len: usize) -> &mut [T] {
        assert!(len <= self.cap);
        // SAFETY: in bounds, initialised (the caller's `len`), and `&mut self` excludes readers.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.as_ptr(), len) }
    }

    /// Resizes the buffer to exactly `cap` elements, keeping the first `len` (`len <= cap`,
    /// exclusive access).
    pub(super) fn set_capacity(&mut self, len: usize, cap: usize) {
        assert!(len <= cap && len <= self.cap);
        if cap == self.cap {
            return;
        }
        let new = Layout::array::<T>(cap).expect("orthtree arena too large");
        if cap == 0 {
            self.free();
            return;
        }
        let ptr = if self.cap == 0 {
            // SAFETY: `new` has a non-zero size (cap > 0, elements are not zero-sized).
            unsafe { alloc::alloc(new) }
        } else {
            let old = Layout::array::<T>(self.cap).expect("layout was valid when allocated");
            // SAFETY: `ptr` was allocated with `old` by this allocator; `new.size()` is non-zero.
            unsafe { alloc::realloc(self.ptr.as_ptr().cast(), old, new.size()) }
        };
        match NonNull::new(ptr.cast::<T>()) {
            Some(p) => {
                self.ptr = p;
                self.cap = cap;
            }
            None => alloc::handle_alloc_error(new),
        }
    }

    /// A new arena of capacity `cap` holding copies of the first `len` elements.
    pub(super) fn duplicate(&self, len: usize, cap: usize) -> Self {
        let mut out = Arena::new();
        out.set_capacity(0, cap.max(len));
        for i in 0..len {
            out.init(i, self.get(i).duplicate());
        }
        out
    }

    fn free(&mut self) {
        if self.cap > 0 {
            let layout = Layout::array::<T>(self.cap).expect("layout was valid when allocated");
            // SAFETY: allocated with this layout by this allocator.
            unsafe { alloc::dealloc(self.ptr.as_ptr().cast(), layout) };
            self.ptr = NonNull::dangling();
            self.cap = 0;
        }
    }
}

impl<T: Element> Drop for Arena<T> {
    fn drop(&mut self) {
        self.free();
    }
}

/// Capacity to grow an arena of capacity `cap` to so it holds `need` elements: by at most 1/8
/// of the capacity beyond what is needed (plus a small floor), instead of doubling, which keeps
/// the slack near 12 % at any size.
pub(super) fn slow_growth(cap: usize, need: usize) -> usize {
    if need <= cap {
        cap
    } else {
        need.max(cap + (cap / 8).max(64))
    }
}
