//! SRTM `.hgt` elevation tiles (NASA's Shuttle Radar Topography Mission): a square grid of
//! big-endian 16-bit heights in metres, north row first, with no header: 1201 × 1201 points
//! (SRTM3, 3 arc-seconds apart) or 3601 × 3601 (SRTM1, 1 arc-second), told by the file's length;
//! −32768 marks a void (a missing point). A tile spans 1° × 1°, about 111 km × 111·cos(latitude)
//! km: no physical size is read, since a window that wide is outside what asperity's contact
//! models describe (a side of at most 1 m), and the tile's latitude is only in its file name.
//! The heights are read and their statistics shown; contact asks for `--size`, and refuses one
//! that large.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::binary::{self, Endian, Sample, Stored};
use super::reading::{Channel, Format};

pub struct Hgt;

/// The value of a void.
const VOID: f64 = -32768.0;

impl Format for Hgt {
    fn name(&self) -> &'static str {
        "hgt"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["hgt"]
    }

    /// None: a tile is bare heights; its extension tells it.
    fn sniff(&self, _head: &[u8]) -> bool {
        false
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        let n = match bytes.len() {
            2_884_802 => 1201,
            25_934_402 => 3601,
            len => {
                return Err(format!(
                    "an SRTM tile holds 1201 × 1201 (SRTM3) or 3601 × 3601 (SRTM1) 16-bit heights, \
                     2884802 or 25934402 bytes, not {len}"
                ))
            }
        };
        let stored = Stored { sample: Sample::I16, endian: Endian::Big, bottom_first: false };
        let data = binary::grid(bytes, 0, (n, n), stored, "the heights", |v| if v == VOID { f64::NAN } else { v })?;
        Ok(vec![Channel {
            name: "elevation".into(),
            data,
            physical_size: None,
            unit: Some("m".into()),
            is_height: true,
        }])
    }
}
