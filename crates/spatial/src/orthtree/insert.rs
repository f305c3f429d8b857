//! Insertion: locating a point's leaf cell and fixed-point offsets, growing the root towards
//! it, creating the nodes and leaf on its path, and appending its record to the leaf's block.
//!
//! Invariants kept: an insert either succeeds or leaves the tree unchanged (every capacity and
//! coordinate check happens before the first change); leaf cells never move when the root
//! grows, so a point's stored position does not depend on insertion order; every node lies on
//! the path to at least one stored point.

use super::arena::{Arena, slow_growth};
use super::pool::LeafPool;
use super::sync::{AtomicU32, AtomicU64, Ordering, increment_mut};
use super::{
    CODE_SCALE, COORD_LIMIT_LEAVES, EMPTY, EPOCH_INSERTS, Leaf, Orthtree, OrthtreeError, Writer,
    decode,
};

/// Room [`Orthtree::prepare_shared`] reserves beyond its estimate, per arena (small in the
/// model-checked build, where every reserved element is a loom object).
const RESERVE_FLOOR: usize = if cfg!(loom) { 16 } else { 4096 };

impl<const D: usize> Orthtree<D> {
    /// Leaf cell of `p` in leaf sides and the fixed-point offsets inside it, after checking the
    /// point. Offsets are rounded to the nearest multiple of `s / 2^32`; one that rounds up to
    /// the cell's upper face is stored as offset 0 of the next cell (the same position), so the
    /// error stays within half a step on every axis.
    fn locate(&self, p: &[f64; D]) -> Result<([i64; D], [u32; D]), OrthtreeError> {
        let mut k = [0i64; D];
        let mut code = [0u32; D];
        let inv_step = CODE_SCALE / self.leaf_side;
        for (axis, &x) in p.iter().enumerate() {
            if !x.is_finite() {
                return Err(OrthtreeError::NonFinite { axis, value: x });
            }
            let u = x / self.leaf_side;
            if u.abs() >= COORD_LIMIT_LEAVES {
                return Err(OrthtreeError::OutOfRange {
                    axis,
                    value: x,
                    limit: COORD_LIMIT_LEAVES * self.leaf_side,
                });
            }
            let cell = u.floor();
            let t = ((x - cell * self.leaf_side) * inv_step).round();
            if t >= CODE_SCALE {
                k[axis] = cell as i64 + 1;
                code[axis] = 0;
            } else {
                k[axis] = cell as i64;
                // t is in [0, 2^32).
                code[axis] = t as u32;
            }
        }
        Ok((k, code))
    }

    /// Whether the leaf cell `k` lies inside the root.
    fn root_contains(&self, k: &[i64; D]) -> bool {
        let side = 1i64 << self.root_level;
        (0..D).all(|i| k[i] >= self.root_origin[i] && k[i] < self.root_origin[i] + side)
    }

    /// Length of the leaf for cell `k`, 0 if it does not exist yet (read-only).
    fn existing_leaf_len(&self, k: &[i64; D]) -> u32 {
        if self.root == EMPTY || !self.root_contains(k) {
            return 0;
        }
        let mut node = self.root;
        let mut level = self.root_level;
        loop {
            // SAFETY: `node` is the root or was read from a slot of its parent at level + 1 >= 2,
            // so it is a reached node; the child index is below FANOUT.
            let child =
                unsafe { self.child(node as usize * Self::FANOUT + self.child_index(k, level)) };
            if child == EMPTY {
                return 0;
            }
            if level == 1 {
                // SAFETY: a non-empty slot of a reached level-1 node: a reached leaf.
                return unsafe { self.leaf(child) }.len;
            }
            node = child;
            level -= 1;
        }
    }

    /// The index-limit checks of an insert into the leaf of length `leaf_len`, before any
    /// change.
    fn check_limits(&self, w: &Writer, leaf_len: u32) -> Result<(), OrthtreeError> {
        // A leaf as long as a `u32` counts cannot take another point.
        let slots = if leaf_len == u32::MAX {
            u64::MAX
        } else {
            LeafPool::push_needs(leaf_len)
        };
        self.check_limits_for(w, slots)
    }

