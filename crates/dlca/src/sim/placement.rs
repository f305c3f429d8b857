//! The initial state of a run: particles on distinct random sites, grouped into clusters of
//! face-adjacent particles.
//!
//! Invariants: the placement is a pure function of the lattice, the particle count and the
//! random stream (whichever bookkeeping of taken sites is used); initial clusters are numbered
//! in order of their first particle, each with its sites in placement order.

use core_lattice::Lattice;
use core_lattice::rng::{SimRng, uniform01};
use run_io::memory::{AllocError, try_reserve, try_vec};

/// `n` distinct sites drawn uniformly (rejection sampling), in draw order. Taken sites are
/// tracked in a bitset (one bit per site) when the lattice has at most 64 sites per particle,
/// else in a hash set; both give the same draws. The large arrays are allocated fallibly: an
/// [`AllocError`] rather than an abort when the memory is not there.
pub(super) fn place_particles(
    lattice: &Lattice,
    n: u64,
    rng: &mut SimRng,
) -> Result<Vec<u64>, AllocError> {
    let volume = lattice.volume();
    let mut sites = Vec::new();
    try_reserve(&mut sites, n as usize, "the particles' sites")?;
    let mut draw = |taken: &mut dyn FnMut(u64) -> bool| {
        while (sites.len() as u64) < n {
            let k = ((uniform01(rng) * volume as f64) as u64).min(volume - 1);
            if taken(k) {
                sites.push(k);
            }
        }
    };
    if volume <= n.saturating_mul(64) {
        let mut bits = try_vec(volume.div_ceil(64) as usize, 0u64, "the taken-sites bitset")?;
        draw(&mut |k| {
            let (w, b) = ((k / 64) as usize, 1u64 << (k % 64));
            let fresh = bits[w] & b == 0;
            bits[w] |= b;
            fresh
        });
    } else {
        let mut taken = std::collections::HashSet::new();
        taken.try_reserve(n as usize).map_err(|_| AllocError {
            bytes: n.saturating_mul(16),
            what: "the taken-sites set".into(),
        })?;
        draw(&mut |k| taken.insert(k));
    }
    Ok(sites)
}

/// Group face-adjacent particles into clusters (union-find), numbered in order of their first
/// particle in `sites`; each cluster's sites in `sites` order.
/// The index of sites and the union-find array are allocated fallibly.
pub(super) fn initial_clusters(
    lattice: &Lattice,
    sites: &[u64],
) -> Result<Vec<Vec<u64>>, AllocError> {
    let mut index: std::collections::HashMap<u64, usize> = std::collections::HashMap::new();
    index.try_reserve(sites.len()).map_err(|_| AllocError {
        bytes: (sites.len() as u64).saturating_mul(24),
        what: "the index of the particles' sites".into(),
    })?;
    index.extend(sites.iter().enumerate().map(|(i, &k)| (k, i)));
    let mut parent: Vec<usize> = Vec::new();
    try_reserve(&mut parent, sites.len(), "the initial grouping")?;
    parent.extend(0..sites.len());
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for (i, &k) in sites.iter().enumerate() {
        for n in lattice.neighbours(k) {
            if let Some(&j) = index.get(&n) {
                let (a, b) = (find(&mut parent, i), find(&mut parent, j));
                if a != b {
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
    }
    let mut cluster_of_root = std::collections::HashMap::new();
    let mut clusters: Vec<Vec<u64>> = Vec::new();
    for (i, &k) in sites.iter().enumerate() {
        let root = find(&mut parent, i);
        let c = *cluster_of_root.entry(root).or_insert_with(|| {
            clusters.push(Vec::new());
            clusters.len() - 1
        });
        clusters[c].push(k);
    }
    Ok(clusters)
}

#[cfg(test)]
mod tests {
    use super::*;
    use core_lattice::Boundary;
    use core_lattice::rng::stream;

    #[test]
    fn adjacent_particles_start_as_one_cluster() {
        let l = Lattice::new(&[5, 4], &[Boundary::Periodic, Boundary::Wall]).unwrap();
        let at = |x, y| l.encode(&[x, y]).unwrap();
        // (0,0)-(4,0) touch across the periodic x axis; (2,0)-(2,3) do not touch (wall in y).
        let sites = vec![
            at(0, 0),
            at(2, 2),
            at(4, 0),
            at(2, 0),
            at(2, 3),
            at(3, 3),
            at(1, 1),
        ];
        let c = initial_clusters(&l, &sites).unwrap();
        assert_eq!(
            c,
            vec![
                vec![at(0, 0), at(4, 0)],
                vec![at(2, 2), at(2, 3), at(3, 3)],
                vec![at(2, 0)],
                vec![at(1, 1)]
            ]
        );
    }

    #[test]
    fn placement_is_distinct_and_a_function_of_the_stream() {
        let l = Lattice::periodic(&[10, 10]).unwrap();
        let a = place_particles(&l, 90, &mut stream(1, 1)).unwrap();
        let b = place_particles(&l, 90, &mut stream(1, 1)).unwrap();
        assert_eq!(a, b);
        assert_ne!(a, place_particles(&l, 90, &mut stream(2, 1)).unwrap());
        // Sparse (hash set) and dense (bitset) tracking draw the same sites.
        let big = Lattice::periodic(&[1000, 1000]).unwrap();
        let sparse = place_particles(&big, 1000, &mut stream(2, 1)).unwrap();
        let dense = place_particles(&big, 20_000, &mut stream(2, 1)).unwrap();
        assert_eq!(&dense[..1000], &sparse[..]);
        let mut s = a.clone();
        s.sort_unstable();
        s.dedup();
        assert_eq!(s.len(), 90);
        assert!(s.iter().all(|&k| k < 100));
    }
}
