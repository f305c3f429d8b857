//! A dense per-cell index of the animats over the unbounded plane: which animat (id and
//! species) stands on each cell.
//!
//! The plane is cut into square tiles of [`TILE`] x [`TILE`] cells; each tile that holds an
//! animat is a flat array of `TILE^2` words (0 = free cell, otherwise `(id + 1) << 1 | kind`,
//! kind 0 = fox, 1 = rabbit) kept in a vector, and a hash map (rustc-hash, already used by
//! `spatial`) goes from tile coordinates to the tile's slot. A tile that empties returns to a
//! free list, so memory follows the occupied area, not the area the animats ever roamed.
//!
//! Small-radius perception (adjacency, overcrowding, and the first few cell rings of a nearest
//! or counting query) reads cells through a [`Window`]: the at most 2 x 2 tiles covering a
//! square of half-side up to [`WINDOW_MAX`] around the query point, fetched with at most four
//! hash lookups per query; every cell read after that is an array index.

use rustc_hash::FxHashMap;

/// log2 of the tile side.
const SHIFT: u32 = 6;
/// Tile side in cells.
pub const TILE: i64 = 1 << SHIFT;
const MASK: i64 = TILE - 1;
/// Largest half-side of a [`Window`] (so that a window spans at most two tiles per axis).
pub const WINDOW_MAX: i64 = TILE / 2;
/// Positions farther than this from the `i64` limits are served by windows; the rest (never
/// reached by a real run) fall back to the grid search.
const EDGE_GUARD: i64 = 4 * TILE;

/// Encodes an occupant.
#[inline]
pub fn encode(id: u64, rabbit: bool) -> u64 {
    ((id + 1) << 1) | u64::from(rabbit)
}

/// Id of a non-zero cell word.
#[inline]
pub fn id_of(w: u64) -> u64 {
    (w >> 1) - 1
}

/// Kind bit of a non-zero cell word (1 = rabbit).
#[inline]
pub fn kind_of(w: u64) -> u64 {
    w & 1
}

#[derive(Debug, Clone)]
struct Tile {
    cells: Box<[u64]>,
    count: u32,
}

/// The cell index; see the module documentation.
#[derive(Debug, Clone, Default)]
pub struct CellIndex {
    map: FxHashMap<[i64; 2], u32>,
    tiles: Vec<Tile>,
    free: Vec<u32>,
}

#[inline]
fn split(p: [i64; 2]) -> ([i64; 2], usize) {
    let key = [p[0] >> SHIFT, p[1] >> SHIFT];
    let off = ((p[1] & MASK) << SHIFT | (p[0] & MASK)) as usize;
    (key, off)
}

impl CellIndex {
    /// The word on cell `p` (0 when free).
    #[inline]
    pub fn get(&self, p: [i64; 2]) -> u64 {
        let (key, off) = split(p);
        match self.map.get(&key) {
            Some(&t) => self.tiles[t as usize].cells[off],
            None => 0,
        }
    }

    /// Puts word `w != 0` on the free cell `p`.
    pub fn set(&mut self, p: [i64; 2], w: u64) {
        debug_assert!(w != 0);
        let (key, off) = split(p);
        let t = match self.map.get(&key) {
            Some(&t) => t,
            None => {
                let t = match self.free.pop() {
                    Some(t) => t,
                    None => {
                        self.tiles.push(Tile {
                            cells: vec![0u64; (TILE * TILE) as usize].into_boxed_slice(),
                            count: 0,
                        });
                        (self.tiles.len() - 1) as u32
                    }
                };
                self.map.insert(key, t);
                t
            }
        };
        let tile = &mut self.tiles[t as usize];
        debug_assert_eq!(tile.cells[off], 0, "cell {p:?} already occupied");
        tile.cells[off] = w;
        tile.count += 1;
    }

