//! A dense per-cell index over the unbounded integer plane ([`CellIndex`]): at most one item
//! per cell, each item an id (`u64`) and one of two kinds. It is the animat model's hot-path
//! neighbour search (the grid boxes of [`plane`](crate::plane) remain the paper's baseline
//! setting): the model asks "what stands on this cell", reads the cells around an animat
//! through a [`Window`], its row words ([`near`]) and its rings of cells ([`rings`]), and
//! answers the queries beyond them with rings of grid boxes read from the index ([`wide`]).
//!
//! The plane is cut into square tiles of [`TILE`] x [`TILE`] cells; each tile that holds an
//! item has a cell byte per cell and, in a parallel array, the id of the item on the cell.
//! A cell byte holds the kind in its low two bits ([`KIND_MASK`]: [`FREE`], [`KIND_A`] or
//! [`KIND_B`]) and the occupant's id bucket in the other six ([`CellIndex::bucket`]), which
//! settles most id comparisons without the ids. Cell bytes are stored in 8 x 8 blocks of 64
//! bytes, so a cell's whole 5 x 5 neighbourhood lies in at most four cache lines. Tiles are
//! kept in a vector; a dense directory over the rectangle of tile coordinates in use (grown
//! with a margin, at most 2^18 entries) and, beyond it, a hash map (rustc-hash) go from tile
//! coordinates to the tile's slot. A tile that empties returns to a free list, so memory
//! follows the occupied area, not the area the items ever roamed.
//!
//! Reads go through a [`Window`]: the at most 2 x 2 tiles covering a square of half-side up
//! to [`WINDOW_MAX`] around the query point, fetched with at most four directory lookups;
//! every cell read after that is an array index, and [`Window::rows`] reads 8 cells of a row
//! as one word. Wide queries read rectangles ([`CellIndex::scan_rect`]): each tile keeps, per
//! kind, a count and a bit per 8 x 8 block of the items in it, so empty tiles and blocks are
//! skipped without reading their cells.
//!
//! Invariants: a cell byte is [`FREE`] exactly when no item stands on the cell, and then its
//! id slot is unused; an occupied cell's byte holds its occupant's kind and the bucket of its
//! id under the current bucket map, which is non-decreasing in the id; a tile is in use
//! exactly while it holds an item (`count` is its number of occupied cells); a tile's block
//! counts are the occupied cells of each kind in each block, and its block masks have a bit
//! set exactly for the blocks with a nonzero count; the dense directory agrees with the map for
//! every tile coordinate in its rectangle.
//!
//! Every answer is exact and independent of the tiles, the directory and the box side of the
//! wide queries: `tests/cells_props.rs` checks them against a brute-force scan.

pub mod near;
pub mod rings;
pub mod wide;

use rustc_hash::FxHashMap;
use std::ops::ControlFlow;

/// log2 of the tile side.
const SHIFT: u32 = 6;
/// Tile side in cells.
pub const TILE: i64 = 1 << SHIFT;
/// Largest half-side of a [`Window`] (so that a window spans at most two tiles per axis).
pub const WINDOW_MAX: i64 = TILE / 2;
/// Positions farther than this from the `i64` limits are served by windows; for the rest
/// [`CellIndex::window`] returns `None` and the caller uses the wide queries.
const EDGE_GUARD: i64 = 4 * TILE;

/// The kind byte of a free cell.
pub const FREE: u8 = 0;

/// The first kind of item (kind byte 1; the animat model's foxes).
pub const KIND_A: u8 = 1;

/// The second kind of item (kind byte 2; the animat model's rabbits).
pub const KIND_B: u8 = 2;

/// The kind bits of a cell byte: [`FREE`], [`KIND_A`] or [`KIND_B`]. The other six bits hold
/// the occupant's id bucket (see [`CellIndex::bucket`]). As a set of kinds (in
/// [`CellIndex::scan_rect`] and the wide queries) it means both.
pub const KIND_MASK: u8 = 3;

#[derive(Debug, Clone)]
struct Tile {
    count: u32,
    /// Occupied cells of each 8 x 8 block, by kind (index `kind - 1`); boxed, so that the
    /// tile records that the wide queries scan for their block masks stay small.
    block_counts: Box<[[u8; BLOCKS]; 2]>,
    /// Bit `b` set when block `b` holds an item of the kind (same index).
    block_masks: [u64; 2],
}