    /// [`check_limits`](Self::check_limits) for a push that appends at most `slots` point
    /// slots. 128 nodes: the most one insert can add (root growth and a path down to a leaf).
    fn check_limits_for(&self, w: &Writer, slots: u64) -> Result<(), OrthtreeError> {
        if w.nodes as u64 + 128 > self.index_limit {
            return Err(OrthtreeError::CapacityExceeded("nodes"));
        }
        if w.leaves as u64 + 1 > self.index_limit {
            return Err(OrthtreeError::CapacityExceeded("leaves"));
        }
        if (w.pool.len as u64).saturating_add(slots) > self.index_limit {
            return Err(OrthtreeError::CapacityExceeded("point slots"));
        }
        Ok(())
    }

    /// Whether the arenas hold what an insert into the leaf of length `leaf_len` may append:
    /// a path of `root_level` nodes, one leaf, and a new block.
    fn has_room(&self, w: &Writer, leaf_len: u32) -> bool {
        self.has_room_for(w, LeafPool::push_needs(leaf_len))
    }

    /// [`has_room`](Self::has_room) for a push that appends at most `slots` point slots.
    fn has_room_for(&self, w: &Writer, slots: u64) -> bool {
        (w.nodes + self.root_level as usize) * Self::FANOUT <= self.children.capacity()
            && w.leaves < self.leaves.capacity()
            && w.pool.len as u64 + slots <= self.slots.capacity() as u64
    }

    /// Whether the index limits and the arenas admit a push into the longest leaf there could
    /// be ([`check_limits`](Self::check_limits) and [`has_room`](Self::has_room) for it), and
    /// so into any leaf: a sufficient condition for an insert under a root that holds its
    /// cell, checked without finding its leaf.
    fn fits_any_leaf(&self, w: &Writer) -> bool {
        w.longest_leaf < u32::MAX && {
            let slots = LeafPool::push_needs_within(w.longest_leaf);
            self.check_limits_for(w, slots).is_ok() && self.has_room_for(w, slots)
        }
    }

    /// An exclusive insert that needs neither a new root nor more room: places the point and
    /// returns `true` when the root holds leaf cell `k` and both the index limits and the
    /// arenas admit an insert into the longest leaf there could be (so into this one, whatever
    /// its length); else changes nothing and returns `false`, and the insert first finds its
    /// leaf's length, checks the limits for it and grows what it needs. In a growing cluster
    /// nearly every insert takes this path, which descends the tree once.
    fn place_if_room(&mut self, k: &[i64; D], code: [u32; D], tag: u32) -> bool {
        if self.root == EMPTY || !self.root_contains(k) {
            return false;
        }
        let mut w = self.writer();
        let fits = self.fits_any_leaf(&w);
        if fits {
            // SAFETY: `w` is this tree's writer; `&mut self` excludes readers, so the old
            // block may be freed at once (`None`).
            unsafe { self.place(&mut w, k, code, tag, None) };
        }
        fits
    }

    /// Initialises internal node `w.nodes` with empty child slots (not yet linked).
    ///
    /// # Safety
    ///
    /// `w` is this tree's writer state, held by the caller (its lock, or exclusive access):
    /// then node `w.nodes` is beyond every node published, so no reader can reach its slots.
    unsafe fn new_node(&self, w: &mut Writer) -> u32 {
        let n = w.nodes;
        for i in 0..Self::FANOUT {
            // SAFETY: node n is not linked yet (the caller's contract), so no reader reaches
            // its slots.
            unsafe {
                self.children
                    .init(n * Self::FANOUT + i, AtomicU32::new(EMPTY));
            }
        }
        w.nodes += 1;
        n as u32
    }

    /// Grows the arenas (exclusive access) so that the next insert fits; an allocation the
    /// system refuses is an error, with the tree's points unchanged.
    fn reserve_for_insert(&mut self, leaf_len: u32) -> Result<(), OrthtreeError> {
        let fanout = Self::FANOUT;
        let depth = self.root_level as usize + 64;
        let w = Self::writer_mut(&mut self.shared);
        let nodes = w.nodes * fanout;
        self.children
            .try_set_capacity(
                nodes,
                slow_growth(self.children.capacity(), nodes + depth * fanout),
            )
            .and_then(|()| {
                self.leaves
                    .try_set_capacity(w.leaves, slow_growth(self.leaves.capacity(), w.leaves + 1))
            })
            .and_then(|()| {
                w.pool
                    .reserve(&mut self.slots, self.tags.as_mut(), leaf_len)
            })
            .map_err(|e| OrthtreeError::OutOfMemory { bytes: e.bytes })
    }

