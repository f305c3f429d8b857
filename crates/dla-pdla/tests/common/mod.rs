//! Helpers shared by the integration tests of whole runs (`growth.rs`, `stress.rs`).

/// Brute force: no two centres closer than 1 - 1e-6; every particle after the first within
/// 1 + 1e-6 of an earlier one. Returns (min pair distance, max contact distance).
pub fn check_contacts<const D: usize>(pos: &[[f64; D]]) -> (f64, f64) {
    let mut min_pair = f64::INFINITY;
    let mut max_contact: f64 = 0.0;
    for i in 1..pos.len() {
        let mut nearest_earlier = f64::INFINITY;
        for j in 0..i {
            let d2: f64 = (0..D).map(|a| (pos[i][a] - pos[j][a]).powi(2)).sum();
            nearest_earlier = nearest_earlier.min(d2);
        }
        let d = nearest_earlier.sqrt();
        min_pair = min_pair.min(d);
        max_contact = max_contact.max(d);
    }
    (min_pair, max_contact)
}
