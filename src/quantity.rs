//! Physical quantities written by people: a number in SI units, or a number with its unit
//! ("0.1 mN", "31.13 µm", "130 GPa"). One parser serves the study file and the command line;
//! [`human`] prints numbers back the way people write them; [`metres_per`] reads length units
//! as instruments write them (the file readers of `topography` use it too).
//!
//! Imports only `error`; must not import topography, contact, friction, study, report, plot, shs,
//! cli.

/// What a quantity measures: its SI unit, the units a string may carry and their factors.
#[derive(Debug)]
pub struct Dimension {
    /// "length", "force", "pressure".
    pub name: &'static str,
    /// The SI unit a bare number is taken in.
    pub si: &'static str,
    /// The units accepted, as a help text lists them.
    pub units: &'static str,
    per_unit: fn(&str) -> Option<f64>,
    /// The units [`show`] writes a value in, largest first, with their size in SI.
    shown: &'static [(&'static str, f64)],
}

/// A length \[m].
pub const LENGTH: Dimension = Dimension {
    name: "length",
    si: "m",
    units: "m, cm, mm, µm (um), nm, Å, pm",
    per_unit: metres_per,
    shown: &[("m", 1.0), ("mm", 1e-3), ("µm", 1e-6), ("nm", 1e-9), ("pm", 1e-12)],
};
/// A force \[N].
pub const FORCE: Dimension = Dimension {
    name: "force",
    si: "N",
    units: "N, mN, µN (uN), nN",
    per_unit: newtons_per,
    shown: &[("N", 1.0), ("mN", 1e-3), ("µN", 1e-6), ("nN", 1e-9)],
};
/// A pressure, stress or modulus \[Pa].
pub const PRESSURE: Dimension = Dimension {
    name: "pressure",
    si: "Pa",
    units: "Pa, kPa, MPa, GPa",
    per_unit: pascals_per,
    shown: &[("GPa", 1e9), ("MPa", 1e6), ("kPa", 1e3), ("Pa", 1.0)],
};
/// An area \[m²].
pub const AREA: Dimension = Dimension {
    name: "area",
    si: "m²",
    units: "m², µm² (um^2), nm² (nm2)…",
    per_unit: square_metres_per,
    shown: &[("m²", 1.0)],
};
/// A duration \[s].
pub const TIME: Dimension = Dimension {
    name: "time",
    si: "s",
    units: "s, ms, µs (us), min, h",
    per_unit: seconds_per,
    shown: &[("s", 1.0), ("ms", 1e-3), ("µs", 1e-6)],
};
/// A speed [m/s].
pub const SPEED: Dimension = Dimension {
    name: "speed",
    si: "m/s",
    units: "m/s, mm/s, µm/s (um/s), nm/s…",
    per_unit: metres_per_second_per,
    shown: &[("m/s", 1.0), ("mm/s", 1e-3), ("µm/s", 1e-6), ("nm/s", 1e-9)],
};
/// A stiffness [N/m].
pub const STIFFNESS: Dimension = Dimension {
    name: "stiffness",
    si: "N/m",
    units: "N/m, mN/µm, N/nm…",
    per_unit: newtons_per_metre_per,
    shown: &[("N/m", 1.0)],
};

/// A work of adhesion (an energy per area) [J/m²].
pub const SURFACE_ENERGY: Dimension = Dimension {
    name: "work of adhesion",
    si: "J/m²",
    units: "J/m², mJ/m² (J/m2, mJ/m2), N/m, mN/m",
    per_unit: joules_per_square_metre_per,
    shown: &[("J/m²", 1.0), ("mJ/m²", 1e-3)],
};

/// Every dimension, to name the one a misplaced unit belongs to.
const DIMENSIONS: [&Dimension; 8] = [&LENGTH, &FORCE, &PRESSURE, &AREA, &TIME, &SPEED, &STIFFNESS, &SURFACE_ENERGY];

/// Seconds per `unit` ("h", "min", "s", "ms", "µs"/"us"), `None` for anything else.
pub fn seconds_per(unit: &str) -> Option<f64> {
    Some(match unit.trim() {
        "h" => 3600.0,
        "min" => 60.0,
        "s" => 1.0,
        "ms" => 1e-3,
        "us" | "µs" | "μs" => 1e-6,
        _ => return None,
    })
}

/// Square metres per `unit`: a length unit squared ("µm²", "um^2", "nm2").
fn square_metres_per(unit: &str) -> Option<f64> {
    let u = unit.trim();
    let base = u.strip_suffix('²').or_else(|| u.strip_suffix("^2")).or_else(|| u.strip_suffix('2'))?;
    metres_per(base).map(|m| m * m)
}

