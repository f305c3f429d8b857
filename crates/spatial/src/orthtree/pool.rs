//! Compact leaf storage: one pool of fixed-point point records, carved into per-leaf blocks by
//! size class (the variable-precision paper, section 3.3: "pointers addressing list structures
//! containing chunks of 10 particles", here contiguous blocks instead of linked chunks).
//!
//! A leaf holding `n` points owns one contiguous block of `cap(n)` slots, where `cap(n) = n` for
//! `n <= 16` and `cap(n)` rounds `n` up to a quarter of the enclosing power of two above that
//! (capacities 20, 24, 28, 32, 40, 48, ...). Growing a leaf past its capacity moves its points to
//! a block of the next class and puts the old block on that class's free list, where the next
//! leaf reaching that size picks it up. Dense small leaves (the DLA case: a handful of particles
//! per leaf) therefore waste nothing, and a free list's next link lives inside the free block, so
//! free lists cost no memory either.

use super::Leaf;
use super::arena::{AllocFailed, Arena, slow_growth};
use super::sync::{AtomicU64, load_mut, store_mut};
use std::collections::VecDeque;

/// Leaf sizes up to this many points get a block of exactly their size.
const EXACT_CLASSES: u32 = 16;

/// Number of size classes: 16 exact ones, then 4 per power of two up to 2^32.
pub(super) const NUM_CLASSES: usize = 128;

/// End-of-list marker for the free lists.
const NIL: u32 = u32::MAX;

/// Size class of a block holding `n >= 1` points: `(class index, capacity in slots)`.
#[inline]
pub(super) fn class_of(n: u32) -> (usize, u64) {
    debug_assert!(n >= 1);
    if n <= EXACT_CLASSES {
        ((n - 1) as usize, u64::from(n))
    } else {
        // n - 1 in [2^b, 2^(b+1)), b >= 4; quarter steps of 2^(b-2).
        let b = 31 - (n - 1).leading_zeros();
        let q = 1u64 << (b - 2);
        let j = u64::from(n).div_ceil(q); // 5..=8
        (
            EXACT_CLASSES as usize + 4 * (b as usize - 4) + (j as usize - 5),
            j * q,
        )
    }
}

/// A block a shared insert replaced: readers may still be scanning it, so it waits here
/// until every reader has announced an epoch after `epoch` (see
/// [`Orthtree::insert_shared`](super::Orthtree::insert_shared)).
#[derive(Debug, Clone, Copy)]
struct Retired {
    epoch: u64,
    start: u32,
    class: u8,
    cap: u32,
}

/// The allocator of the point pool: which slots are in use, the free lists, the retired
/// blocks. The point records themselves live in the tree's slot arena.
#[derive(Debug, Clone)]
pub(super) struct LeafPool {
    /// Slots in use at the front of the arena (blocks of leaves, free or retired).
    pub(super) len: usize,
    /// Head of the free list of each size class (`NIL` when empty).
    free: [u32; NUM_CLASSES],
    /// Total slots currently on free lists.
    free_slots: usize,
    /// Blocks replaced by shared inserts, oldest first.
    retired: VecDeque<Retired>,
    /// Slots of the retired blocks.
    retired_slots: usize,
}

impl LeafPool {
    /// An empty pool.
    pub(super) fn new() -> Self {
        Self {
            len: 0,
            free: [NIL; NUM_CLASSES],
            free_slots: 0,
            retired: VecDeque::new(),
            retired_slots: 0,
        }
    }

    /// Slots on free lists or retired (allocated, counted by `memory_bytes`, holding no point).
    pub(super) fn free_slots(&self) -> usize {
        self.free_slots + self.retired_slots
    }

    /// Upper bound on the number of new slots a push into a leaf of length `len` may append to
    /// the pool (0 if the point fits in the leaf's block).
    pub(super) fn push_needs(len: u32) -> u64 {
        if len == 0 {
            1
        } else if u64::from(len) == class_of(len).1 {
            class_of(len + 1).1
        } else {
            0
        }
    }

    /// Upper bound of [`push_needs`](Self::push_needs) over every leaf length up to `len`: the
    /// block a leaf of `len + 1` points takes (classes grow with their lengths).
    pub(super) fn push_needs_within(len: u32) -> u64 {
        class_of(len.saturating_add(1)).1
    }

    /// Grows `slots` (exclusive access) so that a push into a leaf of length `leaf_len` fits.
    /// Grows the tags too when the tree has them, to the slots' capacity.
    pub(super) fn reserve<const D: usize>(
        &self,
        slots: &mut Arena<[u32; D]>,
        tags: Option<&mut Arena<u32>>,
        leaf_len: u32,
    ) -> Result<(), AllocFailed> {
        let need = self.len + Self::push_needs(leaf_len) as usize;
        slots.try_set_capacity(self.len, slow_growth(slots.capacity(), need))?;
        match tags {
            Some(t) => t.try_set_capacity(self.len, slots.capacity()),
            None => Ok(()),
        }
    }

