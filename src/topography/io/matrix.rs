//! Plain-text matrices: one row of heights per line (row index = y), the numbers separated by
//! whitespace, `,` or `;`, `NaN` for a missing point.
//!
//! An optional header before the numbers, comment lines (`#`, `%`, `//`, `;`) or `key: value`
//! / `key = value` lines, may state the grid, the size, the units and a factor to metres. The
//! forms are those SurfaceTopography's text reader and Gwyddion's SPIP ASCII module know:
//!
//! ```text
//! # Channel: Main                     (or Title, Kanal)
//! # Width: 10 µm                      (or x-length, Breite; Height, y-length, Höhe for y)
//! # Value units: m                    (or z-unit, data unit)
//! h=650 w=650                         (rows and points per row; or y-pixels, x-pixels)
//! pixel size=3.69862e-007 m           (the size is then the pixel times the points)
//! data unit=rad
//! height conversion factor (-> m)=6.30079e-008   (heights = values × factor, in m)
//! # x-unit = nm                       (unit of a width or height written without one)
//! # Bit2nm = 1.0                      (SPIP: heights = values × factor, in nm)
//! ```
//!
//! A width written without a unit takes `x-unit`; in SPIP's export (`File Format = ASCII`) it
//! is in nm, as Gwyddion reads it; otherwise it takes the height unit when that is a length
//! (SurfaceTopography's rule), and is refused when nothing states its unit. A stated grid must
//! match the numbers. Values in a unit that is not a length (rad, V, deg) without a factor to
//! metres are not heights. Without any header the matrix is bare: no physical size (the user
//! gives `--size`) and no height unit (`--height-unit`). Other header lines are ignored.
//! Gwyddion's own export, with its translated labels and several channels in one file, is
//! [`super::gwyddion_txt`].
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::gwyddion_txt::GwyddionTxt;
use super::reading::{Channel, Format};
use super::text::{self, Rows, Separators};
use crate::plausible;
use crate::quantity::metres_per;

pub struct Matrix;

impl Format for Matrix {
    fn name(&self) -> &'static str {
        "matrix"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["txt", "asc", "dat", "csv"]
    }

    /// A table of numbers of more than three columns (two are a line profile's x and height,
    /// three x y z points) and without Gwyddion's header. A two-column map is read only when
    /// `--format matrix` says so.
    fn sniff(&self, head: &[u8]) -> bool {
        text::table_head(head).is_some_and(|t| t.columns >= 2 && (t.columns > 3 || !t.complete))
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
                    } else if let Some(pairs) = pairs(line) {
                        for (key, value) in pairs {
                            header.take(key, value, line_no)?;
                        }
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
        let (ny, nx) = data.dim();
        for (stated, got, what) in [(header.columns, nx, "points per row"), (header.rows, ny, "rows")] {
            if let Some(n) = stated.filter(|&n| n != got) {
                return Err(format!("the header states {n} {what} but the file holds {got}"));
            }
        }
        let physical_size = header.physical_size((nx, ny))?;
        let (scale, unit) = header.heights()?;
        if let Some(s) = scale {
            data.mapv_inplace(|h| h * s);
        }
        Ok(vec![Channel {
            name: header.channel.unwrap_or_else(|| "default".into()),
            data,
            physical_size,
            is_height: unit.is_none() || scale.is_some(),
            unit,
        }])
    }
}

/// The `key = value` pairs of a header line, `None` if it is none: one pair a line
/// (`pixel size=3.7e-7 m`, `# Width: 10 µm`), or several one-word pairs (`h=650 w=650`).
fn pairs(line: &str) -> Option<Vec<(&str, &str)>> {
    let body = text::comment_body(line).unwrap_or(line);
    let words: Vec<&str> = body.split_whitespace().collect();
    let one_word_pair = |w: &&str| w.matches('=').count() == 1 && !w.starts_with('=') && !w.ends_with('=');
    if words.len() > 1 && words.iter().all(one_word_pair) {
        return Some(words.iter().filter_map(|w| w.split_once('=')).collect());
    }
    text::key_value(line).map(|kv| vec![kv])
}

/// A number with an optional unit, `10 µm`, `2000`, `12,5 mm`.
type Written = (f64, Option<String>);

/// What a matrix header states.
#[derive(Debug, Default)]
struct Header {
    channel: Option<String>,
    /// Points per row and rows.
    columns: Option<usize>,
    rows: Option<usize>,
    /// Width and height as written.
    width: Option<Written>,
    height: Option<Written>,
    /// Units of a width and height written without one.
    x_unit: Option<String>,
    y_unit: Option<String>,
    /// Pixel size [m].
    pixel: Option<f64>,
    /// Unit of the values.
    unit: Option<String>,
    /// Factor from the values to heights in the unit given with it.
    factor: Option<(f64, String)>,
    /// SPIP's ASCII export, whose lengths are in nm.
    spip: bool,
}

