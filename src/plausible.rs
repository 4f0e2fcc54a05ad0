//! Plausibility of the quantities people give: a bare number is taken in SI units, so a modulus
//! typed in GPa, a window in µm or a load in mN without its unit lands decades away from any
//! contact problem of this kind. A value outside the range such problems have is refused, and a
//! merely unusual one warned about, each in one line that says which unit was likely meant, in
//! the language of where it was given ([`Spelling`]): the command line, the study file or Python.
//! Every front end calls these functions; they never name an option (the caller does).
//!
//! Imports only `quantity`; must not import topography, contact, friction, study, report, plot,
//! shs, cli.

use crate::quantity::{self, human, Dimension, FORCE, LENGTH, PRESSURE, SURFACE_ENERGY};

/// How a front end writes a quantity, for the suggestion of the unit likely meant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Spelling {
    /// The command line: `130GPa`.
    CommandLine,
    /// The study file: `"130 GPa"`.
    StudyFile,
    /// Python, whose arguments are numbers in SI units: `1.3e11 (130 GPa)`.
    Python,
}

/// What a check finds: `Ok(None)` plausible, `Ok(Some(warning))` unusual, `Err(reason)` refused.
pub type Verdict = Result<Option<String>, String>;

/// The largest friction coefficient taken, local or measured: none measured comes near it
/// (clean metals in vacuum reach a few), so a larger one is a unit or column mistake.
pub const MAX_FRICTION_COEFFICIENT: f64 = 10.0;

/// Above this coefficient a law is unusual (warned about).
const USUAL_FRICTION_COEFFICIENT: f64 = 2.0;

/// Mean pressures over the window above this fraction of E* are unusual for a rough contact:
/// the default study's heaviest load, 100 mN on 31.13 µm of silicon, is 7e-4 E*.
const USUAL_STRAIN: f64 = 1e-3;

/// The numbers people type in a unit (`0.5 um`, `130 GPa`, `2000 nm`): a number outside them is
/// not suggested in another unit.
const TYPED: (f64, f64) = (1e-2, 1e5);

/// The mean strain a suggested load unit aims at.
const TYPICAL_STRAIN: f64 = 1e-4;

/// The range a kind of quantity has in contact problems of this kind.
struct Kind {
    /// "a solid's modulus": what the value would have to be.
    what: &'static str,
    dim: &'static Dimension,
    /// Outside it the value is refused [SI].
    possible: (f64, f64),
    /// Outside it (and inside `possible`) the value is warned about [SI].
    usual: (f64, f64),
    /// The value a suggested unit brings the number nearest to, in decades [SI].
    typical: f64,
    /// The units a bare number may have been meant in, with their factors to SI.
    meant: &'static [(&'static str, f64)],
}

const MODULUS: Kind = Kind {
    what: "a solid's Young's modulus",
    dim: &PRESSURE,
    possible: (1e6, 2e12),
    usual: (1e7, 1.2e12),
    typical: 1e11,
    meant: &[("kPa", 1e3), ("MPa", 1e6), ("GPa", 1e9)],
};

const HARDNESS: Kind = Kind {
    what: "a solid's hardness",
    dim: &PRESSURE,
    possible: (1e6, 2e11),
    usual: (1e8, 1e11),
    typical: 1e10,
    meant: &[("kPa", 1e3), ("MPa", 1e6), ("GPa", 1e9)],
};

const WINDOW: Kind = Kind {
    what: "the size of a measured window",
    dim: &LENGTH,
    possible: (1e-9, 1.0),
    usual: (1e-8, 0.1),
    typical: 1e-5,
    meant: &[("mm", 1e-3), ("um", 1e-6), ("nm", 1e-9)],
};

const PIXEL: Kind = Kind {
    what: "a pixel size",
    dim: &LENGTH,
    possible: (1e-12, 1.0),
    usual: (1e-11, 1e-3),
    typical: 1e-8,
    meant: &[("mm", 1e-3), ("um", 1e-6), ("nm", 1e-9)],
};

const RADIUS: Kind = Kind {
    what: "a ball's radius",
    dim: &LENGTH,
    possible: (1e-9, 1e3),
    usual: (1e-7, 1.0),
    typical: 1e-3,
    meant: &[("mm", 1e-3), ("um", 1e-6), ("nm", 1e-9)],
};

