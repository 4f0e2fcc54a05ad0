//! Mitutoyo SurfTest roughness testers' Excel export (`.xlsx`): a line profile.
//!
//! Sheet `DATA`: positions in column E, heights in column F (empty cells left out); column A
//! lists the roughness parameters, `Ra     0.018  µm`, whose first gives the heights' unit.
//! Sheet `Certificate`: cell E48 holds the cut-off length, `0.08mm`, whose unit is the
//! positions'. The workbook (a zip) is inflated within the input limits before it is parsed
//! ([`super::container::check_inflated`]).
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::io::Cursor;

use calamine::{Data, DataType, Reader, Xlsx};

use super::reading::{ProfileData, ProfileFormat};
use super::{columns, container};
use crate::limits::Limits;
use crate::quantity::quoted;

pub struct Mitutoyo;

impl ProfileFormat for Mitutoyo {
    fn name(&self) -> &'static str {
        "mitutoyo"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["xlsx"]
    }

    /// None: an Excel workbook of any kind starts alike; the extension tells it.
    fn sniff(&self, _head: &[u8]) -> bool {
        false
    }

    fn read(&self, bytes: &[u8]) -> Result<ProfileData, String> {
        self.read_within(bytes, &Limits::default())
    }

    fn read_within(&self, bytes: &[u8], limits: &Limits) -> Result<ProfileData, String> {
        container::check_inflated(bytes, limits)?;
        let mut book: Xlsx<_> =
            calamine::open_workbook_from_rs(Cursor::new(bytes)).map_err(|e| format!("not a readable workbook: {e}"))?;
        let data = book.worksheet_range("DATA").map_err(|e| format!("no Mitutoyo sheet 'DATA': {e}"))?;
        let certificate =
            book.worksheet_range("Certificate").map_err(|e| format!("no Mitutoyo sheet 'Certificate': {e}"))?;

        // Column A's first roughness parameter: key, value, unit.
        let first = data.get_value((0, 0)).and_then(|c| c.get_string()).unwrap_or("");
        let height_unit = match first.split_whitespace().collect::<Vec<_>>()[..] {
            [_, value, unit, ..] if value.parse::<f64>().is_ok() => unit.to_string(),
            _ => return Err(format!("sheet 'DATA' cell A1 {} states no height unit", quoted(first))),
        };
        // The cut-off, `0.08mm`: the number, then the positions' unit.
        let cut_off = certificate.get_value((47, 4)).and_then(|c| c.get_string()).unwrap_or("").trim();
        let position_unit = cut_off.trim_start_matches(|c: char| c.is_ascii_digit() || "+-.".contains(c)).trim();
        for (unit, cell) in [(height_unit.as_str(), "DATA A1"), (position_unit, "Certificate E48")] {
            if columns::metres_per(unit).is_none() {
                return Err(format!("{cell}: {} is not a length unit", quoted(unit)));
            }
        }

        let column = |col: u32| -> Result<Vec<f64>, String> {
            let start = data.start().unwrap_or((0, 0));
            let rows = data.end().map_or(0, |end| end.0 + 1);
            let mut values = Vec::new();
            for row in start.0..rows {
                match data.get_value((row, col)) {
                    None | Some(Data::Empty) => {}
                    Some(Data::Float(v)) => values.push(*v),
                    Some(Data::Int(v)) => values.push(*v as f64),
                    Some(other) => {
                        return Err(format!("sheet 'DATA' row {} column {}: {} is not a number", row + 1, col, other))
                    }
                }
            }
            Ok(values)
        };
        let (positions, heights) = (column(4)?, column(5)?);
        if positions.len() != heights.len() {
            return Err(format!(
                "sheet 'DATA': {} positions (column E) for {} heights (column F)",
                positions.len(),
                heights.len()
            ));
        }
        Ok(ProfileData {
            name: "default".into(),
            positions,
            heights,
            position_unit: Some(position_unit.to_string()),
            height_unit: Some(height_unit),
            decided: true,
            stated_step: None,
        })
    }
}
