//! The particles of a *large* cluster as bits over a box in its own frame ([`Members`]): what
//! tells which cluster holds a site once large clusters stop writing their labels (see
//! [`Rigid`](super::clusters::Rigid)).
//!
//! A large cluster's move can also flip its image in the occupancy bits a word at a time from
//! these rows ([`Members::xor_move`]) instead of a site at a time from its faces.
//!
//! Invariants: the bits set are exactly the relative positions given to [`Members::build`]
//! and [`Members::extend`] since the last build, and all lie in the box; each row's first
//! word is zero, and so is the word after the last row; each row's extent is exactly the
//! range of its words that hold bits (checked by [`Members::check`]).

use super::geometry::Geometry;

/// Relative positions as bits over the box `lo .. lo + side`, in rows along axis 0 that each
/// start a word: position `r` is bit `r[0] - lo[0]` after the zero word of row
/// `sum over a >= 1 of (r[a] - lo[a]) * row_stride[a]`. On a periodic axis of side `L` a
/// relative position in `[L/2, L)` is taken as the one `L` lower, so that a cluster with
/// particles on both sides of its origin has a box of its own extent, not `L`. Each row keeps
/// the range of its words that hold bits, so that [`Members::xor_move`] reads those only.
#[derive(Debug, Clone)]
pub(super) struct Members<const D: usize> {
    lo: [i32; D],
    side: [u32; D],
    /// `L` on a periodic axis, 0 on a wall axis.
    period: [i32; D],
    /// Words a row.
    row_words: usize,
    /// Row strides of axes 1 and up (axis 0's entry unused).
    row_stride: [usize; D],
    bits: Vec<u64>,
    /// First and last word (in the row) holding bits, per row; `(u32::MAX, 0)` for none.
    extent: Vec<(u32, u32)>,
    /// Sum over the rows holding bits of their words plus one.
    words: usize,
}

