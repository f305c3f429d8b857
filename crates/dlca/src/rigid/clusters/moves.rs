//! A move of a rigid cluster ([`Rigid::try_move`]): the occupancy bits of its trailing face
//! cleared and those of its leading face set (with its label, unless it is large; a large one
//! may flip its image by rows instead), then its probes read, a probe that finds a particle
//! telling its owner by the large clusters' members first and the label after.

use super::{Cluster, Cold, Rigid, RowMoves, list};
use crate::rigid::frame::Frame;
use crate::rigid::geometry::{Bits, Geometry};
use core_lattice::{Blocked, Direction};
use spatial::lattice::ItemId;

/// The large cluster among `large` (with their records `clusters` and `cold`) whose members
/// hold the site at coordinates `x`, if any.
pub(super) fn large_owner<const D: usize, F: Frame<D>>(
    geo: &Geometry<D>,
    large: &[ItemId],
    clusters: &[Cluster<D, F>],
    cold: &[Cold<D>],
    x: &[i64; D],
) -> Option<ItemId> {
    large.iter().copied().find(|&b| {
        let members = cold[b as usize].members.as_ref().expect("a large cluster");
        members.contains(&geo.relative(&clusters[b as usize].origin, x))
    })
}

/// Clear the occupancy bits of the sites `entries` at origin `o`. A function of its own (like
/// [`cover`]) so that its loop keeps its few values in registers.
#[inline(never)]
fn vacate<const D: usize, F: Frame<D>>(
    frame: &F,
    geo: &Geometry<D>,
    occupied: &mut Bits,
    o: F::Origin,
    entries: &[F::Entry],
) {
    for &e in entries {
        occupied.clear(frame.site(geo, o, e));
    }
}

/// Set the occupancy bits of the sites `entries` at origin `o` and give them label `label`, if
/// there is one (a large cluster has none to write).
#[inline(never)]
fn cover<const D: usize, F: Frame<D>>(
    frame: &F,
    geo: &Geometry<D>,
    occupied: &mut Bits,
    cells: &mut [u32],
    label: Option<u32>,
    o: F::Origin,
    entries: &[F::Entry],
) {
    match label {
        Some(label) => {
            for &e in entries {
                let k = frame.site(geo, o, e);
                occupied.set(k);
                cells[k] = label;
            }
        }
        None => {
            for &e in entries {
                occupied.set(frame.site(geo, o, e));
            }
        }
    }
}

impl<const D: usize, F: Frame<D>> Rigid<D, F> {
    /// The cluster holding occupied site `k`: the large cluster whose members hold it, else the
    /// owner of its label (stale only under a large cluster, which writes none).
    pub(super) fn owner_of(&self, k: usize) -> ItemId {
        let x = self.geo.coords_of(k);
        large_owner(&self.geo, &self.large, &self.clusters, &self.cold, &x)
            .unwrap_or_else(|| self.id_of[self.cells.get()[k] as usize])
    }

    /// Move cluster `id` by `dir`: all or nothing (a wall blocks it). On success the clusters
    /// now in contact with it are written to `out`, in increasing id.
    pub(in crate::rigid) fn try_move(
        &mut self,
        id: ItemId,
        dir: Direction,
        out: &mut Vec<ItemId>,
    ) -> Result<(), Blocked> {
        out.clear();
        self.shift(id, dir)?;
        self.probe(id, dir.index(), out);
        out.sort_unstable();
        Ok(())
    }

