//! A fine distance map stored sparsely: the cells of [`DistanceMap`](super::DistanceMap)
//! (one byte per cell, a lower bound of the distance from its centre to the nearest point,
//! capped at `cap`), kept in blocks of `B^D` cells that exist only where some cell lies within
//! `cap` of a point, so that small cells (a diameter or two) near a fractal cluster cost memory
//! in proportion to the cluster's neighbourhood rather than to the cube it grows in.
//!
//! A dense map of cells that small holds one byte for every cell of the cluster's bounding cube
//! (in 3D, cells of two diameters over a cluster of radius 300 would be 27 MB); a DLA cluster's
//! `cap`-neighbourhood is a fraction of that cube, and only its blocks are allocated.
//!
//! # Layout and reads
//!
//! - A *block table*, one `u32` per block over a cube of blocks centred on the origin (grown by
//!   a quarter like the dense map's cells, while the map is not shared): `0` means the block is
//!   absent, [`UNKNOWN`] that it could not be allocated, anything else is `1 +` the block's
//!   number in the slab.
//! - A *slab* of blocks in chunks of about 64 KiB, each chunk allocated when its first block is
//!   handed out. Blocks are numbered in the order they were first written.
//! - A cell stores its *nearness* `255 - v`, `v = min(255, floor(m / u))` as in the dense map
//!   (`m` the distance from the cell's centre to the nearest point, `u = cap / 255`): fresh
//!   zeroed memory then reads as "capped", so a block needs no initialisation and a block that
//!   is absent answers like a block of capped cells.
//!
//! A read is the table entry and then the cell: two dependent memory accesses (plus the chunk's
//! pointer, a small array that stays in cache).
//!
//! # Why an absent block is a valid "at least `cap`"
//!
//! An insert lowers every cell whose centre lies within `cap` of the point (the same rows as the
//! dense map), and allocates a block before writing its first cell. A block is therefore
//! absent only if no point inserted so far lies within `cap` of any of its cells' centres, and
//! [`bounds`](SparseDistanceMap::bounds) returns `cap - |p - z|` for it, as for a capped cell
//! of the dense map. A block that could not be allocated (a shared map whose reserved slab ran
//! out) is marked [`UNKNOWN`] and gives no answer at all (`None`), never a capped one.
//!
//! # Sharing (PDLA)
//!
//! [`insert_shared`](SparseDistanceMap::insert_shared) works through `&self` while other
//! threads read: a cell is lowered with an atomic `fetch_max` of its nearness, and a block is
//! allocated lock-free: a slab number from an atomic counter, the chunk created once through a
//! [`OnceLock`] before the number is published, and the table entry set by a compare-and-swap
//! from "absent" (`Release`; readers load it with `Acquire`). A thread that loses the race uses
//! the winner's block; its own number stays unused (all capped, never referenced). The table
//! does not grow while shared: [`reserve`](SparseDistanceMap::reserve) sizes it and the slab's
//! chunk slots for the whole cluster beforehand, so a shared insert never runs out of slots in
//! practice, and if it did the block would be marked [`UNKNOWN`].
//!
//! The bound and its rounding margins are the dense map's (see the parent module): never above
//! the exact distance, at most a cell diagonal plus one quantum below it in a cell that is not
//! capped.

use super::grid::{Grid, WINDOW, WindowBox, merge_row};
use super::{CAPPED, Cells, DistanceMapError, PointMap};
use crate::round::{floor, whole_to_usize};
use std::fmt;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU8, AtomicU32, AtomicUsize, Ordering};

/// Table entry of a block that was never written: every cell is capped.
const ABSENT: u32 = 0;
/// Table entry of a block that could not be allocated: no information.
pub const UNKNOWN: u32 = u32::MAX;
/// Bits of a row's key ([`Cells::row_key`]) that hold its cells' offset within a block
/// (blocks hold at most 2^20 cells); the block row is above them.
const CELL_BITS: u32 = 20;
/// Bytes of a slab chunk (at least one block).
const CHUNK_BYTES: usize = 1 << 16;

/// The two blocks an insert used last, by table index: consecutive rows of a point's ball
/// mostly fall in the same one or two blocks. A published block never changes its entry, so
/// they stay valid.
pub struct Recent<'a> {
    at: [usize; 2],
    block: [&'a [AtomicU8]; 2],
}

impl Default for Recent<'_> {
    /// No block yet.
    fn default() -> Self {
        Recent {
            at: [usize::MAX; 2],
            block: [&[]; 2],
        }
    }
}

