//! HFM line profiles: semicolon-separated text of a header `X;Y;valid`, a line of units
//! `[mm];[mm];[1/0]`, then one point a line, `position;height;valid` (a point whose `valid` is
//! 0 is missing).
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::binary;
use super::columns;
use super::reading::{ProfileData, ProfileFormat};
use super::text;

pub struct Hfm;

const MAGIC: &str = "X;Y;valid";

impl ProfileFormat for Hfm {
    fn name(&self) -> &'static str {
        "hfm"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["hfm"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        text::decode_head(head).is_some_and(|t| t.lines().next().is_some_and(|l| l.trim() == MAGIC))
    }

    fn read(&self, bytes: &[u8]) -> Result<ProfileData, String> {
        let text = text::decode(bytes)?;
        let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim()));
        if lines.next().map(|(_, l)| l) != Some(MAGIC) {
            return Err(format!("not an HFM profile (its first line is not '{MAGIC}')"));
        }
        let units = lines.next().map(|(_, l)| l).unwrap_or_default();
        let unit = |u: Option<&str>, what: &str| {
            let u = u.and_then(|u| u.trim().strip_prefix('[')?.strip_suffix(']')).map(binary::normalise_unit);
            u.filter(|u| columns::metres_per(u).is_some())
                .ok_or_else(|| format!("the units line '{}' gives no length unit of the {what}", text::excerpt(units)))
        };
        let mut fields = units.split(';');
        let position_unit = unit(fields.next(), "positions")?;
        let height_unit = unit(fields.next(), "heights")?;
        let (mut positions, mut heights) = (Vec::new(), Vec::new());
        for (line_no, line) in lines.filter(|(_, l)| !l.is_empty()) {
            let mut f = line.split(';').map(str::trim);
            let mut number = |what: &str| {
                f.next()
                    .and_then(text::number)
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| format!("line {line_no}: '{}' has no {what}", text::excerpt(line)))
            };
            let (x, z, valid) = (number("position")?, number("height")?, number("valid flag")?);
            positions.push(x);
            heights.push(if valid == 0.0 { f64::NAN } else { z });
        }
        if positions.is_empty() {
            return Err("the HFM profile holds no point".into());
        }
        Ok(ProfileData {
            name: "Y".into(),
            positions,
            heights,
            position_unit: Some(position_unit),
            height_unit: Some(height_unit),
            decided: true,
            stated_step: None,
        })
    }
}
