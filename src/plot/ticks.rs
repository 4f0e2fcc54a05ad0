//! Axis ticks and their labels: where a linear or a logarithmic axis puts its ticks, and how
//! a tick's value is written (plainly, or as a power of ten when an axis would mix notations),
//! and the SI prefix that shows a magnitude with one to three digits ([`prefixed`]).
//!
//! Must not import report, study, friction, contact or shs: ticks know only numbers.

/// Ticks for a log axis from `lo` to `hi`: decades, or 1-2-5 or 1…9 per decade when the range
/// is short, or evenly spaced round values when it spans less than one decade.
pub(super) fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    const MANTISSAS: [&[f64]; 3] = [&[1.0], &[1.0, 2.0, 5.0], &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]];
    let (d0, d1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    for mantissas in MANTISSAS {
        let ticks: Vec<f64> = (d0..=d1)
            .flat_map(|d| mantissas.iter().map(move |m| m * 10f64.powi(d)))
            .filter(|v| (lo..=hi).contains(v))
            .collect();
        if ticks.len() >= 3 {
            // Keep at most about a dozen labels on very wide ranges.
            let every = ticks.len().div_ceil(12);
            return ticks.into_iter().step_by(every).collect();
        }
    }
    linear_ticks(lo, hi)
}

/// About six round-valued ticks (steps of 1, 2 or 5 × 10^k) between `lo` and `hi`.
pub(super) fn linear_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let k0 = (hi - lo).log10().floor() as i32;
    let count = |step: f64| (hi / step).floor() - (lo / step).ceil() + 1.0;
    let step = (k0 - 2..=k0)
        .flat_map(|k| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(k)))
        .min_by(|a, b| (count(*a) - 6.0).abs().total_cmp(&(count(*b) - 6.0).abs()))
        .expect("candidate steps");
    let (first, last) = ((lo / step).ceil() as i64, (hi / step).floor() as i64);
    (first..=last).map(|k| k as f64 * step).collect()
}

/// Tick labels with at most four significant digits, in scientific notation for very large or
/// very small magnitudes ("0.3", "250", "1e-4", "2.5e6").
pub fn tick_label(v: &f64) -> String {
    let v = *v;
    if v == 0.0 || !v.is_finite() {
        return if v == 0.0 { "0".into() } else { v.to_string() };
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        let s = format!("{v:.3e}");
        let (mantissa, exp) = s.split_once('e').expect("{:e} output has an exponent");
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        return format!("{mantissa}e{exp}");
    }
    let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Whether the plain labels of `ticks` mix notations ("1e-4" beside "0.001").
pub(super) fn mixed_notation(ticks: &[f64]) -> bool {
    let scientific = ticks.iter().filter(|t| tick_label(t).contains('e')).count();
    scientific > 0 && scientific < ticks.len()
}

/// A tick label as a power of ten with a superscript exponent: "10⁻⁴", "2×10⁻³", "10²".
pub(super) fn power_label(v: &f64) -> String {
    let v = *v;
    if v == 0.0 || !v.is_finite() {
        return tick_label(&v);
    }
    let mut e = v.abs().log10().floor() as i32;
    let mut m = ((v / 10f64.powi(e)) * 1e3).round() / 1e3;
    if m.abs() >= 10.0 {
        (e, m) = (e + 1, m / 10.0);
    }
    const DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let exponent: String = e.to_string().chars().map(|c| c.to_digit(10).map_or('⁻', |d| DIGITS[d as usize])).collect();
    if m == 1.0 {
        format!("10{exponent}")
    } else {
        format!("{}×10{exponent}", tick_label(&m))
    }
}

/// The SI prefix that shows values up to `magnitude` (in `unit`) with one to three digits
/// before the decimal point: returns the factor to multiply values by and the prefixed unit,
/// e.g. `(1e3, "mN")` for 0.024 N.
pub fn prefixed(magnitude: f64, unit: &str) -> (f64, String) {
    const PREFIXES: [(f64, &str); 8] =
        [(1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n"), (1e-12, "p")];
    let m = magnitude.abs();
    if !m.is_normal() {
        return (1.0, unit.to_string());
    }
    let &(p, name) = PREFIXES.iter().find(|(p, _)| m >= *p * (1.0 - 1e-12)).unwrap_or(&PREFIXES[PREFIXES.len() - 1]);
    (1.0 / p, format!("{name}{unit}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_short() {
        let cases = [
            (0.0, "0"),
            (0.30000000000000004, "0.3"),
            (250.0, "250"),
            (1.5, "1.5"),
            (-2.0, "-2"),
            (12345.0, "12345"),
            (1e-4, "1e-4"),
            (2.5e6, "2.5e6"),
            (0.0125, "0.0125"),
        ];
        for (v, s) in cases {
            assert_eq!(tick_label(&v), s, "{v}");
        }
    }

    #[test]
    fn prefixes() {
        assert_eq!(prefixed(0.024, "N"), (1e3, "mN".to_string()));
        assert_eq!(prefixed(2.4e-5, "N"), (1e6, "µN".to_string()));
        assert_eq!(prefixed(1.0, "m"), (1.0, "m".to_string()));
        assert_eq!(prefixed(3.2e9, "Pa"), (1e-9, "GPa".to_string()));
        assert_eq!(prefixed(0.0, "N"), (1.0, "N".to_string()));
    }

    /// Fig. 2's loads read "1e-4, 0.001, 0.01 … 100": one axis in two notations.
    #[test]
    fn log_ticks_are_written_one_way() {
        let loads = log_ticks(6e-5, 150.0);
        assert!(mixed_notation(&loads), "{loads:?}");
        let labels: Vec<String> = loads.iter().map(power_label).collect();
        assert_eq!(labels, ["10⁻⁴", "10⁻³", "10⁻²", "10⁻¹", "10⁰", "10¹", "10²"]);
        assert_eq!(power_label(&2e-3), "2×10⁻³");
        assert_eq!(power_label(&-5e4), "-5×10⁴");
        // Hold times of 1 s to 10⁴ s read plainly: no change there.
        assert!(!mixed_notation(&log_ticks(0.8, 1.2e4)));
    }

    #[test]
    fn log_ticks_adapt_to_the_range() {
        assert_eq!(log_ticks(5e-5, 2.0), vec![1e-4, 1e-3, 1e-2, 1e-1, 1.0]);
        assert_eq!(log_ticks(0.8, 12.0), vec![1.0, 2.0, 5.0, 10.0]);
        let short = log_ticks(1.15, 2.25);
        assert_eq!(short.len(), 6, "{short:?}");
        assert!((short[0] - 1.2).abs() < 1e-12 && (short[5] - 2.2).abs() < 1e-12, "{short:?}");
        let wide = log_ticks(1e-30, 1e30).len();
        assert!((10..=12).contains(&wide), "{wide} ticks over 60 decades");
    }
}