    /// The occupancy part of a move of cluster `id` by `dir`: vacate its trailing face, move
    /// its origin, cover its leading face (with its label, unless it is large).
    fn shift(&mut self, id: ItemId, dir: Direction) -> Result<(), Blocked> {
        let Rigid {
            geo,
            frame,
            occupied,
            cells,
            clusters,
            cold,
            large_at,
            row_moves,
            ..
        } = self;
        let cells = cells.get_mut();
        let c = &mut clusters[id as usize];
        let (axis, d) = (dir.axis(), dir.index());
        if !geo.periodic[axis] {
            let blocked = if dir.is_positive() {
                c.origin[axis] + i64::from(c.hi[axis]) + 1 >= geo.size[axis]
            } else {
                c.origin[axis] + i64::from(c.lo[axis]) <= 0
            };
            if blocked {
                return Err(Blocked);
            }
        }
        let old = c.origin;
        let mut o = old;
        o[axis] += if dir.is_positive() { 1 } else { -1 };
        if o[axis] >= geo.size[axis] {
            o[axis] -= geo.size[axis];
        } else if o[axis] < 0 {
            o[axis] += geo.size[axis];
        }
        c.origin = o;
        let lists = &*c.lists;
        let large = c.len >= *large_at;
        // A large cluster's image moved a word at a time, where that visits at most half as
        // many words and rows as its faces hold sites (see `RowMoves`).
        if large && *row_moves != RowMoves::Never {
            let members = cold[id as usize]
                .members
                .as_deref()
                .expect("a large cluster");
            let faces = |l: &[F::Entry]| list::<D, F>(l, d).len() + list::<D, F>(l, d ^ 1).len();
            let parts = c.parts.as_slice().iter();
            let sites = faces(lists) + parts.map(|p| faces(&p.lists)).sum::<usize>();
            let by_rows = match row_moves {
                RowMoves::WhenCheaper => 2 * (members.words() + members.rows()) <= sites,
                _ => true,
            };
            if by_rows {
                let words = occupied.words_mut();
                members.xor_move(geo, words, &old, axis, dir.is_positive());
                return Ok(());
            }
        }
        // Vacate the trailing face (in the old frame); labels of empty sites are never read.
        let fo = frame.origin(geo, &old);
        vacate(frame, geo, occupied, fo, list::<D, F>(lists, d ^ 1));
        for p in c.parts.as_slice() {
            let po = frame.origin(geo, &geo.shifted(&old, &p.offset));
            vacate(frame, geo, occupied, po, list::<D, F>(&p.lists, d ^ 1));
        }
        let fo = frame.origin(geo, &o);
        // Cover the leading face (in the new frame).
        debug_assert!(
            !c.parts.is_empty()
                || list::<D, F>(lists, d)
                    .iter()
                    .all(|&e| !occupied.get(frame.site(geo, fo, e))),
            "clusters overlap"
        );
        let label = (!large).then_some(c.label);
        cover(
            frame,
            geo,
            occupied,
            cells,
            label,
            fo,
            list::<D, F>(lists, d),
        );
        for p in c.parts.as_slice() {
            let po = frame.origin(geo, &geo.shifted(&o, &p.offset));
            let entries = list::<D, F>(&p.lists, d);
            cover(frame, geo, occupied, cells, label, po, entries);
        }
        Ok(())
    }

    /// The clusters in contact with cluster `id` after its move in direction index `d`, into
    /// `out`: it looks at its new neighbours only.
    fn probe(&self, id: ItemId, d: usize, out: &mut Vec<ItemId>) {
        let (geo, frame, occupied) = (&self.geo, &self.frame, &self.occupied);
        let cells = self.cells.get();
        let c = &self.clusters[id as usize];
        let o = c.origin;
        let label = c.label;
        let mut probe = |fo: F::Origin, lists: &[F::Entry]| {
            for &e in list::<D, F>(lists, 2 * D + d) {
                if let Some(k) = frame.probe(geo, fo, e)
                    && occupied.get(k)
                {
                    // Without large clusters every occupied site's label is its owner's.
                    let other = if self.large.is_empty() {
                        let l = cells[k];
                        if l == label {
                            continue;
                        }
                        self.id_of[l as usize]
                    } else {
                        self.owner_of(k)
                    };
                    if other != id && !out.contains(&other) {
                        out.push(other);
                    }
                }
            }
        };
        probe(frame.origin(geo, &o), &c.lists);
        for p in c.parts.as_slice() {
            probe(frame.origin(geo, &geo.shifted(&o, &p.offset)), &p.lists);
        }
    }
}
