//! The `--seeds` list: `1..=80`, `1..81`, `3,5,9`, or a mix such as `1..=4,10,20..=22`. Each
//! number may be written as any count (`1..=1e3`, `1_000`). A range written as in prose,
//! `1-10`, is refused with its `1..=10` form rather than guessed at: whether `1-10` includes 10
//! is a convention, and the run's recorded command line should not depend on one.

/// Most members one ensemble accepts.
pub const MAX_MEMBERS: usize = 1_000_000;

/// The seeds of an ensemble, in the order given, without repeats.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Seeds(pub Vec<u64>);

/// Parses a seed list; the error names the offending item.
pub fn parse_seeds(s: &str) -> Result<Vec<u64>, String> {
    let mut out = Vec::new();
    let num = |t: &str| {
        run_io::count::count::<u64>(t.trim())
            .map_err(|_| format!("`{}` is not a seed (a whole number >= 0)", t.trim()))
    };
    for item in s.split(',') {
        let item = item.trim();
        if item.is_empty() {
            return Err(format!(
                "`{s}` has an empty item; expected e.g. 1..=80 or 3,5,9"
            ));
        }
        if let Some((a, b)) = run_io::count::dash_range(item) {
            return Err(format!(
                "`{item}` is not a seed range; write {a}..={b} for seeds {a} to {b} \
                 ({a}..{b} leaves out {b})"
            ));
        }
        let (lo, hi) = if let Some((a, b)) = item.split_once("..=") {
            (num(a)?, num(b)?)
        } else if let Some((a, b)) = item.split_once("..") {
            let b = num(b)?;
            if b == 0 {
                return Err(format!("`{item}` is empty"));
            }
            (num(a)?, b - 1)
        } else {
            let v = num(item)?;
            (v, v)
        };
        if lo > hi {
            return Err(format!("`{item}` is empty (the range runs backwards)"));
        }
        if hi - lo >= MAX_MEMBERS as u64 || out.len() + (hi - lo) as usize >= MAX_MEMBERS {
            return Err(format!("`{s}` has more than {MAX_MEMBERS} seeds"));
        }
        out.extend(lo..=hi);
    }
    let mut seen = std::collections::HashSet::new();
    if let Some(d) = out.iter().find(|v| !seen.insert(**v)) {
        return Err(format!("seed {d} appears twice in `{s}`"));
    }
    Ok(out)
}

/// [`parse_seeds`] for clap.
pub(super) fn parse_seeds_arg(s: &str) -> Result<Seeds, String> {
    parse_seeds(s).map(Seeds)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_ranges_and_mixes() {
        assert_eq!(parse_seeds("1..=4").unwrap(), vec![1, 2, 3, 4]);
        assert_eq!(parse_seeds("1..4").unwrap(), vec![1, 2, 3]);
        assert_eq!(parse_seeds("3,5, 9").unwrap(), vec![3, 5, 9]);
        assert_eq!(
            parse_seeds("1..=2,10,20..22").unwrap(),
            vec![1, 2, 10, 20, 21]
        );
        assert_eq!(parse_seeds("7").unwrap(), vec![7]);
        assert_eq!(parse_seeds("1..=1e3").unwrap().len(), 1000);
        assert_eq!(parse_seeds("1_000,2e3").unwrap(), vec![1000, 2000]);
    }

    #[test]
    fn bad_lists_name_the_item() {
        for (bad, says) in [
            ("", "empty item"),
            ("1,,2", "empty item"),
            ("5..=1", "backwards"),
            ("3..3", "backwards"),
            ("0..0", "empty"),
            ("a..=3", "`a`"),
            ("1,2,1", "seed 1 appears twice"),
            ("1..=2000000", "more than"),
            ("-1", "`-1`"),
            ("1-10", "write 1..=10 for seeds 1 to 10"),
            ("3,1-10", "write 1..=10"),
            ("1.5", "`1.5`"),
        ] {
            let e = parse_seeds(bad).unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }
}
