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
//! # The unsafe boundary
//!
//! The accessors that read or write elements ([`Arena::get`], [`Arena::slice`],
//! [`Arena::init`], [`Arena::prefix_mut`], [`Arena::duplicate`]) are `unsafe fn`: the arena
//! checks bounds against its capacity, but whether an element is initialised, and whether
//! another thread may be reading it, is known only to the tree. Their `# Safety` sections say
//! what the caller guarantees. The tree keeps these invariants, and every call site says with
//! a `// SAFETY:` note which one makes it sound there:
//!
//! - an element is written with [`Arena::init`] before anything that leads a reader to it
//!   (a child slot, a leaf record) is published with a `Release` store, and readers follow such
//!   links with `Acquire` loads, so a reader only ever reads initialised elements;
//! - child slots and leaf records, which are overwritten while readers look, are atomics, and
//!   a reachable one is only ever stored into, never re-initialised; point records are plain
//!   integers and are only written while no reader can reach them: fresh slots beyond a leaf's
//!   published length, and blocks a shared writer has retired are only reused once every
//!   reader has announced a later epoch (see `pool.rs`).
//!
//! The helpers above them that take a node or leaf index (the tree's `child`, `leaf`,
//! `leaf_points`, the pool's block operations, the query walks) are `unsafe fn` too, for the
//! same reason: an index is only valid if it was reached from the root. The public API is
//! safe; `insert_shared` relies on its caller's `readers_epoch` being truthful (see its
//! documentation).
//!
//! Under `cfg(loom)` the atomics come from loom (`sync.rs`) and every element access is also
//! recorded on a loom cell, so the model-checked test `tests/loom_shared.rs` sees each read
//! and write of the arenas and reports any that is not ordered by the protocol.
//!
//! This module and `core-lattice`'s prefetch hint are the workspace's only unsafe operations (raw
//! pointers, allocation); the orthtree's other modules only call the `unsafe fn`s above, each
//! call in an `unsafe` block with its `// SAFETY:` note (`#[allow(unsafe_code)]` on those
//! modules). A growable buffer that readers index while a writer appends is exactly what `Vec`
//! cannot offer (its length would be written under the readers' feet).
//!
//! [`Orthtree::insert_shared`]: super::Orthtree::insert_shared
#![allow(unsafe_code)]

use super::sync::{AtomicU32, AtomicU64, Ordering};
use std::alloc::{self, Layout};
use std::ptr::NonNull;

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