const ROUGHNESS: Kind = Kind {
    what: "an RMS roughness",
    dim: &LENGTH,
    possible: (1e-13, 1e-2),
    usual: (1e-12, 1e-4),
    typical: 1e-8,
    meant: &[("mm", 1e-3), ("um", 1e-6), ("nm", 1e-9)],
};

const SLIP_DISTANCE: Kind = Kind {
    what: "a slip-weakening distance",
    dim: &LENGTH,
    possible: (1e-12, 1e-3),
    usual: (1e-11, 1e-4),
    typical: 1e-9,
    meant: &[("mm", 1e-3), ("um", 1e-6), ("nm", 1e-9)],
};

const ADHESION_STRESS: Kind = Kind {
    what: "a cohesive stress",
    dim: &PRESSURE,
    possible: (1e4, 1e12),
    usual: (1e6, 1e11),
    typical: 1e9,
    meant: &[("kPa", 1e3), ("MPa", 1e6), ("GPa", 1e9)],
};

const ADHESION_RANGE: Kind = Kind {
    what: "the range of a cohesive law",
    dim: &LENGTH,
    possible: (1e-12, 1e-6),
    usual: (1e-11, 1e-7),
    typical: 1e-9,
    meant: &[("mm", 1e-3), ("um", 1e-6), ("nm", 1e-9)],
};

const ADHESION_WORK: Kind = Kind {
    what: "a work of adhesion",
    dim: &SURFACE_ENERGY,
    possible: (1e-4, 10.0),
    usual: (1e-3, 2.0),
    typical: 0.05,
    meant: &[("mJ/m2", 1e-3)],
};

/// The stress of a cohesive law \[Pa] (σ₀, or the exponential law's peak tension): 10 kPa to
/// 1 TPa (usually 1 MPa to 100 GPa; a solid's theoretical strength is of order E/10).
pub fn adhesion_stress(pa: f64, spelling: Spelling) -> Verdict {
    check(&ADHESION_STRESS, pa, spelling)
}

/// The range of a cohesive law \[m] (h₀, or the exponential law's ρ): 1 pm to 1 µm (usually
/// 10 pm to 100 nm; van der Waals forces act over a few tenths of a nanometre, a water meniscus
/// over about a nanometre).
pub fn adhesion_range(m: f64, spelling: Spelling) -> Verdict {
    check(&ADHESION_RANGE, m, spelling)
}

/// A work of adhesion w \[J/m²]: 0.1 mJ/m² to 10 J/m² (usually 1 mJ/m² to 2 J/m²; silicon on
/// silicon in air is of order 0.01–0.1 J/m²).
pub fn adhesion_work(w: f64, spelling: Spelling) -> Verdict {
    check(&ADHESION_WORK, w, spelling)
}

/// Young's modulus E \[Pa] of a body: 1 MPa to 2 TPa (usually 10 MPa to 1.2 TPa, diamond's).
pub fn modulus(pa: f64, spelling: Spelling) -> Verdict {
    check(&MODULUS, pa, spelling)
}

/// Hardness H \[Pa] of the softer body: 1 MPa to 200 GPa (usually 100 MPa to 100 GPa).
pub fn hardness(pa: f64, spelling: Spelling) -> Verdict {
    check(&HARDNESS, pa, spelling)
}

/// One side of a topography's window \[m]: 1 nm to 1 m (usually 10 nm to 10 cm).
pub fn window(m: f64, spelling: Spelling) -> Verdict {
    check(&WINDOW, m, spelling)
}

/// A pixel size \[m]: 1 pm to 1 m (usually 10 pm to 1 mm).
pub fn pixel(m: f64, spelling: Spelling) -> Verdict {
    check(&PIXEL, m, spelling)
}

/// The radius of a ball or spherical cap \[m]: 1 nm to 1 km (usually 100 nm to 1 m).
pub fn radius(m: f64, spelling: Spelling) -> Verdict {
    check(&RADIUS, m, spelling)
}

/// An RMS height of roughness \[m]: 0.1 pm to 1 cm (usually 1 pm to 100 µm).
pub fn roughness(m: f64, spelling: Spelling) -> Verdict {
    check(&ROUGHNESS, m, spelling)
}