/// 8 x 8 blocks of cells in a tile.
const BLOCKS: usize = CELLS / 64;

impl Tile {
    /// Counts an occupant of kind byte `k` (not [`FREE`]) in the block of cell offset `off`.
    #[inline]
    fn enter(&mut self, k: u8, off: usize) {
        let (s, b) = (usize::from(k & KIND_MASK) - 1, off >> 6);
        self.block_counts[s][b] += 1;
        self.block_masks[s] |= 1 << b;
    }

    /// Uncounts an occupant of kind byte `k` (not [`FREE`]) in the block of cell offset `off`.
    #[inline]
    fn leave(&mut self, k: u8, off: usize) {
        let (s, b) = (usize::from(k & KIND_MASK) - 1, off >> 6);
        self.block_counts[s][b] -= 1;
        if self.block_counts[s][b] == 0 {
            self.block_masks[s] &= !(1 << b);
        }
    }
}

/// The cell index; see the module documentation.
///
/// ```
/// use spatial::cells::{CellIndex, FREE, KIND_A, KIND_B};
/// let mut c = CellIndex::default();
/// c.set([3, -4], KIND_A, 7);
/// c.set([70, 0], KIND_B, 9);
/// assert_eq!((c.kind([3, -4]), c.id([3, -4])), (KIND_A, 7));
/// c.relocate([3, -4], [4, -4]);
/// assert_eq!(c.kind([3, -4]), FREE);
/// let w = c.window([5, -5], 8).unwrap();
/// assert_eq!(w.at(4, -4), KIND_A);
/// // The nearest item of kind B within squared distance 5000 of [4, -4], with boxes of side 60.
/// assert_eq!(c.nearest_within([4, -4], KIND_B, 5000, 60).0, Some([70, 0]));
/// ```
#[derive(Debug, Clone, Default)]
pub struct CellIndex {
    /// Every tile's slot by tile coordinates.
    map: FxHashMap<[i64; 2], u32>,
    tiles: Vec<Tile>,
    /// The cell bytes of every tile, by slot (parallel to `tiles`), in one allocation: the
    /// bytes that every query reads lie together instead of between the tiles' ids.
    kinds: Vec<[u8; CELLS]>,
    /// The ids on the cells of every tile, by slot, also in one allocation.
    ids: Vec<[u64; CELLS]>,
    free: Vec<u32>,
    /// Dense directory of the tiles in the rectangle of tile coordinates `[dx0, dx0 + dw) x
    /// [dy0, dy0 + dh)`: slot + 1, or 0 for no tile. Complete for its rectangle (a lookup
    /// there never needs the map).
    dir: Vec<u32>,
    dx0: i64,
    dy0: i64,
    dw: u64,
    dh: u64,
    /// Ids map to buckets `min(63, (id - bucket_base) >> bucket_shift)`.
    bucket_base: u64,
    bucket_shift: u32,
}

/// Largest number of entries of the dense tile directory (1 MiB); tiles beyond the rectangle
/// it can cover are found through the hash map alone.
const DIR_MAX: u64 = 1 << 18;

const CELLS: usize = (TILE * TILE) as usize;

/// Bytes of one tile: a cell byte and an 8-byte id per cell (36 KiB). A tile is allocated for
/// each 64 x 64 square holding an item, so in a dilute set, with items farther apart than a
/// tile, this is the memory of each item.
pub const TILE_BYTES: u64 = (CELLS * (1 + size_of::<u64>())) as u64;

/// Offset of a cell inside its tile: 8 x 8 blocks of cells, each block 64 consecutive bytes
/// (one cache line of kind bytes), blocks in row-major order.
#[inline(always)]
fn offset(x: i64, y: i64) -> usize {
    let block = ((y >> 3) & 7) << 3 | ((x >> 3) & 7);
    (block << 6 | (y & 7) << 3 | (x & 7)) as usize
}

#[inline]
fn split(p: [i64; 2]) -> ([i64; 2], usize) {
    ([p[0] >> SHIFT, p[1] >> SHIFT], offset(p[0], p[1]))
}

