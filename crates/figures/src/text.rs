//! Text of charts ([`crate::chart`]) and figures ([`crate`]) : the
//! DejaVu Sans font committed under `crates/figures/assets/fonts/`, registered with plotters'
//! `ab_glyph` backend so that no system font library is needed, and short tick labels.

use plotters::prelude::*;
use std::sync::Once;

/// The font file committed with the repository (Bitstream Vera licence, see
/// `crates/figures/assets/fonts/DejaVu-LICENSE.txt`).
static FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");

/// Registers the committed font as `sans-serif` with plotters (once).
pub(crate) fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
            .map_err(|_| ())
            .expect("the committed DejaVu Sans font parses");
    });
}

/// A short tick label: `0.05`, `10`, `2.5e-6`.
pub(crate) fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e5).contains(&a) {
        format!("{v:.1e}").replace(".0e", "e")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels() {
        assert_eq!(tick(10.0), "10");
        assert_eq!(tick(0.05), "0.05");
        assert_eq!(tick(9.99999999e-6), "1e-5");
        assert_eq!(tick(2.5e-6), "2.5e-6");
        assert_eq!(tick(1e6), "1e6");
    }
}