/// `numerator` per `denominator` units of a ratio written "a/b".
fn ratio(unit: &str, numerator: fn(&str) -> Option<f64>, denominator: fn(&str) -> Option<f64>) -> Option<f64> {
    let (a, b) = unit.split_once('/')?;
    Some(numerator(a)? / denominator(b)?)
}

fn metres_per_second_per(unit: &str) -> Option<f64> {
    ratio(unit, metres_per, seconds_per)
}

fn newtons_per_metre_per(unit: &str) -> Option<f64> {
    ratio(unit, newtons_per, metres_per)
}

/// Joules per square metre in `unit` ("J/m²", "mJ/m2"), or in a force per length ("N/m").
fn joules_per_square_metre_per(unit: &str) -> Option<f64> {
    let joules_per = |u: &str| {
        Some(match u.trim() {
            "J" => 1.0,
            "mJ" => 1e-3,
            "µJ" | "μJ" | "uJ" => 1e-6,
            _ => return None,
        })
    };
    ratio(unit, joules_per, square_metres_per).or_else(|| newtons_per_metre_per(unit))
}

/// Metres per `unit`, for the spellings instruments use (`"nm"`, `"um"`, `"µm"`, `"Å"`, …).
/// `None` for anything that is not a length unit.
pub fn metres_per(unit: &str) -> Option<f64> {
    let u = unit.trim();
    Some(match u {
        "m" | "metre" | "meter" | "metres" | "meters" => 1.0,
        "cm" => 1e-2,
        "mm" => 1e-3,
        "um" | "µm" | "μm" | "micron" | "microns" | "micrometre" | "micrometer" => 1e-6,
        "nm" | "nanometre" | "nanometer" => 1e-9,
        "A" | "Å" | "\u{212B}" | "angstrom" | "Angstrom" => 1e-10,
        "pm" => 1e-12,
        "km" => 1e3,
        _ => return None,
    })
}

/// Newtons per `unit` ("kN", "N", "mN", "µN"/"uN", "nN"), `None` for anything else.
pub fn newtons_per(unit: &str) -> Option<f64> {
    Some(match unit.trim() {
        "kN" => 1e3,
        "N" => 1.0,
        "mN" => 1e-3,
        "µN" | "μN" | "uN" => 1e-6,
        "nN" => 1e-9,
        _ => return None,
    })
}

/// Pascals per `unit` ("Pa", "kPa", "MPa", "GPa"), `None` for anything else.
pub fn pascals_per(unit: &str) -> Option<f64> {
    Some(match unit.trim() {
        "Pa" => 1.0,
        "kPa" => 1e3,
        "MPa" => 1e6,
        "GPa" => 1e9,
        _ => return None,
    })
}

/// How much of a quoted token an error message repeats, so that a message stays one short line.
const QUOTED_CHARS: usize = 40;

/// `text` as an error message quotes it: whole when short, else its start and its end around an
/// ellipsis; control characters (a corrupt file's newlines, NULs) escaped (`\n`, `\0`), so that
/// the message stays one line wherever it is shown.
pub fn quoted(text: &str) -> String {
    format!("'{}'", printable(text))
}

/// [`quoted`] without the quotes.
pub fn printable(text: &str) -> String {
    let shown: String =
        text.chars().map(|c| if c.is_control() { c.escape_debug().to_string() } else { c.to_string() }).collect();
    crate::error::middle_cut(&shown, QUOTED_CHARS)
}

/// The length in bytes of the number at the start of `t` (sign, digits, point, exponent), in
/// one pass; 0 when `t` does not start with one.
fn number_prefix(t: &str) -> usize {
    let b = t.as_bytes();
    let mut i = 0;
    let digits = |i: &mut usize| {
        let start = *i;
        while *i < b.len() && b[*i].is_ascii_digit() {
            *i += 1;
        }
        *i - start
    };
    if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
        i += 1;
    }
    let mut mantissa = digits(&mut i);
    if i < b.len() && b[i] == b'.' {
        i += 1;
        mantissa += digits(&mut i);
    }
    if mantissa == 0 {
        // "inf", "nan": let the float parser have them, to be refused as not finite.
        let rest = t[i..].to_ascii_lowercase();
        return ["infinity", "inf", "nan"].iter().find(|w| rest.starts_with(*w)).map_or(0, |w| i + w.len());
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        let mut j = i + 1;
        if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
            j += 1;
        }
        if digits(&mut j) > 0 {
            i = j;
        }
    }
    i
}