impl Header {
    fn take(&mut self, key: &str, value: &str, line_no: usize) -> Result<(), String> {
        let bad = |what: &str| format!("line {line_no}: '{}' is not {what}", text::excerpt(value));
        let count = || value.parse::<usize>().ok().filter(|&n| n > 0).ok_or_else(|| bad("a number of points"));
        let written = || written(value).ok_or_else(|| bad("a positive length"));
        let lower = key.to_lowercase();
        match lower.as_str() {
            "channel" | "title" | "kanal" => self.channel = Some(value.to_string()),
            "w" | "x-pixels" => self.columns = Some(count()?),
            "h" | "y-pixels" => self.rows = Some(count()?),
            "width" | "x-length" | "breite" => self.width = Some(written()?),
            "height" | "y-length" | "höhe" => self.height = Some(written()?),
            "x-unit" if !value.is_empty() => self.x_unit = Some(value.to_string()),
            "y-unit" if !value.is_empty() => self.y_unit = Some(value.to_string()),
            "value units" | "z-unit" | "data unit" if !value.is_empty() => self.unit = Some(value.to_string()),
            "pixel size" => {
                self.pixel = Some(text::length_in_metres(value).ok_or_else(|| bad("a pixel size with its unit"))?)
            }
            "bit2nm" => self.factor = Some((text::number(value).ok_or_else(|| bad("a factor"))?, "nm".into())),
            "file format" if value.eq_ignore_ascii_case("ascii") => self.spip = true,
            _ if lower.starts_with("height conversion factor") => {
                // `height conversion factor (-> m)`: the unit the factor converts to.
                let unit = key.split_once("->").map(|(_, u)| u.trim_end_matches(')').trim()).unwrap_or("");
                if metres_per(unit).is_none() {
                    return Err(format!(
                        "line {line_no}: the height conversion factor converts to '{unit}', not a length"
                    ));
                }
                self.factor = Some((text::number(value).ok_or_else(|| bad("a factor"))?, unit.to_string()));
            }
            _ => {}
        }
        Ok(())
    }

    /// The physical size [m] of an `n` = (nx, ny) grid, if the header states it.
    fn physical_size(&self, n: (usize, usize)) -> Result<Option<(f64, f64)>, String> {
        match (&self.width, &self.height) {
            (Some(w), Some(h)) => {
                Ok(Some((self.metres(w, &self.x_unit, "width")?, self.metres(h, &self.y_unit, "height")?)))
            }
            (None, None) => Ok(self.pixel.map(|p| (p * n.0 as f64, p * n.1 as f64))),
            _ => Err("the header states only one of the width and the height".into()),
        }
    }

    /// A width or height in metres: its own unit, else `unit`, else SPIP's nm, else the
    /// height unit when that is a length.
    fn metres(&self, (value, own): &Written, unit: &Option<String>, what: &str) -> Result<f64, String> {
        let nm = self.spip.then_some("nm");
        let height_unit = self.unit.as_deref().filter(|u| metres_per(u).is_some());
        let unit = own.as_deref().or(unit.as_deref()).or(nm).or(height_unit).ok_or_else(|| {
            format!("the header states the {what} {value} without a unit, and no x-unit or height unit")
        })?;
        let metres = metres_per(unit).ok_or_else(|| format!("the {what}'s unit '{unit}' is not a length"))?;
        Ok(value * metres)
    }

    /// The factor from the values to metres, if known, and the unit the heights are reported
    /// in (the factor's, or the values' own).
    fn heights(&self) -> Result<(Option<f64>, Option<String>), String> {
        if let Some((factor, unit)) = &self.factor {
            let scale = factor * metres_per(unit).expect("checked when read");
            plausible::height_factor(scale, None)
                .map_err(|e| format!("the height conversion factor {factor} {unit}: {e}"))?;
            return Ok((Some(scale), Some(unit.clone())));
        }
        Ok((self.unit.as_deref().and_then(metres_per), self.unit.clone()))
    }
}

