//! Helpers shared by the integration tests of whole runs (`growth.rs`, `stress.rs`,
//! `variants.rs`, `connectivity.rs`); each test crate uses some of them.

use dla_pdla::{Dim, Params, Simulation, Space};

/// A finished run of `params` (positions kept) with `seed`.
#[allow(dead_code)]
pub fn grow<const D: usize>(params: Params, seed: u64) -> Simulation<D>
where
    Dim<D>: Space<D>,
{
    let params = Params {
        dim: D,
        keep_positions: true,
        ..params
    };
    let mut sim = Simulation::<D>::new(params, seed).unwrap();
    sim.run().unwrap();
    sim
}

/// How far a stored distance may differ from the exact one: the orthtree stores each
/// coordinate to within `leaf_side / 2^33` (9.3e-10 for the default leaf side 8), so a stored
/// position is within `sqrt(D)` times that of the position computed, plus the rounding of the
/// contact itself (far below 1e-12 at these coordinates): 1.32e-9 in 2D, of which a few
/// thousand particles use up to 1.3e-9, so a tolerance of 1e-9 would fail.
#[allow(dead_code)]
pub fn tolerance<const D: usize>(params: &Params) -> f64 {
    (D as f64).sqrt() * params.leaf_side / 2f64.powi(33) + 1e-12
}

/// Brute force: no two centres closer than 1 - 1e-6; every particle after the first within
/// 1 + 1e-6 of an earlier one. Returns (min pair distance, max contact distance).
#[allow(dead_code)]
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