impl CellIndex {
    /// The slot of the tile with coordinates `key`, if there is one.
    #[inline(always)]
    fn slot(&self, key: [i64; 2]) -> Option<u32> {
        let u = key[0].wrapping_sub(self.dx0) as u64;
        let v = key[1].wrapping_sub(self.dy0) as u64;
        if u < self.dw && v < self.dh {
            self.dir[(v * self.dw + u) as usize].checked_sub(1)
        } else {
            self.map.get(&key).copied()
        }
    }

    /// Whether tile coordinates `key` lie in the directory's rectangle.
    #[inline]
    fn in_dir(&self, key: [i64; 2]) -> Option<usize> {
        let u = key[0].wrapping_sub(self.dx0) as u64;
        let v = key[1].wrapping_sub(self.dy0) as u64;
        (u < self.dw && v < self.dh).then(|| (v * self.dw + u) as usize)
    }

    /// Records a new tile `t` at `key` in the map and, growing the directory's rectangle
    /// (with a margin) when it stays within [`DIR_MAX`] entries, in the directory.
    fn register(&mut self, key: [i64; 2], t: u32) {
        self.map.insert(key, t);
        if let Some(i) = self.in_dir(key) {
            self.dir[i] = t + 1;
            return;
        }
        // Tile coordinates are within +-2^58, so these sums cannot overflow.
        let (x0, x1, y0, y1) = if self.dw == 0 {
            (key[0], key[0], key[1], key[1])
        } else {
            (
                self.dx0.min(key[0]),
                (self.dx0 + self.dw as i64 - 1).max(key[0]),
                self.dy0.min(key[1]),
                (self.dy0 + self.dh as i64 - 1).max(key[1]),
            )
        };
        let mx = ((x1 - x0) / 4).max(2);
        let my = ((y1 - y0) / 4).max(2);
        let (x0, x1, y0, y1) = (x0 - mx, x1 + mx, y0 - my, y1 + my);
        let (w, h) = ((x1 - x0 + 1) as u64, (y1 - y0 + 1) as u64);
        if w.saturating_mul(h) > DIR_MAX {
            return;
        }
        self.dx0 = x0;
        self.dy0 = y0;
        self.dw = w;
        self.dh = h;
        self.dir.clear();
        self.dir.resize((w * h) as usize, 0);
        for (&k, &t) in &self.map {
            if let Some(i) = self.in_dir(k) {
                self.dir[i] = t + 1;
            }
        }
    }

    /// The kind byte on cell `p` ([`FREE`] when free).
    #[inline]
    pub fn kind(&self, p: [i64; 2]) -> u8 {
        let (key, off) = split(p);
        match self.slot(key) {
            Some(t) => self.kinds[t as usize][off] & KIND_MASK,
            None => FREE,
        }
    }

    /// The bucket of an id, kept in the top six bits of its cell byte: non-decreasing in the
    /// id, so between two items the one with the lower bucket has the lower id, and only
    /// equal buckets need the ids themselves.
    #[inline]
    pub fn bucket(&self, id: u64) -> u8 {
        let d = id.saturating_sub(self.bucket_base) >> self.bucket_shift;
        d.min(63) as u8
    }

    /// Whether the bucket of `id` would exceed 63 (and be capped).
    #[inline]
    pub fn bucket_capped(&self, id: u64) -> bool {
        id.saturating_sub(self.bucket_base) >> self.bucket_shift > 63
    }

    /// The lowest id bucket 0 stands for, and the bucket width (log2).
    #[inline]
    pub fn bucket_range(&self) -> (u64, u32) {
        (self.bucket_base, self.bucket_shift)
    }

    /// Maps ids to buckets afresh (`base`, `shift < 64`) and rewrites the bucket of every
    /// item, given as (cell, id).
    pub fn rebucket(
        &mut self,
        base: u64,
        shift: u32,
        items: impl Iterator<Item = ([i64; 2], u64)>,
    ) {
        debug_assert!(shift < 64);
        self.bucket_base = base;
        self.bucket_shift = shift;
        for (p, id) in items {
            let b = self.bucket(id) << 2;
            let (key, off) = split(p);
            if let Some(t) = self.slot(key) {
                let k = &mut self.kinds[t as usize][off];
                *k = (*k & KIND_MASK) | b;
            }
        }
    }

