//! The convergence of the elastic-sharing onset with the pixel size: the friction drop (and so
//! the static coefficient μ_S = μ_d · drop) of one surface resampled to several pixel sizes, per
//! load and slip weakening, as `tools/sharing-convergence.sh` measures it.
//!
//! Must not import report: plot draws what study, friction, contact and shs hand it.

use super::figure::LegendPosition;
use super::figure::{Axis, Grid, Panel};
use super::series::{Marker, Series};
use super::style;
use super::ticks::tick_label;

/// One onset under elastic sharing, with equal sharing's on the same pressure.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvergencePoint {
    /// Pixel size \[m].
    pub pixel_size_m: f64,
    /// Normal load \[N].
    pub load_n: f64,
    /// Slip-weakening distance d_c \[m]; 0 for the instant drop from mu_s to mu_d.
    pub slip_distance_m: f64,
    /// Contact points (elements) at this pixel size and load.
    pub contact_points: usize,
    /// F_S / (mu_d N) under elastic sharing.
    pub friction_drop: f64,
    /// F_S / (mu_d N) of the paper's equal sharing on the same pressure.
    pub equal_friction_drop: f64,
}

/// The name of a slip weakening in the legend.
fn weakening_label(dc: f64) -> String {
    if dc == 0.0 {
        "elastic, instant drop".to_string()
    } else {
        format!("elastic, d_c = {} nm", tick_label(&(dc * 1e9)))
    }
}

/// One panel per load (in increasing order): the friction drop against the pixel size \[nm]
/// (logarithmic), a line with markers per slip weakening (the instant drop first) and equal
/// sharing's drop dashed. `mu_d` is the law's dynamic coefficient, for the y label's μ_S.
pub fn sharing_convergence(points: &[ConvergencePoint], mu_d: f64) -> Grid {
    let panels = panels(points, mu_d);
    let columns = panels.len().max(1);
    Grid::new(panels, columns, (900 * columns as u32, 800))
}

/// The panels of [`sharing_convergence`].
fn panels(points: &[ConvergencePoint], mu_d: f64) -> Vec<Panel> {
    let sorted = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    };
    let loads = sorted(points.iter().map(|p| p.load_n).collect());
    let weakenings = sorted(points.iter().map(|p| p.slip_distance_m).collect());
    let pixels = sorted(points.iter().map(|p| p.pixel_size_m * 1e9).collect());
    let (x0, x1) = (pixels.first().copied().unwrap_or(1.0) / 1.25, pixels.last().copied().unwrap_or(1.0) * 1.25);
    // Room above the data for the legend (upper right), so that it covers no point.
    let drops = sorted(points.iter().map(|p| p.friction_drop).collect());
    let (lo, hi) = (drops.first().copied().unwrap_or(1.0), drops.last().copied().unwrap_or(1.0));
    let (y0, y1) = (lo - 0.05 * (hi - lo), hi + 0.8 * (hi - lo));
    loads
        .iter()
        .map(|&load| {
            let at_load: Vec<&ConvergencePoint> = points.iter().filter(|p| p.load_n == load).collect();
            let elements = sorted(at_load.iter().map(|p| p.contact_points as f64).collect());
            let mut panel = Panel::new(
                Axis::new("pixel size", "nm").log().range(x0, x1),
                Axis::dimensionless(&format!("friction drop F_S/(μ^D N) = μ_S/{}", tick_label(&mu_d))).range(y0, y1),
            )
            .title(format!(
                "{} mN: {}–{} elements",
                tick_label(&(load * 1e3)),
                elements.first().copied().unwrap_or(0.0),
                elements.last().copied().unwrap_or(0.0)
            ))
            .legend(LegendPosition::UpperRight);
            for (k, &dc) in weakenings.iter().enumerate() {
                let mut line: Vec<(f64, f64)> = at_load
                    .iter()
                    .filter(|p| p.slip_distance_m == dc)
                    .map(|p| (p.pixel_size_m * 1e9, p.friction_drop))
                    .collect();
                line.sort_by(|a, b| a.0.total_cmp(&b.0));
                let colour = style::PALETTE[k % style::PALETTE.len()];
                panel.push(Series::line(line.clone(), colour).label(weakening_label(dc)));
                panel.push(Series::scatter(line, Marker::Circle, colour));
            }
            let mut equal: Vec<(f64, f64)> =
                at_load.iter().map(|p| (p.pixel_size_m * 1e9, p.equal_friction_drop)).collect();
            equal.sort_by(|a, b| a.0.total_cmp(&b.0));
            equal.dedup();
            panel.push(Series::line(equal, style::GREY).dashed().label("equal sharing (the paper's model)"));
            panel
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::series::Shape;

    fn point(pixel_nm: f64, load_n: f64, dc_nm: f64, drop: f64) -> ConvergencePoint {
        ConvergencePoint {
            pixel_size_m: pixel_nm * 1e-9,
            load_n,
            slip_distance_m: dc_nm * 1e-9,
            contact_points: (1e6 * load_n * (41.5 / pixel_nm).powi(2)) as usize,
            friction_drop: drop,
            equal_friction_drop: 1.1,
        }
    }

    #[test]
    fn one_panel_per_load_with_a_line_per_weakening() {
        let mut points = Vec::new();
        for pixel in [41.5, 20.75, 10.375] {
            for load in [4e-4, 1e-4] {
                points.push(point(pixel, load, 2.0, 1.16));
                points.push(point(pixel, load, 0.0, 1.0 + pixel / 1000.0));
            }
        }
        let panels = panels(&points, 0.4);
        // Loads in increasing order, each titled with its element counts at the three pixels.
        let titles: Vec<&str> = panels.iter().map(|p| p.title.as_deref().unwrap()).collect();
        assert_eq!(titles, ["0.1 mN: 100–1600 elements", "0.4 mN: 400–6400 elements"]);
        for panel in &panels {
            let labels: Vec<&str> = panel.series.iter().filter_map(|s| s.label.as_deref()).collect();
            // The instant drop first, then d_c, then equal sharing.
            assert_eq!(labels, ["elastic, instant drop", "elastic, d_c = 2 nm", "equal sharing (the paper's model)"]);
            let ends: Vec<(f64, f64)> = panel
                .series
                .iter()
                .filter_map(|s| match &s.shape {
                    Shape::Line { points, .. } => Some((points[0].0, points[points.len() - 1].0)),
                    _ => None,
                })
                .collect();
            // Each line runs over the three pixel sizes [nm], finest first.
            assert!(ends.iter().all(|&(a, b)| a == 10.375 && b == 41.5), "{ends:?}");
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sharing-convergence.png");
        crate::plot::draw::write_figure(&path, &sharing_convergence(&points, 0.4)).unwrap();
        let svg = std::fs::read_to_string(path.with_extension("svg")).unwrap();
        assert!(svg.contains("pixel size [nm]") && svg.contains("0.4 mN: 400–6400 elements"));
    }
}