    /// A block of `cap` slots of class `class`, from the free list or the end of the pool
    /// (whose capacity the caller has checked).
    ///
    /// # Safety
    ///
    /// `slots` is the arena this pool carves (its first `self.len` slots are initialised, and
    /// no reader can reach a block on a free list or beyond `self.len`), and the caller is the
    /// tree's only writer (its lock held, or exclusive access).
    unsafe fn alloc<const D: usize>(
        &mut self,
        slots: &Arena<[u32; D]>,
        tags: Option<&Arena<u32>>,
        class: usize,
        cap: u64,
    ) -> u32 {
        let head = self.free[class];
        if head != NIL {
            // SAFETY: a free block's first slot holds its list link, written by `free` on this
            // (the writer's) thread or under the lock a previous writer released.
            self.free[class] = unsafe { slots.get(head as usize) }[0];
            self.free_slots -= cap as usize;
            head
        } else {
            let start = self.len;
            for i in start..start + cap as usize {
                // SAFETY: slots from `self.len` on are in no block, so no reader can reach them.
                unsafe { slots.init(i, [0; D]) };
                if let Some(t) = tags {
                    // SAFETY: as for the slot (the tags have the slots' capacity).
                    unsafe { t.init(i, 0) };
                }
            }
            self.len += cap as usize;
            start as u32
        }
    }

    /// Puts the block at `start` (class `class`) on its free list.
    ///
    /// # Safety
    ///
    /// As for [`alloc`](Self::alloc); besides, the block is one of this pool's and no reader
    /// can be scanning it (it was replaced with exclusive access, or retired and then
    /// reclaimed once every reader had announced a later epoch).
    unsafe fn free<const D: usize>(
        &mut self,
        slots: &Arena<[u32; D]>,
        start: u32,
        class: usize,
        cap: u64,
    ) {
        let mut link = [0; D];
        link[0] = self.free[class];
        // SAFETY: no reader can reach the block (the caller's contract).
        unsafe { slots.init(start as usize, link) };
        self.free[class] = start;
        self.free_slots += cap as usize;
    }

    /// Appends one point record to the leaf `leaf` and returns its new record, moving the
    /// points to a larger block if the block is full. The old block goes to its free list, or,
    /// with `retire = Some(epoch)` (readers may be scanning it), to the retired blocks. The
    /// caller has checked the slot capacity ([`push_needs`](Self::push_needs)). The new point
    /// is written before the record that makes it visible is returned. `tags`: the tree's tags
    /// (of the slots' capacity) and the new point's tag, when the tree keeps tags; they move
    /// with their points.
    ///
    /// # Safety
    ///
    /// As for [`alloc`](Self::alloc); besides, `leaf` is a record of this pool (its block is
    /// `leaf.start..` of class `class_of(leaf.len)`, its first `leaf.len` slots written) or
    /// the empty record, and `retire` is `Some(current epoch)` whenever other threads may be
    /// reading the tree (with `None` the replaced block is reused at once).
    pub(super) unsafe fn push<const D: usize>(
        &mut self,
        slots: &Arena<[u32; D]>,
        tags: Option<(&Arena<u32>, u32)>,
        leaf: Leaf,
        code: [u32; D],
        retire: Option<u64>,
    ) -> Leaf {
        let tag_arena = tags.map(|(t, _)| t);
        let n = leaf.len;
        let mut start = leaf.start;
        if n == 0 {
            let (class, cap) = class_of(1);
            // SAFETY: the caller's contract is `alloc`'s.
            start = unsafe { self.alloc(slots, tag_arena, class, cap) };
        } else {
            let (old_class, old_cap) = class_of(n);
            if u64::from(n) == old_cap {
                let (new_class, new_cap) = class_of(n + 1);
                // SAFETY: the caller's contract is `alloc`'s.
                start = unsafe { self.alloc(slots, tag_arena, new_class, new_cap) };
                for i in 0..n {
                    // SAFETY: the old block's first n slots are written (the caller's
                    // contract); the new block is fresh or was free, so no reader reaches it
                    // until the returned record is published.
                    unsafe {
                        slots.init((start + i) as usize, *slots.get((leaf.start + i) as usize));
                    }
                    if let Some(t) = tag_arena {
                        // SAFETY: as for the slot; tags are read only by the writer.
                        unsafe { t.init((start + i) as usize, *t.get((leaf.start + i) as usize)) };
                    }
                }
                match retire {
                    // SAFETY: `None` means no other thread reads the tree (the caller's
                    // contract), so nobody scans the old block.
                    None => unsafe { self.free(slots, leaf.start, old_class, old_cap) },
                    Some(epoch) => {
                        self.retired.push_back(Retired {
                            epoch,
                            start: leaf.start,
                            class: old_class as u8,
                            cap: old_cap as u32,
                        });
                        self.retired_slots += old_cap as usize;
                    }
                }
            }
        }
        // SAFETY: slot n of the block lies beyond the published length n (or the block is
        // new), so no reader reaches it until the returned record is published.
        unsafe { slots.init((start + n) as usize, code) };
        if let Some((t, tag)) = tags {
            // SAFETY: as for the slot.
            unsafe { t.init((start + n) as usize, tag) };
        }
        Leaf { start, len: n + 1 }
    }