impl<const D: usize> Members<D> {
    /// The bits of `sites` (relative positions in a frame of `geo`), over their bounding box
    /// widened by a quarter of its extent (at least 8) on each side, so that a cluster growing
    /// by merges rebuilds its box O(log) times; on periodic axes the box stays within
    /// `[0, L)`, where relative positions lie.
    pub(super) fn build<'a>(
        geo: &Geometry<D>,
        sites: impl IntoIterator<Item = &'a [i32; D]> + Clone,
    ) -> Self {
        let period: [i32; D] = std::array::from_fn(|a| {
            if geo.periodic[a] {
                geo.size[a] as i32
            } else {
                0
            }
        });
        let (mut lo, mut hi) = ([i32::MAX; D], [i32::MIN; D]);
        for s in sites.clone() {
            let s = fold(&period, s);
            for a in 0..D {
                lo[a] = lo[a].min(s[a]);
                hi[a] = hi[a].max(s[a]);
            }
        }
        let mut side = [0; D];
        for a in 0..D {
            let margin = ((hi[a] - lo[a]) / 4).max(8);
            lo[a] -= margin;
            hi[a] += margin;
            if period[a] > 0 {
                // The folded positions: `[-L/2, L/2)` or so.
                lo[a] = lo[a].max(period[a] / 2 - period[a]);
                hi[a] = hi[a].min(period[a] / 2);
            }
            side[a] = (hi[a] - lo[a] + 1) as u32;
        }
        // A zero word before each row's bits, and one after the last row (see `xor_move`).
        let row_words = (side[0] as usize).div_ceil(64) + 1;
        let mut row_stride = [0; D];
        let mut rows = 1;
        for a in 1..D {
            row_stride[a] = rows;
            rows *= side[a] as usize;
        }
        let mut m = Members {
            lo,
            side,
            period,
            row_words,
            row_stride,
            bits: vec![0; rows * row_words + 1],
            extent: vec![(u32::MAX, 0); rows],
            words: 0,
        };
        for s in sites {
            m.insert(s);
        }
        m
    }

    /// Row and bit in the row of relative position `r` (in `[0, L)` on periodic axes), or
    /// `None` outside the box.
    #[inline]
    fn index(&self, r: &[i32; D]) -> Option<(usize, usize)> {
        let r = fold(&self.period, r);
        let mut row = 0;
        let mut bit = 0;
        for a in 0..D {
            let d = r[a].wrapping_sub(self.lo[a]) as u32;
            if d >= self.side[a] {
                return None;
            }
            if a == 0 {
                bit = d as usize;
            } else {
                row += d as usize * self.row_stride[a];
            }
        }
        Some((row, bit))
    }

    /// Set relative position `r`, which lies in the box.
    fn insert(&mut self, r: &[i32; D]) {
        let (row, bit) = self.index(r).expect("inside the box");
        let w = (1 + bit / 64) as u32;
        self.bits[row * self.row_words + w as usize] |= 1 << (bit % 64);
        let (lo, hi) = self.extent[row];
        let span = |(lo, hi): (u32, u32)| if lo > hi { 0 } else { (hi - lo + 2) as usize };
        let new = (lo.min(w), hi.max(w));
        self.words = self.words + span(new) - span((lo, hi));
        self.extent[row] = new;
    }

    /// Whether relative position `r` is set.
    #[inline]
    pub(super) fn contains(&self, r: &[i32; D]) -> bool {
        self.index(r).is_some_and(|(row, bit)| {
            self.bits[row * self.row_words + 1 + bit / 64] & (1 << (bit % 64)) != 0
        })
    }

    /// Set `added`, the sites merged in; `all` are all the cluster's sites, `added` among them,
    /// from which the box is rebuilt when an added site lies outside it.
    pub(super) fn extend(&mut self, geo: &Geometry<D>, all: &[[i32; D]], added: &[[i32; D]]) {
        if added.iter().any(|r| self.index(r).is_none()) {
            *self = Members::build(geo, all);
            return;
        }
        for r in added {
            self.insert(r);
        }
    }

    /// Number of positions set.
    pub(super) fn count(&self) -> usize {
        self.bits.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// Rows of the box.
    pub(super) fn rows(&self) -> usize {
        self.extent.len()
    }

    /// Words a move by rows writes, about: each row holding bits, its words plus one.
    pub(super) fn words(&self) -> usize {
        self.words
    }

    /// Panic unless each row's extent is exactly its words holding bits. For tests.
    pub(super) fn check(&self) {
        let mut words = 0;
        for (row, &(lo, hi)) in self.extent.iter().enumerate() {
            let w = &self.bits[row * self.row_words..][..self.row_words];
            assert_eq!(w[0], 0, "the zero word of row {row}");
            let first = w.iter().position(|&x| x != 0);
            let last = w.iter().rposition(|&x| x != 0);
            match (first, last) {
                (Some(f), Some(l)) => {
                    assert_eq!((f as u32, l as u32), (lo, hi), "extent of row {row}");
                    words += l - f + 2;
                }
                _ => assert!(lo > hi, "extent of empty row {row}"),
            }
        }
        assert_eq!(words, self.words, "words of the extents");
    }

    /// Move the cluster's particles in `occupied` (one bit a site by site index of `geo`) from
    /// origin `origin` one step along `axis` (up if `up`): each lattice word that changes is
    /// flipped once, by the exclusive or of the old and the new image there, worked out from
    /// the members' rows and shifted into the lattice row's alignment (a word at a time where
    /// the rows are whole words, [`Geometry::word_rows`]). Needs consecutive site indices along
    /// axis 0 and a first side of at least 64 ([`Geometry::bit_rows`]). Exclusive or is linear,
    /// so this holds where images wrap onto themselves around a periodic axis too.
    pub(super) fn xor_move(
        &self,
        geo: &Geometry<D>,
        occupied: &mut [u64],
        origin: &[i64; D],
        axis: usize,
        up: bool,
    ) {
        let row_len = geo.size[0];
        // The lattice position of the start of the box's word 0 (each row's zero word): box
        // word `j` starts at `x0 + 64 j` (modulo the row).
        let x0 = (origin[0] + i64::from(self.lo[0]) - 64).rem_euclid(row_len) as usize;
        let emit = Emitter::new(geo, x0);
        // Absolute coordinates along axes 1 and up of the current row, at `origin`.
        let start: [i64; D] = std::array::from_fn(|a| {
            if a == 0 {
                0
            } else {
                (origin[a] + i64::from(self.lo[a])).rem_euclid(geo.size[a])
            }
        });
        // The site index of a row's first site (`y[0]` is 0).
        let base_of = |y: &[i64; D]| geo.site(y, &[0; D]);
        let step: i64 = if up { 1 } else { -1 };
        let rw = self.row_words;
        let words = |row: usize, lo: u32, hi: u32| {
            &self.bits[row * rw + lo as usize - 1..][..(hi - lo + 3) as usize]
        };
        let mut y = start;
        let mut at = [0u32; D];
        for (row, &(lo, hi)) in self.extent.iter().enumerate() {
            if row > 0 {
                // Odometer over the axes 1 and up.
                for a in 1..D {
                    at[a] += 1;
                    y[a] += 1;
                    if y[a] == geo.size[a] {
                        y[a] = 0;
                    }
                    if at[a] < self.side[a] {
                        break;
                    }
                    at[a] = 0;
                    y[a] = start[a];
                }
            }
            let base = base_of(&y);
            if axis == 0 {
                if lo > hi {
                    continue;
                }
                // The row's change: its bits, exclusive or themselves one bit up (or down).
                let m = words(row, lo, hi);
                if up {
                    let d = m.windows(2).map(|p| p[1] ^ ((p[1] << 1) | (p[0] >> 63)));
                    emit.xor(occupied, base, lo as usize, d);
                } else {
                    let d = m.windows(2).map(|p| p[0] ^ ((p[0] >> 1) | (p[1] << 63)));
                    emit.xor(occupied, base, lo as usize - 1, d);
                }
                continue;
            }
            // Along axis `axis` >= 1: this lattice row loses this member row and gains the
            // one `step` behind it (if in the box); and where no member row lies `step` ahead,
            // the lattice row ahead gains this one.
            let back = i64::from(at[axis]) - step;
            let prev = (0..i64::from(self.side[axis]))
                .contains(&back)
                .then(|| {
                    let p = (row as i64 - step * self.row_stride[axis] as i64) as usize;
                    (p, self.extent[p])
                })
                .filter(|&(_, (l, h))| l <= h);
            let own = |row: usize, lo: u32, hi: u32| words(row, lo, hi)[1..].iter().copied();
            match (lo <= hi, prev) {
                (false, None) => {}
                (true, None) => emit.xor(occupied, base, lo as usize, own(row, lo, hi)),
                (false, Some((p, (l, h)))) => emit.xor(occupied, base, l as usize, own(p, l, h)),
                (true, Some((p, (l, h)))) => {
                    let (ul, uh) = (lo.min(l), hi.max(h));
                    let d = own(row, ul, uh).zip(own(p, ul, uh)).map(|(a, b)| a ^ b);
                    emit.xor(occupied, base, ul as usize, d);
                }
            }
            let ahead = i64::from(at[axis]) + step;
            if lo <= hi && !(0..i64::from(self.side[axis])).contains(&ahead) {
                let mut z = y;
                z[axis] = (z[axis] + step).rem_euclid(geo.size[axis]);
                emit.xor(occupied, base_of(&z), lo as usize, own(row, lo, hi));
            }
        }
    }
}

