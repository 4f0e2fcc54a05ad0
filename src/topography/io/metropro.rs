//! Zygo MetroPro `.dat` (phase data of Zygo interferometers).
//!
//! A big-endian header (834 bytes for the magics `88 1b 03 6f`/`70`, 4096 for `…71`; its
//! length is stated at byte 6) is followed by the intensity data (`ac_n_buckets` frames of
//! `ac_org_width` × `ac_org_height` 16-bit values), then the phase data: `cn_org_width` ×
//! `cn_org_height` signed 32-bit integers, rows top first. A phase value of 2147483640 or more
//! marks a point not measured. A phase value times `intf_scale_factor · obliquity_factor ·
//! wavelength_in / R` is a height in metres, R = 4096, 32768 or 131072 for `phase_res` 0, 1
//! or 2, negated when `sign` is set; the pixel is `lateral_res` metres square.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::binary::{self, Cursor, Endian, Sample, Stored};
use super::reading::{Channel, Format};
use crate::plausible;

pub struct MetroPro;

const MAGICS: [&[u8]; 3] = [b"\x88\x1b\x03\x6f", b"\x88\x1b\x03\x70", b"\x88\x1b\x03\x71"];
/// The fixed header of the older two magics; the stated length may not be shorter.
const HEADER_MIN: usize = 834;
/// Phase values from this one up mark points not measured.
const INVALID_PHASE: i32 = 2_147_483_640;

impl Format for MetroPro {
    fn name(&self) -> &'static str {
        "metropro"
    }

    fn size_field(&self) -> &'static str {
        "lateral_res"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["dat"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        MAGICS.iter().any(|m| head.starts_with(m))
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        if !self.sniff(bytes) {
            return Err("not a MetroPro file (no MetroPro magic number)".into());
        }
        let h = Header::parse(bytes)?;
        let (nx, ny) = (usize::from(h.cn_width), usize::from(h.cn_height));
        if nx == 0 || ny == 0 || h.cn_bytes == 0 {
            return Err("the file holds no phase data (cn_org_width, cn_org_height or cn_n_bytes is 0)".into());
        }
        let points = binary::grid_points(nx, ny)?;
        if h.cn_bytes != points as u64 * 4 {
            return Err(format!(
                "cn_n_bytes = {} does not match the {nx} × {ny} phase grid of 4-byte values",
                h.cn_bytes
            ));
        }
        let intensity = (usize::from(h.ac_buckets) * usize::from(h.ac_width) * usize::from(h.ac_height))
            .checked_mul(2)
            .ok_or("the declared intensity data size overflows")?;
        let offset = h.header_size.checked_add(intensity).ok_or("the declared data offset overflows")?;
        let resolution = match h.phase_res {
            0 => 4096.0,
            1 => 32768.0,
            2 => 131072.0,
            r => return Err(format!("phase_res = {r} is not 0, 1 or 2")),
        };
        let mut scale =
            f64::from(h.intf_scale_factor) * f64::from(h.obliquity_factor) * f64::from(h.wavelength) / resolution;
        if h.sign != 0 {
            scale = -scale;
        }
        let stored = Stored { sample: Sample::I32, endian: Endian::Big, bottom_first: false };
        plausible::height_factor(scale, stored.sample.levels().map(|l| scale * l)).map_err(|e| {
            format!(
                "the height scale (intf_scale_factor {} × obliquity_factor {} × wavelength_in {} m): {e}",
                h.intf_scale_factor, h.obliquity_factor, h.wavelength
            )
        })?;
        let data = binary::grid(bytes, offset, (nx, ny), stored, "the phase data", |v| {
            if v >= f64::from(INVALID_PHASE) {
                f64::NAN
            } else {
                v * scale
            }
        })?;
        let pixel = f64::from(h.lateral_res);
        let physical_size = (pixel.is_finite() && pixel > 0.0).then_some((nx as f64 * pixel, ny as f64 * pixel));
        Ok(vec![Channel { name: "Default".into(), data, physical_size, unit: Some("m".into()), is_height: true }])
    }
}

/// The header fields that shape and scale the phase data.
struct Header {
    header_size: usize,
    ac_width: u16,
    ac_height: u16,
    ac_buckets: u16,
    cn_width: u16,
    cn_height: u16,
    cn_bytes: u64,
    intf_scale_factor: f32,
    wavelength: f32,
    obliquity_factor: f32,
    lateral_res: f32,
    phase_res: i16,
    sign: i16,
}

impl Header {
    fn parse(bytes: &[u8]) -> Result<Header, String> {
        let mut c = Cursor::new(bytes, Endian::Big);
        c.skip(6, "the magic and header format")?;
        let header_size = c.u32("header_size")? as usize;
        if header_size < HEADER_MIN {
            return Err(format!("header_size = {header_size} is shorter than the {HEADER_MIN}-byte MetroPro header"));
        }
        c.skip(52 - 10, "the software information")?;
        let ac_width = c.u16("ac_org_width")?;
        let ac_height = c.u16("ac_org_height")?;
        let ac_buckets = c.u16("ac_n_buckets")?;
        c.skip(68 - 58, "the intensity origin")?;
        let cn_width = c.u16("cn_org_width")?;
        let cn_height = c.u16("cn_org_height")?;
        let cn_bytes = u64::from(c.u32("cn_n_bytes")?);
        c.skip(164 - 76, "the time stamp and comment")?;
        let intf_scale_factor = c.f32("intf_scale_factor")?;
        let wavelength = c.f32("wavelength_in")?;
        c.skip(4, "num_aperture")?;
        let obliquity_factor = c.f32("obliquity_factor")?;
        c.skip(4, "magnification")?;
        let lateral_res = c.f32("lateral_res")?;
        c.skip(218 - 188, "the acquisition settings")?;
        let phase_res = c.i16("phase_res")?;
        c.skip(232 - 220, "the connection settings")?;
        let sign = c.i16("sign")?;
        Ok(Header {
            header_size,
            ac_width,
            ac_height,
            ac_buckets,
            cn_width,
            cn_height,
            cn_bytes,
            intf_scale_factor,
            wavelength,
            obliquity_factor,
            lateral_res,
            phase_res,
            sign,
        })
    }
}
