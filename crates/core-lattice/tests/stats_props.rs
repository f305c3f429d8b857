//! Property tests of the statistics against straightforward two-pass references, and the
//! far-from-origin radius-of-gyration accuracy test.

use core_lattice::rng::{stream, uniform01, unit_vector};
use core_lattice::{Fit, Gyration, IntHistogram, LatticeGyration, LogHistogram, Welford};
use proptest::prelude::*;

fn two_pass(xs: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var)
}

fn close(a: f64, b: f64, rel: f64, abs: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + abs
}

/// Reference radius of gyration squared: mean by one pass, then mean squared deviation.
fn rg2_two_pass<const D: usize>(pts: &[[f64; D]]) -> f64 {
    let n = pts.len() as f64;
    let mut c = [0.0; D];
    for p in pts {
        for i in 0..D {
            c[i] += p[i] / n;
        }
    }
    pts.iter()
        .map(|p| (0..D).map(|i| (p[i] - c[i]).powi(2)).sum::<f64>())
        .sum::<f64>()
        / n
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn welford_matches_two_pass(
        xs in prop::collection::vec(-1e6f64..1e6, 2..200),
        offset in -1e9f64..1e9,
        split in 0usize..200,
    ) {
        let xs: Vec<f64> = xs.iter().map(|x| x + offset).collect();
        let (mean, var) = two_pass(&xs);
        let w: Welford = xs.iter().copied().collect();
        prop_assert_eq!(w.count(), xs.len() as u64);
        prop_assert!(close(w.mean(), mean, 1e-12, 1e-9));
        prop_assert!(close(w.variance(), var, 1e-6, 1e-6), "{} vs {}", w.variance(), var);
        // Merging two halves equals pushing everything.
        let k = split.min(xs.len());
        let mut a: Welford = xs[..k].iter().copied().collect();
        let b: Welford = xs[k..].iter().copied().collect();
        a.merge(&b);
        prop_assert_eq!(a.count(), w.count());
        prop_assert!(close(a.mean(), w.mean(), 1e-12, 1e-9));
        prop_assert!(close(a.variance(), w.variance(), 1e-6, 1e-6));
        prop_assert_eq!(a.min(), xs.iter().copied().fold(f64::INFINITY, f64::min));
        prop_assert_eq!(a.max(), xs.iter().copied().fold(f64::NEG_INFINITY, f64::max));
    }

    #[test]
    fn int_histogram_matches_counting(values in prop::collection::vec(0u64..50, 0..300)) {
        let mut h = IntHistogram::new();
        for &v in &values { h.add(v); }
        prop_assert_eq!(h.total(), values.len() as u64);
        for v in 0..60 {
            prop_assert_eq!(h.count(v), values.iter().filter(|&&x| x == v).count() as u64);
        }
        prop_assert_eq!(h.max_value(), values.iter().copied().max());
        let mut merged = IntHistogram::new();
        merged.merge(&h);
        merged.merge(&h);
        prop_assert_eq!(merged.total(), 2 * h.total());
    }

    #[test]
    fn log_histogram_bins_contain_their_values(
        values in prop::collection::vec(1e-3f64..1e9, 1..100),
        min in 1e-2f64..10.0,
        bpd in 1u32..12,
    ) {
        let mut h = LogHistogram::new(min, bpd).unwrap();
        for &v in &values { h.add(v).unwrap(); }
        prop_assert_eq!(h.underflow(), values.iter().filter(|&&v| v < min).count() as u64);
        for &v in &values {
            if let Some(i) = h.bin_of(v) {
                let (lo, hi) = h.bin_edges(i);
                prop_assert!(lo <= v && v < hi, "{} not in [{}, {})", v, lo, hi);
            }
        }
        let in_bins: u64 = h.iter().map(|(_, _, c, _)| c).sum();
        prop_assert_eq!(in_bins + h.underflow(), values.len() as u64);
        // Densities integrate to the fraction not in underflow.
        let mass: f64 = h.iter().map(|(lo, hi, _, dens)| dens * (hi - lo)).sum();
        prop_assert!(close(mass, in_bins as f64 / values.len() as f64, 1e-12, 1e-12));
    }

    #[test]
    fn linear_fit_matches_normal_equations(
        pts in prop::collection::vec((-1e3f64..1e3, -1e3f64..1e3), 3..60),
    ) {
        let x: Vec<f64> = pts.iter().map(|p| p.0).collect();
        let y: Vec<f64> = pts.iter().map(|p| p.1).collect();
        let n = x.len() as f64;
        let (sx, sy) = (x.iter().sum::<f64>(), y.iter().sum::<f64>());
        let sxx: f64 = x.iter().map(|v| v * v).sum();
        let sxy: f64 = x.iter().zip(&y).map(|(a, b)| a * b).sum();
        let det = n * sxx - sx * sx;
        prop_assume!(det.abs() > 1e-3 * n * sxx.max(1.0));
        let slope = (n * sxy - sx * sy) / det;
        let intercept = (sy - slope * sx) / n;
        let ssr: f64 = x.iter().zip(&y).map(|(a, b)| (b - slope * a - intercept).powi(2)).sum();
        let s2 = ssr / (n - 2.0);
        let se_slope = (n * s2 / det).sqrt();
        let se_intercept = (s2 * sxx / det).sqrt();
        let f = Fit::linear(&x, &y).unwrap();
        prop_assert!(close(f.slope, slope, 1e-8, 1e-10));
        prop_assert!(close(f.intercept, intercept, 1e-8, 1e-8));
        prop_assert!(close(f.slope_stderr, se_slope, 1e-6, 1e-10));
        prop_assert!(close(f.intercept_stderr, se_intercept, 1e-6, 1e-8));
        prop_assert!((0.0..=1.0).contains(&f.r2));
    }

    #[test]
    fn log_log_fit_recovers_power_laws(
        slope in -3.0f64..3.0,
        prefactor in 1e-3f64..1e3,
        xs in prop::collection::btree_set(1u32..100_000, 3..40),
    ) {
        let x: Vec<f64> = xs.iter().map(|&v| f64::from(v)).collect();
        let y: Vec<f64> = x.iter().map(|v| prefactor * v.powf(slope)).collect();
        let f = Fit::log_log(&x, &y).unwrap();
        prop_assert!((f.slope - slope).abs() < 1e-9);
        prop_assert!(close(f.prefactor(), prefactor, 1e-8, 0.0));
        prop_assert!(f.slope_stderr < 1e-8);
    }

    #[test]
    fn gyration_matches_two_pass(
        pts in prop::collection::vec(prop::array::uniform3(-1e3f64..1e3), 1..200),
        shift in prop::array::uniform3(-1e6f64..1e6),
        split in 0usize..200,
    ) {
        let pts: Vec<[f64; 3]> = pts.iter().map(|p| [p[0] + shift[0], p[1] + shift[1], p[2] + shift[2]]).collect();
        let reference = rg2_two_pass(&pts);
        let mut g = Gyration::<3>::new();
        pts.iter().for_each(|p| g.push(p));
        prop_assert!(close(g.radius_squared(), reference, 1e-7, 1e-9), "{} vs {}", g.radius_squared(), reference);
        let k = split.min(pts.len());
        let mut a = Gyration::<3>::new();
        let mut b = Gyration::<3>::new();
        pts[..k].iter().for_each(|p| a.push(p));
        pts[k..].iter().for_each(|p| b.push(p));
        a.merge(&b);
        prop_assert_eq!(a.count(), pts.len() as u64);
        prop_assert!(close(a.radius_squared(), reference, 1e-7, 1e-9));
    }

    #[test]
    fn lattice_gyration_is_exact(
        pts in prop::collection::vec(prop::collection::vec(-1_000_000i64..1_000_000, 4), 1..100),
        shift in -(1i64 << 39)..(1i64 << 39),
    ) {
        let pts: Vec<Vec<i64>> = pts.iter().map(|p| p.iter().map(|x| x / 1000 + shift).collect()).collect();
        // Exact rational reference: N^2 Rg^2 = N sum |x|^2 - |sum x|^2, in i128 with the shift
        // removed first (which leaves Rg unchanged) so nothing overflows.
        let n = pts.len() as i128;
        let mut num = 0i128;
        for a in 0..4 {
            let col: Vec<i128> = pts.iter().map(|p| i128::from(p[a] - shift)).collect();
            let s: i128 = col.iter().sum();
            let s2: i128 = col.iter().map(|v| v * v).sum();
            num += n * s2 - s * s;
        }
        let reference = num as f64 / (n * n) as f64;
        let mut g = LatticeGyration::new(4);
        pts.iter().for_each(|p| g.push(p));
        prop_assert!(close(g.radius_squared(), reference, 1e-14, 1e-12), "{} vs {}", g.radius_squared(), reference);
    }
}

