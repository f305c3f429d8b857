//! The exact scan of a leaf's points for the nearest one, in independent lanes.

use super::super::decode;
use super::dist_sq;

/// Lanes of the leaf scan: independent running minima, so consecutive points do not wait for
/// each other's comparison (the scan was bound by that dependency chain) and the compiler can
/// keep each lane in a vector register.
const LANES: usize = 4;

/// The smallest squared distance below `best_sq` from `p` to a point of a leaf (origin
/// `origin`), and the index of the first point reaching it (`usize::MAX` if none is below
/// `best_sq`). Each point's squared distance is computed exactly as the scalar loop
/// `sum_i (p_i - decode(origin_i, code_i, step))^2` would, so the result is bit for bit the same
/// as scanning the points one by one; ties go to the lowest index, as in that scan.
#[inline(always)]
pub(super) fn nearest_in_leaf<const D: usize>(
    p: &[f64; D],
    origin: &[f64; D],
    step: f64,
    pts: &[[u32; D]],
    best_sq: f64,
) -> (f64, usize) {
    let mut m = [best_sq; LANES];
    let mut at = [usize::MAX; LANES];
    let chunks = pts.chunks_exact(LANES);
    let tail = chunks.remainder();
    for (c, chunk) in chunks.enumerate() {
        let mut d2 = [0.0f64; LANES];
        for i in 0..D {
            for k in 0..LANES {
                let e = p[i] - decode(origin[i], chunk[k][i], step);
                d2[k] += e * e;
            }
        }
        for k in 0..LANES {
            if d2[k] < m[k] {
                m[k] = d2[k];
                at[k] = c * LANES + k;
            }
        }
    }
    let base = pts.len() - tail.len();
    for (k, code) in tail.iter().enumerate() {
        let d2 = dist_sq(
            p,
            &std::array::from_fn(|i| decode(origin[i], code[i], step)),
        );
        if d2 < m[k] {
            m[k] = d2;
            at[k] = base + k;
        }
    }
    // Combine the lanes: smallest value, then lowest index among equal values.
    let mut best = (best_sq, usize::MAX);
    for k in 0..LANES {
        if m[k] < best.0 || (m[k] == best.0 && at[k] < best.1) {
            best = (m[k], at[k]);
        }
    }
    best
}