/// A slip-weakening distance d_c \[m]: 1 pm to 1 mm (usually 10 pm to 100 µm; nanoscale
/// friction curves weaken over nanometres, rocks over micrometres). Zero (the instant drop) is
/// the callers' own case.
pub fn slip_distance(m: f64, spelling: Spelling) -> Verdict {
    check(&SLIP_DISTANCE, m, spelling)
}

/// A height scale factor a file states: `factor` is what one stored unit is worth (in metres
/// for heights, else in the channel's own unit), `full_scale` \[m] the height the stored values'
/// whole range spans when the channel holds heights. Refused when the factor is zero, subnormal
/// or not finite (every height would decode as flat, or as noise of rounding), or when the full
/// scale is below the smallest roughness taken (0.1 pm): no instrument measures such heights.
/// The caller names the file's field and its value.
pub fn height_factor(factor: f64, full_scale: Option<f64>) -> Result<(), String> {
    if !factor.is_normal() {
        return Err(format!(
            "a factor of {} per stored unit is zero, subnormal or not finite: every height would decode as flat",
            human(factor)
        ));
    }
    match full_scale {
        Some(m) => height_span(m.abs()).map_err(|e| format!("the whole range of the stored values spans {e}")),
        None => Ok(()),
    }
}

/// A span of heights \[m], read or computed: none (a flat map) or at least the smallest heights
/// any instrument measures, 0.1 pm; between, heights a rounding apart are no surface (a contact
/// on them is an ill-posed solve, not a measurement).
pub fn height_span(m: f64) -> Result<(), String> {
    if m > 0.0 && m < ROUGHNESS.possible.0 {
        return Err(format!(
            "{}, below {}, the smallest heights any instrument measures",
            quantity::show(m, &LENGTH),
            quantity::show(ROUGHNESS.possible.0, &LENGTH)
        ));
    }
    Ok(())
}

/// A friction coefficient (dimensionless): at most [`MAX_FRICTION_COEFFICIENT`], unusual above
/// 2. Its sign and the order of mu_s and mu_d are the law's own checks.
pub fn friction_coefficient(mu: f64) -> Verdict {
    if !(mu > 0.0 && mu.is_finite()) {
        return Ok(None);
    }
    // A coefficient written as a percentage (60 for 0.6) is the likely slip.
    let percent = |mu: f64| {
        if mu <= 100.0 * MAX_FRICTION_COEFFICIENT {
            format!("; did you mean {} (a coefficient is a ratio, not a percentage)?", human(mu / 100.0))
        } else {
            String::new()
        }
    };
    if mu > MAX_FRICTION_COEFFICIENT {
        return Err(format!(
            "a friction coefficient of {} is above {MAX_FRICTION_COEFFICIENT}, higher than any measured one{}",
            human(mu),
            percent(mu)
        ));
    }
    Ok((mu > USUAL_FRICTION_COEFFICIENT).then(|| {
        format!(
            "a friction coefficient of {} is unusual (most lie below {USUAL_FRICTION_COEFFICIENT}){}",
            human(mu),
            percent(mu)
        )
    }))
}

/// A normal load \[N] on a window of `size` (Lx, Ly) \[m] pressed on a modulus `e_star` \[Pa]:
/// refused when its mean pressure over the window exceeds E* (no rough contact of this kind is
/// strained that far), unusual above 1e-3 E*.
pub fn load(n: f64, (lx, ly): (f64, f64), e_star: f64, spelling: Spelling) -> Verdict {
    let area = lx * ly;
    let strain = n / area / e_star;
    if !(strain > 0.0 && strain.is_finite()) {
        return Ok(None);
    }
    let meant = || {
        [("mN", 1e-3), ("uN", 1e-6), ("nN", 1e-9)]
            .into_iter()
            .filter(|(_, f)| strain * f <= USUAL_STRAIN)
            .min_by(|a, b| decades(strain * a.1, TYPICAL_STRAIN).total_cmp(&decades(strain * b.1, TYPICAL_STRAIN)))
            .map_or(String::new(), |(unit, f)| format!("; did you mean {}?", spelled(n, unit, n * f, &FORCE, spelling)))
    };
    let said = format!(
        "{} on the {} × {} window is a mean pressure of {}, {} times E* = {}",
        quantity::show(n, &FORCE),
        quantity::show(lx, &LENGTH),
        quantity::show(ly, &LENGTH),
        quantity::show(n / area, &PRESSURE),
        human(round3(strain)),
        quantity::show(e_star, &PRESSURE)
    );
    if strain > 1.0 {
        return Err(format!("{said}: no contact of this kind is pressed that hard{}", meant()));
    }
    Ok((strain > USUAL_STRAIN).then(|| format!("{said}, unusually high for a rough contact{}", meant())))
}