    /// Whether cell `p` is occupied.
    #[inline]
    pub fn occupied(&self, p: [i64; 2]) -> bool {
        self.kind(p) != FREE
    }

    /// Puts item `id` of kind byte `k` ([`KIND_A`] or [`KIND_B`]) on the free cell `p`.
    #[inline]
    pub fn set(&mut self, p: [i64; 2], k: u8, id: u64) {
        debug_assert!(k != FREE && k & KIND_MASK == k);
        let b = self.bucket(id) << 2;
        let (key, off) = split(p);
        let t = match self.slot(key) {
            Some(t) => t,
            None => {
                let t = match self.free.pop() {
                    Some(t) => t,
                    None => {
                        self.push_tile_arrays();
                        self.tiles.push(Tile {
                            count: 0,
                            block_counts: Box::new([[0; BLOCKS]; 2]),
                            block_masks: [0; 2],
                        });
                        (self.tiles.len() - 1) as u32
                    }
                };
                self.register(key, t);
                t
            }
        };
        let tile = &mut self.tiles[t as usize];
        let kinds = &mut self.kinds[t as usize];
        debug_assert_eq!(kinds[off], FREE, "cell {p:?} already occupied");
        kinds[off] = k | b;
        self.ids[t as usize][off] = id;
        tile.count += 1;
        tile.enter(k, off);
    }

    /// Adds a new slot's cell bytes (all [`FREE`]) and ids. The two vectors grow by a quarter
    /// at a time, not double: they hold most of the index's memory, so doubling could ask
    /// for nearly twice what a large run uses in one allocation. The smaller steps cost little:
    /// the system allocator (glibc's) grows a large allocation by remapping its pages, not by
    /// copying them.
    fn push_tile_arrays(&mut self) {
        if self.ids.len() == self.ids.capacity() {
            let more = (self.ids.len() / 4).max(16);
            self.kinds.reserve_exact(more);
            self.ids.reserve_exact(more);
        }
        self.kinds.push([FREE; CELLS]);
        self.ids.push([0; CELLS]);
    }

    /// Frees cell `p` (which must be occupied).
    #[inline]
    pub fn clear(&mut self, p: [i64; 2]) {
        let (key, off) = split(p);
        let Some(t) = self.slot(key) else {
            debug_assert!(false, "clearing a cell of a missing tile");
            return;
        };
        let tile = &mut self.tiles[t as usize];
        let kinds = &mut self.kinds[t as usize];
        debug_assert_ne!(kinds[off], FREE);
        let k = kinds[off];
        tile.leave(k, off);
        kinds[off] = FREE;
        tile.count -= 1;
        if tile.count == 0 {
            self.map.remove(&key);
            if let Some(i) = self.in_dir(key) {
                self.dir[i] = 0;
            }
            self.free.push(t);
        }
    }

    /// Moves the occupant of `from` to the free cell `to`.
    #[inline]
    pub fn relocate(&mut self, from: [i64; 2], to: [i64; 2]) {
        let (kf, of) = split(from);
        let (kt, ot) = split(to);
        if kf == kt {
            if let Some(t) = self.slot(kf) {
                let tile = &mut self.tiles[t as usize];
                let kinds = &mut self.kinds[t as usize];
                let k = kinds[of];
                if of >> 6 != ot >> 6 {
                    tile.leave(k, of);
                    tile.enter(k, ot);
                }
                kinds[ot] = k;
                let ids = &mut self.ids[t as usize];
                ids[ot] = ids[of];
                kinds[of] = FREE;
                return;
            }
        }
        let k = self.kind(from);
        let id = self.id(from);
        self.clear(from);
        self.set(to, k, id);
    }

    /// Id of the item on the occupied cell `p`.
    #[inline]
    pub fn id(&self, p: [i64; 2]) -> u64 {
        let (key, off) = split(p);
        self.slot(key).map_or(0, |t| self.ids[t as usize][off])
    }