    /// Doubles the root towards leaf cell `k` (the variable-precision paper builds its tree over a
    /// fixed domain; here the domain grows, the old root becoming a child of the new one).
    /// Exclusive access, with room for one node reserved.
    fn grow_root(&mut self, k: &[i64; D]) {
        let side = 1i64 << self.root_level;
        let mut origin = self.root_origin;
        let mut slot = 0;
        for i in 0..D {
            let lo = self.root_origin[i];
            let down = if k[i] < lo {
                true
            } else if k[i] >= lo + side {
                false
            } else {
                lo + side / 2 > self.anchor[i]
            };
            if down {
                origin[i] = lo - side;
                slot |= 1 << i;
            }
        }
        let mut w = self.writer();
        // SAFETY: `w` is this tree's writer, and `&mut self` excludes readers.
        let n = unsafe { self.new_node(&mut w) };
        drop(w);
        // SAFETY: node n was just initialised on this thread; `&mut self` excludes readers.
        unsafe { self.children.get(n as usize * Self::FANOUT + slot) }
            .store(self.root, Ordering::Relaxed);
        self.root = n;
        self.root_level += 1;
        self.root_origin = origin;
    }

    /// Makes the root contain leaf cell `k` (exclusive access): creates it for the first point
    /// `p`, or doubles it towards `k`.
    fn cover(&mut self, p: &[f64; D], k: &[i64; D]) -> Result<(), OrthtreeError> {
        if self.root == EMPTY {
            // Root of 2 x 2 leaf cells centred on the leaf-cell corner nearest to p.
            for i in 0..D {
                let frac = p[i] / self.leaf_side - k[i] as f64;
                self.root_origin[i] = if frac < 0.5 { k[i] - 1 } else { k[i] };
                self.anchor[i] = self.root_origin[i] + 1;
            }
            self.root_level = 1;
            if let Err(e) = self.reserve_for_insert(0) {
                self.root_level = 0;
                return Err(e);
            }
            let mut w = self.writer();
            // SAFETY: `w` is this tree's writer, and `&mut self` excludes readers.
            let n = unsafe { self.new_node(&mut w) };
            drop(w);
            self.root = n;
        }
        while !self.root_contains(k) {
            self.reserve_for_insert(0)?;
            self.grow_root(k);
        }
        Ok(())
    }