/// Where a move by rows flips the bits of a lattice row: by whole words where the rows are
/// whole words ([`Geometry::word_rows`]), else bit by bit from any position.
enum Emitter {
    /// Box word `j` lands in lattice words `q0 + j` and `q0 + j + 1` of the row (of `words`
    /// words), shifted up by `t` bits.
    Words { q0: usize, t: u32, words: usize },
    /// Box word `j` starts at lattice position `x0 + 64 j` of a row of `len` sites.
    Bits { x0: usize, len: usize },
}

impl Emitter {
    fn new<const D: usize>(geo: &Geometry<D>, x0: usize) -> Self {
        let len = geo.size[0] as usize;
        if geo.word_rows() {
            Emitter::Words {
                q0: x0 / 64,
                t: (x0 % 64) as u32,
                words: len / 64,
            }
        } else {
            Emitter::Bits { x0, len }
        }
    }

    /// Flip in `occupied` the row starting at site index `base` by `words`, box words
    /// `j, j + 1, ...` of a row (wrapping around the lattice row).
    #[inline(always)]
    fn xor(&self, occupied: &mut [u64], base: usize, j: usize, words: impl Iterator<Item = u64>) {
        match *self {
            Emitter::Words { q0, t, words: n } => {
                let row = &mut occupied[base / 64..base / 64 + n];
                xor_words(row, q0 + j, words, t);
            }
            Emitter::Bits { x0, len } => xor_bits(occupied, base, len, (x0 + 64 * j) % len, words),
        }
    }
}

