//! Bruker Dektak stylus profilometers' CSV export: `Scan Parameters` and `Analytical Results`
//! as `key,value` lines, then `Scan Data`, a row of column names with their units and the
//! profile, one point a line:
//!
//! ```text
//! Scan Parameters
//! Length,1500.0 um
//! Resolution,0.156 um/sample
//! …
//! Scan Data
//!
//! Lateral um,Raw Micrometer,
//! 0.0,-0.00933,,
//! ```
//!
//! Latin-1 text (`µ` is the byte 0xB5). The positions are rounded to 0.1 µm, the step
//! `Resolution` states to 0.001 µm: the profile is uniform when they agree to that rounding
//! ([`crate::topography::profile::Profile::adopt_stated_step`]).
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::columns;
use super::reading::{ProfileData, ProfileFormat};
use super::text;
use crate::topography::profile::StatedStep;

pub struct Dektak;

const MAGIC: &str = "Scan Parameters";

impl ProfileFormat for Dektak {
    fn name(&self) -> &'static str {
        "dektak"
    }

    /// None: the export's first line tells it apart from any other CSV file.
    fn extensions(&self) -> &'static [&'static str] {
        &[]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        text::decode_head(head).is_some_and(|t| t.trim_start().starts_with(MAGIC))
    }

    fn read(&self, bytes: &[u8]) -> Result<ProfileData, String> {
        let text = text::decode(bytes)?;
        let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
        let mut header = Vec::new();
        loop {
            match lines.next() {
                Some((_, l)) if l.trim() == "Scan Data" => break,
                Some((_, l)) => header.push(l),
                None => return Err("a Dektak export without its 'Scan Data' section".into()),
            }
        }
        let mut data = columns::table(lines)?;
        // The export's format says it is a profile, however short.
        data.decided = true;
        data.stated_step = header.iter().find_map(|l| stated_step(l, data.position_unit.as_deref()));
        Ok(data)
    }
}

/// The step a `Resolution,0.156 um/sample` line states, in `position_unit` (the positions'):
/// `None` on any other line, or when either unit is not a length.
fn stated_step(line: &str, position_unit: Option<&str>) -> Option<StatedStep> {
    let value = line.trim().strip_prefix("Resolution,")?.trim();
    let (number, unit) = value.split_once(char::is_whitespace)?;
    let unit = unit.trim().strip_suffix("/sample")?;
    let scale = columns::metres_per(unit)? / columns::metres_per(position_unit?)?;
    let step: f64 = number.parse().ok()?;
    let decimals = number.split_once('.').map_or(0, |(_, d)| d.len()) as i32;
    (step > 0.0 && step.is_finite())
        .then(|| StatedStep { step: step * scale, rounding: 0.5 * 10f64.powi(-decimals) * scale })
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::super::text::testing;
    use super::*;

    #[test]
    fn reads_the_scan_data_with_its_units() {
        let p = Dektak.read(&testing::sample("dektak-1.csv")).unwrap();
        assert_eq!(p.positions.len(), 9600);
        assert_eq!((p.positions[1], p.heights[1]), (0.2, -0.00760));
        assert_eq!((p.positions[9599], p.heights[9599]), (1499.8, 16.58112));
        assert_eq!((p.position_unit.as_deref(), p.height_unit.as_deref()), (Some("um"), Some("Micrometer")));
        assert_eq!(p.name, "Raw Micrometer");
        assert_eq!(p.stated_step, Some(StatedStep { step: 0.156, rounding: 0.0005 }));
        assert!(Dektak.sniff(&testing::sample("dektak-1.csv")));
        // A step in another unit than the positions' is converted; a line without one is none.
        let nm = stated_step("Resolution,156 nm/sample", Some("um")).unwrap();
        assert!((nm.step - 0.156).abs() < 1e-15 && (nm.rounding - 0.0005).abs() < 1e-15, "{nm:?}");
        assert_eq!(stated_step("Resolution,0.156 um/sample", None), None);
        assert_eq!(stated_step("Length,1500.0 um", Some("um")), None);
    }

    #[test]
    fn a_cut_export_is_refused() {
        assert_eq!(
            Dektak.read(b"Scan Parameters\nLength,1 um\n").unwrap_err(),
            "a Dektak export without its 'Scan Data' section"
        );
        let e = Dektak.read(b"Scan Parameters\nScan Data\n\nLateral um,Raw Micrometer,\n").unwrap_err();
        assert!(e.contains("no row of numbers"), "{e}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(128))]
        #[test]
        fn mutated_sample_never_panics(edits in testing::edits()) {
            let bytes = testing::apply(testing::sample("dektak-1.csv")[..4000].to_vec(), &edits);
            prop_assert!(testing::one_line(&Dektak.read(&bytes)));
        }
    }
}