    /// A window of half-side `k <= WINDOW_MAX` around `p`, or `None` when `p` is too close to
    /// the `i64` limits for the fast path.
    #[inline]
    pub fn window(&self, p: [i64; 2], k: i64) -> Option<Window<'_>> {
        debug_assert!((0..=WINDOW_MAX).contains(&k));
        let lo = i64::MIN + EDGE_GUARD;
        let hi = i64::MAX - EDGE_GUARD;
        if p[0] < lo || p[0] > hi || p[1] < lo || p[1] > hi {
            return None;
        }
        let tx0 = (p[0] - k) >> SHIFT;
        let ty0 = (p[1] - k) >> SHIFT;
        let tx1 = (p[0] + k) >> SHIFT;
        let ty1 = (p[1] + k) >> SHIFT;
        let fetch = |tx: i64, ty: i64| -> (&[u8; CELLS], &[u64; CELLS]) {
            match self.slot([tx, ty]) {
                Some(t) => {
                    let t = t as usize;
                    (&self.kinds[t], &self.ids[t])
                }
                None => (&EMPTY_KINDS, &EMPTY_IDS),
            }
        };
        let t00 = fetch(tx0, ty0);
        let t10 = if tx1 != tx0 { fetch(tx1, ty0) } else { t00 };
        let (t01, t11) = if ty1 != ty0 {
            let a = fetch(tx0, ty1);
            (a, if tx1 != tx0 { fetch(tx1, ty1) } else { a })
        } else {
            (t00, t10)
        };
        Some(Window {
            bx: tx0 << SHIFT,
            by: ty0 << SHIFT,
            kinds: [t00.0, t10.0, t01.0, t11.0],
            ids: [t00.1, t10.1, t01.1, t11.1],
        })
    }

    /// Tiles in use (each holds at least one item).
    #[inline]
    pub fn tiles_in_use(&self) -> usize {
        self.map.len()
    }

    /// Calls `f(x, y, byte)` for every occupied cell `(x, y)` of the rectangle `x0..=x1`,
    /// `y0..=y1` whose kind meets `kinds` (bit 0 [`KIND_A`], bit 1 [`KIND_B`]: the kind
    /// bytes' own bits), with its whole cell byte, in no particular order, until `f` breaks. Tiles
    /// and 8 x 8 blocks without such an item are skipped without reading their cells, so
    /// the cost follows the occupied blocks rather than the area; a rectangle covering more
    /// tile positions than there are tiles in use goes through the tiles in use instead.
    pub fn scan_rect(
        &self,
        [x0, x1]: [i64; 2],
        [y0, y1]: [i64; 2],
        kinds: u8,
        mut f: impl FnMut(i64, i64, u8) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if x0 > x1 || y0 > y1 || kinds & KIND_MASK == 0 {
            return ControlFlow::Continue(());
        }
        let (tx0, tx1, ty0, ty1) = (x0 >> SHIFT, x1 >> SHIFT, y0 >> SHIFT, y1 >> SHIFT);
        let span =
            (i128::from(tx1) - i128::from(tx0) + 1) * (i128::from(ty1) - i128::from(ty0) + 1);
        let rect = Rect {
            x0,
            x1,
            y0,
            y1,
            kinds,
        };
        if span > self.map.len() as i128 {
            for (&[tx, ty], &t) in &self.map {
                if (tx0..=tx1).contains(&tx) && (ty0..=ty1).contains(&ty) {
                    self.scan_tile(t, [tx, ty], &rect, &mut f)?;
                }
            }
        } else {
            for ty in ty0..=ty1 {
                for tx in tx0..=tx1 {
                    if let Some(t) = self.slot([tx, ty]) {
                        self.scan_tile(t, [tx, ty], &rect, &mut f)?;
                    }
                }
            }
        }
        ControlFlow::Continue(())
    }

    /// [`CellIndex::scan_rect`] within tile `t` at tile coordinates `key`, which must meet the
    /// rectangle.
    fn scan_tile(
        &self,
        t: u32,
        key: [i64; 2],
        r: &Rect,
        f: &mut impl FnMut(i64, i64, u8) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let tile = &self.tiles[t as usize];
        let kinds = &self.kinds[t as usize];
        // `key` is some cell's coordinates shifted right, so shifting back cannot overflow,
        // nor can adding TILE - 1; the rectangle meets the tile, so the local bounds lie in
        // 0..TILE.
        let (ox, oy) = (key[0] << SHIFT, key[1] << SHIFT);
        let lx0 = (r.x0.max(ox) - ox) as usize;
        let lx1 = (r.x1.min(ox + (TILE - 1)) - ox) as usize;
        let ly0 = (r.y0.max(oy) - oy) as usize;
        let ly1 = (r.y1.min(oy + (TILE - 1)) - oy) as usize;
        let mut m = 0;
        if r.kinds & 1 != 0 {
            m |= tile.block_masks[0];
        }
        if r.kinds & 2 != 0 {
            m |= tile.block_masks[1];
        }
        // Only the blocks that meet the rectangle.
        let cols = ((1u64 << ((lx1 >> 3) - (lx0 >> 3) + 1)) - 1) << (lx0 >> 3);
        let mut within = 0u64;
        for br in (ly0 >> 3)..=(ly1 >> 3) {
            within |= cols << (8 * br);
        }
        m &= within;
        const LOW: u64 = 0x0101_0101_0101_0101;
        while m != 0 {
            let b = m.trailing_zeros() as usize;
            m &= m - 1;
            let (bx, by) = ((b & 7) * 8, (b >> 3) * 8);
            // Bit 0 of the bytes of the block row's cells within the rectangle.
            let (c0, c1) = (lx0.max(bx) - bx, lx1.min(bx + 7) - bx);
            let cmask = (u64::MAX >> (8 * (7 - c1))) & (u64::MAX << (8 * c0)) & LOW;
            for ly in ly0.max(by)..=ly1.min(by + 7) {
                let o = (b << 6) | ((ly & 7) << 3);
                let w =
                    u64::from_le_bytes(kinds[o..o + 8].try_into().expect("a block row is 8 bytes"));
                let sel = match r.kinds & KIND_MASK {
                    1 => w,
                    2 => w >> 1,
                    _ => w | w >> 1,
                };
                let mut hits = sel & cmask;
                while hits != 0 {
                    let i = (hits.trailing_zeros() / 8) as usize;
                    hits &= hits - 1;
                    f(ox + (bx + i) as i64, oy + ly as i64, (w >> (8 * i)) as u8)?;
                }
            }
        }
        ControlFlow::Continue(())
    }

    /// Calls `touch` with one cell byte in each cache line that [`Window::rows`] reads first
    /// around `p` (cells `x - 2 ..= x + 5` of rows `y - 2 ..= y + 2`), for a prefetch hint:
    /// the caller can ask the CPU to start loading them without waiting (this crate has no
    /// `unsafe` code of its own for it). Only the lines in `p`'s own tile are given
    /// (`near_line_offsets`); the rest are rare and load on use. A line may be given twice.
    #[inline(always)]
    pub fn near_lines(&self, p: [i64; 2], mut touch: impl FnMut(&u8)) {
        if let Some(t) = self.slot([p[0] >> SHIFT, p[1] >> SHIFT]) {
            let kinds = &self.kinds[t as usize];
            for o in near_line_offsets(p) {
                touch(&kinds[o]);
            }
        }
    }

    /// Heap bytes of the index: its tiles (in use or on the free list), the directory and the
    /// map.
    pub fn memory_bytes(&self) -> u64 {
        let slots = self.tiles.capacity() * size_of::<Tile>()
            + (self.dir.capacity() + self.free.capacity()) * size_of::<u32>()
            + self.map.capacity() * (size_of::<[i64; 2]>() + size_of::<u32>() + 1);
        self.tiles.len() as u64 * TILE_BYTES + slots as u64
    }

    /// Occupied cells (O(tiles in use); for consistency checks).
    pub fn len(&self) -> usize {
        self.map
            .values()
            .map(|&t| self.tiles[t as usize].count as usize)
            .sum()
    }

    /// Whether no cell is occupied.
    pub fn is_empty(&self) -> bool {
        self.map.is_empty()
    }
}

