//! Line profiles as text: two columns, position and height, one point a line (stylus
//! profilometers' exports, `xy` files, CSV tables), `NaN` for a missing height, read as
//! [`columns::table`] reads such a table. Text may be UTF-8, Latin-1 or UTF-16 with a byte
//! order mark.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::columns::{self, names_an_index};
use super::dektak::Dektak;
use super::gwyddion_txt::GwyddionTxt;
use super::reading::{Format, ProfileData, ProfileFormat};
use super::text::{self, Separators};

pub struct ProfileText;

impl ProfileFormat for ProfileText {
    fn name(&self) -> &'static str {
        "profile"
    }

    /// None: a profile is told apart from a matrix by its content.
    fn extensions(&self) -> &'static [&'static str] {
        &[]
    }

    /// A table whose first row of numbers has two (or an index and two) values, after any
    /// header; not a Dektak or Gwyddion export.
    fn sniff(&self, head: &[u8]) -> bool {
        let Some(text) = text::decode_head(head) else { return false };
        if Dektak.sniff(head) || GwyddionTxt.sniff(head) {
            return false;
        }
        let mut last_header = None;
        for line in text.split_inclusive('\n').filter(|l| !l.trim().is_empty()) {
            let Some(sep) = Separators::detect(line) else {
                last_header = Some(line);
                continue;
            };
            let mut values = Vec::new();
            let numbers = sep.row(line, &mut values).is_ok();
            if numbers && values.len() < 2 {
                // A lone number before the table: a header's count of points.
                last_header = Some(line);
                continue;
            }
            return line.ends_with('\n')
                && numbers
                && (values.len() == 2 || (values.len() == 3 && last_header.is_some_and(names_an_index)));
        }
        false
    }

    fn read(&self, bytes: &[u8]) -> Result<ProfileData, String> {
        let text = text::decode(bytes)?;
        columns::table(text.lines().enumerate().map(|(i, l)| (i + 1, l)))
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::super::text::testing;
    use super::*;

    fn read(text: &str) -> Result<ProfileData, String> {
        ProfileText.read(text.as_bytes())
    }

    #[test]
    fn samples_read_as_profiles() {
        let p = ProfileText.read(&testing::sample("xy-1.txt")).unwrap();
        assert_eq!((p.positions.len(), p.positions[0], p.heights[0]), (132, 13.381669, 17.85497));
        assert_eq!((p.position_unit, p.height_unit, p.decided), (None, None, true));
        // A line of units, then a line of one number, before the table.
        let p = ProfileText.read(&testing::sample("xy-2.txt")).unwrap();
        assert_eq!(p.positions.len(), 24);
        assert_eq!(
            (p.position_unit.as_deref(), p.height_unit.as_deref(), p.name.as_str()),
            (Some("µm"), Some("µm"), "default")
        );
        let p = ProfileText.read(&testing::sample("csv-1.csv")).unwrap();
        assert_eq!((p.position_unit.as_deref(), p.height_unit, p.name.as_str()), (Some("microns"), None, "y1"));
        // UTF-16 with a byte order mark, and an index column.
        let p = ProfileText.read(&testing::sample("csv-2.csv")).unwrap();
        assert_eq!((p.positions.len(), p.positions[1], p.heights[0]), (8, -99.875, -1.427432857434913));
        assert_eq!((p.position_unit.as_deref(), p.height_unit.as_deref()), (Some("µm"), Some("µm")));
        let p = ProfileText.read(&testing::sample("xy-5.txt")).unwrap();
        assert!(p.heights[1].is_nan() && p.decided);
    }

    #[test]
    fn column_names_give_units() {
        let p = read("x [mm];z [nm]\n0;1\n1;2\n").unwrap();
        assert_eq!((p.position_unit.as_deref(), p.height_unit.as_deref(), p.decided), (Some("mm"), Some("nm"), true));
        let p = read("1,5\t2,5\n2,5\t3,5\n").unwrap();
        assert_eq!((p.positions, p.heights, p.decided), (vec![1.5, 2.5], vec![2.5, 3.5], false));
    }

    #[test]
    fn what_is_no_profile_is_refused_with_its_line() {
        let e = read("0 1\n2 1\n1 1\n4 1\n").unwrap_err();
        assert!(e.starts_with("line 3: x = 1 does not increase") && e.contains("--format matrix"), "{e}");
        assert!(read("0 1\n1 1 2\n").unwrap_err().contains("line 2 holds 3 values but line 1 holds 2"));
        assert!(read("0 0 1\n1 0 2\n").unwrap_err().contains("--format xyz"));
        assert!(read("1 2 3 4\n").unwrap_err().contains("not the 2 of a line profile"));
        assert!(read("nothing here\n").unwrap_err().contains("no row of numbers"));
        assert!(read("0 1\nNaN 2\n").unwrap_err().contains("line 2: the point has no position"));
        assert!(read("0 1\n1 x\n").unwrap_err().contains("line 2: 'x' is not a number"));
    }

    #[test]
    fn sniffs_two_columns_and_an_index_only() {
        for yes in ["0 1\n1 2\n", "x,z\n0,1\n", "index,x,z\n0,0,1\n", "µm µm\n23\n0, 1\n"] {
            assert!(ProfileText.sniff(yes.as_bytes()), "{yes:?}");
        }
        for no in
            ["0 1 2\n", "1 2 3 4\n", "x,y,z\n0,0,1\n", "0 1", "prose\n", "Scan Parameters\nScan Data\n\nx,z\n0,1\n"]
        {
            assert!(!ProfileText.sniff(no.as_bytes()), "{no:?}");
        }
        let utf16: Vec<u8> =
            [0xFF, 0xFE].into_iter().chain("x,z\n0,1\n".encode_utf16().flat_map(u16::to_le_bytes)).collect();
        assert!(ProfileText.sniff(&utf16));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]
        #[test]
        fn arbitrary_text_never_panics(bytes in testing::texts()) {
            prop_assert!(testing::one_line(&ProfileText.read(&bytes)));
        }

        #[test]
        fn mutated_sample_never_panics(edits in testing::edits()) {
            let bytes = testing::apply(testing::sample("csv-1.csv"), &edits);
            prop_assert!(testing::one_line(&ProfileText.read(&bytes)));
        }
    }
}
