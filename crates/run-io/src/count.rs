//! Counts as physicists write them: `1000000`, `1_000_000`, `1e6`, `2.5e5`, `1E6`. Only exact
//! whole numbers are counts: `1.5` and `2.5e-1` are refused as not whole, `1e30` as too large
//! for the count's type, negative numbers as negative. The value's own range (at least one
//! particle, say) is the model's validation, which names the flag and the range.

/// Parses a count written as digits (with `_` between digits allowed), or as a decimal with an
/// exponent (`1e6`, `2.5e5`, `1.25E+3`), exactly: no floating point is involved, so every
/// whole number up to the type's maximum is accepted exactly and nothing else is.
///
/// # Errors
/// A message saying why `s` is not a count of type `T` (for clap's `invalid value ... for
/// '--flag'` line).
pub fn count<T: TryFrom<u128>>(s: &str) -> Result<T, String> {
    let t = s.trim();
    let too_large = || format!("{t} is too large for a count here (at most {})", max::<T>());
    if t.starts_with('-') {
        return Err(format!(
            "{t} is negative; a count is a whole number of 0 or more"
        ));
    }
    let t_plus = t.strip_prefix('+').unwrap_or(t);
    let (mantissa, exponent) = match t_plus.find(['e', 'E']) {
        Some(i) => (&t_plus[..i], Some(&t_plus[i + 1..])),
        None => (t_plus, None),
    };
    let (whole, frac) = match mantissa.split_once('.') {
        Some((w, f)) => (w, f),
        None => (mantissa, ""),
    };
    let digits_ok = |d: &str| {
        !d.starts_with('_')
            && !d.ends_with('_')
            && !d.contains("__")
            && d.chars().all(|c| c.is_ascii_digit() || c == '_')
    };
    if (whole.is_empty() && frac.is_empty()) || !digits_ok(whole) || !digits_ok(frac) {
        return Err(format!(
            "{t} is not a count: write digits (1000000, 1_000_000) or a decimal with an \
             exponent (1e6, 2.5e5)"
        ));
    }
    let exp: i64 = match exponent {
        None => 0,
        Some(e) => e
            .strip_prefix('+')
            .unwrap_or(e)
            .parse()
            .ok()
            .filter(|x: &i64| x.abs() <= 1000)
            .ok_or_else(|| format!("{t} is not a count: the exponent must be a whole number"))?,
    };
    // value = (whole.frac digits as an integer) * 10^(exp - frac digits)
    let digits: String = whole
        .chars()
        .chain(frac.chars())
        .filter(|c| *c != '_')
        .collect();
    let digits = digits.trim_start_matches('0');
    let frac_len = frac.chars().filter(|c| *c != '_').count() as i64;
    let mut scale = exp - frac_len;
    // Trailing zeros of the digits can pay for a negative scale.
    let mut digits = digits.to_string();
    while scale < 0 && digits.ends_with('0') {
        digits.pop();
        scale += 1;
    }
    if digits.is_empty() {
        return T::try_from(0).map_err(|_| too_large());
    }
    if scale < 0 {
        return Err(format!("{t} is not a whole number; a count is"));
    }
    if digits.len() as i64 + scale > 39 {
        return Err(too_large());
    }
    let mut value: u128 = digits.parse().map_err(|_| too_large())?;
    for _ in 0..scale {
        value = value.checked_mul(10).ok_or_else(too_large)?;
    }
    T::try_from(value).map_err(|_| too_large())
}

/// [`count`] for a count of at least one (`--checkpoint-every N`, `--jobs J`): 0 is refused
/// with the range.
///
/// # Errors
/// As [`count`], and `0 is outside the accepted range 1..` for zero.
pub fn count_at_least_1<T: TryFrom<u128> + PartialEq + Default>(s: &str) -> Result<T, String> {
    let v = count::<T>(s)?;
    if v == T::default() {
        return Err(format!("{} is outside the accepted range 1..", s.trim()));
    }
    Ok(v)
}

/// A seed (`--seed`): a whole number in any notation [`count`] accepts. A list or range of
/// seeds (`1..=10`, `1-10`, `3,5`) is refused with the `--seeds` flag that runs one member per
/// seed, in its own syntax.
///
/// # Errors
/// Why `s` is not one seed, with the `--seeds` form of a list or range.
pub fn seed(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let hint = |list: &str| {
        format!(
            "`{t}` is several seeds, --seed takes one; for one run per seed (an ensemble) use              --seeds {list}"
        )
    };
    if t.contains("..") || t.contains(',') {
        return Err(hint(t));
    }
    if let Some((a, b)) = dash_range(t) {
        return Err(hint(&format!("{a}..={b}")));
    }
    count::<u64>(t).map_err(|e| format!("{e} (a seed is a whole number >= 0)"))
}

