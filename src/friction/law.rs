//! The local friction law of one contact element: it stays stuck while its shear force is
//! below `mu_s · n`, and carries `mu_d · n` once it has slipped.
//!
//! Must not import study, shs, plot or report: friction builds on contact and the base row.

use std::path::Path;

use crate::error::{Error, Result};

/// A local (element-scale) friction law: static and dynamic friction coefficients, both
/// dimensionless, with `0 < mu_d ≤ mu_s`.
#[derive(Debug, Clone, PartialEq)]
pub struct FrictionLaw {
    /// A label, e.g. the AFM hold time the pair was measured at ("hold 100 s").
    pub name: Option<String>,
    /// Static friction coefficient mu_s: the local stress ratio at which an element slips.
    pub mu_s: f64,
    /// Dynamic friction coefficient mu_d: the local stress ratio of a slipped element.
    pub mu_d: f64,
}

/// Named laws for `--law`. ILLUSTRATIVE PLACEHOLDERS, not measurements: the paper (Fig. S5,
/// after Li et al., Nature 480, 233, 2011) uses AFM curves for hold times of 100 s and 10 s
/// but its text states no values. These pairs only keep the paper's ordering (the longer hold
/// has the larger drop); quantitative work must pass measured values (`--mu-s`/`--mu-d` or
/// `--curve`).
pub const PRESETS: &[(&str, f64, f64)] = &[("hold 100 s", 0.6, 0.4), ("hold 10 s", 0.5, 0.4)];

impl FrictionLaw {
    /// A law from its two coefficients; errors name the option (`--mu-s`, `--mu-d`) at fault.
    pub fn new(mu_s: f64, mu_d: f64) -> Result<Self> {
        // A subnormal coefficient has lost its digits, and every force made from it underflows
        // (5e-324 gave F_S = 0 and a friction drop of 0/0).
        if !(mu_d.is_normal() && mu_d > 0.0) {
            return Err(Error::invalid(
                "--mu-d",
                format!(
                    "the dynamic friction coefficient must be positive, finite and at least {:e} (a normal float), got {mu_d:e}",
                    f64::MIN_POSITIVE
                ),
            ));
        }
        if !(mu_s.is_normal() && mu_s > 0.0) {
            return Err(Error::invalid(
                "--mu-s",
                format!(
                    "the static friction coefficient must be positive, finite and at least {:e} (a normal float), got {mu_s:e}",
                    f64::MIN_POSITIVE
                ),
            ));
        }
        if mu_s < mu_d {
            return Err(Error::invalid(
                "--mu-s",
                format!("the static friction coefficient {mu_s} is below the dynamic one {mu_d} (a local law needs mu_s ≥ mu_d)"),
            ));
        }
        if !(mu_s / mu_d).is_finite() {
            return Err(Error::invalid(
                "--mu-s",
                format!(
                    "mu_s / mu_d = {} / {} is past the largest float: the friction drop is not representable",
                    crate::quantity::human(mu_s),
                    crate::quantity::human(mu_d)
                ),
            ));
        }
        Ok(FrictionLaw { name: None, mu_s, mu_d })
    }

    /// The same law with a label.
    pub fn named(mut self, name: impl Into<String>) -> Self {
        self.name = Some(name.into());
        self
    }

    /// A law from the [`PRESETS`] table (illustrative values).
    pub fn preset(name: &str) -> Result<Self> {
        let (label, mu_s, mu_d) = PRESETS.iter().copied().find(|(n, _, _)| *n == name).ok_or_else(|| {
            let known: Vec<_> = PRESETS.iter().map(|(n, _, _)| format!("\"{n}\"")).collect();
            Error::invalid("--law", format!("unknown law \"{name}\" (presets: {})", known.join(", ")))
        })?;
        Ok(FrictionLaw::new(mu_s, mu_d)?.named(label))
    }

    /// The law after a hold of `hold` \[s] for Si–Si contacts that age (AFM, Li et al., Nature
    /// 480, 233, 2011): mu_s(t) = mu_s(t₀) + β·log10(t/t₀), mu_d fixed, where `mu_s` is
    /// measured after a hold of `t0` \[s] and `beta` is the gain per decade of hold time. An
    /// error when mu_s(t) falls below mu_d (named `--hold-time`).
    pub fn aged(mu_s: f64, mu_d: f64, t0: f64, beta: f64, hold: f64) -> Result<Self> {
        if !(t0 > 0.0 && hold > 0.0 && t0.is_finite() && hold.is_finite() && beta.is_finite()) {
            return Err(Error::invalid(
                "--hold-time",
                format!(
                    "hold times must be positive and finite and β finite, got t₀ = {t0} s, t = {hold} s, β = {beta}"
                ),
            ));
        }
        let aged = mu_s + beta * (hold / t0).log10();
        FrictionLaw::new(aged, mu_d).map_err(|e| {
            Error::invalid(
                "--hold-time",
                format!("after a hold of {hold} s: {}", e.to_string().trim_start_matches("--mu-s: ")),
            )
        })
    }