/// The sparse fine distance map (see the module documentation).
pub struct SparseDistanceMap<const D: usize> {
    /// Cells, tables (`below` indexed by nearness: `below[s]` is the dense map's
    /// `below[255 - s]`) and points; `grid.half` is a multiple of `B`.
    grid: Grid,
    /// `log2` of the block side in cells.
    shift: u32,
    /// Block side in cells, less one.
    mask: usize,
    /// Cells per block, `B^D`.
    block_cells: usize,
    /// `2 * half`: cells per axis.
    side: usize,
    /// Blocks per axis.
    bside: usize,
    /// One entry per block, axis 0 fastest: [`ABSENT`], [`UNKNOWN`] or `1 +` slab number.
    table: Vec<AtomicU32>,
    /// The slab's chunks, each `chunk_blocks` blocks, created on first use.
    chunks: Vec<OnceLock<Box<[AtomicU8]>>>,
    /// `log2` of the blocks per chunk.
    chunk_shift: u32,
    /// Slab numbers handed out.
    next: AtomicUsize,
    /// A 3D window insert's rows, kept between inserts for their room
    /// ([`window_rows_3d`](Self::window_rows_3d)).
    staged: Vec<Staged>,
}

/// A row of a 3D window insert ([`SparseDistanceMap::window_rows_3d`]): its group (which of
/// the box's block rows along axes 1 and 2 it lies in), its cells' offset within a block, and
/// its nearness bytes from the first column of the box's first block.
#[derive(Clone, Copy)]
struct Staged {
    group: u8,
    crow: u32,
    near: [u8; 32],
}

/// Where a row's key carries its group in a 3D window insert (above the table index).
const GROUP_SHIFT: u32 = 56;

/// Raises the `B` cells of `block` from offset `crow` on to the nearness `near` where it is
/// higher (plain bytes: the access is exclusive).
#[inline(always)]
fn raise<const B: usize>(block: &mut [AtomicU8], crow: usize, near: [u8; B]) {
    let row: &mut [AtomicU8; B] = (&mut block[crow..crow + B])
        .try_into()
        .expect("a block row holds B cells");
    merge_row(row, near, u8::max);
}

impl<const D: usize> fmt::Debug for SparseDistanceMap<D> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SparseDistanceMap")
            .field("cell", &self.grid.cell)
            .field("cap", &self.grid.cap)
            .field("block_side", &(self.mask + 1))
            .field("cells_per_axis", &self.side)
            .field("blocks", &self.blocks())
            .field("points", &self.grid.points)
            .finish()
    }
}

impl<const D: usize> SparseDistanceMap<D> {
    /// An empty map with cell side `cell`, cap distance `cap` and blocks of `block_side^D`
    /// cells (`block_side` a power of two, `block_side^D` at most 2^20). Nothing is allocated
    /// until the first insert.
    pub fn new(cell: f64, cap: f64, block_side: usize) -> Result<Self, DistanceMapError> {
        let mut grid = Grid::new(cell, cap)?;
        let block_cells = block_side.checked_pow(D as u32).unwrap_or(usize::MAX);
        if !block_side.is_power_of_two() || block_cells > 1 << CELL_BITS {
            return Err(DistanceMapError::TooLarge {
                cells_per_axis: block_side as f64,
            });
        }
        // Cells store their nearness `255 - v`: the dense map's table read backwards.
        grid.below.reverse();
        if grid.widths.is_empty() {
            return Err(DistanceMapError::TooLarge {
                cells_per_axis: 2.0 * cap / cell,
            });
        }
        let chunk_blocks = (CHUNK_BYTES / block_cells).max(1);
        Ok(SparseDistanceMap {
            grid,
            shift: block_side.trailing_zeros(),
            mask: block_side - 1,
            block_cells,
            side: 0,
            bside: 0,
            table: Vec::new(),
            chunks: Vec::new(),
            chunk_shift: chunk_blocks.trailing_zeros(),
            next: AtomicUsize::new(0),
            staged: Vec::new(),
        })
    }

    /// Blocks handed out (allocated, including any lost to a race between shared inserts).
    pub fn blocks(&self) -> usize {
        self.next.load(Ordering::Relaxed)
    }

