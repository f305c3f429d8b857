//! The fractal dimension of DLCA clusters against the literature (Jullien, Kolb & Botet 1984,
//! lattice DLCA: 1.42 +- 0.03 in 2D, often quoted 1.44-1.45; 1.78 +- 0.05 in 3D; 2.02-2.04 +-
//! 0.08 in 4D; 2.25-2.30 +- 0.2 in 5D; docs/dlca.md, "Validation").
//!
//! Method (`--gyration`): measure every cluster's radius of gyration (unwrapped), pool the
//! clusters of several seeds and fit `log s = D log R_g + c` over clusters of at least 10
//! particles. In 2D and 3D the clusters are those left at the end of a run to a few tens of
//! clusters at low fill (1% in 2D, 0.25% in 3D: D rises with concentration and the literature
//! value is the dilute limit). In 4D and 5D a cluster of `s` particles meets others at a rate
//! growing faster than `s` (its cross-section `R^(d-2)` grows as `s^((d-2)/D)`, and
//! `(d - 2) / D` is about 1 in 4D and 1.3 in 5D), so one cluster runs away with most particles
//! and grows by swallowing small ones: the end of a run holds one large cluster and debris, and
//! a fit over them measures that accretion (2.1 in 4D, 2.5-2.6 in 5D), not cluster-cluster
//! aggregation. There the clusters are pooled from four moments of each run instead, when the
//! mean cluster size passes 8, 16, 32 and 64: from when clusters of 10 particles are common to
//! when tens remain, as the literature pools the clusters formed during the aggregation.
//!
//! Tolerances. The issue allows at most +-0.08 (2D) and +-0.12 (3D) around 1.44 and 1.78. Those
//! windows hold the literature's own spread (1.42-1.45 in 2D, +-0.05 in 3D) plus the statistical
//! error of a pooled fit over about a hundred clusters (the fit's standard error is 0.02-0.04
//! here, so two standard errors are 0.05-0.08) and the finite-size bias of clusters of tens to
//! hundreds of particles. In 4D and 5D the windows are the literature's error plus the spread
//! of this test's value over seeds and the finite-size shift of its small lattices, measured in
//! release on 64 seeds (docs/dlca.md, "Validation"). The test also requires the fit's own
//! standard error to be small enough for the comparison to mean something.

use core_lattice::Boundary;
use dlca::analysis::{ClusterMeasure, PoolAt, fractal_dimension, pooled_clusters};
use dlca::{Init, Params};

fn pooled_dimension(dim: usize, side: u64, fill: f64, at: PoolAt, seeds: u64) -> (f64, f64, usize) {
    let params = Params {
        size: vec![side; dim],
        boundary: vec![Boundary::Periodic; dim],
        init: Init::Fill(fill),
        ..Params::default()
    };
    let mut pooled: Vec<ClusterMeasure> = Vec::new();
    for seed in 1..=seeds {
        pooled.extend(pooled_clusters(&params, seed, &at).unwrap());
    }
    let fit = fractal_dimension(&pooled, 10).unwrap();
    (fit.slope, fit.slope_stderr, fit.n)
}

/// The moments at which 4D and 5D runs contribute their clusters.
fn mean_sizes() -> PoolAt {
    PoolAt::MeanSizes(vec![8, 16, 32, 64])
}

#[test]
fn fractal_dimension_2d_matches_literature() {
    let (d, se, n) = pooled_dimension(2, 1024, 0.01, PoolAt::End(30), 4);
    eprintln!("2D DLCA: D = {d:.4} +- {se:.4} over {n} clusters");
    assert!(n >= 80, "only {n} clusters in the fit");
    assert!(se < 0.04, "fit too noisy: stderr {se}");
    assert!(
        (d - 1.44).abs() <= 0.08,
        "2D DLCA fractal dimension {d} (+- {se}) outside 1.44 +- 0.08"
    );
}

#[test]
fn fractal_dimension_3d_matches_literature() {
    // 0.25% fill: in 3D, D still rises visibly with concentration at 1% (docs/dlca.md,
    // "Validation"), and the literature value is the dilute limit.
    let (d, se, n) = pooled_dimension(3, 128, 0.0025, PoolAt::End(20), 12);
    eprintln!("3D DLCA: D = {d:.4} +- {se:.4} over {n} clusters");
    assert!(n >= 80, "only {n} clusters in the fit");
    assert!(se < 0.06, "fit too noisy: stderr {se}");
    assert!(
        (d - 1.78).abs() <= 0.12,
        "3D DLCA fractal dimension {d} (+- {se}) outside 1.78 +- 0.12"
    );
}

#[test]
fn fractal_dimension_4d_matches_literature() {
    // Jullien, Kolb & Botet: 2.02-2.04 +- 0.08. Measured in release on 64 seeds of this
    // lattice (32^4 at 0.2%, clusters pooled at mean sizes 8-64), eight at a time: 2.024 with a
    // spread of 0.030 between groups of eight; on larger, more dilute lattices 1.99-2.00
    // (40^4 at 0.1%, 48^4 at 0.05%). Window: the literature's +-0.08 plus about three of those
    // spreads.
    let (d, se, n) = pooled_dimension(4, 32, 0.002, mean_sizes(), 8);
    eprintln!("4D DLCA: D = {d:.4} +- {se:.4} over {n} clusters");
    assert!(n >= 400, "only {n} clusters in the fit");
    assert!(se < 0.04, "fit too noisy: stderr {se}");
    assert!(
        (d - 2.03).abs() <= 0.17,
        "4D DLCA fractal dimension {d} (+- {se}) outside 2.03 +- 0.17"
    );
}

#[test]
fn fractal_dimension_5d_matches_literature() {
    // Jullien, Kolb & Botet: 2.25-2.30 +- 0.2. Measured in release on 64 seeds of this lattice
    // (16^5 at 0.2%, clusters pooled at mean sizes 8-64), eight at a time: 2.444 with a spread
    // of 0.023 between groups of eight; 2.37-2.42 on larger, more dilute lattices (20^5 at
    // 0.1%, 24^5 at 0.03%). The excess over the literature's centre is the runaway cluster of
    // the 5D kernel (module docs): it grows with the mean size at which clusters are pooled.
    // Window: the literature's +-0.2 plus three of those spreads.
    let (d, se, n) = pooled_dimension(5, 16, 0.002, mean_sizes(), 8);
    eprintln!("5D DLCA: D = {d:.4} +- {se:.4} over {n} clusters");
    assert!(n >= 200, "only {n} clusters in the fit");
    assert!(se < 0.05, "fit too noisy: stderr {se}");
    assert!(
        (d - 2.275).abs() <= 0.27,
        "5D DLCA fractal dimension {d} (+- {se}) outside 2.275 +- 0.27"
    );
}