    /// The epoch of the oldest retired block, if any.
    pub(super) fn oldest_retired(&self) -> Option<u64> {
        self.retired.front().map(|r| r.epoch)
    }

    /// Moves the retired blocks of epochs before `safe` to the free lists.
    ///
    /// # Safety
    ///
    /// As for [`alloc`](Self::alloc); besides, no reader still holds a block retired before
    /// epoch `safe`: every thread reading the tree has announced `safe` or later since, at a
    /// point where it held nothing from the tree, and the announcement was read with
    /// `Acquire` (or there is no reader: exclusive access).
    pub(super) unsafe fn reclaim<const D: usize>(&mut self, slots: &Arena<[u32; D]>, safe: u64) {
        while let Some(r) = self.retired.front().copied() {
            if r.epoch >= safe {
                break;
            }
            self.retired.pop_front();
            self.retired_slots -= r.cap as usize;
            // SAFETY: retired at an epoch before `safe`, so no reader holds it (the caller's
            // contract).
            unsafe { self.free(slots, r.start, r.class as usize, u64::from(r.cap)) };
        }
    }

    /// Whether enough slots sit on free lists to make [`compact`](Self::compact) worth it:
    /// more than 1/8 of the pool and more than 64 Ki slots.
    pub(super) fn wants_compaction(&self) -> bool {
        self.free_slots > (self.len / 8).max(1 << 16)
    }

    /// Slides every leaf's block down over the free blocks, in place (blocks keep their order
    /// and their class capacity), and empties the free lists (exclusive access: no reader, no
    /// retired block). O(slots + leaves log leaves), with a temporary index of 4 bytes per leaf.
    ///
    /// # Safety
    ///
    /// `slots` is the arena this pool carves and `leaves` are the records of its blocks.
    pub(super) unsafe fn compact<const D: usize>(
        &mut self,
        slots: &mut Arena<[u32; D]>,
        mut tags: Option<&mut Arena<u32>>,
        leaves: &mut [AtomicU64],
    ) {
        debug_assert!(self.retired.is_empty());
        let mut order: Vec<u32> = (0..leaves.len() as u32)
            .filter(|&l| Leaf::unpack(load_mut(&mut leaves[l as usize])).len > 0)
            .collect();
        order.sort_unstable_by_key(|&l| Leaf::unpack(load_mut(&mut leaves[l as usize])).start);
        // SAFETY: the pool's first `self.len` slots are initialised (`alloc` writes every slot
        // it appends), and `slots` is its arena (the caller's contract).
        let pool = unsafe { slots.prefix_mut(self.len) };
        // SAFETY: as for the slots: `alloc` writes the tag of every slot it appends.
        let mut tags = tags.as_mut().map(|t| unsafe { t.prefix_mut(self.len) });
        let mut cursor = 0usize;
        for l in order {
            let rec = &mut leaves[l as usize];
            let mut leaf = Leaf::unpack(load_mut(rec));
            let start = leaf.start as usize;
            debug_assert!(cursor <= start);
            pool.copy_within(start..start + leaf.len as usize, cursor);
            if let Some(t) = &mut tags {
                t.copy_within(start..start + leaf.len as usize, cursor);
            }
            leaf.start = cursor as u32;
            store_mut(rec, leaf.pack());
            cursor += class_of(leaf.len).1 as usize;
        }
        self.len = cursor;
        self.free = [NIL; NUM_CLASSES];
        self.free_slots = 0;
    }