/// The value \[SI] of `text`: a number followed by a unit of `dim` ("0.1 mN", "31.13µm"), or,
/// when `bare_is_si`, also a bare number taken in SI units (the command line's form; in the
/// study file a bare quantity is a TOML number, so a string must carry its unit).
pub fn parse(text: &str, dim: &Dimension, bare_is_si: bool) -> Result<f64, String> {
    let t = text.trim();
    let split = number_prefix(t);
    let Ok(number) = t[..split].parse::<f64>() else {
        return Err(format!("{} is not a {} (a number and a unit: {})", quoted(text), dim.name, dim.units));
    };
    let unit = t[split..].trim();
    if unit.is_empty() {
        if bare_is_si {
            return finite(number, text);
        }
        return Err(format!(
            "{} has no unit: write a bare number for {}, or a string with a unit ({})",
            quoted(text),
            dim.si,
            dim.units
        ));
    }
    let factor =
        (dim.per_unit)(unit).ok_or_else(|| match DIMENSIONS.into_iter().find(|d| (d.per_unit)(unit).is_some()) {
            Some(other) => {
                format!("{} is {}, not {} (units: {})", quoted(text), article(other.name), article(dim.name), dim.units)
            }
            None => {
                format!("{}: unknown unit {} for a {} (units: {})", quoted(text), quoted(unit), dim.name, dim.units)
            }
        })?;
    // A power-of-ten unit shifts the decimal exponent, so "0.1 mN" is exactly what 1e-4 is.
    let exponent = factor.log10().round() as i32;
    // Derived units (µm², mN/µm) come out of products within rounding of their power of ten.
    let decimal = (10f64.powi(exponent) / factor - 1.0).abs() < 1e-12;
    let value = if decimal { shifted(&t[..split], exponent) } else { None };
    finite(value.unwrap_or(number * factor), text)
}

/// The decimal number `number` times 10^`exponent`, rounded once.
fn shifted(number: &str, exponent: i32) -> Option<f64> {
    let (mantissa, own) = match number.find(['e', 'E']) {
        Some(i) => (&number[..i], number[i + 1..].parse::<i32>().ok()?),
        None => (number, 0),
    };
    format!("{mantissa}e{}", own.checked_add(exponent)?).parse().ok()
}

/// `v`, or the reason it is refused.
pub fn finite(v: f64, text: &str) -> Result<f64, String> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{} is not finite", quoted(text)))
    }
}

/// "a length", "an area".
fn article(name: &str) -> String {
    if name.starts_with(['a', 'e', 'i', 'o', 'u']) {
        format!("an {name}")
    } else {
        format!("a {name}")
    }
}

/// `x` as people write it: rounded to 12 significant digits, which hides the last bits of
/// binary arithmetic (`0.6`, not `0.6000000000000001`; `1e-5`, not `9.999999999999999e-6`),
/// in plain notation from 0.001 to a million and with an exponent outside.
pub fn human(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return x.to_string();
    }
    let rounded: f64 = format!("{x:.11e}").parse().expect("a formatted float parses");
    if (1e-3..1e6).contains(&rounded.abs()) {
        rounded.to_string()
    } else {
        format!("{rounded:e}")
    }
}