    /// Stores the record `code` in leaf cell `k` (inside the root; limits and room checked):
    /// appends it to the existing leaf, or builds the missing nodes and the leaf below the
    /// first empty slot of the path and links them with one `Release` store, so a concurrent
    /// reader sees either the tree before the insert or after it, and every node it reaches
    /// holds a point. Old blocks are retired at epoch `retire` if given (readers may scan
    /// them), else freed. Returns whether the leaf is new.
    ///
    /// # Safety
    ///
    /// `w` is this tree's writer state, held by the caller (its lock, or exclusive access),
    /// and `retire` is `Some(current epoch)` whenever other threads may be reading the tree.
    unsafe fn place(
        &self,
        w: &mut Writer,
        k: &[i64; D],
        code: [u32; D],
        tag: u32,
        retire: Option<u64>,
    ) -> bool {
        let tags = self.tags.as_ref().map(|t| (t, tag));
        let mut node = self.root;
        let mut level = self.root_level;
        loop {
            let slot = node as usize * Self::FANOUT + self.child_index(k, level);
            // SAFETY: `node` is the root or was read from its parent's slot below, so it is
            // initialised (by this writer or one whose lock release we acquired); the writer
            // only stores into reachable slots.
            let child = unsafe { self.children.get(slot) }.load(Ordering::Relaxed);
            if child == EMPTY {
                // Build the missing part of the path bottom-up, then link it.
                // SAFETY: `w` is this tree's writer and `retire` follows the readers (the
                // caller's contract); the empty record has no block.
                let rec = unsafe {
                    w.pool
                        .push(&self.slots, tags, Leaf { start: 0, len: 0 }, code, retire)
                };
                w.longest_leaf = w.longest_leaf.max(1);
                let l = w.leaves;
                // SAFETY: leaf record l is beyond every published leaf: no reader reaches it
                // until the `Release` store below links the path.
                unsafe { self.leaves.init(l, AtomicU64::new(rec.pack())) };
                w.leaves += 1;
                let mut below = l as u32;
                for lv in 1..level {
                    // SAFETY: `w` is this tree's writer (the caller's contract).
                    let n = unsafe { self.new_node(w) };
                    // SAFETY: node n was just initialised on this thread.
                    unsafe {
                        self.children
                            .get(n as usize * Self::FANOUT + self.child_index(k, lv))
                    }
                    .store(below, Ordering::Relaxed);
                    below = n;
                }
                // SAFETY: as for the load of this slot above.
                unsafe { self.children.get(slot) }.store(below, Ordering::Release);
                return true;
            }
            if level == 1 {
                // SAFETY: a non-empty slot of a level-1 node holds an initialised leaf record
                // (written before it was linked, by this writer or one whose lock release we
                // acquired); the writer only stores into it.
                let record = unsafe { self.leaves.get(child as usize) };
                let leaf = Leaf::unpack(record.load(Ordering::Relaxed));
                // SAFETY: `leaf` is this pool's current record of the leaf (only the writer
                // changes it), `w` is this tree's writer and `retire` follows the readers (the
                // caller's contract).
                let rec = unsafe { w.pool.push(&self.slots, tags, leaf, code, retire) };
                w.longest_leaf = w.longest_leaf.max(leaf.len.saturating_add(1));
                record.store(rec.pack(), Ordering::Release);
                return false;
            }
            node = child;
            level -= 1;
        }
    }

    /// The stored position of cell `k` and offsets `code`.
    fn decoded(&self, k: &[i64; D], code: &[u32; D]) -> [f64; D] {
        let mut stored = [0.0; D];
        for i in 0..D {
            stored[i] = decode(k[i] as f64 * self.leaf_side, code[i], self.step);
        }
        stored
    }

    /// Inserts a particle centre (the variable-precision paper, section 3.3: the particle is stored
    /// in the leaf containing it, in relative coordinates) and returns its stored position, which
    /// is what every query sees: within `leaf_side / 2^33` of `p` per coordinate (plus `f64`
    /// rounding at the coordinate's magnitude).
    ///
    /// Duplicate points are allowed. On error the tree is unchanged.
    pub fn insert(&mut self, p: [f64; D]) -> Result<[f64; D], OrthtreeError> {
        self.insert_tagged(p, 0)
    }

    /// [`insert`](Self::insert) of a point with tag `tag`, kept when the tree keeps tags
    /// ([`keep_tags`](Self::keep_tags)) and ignored otherwise.
    pub fn insert_tagged(&mut self, p: [f64; D], tag: u32) -> Result<[f64; D], OrthtreeError> {
        let (k, code) = self.locate(&p)?;
        if !self.place_if_room(&k, code, tag) {
            // Capacity checks before any change, so that an error leaves the tree as it was.
            let leaf_len = self.existing_leaf_len(&k);
            self.check_limits(&self.writer(), leaf_len)?;
            self.cover(&p, &k)?;
            self.reserve_for_insert(leaf_len)?;
            let mut w = self.writer();
            // SAFETY: `w` is this tree's writer; `&mut self` excludes readers, so the old
            // block may be freed at once (`None`).
            unsafe { self.place(&mut w, &k, code, tag, None) };
        }
        increment_mut(&mut self.shared.len);
        let w = Self::writer_mut(&mut self.shared);
        if w.pool.wants_compaction() {
            // SAFETY: the first `w.leaves` leaf records are initialised (`place` writes each
            // before counting it); `self.slots` is the arena of `w.pool`, whose blocks these
            // records describe.
            unsafe {
                let leaves = self.leaves.prefix_mut(w.leaves);
                w.pool.compact(&mut self.slots, self.tags.as_mut(), leaves);
            }
        }
        Ok(self.decoded(&k, &code))
    }

