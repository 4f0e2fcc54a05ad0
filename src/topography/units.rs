//! Length units as instruments write them.

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_units() {
        assert_eq!(metres_per("nm"), Some(1e-9));
        assert_eq!(metres_per("µm"), Some(1e-6));
        assert_eq!(metres_per(" um "), Some(1e-6));
        assert_eq!(metres_per("V"), None);
    }
}
