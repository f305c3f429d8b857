//! Unit tests of the statistics against worked examples and exact values.

use super::*;

#[test]
fn welford_basics() {
    let w: Welford = [2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]
        .into_iter()
        .collect();
    assert_eq!(w.count(), 8);
    assert!((w.mean() - 5.0).abs() < 1e-15);
    assert!((w.population_variance() - 4.0).abs() < 1e-15);
    assert!((w.variance() - 32.0 / 7.0).abs() < 1e-14);
    assert_eq!((w.min(), w.max()), (2.0, 9.0));
    assert!(Welford::new().mean().is_nan());
}

#[test]
fn fit_recovers_exact_power_law() {
    let x: Vec<f64> = (1..=20).map(|i| i as f64 * 10.0).collect();
    let y: Vec<f64> = x.iter().map(|x| 3.5 * x.powf(1.71)).collect();
    let f = Fit::log_log(&x, &y).unwrap();
    assert!((f.slope - 1.71).abs() < 1e-12);
    assert!((f.prefactor() - 3.5).abs() < 1e-10);
    assert!(f.slope_stderr < 1e-12);
    assert!((f.r2 - 1.0).abs() < 1e-12);
    assert_eq!(f.n, 20);
}

#[test]
fn fit_standard_errors_match_textbook() {
    // Worked example: x = 1..5, y = 2, 4, 5, 4, 5 -> slope 0.6, intercept 2.2,
    // SSR = 2.4, s^2 = 0.8, Sxx = 10: se(slope) = sqrt(0.08), se(intercept) = sqrt(0.8*(1/5+9/10)).
    let f = Fit::linear(&[1., 2., 3., 4., 5.], &[2., 4., 5., 4., 5.]).unwrap();
    assert!((f.slope - 0.6).abs() < 1e-14);
    assert!((f.intercept - 2.2).abs() < 1e-14);
    assert!((f.slope_stderr - 0.08f64.sqrt()).abs() < 1e-14);
    assert!((f.intercept_stderr - (0.8f64 * 1.1).sqrt()).abs() < 1e-14);
    assert!((f.r2 - 0.6).abs() < 1e-14); // SST = 6
}

#[test]
fn predict_and_prefactor_follow_the_axes() {
    let x = [1.0, 2.0, 4.0, 8.0];
    let lin = Fit::linear(&x, &[3.0, 5.0, 9.0, 17.0]).unwrap();
    assert_eq!(lin.scale, FitScale::Linear);
    assert!((lin.predict(16.0) - 33.0).abs() < 1e-12);
    assert!((lin.prefactor() - 1.0).abs() < 1e-12);
    let pow = Fit::log_log(&x, &[3.0, 12.0, 48.0, 192.0]).unwrap();
    assert_eq!(pow.scale, FitScale::LogLog);
    assert!((pow.predict(16.0) - 768.0).abs() < 1e-9);
    assert!((pow.prefactor() - 3.0).abs() < 1e-12);
    // The same points on log axes give the same line as the linear fit of the logarithms.
    let logs = |v: &[f64]| v.iter().map(|a| a.ln()).collect::<Vec<_>>();
    let by_hand = Fit::linear(&logs(&x), &logs(&[3.0, 12.0, 48.0, 192.0])).unwrap();
    assert_eq!(
        (pow.slope, pow.intercept, pow.slope_stderr, pow.r2),
        (
            by_hand.slope,
            by_hand.intercept,
            by_hand.slope_stderr,
            by_hand.r2
        )
    );
}

#[test]
fn fit_refuses_bad_input() {
    assert_eq!(
        Fit::log_log(&[1., 2.], &[1., 2.]),
        Err(StatsError::TooFewPoints(2))
    );
    assert!(matches!(
        Fit::log_log(&[1., 0., 3.], &[1., 2., 3.]),
        Err(StatsError::NonPositive { index: 1, .. })
    ));
    assert!(matches!(
        Fit::log_log(&[1., 2., 3.], &[1., -2., 3.]),
        Err(StatsError::NonPositive { index: 1, .. })
    ));
    assert!(matches!(
        Fit::log_log(&[1., 2., f64::NAN], &[1., 2., 3.]),
        Err(StatsError::NonFinite { index: 2, .. })
    ));
    assert!(matches!(
        Fit::linear(&[2., 2., 2.], &[1., 2., 3.]),
        Err(StatsError::Degenerate(_))
    ));
    assert!(matches!(
        Fit::linear(&[1., 2., 3.], &[1., 2.]),
        Err(StatsError::LengthMismatch { .. })
    ));
}

#[test]
fn int_histogram_counts() {
    let mut h = IntHistogram::new();
    for v in [3, 0, 3, 7, 3] {
        h.add(v);
    }
    assert_eq!(h.count(3), 3);
    assert_eq!(h.count(1), 0);
    assert_eq!(h.count(1000), 0);
    assert_eq!(h.total(), 5);
    assert_eq!(h.max_value(), Some(7));
    assert!((h.mean() - 16.0 / 5.0).abs() < 1e-15);
    assert_eq!(h.iter().collect::<Vec<_>>(), vec![(0, 1), (3, 3), (7, 1)]);
}

#[test]
fn log_histogram_edges() {
    let mut h = LogHistogram::new(1.0, 1).unwrap();
    for x in [0.5, 1.0, 9.999, 10.0, 99.0, 100.0, 1e6] {
        h.add(x).unwrap();
    }
    assert_eq!(h.underflow(), 1);
    assert_eq!(h.count(0), 2); // 1.0 and 9.999
    assert_eq!(h.count(1), 2); // 10 and 99
    assert_eq!(h.count(2), 1); // 100
    assert_eq!(h.count(6), 1);
    assert_eq!(h.total(), 7);
    assert!(h.add(0.0).is_err());
    assert!(h.add(f64::NAN).is_err());
    assert!(LogHistogram::new(0.0, 3).is_err());
    assert!(LogHistogram::new(1.0, 0).is_err());
}

#[test]
fn gyration_of_a_square() {
    let mut g = Gyration::<2>::new();
    for p in [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0], [2.0, 2.0]] {
        g.push(&p);
    }
    assert!((g.radius_squared() - 2.0).abs() < 1e-15);
    assert_eq!(g.centre(), [1.0, 1.0]);
    let mut l = LatticeGyration::new(2);
    for p in [[0, 0], [2, 0], [0, 2], [2, 2]] {
        l.push(&p);
    }
    assert_eq!(l.radius_squared(), 2.0);
    assert_eq!(LatticeGyration::new(3).radius(), 0.0);
}
