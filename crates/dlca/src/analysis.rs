//! Final-state measurements: the cluster size distribution and, with `--gyration`, each
//! cluster's radius of gyration (unwrapped across periodic boundaries) and the fractal dimension
//! `D` from the fit `log s = D log R_g + c` over the clusters (docs/dlca.md,
//! "Validation"), of one run or pooled over the runs of an ensemble
//! ([`pooled_fractal_dimension`]).

use crate::params::{ParamError, Params};
use crate::sim::Simulation;
use core_lattice::stats::StatsError;
use core_lattice::{Direction, Fit, IntHistogram, LatticeGyration, MAX_DIM};
use spatial::lattice::ItemId;
use std::collections::{HashMap, VecDeque};

/// One final cluster.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClusterMeasure {
    /// Cluster id.
    pub id: ItemId,
    /// Number of particles.
    pub size: u64,
    /// Radius of gyration, unwrapped across periodic boundaries.
    pub radius_of_gyration: f64,
    /// Whether the cluster wraps around a periodic axis (spans the system), where unwrapping is
    /// ill-defined; such clusters are left out of the fit.
    pub wraps: bool,
}

/// Size distribution of the final clusters.
pub fn size_distribution(sim: &Simulation) -> IntHistogram {
    let mut h = IntHistogram::new();
    for &id in sim.sets().live() {
        h.add(sim.sets().sites(id).len() as u64);
    }
    h
}

/// Radius of gyration of every final cluster, in increasing id. Each cluster is unwrapped by a
/// breadth-first walk over its face-adjacent particles from its first particle, accumulating
/// unit steps, so periodic images are joined; a cluster reached at two different unwrapped
/// positions wraps around the system and is flagged.
pub fn gyration(sim: &Simulation) -> Vec<ClusterMeasure> {
    let lattice = sim.lattice();
    let sets = sim.sets();
    let dim = lattice.dim();
    let mut owner: HashMap<u64, ItemId> = HashMap::with_capacity(sim.particles() as usize);
    for &id in sets.live() {
        for &k in sets.sites(id) {
            owner.insert(k, id);
        }
    }
    let mut ids: Vec<ItemId> = sets.live().to_vec();
    ids.sort_unstable();
    let mut out = Vec::with_capacity(ids.len());
    let mut pos: HashMap<u64, [i64; MAX_DIM]> = HashMap::new();
    let mut queue = VecDeque::new();
    for id in ids {
        let sites = sets.sites(id);
        pos.clear();
        let start = lattice.decode(sites[0]).expect("site on the lattice");
        let mut u = [0i64; MAX_DIM];
        for a in 0..dim {
            u[a] = start[a] as i64;
        }
        pos.insert(sites[0], u);
        queue.push_back(sites[0]);
        let mut wraps = false;
        let mut g = LatticeGyration::new(dim);
        while let Some(k) = queue.pop_front() {
            let here = pos[&k];
            g.push(&here[..dim]);
            for dir in Direction::all(dim) {
                let Some(n) = lattice.neighbour(k, dir) else {
                    continue;
                };
                if owner.get(&n) != Some(&id) {
                    continue;
                }
                let mut next = here;
                next[dir.axis()] += if dir.is_positive() { 1 } else { -1 };
                match pos.get(&n) {
                    None => {
                        pos.insert(n, next);
                        queue.push_back(n);
                    }
                    Some(p) if *p != next => wraps = true,
                    Some(_) => {}
                }
            }
        }
        out.push(ClusterMeasure {
            id,
            size: sites.len() as u64,
            radius_of_gyration: g.radius(),
            wraps,
        });
    }
    out
}

/// Fit `log s = D log R_g + c` over the clusters of at least `min_size` particles that do not
/// wrap; the slope is the fractal dimension `D`.
pub fn fractal_dimension(clusters: &[ClusterMeasure], min_size: u64) -> Result<Fit, StatsError> {
    let (rg, s): (Vec<f64>, Vec<f64>) = clusters
        .iter()
        .filter(|c| c.size >= min_size.max(2) && !c.wraps)
        .map(|c| (c.radius_of_gyration, c.size as f64))
        .unzip();
    Fit::log_log(&rg, &s)
}

/// The fractal dimension of the clusters of several runs pooled into one fit, as the literature
/// measures DLCA's `D` (one run at low fill ends with tens of clusters; their fit scatters).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PooledFit {
    /// `D`: the slope of `log s = D log R_g + c` over every fitted cluster of every run.
    pub slope: f64,
    /// The error of `D` with the runs as the independent units: the jackknife over runs
    /// (`sqrt((m - 1) / m * sum (D_-i - mean D_-i)^2)`, `D_-i` the fit without run `i`); the
    /// clusters of one run share its history, so the regression's own error, which treats
    /// each cluster as independent, understates it. `None` with fewer than 2 runs (or when a
    /// leave-one-out fit fails).
    pub jackknife_stderr: Option<f64>,
    /// The regression's standard error of the slope over the pooled clusters.
    pub fit_stderr: f64,
    /// Clusters in the fit (at least `min_size` particles, not wrapping).
    pub clusters: usize,
    /// Runs pooled.
    pub runs: usize,
}