/// Relative error of the accumulator against an accurate two-pass reference, for `n` points
/// uniform in a disc of radius `radius` centred at `(shift, -shift)`.
fn far_from_origin_error(n: usize, shift: f64, radius: f64, seed: u64) -> f64 {
    let centre = [shift, -shift];
    let mut rng = stream(seed, 0);
    let mut pts = Vec::with_capacity(n);
    for _ in 0..n {
        let u: [f64; 2] = unit_vector::<2, _>(&mut rng);
        let r = radius * uniform01(&mut rng).sqrt();
        pts.push([centre[0] + r * u[0], centre[1] + r * u[1]]);
    }
    let mut g = Gyration::<2>::new();
    pts.iter().for_each(|p| g.push(p));
    assert_eq!(g.count(), n as u64);

    // Reference: two passes over the coordinates relative to the known centre (the differences
    // are exact, so nothing cancels), with Neumaier-compensated sums.
    let neumaier = |it: &mut dyn Iterator<Item = f64>| {
        let (mut s, mut c) = (0.0f64, 0.0f64);
        for x in it {
            let t = s + x;
            c += if s.abs() >= x.abs() {
                (s - t) + x
            } else {
                (x - t) + s
            };
            s = t;
        }
        s + c
    };
    let nf = n as f64;
    let mean: Vec<f64> = (0..2)
        .map(|a| neumaier(&mut pts.iter().map(|p| p[a] - centre[a])) / nf)
        .collect();
    let reference = neumaier(&mut pts.iter().map(|p| {
        (0..2)
            .map(|a| (p[a] - centre[a] - mean[a]).powi(2))
            .sum::<f64>()
    })) / nf;
    (g.radius_squared() - reference).abs() / reference
}

/// The variable-precision paper measures R_g of clusters of up to 1e10 particles; the accumulator
/// must not lose precision to a cluster's distance from the origin.
///
/// The required case: 1e7 points spread over a radius of 1e4, shifted 1e6 from the origin,
/// relative error <= 1e-9. The naive `sum x^2 / N - mean^2` is borderline there (about 4e-9 on
/// some seeds, below 1e-9 on others), so a second case with a larger shift relative to the
/// spread (1e8 and 1e2, where the naive formula is off by tens of percent) makes sure the test
/// fails for any accumulator with that cancellation.
#[test]
fn gyration_far_from_origin() {
    let rel = far_from_origin_error(10_000_000, 1e6, 1e4, 2024);
    assert!(rel <= 1e-9, "shift 1e6, radius 1e4: relative error {rel:e}");
    let rel = far_from_origin_error(2_000_000, 1e8, 1e2, 7);
    assert!(rel <= 1e-9, "shift 1e8, radius 1e2: relative error {rel:e}");
}