    /// The local friction drop mu_s / mu_d: the friction drop of a single-element interface.
    pub fn drop(&self) -> f64 {
        self.mu_s / self.mu_d
    }

    /// A law read from a measured nanoscale friction–displacement curve (CSV, see
    /// [`law_from_curve`]) in the file at `path`; content errors name the file.
    pub fn from_curve_file(path: &Path, window: Option<(f64, f64)>) -> Result<Self> {
        let text = crate::limits::Limits::default().read_text(path)?;
        let points = parse_curve(&text).map_err(|r| Error::file(path, r))?;
        let (mu_s, mu_d) = law_from_curve(&points, window).map_err(|e| match e {
            CurveError::Window(reason) => Error::invalid("--window", format!("{}: {reason}", path.display())),
            CurveError::Content(reason) => Error::file(path, reason),
        })?;
        Ok(FrictionLaw::new(mu_s, mu_d)
            .map_err(|e| Error::file(path, e.to_string()))?
            .named(path.display().to_string()))
    }
}

/// An error unless `unit`, the displacement unit \[m] of a friction curve that a user gave (as
/// `option`), is a positive finite length.
pub fn check_curve_unit(unit: f64, option: &str) -> Result<()> {
    if unit > 0.0 && unit.is_finite() {
        Ok(())
    } else {
        Err(Error::invalid(option, format!("must be a positive length, got {unit} m")))
    }
}

/// μ(slip) past the peak of the measured friction curve in the file at `path` (CSV, see
/// [`parse_curve`]) whose displacements are in units of `unit` \[m]: the points from its peak
/// on, slip \[m] counted from the peak, as [`crate::friction::Weakening::Curve`] follows them
/// (the curve's own slip-weakening distance). Content errors name the file.
pub fn slip_curve_file(path: &Path, unit: f64) -> Result<Vec<(f64, f64)>> {
    let text = crate::limits::Limits::default().read_text(path)?;
    let points = parse_curve(&text).map_err(|r| Error::file(path, r))?;
    // The peak as the law read from the same curve defines it.
    law_from_curve(&points, None).map_err(|_| Error::file(path, "no sliding after the friction peak"))?;
    let peak = points.iter().enumerate().fold(0, |best, (i, p)| if p.1 > points[best].1 { i } else { best });
    let x0 = points[peak].0;
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(points.len() - peak);
    for &(x, mu) in &points[peak..] {
        if mu <= 0.0 {
            return Err(Error::file(
                path,
                format!("friction coefficient {mu} at displacement {x} after the peak is not positive"),
            ));
        }
        let s = (x - x0) * unit;
        match out.last_mut() {
            // Repeated displacements: keep the last value.
            Some(last) if last.0 == s => last.1 = mu,
            _ => out.push((s, mu)),
        }
    }
    Ok(out)
}

/// Why a curve gives no law: its content, or the averaging window chosen for it.
#[derive(Debug, Clone, PartialEq)]
pub enum CurveError {
    /// The curve itself gives no law (its peak is its last point, or the mean after the peak is
    /// not positive): the reason, reported against the curve's file.
    Content(String),
    /// The averaging window (`--window`) does not fit the curve: the reason.
    Window(String),
}

/// The largest friction coefficient a curve may hold, as any law given (see [`crate::plausible`]).
pub const MAX_CURVE_COEFFICIENT: f64 = crate::plausible::MAX_FRICTION_COEFFICIENT;

/// Parse a friction–displacement curve: CSV with the displacement in the first column and
/// the friction coefficient (friction force over normal force) in the second; further
/// columns are ignored, an optional header line and `#` comment lines are skipped. The
/// displacement may be in any unit (the window of [`law_from_curve`] uses the same one) and
/// must not decrease.
pub fn parse_curve(text: &str) -> std::result::Result<Vec<(f64, f64)>, String> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let mut points: Vec<(f64, f64)> = Vec::new();
    for (i, record) in reader.records().enumerate() {
        let record = record.map_err(|e| format!("not a readable CSV curve: {e}"))?;
        let line = record.position().map_or(i as u64 + 1, |p| p.line());
        if record.len() < 2 {
            return Err(format!("line {line}: expected two columns (displacement, friction coefficient)"));
        }
        let (x, y) = match (record[0].parse::<f64>(), record[1].parse::<f64>()) {
            (Ok(x), Ok(y)) => (x, y),
            _ if i == 0 => continue, // a header line
            _ => return Err(format!("line {line}: '{},{}' is not a pair of numbers", &record[0], &record[1])),
        };
        if !(x.is_finite() && y.is_finite()) {
            return Err(format!("line {line}: values must be finite, got {x}, {y}"));
        }
        if y > MAX_CURVE_COEFFICIENT {
            return Err(format!(
                "line {line}: friction coefficient {y:e} is above {MAX_CURVE_COEFFICIENT}, higher than any measured one (a unit or column mistake?)"
            ));
        }
        if let Some(&(prev, _)) = points.last() {
            if x < prev {
                return Err(format!(
                    "line {line}: displacement {x} decreases (after {prev}); order the curve by displacement"
                ));
            }
        }
        points.push((x, y));
    }
    if points.len() < 2 {
        return Err(format!("a friction curve needs at least two points, found {}", points.len()));
    }
    Ok(points)
}