/// `10 µm`, `12,5 mm`, `2000`: a positive finite number and the rest of the text as its unit.
fn written(text: &str) -> Option<Written> {
    let text = text.trim();
    let split = text.find(char::is_whitespace).unwrap_or(text.len());
    let number = &text[..split];
    let value = text::number(number).or_else(|| text::number(&number.replacen(',', ".", 1)))?;
    let unit = text[split..].trim();
    (value.is_finite() && value > 0.0).then(|| (value, (!unit.is_empty()).then(|| unit.to_string())))
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

    /// The header of SurfaceTopography's `matrix-2.txt` and `matrix-4.txt` (an interferometer's
    /// phase export): grid, pixel size, a non-length data unit and its factor to metres.
    #[test]
    fn grid_pixel_size_and_conversion_factor() {
        let file = "h=3 w=4\npixel size=3.69862e-007 m\ndata unit=rad\nheight conversion factor (-> m)=6.30079e-008\n\
                    1 2 3 4\n5 6 7 8\n-1 -2 -3 -4\n";
        assert!(Matrix.sniff(file.as_bytes()));
        let ch = &Matrix.read(file.as_bytes()).unwrap()[0];
        assert_eq!(ch.data.dim(), (3, 4));
        assert_eq!(ch.physical_size, Some((4.0 * 3.69862e-7, 3.0 * 3.69862e-7)));
        assert_eq!(ch.data[(1, 2)], 7.0 * 6.30079e-8);
        assert_eq!((ch.unit.as_deref(), ch.is_height), (Some("m"), true));
        // The factor may convert to another length unit.
        let nm = file.replace("(-> m)=6.30079e-008", "(-> nm)=2");
        assert_eq!(Matrix.read(nm.as_bytes()).unwrap()[0].data[(0, 0)], 2e-9);
        // Without the factor the values are phases, not heights.
        let rad = file.replace("height conversion factor (-> m)=6.30079e-008\n", "");
        let ch = &Matrix.read(rad.as_bytes()).unwrap()[0];
        assert_eq!((ch.unit.as_deref(), ch.is_height, ch.data[(0, 1)]), (Some("rad"), false, 2.0));
        // A stated grid must be the file's.
        let e = Matrix.read(file.replace("h=3", "h=4").as_bytes()).unwrap_err();
        assert_eq!(e, "the header states 4 rows but the file holds 3");
        let e = Matrix.read(file.replace("w=4", "w=5").as_bytes()).unwrap_err();
        assert_eq!(e, "the header states 5 points per row but the file holds 4");
        let e = Matrix.read(file.replace("(-> m)", "(-> V)").as_bytes()).unwrap_err();
        assert!(e.contains("converts to 'V', not a length"), "{e}");
    }

    /// SPIP's ASCII export as Gwyddion writes it: lengths without a unit in nm, `Bit2nm`.
    #[test]
    fn spip_ascii_lengths_in_nm() {
        let file = "# File Format = ASCII\n# Created by Gwyddion 2.60\n# x-pixels = 3\n# y-pixels = 2\n\
                    # x-length = 3000\n# y-length = 2000\n# x-offset = 0\n# y-offset = 0\n# Bit2nm = 1.0\n\
                    # Start of Data:\n1\t2\t3\n4\t5\t6\n";
        let ch = &Matrix.read(file.as_bytes()).unwrap()[0];
        assert_eq!(ch.physical_size, Some((3000.0 * 1e-9, 2000.0 * 1e-9)));
        assert_eq!((ch.data[(1, 2)], ch.unit.as_deref()), (6.0 * 1e-9, Some("nm")));
        let e = Matrix.read(file.replace("# x-pixels = 3", "# x-pixels = 2").as_bytes()).unwrap_err();
        assert!(e.contains("states 2 points per row"), "{e}");
    }

    /// Lengths without a unit take `x-unit`/`y-unit`, else the height unit when it is a
    /// length (SurfaceTopography's rule); with no unit at all they are refused.
    #[test]
    fn unitless_lengths_take_a_stated_unit_or_are_refused() {
        let ch = &Matrix.read(b"# x-length = 2\n# y-length = 1\n# x-unit = um\n# y-unit = um\n1 2\n3 4\n").unwrap()[0];
        assert_eq!((ch.physical_size, ch.unit.as_deref()), (Some((2e-6, 1e-6)), None));
        let ch = &Matrix.read(b"x-length = 2000\ny-length = 2000\nz-unit = nm\n1 2\n3 4\n").unwrap()[0];
        assert_eq!((ch.physical_size, ch.data[(1, 1)]), (Some((2000.0 * 1e-9, 2000.0 * 1e-9)), 4e-9));
        let e = Matrix.read(b"x-length = 2\ny-length = 1\n1 2\n3 4\n").unwrap_err();
        assert!(e.contains("width 2 without a unit"), "{e}");
        let e = Matrix.read(b"# Width: 2 px\n# Height: 2 px\n1 2\n3 4\n").unwrap_err();
        assert!(e.contains("unit 'px' is not a length"), "{e}");
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
