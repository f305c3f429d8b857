//! Rounding to integers without a library call: on baseline x86-64 (no SSE4.1) `f64::floor`
//! and `f64::ceil` are calls into libm, which the hot loops of the orthtree and the distance
//! maps cannot afford.

/// `x.floor()` for finite `x` inside the `i64` range (values beyond it saturate, which every
/// caller clamps or excludes).
#[inline(always)]
pub(crate) fn floor(x: f64) -> f64 {
    let t = x as i64 as f64;
    if t > x { t - 1.0 } else { t }
}

/// `x.ceil()`, likewise.
#[inline(always)]
pub(crate) fn ceil(x: f64) -> f64 {
    -floor(-x)
}

#[cfg(test)]
mod tests {
    use super::*;

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
        }
    }
}
