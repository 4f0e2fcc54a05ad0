//! The convergence figure of `tools/sharing-convergence.sh`: reads its CSV (one row per pixel
//! size × load × slip weakening) and draws the friction drop against the pixel size, one panel
//! per load. `cargo run --release --example sharing_convergence -- CSV FIGURE.png` (the SVG is
//! written beside the PNG).

use std::path::PathBuf;

use asperity::plot::{sharing_convergence, write_figure, ConvergencePoint};
use asperity::{Error, Result};

fn main() -> Result<()> {
    let args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    let [csv, png] = &args[..] else {
        return Err(Error::invalid("arguments", "give CSV FIGURE.png"));
    };
    let mut reader = csv::Reader::from_path(csv).map_err(|e| Error::file(csv, e.to_string()))?;
    let header = reader.headers().map_err(|e| Error::file(csv, e.to_string()))?.clone();
    let column =
        |name: &str| header.iter().position(|h| h == name).ok_or_else(|| Error::file(csv, format!("no column {name}")));
    let (pixel, load, dc, points, mu, drop, equal) = (
        column("pixel_size_m")?,
        column("load_n")?,
        column("slip_distance_m")?,
        column("contact_points")?,
        column("static_coefficient")?,
        column("friction_drop")?,
        column("equal_friction_drop")?,
    );
    let (mut rows, mut mu_d) = (Vec::new(), None);
    for record in reader.records() {
        let r = record.map_err(|e| Error::file(csv, e.to_string()))?;
        let num = |i: usize| r[i].parse::<f64>().map_err(|e| Error::file(csv, format!("{}: {e}", &r[i])));
        // mu_d = μ_S / drop, the same on every row (one law).
        mu_d.get_or_insert(num(mu)? / num(drop)?);
        rows.push(ConvergencePoint {
            pixel_size_m: num(pixel)?,
            load_n: num(load)?,
            slip_distance_m: num(dc)?,
            contact_points: num(points)? as usize,
            friction_drop: num(drop)?,
            equal_friction_drop: num(equal)?,
        });
    }
    let mu_d = mu_d.ok_or_else(|| Error::file(csv, "no rows"))?;
    // Rounded as the law states it (0.4, not 0.39999999999999997).
    let mu_d = (mu_d * 1e6).round() / 1e6;
    let svg = write_figure(png, &sharing_convergence(&rows, mu_d))?;
    println!("wrote {} and {}", png.display(), svg.display());
    Ok(())
}