    /// The cells of block `entry` (a table entry other than [`ABSENT`] and [`UNKNOWN`]).
    #[inline(always)]
    fn block(&self, entry: u32) -> &[AtomicU8] {
        let n = entry as usize - 1;
        let chunk = self.chunks[n >> self.chunk_shift]
            .get()
            .expect("a block is published after its chunk is created");
        let start = (n & ((1 << self.chunk_shift) - 1)) * self.block_cells;
        &chunk[start..start + self.block_cells]
    }

    /// Makes room for chunk slots up to slab number `blocks` (exclusive access).
    fn ensure_slots(&mut self, blocks: usize) {
        let slots = (blocks >> self.chunk_shift) + 1;
        if self.chunks.len() < slots {
            self.chunks.resize_with(slots, OnceLock::new);
        }
    }

    /// A block for the table entry `slot` (absent when read): a fresh slab number published by
    /// a compare-and-swap, or the entry another thread published first; [`UNKNOWN`] when the
    /// slab has no room.
    #[cold]
    fn allocate(&self, slot: &AtomicU32) -> u32 {
        let n = self.next.fetch_add(1, Ordering::Relaxed);
        let chunk = n >> self.chunk_shift;
        let entry = if chunk < self.chunks.len() && n < UNKNOWN as usize - 1 {
            let bytes = self.block_cells << self.chunk_shift;
            self.chunks[chunk].get_or_init(|| (0..bytes).map(|_| AtomicU8::new(0)).collect());
            n as u32 + 1
        } else {
            UNKNOWN
        };
        match slot.compare_exchange(ABSENT, entry, Ordering::AcqRel, Ordering::Acquire) {
            Ok(_) => entry,
            Err(current) => current,
        }
    }