/// The offsets, in `p`'s tile's kind bytes, of the first byte of each cache line that the
/// part of `x - 2 ..= x + 5`, `y - 2 ..= y + 2` around `p = [x, y]` lying in that tile touches.
/// That part spans at most 2 x 2 blocks of 8 x 8 cells (it is 8 x 5 cells), and each block
/// is one line; the part's corners, in the tile's own coordinates, name them. Worked on the
/// coordinates within the tile, so that no sum can overflow.
#[inline(always)]
fn near_line_offsets(p: [i64; 2]) -> [usize; 4] {
    let (lx, ly) = ((p[0] & (TILE - 1)) as usize, (p[1] & (TILE - 1)) as usize);
    let last = (TILE - 1) as usize;
    let (bx0, bx1) = (lx.saturating_sub(2) >> 3, (lx + 5).min(last) >> 3);
    let (by0, by1) = (ly.saturating_sub(2) >> 3, (ly + 2).min(last) >> 3);
    // Block rows and columns are below 8, so the offsets stay below CELLS; the mask lets the
    // compiler see it.
    let line = |by: usize, bx: usize| ((by << 3 | bx) << 6) & (CELLS - 64);
    [
        line(by0, bx0),
        line(by0, bx1),
        line(by1, bx0),
        line(by1, bx1),
    ]
}

