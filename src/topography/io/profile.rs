//! Line profiles as text: two columns, position and height, one point a line (stylus
//! profilometers' exports, `xy` files, CSV tables), `NaN` for a missing height.
//!
//! Lines before the numbers are a header: the one nearest the numbers that has a field for each
//! column names the columns, and a length unit in a name is that column's unit (`x in µm`,
//! `X_(microns)`, `Lateral um`, `Raw Micrometer`, `µm µm`). A table of three columns is a
//! profile when its header names the first an index (`index,x in µm,y in µm`). The positions
//! must increase; a table whose first column does not is no profile (a two-column map reads
//! with `--format matrix`). Text may be UTF-8, Latin-1 or UTF-16 with a byte order mark.
//!
//! A table of two columns could also be a map two points wide. Its content decides: a header
//! naming its columns, or at least [`DECIDED_ROWS`] rows of increasing positions, make it a
//! profile; a shorter headless table is left to the user (`--format profile | matrix`).

use super::dektak::Dektak;
use super::gwyddion_txt::GwyddionTxt;
use super::text::{self, Separators};
use super::{Format, ProfileData, ProfileFormat};
use crate::topography::units;

pub struct ProfileText;

/// Rows of increasing positions that make a headless two-column table a profile rather than a
/// map two points wide: fewer could be either.
pub const DECIDED_ROWS: usize = 4;

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
        table(text.lines().enumerate().map(|(i, l)| (i + 1, l)))
    }
}

/// A header line's fields: split at commas, semicolons or tabs when it has any, else at
/// whitespace; trailing empty fields (`Lateral um,Raw Micrometer,`) dropped.
fn fields(line: &str) -> Vec<&str> {
    let line = text::comment_body(line).unwrap_or(line).trim();
    let mut fields: Vec<&str> = if line.contains([',', ';', '\t']) {
        line.split([',', ';', '\t']).map(str::trim).collect()
    } else {
        line.split_whitespace().collect()
    };
    while fields.last().is_some_and(|f| f.is_empty()) {
        fields.pop();
    }
    fields
}

/// Whether a column name is that of an index (`index`, `#`, `No.`).
fn is_index(name: &str) -> bool {
    ["index", "#", "no", "no.", "n", "point", "i"].contains(&name.to_lowercase().as_str())
}

/// Whether a header line names three columns, the first an index.
fn names_an_index(line: &str) -> bool {
    let f = fields(line);
    f.len() == 3 && is_index(f[0])
}

/// The length unit a column name states (`x in µm`, `X_(microns)`, `height_m`), as written:
/// its last word that is one. A lone `A` is a name, not ångström.
fn unit_in(name: &str) -> Option<String> {
    name.split(|c: char| c.is_whitespace() || "()[]{}_/:,".contains(c))
        .rfind(|w| !w.is_empty() && *w != "A" && metres_per(w).is_some())
        .map(|w| w.to_string())
}

/// The metres per `unit` as [`unit_in`] finds it (long names in any case: `Micrometer`).
pub(super) fn metres_per(unit: &str) -> Option<f64> {
    units::metres_per(unit).or_else(|| units::metres_per(&unit.to_lowercase()))
}

/// The profile in numbered lines: header lines, then rows of numbers (see the module's doc).
/// Allocates in proportion to the numbers present.
pub(super) fn table<'a>(lines: impl Iterator<Item = (usize, &'a str)>) -> Result<ProfileData, String> {
    let mut header: Vec<&str> = Vec::new();
    // Separators, values a row, the column of the positions, the first row's line.
    let mut layout: Option<(Separators, usize, usize, usize)> = None;
    let (mut x, mut z) = (Vec::new(), Vec::new());
    let mut row = Vec::with_capacity(3);
    let mut names: Option<Vec<&str>> = None;
    for (line_no, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        let (sep, width, at, first) = match layout {
            Some(l) => {
                if text::comment_body(line).is_some() {
                    continue;
                }
                l
            }
            None => {
                let Some(sep) = Separators::detect(line) else {
                    header.push(line);
                    continue;
                };
                row.clear();
                sep.row(line, &mut row).map_err(|e| format!("line {line_no}: {e}"))?;
                // A lone number before the table is a header's count of points.
                if row.len() < 2 {
                    header.push(line);
                    continue;
                }
                let width = row.len();
                // The header line nearest the numbers with a field for each column names them.
                names = header.iter().rev().map(|l| fields(l)).find(|f| f.len() == width);
                let at = match (width, &names) {
                    (2, _) => 0,
                    (3, Some(n)) if is_index(n[0]) => 1,
                    _ => {
                        return Err(format!(
                            "line {line_no} holds {width} values, not the 2 of a line profile (x, height){}",
                            if width == 3 { ": x y z points read with --format xyz" } else { "" }
                        ))
                    }
                };
                *layout.insert((sep, width, at, line_no))
            }
        };
        row.clear();
        sep.row(line, &mut row).map_err(|e| format!("line {line_no}: {e}"))?;
        if row.len() != width {
            return Err(format!("line {line_no} holds {} values but line {first} holds {width}", row.len()));
        }
        let (xi, zi) = (row[at], row[at + 1]);
        if !xi.is_finite() {
            return Err(format!("line {line_no}: the point has no position (x = {xi})"));
        }
        if let Some(&prev) = x.last() {
            if xi <= prev {
                return Err(format!(
                    "line {line_no}: x = {xi} does not increase (the line before holds {prev}): not a line \
                     profile (a two-column height map reads with --format matrix)"
                ));
            }
        }
        x.push(xi);
        z.push(zi);
    }
    if x.is_empty() {
        return Err("no line profile in it: no row of numbers".into());
    }
    let names = names.map(|n| n[n.len() - 2..].to_vec());
    let unit = |i: usize| names.as_ref().and_then(|n| unit_in(n[i]));
    // A name that is only a unit (`µm µm`) is no channel name.
    let name = names
        .as_ref()
        .map(|n| n[1])
        .filter(|n| !n.is_empty() && metres_per(n).is_none())
        .unwrap_or("default")
        .to_string();
    Ok(ProfileData {
        decided: names.is_some() || x.len() >= DECIDED_ROWS,
        position_unit: unit(0),
        height_unit: unit(1),
        name,
        positions: x,
        heights: z,
    })
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
        assert_eq!(unit_in("x in µm").as_deref(), Some("µm"));
        assert_eq!(unit_in("X_(microns)").as_deref(), Some("microns"));
        assert_eq!(unit_in("Raw Micrometer").as_deref(), Some("Micrometer"));
        assert_eq!(unit_in("height_m").as_deref(), Some("m"));
        assert_eq!(unit_in("A"), None);
        assert_eq!(unit_in("y1"), None);
        assert_eq!(metres_per("Micrometer"), Some(1e-6));
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