    /// Lowers cells `u..=end` (table coordinates along axis 0, one block) of the row with
    /// squared off-axis distance `s`, block row `brow` and in-block offset `crow`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn lower_segment<'a>(
        &'a self,
        q: &[f64; D],
        s: f64,
        brow: usize,
        crow: usize,
        u: usize,
        end: usize,
        lower: &mut impl FnMut(&AtomicU8, u8),
        recent: &mut Recent<'a>,
    ) {
        let at = brow + (u >> self.shift);
        let kc = (u as i64 - self.grid.half) as f64 + 0.5;
        let x0 = self.grid.offset(kc, 0.0, q[0]);
        let block = if recent.at[0] == at {
            recent.block[0]
        } else if recent.at[1] == at {
            recent.block[1]
        } else {
            let Some(block) = self.find_block(at, x0, s, end - u) else {
                return;
            };
            recent.at = [at, recent.at[0]];
            recent.block = [block, recent.block[0]];
            block
        };
        let row = &block[crow | (u & self.mask)..=crow | (end & self.mask)];
        for (n, v) in row.iter().enumerate() {
            let x = self.grid.offset(kc, f64::from(n as i32), q[0]);
            let d2 = x * x + s;
            if d2 < self.grid.below[usize::from(v.load(Ordering::Relaxed))] {
                let d = d2.sqrt() * self.grid.inv_quantum;
                if d < f64::from(CAPPED) {
                    lower(v, CAPPED - d as u8);
                }
            }
        }
    }

    /// [`Cells::lower_window`] with blocks of `B` cells a side (`B = mask + 1`).
    #[inline(always)]
    fn lower_window_in<const B: usize>(&mut self, q: &[f64; D]) -> bool {
        let Some(b) = self.grid.window_box(q) else {
            return false;
        };
        let Some(b) = b else {
            return true;
        };
        match (D, b.cells <= 8) {
            (3, true) => self.window_rows_3d::<B, 8>(&b),
            (3, false) => self.window_rows_3d::<B, WINDOW>(&b),
            (_, true) => self.window_rows::<B, 8>(&b),
            (_, false) => self.window_rows::<B, WINDOW>(&b),
        }
        true
    }

    /// [`window_rows`](Self::window_rows) in 3D, block by block: the rows' nearness is
    /// computed first, grouped by the block row along axes 1 and 2 it falls in (at most 3 x 3),
    /// then each group's blocks (at most 3 along axis 0) are resolved once and every row of
    /// the group merged into them, where the row by row merge resolved a block per row (its
    /// table entry, chunk and bounds: several tens of instructions). The same blocks are
    /// allocated (a block whose rows would raise no cell stays absent), in another order.
    #[inline(always)]
    fn window_rows_3d<const B: usize, const L: usize>(&mut self, b: &WindowBox<D>) {
        const GROUPS: usize = 9;
        let off = b.start % B;
        let blocks = (off + b.cells - 1) / B + 1;
        let first_block = |m: &Self, i: usize| (b.lo(i) + m.grid.half) as u64 >> m.shift;
        let lob = [0, first_block(self, 1), first_block(self, 2)];
        let mut staged = std::mem::take(&mut self.staged);
        staged.clear();
        let mut count = [0u8; GROUPS];
        let mut brow = [0usize; GROUPS];
        b.rows(
            self,
            |m, i, k| {
                // The row's block row along axis i, from the box's first: 0 to 2.
                let g = ((k + m.grid.half) as u64 >> m.shift) - lob[i];
                m.row_key(i, k) + ((g * if i == 1 { 1 } else { 3 }) << GROUP_SHIFT)
            },
            |m, s, key| {
                let group = (key >> GROUP_SHIFT) as usize;
                let key = key & ((1 << GROUP_SHIFT) - 1);
                let w = m.grid.window_row::<L>(&b.x2, s).map(|w| CAPPED - w);
                let mut near = [0u8; 32];
                near[off..off + 16].copy_from_slice(&w);
                staged.push(Staged {
                    group: group as u8,
                    crow: (key & ((1 << CELL_BITS) - 1)) as u32,
                    near,
                });
                count[group] += 1;
                brow[group] = (key >> CELL_BITS) as usize + b.start / B;
            },
        );
        // The rows in group order (a counting sort).
        let mut start = [0usize; GROUPS + 1];
        for g in 0..GROUPS {
            start[g + 1] = start[g] + usize::from(count[g]);
        }
        let mut order = [0u8; WINDOW * WINDOW];
        let mut next = start;
        for (r, row) in staged.iter().enumerate() {
            let g = usize::from(row.group);
            order[next[g]] = r as u8;
            next[g] += 1;
        }
        for g in 0..GROUPS {
            let rows = &order[start[g]..start[g + 1]];
            for j in 0..blocks {
                let segment = |r: &u8| -> [u8; B] {
                    staged[usize::from(*r)].near[j * B..(j + 1) * B]
                        .try_into()
                        .expect("B bytes")
                };
                let wanted = || rows.iter().any(|r| segment(r).iter().any(|&n| n > 0));
                let Some(block) = self.block_mut(brow[g] + j, wanted) else {
                    continue;
                };
                for r in rows {
                    raise(block, staged[usize::from(*r)].crow as usize, segment(r));
                }
            }
        }
        self.staged = staged;
    }

    /// [`lower_window_in`](Self::lower_window_in)'s rows, `L` lanes of each computed
    /// ([`Grid::window_row`]).
    #[inline(always)]
    fn window_rows<const B: usize, const L: usize>(&mut self, b: &WindowBox<D>) {
        let off = b.start % B;
        // Block rows spanned by the box's rows: at most 2 of 16 cells, 3 of 8.
        let blocks = (off + b.cells - 1) / B + 1;
        let mut near = [0u8; 32];
        b.rows(
            self,
            |m, i, k| m.row_key(i, k),
            |m, s, key| {
                // As nearness, then placed at the box's first column by one 16-byte copy.
                let w = m.grid.window_row::<L>(&b.x2, s).map(|w| CAPPED - w);
                near[off..off + 16].copy_from_slice(&w);
                let at = ((key >> CELL_BITS) as usize) + b.start / B;
                let crow = (key & ((1 << CELL_BITS) - 1)) as usize;
                for j in 0..blocks {
                    let near: [u8; B] = near[j * B..(j + 1) * B].try_into().expect("B bytes");
                    m.raise_row(at + j, crow, near);
                }
            },
        );
    }

    /// Raises the `B` cells of the block row at in-block offset `crow` of the block at table
    /// index `at` to the nearness `near` where it is higher (exclusive access: plain bytes),
    /// allocating the block if it is absent and some nearness is above zero.
    #[inline(always)]
    fn raise_row<const B: usize>(&mut self, at: usize, crow: usize, near: [u8; B]) {
        if let Some(block) = self.block_mut(at, || near.iter().any(|&n| n > 0)) {
            raise(block, crow, near);
        }
    }

    /// The cells of the block at table index `at` (exclusive access), allocated if absent and
    /// `wanted()`; `None` if it stays absent or is unknown.
    #[inline(always)]
    fn block_mut(&mut self, at: usize, wanted: impl FnOnce() -> bool) -> Option<&mut [AtomicU8]> {
        let slot = &self.table[at];
        let entry = match slot.load(Ordering::Relaxed) {
            ABSENT if !wanted() => return None,
            ABSENT => self.allocate(slot),
            entry => entry,
        };
        if entry == UNKNOWN {
            return None;
        }
        let n = entry as usize - 1;
        let first = (n & ((1 << self.chunk_shift) - 1)) * self.block_cells;
        let chunk = self.chunks[n >> self.chunk_shift]
            .get_mut()
            .expect("a block is published after its chunk is created");
        Some(&mut chunk[first..first + self.block_cells])
    }

    /// The block at table index `at` for a segment of `len + 1` cells starting `x0` from `q`
    /// along the row, `s` off it: allocated if absent and some cell of the segment comes
    /// within the cap; `None` if it stays absent or is unknown.
    #[inline(always)]
    fn find_block(&self, at: usize, x0: f64, s: f64, len: usize) -> Option<&[AtomicU8]> {
        let slot = &self.table[at];
        let entry = match slot.load(Ordering::Acquire) {
            UNKNOWN => return None,
            ABSENT => {
                // Allocate only if some cell of the segment comes within the cap: the centre
                // nearest q along the row.
                let n = (-x0 * self.grid.inv_cell + 0.5).max(0.0).min(len as f64);
                let x = x0 + floor(n) * self.grid.cell;
                if x * x + s >= self.grid.cap * self.grid.cap {
                    return None;
                }
                match self.allocate(slot) {
                    UNKNOWN => return None,
                    entry => entry,
                }
            }
            entry => entry,
        };
        (entry != UNKNOWN).then(|| self.block(entry))
    }
}