/// Fit `log s = D log R_g + c` over the clusters of every run in `runs` (each run's
/// [`ClusterMeasure`]s; those of at least `min_size` particles that do not wrap, as
/// [`fractal_dimension`]), with the jackknife error over runs.
///
/// # Errors
/// The pooled fit fails (fewer than 3 clusters, or all of one radius).
pub fn pooled_fractal_dimension(
    runs: &[Vec<ClusterMeasure>],
    min_size: u64,
) -> Result<PooledFit, StatsError> {
    let all: Vec<ClusterMeasure> = runs.iter().flatten().copied().collect();
    let fit = fractal_dimension(&all, min_size)?;
    let m = runs.len();
    let jackknife_stderr = (m >= 2)
        .then(|| {
            let leave_one_out: Option<Vec<f64>> = (0..m)
                .map(|i| {
                    let rest: Vec<ClusterMeasure> = runs
                        .iter()
                        .enumerate()
                        .filter(|(j, _)| *j != i)
                        .flat_map(|(_, r)| r.iter().copied())
                        .collect();
                    fractal_dimension(&rest, min_size).ok().map(|f| f.slope)
                })
                .collect();
            let d = leave_one_out?;
            let mean = d.iter().sum::<f64>() / m as f64;
            let ss: f64 = d.iter().map(|x| (x - mean) * (x - mean)).sum();
            Some((ss * (m - 1) as f64 / m as f64).sqrt())
        })
        .flatten();
    Ok(PooledFit {
        slope: fit.slope,
        jackknife_stderr,
        fit_stderr: fit.slope_stderr,
        clusters: fit.n,
        runs: m,
    })
}

/// When one run contributes its clusters to a pooled fractal-dimension fit
/// ([`pooled_clusters`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PoolAt {
    /// The clusters left when the run reaches this many clusters (2D and 3D: clusters of tens
    /// to hundreds of particles at low fill).
    End(u64),
    /// The clusters present each time the mean cluster size `particles / clusters` passes one
    /// of these, in increasing order. In 4D and 5D one cluster runs away with most particles and
    /// the end of a run is that cluster and debris, so the clusters are pooled during the
    /// aggregation instead (docs/dlca.md, "Validation").
    MeanSizes(Vec<u64>),
}

/// Run `params` from `seed` and return the clusters it contributes to a pooled fit: at the end
/// for [`PoolAt::End`], at each mean size for [`PoolAt::MeanSizes`] (their radii of gyration from
/// [`gyration`]). `params.target_clusters` is replaced by the last moment's cluster count. A run
/// that stops early (`max_sweeps`, or frozen clusters) contributes the moments it reached.
pub fn pooled_clusters(
    params: &Params,
    seed: u64,
    at: &PoolAt,
) -> Result<Vec<ClusterMeasure>, ParamError> {
    let n = params.particles()?;
    let targets: Vec<u64> = match at {
        PoolAt::End(clusters) => vec![*clusters],
        PoolAt::MeanSizes(sizes) => sizes.iter().map(|&m| (n / m.max(1)).max(1)).collect(),
    };
    let mut params = params.clone();
    params.target_clusters = targets.iter().copied().min().unwrap_or(1).max(1);
    let mut sim = Simulation::new(params, seed)?;
    let mut pooled = Vec::new();
    for target in targets {
        while sim.clusters() > target && !sim.is_done() {
            sim.sweep();
        }
        if sim.clusters() > target {
            break;
        }
        pooled.extend(gyration(&sim));
    }
    Ok(pooled)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cluster(size: u64, rg: f64) -> ClusterMeasure {
        ClusterMeasure {
            id: 0,
            size,
            radius_of_gyration: rg,
            wraps: false,
        }
    }

    /// Clusters on the exact power law s = R_g^2 give D = 2 with no error; runs that
    /// differ in their exponent give a jackknife error that grows with the spread between runs,
    /// which the pooled regression's error does not see.
    #[test]
    fn the_pooled_fit_has_the_spread_between_runs_as_its_error() {
        // Sizes rounded to whole particles: the slope is close to `d`, not exact.
        let run = |d: f64| -> Vec<ClusterMeasure> {
            (1..=20)
                .map(|i| {
                    let rg = 2.0 + f64::from(i);
                    cluster((rg.powf(d).round() as u64).max(2), rg)
                })
                .collect()
        };
        let exact: Vec<Vec<ClusterMeasure>> = (0..4)
            .map(|_| {
                (1..=20)
                    .map(|i| {
                        let rg = 2f64.powi(i % 10 + 1);
                        cluster(4u64.pow((i % 10 + 1) as u32), rg)
                    })
                    .collect()
            })
            .collect();
        let f = pooled_fractal_dimension(&exact, 2).unwrap();
        assert!((f.slope - 2.0).abs() < 1e-12, "{f:?}");
        assert!(f.jackknife_stderr.unwrap() < 1e-12, "{f:?}");
        assert_eq!((f.clusters, f.runs), (80, 4));

        let close = vec![run(1.40), run(1.42), run(1.44), run(1.46)];
        let far = vec![run(1.20), run(1.35), run(1.50), run(1.65)];
        let c = pooled_fractal_dimension(&close, 2).unwrap();
        let w = pooled_fractal_dimension(&far, 2).unwrap();
        assert!((c.slope - 1.43).abs() < 0.02, "{c:?}");
        assert!(
            w.jackknife_stderr.unwrap() > 4.0 * c.jackknife_stderr.unwrap(),
            "{c:?} {w:?}"
        );

        let one = pooled_fractal_dimension(&close[..1], 2).unwrap();
        assert_eq!(one.jackknife_stderr, None);
        assert!(pooled_fractal_dimension(&[vec![cluster(5, 1.0)]], 2).is_err());
    }
}
