//! Byte counts as flags take them (`--max-memory 4G`) and as messages print them (`4.0 GiB`).

/// A byte count, with an optional suffix K, M, G or T (powers of 1024): `4G`, `500M`, `1024`.
pub fn parse_bytes(s: &str) -> Result<u64, String> {
    let (digits, mult) = match s.trim().chars().last() {
        Some('K' | 'k') => (&s[..s.len() - 1], 1u64 << 10),
        Some('M' | 'm') => (&s[..s.len() - 1], 1 << 20),
        Some('G' | 'g') => (&s[..s.len() - 1], 1 << 30),
        Some('T' | 't') => (&s[..s.len() - 1], 1 << 40),
        _ => (s, 1),
    };
    digits
        .trim()
        .parse::<u64>()
        .ok()
        .and_then(|v| v.checked_mul(mult))
        .ok_or_else(|| format!("'{s}' is not a byte count like 4G or 500M"))
}

/// `bytes` in the largest binary unit that keeps a leading digit: `512 B`, `1.5 KiB`,
/// `4.0 GiB`, up to EiB.
pub fn show_bytes(bytes: u64) -> String {
    const UNITS: [&str; 6] = ["KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    if bytes < 1024 {
        return format!("{bytes} B");
    }
    let mut v = bytes as f64 / 1024.0;
    let mut unit = 0;
    while v >= 1024.0 && unit + 1 < UNITS.len() {
        v /= 1024.0;
        unit += 1;
    }
    format!("{v:.1} {}", UNITS[unit])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_counts_parse_and_print() {
        assert_eq!(parse_bytes("4G"), Ok(4 << 30));
        assert_eq!(parse_bytes("500"), Ok(500));
        assert_eq!(parse_bytes("2t"), Ok(2 << 40));
        assert!(
            parse_bytes("lots")
                .unwrap_err()
                .contains("is not a byte count")
        );
        assert!(parse_bytes("99999999999T").is_err());
        assert_eq!(show_bytes(512), "512 B");
        assert_eq!(show_bytes(1536), "1.5 KiB");
        assert_eq!(show_bytes(4 << 30), "4.0 GiB");
        assert_eq!(show_bytes(u64::MAX), "16.0 EiB");
    }
}