impl<const D: usize> PointMap<D> for SparseDistanceMap<D> {
    /// Heap bytes held: the table and the chunks created.
    fn memory_bytes(&self) -> usize {
        let chunk = self.block_cells << self.chunk_shift;
        self.table.capacity() * 4
            + self.chunks.capacity() * size_of::<OnceLock<Box<[AtomicU8]>>>()
            + self.chunks.iter().filter(|c| c.get().is_some()).count() * chunk
    }

    /// The distance byte of the cell holding `p` (255 in an absent block), for tests.
    fn value(&self, p: &[f64; D]) -> Option<u8> {
        self.read(p).map(|(_, _, v, _)| v)
    }

    /// As [`PointMap::reserve`], and reserves chunk slots for every block of the table, so
    /// that shared inserts can allocate any block.
    fn reserve(&mut self, reach: f64) -> Result<(), DistanceMapError> {
        self.cover(reach)?;
        self.ensure_slots(self.blocks() + self.table.len());
        Ok(())
    }
}

impl<const D: usize> Cells<D> for SparseDistanceMap<D> {
    #[inline(always)]
    fn grid(&self) -> &Grid {
        &self.grid
    }

    #[inline(always)]
    fn grid_mut(&mut self) -> &mut Grid {
        &mut self.grid
    }

    /// The cell holding `p`: its stored distance `m` from the centre, `|p - centre|` and its
    /// distance byte `v`; `None` outside the table or in an [`UNKNOWN`] block.
    #[inline(always)]
    fn read(&self, p: &[f64; D]) -> Option<(f64, f64, u8, [f64; D])> {
        let mut centre = [0.0; D];
        let mut bidx = 0usize;
        let mut cidx = 0usize;
        let mut stride = 1usize;
        let mut e2 = 0.0;
        for i in 0..D {
            let k = floor(p[i] * self.grid.inv_cell);
            // `side = 2 half`, tested through the signed `half` as the dense map does.
            let half = self.grid.half_f;
            if !(k >= -half && k < half) {
                return None;
            }
            // A whole number in [0, side), side < 2^32 (`grow`).
            let j = whole_to_usize(k + half);
            bidx += (j >> self.shift) * stride;
            stride *= self.bside;
            cidx |= (j & self.mask) << (self.shift as usize * i);
            centre[i] = (k + 0.5) * self.grid.cell;
            let e = p[i] - centre[i];
            e2 += e * e;
        }
        let v = match self.table[bidx].load(Ordering::Acquire) {
            ABSENT => CAPPED,
            UNKNOWN => return None,
            entry => CAPPED - self.block(entry)[cidx].load(Ordering::Relaxed),
        };
        Some((f64::from(v) * self.grid.quantum, e2.sqrt(), v, centre))
    }

