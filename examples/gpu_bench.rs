//! The GPU normal solve against the CPU's on the same host (the benchmark that
//! `tools/gpu-check.sh` runs): the default rough ball (31.13 µm window, roughness on a 1.5 mm
//! sphere, seed 1), periodic, at one load (10 mN) and tolerance 1e-10, on N × N grids, each
//! solve cold. One Markdown row per grid: seconds, iterations, ms per iteration, the GPU's
//! memory in use during the solve (nvidia-smi), and the GPU's pressure against the CPU's.
//!
//! usage: gpu_bench [--cpu-up-to N] [--load NEWTONS] N...

use std::io::Write;
use std::process::Command;
use std::time::Instant;

use asperity::contact::{Boundary, ContactSolver, Convergence, Device, Material, SolverOptions};
use asperity::limits::Limits;
use asperity::topography::synth::SyntheticSurface;

fn main() {
    let mut args = std::env::args().skip(1);
    let (mut cpu_up_to, mut load, mut sizes) = (usize::MAX, 1e-2, Vec::new());
    while let Some(a) = args.next() {
        let mut value = || args.next().expect("a value after the option");
        match a.as_str() {
            "--cpu-up-to" => cpu_up_to = value().parse().expect("--cpu-up-to N"),
            "--load" => load = value().parse().expect("--load NEWTONS"),
            n => sizes.push(n.parse::<usize>().expect("a grid size")),
        }
    }
    let e_star = Material::SILICON.plane_strain_modulus();
    let threads = rayon::current_num_threads();
    println!(
        "| grid | CPU s ({threads} threads) | CPU it | GPU set-up s | GPU s | GPU it | GPU ms/it | GPU memory used | CPU/GPU | relative L2 | contact points differ |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for n in sizes {
        let started = Instant::now();
        let surface = SyntheticSurface { grid: (n, n), seed: 1, ..Default::default() };
        let heights: Vec<f64> =
            surface.generate_within(&Limits { max_points: 1 << 31 }).expect("surface").heights.iter().copied().collect();
        eprintln!("{n}²: surface in {:.1} s", started.elapsed().as_secs_f64());
        let convergence = Convergence { tolerance: 1e-10, ..SolverOptions::default().convergence };
        let options = SolverOptions { convergence, ..Default::default() };
        let cpu = (n <= cpu_up_to).then(|| {
            let mut s = ContactSolver::new(&heights, (n, n), surface.size, e_star, Boundary::Periodic, options).unwrap();
            let r = s.solve(load, |_, _| ()).unwrap();
            eprintln!("{n}²: CPU {} iterations, {:.2} s", r.iterations, r.seconds);
            (r, s.pressure().to_vec())
        });
        let set_up = Instant::now();
        let gpu_options = SolverOptions { device: Device::Gpu, ..options };
        let mut g = ContactSolver::new(&heights, (n, n), surface.size, e_star, Boundary::Periodic, gpu_options).unwrap();
        let set_up = set_up.elapsed().as_secs_f64();
        let r = g.solve(load, |_, _| ()).unwrap();
        let memory = Command::new("nvidia-smi")
            .args(["--query-gpu=memory.used", "--format=csv,noheader"])
            .output()
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
            .unwrap_or_default();
        let ms = 1e3 * r.seconds / r.iterations.max(1) as f64;
        let (cpu_s, cpu_it, ratio, error, differ) = match &cpu {
            Some((c, p)) => {
                let q = g.pressure();
                let d: f64 = q.iter().zip(p).map(|(a, b)| (a - b).powi(2)).sum();
                let error = (d / p.iter().map(|b| b * b).sum::<f64>()).sqrt();
                let differ = q.iter().zip(p).filter(|(a, b)| (**a > 0.0) != (**b > 0.0)).count();
                (
                    format!("{:.3}", c.seconds),
                    c.iterations.to_string(),
                    format!("{:.1}", c.seconds / r.seconds),
                    format!("{error:.1e}"),
                    differ.to_string(),
                )
            }
            None => ("-".into(), "-".into(), "-".into(), "-".into(), "-".into()),
        };
        println!(
            "| {n}² | {cpu_s} | {cpu_it} | {set_up:.2} | {:.3} | {} | {ms:.2} | {memory} | {ratio} | {error} | {differ} |",
            r.seconds, r.iterations
        );
        std::io::stdout().flush().unwrap();
    }
}
