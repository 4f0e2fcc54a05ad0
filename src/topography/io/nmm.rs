//! The Nanomeasuring Machine (NMM, SIOS) line scan: a zip of `NAME.dat`, a table of numbers
//! (one row per point, columns separated by spaces), and `NAME.dsc`, which names the columns,
//! one line each: `index : date : name : points : description`. The profile is the surface
//! height `-Lz+Az` [m] along the stage's x position `Lx` [m], as SurfaceTopography read these
//! files; a scan run towards −x is read from its end, so that the positions increase. Files
//! the archiver adds (`__MACOSX/`, names starting with `.` or `_`) are ignored.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::container;
use super::reading::{ProfileData, ProfileFormat};
use crate::limits::Limits;

pub struct Nmm;

/// The columns read: the stage's x position and the surface height.
const POSITION: &str = "Lx";
const HEIGHT: &str = "-Lz+Az";

impl ProfileFormat for Nmm {
    fn name(&self) -> &'static str {
        "nmm"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &[]
    }

    /// None from the head: the zip's member names tell it ([`ProfileFormat::sniff_all`]).
    fn sniff(&self, _head: &[u8]) -> bool {
        false
    }

    fn sniff_all(&self, bytes: &[u8]) -> bool {
        container::is_zip(bytes) && pair(bytes).is_ok()
    }

    fn read(&self, bytes: &[u8]) -> Result<ProfileData, String> {
        self.read_within(bytes, &Limits::default())
    }

    fn read_within(&self, bytes: &[u8], limits: &Limits) -> Result<ProfileData, String> {
        let (dat, dsc) = pair(bytes)?;
        let mut archive = container::Archive::open(bytes)?;
        let text = |bytes: Vec<u8>, name: &str| {
            String::from_utf8(bytes).map_err(|_| format!("{} is not UTF-8 text", crate::quantity::quoted(name)))
        };
        let dsc_text = text(archive.read(&dsc, limits)?, &dsc)?;
        let columns: Vec<(String, usize)> = dsc_text
            .lines()
            .filter_map(|line| {
                let fields: Vec<&str> = line.split(" : ").map(str::trim).collect();
                match fields[..] {
                    [_, _, name, points, ..] => points.parse().ok().map(|p| (name.to_string(), p)),
                    _ => None,
                }
            })
            .collect();
        let index = |name: &str| {
            columns.iter().position(|(n, _)| n == name).ok_or_else(|| format!("{dsc} names no column '{name}'"))
        };
        let (ix, iz) = (index(POSITION)?, index(HEIGHT)?);
        let dat_text = text(archive.read(&dat, limits)?, &dat)?;
        let mut positions = Vec::new();
        let mut heights = Vec::new();
        for (row, line) in dat_text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
            let values: Vec<&str> = line.split_whitespace().collect();
            if values.len() != columns.len() {
                return Err(format!(
                    "{dat} line {}: {} values where {dsc} names {} columns",
                    row + 1,
                    values.len(),
                    columns.len()
                ));
            }
            let number = |i: usize| {
                values[i].parse::<f64>().map_err(|_| format!("{dat} line {}: '{}' is not a number", row + 1, values[i]))
            };
            positions.push(number(ix)?);
            heights.push(number(iz)?);
        }
        if let Some((name, points)) = columns.iter().find(|(_, p)| *p != heights.len()) {
            return Err(format!("{dsc} declares {points} points of '{name}' but {dat} holds {}", heights.len()));
        }
        if positions.len() > 1 && positions[0] > positions[positions.len() - 1] {
            positions.reverse();
            heights.reverse();
        }
        Ok(ProfileData {
            name: HEIGHT.to_string(),
            positions,
            heights,
            position_unit: Some("m".into()),
            height_unit: Some("m".into()),
            decided: true,
            stated_step: None,
        })
    }
}

/// The names of the zip's `.dat` and `.dsc` members of one stem, when they are its only files.
fn pair(bytes: &[u8]) -> Result<(String, String), String> {
    let names = container::Archive::open(bytes)?.members()?;
    let own: Vec<&String> = names
        .iter()
        .filter(|n| {
            let file = n.rsplit('/').next().unwrap_or(n);
            !(n.starts_with("__MACOSX/") || file.starts_with('.') || file.starts_with('_'))
        })
        .collect();
    let stem = |ext: &str| own.iter().find_map(|n| n.strip_suffix(ext).map(str::to_string));
    match (own.len(), stem(".dat"), stem(".dsc")) {
        (2, Some(a), Some(b)) if a == b => Ok((format!("{a}.dat"), format!("{a}.dsc"))),
        _ => Err("not an NMM scan: a zip of one NAME.dat and its NAME.dsc".into()),
    }
}