    /// Inserts `p` like [`insert`](Self::insert) while other threads query the tree (PDLA's
    /// shared tree, the variable-precision paper, section 3.4). Inserts are serialised by the
    /// tree's writer lock; a query running meanwhile sees the tree before or after the insert.
    ///
    /// Returns the stored position, as [`insert`](Self::insert) does, and whether the point
    /// opened a new leaf (the first point of its leaf cell): callers that index the leaves'
    /// boxes, such as DLA's coarse distance maps, act once per leaf.
    ///
    /// Needs the root to contain `p` and the room reserved by
    /// [`prepare_shared`](Self::prepare_shared); otherwise it fails with
    /// [`OrthtreeError::NeedsExclusive`] and changes nothing (insert the point with
    /// [`insert`](Self::insert) once the readers are gone).
    ///
    /// **Reclamation.** A leaf that outgrows its block moves to a larger one; the old block may
    /// still be scanned by a reader, so it is retired, not reused. Every reader announces the
    /// [`epoch`](Self::epoch) it read at a point where it holds nothing from the tree (a
    /// walker's birth, say); `readers_epoch` returns the smallest such announcement over the
    /// readers (`u64::MAX` when none is reading), and blocks retired before it are reused. The
    /// readers' announcements live on their own cache lines, which another core writes: the
    /// insert asks `readers_epoch` only when that can free a block (the oldest retired block
    /// is not before the last answer) and the epoch has advanced since it last asked, about
    /// once per 64 inserts. An old answer stays safe, as announcements only grow within a
    /// phase ([`prepare_shared`](Self::prepare_shared) forgets it).
    ///
    /// # Safety
    ///
    /// `readers_epoch` must not return more than the smallest epoch announced by a thread
    /// that may still be reading the tree, and a thread may announce only where it holds
    /// nothing from the tree (no query running, no [`Points`] iterator alive), with a
    /// `Release` store that `readers_epoch` reads with `Acquire`. A block is reused on that
    /// word: an answer that is too large lets the writer overwrite points a reader is
    /// scanning, a data race. `tests/loom_shared.rs` model-checks the protocol when this is
    /// kept. (`|| u64::MAX` is sound exactly when no other thread reads the tree.)
    ///
    /// [`Points`]: super::Points
    pub unsafe fn insert_shared(
        &self,
        p: [f64; D],
        readers_epoch: impl FnOnce() -> u64,
    ) -> Result<([f64; D], bool), OrthtreeError> {
        // SAFETY: the caller's contract is the same.
        unsafe { self.insert_shared_tagged(p, 0, readers_epoch) }
    }

    /// [`insert_shared`](Self::insert_shared) of a point with tag `tag` (see
    /// [`insert_tagged`](Self::insert_tagged)).
    ///
    /// # Safety
    ///
    /// As for [`insert_shared`](Self::insert_shared).
    pub unsafe fn insert_shared_tagged(
        &self,
        p: [f64; D],
        tag: u32,
        readers_epoch: impl FnOnce() -> u64,
    ) -> Result<([f64; D], bool), OrthtreeError> {
        let (k, code) = self.locate(&p)?;
        if self.root == EMPTY || !self.root_contains(&k) {
            return Err(OrthtreeError::NeedsExclusive);
        }
        let mut w = self.writer();
        // As `place_if_room`: room for a push into the longest leaf is room for this one,
        // without a first descent to find its length; else the exact checks.
        if !self.fits_any_leaf(&w) {
            let leaf_len = self.existing_leaf_len(&k);
            self.check_limits(&w, leaf_len)?;
            if !self.has_room(&w, leaf_len) {
                return Err(OrthtreeError::NeedsExclusive);
            }
        }
        let epoch = self.shared.epoch.load(Ordering::Relaxed);
        if w.pool.oldest_retired() >= Some(w.readers_known) && epoch > w.readers_asked_at {
            w.readers_known = readers_epoch();
            w.readers_asked_at = epoch;
        }
        let known = w.readers_known;
        // SAFETY: `w` is this tree's writer, locked. `known` is an answer of `readers_epoch`
        // (or 0): every reader has announced that epoch or a later one since it held nothing
        // from the tree (the caller's promise, see above), so no reader holds a block retired
        // before it.
        unsafe { w.pool.reclaim(&self.slots, known) };
        // SAFETY: `w` is this tree's writer, locked, and old blocks are retired at the current
        // epoch, as readers may be scanning them.
        let new_leaf = unsafe { self.place(&mut w, &k, code, tag, Some(epoch)) };
        self.shared.len.fetch_add(1, Ordering::Relaxed);
        w.since_epoch += 1;
        if w.since_epoch >= EPOCH_INSERTS {
            w.since_epoch = 0;
            // Release: a reader that reads the new value sees every record stored before it.
            self.shared.epoch.fetch_add(1, Ordering::AcqRel);
        }
        Ok((self.decoded(&k, &code), new_leaf))
    }

