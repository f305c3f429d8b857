//! Rounding to integers without a library call: on baseline x86-64 (no SSE4.1) `f64::floor`
//! and `f64::ceil` are calls into libm, which the hot loops of the orthtree and the distance
//! maps cannot afford. Where the build has SSE4.1 (the workspace's `x86-64-v3` level) or is not
//! x86-64 at all, the standard functions compile to one rounding instruction and are used.

/// Whether `f64::floor` is a library call in this build.
const FLOOR_IS_A_CALL: bool = cfg!(all(target_arch = "x86_64", not(target_feature = "sse4.1")));

/// `x.floor()` for finite `x` inside the `i64` range (values beyond it saturate, which every
/// caller clamps or excludes).
#[inline(always)]
pub(crate) fn floor(x: f64) -> f64 {
    if FLOOR_IS_A_CALL {
        floor_by_cast(x)
    } else {
        x.floor()
    }
}

/// `floor` through a conversion to `i64` and back (two instructions and a compare).
#[inline(always)]
fn floor_by_cast(x: f64) -> f64 {
    let t = x as i64 as f64;
    if t > x { t - 1.0 } else { t }
}

/// `x.ceil()`, likewise.
#[inline(always)]
pub(crate) fn ceil(x: f64) -> f64 {
    if FLOOR_IS_A_CALL {
        -floor(-x)
    } else {
        x.ceil()
    }
}

/// A whole number `x` in `[0, 2^52)` as `usize`, through its bits: `x + 2^52` has `x` in the
/// low bits of its mantissa. Two instructions, where `x as usize` (or through `i64`) adds
/// the saturation of values out of range and NaN; the distance maps' reads, whose indices
/// are whole numbers already tested against the map's side, convert one at every read.
#[inline(always)]
pub(crate) fn whole_to_usize(x: f64) -> usize {
    const MAGIC: f64 = 4_503_599_627_370_496.0; // 2^52
    debug_assert!((0.0..MAGIC).contains(&x) && x.fract() == 0.0, "{x}");
    ((x + MAGIC).to_bits() - MAGIC.to_bits()) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_numbers_convert_exactly() {
        for x in [
            0u64,
            1,
            2,
            255,
            65_535,
            1 << 31,
            (1 << 32) + 7,
            (1 << 52) - 1,
        ] {
            assert_eq!(whole_to_usize(x as f64), x as usize, "{x}");
        }
    }

    #[test]
    fn floor_and_ceil_match_std() {
        for x in [
            -3.5,
            -3.0,
            -0.2,
            -0.0,
            0.0,
            0.7,
            2.0,
            2.5,
            1e12 + 0.5,
            -1e12 - 0.5,
        ] {
            assert_eq!(floor(x), x.floor(), "{x}");
            assert_eq!(ceil(x), x.ceil(), "{x}");
            assert_eq!(floor_by_cast(x), x.floor(), "{x}");
            assert_eq!(-floor_by_cast(-x), x.ceil(), "{x}");
        }
    }
}