/// The verdict on `value` [SI] of a quantity of `kind`.
fn check(kind: &Kind, value: f64, spelling: Spelling) -> Verdict {
    // Signs and infinities are the callers' own checks, with their own words.
    if !(value > 0.0 && value.is_finite()) {
        return Ok(None);
    }
    let inside = |(lo, hi): (f64, f64), v: f64| v >= lo * (1.0 - 1e-12) && v <= hi * (1.0 + 1e-12);
    if inside(kind.usual, value) {
        return Ok(None);
    }
    // The unit the number was likely meant in: the one bringing it nearest the typical value,
    // among those that make it usual (a bare number is in SI, the largest unit listed here).
    // Only for a number people type in a unit: nobody means 2e-6 as "2e-6 mm".
    let meant = kind
        .meant
        .iter()
        .filter(|(_, f)| (TYPED.0..TYPED.1).contains(&value) && inside(kind.usual, value * f))
        .min_by(|a, b| decades(value * a.1, kind.typical).total_cmp(&decades(value * b.1, kind.typical)))
        .map_or(String::new(), |&(unit, f)| {
            format!("; did you mean {}?", spelled(value, unit, value * f, kind.dim, spelling))
        });
    let range = |(lo, hi): (f64, f64)| format!("{} to {}", quantity::show(lo, kind.dim), quantity::show(hi, kind.dim));
    let shown = quantity::show(value, kind.dim);
    if !inside(kind.possible, value) {
        return Err(format!("{shown} is not {} ({}){meant}", kind.what, range(kind.possible)));
    }
    Ok(Some(format!("{shown} is unusual for {} (usually {}){meant}", kind.what, range(kind.usual))))
}

/// `number` in `unit`, as the front end writes it: `130GPa`, `"130 GPa"`, `1.3e11 (130 GPa)`.
fn spelled(number: f64, unit: &str, si: f64, dim: &Dimension, spelling: Spelling) -> String {
    let unit_shown = unit.replace("um", "µm").replace("uN", "µN");
    match spelling {
        Spelling::CommandLine => format!("{}{unit}", human(number)),
        Spelling::StudyFile => format!("\"{} {unit_shown}\"", human(number)),
        Spelling::Python => format!("{} ({})", human(si), quantity::show(si, dim)),
    }
}

/// How many decades apart `a` and `b` are.
fn decades(a: f64, b: f64) -> f64 {
    (a / b).log10().abs()
}

/// `x` to 3 significant digits.
fn round3(x: f64) -> f64 {
    format!("{x:.2e}").parse().expect("a formatted float parses")
}

#[cfg(test)]
mod tests {
    use super::*;
    use Spelling::*;

