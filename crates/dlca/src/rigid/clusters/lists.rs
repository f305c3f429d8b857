//! The face and probe lists of a cluster's shape ([`Rigid::finish`]): computed from its sites
//! and the occupancy lattice at the start and after merges, kept as parts in between.

use super::moves::large_owner;
use super::{Cluster, Lists, Rigid, SMALL};
use crate::rigid::frame::Frame;
use crate::rigid::geometry::step;
use crate::rigid::members::Members;
use spatial::lattice::ItemId;

impl<const D: usize, F: Frame<D>> Rigid<D, F> {
    /// After merges into cluster `id`: recompute its extent and its face and probe lists from
    /// its sites and the occupancy lattice (O(size)) if the parts merged in since the last time
    /// hold as many particles as the lists cover; otherwise keep the parts (see [`Part`]).
    pub(in crate::rigid) fn finish(&mut self, id: ItemId) {
        let c = &self.clusters[id as usize];
        let extra: u32 = c.parts.as_slice().iter().map(|p| p.len).sum();
        // Small clusters are recomputed at once: cheap, and it spares their moves the parts'
        // extra pointers.
        if !c.parts.is_empty() && 2 * extra < c.len && c.len > SMALL {
            return;
        }
        if self.marks.is_empty() {
            self.marks = vec![0; self.geo.ext_volume.div_ceil(64) as usize];
        }
        let mut c = std::mem::take(&mut self.clusters[id as usize]);
        let mut cold = std::mem::take(&mut self.cold[id as usize]);
        // Large clusters are kept in memory order (re-sorted when they double), so their lists
        // walk the occupancy lattice in order.
        if cold.sites.len() >= 64 && cold.sites.len() >= 2 * cold.sorted_len {
            let (geo, o) = (&self.geo, c.origin);
            cold.sites.sort_by_cached_key(|r| geo.site(&o, r));
            cold.sorted_len = cold.sites.len();
        }
        c.parts.clear();
        c.lists = match &self.single {
            Some(single) if cold.sites.len() == 1 => single.clone(),
            _ => self.build_lists(&mut c, &cold.sites, cold.members.as_deref()),
        };
        if cold.sites.len() == 1 && self.single.is_none() {
            self.single = Some(c.lists.clone());
        }
        self.clusters[id as usize] = c;
        self.cold[id as usize] = cold;
    }

    /// The extent and the lists of `c`, whose particles are `sites` (and `members`, for a large
    /// cluster, whose labels are stale).
    pub(super) fn build_lists(
        &mut self,
        c: &mut Cluster<D, F>,
        sites: &[[i32; D]],
        members: Option<&Members<D>>,
    ) -> Lists<F::Entry> {
        let label = c.label;
        let Rigid {
            geo,
            frame,
            occupied,
            cells,
            marks,
            hood,
            scratch,
            large,
            clusters,
            cold,
            ..
        } = self;
        let o = c.origin;
        let cells = cells.get();
        // A small cluster's label on a site is stale where a large cluster covered it since.
        let held =
            |r: &[i32; D]| large_owner(geo, large, clusters, cold, &geo.absolute(&o, r)).is_some();
        let in_c = |r: &[i32; D]| match members {
            // Relative positions of particles lie in `[0, L)` on periodic axes.
            Some(m) => m.contains(&std::array::from_fn(|a| {
                if geo.periodic[a] {
                    r[a].rem_euclid(geo.size[a] as i32)
                } else {
                    r[a]
                }
            })),
            None => geo
                .any(&o, r)
                .is_some_and(|k| occupied.get(k) && cells[k] == label && !held(r)),
        };
        scratch.iter_mut().for_each(Vec::clear);
        hood.clear();
        c.lo = [i32::MAX; D];
        c.hi = [i32::MIN; D];
        for s in sites {
            for a in 0..D {
                c.lo[a] = c.lo[a].min(s[a]);
                c.hi[a] = c.hi[a].max(s[a]);
            }
            for d in 0..2 * D {
                let q = step(s, d);
                if in_c(&q) {
                    continue;
                }
                scratch[d].push(*s);
                // A neighbour site (possibly one step beyond a wall), each once.
                let e = geo.ext(&o, &q).expect("one step from a particle");
                let (w, b) = (e / 64, 1u64 << (e % 64));
                if marks[w] & b == 0 {
                    marks[w] |= b;
                    hood.push((q, e));
                }
            }
        }
        for (q, _) in hood.iter() {
            for d in 0..2 * D {
                let n = step(q, d);
                let near = in_c(&n)
                    || geo
                        .ext(&o, &n)
                        .is_some_and(|e| marks[e / 64] & (1u64 << (e % 64)) != 0);
                if !near {
                    scratch[2 * D + d].push(*q);
                }
            }
        }
        for (_, e) in hood.iter() {
            marks[e / 64] &= !(1u64 << (e % 64));
        }
        let head = 4 * D + 1;
        let mut lists = Vec::with_capacity(head + scratch.iter().map(Vec::len).sum::<usize>());
        lists.push(F::start(head));
        let mut end = head;
        for list in scratch.iter() {
            end += list.len();
            lists.push(F::start(end));
        }
        for list in scratch.iter() {
            lists.extend(list.iter().map(|r| frame.entry(geo, r)));
        }
        lists.into()
    }
}