/// (mu_s, mu_d) from a curve of (displacement, friction coefficient) points: mu_s is its
/// peak (the first, if repeated), mu_d the mean over the points after the peak whose
/// displacement lies within `window` = (start, end) past the peak's displacement (both in
/// the curve's unit, 0 ≤ start < end); without a window, the mean over every point after
/// the peak.
pub fn law_from_curve(points: &[(f64, f64)], window: Option<(f64, f64)>) -> Result<(f64, f64), CurveError> {
    let peak = points.iter().enumerate().fold(0, |best, (i, p)| if p.1 > points[best].1 { i } else { best });
    let (x_peak, mu_s) = points[peak];
    let after = &points[peak + 1..];
    if after.is_empty() {
        return Err(CurveError::Content(format!(
            "the friction peak {mu_s} is the curve's last point: no sliding after it to read mu_d from"
        )));
    }
    let selected: Vec<f64> = match window {
        None => after.iter().map(|p| p.1).collect(),
        Some((start, end)) => {
            if !(start.is_finite() && end.is_finite() && start >= 0.0 && start < end) {
                return Err(CurveError::Window(format!("the window must satisfy 0 ≤ START < END, got {start},{end}")));
            }
            let (lo, hi) = (x_peak + start, x_peak + end);
            let inside: Vec<f64> = after.iter().filter(|p| p.0 >= lo && p.0 <= hi).map(|p| p.1).collect();
            if inside.is_empty() {
                let last = points[points.len() - 1].0;
                return Err(CurveError::Window(format!(
                    "no point lies {start} to {end} after the peak at displacement {x_peak} (the curve ends at {last})"
                )));
            }
            inside
        }
    };
    let mu_d = selected.iter().sum::<f64>() / selected.len() as f64;
    if mu_d <= 0.0 {
        return Err(CurveError::Content(format!("the mean friction after the peak is {mu_d}: mu_d must be positive")));
    }
    Ok((mu_s, mu_d))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn law_is_validated() {
        assert!(FrictionLaw::new(0.6, 0.4).is_ok());
        assert!(FrictionLaw::new(0.4, 0.4).is_ok());
        let e = FrictionLaw::new(0.6, 0.0).unwrap_err().to_string();
        assert!(e.starts_with("--mu-d:"), "{e}");
        let e = FrictionLaw::new(0.6, -0.1).unwrap_err().to_string();
        assert!(e.starts_with("--mu-d:"), "{e}");
        let e = FrictionLaw::new(0.3, 0.4).unwrap_err().to_string();
        assert!(e.starts_with("--mu-s:") && e.contains("below"), "{e}");
        assert!(FrictionLaw::new(f64::NAN, 0.4).is_err());
        assert!(FrictionLaw::new(0.6, f64::INFINITY).is_err());
        // Subnormal coefficients (their forces underflow to zero): refused, naming the option.
        let e = FrictionLaw::new(5e-324, 5e-324).unwrap_err().to_string();
        assert!(
            e.starts_with("--mu-d:") && e.contains("at least 2.2250738585072014e-308 (a normal float), got 5e-324"),
            "{e}"
        );
        let e = FrictionLaw::new(1e-310, f64::MIN_POSITIVE).unwrap_err().to_string();
        assert!(e.starts_with("--mu-s:") && e.contains("got 1e-310"), "{e}");
        assert!(FrictionLaw::new(f64::MIN_POSITIVE, f64::MIN_POSITIVE).is_ok());
        for (mu_s, mu_d) in [(0.6, 0.0), (0.3, 0.4), (f64::NAN, 0.4)] {
            assert!(!FrictionLaw::new(mu_s, mu_d).unwrap_err().to_string().contains('\n'));
        }
    }

    #[test]
    fn aging_adds_beta_per_decade_of_hold_time() {
        let law = FrictionLaw::aged(0.6, 0.4, 100.0, 0.1, 10.0).unwrap();
        assert!((law.mu_s - 0.5).abs() < 1e-15 && law.mu_d == 0.4);
        let law = FrictionLaw::aged(0.6, 0.4, 100.0, 0.1, 1000.0).unwrap();
        assert!((law.mu_s - 0.7).abs() < 1e-15);
        assert_eq!(FrictionLaw::aged(0.6, 0.4, 100.0, 0.1, 100.0).unwrap().mu_s, 0.6);
        let e = FrictionLaw::aged(0.6, 0.4, 100.0, 0.1, 0.1).unwrap_err().to_string();
        assert!(e.starts_with("--hold-time: after a hold of 0.1 s") && e.contains("below the dynamic"), "{e}");
        assert!(FrictionLaw::aged(0.6, 0.4, 0.0, 0.1, 1.0).is_err());
    }

    #[test]
    fn presets_are_valid_and_named() {
        for (name, mu_s, mu_d) in PRESETS {
            let law = FrictionLaw::preset(name).unwrap();
            assert_eq!((law.mu_s, law.mu_d, law.name.as_deref()), (*mu_s, *mu_d, Some(*name)));
        }
        let e = FrictionLaw::preset("hold 1 s").unwrap_err().to_string();
        assert!(e.starts_with("--law:") && e.contains("hold 100 s"), "{e}");
    }

    #[test]
    fn curve_gives_peak_and_windowed_mean() {
        let text = "displacement_nm,mu\n0,0.1\n1,0.5\n2,0.8\n3,0.45\n4,0.4\n5,0.35\n6,0.3\n";
        let pts = parse_curve(text).unwrap();
        assert_eq!(pts.len(), 7);
        // Without a window: every point after the peak at x = 2.
        let (mu_s, mu_d) = law_from_curve(&pts, None).unwrap();
        assert_eq!(mu_s, 0.8);
        assert!((mu_d - (0.45 + 0.4 + 0.35 + 0.3) / 4.0).abs() < 1e-15);
        // Window 2..4 past the peak: x in [4, 6].
        let (_, mu_d) = law_from_curve(&pts, Some((2.0, 4.0))).unwrap();
        assert!((mu_d - 0.35).abs() < 1e-15);
    }

    #[test]
    fn curve_errors_are_one_line_and_specific() {
        assert!(parse_curve("0,0.1\n").unwrap_err().contains("two points"));
        assert!(parse_curve("0,0.1\n1,x\n").unwrap_err().contains("line 2"));
        assert!(parse_curve("0,0.1\n1\n").unwrap_err().contains("two columns"));
        assert!(parse_curve("1,0.1\n0,0.2\n").unwrap_err().contains("decreases"));
        assert!(parse_curve("0,0.1\n1,NaN\n").unwrap_err().contains("finite"));
        let e = parse_curve("0,0.1\n1,5e300\n2,0.2\n").unwrap_err();
        assert!(e.starts_with("line 2: friction coefficient 5e300 is above 10"), "{e}");
        assert!(parse_curve("0,0.1\n1,10\n2,0.2\n").is_ok());
        let pts = parse_curve("0,0.1\n1,0.2\n").unwrap();
        assert!(matches!(law_from_curve(&pts, None), Err(CurveError::Content(r)) if r.contains("last point")));
        let pts = parse_curve("0,0.5\n1,0.2\n2,0.2\n").unwrap();
        assert!(matches!(law_from_curve(&pts, Some((5.0, 6.0))), Err(CurveError::Window(r)) if r.contains("no point")));
        assert!(matches!(law_from_curve(&pts, Some((1.0, 0.5))), Err(CurveError::Window(_))));
        let pts = parse_curve("0,0.5\n1,-0.2\n2,0.0\n").unwrap();
        assert!(matches!(law_from_curve(&pts, None), Err(CurveError::Content(r)) if r.contains("positive")));
    }

    #[test]
    fn curve_file_errors_name_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("afm.csv");
        std::fs::write(&path, "0,0.1\n1,0.6\n2,0.3\n3,0.3\n").unwrap();
        let law = FrictionLaw::from_curve_file(&path, Some((0.5, 1.5))).unwrap();
        assert_eq!((law.mu_s, law.mu_d), (0.6, 0.3));
        let e = FrictionLaw::from_curve_file(&path, Some((3.0, 4.0))).unwrap_err().to_string();
        assert!(e.starts_with("--window:") && e.contains("afm.csv"), "{e}");
        std::fs::write(&path, "0,0.1\n1,0.6\n2,zz\n").unwrap();
        let e = FrictionLaw::from_curve_file(&path, None).unwrap_err().to_string();
        assert!(e.contains("afm.csv") && e.contains("line 3"), "{e}");
        let e = FrictionLaw::from_curve_file(&dir.path().join("missing.csv"), None).unwrap_err().to_string();
        assert!(e.contains("missing.csv"), "{e}");
    }
}