    /// The point records of `leaf`.
    ///
    /// # Safety
    ///
    /// `leaf` is a record of the pool carving `slots`, read on the writer's thread or loaded
    /// with `Acquire` after its `Release` store, and its block is not written while the slice
    /// lives (a shared writer only appends beyond the record's length, and reuses a replaced
    /// block only after every reader that could hold it has announced a later epoch).
    #[inline(always)]
    pub(super) unsafe fn points<const D: usize>(
        slots: &Arena<[u32; D]>,
        leaf: Leaf,
    ) -> &[[u32; D]] {
        // SAFETY: the record's first `len` slots were written before it was published, and
        // are not written while the slice lives (the caller's contract).
        unsafe { slots.slice(leaf.start as usize, leaf.len as usize) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classes_are_contiguous_monotone_and_cover_u32() {
        let mut last = class_of(1);
        assert_eq!(last, (0, 1));
        let mut n: u64 = 2;
        while n <= u64::from(u32::MAX) {
            let (c, cap) = class_of(n as u32);
            assert!(cap >= n, "cap({n}) = {cap}");
            assert!(c < NUM_CLASSES);
            assert!(c == last.0 || c == last.0 + 1, "class jump at {n}");
            assert!(cap >= last.1);
            if c == last.0 {
                assert_eq!(cap, last.1);
            }
            // Next interesting n: the first one beyond this capacity.
            last = (c, cap);
            n = if n == cap { n + 1 } else { cap };
        }
        assert_eq!(class_of(u32::MAX).0, NUM_CLASSES - 1);
        assert_eq!(class_of(16), (15, 16));
        assert_eq!(class_of(17), (16, 20));
        assert_eq!(class_of(33), (20, 40));
    }

    #[test]
    fn pool_reuses_freed_blocks_and_keeps_contents() {
        let mut slots = Arena::<[u32; 2]>::new();
        let mut pool = LeafPool::new();
        let mut a = Leaf { start: 0, len: 0 };
        let mut b = Leaf { start: 0, len: 0 };
        // SAFETY (the pool calls below): one thread, no reader; `slots` is this pool's arena
        // and every record passed is the empty one or one the pool returned.
        unsafe {
            for i in 0..40u32 {
                pool.reserve(&mut slots, None, a.len).unwrap();
                a = pool.push(&slots, None, a, [i, 1000 + i], None);
                if i % 3 == 0 {
                    pool.reserve(&mut slots, None, b.len).unwrap();
                    b = pool.push(&slots, None, b, [i, 7], None);
                }
            }
            let pa: Vec<_> = LeafPool::points(&slots, a).to_vec();
            assert_eq!(pa.len(), 40);
            for (i, p) in pa.iter().enumerate() {
                assert_eq!(*p, [i as u32, 1000 + i as u32]);
            }
            let pb: Vec<_> = LeafPool::points(&slots, b).to_vec();
            assert_eq!(pb.len(), 14);
            for (k, p) in pb.iter().enumerate() {
                assert_eq!(*p, [3 * k as u32, 7]);
            }
            // Every block of a's and b's old classes was freed and partly reused by b.
            let used = (class_of(40).1 + class_of(14).1) as usize;
            assert_eq!(pool.len, used + pool.free_slots());
            let mut leaves = [AtomicU64::new(a.pack()), AtomicU64::new(b.pack())];
            pool.compact(&mut slots, None, &mut leaves);
            let [a, b] = leaves.map(|l| Leaf::unpack(l.into_inner()));
            assert_eq!(pool.len, used);
            assert_eq!(pool.free_slots(), 0);
            assert_eq!(LeafPool::points(&slots, a), &pa[..]);
            assert_eq!(LeafPool::points(&slots, b), &pb[..]);
            // Growing after compaction works.
            pool.reserve(&mut slots, None, b.len).unwrap();
            let b = pool.push(&slots, None, b, [99, 99], None);
            assert_eq!(LeafPool::points(&slots, b).len(), 15);
            assert_eq!(LeafPool::points(&slots, b)[14], [99, 99]);
            assert_eq!(LeafPool::points(&slots, a), &pa[..]);
        }
    }

    #[test]
    fn retired_blocks_wait_for_their_epoch() {
        let mut slots = Arena::<[u32; 2]>::new();
        let mut pool = LeafPool::new();
        let mut a = Leaf { start: 0, len: 0 };
        // SAFETY (the pool calls below): one thread, no reader, so no retired block is held;
        // `slots` is this pool's arena and every record passed is the empty one or one the
        // pool returned.
        unsafe {
            for i in 0..3u32 {
                pool.reserve(&mut slots, None, a.len).unwrap();
                a = pool.push(&slots, None, a, [i, i], Some(u64::from(i) + 1));
            }
            // Blocks of 1 (epoch 2) and 2 (epoch 3) slots are retired, not free.
            assert_eq!(pool.free_slots(), 3);
            assert_eq!(pool.free[0], NIL);
            pool.reclaim(&slots, 3);
            assert_ne!(pool.free[0], NIL);
            assert_eq!(pool.free[1], NIL);
            pool.reclaim(&slots, u64::MAX);
            assert_ne!(pool.free[1], NIL);
            assert_eq!(pool.free_slots(), 3);
            assert_eq!(LeafPool::points(&slots, a), &[[0, 0], [1, 1], [2, 2]]);
        }
    }
}
