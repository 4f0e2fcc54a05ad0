//! HDF5 (`.h5`), as the contact-mechanics challenge and SurfaceTopography store topographies:
//! each 2-D numeric dataset at the file's root (in name order) is a channel named after it, shape (ny, nx) as
//! a `.npy`'s. The file states neither physical size nor unit: both come from the user, as for
//! SurfaceTopography. Decoded by `hdf5-reader` (pure Rust); every dataset's grid is checked
//! against the limits before it is read, and no read may allocate past them.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use ndarray::{Array2, ArrayD, Ix2};

use hdf5_reader::{Dataset, Datatype, Hdf5File, OpenOptions};

use super::binary::one_line;
use super::gzip;
use super::reading::{Channel, Format};
use crate::limits::{self, Limits};
use crate::quantity::quoted;

pub struct Hdf5;

const MAGIC: &[u8] = b"\x89HDF\r\n\x1a\n";

impl Format for Hdf5 {
    fn name(&self) -> &'static str {
        "hdf5"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["h5", "hdf5"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(MAGIC)
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        self.read_within(bytes, &Limits::default())
    }

    fn read_within(&self, bytes: &[u8], limits: &Limits) -> Result<Vec<Channel>, String> {
        let file = open(bytes, limits)?;
        let mut datasets = file.root_group().and_then(|g| g.datasets()).map_err(|e| one_line(format!("HDF5: {e}")))?;
        // In name order, as h5py (and so SurfaceTopography) lists them.
        datasets.sort_by(|a, b| a.name().cmp(b.name()));
        let mut channels = Vec::new();
        for ds in datasets.iter().filter(|d| d.ndim() == 2) {
            let data = map(ds, bytes.len(), limits)?;
            channels.push(Channel {
                name: ds.name().to_string(),
                data,
                physical_size: None,
                unit: None,
                is_height: true,
            });
        }
        if channels.is_empty() {
            return Err("an HDF5 file without a 2-D dataset at its root".into());
        }
        Ok(channels)
    }

    fn is_bare(&self) -> bool {
        true
    }
}

/// The HDF5 file of `bytes`, no read of which allocates more than a grid within `limits` of
/// float64 values.
pub(super) fn open(bytes: &[u8], limits: &Limits) -> Result<Hdf5File, String> {
    let options = OpenOptions::default().with_max_read_bytes(limits.max_points.saturating_mul(8));
    // The decoder's errors quote the file's bytes (a child's name): kept to one line.
    Hdf5File::from_bytes_with_options(bytes, options).map_err(|e| one_line(format!("HDF5: {e}")))
}

/// The values of the 2-D dataset `ds` of a file of `file_len` bytes as float64, shape (ny, nx),
/// its grid checked against `limits` and the file before it is read.
pub(super) fn map(ds: &Dataset, file_len: usize, limits: &Limits) -> Result<Array2<f64>, String> {
    let (ny, nx) = (ds.shape()[0], ds.shape()[1]);
    let (nx, ny) = (usize::try_from(nx).unwrap_or(usize::MAX), usize::try_from(ny).unwrap_or(usize::MAX));
    limits.check_grid(nx, ny)?;
    in_file(ds, (nx, ny), file_len)?;
    values(ds)?.into_dimensionality::<Ix2>().map_err(|e| format!("HDF5: {e}"))
}

/// Refuse a dataset of `nx` × `ny` values whose data cannot all be in the file of `file_len`
/// bytes, compressed as tightly as deflate can (chunks declared but never written read as the
/// fill value: a file of a kilobyte may declare gigabytes), or whose values the memory
/// available cannot hold; the reader allocates the whole dataset before decoding it.
fn in_file(ds: &Dataset, (nx, ny): (usize, usize), file_len: usize) -> Result<(), String> {
    let name = quoted(ds.name());
    let size = ds.raw_element_size().map_err(|e| format!("HDF5 dataset {name}: {e}"))?;
    let declared = limits::grid_memory(nx, ny, size as u64);
    let most = (file_len as u64).saturating_mul(gzip::MAX_INFLATION as u64);
    if declared > most {
        return Err(format!(
            "HDF5 dataset {name} declares {nx} × {ny} values ({declared} bytes), more than the {file_len} bytes of \
             the file can hold compressed: its data are not in the file (chunks never written)"
        ));
    }
    // The stored values, then their float64 copy.
    limits::check_memory(declared.saturating_add(limits::grid_memory(nx, ny, 8)), &format!("HDF5 dataset {name}"))
}

/// A numeric dataset's values as float64.
fn values(ds: &Dataset) -> Result<ArrayD<f64>, String> {
    let name = quoted(ds.name());
    let read = match ds.dtype() {
        Datatype::FloatingPoint { size: 8, .. } => ds.read_array::<f64>(),
        Datatype::FloatingPoint { size: 4, .. } => ds.read_array::<f32>().map(|a| a.mapv(f64::from)),
        Datatype::FixedPoint { size: 1, signed: true, .. } => ds.read_array::<i8>().map(|a| a.mapv(f64::from)),
        Datatype::FixedPoint { size: 1, signed: false, .. } => ds.read_array::<u8>().map(|a| a.mapv(f64::from)),
        Datatype::FixedPoint { size: 2, signed: true, .. } => ds.read_array::<i16>().map(|a| a.mapv(f64::from)),
        Datatype::FixedPoint { size: 2, signed: false, .. } => ds.read_array::<u16>().map(|a| a.mapv(f64::from)),
        Datatype::FixedPoint { size: 4, signed: true, .. } => ds.read_array::<i32>().map(|a| a.mapv(f64::from)),
        Datatype::FixedPoint { size: 4, signed: false, .. } => ds.read_array::<u32>().map(|a| a.mapv(f64::from)),
        Datatype::FixedPoint { size: 8, signed: true, .. } => ds.read_array::<i64>().map(|a| a.mapv(|v| v as f64)),
        Datatype::FixedPoint { size: 8, signed: false, .. } => ds.read_array::<u64>().map(|a| a.mapv(|v| v as f64)),
        other => return Err(format!("HDF5 dataset {name} holds {other:?}, not numbers")),
    };
    read.map_err(|e| one_line(format!("HDF5 dataset {name}: {e}")))
}
