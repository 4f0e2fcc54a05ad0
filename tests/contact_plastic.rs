//! Elastic–perfectly-plastic contact (0 ≤ p ≤ H) on the Tamaas fixture's rough sphere: the
//! conditions of the saturated-pressure problem checked on the result, the fully plastic limit,
//! and the elastic solve when the hardness is out of reach.

use std::path::Path;

use asperity::contact::{Boundary, ContactSolver, Influence, SolverOptions};
use ndarray::Array2;
use ndarray_npy::read_npy;

const E_STAR: f64 = 1.39e11;
const SIZE: (f64, f64) = (8e-6, 6e-6);

fn heights() -> Array2<f64> {
    read_npy(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tamaas/heights.npy")).unwrap()
}

fn solve(h: &Array2<f64>, load: f64, hardness: Option<f64>) -> ContactSolver {
    let mut s =
        ContactSolver::new(h.as_slice().unwrap(), h.dim(), SIZE, E_STAR, Boundary::Periodic, SolverOptions::default())
            .unwrap();
    s.set_hardness(hardness).unwrap();
    s.solve(load, |_, _| {}).unwrap();
    s
}

fn pixel_area(h: &Array2<f64>) -> f64 {
    SIZE.0 * SIZE.1 / h.len() as f64
}

fn rms(h: &Array2<f64>) -> f64 {
    let mean = h.mean().unwrap();
    (h.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / h.len() as f64).sqrt()
}

/// The gap u − h − ḡ of a pressure map, with ḡ the mean over the free points (0 < p < H).
fn gap(h: &Array2<f64>, p: &[f64], hardness: f64) -> Vec<f64> {
    let (ny, nx) = h.dim();
    let mut u = vec![0.0; p.len()];
    Influence::periodic(ny, nx, SIZE, E_STAR).apply(p, &mut u);
    let g: Vec<f64> = u.iter().zip(h.iter()).map(|(u, h)| u - h).collect();
    let free: Vec<f64> = g.iter().zip(p).filter(|(_, p)| **p > 0.0 && **p < hardness).map(|(g, _)| *g).collect();
    let mean = free.iter().sum::<f64>() / free.len() as f64;
    g.iter().map(|g| g - mean).collect()
}

/// Gap zero where 0 < p < H, non-negative where p = 0, penetration only where p = H; the load
/// carried, no pressure above H, and the saturated points really penetrating.
#[test]
fn complementarity_holds_on_the_result() {
    let h = heights();
    let load = 2e-3;
    let peak = solve(&h, load, None).pressure().iter().copied().fold(0.0, f64::max);
    let hardness = 0.3 * peak;
    let s = solve(&h, load, Some(hardness));
    let p = s.pressure();
    let g = gap(&h, p, hardness);
    let scale = rms(&h);
    let (mut free, mut saturated, mut deepest) = (0, 0, 0.0f64);
    for (i, (&p, &g)) in p.iter().zip(&g).enumerate() {
        assert!((0.0..=hardness).contains(&p), "point {i}: p = {p} outside [0, {hardness}]");
        if p == 0.0 {
            assert!(g >= -1e-6 * scale, "point {i} out of contact penetrates: gap {g:e} m");
        } else if p == hardness {
            assert!(g <= 1e-6 * scale, "saturated point {i} has an open gap {g:e} m");
            saturated += 1;
            deepest = deepest.min(g);
        } else {
            assert!(g.abs() <= 1e-7 * scale, "free point {i} (p = {p:e}) has gap {g:e} m");
            free += 1;
        }
    }
    assert!(saturated >= 20 && free >= 20, "{saturated} saturated, {free} free points");
    assert!(deepest < -1e-3 * scale, "the saturated points hardly penetrate: {deepest:e} m");
    let force = p.iter().sum::<f64>() * pixel_area(&h);
    assert!((force / load - 1.0).abs() < 1e-10, "force {force:e} N for {load:e} N");
    // The solver's own gap map says the same: zero on the free points, penetration on the
    // saturated ones.
    let reported = s.gap();
    for ((&p, &r), &g) in p.iter().zip(&reported).zip(&g) {
        let want = if p == 0.0 {
            g.max(0.0)
        } else if p == hardness {
            g.min(0.0)
        } else {
            0.0
        };
        assert!((r - want).abs() <= 1e-6 * scale, "reported gap {r:e} vs {want:e}");
    }
}

/// A hardness far below the elastic peak saturates nearly every contact point: the contact
/// area tends to N/H.
#[test]
fn fully_plastic_limit() {
    let h = heights();
    let load = 2e-3;
    let peak = solve(&h, load, None).pressure().iter().copied().fold(0.0, f64::max);
    let mut last = f64::INFINITY;
    for ratio in [0.1, 0.03, 0.01] {
        let hardness = ratio * peak;
        let s = solve(&h, load, Some(hardness));
        let p = s.pressure();
        let area = p.iter().filter(|p| **p > 0.0).count() as f64 * pixel_area(&h);
        let plastic = load / hardness;
        let excess = area / plastic - 1.0;
        let saturated = p.iter().filter(|p| **p == hardness).sum::<f64>() * pixel_area(&h) / load;
        assert!(excess >= -1e-9, "H = {ratio} × peak: area {area:e} m² below N/H = {plastic:e} m²");
        assert!(excess < last, "H = {ratio} × peak: area excess {excess} did not fall (was {last})");
        last = excess;
        if ratio == 0.01 {
            assert!(excess < 0.01, "area {area:e} m² vs N/H = {plastic:e} m²");
            assert!(saturated > 0.99, "saturated points carry {saturated} of the load");
        }
    }
}

/// With the hardness above the elastic peak nothing saturates: the elastic solution.
#[test]
fn unreachable_hardness_is_the_elastic_solve() {
    let h = heights();
    for load in [2e-4, 2e-3, 2e-2] {
        let elastic = solve(&h, load, None);
        let peak = elastic.pressure().iter().copied().fold(0.0, f64::max);
        let capped = solve(&h, load, Some(1.5 * peak));
        let (a, b) = (elastic.pressure(), capped.pressure());
        let diff = a.iter().zip(b).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
        let norm = a.iter().map(|a| a * a).sum::<f64>().sqrt();
        assert!(diff / norm < 1e-7, "load {load} N: relative L2 difference {:e}", diff / norm);
        assert_eq!(a.iter().zip(b).filter(|(a, b)| (**a > 0.0) != (**b > 0.0)).count(), 0, "load {load} N");
    }
}

/// A load the window cannot carry at the hardness is refused in one line.
#[test]
fn hardness_below_the_mean_pressure_is_refused() {
    let h = heights();
    let mut s =
        ContactSolver::new(h.as_slice().unwrap(), h.dim(), SIZE, E_STAR, Boundary::Periodic, SolverOptions::default())
            .unwrap();
    s.set_hardness(Some(1e9)).unwrap();
    let err = s.solve(1e9 * SIZE.0 * SIZE.1 * 1.01, |_, _| {}).unwrap_err().to_string();
    assert!(err.contains("--hardness") && err.contains("mean pressure") && !err.contains('\n'), "{err}");
    assert!(s.set_hardness(Some(-1.0)).is_err());
}
