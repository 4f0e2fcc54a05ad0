//! Calibration of the default study's synthetic balls against the paper's description of its
//! interface (Fig. S4): per ball, RMS height and slope of the compound roughness, and at each
//! load the contact elements, patches, the largest distance between patch centres and the peak
//! pressure. `cargo run --release --example calibrate -- H ROLLOFF CUTOFF RMS [LOAD…]`
//! (lengths in m, loads in N).

use asperity::contact::{patches, Boundary, ContactSolver, Convergence, SolverOptions};
use asperity::topography::resample::compound;
use asperity::topography::stats::{height_stats, rms_slope};
use asperity::topography::synth::{Amplitude, Cap, CapShape, SelfAffine, SyntheticSurface};

fn main() -> asperity::Result<()> {
    let a: Vec<f64> = std::env::args().skip(1).map(|s| s.parse().expect("numbers")).collect();
    let (hurst, rolloff, cutoff, rms) = (a[0], a[1], a[2], a[3]);
    let loads: Vec<f64> = if a.len() > 4 { a[4..].to_vec() } else { vec![1e-4, 1e-3, 1e-2] };
    let size = (31.13e-6, 31.13e-6);
    let grid = (1500, 1500);
    for seed in 1..=3u64 {
        let ball = SyntheticSurface {
            size,
            grid,
            roughness: Some(SelfAffine {
                hurst,
                rolloff_wavelength: Some(rolloff),
                short_cutoff_wavelength: (cutoff > 0.0).then_some(cutoff),
                long_cutoff_wavelength: None,
                amplitude: Amplitude::RmsHeight(rms),
            }),
            cap: Some(Cap { radius: 1.5e-3, shape: CapShape::Sphere }),
            seed,
        }
        .generate()?;
        let wafer =
            SyntheticSurface { size, grid, roughness: Some(SelfAffine::silicon_wafer()), cap: None, seed: 100 + seed }
                .generate()?;
        let topo = compound(&ball, &wafer)?;
        let stats = height_stats(&topo)?;
        let slope = rms_slope(&topo)?;
        print!("ball-{seed}: rms {:.1} nm, slope {:.4}", stats.rms_height * 1e9, slope);
        let shape = topo.heights.dim();
        let h = topo.heights.as_standard_layout();
        let e_star = 130e9 / (1.0 - 0.26 * 0.26);
        let convergence = Convergence { tolerance: 1e-8, max_iterations: 20000 };
        let opts = SolverOptions { convergence, ..Default::default() };
        let mut solver = ContactSolver::new(h.as_slice().unwrap(), shape, size, e_star, Boundary::Periodic, opts)?;
        let dx = size.0 / shape.1 as f64;
        for &load in &loads {
            let report = solver.solve(load, |_, _| ())?;
            let p = solver.pressure();
            let mask: Vec<bool> = p.iter().map(|v| *v > 0.0).collect();
            let (labels, sizes) = patches::label(&mask, shape, true);
            let mut cx = vec![(0.0, 0.0, 0.0); sizes.len() + 1];
            for (i, l) in labels.iter().enumerate() {
                if *l > 0 {
                    let c = &mut cx[*l as usize];
                    c.0 += (i % shape.1) as f64;
                    c.1 += (i / shape.1) as f64;
                    c.2 += 1.0;
                }
            }
            let centres: Vec<(f64, f64)> = cx[1..].iter().map(|c| (c.0 / c.2, c.1 / c.2)).collect();
            let mut spread: f64 = 0.0;
            for a in &centres {
                for b in &centres {
                    spread = spread.max((a.0 - b.0).hypot(a.1 - b.1));
                }
            }
            let pmax = p.iter().cloned().fold(0.0, f64::max);
            let n = mask.iter().filter(|m| **m).count();
            print!(
                " | {:.0e} N: {n} el, {} patches, spread {:.1} µm, pmax {:.1} GPa ({} it)",
                load,
                sizes.len(),
                spread * dx * 1e6,
                pmax / 1e9,
                report.iterations
            );
        }
        println!();
    }
    Ok(())
}
