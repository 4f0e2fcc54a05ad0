//! Zygo Mx `.datx` (MetroPro and Mx interferometer data): an HDF5 file whose `/Data/Surface`
//! group holds the measured heights and `/Data/Intensity` the camera's intensity, each a 2-D
//! dataset with its attributes: `Unit` (`Fringes`, `NanoMeters`, …), `Wavelength` [m],
//! `Interferometric Scale Factor` and `Obliquity Factor` (a fringe is wavelength × scale factor
//! × obliquity of height), `No Data` (the value of a point not measured) and `X Converter` /
//! `Y Converter`, whose `Parameters[1]` is the lateral resolution [m per pixel]. Decoded by
//! `hdf5-reader` (pure Rust), each grid within the limits before it is read.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use hdf5_reader::{Attribute, Dataset, Datatype};

use super::binary::one_line;
use super::reading::{Channel, Format};
use crate::limits::Limits;
use crate::quantity::metres_per;
use crate::quantity::quoted;

pub struct Datx;

const HDF5_MAGIC: &[u8] = b"\x89HDF\r\n\x1a\n";

impl Format for Datx {
    fn name(&self) -> &'static str {
        "datx"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["datx"]
    }

    /// An HDF5 file whose root names a `MetaData` dataset (in the root group's name heap, at
    /// the start of the files Zygo's software writes); other HDF5 files are read as `hdf5`.
    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(HDF5_MAGIC) && head.windows(9).any(|w| w == b"MetaData\0")
    }

    fn size_field(&self) -> &'static str {
        "the X and Y Converter (lateral resolution)"
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        self.read_within(bytes, &Limits::default())
    }

    fn read_within(&self, bytes: &[u8], limits: &Limits) -> Result<Vec<Channel>, String> {
        let file = super::hdf5::open(bytes, limits)?;
        let data =
            file.root_group().and_then(|g| g.group("Data")).map_err(|e| one_line(format!("datx: /Data: {e}")))?;
        let mut channels = Vec::new();
        for group in ["Surface", "Intensity"] {
            let g = match data.group(group) {
                Ok(g) => g,
                Err(hdf5_reader::error::Error::GroupNotFound(_)) => continue,
                Err(e) => return Err(one_line(format!("datx: /Data/{group}: {e}"))),
            };
            let datasets = g.datasets().map_err(|e| one_line(format!("datx: /Data/{group}: {e}")))?;
            for ds in datasets.iter().filter(|d| d.ndim() == 2) {
                channels.push(channel(group, ds, bytes.len(), limits).map_err(one_line)?);
            }
        }
        if channels.is_empty() {
            return Err("a datx file without a 2-D dataset in /Data/Surface or /Data/Intensity".into());
        }
        Ok(channels)
    }
}

/// The dataset `ds` of `group` as a channel: heights in metres when its unit is a length or
/// fringes, as stored otherwise; the no-data value as missing points.
fn channel(group: &str, ds: &Dataset, file_len: usize, limits: &Limits) -> Result<Channel, String> {
    let name = group.to_string();
    let attr = |key: &str| ds.attribute(key).map_err(|e| format!("datx dataset {}: {key}: {e}", quoted(&name)));
    let number = |key: &str| attr(key).and_then(|a| first_number(&a).map_err(|e| format!("{key}: {e}")));
    let unit = attr("Unit").ok().and_then(|a| a.read_strings().ok());
    let unit = unit.and_then(|u| u.into_iter().next()).unwrap_or_default();
    let to_metres = match unit.as_str() {
        "Fringes" => Some(
            number("Wavelength")? * number("Interferometric Scale Factor")? * number("Obliquity Factor").unwrap_or(1.0),
        ),
        "Waves" => Some(number("Wavelength")?),
        "NanoMeters" => Some(1e-9),
        "MicroMeters" => Some(1e-6),
        "MilliMeters" => Some(1e-3),
        "Meters" => Some(1.0),
        "Angstroms" => Some(1e-10),
        u => metres_per(u),
    };
    if let Some(f) = to_metres {
        crate::plausible::height_factor(f, None).map_err(|e| format!("datx unit {}: {e}", quoted(&unit)))?;
    }
    let no_data = number("No Data").ok();
    let mut data = super::hdf5::map(ds, file_len, limits)?;
    data.mapv_inplace(|v| match (no_data, to_metres) {
        (Some(nd), _) if v == nd => f64::NAN,
        (_, Some(f)) => v * f,
        (_, None) => v,
    });
    let resolution = |key: &str| converter_step(ds, key).ok().filter(|d| d.is_finite() && *d > 0.0);
    let physical_size = resolution("X Converter")
        .zip(resolution("Y Converter"))
        .map(|(dx, dy)| (dx * data.ncols() as f64, dy * data.nrows() as f64));
    Ok(Channel {
        name,
        data,
        physical_size,
        is_height: to_metres.is_some(),
        unit: Some(if to_metres.is_some() { "m".to_string() } else { unit }).filter(|u| !u.is_empty()),
    })
}

/// The first value of a numeric attribute.
fn first_number(a: &Attribute) -> Result<f64, String> {
    match a.datatype {
        Datatype::FloatingPoint { size: 8, .. } => a.read_1d::<f64>().map_err(|e| e.to_string())?.first().copied(),
        Datatype::FloatingPoint { size: 4, .. } => {
            a.read_1d::<f32>().map_err(|e| e.to_string())?.first().map(|&v| f64::from(v))
        }
        _ => a.read_as_f64().ok(),
    }
    .ok_or_else(|| "no value".to_string())
}

/// `Parameters[1]` of the converter attribute `key` (a compound of category, base unit and a
/// variable-length list of parameters): the step [m] between pixels.
fn converter_step(ds: &Dataset, key: &str) -> Result<f64, String> {
    let a = ds.attribute(key).map_err(|e| e.to_string())?;
    let Datatype::Compound { fields, .. } = &a.datatype else { return Err(format!("{key} is not a compound")) };
    let field = fields.iter().find(|f| f.name == "Parameters").ok_or("no Parameters")?;
    let at = field.byte_offset as usize;
    let reference = a.raw_data.get(at..).ok_or("truncated")?;
    let bytes = ds.resolve_vlen_reference_bytes(reference, 8).map_err(|e| e.to_string())?;
    bytes
        .get(8..16)
        .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
        .ok_or_else(|| "no Parameters[1]".into())
}