    #[test]
    fn bare_numbers_in_the_wrong_unit_are_refused_with_the_unit_meant() {
        let e = modulus(130.0, CommandLine).unwrap_err();
        assert_eq!(e, "130 Pa is not a solid's Young's modulus (1 MPa to 2000 GPa); did you mean 130GPa?");
        assert!(modulus(130.0, StudyFile).unwrap_err().ends_with("did you mean \"130 GPa\"?"));
        assert!(modulus(130.0, Python).unwrap_err().ends_with("did you mean 1.3e11 (130 GPa)?"));
        let e = window(31.13, CommandLine).unwrap_err();
        assert!(e.starts_with("31.13 m is not the size of a measured window") && e.ends_with("31.13um?"), "{e}");
        assert!(window(31.13, StudyFile).unwrap_err().ends_with("\"31.13 µm\"?"));
        assert!(pixel(20.0, CommandLine).unwrap_err().ends_with("did you mean 20nm?"));
        assert!(hardness(12.0, CommandLine).unwrap_err().ends_with("did you mean 12GPa?"));
        assert!(roughness(22.0, CommandLine).unwrap_err().ends_with("did you mean 22nm?"));
        let e = slip_distance(2.0, CommandLine).unwrap_err();
        assert_eq!(e, "2 m is not a slip-weakening distance (1 pm to 1 mm); did you mean 2nm?");
        assert!(slip_distance(2.0, Python).unwrap_err().ends_with("did you mean 2e-9 (2 nm)?"));
        assert_eq!(slip_distance(2e-9, StudyFile), Ok(None));
        assert_eq!(slip_distance(5e-6, CommandLine), Ok(None));
        let e = adhesion_work(50.0, CommandLine).unwrap_err();
        assert_eq!(e, "50 J/m² is not a work of adhesion (0.1 mJ/m² to 10 J/m²); did you mean 50mJ/m2?");
        assert_eq!(adhesion_work(0.05, StudyFile), Ok(None));
        assert!(adhesion_work(5e-5, Python).is_err());
        // A number nobody types in a unit gets no suggestion of one: 2e-6 m is not "2e-6 mm".
        assert_eq!(
            adhesion_range(2e-6, StudyFile).unwrap_err(),
            "2 µm is not the range of a cohesive law (1 pm to 1 µm)"
        );
        assert!(adhesion_range(2.0, StudyFile).unwrap_err().ends_with("did you mean \"2 nm\"?"));
        // Nothing scales a value too small up: no suggestion.
        assert_eq!(pixel(1e-13, CommandLine).unwrap_err(), "0.1 pm is not a pixel size (1 pm to 1 m)");
        assert!(modulus(130.0, CommandLine).unwrap_err().starts_with("130 Pa is not"));
        assert!(modulus(1e300, CommandLine).unwrap_err().contains("is not a solid's Young's modulus"));
    }

    #[test]
    fn unusual_values_are_warned_about_and_usual_ones_pass() {
        assert_eq!(modulus(130e9, CommandLine), Ok(None));
        assert_eq!(modulus(1.2e12, CommandLine), Ok(None));
        assert_eq!(window(31.13e-6, CommandLine), Ok(None));
        assert_eq!(pixel(20.75e-9, CommandLine), Ok(None));
        assert_eq!(radius(1.5e-3, CommandLine), Ok(None));
        let w = modulus(5e6, CommandLine).unwrap().unwrap();
        assert!(w.starts_with("5 MPa is unusual for a solid's Young's modulus (usually 10 MPa to"), "{w}");
        let w = radius(1.5, CommandLine).unwrap().unwrap();
        assert!(w.ends_with("did you mean 1.5mm?"), "{w}");
        // Signs and infinities are left to the callers' checks.
        assert_eq!(modulus(-1.0, CommandLine), Ok(None));
        assert_eq!(window(f64::INFINITY, CommandLine), Ok(None));
    }

    #[test]
    fn friction_coefficients_above_ten_are_refused() {
        let e = friction_coefficient(60.0).unwrap_err();
        assert_eq!(
            e,
            "a friction coefficient of 60 is above 10, higher than any measured one; did you mean 0.6 (a coefficient \
             is a ratio, not a percentage)?"
        );
        assert!(!friction_coefficient(1e300).unwrap_err().contains("did you mean"));
        assert!(friction_coefficient(10.0).unwrap().is_some());
        assert_eq!(friction_coefficient(0.6), Ok(None));
        assert_eq!(friction_coefficient(2.0), Ok(None));
    }

    #[test]
    fn loads_are_judged_by_their_mean_pressure_over_the_window() {
        let (area, e_star) = ((31.13e-6, 31.13e-6), 130e9 / (1.0 - 0.26 * 0.26));
        // The default study's range passes.
        assert_eq!(load(1e-7, area, e_star, CommandLine), Ok(None));
        assert_eq!(load(0.1, area, e_star, CommandLine), Ok(None));
        // 1 N (meant 1 mN) is 7e-3 E*: a warning.
        let w = load(1.0, area, e_star, CommandLine).unwrap().unwrap();
        assert!(
            w.starts_with("1 N on the 31.13 µm × 31.13 µm window is a mean pressure of 1.03191 GPa, 0.0074 times"),
            "{w}"
        );
        assert!(w.ends_with("did you mean 1mN?"), "{w}");
        // 1 kN: beyond E*, refused.
        let e = load(1e3, area, e_star, StudyFile).unwrap_err();
        assert!(e.contains("no contact of this kind is pressed that hard; did you mean \"1000 µN\"?"), "{e}");
    }
}
