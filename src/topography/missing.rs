//! Missing points (`NaN` heights): refuse them, or fill them harmonically.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::map::Topography;
use crate::error::{Error, Result};

/// An error counting the missing points of `topo`, if it has any.
pub fn refuse_missing(topo: &Topography) -> Result<()> {
    match topo.missing_points() {
        0 => Ok(()),
        m => Err(topo.error(format!(
            "{m} of {} points are missing (NaN): fill them (--fill-missing) or crop them away",
            topo.heights.len()
        ))),
    }
}

/// Fill the missing points of `topo` with the harmonic interpolant of the defined ones: each
/// filled height is the mean of its four neighbours (the discrete Laplace equation, with the
/// defined points as boundary values; neighbours wrap around a periodic map and are absent
/// beyond the edge of a non-periodic one). Smooth across holes and exact for planes away from
/// the edges. Solved by conjugate gradients. Returns the number of points filled.
pub fn fill_missing(topo: &mut Topography) -> Result<usize> {
    let (ny, nx) = topo.heights.dim();
    let n = nx * ny;
    let missing: Vec<usize> = topo.heights.iter().enumerate().filter(|(_, h)| h.is_nan()).map(|(p, _)| p).collect();
    let m = missing.len();
    if m == 0 {
        return Ok(0);
    }
    if m == n {
        return Err(topo.error(format!("all {n} points are missing: nothing to fill them from")));
    }
    let h: Vec<f64> = topo.heights.iter().copied().collect();
    const NONE: usize = usize::MAX;
    let mut unknown = vec![NONE; n];
    for (k, &p) in missing.iter().enumerate() {
        unknown[p] = k;
    }
    let periodic = topo.periodic;
    let neighbours = |p: usize| -> [Option<usize>; 4] {
        let (y, x) = (p / nx, p % nx);
        let step = |v: usize, len: usize, up: bool| -> Option<usize> {
            match (up, periodic) {
                (true, _) if v + 1 < len => Some(v + 1),
                (true, true) => Some(0),
                (false, _) if v > 0 => Some(v - 1),
                (false, true) => Some(len - 1),
                _ => None,
            }
        };
        [
            step(x, nx, false).map(|x| y * nx + x),
            step(x, nx, true).map(|x| y * nx + x),
            step(y, ny, false).map(|y| y * nx + x),
            step(y, ny, true).map(|y| y * nx + x),
        ]
    };
    // The system A u = b on the unknowns: degree·u_k − Σ (unknown neighbours) = Σ (known neighbours).
    let mut degree = vec![0.0; m];
    let mut links = vec![[NONE; 4]; m];
    let mut b = vec![0.0; m];
    for (k, &p) in missing.iter().enumerate() {
        for (slot, q) in neighbours(p).into_iter().enumerate() {
            let Some(q) = q else { continue };
            degree[k] += 1.0;
            if unknown[q] == NONE {
                b[k] += h[q];
            } else {
                links[k][slot] = unknown[q];
            }
        }
    }
    let apply = |u: &[f64], out: &mut [f64]| {
        for k in 0..m {
            out[k] = degree[k] * u[k] - links[k].iter().filter(|&&l| l != NONE).map(|&l| u[l]).sum::<f64>();
        }
    };
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();

    // Conjugate gradients from the mean of the known neighbours.
    let mut u: Vec<f64> = b.iter().zip(&degree).map(|(b, d)| b / d).collect();
    let mut r = vec![0.0; m];
    apply(&u, &mut r);
    r.iter_mut().zip(&b).for_each(|(r, b)| *r = b - *r);
    let mut d = r.clone();
    let mut ad = vec![0.0; m];
    let mut rr = dot(&r, &r);
    let tolerance = 1e-12 * dot(&b, &b).sqrt().max(f64::MIN_POSITIVE);
    let max_iter = 10 * m + 100;
    let mut iterations = 0;
    while rr.sqrt() > tolerance {
        if iterations == max_iter {
            return Err(Error::NotConverged {
                solver: "missing-point fill",
                iterations,
                residual: rr.sqrt() / (tolerance / 1e-12),
                tolerance: 1e-12,
            });
        }
        apply(&d, &mut ad);
        let alpha = rr / dot(&d, &ad);
        u.iter_mut().zip(&d).for_each(|(u, d)| *u += alpha * d);
        r.iter_mut().zip(&ad).for_each(|(r, ad)| *r -= alpha * ad);
        let rr_next = dot(&r, &r);
        let beta = rr_next / rr;
        d.iter_mut().zip(&r).for_each(|(d, r)| *d = r + beta * *d);
        rr = rr_next;
        iterations += 1;
    }
    for (&p, &value) in missing.iter().zip(&u) {
        topo.heights[(p / nx, p % nx)] = value;
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topography::map::Provenance;
    use ndarray::Array2;

    fn map(heights: Array2<f64>, periodic: bool) -> Topography {
        Topography {
            heights,
            physical_size: Some((1e-6, 1e-6)),
            periodic,
            height_unit_known: true,
            channel: "test".into(),
            provenance: Provenance { file: Some("scan.spm".into()), format: "test".into(), height_unit: None },
        }
    }

    #[test]
    fn refusal_counts_the_missing_points_in_one_line() {
        let mut h = Array2::zeros((4, 5));
        h[(1, 1)] = f64::NAN;
        h[(3, 4)] = f64::NAN;
        let err = refuse_missing(&map(h, false)).unwrap_err().to_string();
        assert_eq!(err, "scan.spm: 2 of 20 points are missing (NaN): fill them (--fill-missing) or crop them away");
        assert!(refuse_missing(&map(Array2::zeros((2, 2)), false)).is_ok());
    }

    #[test]
    fn holes_in_a_plane_are_filled_with_the_plane() {
        // A harmonic fill reproduces any harmonic function, planes included.
        let plane = Array2::from_shape_fn((30, 40), |(j, i)| 1e-9 * (3.0 + 0.5 * i as f64 - 0.25 * j as f64));
        let mut h = plane.clone();
        for j in 5..20 {
            for i in 10..30 {
                h[(j, i)] = f64::NAN;
            }
        }
        let mut t = map(h, false);
        assert_eq!(fill_missing(&mut t).unwrap(), 15 * 20);
        let err = (&t.heights - &plane).iter().fold(0.0f64, |m, e| m.max(e.abs()));
        assert!(err < 1e-12 * 1e-9 * 30.0, "error {err}");
        // On a non-periodic edge a lone hole takes the mean of its three neighbours.
        let mut t = map(plane.clone(), false);
        t.heights[(0, 7)] = f64::NAN;
        fill_missing(&mut t).unwrap();
        let mean = (plane[(0, 6)] + plane[(0, 8)] + plane[(1, 7)]) / 3.0;
        assert!((t.heights[(0, 7)] - mean).abs() < 1e-24);
    }

    #[test]
    fn a_periodic_fill_wraps_around_the_edges() {
        // A column of missing points on the left edge of a map whose right edge is 10 and the
        // next column 0: periodic neighbours give 5, non-periodic ones 0.
        let h = Array2::from_shape_fn((6, 8), |(_, i)| match i {
            0 => f64::NAN,
            7 => 10.0,
            _ => 0.0,
        });
        let mut periodic = map(h.clone(), true);
        fill_missing(&mut periodic).unwrap();
        assert!(periodic.heights.column(0).iter().all(|&v| (v - 5.0).abs() < 1e-10), "{}", periodic.heights);
        let mut open = map(h, false);
        fill_missing(&mut open).unwrap();
        assert!(open.heights.column(0).iter().all(|&v| v.abs() < 1e-10), "{}", open.heights);
    }

    #[test]
    fn a_map_with_nothing_defined_cannot_be_filled() {
        let mut t = map(Array2::from_elem((3, 3), f64::NAN), false);
        assert_eq!(
            fill_missing(&mut t).unwrap_err().to_string(),
            "scan.spm: all 9 points are missing: nothing to fill them from"
        );
    }
}