    /// Enlarges the table to cover `|x_i| < need` (by at least a quarter), copying the old
    /// entries into the middle of the new table (blocks keep their slab numbers).
    fn grow(&mut self, need: f64) -> Result<(), DistanceMapError> {
        let b = (self.mask + 1) as f64;
        let cells = ((need * self.grid.inv_cell)
            .ceil()
            .max(self.grid.half as f64 * 1.25)
            / b)
            .ceil()
            * b;
        let side = 2.0 * cells;
        let bside = side / b;
        let total = bside.powi(D as i32);
        if !(side < f64::from(u32::MAX) && total < (u32::MAX as f64) / 2.0) {
            return Err(DistanceMapError::TooLarge {
                cells_per_axis: side,
            });
        }
        let half = cells as i64;
        let bside = bside as usize;
        let mut table: Vec<AtomicU32> = (0..total as usize).map(|_| AtomicU32::new(0)).collect();
        if self.bside > 0 {
            let off = ((half - self.grid.half) as usize) >> self.shift;
            for (r, old) in self.table.iter_mut().enumerate() {
                let mut rem = r;
                let mut at = 0;
                let mut stride = 1;
                for _ in 0..D {
                    at += (rem % self.bside + off) * stride;
                    rem /= self.bside;
                    stride *= bside;
                }
                *table[at].get_mut() = *old.get_mut();
            }
        }
        self.table = table;
        self.grid.set_half(half);
        self.side = side as usize;
        self.bside = bside;
        Ok(())
    }

    /// Stores the nearness `s` if it is above the cell's (exclusive access).
    #[inline(always)]
    fn keep_nearer(v: &AtomicU8, s: u8) {
        if s > v.load(Ordering::Relaxed) {
            v.store(s, Ordering::Relaxed);
        }
    }

    /// Raises the cell to the nearness `s` with an atomic `fetch_max`.
    #[inline(always)]
    fn keep_nearer_shared(v: &AtomicU8, s: u8) {
        if s > v.load(Ordering::Relaxed) {
            v.fetch_max(s, Ordering::Relaxed);
        }
    }

    /// Room in the slab for every block the point's ball can touch.
    fn make_room(&mut self) {
        let per_axis = (2.0 * self.grid.cap * self.grid.inv_cell) as usize / (self.mask + 1) + 2;
        self.ensure_slots(self.blocks() + per_axis.pow(D as u32));
    }

    /// Row by row of the ball's box (in 2D and 3D): [`Grid::window_row`] as nearness, placed
    /// at the box's first column in the cells of consecutive block rows and merged into the
    /// blocks a block row at a time by a byte maximum ([`raise_row`](Self::raise_row)). Needs
    /// blocks of 8 or 16 cells a side (a row of the box then spans at most three or two).
    fn lower_window(&mut self, q: &[f64; D]) -> bool {
        // `Grid::window_box` turns down the other dimensions.
        match self.mask + 1 {
            8 => self.lower_window_in::<8>(q),
            16 => self.lower_window_in::<16>(q),
            _ => false,
        }
    }

    type RowCache<'a> = Recent<'a>;

    /// The row's block row in the table (above [`CELL_BITS`]) and its cells' offset within a
    /// block (below), along axis `i`.
    #[inline(always)]
    fn row_key(&self, i: usize, k: i64) -> u64 {
        let u = (k + self.grid.half) as usize;
        let brow = (u >> self.shift) * self.bside.pow(i as u32);
        let crow = (u & self.mask) << (self.shift as usize * i);
        ((brow as u64) << CELL_BITS) + crow as u64
    }

    /// Raises the row's cells to their nearness `s`, block by block, allocating a block at its
    /// first cell within the cap.
    #[inline(always)]
    fn lower_row<'a>(
        &'a self,
        q: &[f64; D],
        s: f64,
        key: u64,
        (a, b): (i64, i64),
        lower: &mut impl FnMut(&AtomicU8, u8),
        recent: &mut Recent<'a>,
    ) {
        let half = self.grid.half;
        let brow = (key >> CELL_BITS) as usize;
        let crow = (key & ((1 << CELL_BITS) - 1)) as usize;
        let last = (b + half) as usize;
        let mut u = (a + half) as usize;
        while u <= last {
            let end = (u | self.mask).min(last);
            self.lower_segment(q, s, brow, crow, u, end, lower, recent);
            u = end + 1;
        }
    }
}

#[cfg(test)]
mod tests;
