//! NumPy `.npz`: a zip of `.npy` arrays, as `numpy.savez` and `numpy.savez_compressed` write
//! them. Each 2-D array is a channel named after its member (less `.npy`), in archive order,
//! shape (ny, nx) as for a `.npy` ([`super::npy`]); arrays of other dimensions are left out, as
//! SurfaceTopography leaves them. Like a `.npy`, the archive states neither physical size nor
//! height unit: both come from the user.
//!
//! Members are inflated as streams within the input limits, as any container's
//! ([`super::container`]).
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::reading::{Channel, Format};
use super::{container, npy};
use crate::limits::Limits;

pub struct Npz;

impl Format for Npz {
    fn name(&self) -> &'static str {
        "npz"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["npz"]
    }

    /// A zip whose first member is a `.npy` array (numpy writes nothing else into one).
    fn sniff(&self, head: &[u8]) -> bool {
        let name_len = head.get(26..28).map_or(0, |b| u16::from_le_bytes([b[0], b[1]]) as usize);
        container::is_zip(head) && head.get(30..30 + name_len).is_some_and(|name| name.ends_with(b".npy"))
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        self.read_within(bytes, &Limits::default())
    }

    fn read_within(&self, bytes: &[u8], limits: &Limits) -> Result<Vec<Channel>, String> {
        let mut channels = Vec::new();
        let mut archive = container::Archive::open(bytes)?;
        for name in archive.members()? {
            let Some(stem) = name.strip_suffix(".npy") else { continue };
            let array = archive.read(&name, limits)?;
            if npy::dimensions(&array).map_err(|e| format!("{name}: {e}"))? != 2 {
                continue;
            }
            let data = npy::read_f64(&array).map_err(|e| format!("{name}: {e}"))?;
            limits.check_grid(data.ncols(), data.nrows())?;
            channels.push(Channel { name: stem.to_string(), data, physical_size: None, unit: None, is_height: true });
        }
        if channels.is_empty() {
            return Err("an .npz archive without a 2-D array".into());
        }
        Ok(channels)
    }

    fn is_bare(&self) -> bool {
        true
    }
}