/// The rectangle and kinds of a [`CellIndex::scan_rect`].
struct Rect {
    x0: i64,
    x1: i64,
    y0: i64,
    y1: i64,
    kinds: u8,
}

static EMPTY_KINDS: [u8; CELLS] = [FREE; CELLS];
static EMPTY_IDS: [u64; CELLS] = [0; CELLS];

/// Up to 2 x 2 tiles around a query point; cells are read with [`Window::at`] and
/// [`Window::id`].
#[derive(Clone, Copy)]
pub struct Window<'a> {
    bx: i64,
    by: i64,
    kinds: [&'a [u8; CELLS]; 4],
    ids: [&'a [u64; CELLS]; 4],
}

impl Window<'_> {
    #[inline(always)]
    fn locate(&self, x: i64, y: i64) -> (usize, usize) {
        let rx = x - self.bx;
        let ry = y - self.by;
        let t = usize::from(rx >= TILE) | (usize::from(ry >= TILE) << 1);
        (t, offset(rx, ry))
    }

    /// The kind byte on cell `(x, y)`, which must lie within the window's square.
    #[inline(always)]
    pub fn at(&self, x: i64, y: i64) -> u8 {
        self.byte(x, y) & KIND_MASK
    }

    /// The whole cell byte on `(x, y)`: kind and id bucket (within the window's square).
    #[inline(always)]
    pub fn byte(&self, x: i64, y: i64) -> u8 {
        let (t, off) = self.locate(x, y);
        self.kinds[t][off]
    }

    /// The cell bytes (kind and id bucket) of the 8 cells `x0 .. x0 + 8` of rows
    /// `y0 .. y0 + N`, one `u64` per row (byte `i` is cell `x0 + i`). These cells must lie
    /// within the window's square.
    #[inline]
    pub fn rows<const N: usize>(&self, x0: i64, y0: i64) -> [u64; N] {
        // Kind bytes are stored in 8 x 8 blocks, each block row 8 consecutive bytes: the 8
        // cells are the tail of one block row and the head of the next (in the same tile or
        // the next one along x).
        let rx = x0 - self.bx;
        let ry0 = y0 - self.by;
        let a = rx & !7;
        let b = a + 8;
        let s = ((rx - a) * 8) as u32;
        let (ta, xa) = (usize::from(a >= TILE), (((a >> 3) & 7) << 6) as usize);
        let (tb, xb) = (usize::from(b >= TILE), (((b >> 3) & 7) << 6) as usize);
        let load = |t: usize, o: usize| -> u64 {
            let o = o & (CELLS - 8);
            let bytes: [u8; 8] = self.kinds[t & 3][o..o + 8]
                .try_into()
                .expect("a block row is 8 bytes");
            u64::from_le_bytes(bytes)
        };
        let mut out = [0u64; N];
        for (i, row) in out.iter_mut().enumerate() {
            let ry = ry0 + i as i64;
            let ty = usize::from(ry >= TILE) << 1;
            let yo = ((((ry >> 3) & 7) << 9) | ((ry & 7) << 3)) as usize;
            let lo = load(ta | ty, xa | yo);
            let hi = load(tb | ty, xb | yo);
            *row = ((u128::from(hi) << 64 | u128::from(lo)) >> s) as u64;
        }
        out
    }

    /// The id of the item on the occupied cell `(x, y)` (within the window's square).
    #[inline(always)]
    pub fn id(&self, x: i64, y: i64) -> u64 {
        let (t, off) = self.locate(x, y);
        self.ids[t][off]
    }
}

#[cfg(test)]
mod tests;
