//! NumPy `.npy`: a bare 2-D array of heights; size and unit come from the user.

use ndarray::Array2;
use ndarray_npy::ReadNpyExt;

use super::{Channel, Format};

pub struct Npy;

impl Format for Npy {
    fn name(&self) -> &'static str {
        "npy"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["npy"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(b"\x93NUMPY")
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        let data = read_f64(bytes)?;
        if data.nrows() == 0 || data.ncols() == 0 {
            return Err("the array is empty".into());
        }
        Ok(vec![Channel { name: "default".into(), data, physical_size: None, unit: None, is_height: true }])
    }

    fn is_bare(&self) -> bool {
        true
    }
}

/// A 2-D `.npy` array of any common numeric type, as float64.
pub fn read_f64(bytes: &[u8]) -> Result<Array2<f64>, String> {
    if !bytes.starts_with(b"\x93NUMPY") {
        return Err("not a .npy file (no \\x93NUMPY magic)".into());
    }
    let first_err = match Array2::<f64>::read_npy(bytes) {
        Ok(a) => return Ok(a),
        Err(e) => e,
    };
    if let Ok(a) = Array2::<f32>::read_npy(bytes) {
        return Ok(a.mapv(f64::from));
    }
    if let Ok(a) = Array2::<i64>::read_npy(bytes) {
        return Ok(a.mapv(|v| v as f64));
    }
    if let Ok(a) = Array2::<i32>::read_npy(bytes) {
        return Ok(a.mapv(f64::from));
    }
    Err(format!("not a readable 2-D numeric .npy array: {first_err}"))
}
