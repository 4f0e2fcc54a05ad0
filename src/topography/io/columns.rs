//! Tables of numbers in columns under a header that names them, as line profiles come in text
//! (a two-column export, the `Scan Data` of a Dektak export).
//!
//! Lines before the numbers are a header: the one nearest the numbers that has a field for each
//! column names the columns, and a length unit in a name is that column's unit (`x in µm`,
//! `X_(microns)`, `Lateral um`, `Raw Micrometer`, `µm µm`). A table of three columns is a
//! profile when its header names the first an index (`index,x in µm,y in µm`). The positions
//! must increase; a table whose first column does not is no profile (a two-column map reads
//! with `--format matrix`).
//!
//! A table of two columns could also be a map two points wide. Its content decides: a header
//! naming its columns, or at least [`DECIDED_ROWS`] rows of increasing positions, make it a
//! profile; a shorter headless table is left to the user (`--format profile | matrix`).
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::reading::ProfileData;
use super::text::{self, Separators};
use crate::quantity;

/// Rows of increasing positions that make a headless two-column table a profile rather than a
/// map two points wide: fewer could be either.
pub const DECIDED_ROWS: usize = 4;

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
pub(super) fn names_an_index(line: &str) -> bool {
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
    quantity::metres_per(unit).or_else(|| quantity::metres_per(&unit.to_lowercase()))
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
        stated_step: None,
        position_unit: unit(0),
        height_unit: unit(1),
        name,
        positions: x,
        heights: z,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn column_names_give_units() {
        assert_eq!(unit_in("x in µm").as_deref(), Some("µm"));
        assert_eq!(unit_in("X_(microns)").as_deref(), Some("microns"));
        assert_eq!(unit_in("Raw Micrometer").as_deref(), Some("Micrometer"));
        assert_eq!(unit_in("height_m").as_deref(), Some("m"));
        assert_eq!(unit_in("A"), None);
        assert_eq!(unit_in("y1"), None);
        assert_eq!(metres_per("Micrometer"), Some(1e-6));
    }
}