impl Element for u32 {
    fn duplicate(&self) -> Self {
        *self
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
    /// Under `cfg(loom)` only: one loom cell per element, which `get`, `slice` (reads) and
    /// `init` (writes) touch, so that loom checks every element access for a data race (it
    /// cannot see plain memory).
    #[cfg(loom)]
    track: Vec<loom::cell::UnsafeCell<()>>,
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
            #[cfg(loom)]
            track: Vec::new(),
        }
    }

    /// Elements the buffer has room for.
    #[inline]
    pub(super) fn capacity(&self) -> usize {
        self.cap
    }

    /// Element `i` (bounds-checked against the capacity).
    ///
    /// # Safety
    ///
    /// Element `i` was written by [`init`](Self::init), and that write happens before this
    /// call: on the writer's own thread, or published to this thread by a `Release` store that
    /// it has read with an `Acquire` load (a child slot or leaf record leading here). No
    /// [`init`](Self::init) of element `i` may run while the returned reference lives (the tree
    /// never rewrites a reachable child slot or leaf record: it stores into them atomically).
    #[inline(always)]
    pub(super) unsafe fn get(&self, i: usize) -> &T {
        assert!(i < self.cap, "arena index {i} out of capacity {}", self.cap);
        #[cfg(loom)]
        self.track[i].with(|_| ());
        // SAFETY: in bounds (asserted); initialised and not rewritten while borrowed (the
        // caller's contract).
        unsafe { &*self.ptr.as_ptr().add(i) }
    }

    /// Elements `start..start + len` (bounds-checked against the capacity).
    ///
    /// # Safety
    ///
    /// Every element of the range was written by [`init`](Self::init) before this call, as
    /// for [`get`](Self::get) (a leaf's block, reached through its leaf record loaded with
    /// `Acquire`), and none of them is written while the slice lives: the writer only appends
    /// beyond a published length, and reuses a replaced block only after every reader that
    /// could hold it has announced a later epoch (`pool.rs`).
    #[inline(always)]
    pub(super) unsafe fn slice(&self, start: usize, len: usize) -> &[T] {
        assert!(start <= self.cap && len <= self.cap - start);
        #[cfg(loom)]
        for t in &self.track[start..start + len] {
            t.with(|_| ());
        }
        // SAFETY: in bounds (asserted); initialised and not written while borrowed (the
        // caller's contract).
        unsafe { std::slice::from_raw_parts(self.ptr.as_ptr().add(start), len) }
    }

    /// Writes element `i`, fresh or overwriting (bounds-checked against the capacity).
    ///
    /// # Safety
    ///
    /// No other thread can reach element `i` while it is written, and no reference to it is
    /// live: it lies beyond everything published to readers (fresh nodes, leaf records and
    /// slots, linked afterwards by a `Release` store), or in a block that no reader can still
    /// hold (freed with exclusive access, or retired and reclaimed after every reader
    /// announced a later epoch). Overwriting leaks nothing: elements have no drop glue.
    #[inline]
    pub(super) unsafe fn init(&self, i: usize, value: T) {
        assert!(i < self.cap, "arena index {i} out of capacity {}", self.cap);
        #[cfg(loom)]
        self.track[i].with_mut(|_| ());
        // SAFETY: in bounds (asserted); nobody reads or borrows element i meanwhile (the
        // caller's contract), and `T` has no drop glue.
        unsafe { self.ptr.as_ptr().add(i).write(value) }
    }

    /// The first `len` elements, mutably (`&mut self`: no reader).
    ///
    /// # Safety
    ///
    /// The first `len` elements were written by [`init`](Self::init).
    pub(super) unsafe fn prefix_mut(&mut self, len: usize) -> &mut [T] {
        assert!(len <= self.cap);
        // SAFETY: in bounds (asserted), initialised (the caller's contract), and `&mut self`
        // excludes every other access.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.as_ptr(), len) }
    }

    /// Resizes the buffer to exactly `cap` elements, keeping the first `len` (`len <= cap`,
    /// exclusive access). When the allocator refuses, the arena is unchanged and the error
    /// gives the bytes asked for.
    pub(super) fn try_set_capacity(&mut self, len: usize, cap: usize) -> Result<(), AllocFailed> {
        assert!(len <= cap && len <= self.cap);
        if cap == self.cap {
            return Ok(());
        }
        let refused = AllocFailed {
            bytes: cap.saturating_mul(size_of::<T>()),
        };
        let new = Layout::array::<T>(cap).map_err(|_| refused)?;
        if cap == 0 {
            self.free();
            return Ok(());
        }
        let ptr = if self.cap == 0 {
            // SAFETY: `new` has a non-zero size (cap > 0, elements are not zero-sized).
            unsafe { alloc::alloc(new) }
        } else {
            let old = Layout::array::<T>(self.cap).expect("layout was valid when allocated");
            // SAFETY: `ptr` was allocated with `old` by this allocator; `new.size()` is non-zero.
            // On failure `realloc` returns null and leaves the old block as it was.
            unsafe { alloc::realloc(self.ptr.as_ptr().cast(), old, new.size()) }
        };
        let p = NonNull::new(ptr.cast::<T>()).ok_or(refused)?;
        self.ptr = p;
        self.cap = cap;
        #[cfg(loom)]
        self.track
            .resize_with(cap, || loom::cell::UnsafeCell::new(()));
        Ok(())
    }

    /// [`try_set_capacity`](Self::try_set_capacity) where a refusal cannot be reported (a
    /// clone of the tree): the allocator's usual out-of-memory handling.
    pub(super) fn set_capacity(&mut self, len: usize, cap: usize) {
        if let Err(e) = self.try_set_capacity(len, cap) {
            let layout = Layout::from_size_align(e.bytes.max(1), align_of::<T>())
                .unwrap_or(Layout::new::<T>());
            alloc::handle_alloc_error(layout)
        }
    }

    /// A new arena of capacity `cap` holding copies of the first `len` elements.
    ///
    /// # Safety
    ///
    /// The first `len` elements were written by [`init`](Self::init), and none of them is
    /// being written meanwhile (as for [`get`](Self::get)).
    pub(super) unsafe fn duplicate(&self, len: usize, cap: usize) -> Self {
        let mut out = Arena::new();
        out.set_capacity(0, cap.max(len));
        for i in 0..len {
            // SAFETY: `out` is new and not shared, so nothing else can reach its element i;
            // element i of `self` is initialised and not being written (the caller's
            // contract).
            unsafe { out.init(i, self.get(i).duplicate()) };
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
            #[cfg(loom)]
            self.track.clear();
        }
    }
}

impl<T: Element> Drop for Arena<T> {
    fn drop(&mut self) {
        self.free();
    }
}

/// The allocator refused to grow an arena to `bytes` bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct AllocFailed {
    pub(super) bytes: usize,
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