/// `a-b` with both ends whole numbers (`1-10`): the ends, as a user writes a range in prose.
pub fn dash_range(t: &str) -> Option<(&str, &str)> {
    let (a, b) = t.split_once('-')?;
    let (a, b) = (a.trim(), b.trim());
    (count::<u64>(a).is_ok() && count::<u64>(b).is_ok() && !a.is_empty()).then_some((a, b))
}

/// The largest value of `T` (found by bisection over what `T::try_from` accepts), for messages.
fn max<T: TryFrom<u128>>() -> u128 {
    let (mut lo, mut hi) = (0u128, u128::MAX);
    while lo < hi {
        let mid = lo + (hi - lo).div_ceil(2);
        if T::try_from(mid).is_ok() {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    lo
}

#[cfg(test)]
mod tests {
    use super::{count, count_at_least_1, seed};

    #[test]
    fn counts_of_at_least_one_refuse_zero_with_the_range() {
        assert_eq!(count_at_least_1::<u64>("1e3"), Ok(1000));
        assert_eq!(count_at_least_1::<u64>("1"), Ok(1));
        for z in ["0", "0e5", "0.0"] {
            let e = count_at_least_1::<u64>(z).unwrap_err();
            assert!(e.contains("outside the accepted range 1.."), "{z}: {e}");
        }
        assert!(
            count_at_least_1::<u64>("1.5")
                .unwrap_err()
                .contains("not a whole number")
        );
    }

    #[test]
    fn a_seed_is_one_whole_number_and_a_list_points_to_seeds() {
        assert_eq!(seed("7"), Ok(7));
        assert_eq!(seed("1e3"), Ok(1000));
        assert_eq!(seed("1_000"), Ok(1000));
        for (s, hint) in [
            ("1..=10", "--seeds 1..=10"),
            ("1..11", "--seeds 1..11"),
            ("3,5,9", "--seeds 3,5,9"),
            ("1-10", "--seeds 1..=10"),
            ("1 - 10", "--seeds 1..=10"),
        ] {
            let e = seed(s).unwrap_err();
            assert!(e.contains(hint) && e.contains("several seeds"), "{s}: {e}");
        }
        for s in ["1.5", "-3", "x", "1e30"] {
            let e = seed(s).unwrap_err();
            assert!(!e.contains("--seeds"), "{s}: {e}");
        }
    }

    #[test]
    fn accepts_counts_in_every_notation() {
        for (s, v) in [
            ("1000000", 1_000_000u64),
            ("1_000_000", 1_000_000),
            ("1e6", 1_000_000),
            ("1E6", 1_000_000),
            ("1e+6", 1_000_000),
            ("+20", 20),
            ("2.5e5", 250_000),
            ("2.50e5", 250_000),
            ("0.5e1", 5),
            ("1.0", 1),
            ("10e-1", 1),
            ("100e-2", 1),
            ("0", 0),
            ("0e0", 0),
            ("007", 7),
            ("18446744073709551615", u64::MAX),
            ("1.8446744073709551615e19", u64::MAX),
        ] {
            assert_eq!(count::<u64>(s), Ok(v), "{s}");
        }
        assert_eq!(count::<u32>("4.294967295e9"), Ok(u32::MAX));
    }

    #[test]
    fn refuses_what_is_not_an_exact_whole_count() {
        for (s, why) in [
            ("1.5", "not a whole number"),
            ("2.5e-1", "not a whole number"),
            ("1e-6", "not a whole number"),
            ("1e30", "too large"),
            ("18446744073709551616", "too large"),
            ("1e400", "too large"),
            ("-3", "negative"),
            ("", "not a count"),
            ("e6", "not a count"),
            ("1_", "not a count"),
            ("_1", "not a count"),
            ("1__0", "not a count"),
            ("1e", "exponent"),
            ("1e6.5", "exponent"),
            ("0x10", "not a count"),
            ("1,000", "not a count"),
            ("inf", "not a count"),
            ("NaN", "not a count"),
            ("1e99999999999", "exponent"),
        ] {
            let e = count::<u64>(s).unwrap_err();
            assert!(e.contains(why), "{s}: {e}");
        }
        let e = count::<u32>("5e9").unwrap_err();
        assert!(e.contains("at most 4294967295"), "{e}");
    }
}