    /// The reclamation epoch a reader announces (see [`insert_shared`](Self::insert_shared)).
    pub fn epoch(&self) -> u64 {
        self.shared.epoch.load(Ordering::Acquire)
    }

    /// Prepares for [`insert_shared`](Self::insert_shared) of up to about `points` more points
    /// within `radius` of the origin: grows the root to cover the cube of half side `radius`
    /// and reserves room for the points at the tree's current nodes, leaves and slots per point
    /// (plus a quarter and a floor for small trees). Reserved room that is never used costs
    /// address space only: the pages are touched when used. Needs a non-empty tree.
    pub fn prepare_shared(&mut self, points: usize, radius: f64) -> Result<(), OrthtreeError> {
        if self.root == EMPTY {
            return Err(OrthtreeError::NeedsExclusive);
        }
        for corner in [-radius, radius] {
            let (k, _) = self.locate(&[corner; D])?;
            self.cover(&[corner; D], &k)?;
        }
        let n = self.len().max(1);
        let fanout = Self::FANOUT;
        let levels = self.root_level as usize;
        let w = Self::writer_mut(&mut self.shared);
        // A new phase has new readers, whose announcements start from nothing.
        w.readers_known = 0;
        w.readers_asked_at = 0;
        // Per point now, at least what a small tree of one leaf per point would need.
        let small = n < 4096;
        let per = |used: usize, floor: f64| {
            let ratio = used as f64 / n as f64;
            let ratio = if small { ratio.max(floor) } else { ratio };
            used + (ratio * points as f64 * 1.25) as usize + RESERVE_FLOOR
        };
        let nodes = per(w.nodes, 1.0) + levels;
        let leaves = per(w.leaves, 1.0);
        let slots = per(w.pool.len, 2.0);
        self.children
            .try_set_capacity(
                w.nodes * fanout,
                self.children.capacity().max(nodes * fanout),
            )
            .and_then(|()| {
                self.leaves
                    .try_set_capacity(w.leaves, self.leaves.capacity().max(leaves))
            })
            .and_then(|()| {
                self.slots
                    .try_set_capacity(w.pool.len, self.slots.capacity().max(slots))
            })
            .and_then(|()| match &mut self.tags {
                Some(t) => t.try_set_capacity(w.pool.len, self.slots.capacity()),
                None => Ok(()),
            })
            .map_err(|e| OrthtreeError::OutOfMemory { bytes: e.bytes })?;
        // SAFETY: `&mut self`: no reader holds anything from the tree, so every retired block
        // can be reused; `self.slots` is the arena of `w.pool`.
        unsafe { w.pool.reclaim(&self.slots, u64::MAX) };
        Ok(())
    }

    /// Ends shared inserting (exclusive access): reuses every retired block and returns the
    /// unused part of the reserved room, keeping the usual slack of about 1/8.
    pub fn finish_shared(&mut self) {
        let fanout = Self::FANOUT;
        let w = Self::writer_mut(&mut self.shared);
        // SAFETY: `&mut self`: no reader holds anything from the tree, so every retired block
        // can be reused; `self.slots` is the arena of `w.pool`.
        unsafe { w.pool.reclaim(&self.slots, u64::MAX) };
        let keep = |len: usize| len + (len / 8).max(64);
        // Shrinking: where the allocator refuses, the larger buffer simply stays.
        let _ = self.children.try_set_capacity(
            w.nodes * fanout,
            keep(w.nodes * fanout).min(self.children.capacity()),
        );
        let _ = self
            .leaves
            .try_set_capacity(w.leaves, keep(w.leaves).min(self.leaves.capacity()));
        let _ = self
            .slots
            .try_set_capacity(w.pool.len, keep(w.pool.len).min(self.slots.capacity()));
        if let Some(t) = &mut self.tags {
            // The tags follow the slots' capacity; if they cannot shrink with it, the
            // slots grow back to theirs, which they had a moment ago.
            if t.try_set_capacity(w.pool.len, self.slots.capacity())
                .is_err()
            {
                self.slots.set_capacity(w.pool.len, t.capacity());
            }
        }
    }