/// `x` \[SI] of `dim` as people write it, to 6 significant digits, in the largest of its usual
/// units that keeps the number at 1 or more: `100 µN` for 9.999999999999999e-5 N, `31.13 µm`,
/// `130 GPa`. The one way a quantity is printed for people (tables, messages); files keep SI
/// numbers.
pub fn show(x: f64, dim: &Dimension) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{} {}", human(x), dim.si);
    }
    let &(unit, size) = dim
        .shown
        .iter()
        .find(|(_, size)| x.abs() >= size * (1.0 - 1e-9))
        .unwrap_or(dim.shown.last().expect("a dimension shows at least its SI unit"));
    let six: f64 = format!("{:.5e}", x / size).parse().expect("a formatted float parses");
    format!("{} {unit}", human(six))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantities_print_in_the_unit_people_use() {
        assert_eq!(show(1e-4, &FORCE), "100 µN");
        assert_eq!(show(9.999999999999999e-5, &FORCE), "100 µN");
        assert_eq!(show(1e-3, &FORCE), "1 mN");
        assert_eq!(show(5e-5, &FORCE), "50 µN");
        assert_eq!(show(1.0, &FORCE), "1 N");
        assert_eq!(show(1e-12, &FORCE), "0.001 nN");
        assert_eq!(show(4.17295326174e9, &PRESSURE), "4.17295 GPa");
        assert_eq!(show(0.05, &SURFACE_ENERGY), "50 mJ/m²");
        assert_eq!(parse("50 mJ/m2", &SURFACE_ENERGY, true), Ok(0.05));
        assert_eq!(parse("0.05J/m²", &SURFACE_ENERGY, true), Ok(0.05));
        assert_eq!(parse("50mN/m", &SURFACE_ENERGY, true), Ok(0.05));
        assert_eq!(show(130.0, &PRESSURE), "130 Pa");
        assert_eq!(show(31.13e-6, &LENGTH), "31.13 µm");
        assert_eq!(show(130e9, &PRESSURE), "130 GPa");
        assert_eq!(show(2e12, &PRESSURE), "2000 GPa");
        assert_eq!(show(0.0, &FORCE), "0 N");
    }

    #[test]
    fn numbers_print_as_people_write_them() {
        assert_eq!(human(0.6000000000000001), "0.6");
        assert_eq!(human(9.999999999999999e-6), "1e-5");
        assert_eq!(human(31.13e-6), "3.113e-5");
        assert_eq!(human(130e9), "1.3e11");
        assert_eq!(human(-2.5), "-2.5");
        assert_eq!(human(0.0), "0");
        assert_eq!(human(f64::INFINITY), "inf");
        assert_eq!(human(123456.0), "123456");
    }

    #[test]
    fn derived_units() {
        assert_eq!(parse("4 µm²", &AREA, true), Ok(4e-12));
        assert_eq!(parse("4um^2", &AREA, true), Ok(4e-12));
        assert_eq!(parse("0.3 um/s", &SPEED, true), Ok(0.3e-6));
        assert_eq!(parse("2 ms", &TIME, true), Ok(2e-3));
        assert_eq!(parse("1 min", &TIME, true), Ok(60.0));
        assert_eq!(parse("5 mN/um", &STIFFNESS, true), Ok(5e3));
        assert!(parse("3 um", &AREA, true).unwrap_err().contains("is a length, not an area"));
    }

    #[test]
    fn quantities() {
        assert_eq!(parse("0.1 mN", &FORCE, false), Ok(1e-4));
        assert_eq!(parse("31.13 µm", &LENGTH, false), Ok(31.13e-6));
        assert_eq!(parse("31.13um", &LENGTH, false), Ok(31.13e-6));
        assert_eq!(parse("130 GPa", &PRESSURE, false), Ok(130e9));
        assert_eq!(parse("20.75 nm", &LENGTH, false), Ok(20.75e-9));
        assert_eq!(parse("1e-3 N", &FORCE, false), Ok(1e-3));
        assert_eq!(parse("0.2 nm", &LENGTH, false), Ok(0.2e-9));
        assert_eq!(parse("22E-1 nm", &LENGTH, false), Ok(2.2e-9));
        assert_eq!(parse("-5 kPa", &PRESSURE, false), Ok(-5e3));
        assert_eq!(parse(".5 mm", &LENGTH, false), Ok(0.5e-3));
        assert_eq!(parse("2e3m", &LENGTH, false), Ok(2e3));
        // "1e" is the number 1 followed by the unit "e", which no dimension has.
        assert!(parse("1e", &LENGTH, true).unwrap_err().contains("unknown unit 'e'"));
        let e = parse("0.1 mm", &FORCE, false).unwrap_err();
        assert!(e.contains("is a length, not a force"), "{e}");
        assert!(parse("2 furlongs", &LENGTH, false).unwrap_err().contains("unknown unit 'furlongs'"));
        assert!(parse("0.1", &FORCE, false).unwrap_err().contains("no unit"));
        assert!(parse("inf N", &FORCE, false).unwrap_err().contains("not finite"));
        assert!(parse("mN", &FORCE, false).is_err());
    }

    #[test]
    fn bare_numbers_on_the_command_line_are_si() {
        assert_eq!(parse("1e-3", &FORCE, true), Ok(1e-3));
        assert_eq!(parse(" 130e9 ", &PRESSURE, true), Ok(130e9));
        assert!(parse("-inf", &FORCE, true).unwrap_err().contains("not finite"));
        assert!(parse("1e999", &FORCE, true).unwrap_err().contains("not finite"));
    }

    #[test]
    fn long_tokens_are_quoted_short_and_parsed_in_linear_time() {
        let long = "9".repeat(100_000) + "x";
        let e = parse(&long, &LENGTH, true).unwrap_err();
        assert!(e.len() < 200, "{} characters", e.len());
        let junk = "[".repeat(100_000);
        assert!(parse(&junk, &LENGTH, true).unwrap_err().len() < 200);
    }

    #[test]
    fn length_units_as_instruments_write_them() {
        assert_eq!(metres_per("nm"), Some(1e-9));
        assert_eq!(metres_per("µm"), Some(1e-6));
        assert_eq!(metres_per(" um "), Some(1e-6));
        assert_eq!(metres_per("V"), None);
    }
}
