//! Measured points for the friction-drop-vs-load figure, as CSV.
//!
//! One row per hold-time group of one trace (one load). Header and units:
//!
//! ```text
//! load_n,load_n_std,friction_drop,friction_drop_std,static_coefficient,static_coefficient_std,
//! dynamic_coefficient,dynamic_coefficient_std,hold_s,hold_s_std,n_restarts
//! ```
//!
//! `load_n` is the mean normal force N [N] and `friction_drop` the mean F_S/F_D over the
//! group's `n_restarts` restarts; each `_std` is the sample standard deviation, empty for a
//! single restart. `hold_s` [s] matches a point to the friction law of the same hold time.
//! Files from several traces (loads) may be concatenated below one header. Readers need only
//! `load_n`, `friction_drop`, `hold_s` and `n_restarts`; other columns may be absent.
//!
//! Must not import topography, contact, friction, study, plot or report: a trace is its own input.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::analysis::Group;
use crate::error::{Error, Result};

/// One measured point: a group of restarts after holds of similar length.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShsPoint {
    /// Mean normal force \[N].
    pub load_n: f64,
    /// Its sample standard deviation \[N]; none for a single restart.
    #[serde(default)]
    pub load_n_std: Option<f64>,
    /// Mean F_S / F_D.
    pub friction_drop: f64,
    /// Its sample standard deviation; none for a single restart.
    #[serde(default)]
    pub friction_drop_std: Option<f64>,
    /// Mean mu_s = F_S / N; none when the file has no such column.
    #[serde(default)]
    pub static_coefficient: Option<f64>,
    /// Its sample standard deviation; none for a single restart.
    #[serde(default)]
    pub static_coefficient_std: Option<f64>,
    /// Mean mu_d = F_D / N; none when the file has no such column.
    #[serde(default)]
    pub dynamic_coefficient: Option<f64>,
    /// Its sample standard deviation; none for a single restart.
    #[serde(default)]
    pub dynamic_coefficient_std: Option<f64>,
    /// Mean hold time \[s].
    pub hold_s: f64,
    /// Its sample standard deviation \[s]; none for a single restart.
    #[serde(default)]
    pub hold_s_std: Option<f64>,
    /// Restarts averaged.
    pub n_restarts: usize,
}

impl From<&Group> for ShsPoint {
    fn from(g: &Group) -> Self {
        ShsPoint {
            load_n: g.normal_force_n.mean,
            load_n_std: g.normal_force_n.std,
            friction_drop: g.friction_drop.mean,
            friction_drop_std: g.friction_drop.std,
            static_coefficient: Some(g.static_coefficient.mean),
            static_coefficient_std: g.static_coefficient.std,
            dynamic_coefficient: Some(g.dynamic_coefficient.mean),
            dynamic_coefficient_std: g.dynamic_coefficient.std,
            hold_s: g.hold_s.mean,
            hold_s_std: g.hold_s.std,
            n_restarts: g.n_restarts,
        }
    }
}

/// Write `points` as CSV (the format above), atomically.
pub fn write_points(path: &Path, points: &[ShsPoint]) -> Result<()> {
    crate::output::write_atomic(path, |w| {
        let mut csv = csv::Writer::from_writer(w);
        for p in points {
            csv.serialize(p).map_err(std::io::Error::other)?;
        }
        csv.flush()
    })
}

/// Read points written by [`write_points`] (or by hand, with at least the required columns).
pub fn read_points(path: &Path) -> Result<Vec<ShsPoint>> {
    let bytes = crate::limits::Limits::default().read_file(path)?;
    let mut reader = csv::ReaderBuilder::new().trim(csv::Trim::All).comment(Some(b'#')).from_reader(&bytes[..]);
    let mut points = Vec::new();
    for row in reader.deserialize::<ShsPoint>() {
        let point = row.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            match e.kind() {
                csv::ErrorKind::Deserialize { err, .. } => Error::file(path, format!("line {line}: {err}")),
                _ => Error::file(path, format!("line {line}: {e}")),
            }
        })?;
        if !(point.load_n > 0.0 && point.friction_drop.is_finite() && point.hold_s >= 0.0) {
            return Err(Error::file(
                path,
                format!("a point with load {} N and drop {}", point.load_n, point.friction_drop),
            ));
        }
        points.push(point);
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_minimal_columns() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("points.csv");
        let points = vec![
            ShsPoint {
                load_n: 0.024,
                load_n_std: Some(1e-4),
                friction_drop: 1.52,
                friction_drop_std: Some(0.03),
                static_coefficient: Some(0.61),
                static_coefficient_std: Some(0.01),
                dynamic_coefficient: Some(0.40),
                dynamic_coefficient_std: Some(0.005),
                hold_s: 100.0,
                hold_s_std: Some(0.1),
                n_restarts: 3,
            },
            ShsPoint {
                load_n: 0.024,
                load_n_std: None,
                friction_drop: 1.3,
                friction_drop_std: None,
                static_coefficient: Some(0.52),
                static_coefficient_std: None,
                dynamic_coefficient: Some(0.40),
                dynamic_coefficient_std: None,
                hold_s: 10.0,
                hold_s_std: None,
                n_restarts: 1,
            },
        ];
        write_points(&path, &points).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with("load_n,load_n_std,friction_drop,friction_drop_std,"), "{text}");
        assert_eq!(read_points(&path).unwrap(), points);

        std::fs::write(&path, "hold_s,load_n,friction_drop,n_restarts\n10,1e-3,1.8,3\n").unwrap();
        let minimal = read_points(&path).unwrap();
        assert_eq!((minimal[0].load_n, minimal[0].friction_drop, minimal[0].friction_drop_std), (1e-3, 1.8, None));

        std::fs::write(&path, "hold_s,friction_drop,n_restarts\n10,1.8,3\n").unwrap();
        let e = read_points(&path).unwrap_err().to_string();
        assert!(e.contains("points.csv") && e.contains("load_n") && !e.contains('\n'), "{e}");
    }
}