    /// The position [`insert`](Self::insert) would store for `p` (its fixed-point rounding),
    /// without inserting it: PDLA computes it outside the tree's writer (the variable-precision
    /// paper, section 3.4). Fails as `insert` would on a non-finite or out-of-range coordinate.
    pub fn stored_position(&self, p: &[f64; D]) -> Result<[f64; D], OrthtreeError> {
        let (k, code) = self.locate(p)?;
        Ok(self.decoded(&k, &code))
    }

    /// Makes the tree keep a 32-bit tag with every point from now on (4 bytes per point
    /// slot), given at insertion ([`insert_tagged`](Self::insert_tagged),
    /// [`insert_shared_tagged`](Self::insert_shared_tagged)) and looked up by stored position
    /// ([`tag_of`](Self::tag_of)): DLA tags each particle with its arrival index, so that the
    /// particle a walker touched names its parent. Queries never read the tags, so they cost
    /// nothing there. Only an empty tree can start keeping tags (else
    /// [`OrthtreeError::TagsOnNonEmpty`]); points inserted untagged get tag 0.
    pub fn keep_tags(&mut self) -> Result<(), OrthtreeError> {
        if !self.is_empty() {
            return Err(OrthtreeError::TagsOnNonEmpty);
        }
        if self.tags.is_none() {
            // An empty tree's pool holds no slot (points are never removed), so there is no
            // tag to write.
            debug_assert_eq!(Self::writer_mut(&mut self.shared).pool.len, 0);
            let mut tags = Arena::new();
            tags.try_set_capacity(0, self.slots.capacity())
                .map_err(|e| OrthtreeError::OutOfMemory { bytes: e.bytes })?;
            self.tags = Some(tags);
        }
        Ok(())
    }

    /// Whether the tree keeps tags ([`keep_tags`](Self::keep_tags)).
    pub fn keeps_tags(&self) -> bool {
        self.tags.is_some()
    }

    /// The tag of the point stored at `q` (a stored position, as an insert or a query
    /// returned it), or `None` when no point is stored there or the tree keeps no tags. Of
    /// several points stored at `q`, the first inserted. Takes the writer's lock, so it may
    /// run while other threads insert; O(depth + points in the leaf).
    pub fn tag_of(&self, q: &[f64; D]) -> Option<u32> {
        let tags = self.tags.as_ref()?;
        let (k, code) = self.locate(q).ok()?;
        // The lock: no insert changes a node, record, slot or tag meanwhile.
        let _w = self.writer();
        if self.root == EMPTY || !self.root_contains(&k) {
            return None;
        }
        let mut node = self.root;
        let mut level = self.root_level;
        #[allow(unsafe_code)]
        loop {
            let slot = node as usize * Self::FANOUT + self.child_index(&k, level);
            // SAFETY: `node` is the root or a non-empty value read below from a reached
            // node's slot, so it was initialised before it was linked; the writer's lock is
            // held, so nothing is written meanwhile.
            let child = unsafe { self.children.get(slot) }.load(Ordering::Acquire);
            if child == EMPTY {
                return None;
            }
            if level == 1 {
                // SAFETY: a non-empty slot of a level-1 node holds a published leaf record;
                // its block's first `len` slots and tags were written before it was
                // published, and the lock keeps them unchanged.
                let leaf = Leaf::unpack(
                    unsafe { self.leaves.get(child as usize) }.load(Ordering::Acquire),
                );
                let points = unsafe { LeafPool::points(&self.slots, leaf) };
                let i = points.iter().position(|c| *c == code)?;
                // SAFETY: as for the slots: the tag of a published slot is written first.
                return Some(unsafe { *tags.get(leaf.start as usize + i) });
            }
            node = child;
            level -= 1;
        }
    }
}