    /// Frees cell `p` (which must be occupied).
    pub fn clear(&mut self, p: [i64; 2]) {
        let (key, off) = split(p);
        let Some(&t) = self.map.get(&key) else {
            debug_assert!(false, "clearing a cell of a missing tile");
            return;
        };
        let tile = &mut self.tiles[t as usize];
        debug_assert_ne!(tile.cells[off], 0);
        tile.cells[off] = 0;
        tile.count -= 1;
        if tile.count == 0 {
            self.map.remove(&key);
            self.free.push(t);
        }
    }

    /// Moves the occupant of `from` to the free cell `to`.
    pub fn relocate(&mut self, from: [i64; 2], to: [i64; 2]) {
        let (kf, of) = split(from);
        let (kt, ot) = split(to);
        if kf == kt {
            if let Some(&t) = self.map.get(&kf) {
                let cells = &mut self.tiles[t as usize].cells;
                cells[ot] = cells[of];
                cells[of] = 0;
                return;
            }
        }
        let w = self.get(from);
        self.clear(from);
        self.set(to, w);
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
        let fetch = |tx: i64, ty: i64| -> &[u64] {
            match self.map.get(&[tx, ty]) {
                Some(&t) => &self.tiles[t as usize].cells,
                None => &EMPTY_TILE,
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
            tiles: [t00, t10, t01, t11],
        })
    }

    /// Occupied cells (for consistency checks).
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.tiles
            .iter()
            .enumerate()
            .filter(|(i, _)| !self.free.contains(&(*i as u32)))
            .map(|(_, t)| t.count as usize)
            .sum()
    }

    /// Whether no cell is occupied.
    #[cfg(test)]
    pub fn is_empty(&self) -> bool {
        self.map.is_empty()
    }
}

static EMPTY_TILE: [u64; (TILE * TILE) as usize] = [0; (TILE * TILE) as usize];

/// Up to 2 x 2 tiles around a query point; cells are read with [`Window::at`].
#[derive(Clone, Copy)]
pub struct Window<'a> {
    bx: i64,
    by: i64,
    tiles: [&'a [u64]; 4],
}

impl Window<'_> {
    /// The word on cell `(x, y)`, which must lie within the window's square.
    #[inline(always)]
    pub fn at(&self, x: i64, y: i64) -> u64 {
        let rx = x - self.bx;
        let ry = y - self.by;
        let ix = usize::from(rx >= TILE);
        let iy = usize::from(ry >= TILE);
        let off = (((ry & MASK) << SHIFT) | (rx & MASK)) as usize;
        self.tiles[ix | (iy << 1)][off]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_get_clear_relocate_and_windows_across_tiles() {
        let mut c = CellIndex::default();
        let pts = [[0, 0], [-1, -1], [63, 64], [64, 63], [-65, 130], [5, -200]];
        for (i, &p) in pts.iter().enumerate() {
            c.set(p, encode(i as u64, i % 2 == 1));
        }
        for (i, &p) in pts.iter().enumerate() {
            let w = c.get(p);
            assert_eq!(id_of(w), i as u64);
            assert_eq!(kind_of(w), (i % 2) as u64);
        }
        assert_eq!(c.len(), pts.len());
        // Windows agree with get everywhere in their square, across tile corners.
        for &q in &[[0i64, 0], [63, 63], [-32, 100], [64, 64], [-1, -1]] {
            let k = WINDOW_MAX;
            let w = c.window(q, k).unwrap();
            for x in q[0] - k..=q[0] + k {
                for y in q[1] - k..=q[1] + k {
                    assert_eq!(w.at(x, y), c.get([x, y]), "{q:?} {x} {y}");
                }
            }
        }
        c.relocate([63, 64], [64, 64]);
        assert_eq!(c.get([63, 64]), 0);
        assert_eq!(id_of(c.get([64, 64])), 2);
        c.relocate([0, 0], [1, 0]);
        assert_eq!(id_of(c.get([1, 0])), 0);
        for p in [[1, 0], [-1, -1], [64, 64], [64, 63], [-65, 130], [5, -200]] {
            c.clear(p);
        }
        assert!(c.is_empty());
        assert_eq!(c.len(), 0);
        assert!(c.window([i64::MAX, 0], 1).is_none());
        assert_eq!(c.get([i64::MAX, i64::MIN]), 0);
    }
}
