//! Plain-text matrices: one row of heights per line (row index = y), the numbers separated by
//! whitespace, `,` or `;`, `NaN` for a missing point.
//!
//! An optional header before the numbers, comment lines (`#`, `%`, `//`, `;`) or `key: value`
//! / `key = value` lines, may state the size and units:
//!
//! ```text
//! # Channel: Main
//! # Width: 10 µm          (or x-length = 10 µm)
//! # Height: 10 µm         (or y-length = 10 µm)
//! # Value units: m        (or z-unit = nm)
//! ```
//!
//! Without it the matrix is bare: no physical size (the user gives `--size`) and no height unit.
//! Other header lines are ignored. Gwyddion's own export, with its translated labels and
//! several channels in one file, is [`super::gwyddion_txt`].

use super::gwyddion_txt::GwyddionTxt;
use super::text::{self, Rows, Separators};
use super::{Channel, Format};
use crate::topography::units;

pub struct Matrix;

impl Format for Matrix {
    fn name(&self) -> &'static str {
        "matrix"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["txt", "asc", "dat", "csv"]
    }

    /// A table of numbers other than three columns (those are x y z points) and without
    /// Gwyddion's header.
    fn sniff(&self, head: &[u8]) -> bool {
        text::table_head(head).is_some_and(|t| t.columns >= 2 && (t.columns != 3 || !t.complete))
            && !GwyddionTxt.sniff(head)
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        let text = text::decode(bytes)?;
        let mut header = Header::default();
        let mut rows = Rows::default();
        let mut sep = None;
        for (i, line) in text.lines().enumerate() {
            let line_no = i + 1;
            if line.trim().is_empty() {
                continue;
            }
            match sep {
                Some(s) if text::comment_body(line).is_none() => rows.push(s, line_no, line)?,
                Some(_) => {}
                None => {
                    if let Some(s) = Separators::detect(line) {
                        sep = Some(s);
                        rows.push(s, line_no, line)?;
                    } else if let Some((key, value)) = text::key_value(line) {
                        header.take(key, value, line_no)?;
                    } else if text::comment_body(line).is_none() {
                        return Err(format!(
                            "no topography in it: line {line_no} ('{}') is neither a header line nor a row of numbers",
                            text::excerpt(line)
                        ));
                    }
                }
            }
        }
        if rows.is_empty() {
            return Err("no topography in it: no row of numbers".into());
        }
        let mut data = rows.finish()?;
        let physical_size = match (header.width, header.height) {
            (Some(lx), Some(ly)) => Some((lx, ly)),
            (None, None) => None,
            _ => return Err("the header states only one of the width and the height".into()),
        };
        let scale = header.unit.as_deref().and_then(units::metres_per);
        if let Some(s) = scale {
            data.mapv_inplace(|h| h * s);
        }
        Ok(vec![Channel {
            name: header.channel.unwrap_or_else(|| "default".into()),
            data,
            physical_size,
            is_height: header.unit.is_none() || scale.is_some(),
            unit: header.unit,
        }])
    }
}

/// What a matrix header states.
#[derive(Debug, Default)]
struct Header {
    channel: Option<String>,
    /// Physical width and height [m].
    width: Option<f64>,
    height: Option<f64>,
    unit: Option<String>,
}

impl Header {
    fn take(&mut self, key: &str, value: &str, line_no: usize) -> Result<(), String> {
        let length = || {
            text::length_in_metres(value)
                .map(Some)
                .ok_or_else(|| format!("line {line_no}: '{}' is not a positive length with its unit", value))
        };
        match key.to_ascii_lowercase().as_str() {
            "channel" | "title" => self.channel = Some(value.to_string()),
            "width" | "x-length" => self.width = length()?,
            "height" | "y-length" => self.height = length()?,
            "value units" | "z-unit" if !value.is_empty() => self.unit = Some(value.to_string()),
            _ => {}
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::super::text::testing;
    use super::*;

    #[test]
    fn headed_matrix_has_size_unit_and_name() {
        let ch = Matrix.read(&testing::sample("matrix-6.txt")).unwrap();
        assert_eq!(ch.len(), 1);
        assert_eq!(ch[0].name, "Main");
        assert_eq!(ch[0].data.dim(), (3, 4));
        assert_eq!(ch[0].data[(1, 2)], 7.0);
        let (lx, ly) = ch[0].physical_size.unwrap();
        assert!((lx - 10e-6).abs() < 1e-18 && (ly - 10e-6).abs() < 1e-18);
        assert_eq!(ch[0].unit.as_deref(), Some("m"));
    }

    #[test]
    fn bare_matrix_has_no_size_and_nm_header_converts() {
        let ch = Matrix.read(b"1 2 3 4\n5 6 7 NaN\n").unwrap();
        assert_eq!(ch[0].physical_size, None);
        assert_eq!(ch[0].unit, None);
        assert!(ch[0].data[(1, 3)].is_nan());
        let ch = Matrix.read("x-length = 2 µm\ny-length = 1 µm\nz-unit = nm\n1,2\n3,4\n".as_bytes()).unwrap();
        assert_eq!(ch[0].physical_size, Some((2e-6, 1e-6)));
        assert_eq!(ch[0].data[(1, 1)], 4e-9);
        assert!(ch[0].is_height);
        let ch = Matrix.read(b"# Value units: V\n1 2\n3 4\n").unwrap();
        assert!(!ch[0].is_height);
        assert_eq!(ch[0].data[(0, 1)], 2.0);
    }

    #[test]
    fn reads_gwyddion_exports_alike() {
        for name in ["matrix-3.txt", "gwyddion-export-english.txt"] {
            let bytes = testing::sample(name);
            let (m, g) = (Matrix.read(&bytes).unwrap(), GwyddionTxt.read(&bytes).unwrap());
            assert_eq!((&m[0].name, &m[0].data, m[0].physical_size), (&g[0].name, &g[0].data, g[0].physical_size));
        }
    }

    #[test]
    fn refusals_say_why() {
        let e = Matrix.read(&testing::sample("nonsense_txt_file.txt")).unwrap_err();
        assert!(e.starts_with("no topography in it: line 1"), "{e}");
        let e = Matrix.read(b"1 2 3\n4 5\n").unwrap_err();
        assert!(e.contains("line 2 holds 2 values but line 1 holds 3"), "{e}");
        let e = Matrix.read(b"1 2\n3 x\n").unwrap_err();
        assert!(e.contains("line 2: 'x' is not a number"), "{e}");
        let e = Matrix.read(b"# just a comment\n").unwrap_err();
        assert!(e.contains("no row of numbers"), "{e}");
        assert!(Matrix.read(b"1 2 3 4\n").unwrap_err().contains("not a 2-D topography"));
        assert!(Matrix.read(b"# Width: 1 um\n1 2\n3 4\n").unwrap_err().contains("only one of"));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]
        #[test]
        fn arbitrary_text_never_panics(bytes in testing::texts()) {
            prop_assert!(testing::one_line(&Matrix.read(&bytes)));
        }

        #[test]
        fn mutated_sample_never_panics(edits in testing::edits()) {
            let bytes = testing::apply(testing::sample("matrix-6.txt"), &edits);
            prop_assert!(testing::one_line(&Matrix.read(&bytes)));
        }
    }
}
