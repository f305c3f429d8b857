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

/// Grows `v` so it can take `additional` more elements, by at most 1/8 of its capacity beyond
/// what is needed (plus a small floor), instead of `Vec`'s doubling. This keeps the heap slack
/// that [`memory_bytes`](super::Orthtree::memory_bytes) reports at about 12 % at any size.
pub(super) fn reserve_slowly<T>(v: &mut Vec<T>, additional: usize) {
    let need = v.len() + additional;
    if need > v.capacity() {
        let target = need.max(v.capacity() + (v.capacity() / 8).max(64));
        v.reserve_exact(target - v.len());
    }
}

/// The pool of fixed-point point records shared by all leaves.
#[derive(Clone)]
pub(super) struct LeafPool<const D: usize> {
    /// Point records: per coordinate, the offset inside the leaf cell in units of
    /// `leaf_side / 2^32`. Free blocks are also in here.
    pub(super) slots: Vec<[u32; D]>,
    /// Head of the free list of each size class (`NIL` when empty).
    free: [u32; NUM_CLASSES],
    /// Total slots currently on free lists.
    free_slots: usize,
}

impl<const D: usize> LeafPool<D> {
    /// An empty pool.
    pub(super) fn new() -> Self {
        Self {
            slots: Vec::new(),
            free: [NIL; NUM_CLASSES],
            free_slots: 0,
        }
    }

    /// Slots sitting on free lists (allocated, counted by `memory_bytes`, holding no point).
    pub(super) fn free_slots(&self) -> usize {
        self.free_slots
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

    /// A block of `cap` slots of class `class`, from the free list or the end of the pool.
    fn alloc(&mut self, class: usize, cap: u64) -> u32 {
        let head = self.free[class];
        if head != NIL {
            self.free[class] = self.slots[head as usize][0];
            self.free_slots -= cap as usize;
            head
        } else {
            let start = self.slots.len();
            let cap = cap as usize;
            reserve_slowly(&mut self.slots, cap);
            self.slots.resize(start + cap, [0; D]);
            start as u32
        }
    }

    /// Puts the block at `start` (class `class`, `cap` slots) on its free list.
    fn free(&mut self, start: u32, class: usize, cap: u64) {
        self.slots[start as usize][0] = self.free[class];
        self.free[class] = start;
        self.free_slots += cap as usize;
    }

    /// Appends one point record to `leaf`, moving the leaf to a larger block if its block is
    /// full. The caller has checked with [`push_needs`](Self::push_needs) that the pool indices
    /// stay below `u32::MAX`.
    pub(super) fn push(&mut self, leaf: &mut Leaf, code: [u32; D]) {
        let n = leaf.len;
        if n == 0 {
            let (class, cap) = class_of(1);
            leaf.start = self.alloc(class, cap);
        } else {
            let (old_class, old_cap) = class_of(n);
            if u64::from(n) == old_cap {
                let (new_class, new_cap) = class_of(n + 1);
                let new_start = self.alloc(new_class, new_cap);
                let old = leaf.start as usize;
                self.slots
                    .copy_within(old..old + n as usize, new_start as usize);
                self.free(leaf.start, old_class, old_cap);
                leaf.start = new_start;
            }
        }
        self.slots[(leaf.start + n) as usize] = code;
        leaf.len = n + 1;
    }

    /// Whether enough slots sit on free lists to make [`compact`](Self::compact) worth it:
    /// more than 1/8 of the pool and more than 64 Ki slots.
    pub(super) fn wants_compaction(&self) -> bool {
        self.free_slots > (self.slots.len() / 8).max(1 << 16)
    }

    /// Slides every leaf's block down over the free blocks, in place (blocks keep their order
    /// and their class capacity), and empties the free lists. The pool's capacity is kept for
    /// the blocks allocated next. O(slots + leaves log leaves), with a temporary index of 4
    /// bytes per leaf.
    pub(super) fn compact(&mut self, leaves: &mut [Leaf]) {
        let mut order: Vec<u32> = (0..leaves.len() as u32)
            .filter(|&l| leaves[l as usize].len > 0)
            .collect();
        order.sort_unstable_by_key(|&l| leaves[l as usize].start);
        let mut cursor = 0usize;
        for l in order {
            let leaf = &mut leaves[l as usize];
            let start = leaf.start as usize;
            debug_assert!(cursor <= start);
            self.slots
                .copy_within(start..start + leaf.len as usize, cursor);
            leaf.start = cursor as u32;
            cursor += class_of(leaf.len).1 as usize;
        }
        self.slots.truncate(cursor);
        self.free = [NIL; NUM_CLASSES];
        self.free_slots = 0;
    }

    /// The point records of `leaf`.
    #[inline]
    pub(super) fn points(&self, leaf: Leaf) -> &[[u32; D]] {
        let s = leaf.start as usize;
        &self.slots[s..s + leaf.len as usize]
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
        let mut pool = LeafPool::<2>::new();
        let mut a = Leaf { start: 0, len: 0 };
        let mut b = Leaf { start: 0, len: 0 };
        for i in 0..40u32 {
            pool.push(&mut a, [i, 1000 + i]);
            if i % 3 == 0 {
                pool.push(&mut b, [i, 7]);
            }
        }
        let pa: Vec<_> = pool.points(a).to_vec();
        assert_eq!(pa.len(), 40);
        for (i, p) in pa.iter().enumerate() {
            assert_eq!(*p, [i as u32, 1000 + i as u32]);
        }
        let pb: Vec<_> = pool.points(b).to_vec();
        assert_eq!(pb.len(), 14);
        for (k, p) in pb.iter().enumerate() {
            assert_eq!(*p, [3 * k as u32, 7]);
        }
        // Every block of a's and b's old classes was freed and partly reused by b.
        let used = (class_of(40).1 + class_of(14).1) as usize;
        assert_eq!(pool.slots.len(), used + pool.free_slots());
        let mut leaves = [a, b];
        pool.compact(&mut leaves);
        assert_eq!(pool.slots.len(), used);
        assert_eq!(pool.free_slots(), 0);
        assert_eq!(pool.points(leaves[0]), &pa[..]);
        assert_eq!(pool.points(leaves[1]), &pb[..]);
        // Growing after compaction works.
        pool.push(&mut leaves[1], [99, 99]);
        assert_eq!(pool.points(leaves[1]).len(), 15);
        assert_eq!(pool.points(leaves[1])[14], [99, 99]);
        assert_eq!(pool.points(leaves[0]), &pa[..]);
    }
}