/// Flip in `occupied` the bits of the lattice row of `len` sites (at least 64) starting at bit
/// `base`, from position `x` on (wrapping around the row), by the bits of `words`.
fn xor_bits(
    occupied: &mut [u64],
    base: usize,
    len: usize,
    mut x: usize,
    words: impl Iterator<Item = u64>,
) {
    for w in words {
        if w == 0 {
            x += 64;
            while x >= len {
                x -= len;
            }
            continue;
        }
        // The word's 64 bits, in at most two runs (split where the row wraps).
        let mut v = w;
        let mut left = 64;
        while left > 0 {
            let run = left.min(len - x);
            let bits = if run == 64 { v } else { v & ((1 << run) - 1) };
            let (i, s) = ((base + x) / 64, (base + x) % 64);
            occupied[i] ^= bits << s;
            if s + run > 64 {
                occupied[i + 1] ^= bits >> (64 - s);
            }
            v = if run == 64 { 0 } else { v >> run };
            left -= run;
            x += run;
            if x == len {
                x = 0;
            }
        }
    }
}

/// Flip in `lattice_row` the words from `w` on (wrapping around the row) by `words` shifted up
/// by `t` bits, each word's low bits from the one before it (zero before the first), and the
/// word after them by the last one's high bits.
#[inline(always)]
fn xor_words(lattice_row: &mut [u64], mut w: usize, words: impl Iterator<Item = u64>, t: u32) {
    let n = lattice_row.len();
    while w >= n {
        w -= n;
    }
    let mut carry = 0;
    for x in words {
        lattice_row[w] ^= (x << t) | carry;
        // `x >> (64 - t)`, and 0 when `t` is 0.
        carry = (x >> 1) >> (63 - t);
        w += 1;
        if w == n {
            w = 0;
        }
    }
    lattice_row[w] ^= carry;
}

/// `r` with each coordinate in `[ceil(L/2), L)` of an axis of period `L` taken `L` lower.
#[inline]
fn fold<const D: usize>(period: &[i32; D], r: &[i32; D]) -> [i32; D] {
    std::array::from_fn(|a| {
        if period[a] > 0 && 2 * r[a] >= period[a] {
            r[a] - period[a]
        } else {
            r[a]
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use core_lattice::{Boundary, Lattice};

    /// Members hold exactly what they were given, on both sides of the origin of a periodic axis
    /// (positions near `L` are the ones just below 0), beside a wall axis with negative
    /// positions, and after an extension that rebuilds the box.
    #[test]
    fn members_are_exactly_the_positions_given() {
        let lattice = Lattice::new(&[10, 300], &[Boundary::Periodic, Boundary::Wall]).unwrap();
        let geo = Geometry::<2>::new(&lattice);
        let mut all = vec![[0, 0], [9, 0], [5, -3], [1, 2]];
        let mut m = Members::build(&geo, &all);
        let check = |m: &Members<2>, all: &[[i32; 2]]| {
            m.check();
            assert_eq!(m.count(), all.len());
            for x in 0..10 {
                for y in -299..300 {
                    assert_eq!(m.contains(&[x, y]), all.contains(&[x, y]), "{x}, {y}");
                }
            }
        };
        check(&m, &all);
        // Inside the box, then far outside it along the wall axis.
        for added in [vec![[2, 2]], vec![[3, 250], [4, -200]]] {
            let before = all.len();
            all.extend(added);
            m.extend(&geo, &all, &all[before..]);
            check(&m, &all);
        }
    }
}
