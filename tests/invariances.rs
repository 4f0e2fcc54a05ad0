//! Symmetries of the elastic contact and of the onset of sliding (proptest), on small random
//! periodic surfaces: a periodic roll, a flip along x or y and a transpose (the window's sides
//! swapped with the grid's) move the pressure field with the surface and leave the contact
//! area, the force, the largest pressure and the onset's static force unchanged; heights and
//! load scaled by the same factor scale the pressures by it on the same contact set (the
//! elastic solve is linear: no hardness cap).

use std::f64::consts::PI;

use asperity::contact::{full_contact_load, summarize, Boundary, ContactSolver, SolverOptions};
use asperity::friction::{ElementLoads, FrictionLaw, Onset};
use ndarray::{s, Array2};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;

/// Effective modulus E* [Pa] (silicon against a rigid flat).
const E_STAR: f64 = 1.39e11;

/// Relative agreement of two solves of the same problem on transformed grids: the solver's
/// iterations see the same numbers in another order, so only rounding separates them (measured:
/// at most 1e-14 of the largest pressure); a transform applied wrongly (a transpose without its
/// sides swapped) moves pressures by 40 % to 75 % of it.
const SAME: f64 = 1e-9;

/// A random periodic surface: a few Fourier modes of the window, its heights [m] scaled to
/// `rms`, on a grid of `ny` × `nx` points over `lx` × `ly` [m].
#[derive(Debug, Clone)]
struct Surface {
    heights: Array2<f64>,
    size: (f64, f64),
}

prop_compose! {
    fn surface()(
        ny in 16usize..=32,
        nx in 16usize..=32,
        lx in 1e-6..4e-6f64,
        ly in 1e-6..4e-6f64,
        rms in 1e-9..5e-9f64,
        modes in prop::collection::vec((-3i32..=3, -3i32..=3, 0.2..1.0f64, 0.0..2.0 * PI), 3..8),
    ) -> Surface {
        let mut h = Array2::from_shape_fn((ny, nx), |(j, i)| {
            modes.iter().map(|&(kx, ky, a, phase)| {
                a * (2.0 * PI * (kx as f64 * i as f64 / nx as f64 + ky as f64 * j as f64 / ny as f64) + phase).cos()
            }).sum::<f64>()
        });
        let mean = h.mean().unwrap();
        h.mapv_inplace(|v| v - mean);
        let norm = (h.mapv(|v| v * v).mean().unwrap()).sqrt().max(f64::MIN_POSITIVE);
        h.mapv_inplace(|v| v * rms / norm);
        Surface { heights: h, size: (lx, ly) }
    }
}

/// What a solve gives: the pressure field [Pa], contact area [m²], force Σ p ΔxΔy [N] and the
/// largest pressure [Pa].
struct Contact {
    pressure: Array2<f64>,
    area: f64,
    points: usize,
    force: f64,
    max_pressure: f64,
}

fn solve(heights: &Array2<f64>, (lx, ly): (f64, f64), load: f64) -> Contact {
    let shape = heights.dim();
    let h = heights.as_standard_layout();
    let h = h.as_slice().unwrap();
    let mut s = ContactSolver::new(h, shape, (lx, ly), E_STAR, Boundary::Periodic, SolverOptions::default()).unwrap();
    s.solve(load, |_, _| {}).unwrap();
    let pressure = Array2::from_shape_vec(shape, s.pressure().to_vec()).unwrap();
    let summary = summarize(s.pressure(), shape, (lx, ly), Boundary::Periodic, None);
    let pixel = lx * ly / (shape.0 * shape.1) as f64;
    Contact {
        force: pressure.sum() * pixel,
        area: summary.contact_area,
        points: summary.contact_points,
        max_pressure: summary.max_pressure,
        pressure,
    }
}

/// A load between 5 % and 50 % of full contact's [N]: partial contact of a few patches.
fn partial_load(surface: &Surface, fraction: f64) -> f64 {
    let h = surface.heights.as_standard_layout();
    fraction * full_contact_load(h.as_slice().unwrap(), surface.heights.dim(), surface.size, E_STAR)
}

/// `a` rolled periodically by (dy, dx) points: a[j, i] moves to [j + dy, i + dx].
fn roll(a: &Array2<f64>, (dy, dx): (usize, usize)) -> Array2<f64> {
    let (ny, nx) = a.dim();
    Array2::from_shape_fn((ny, nx), |(j, i)| a[[(j + ny - dy % ny) % ny, (i + nx - dx % nx) % nx]])
}

/// A map of a grid onto another, of the same points.
type Transform = fn(&Array2<f64>) -> Array2<f64>;

fn flip_x(a: &Array2<f64>) -> Array2<f64> {
    a.slice(s![.., ..;-1]).to_owned()
}

fn flip_y(a: &Array2<f64>) -> Array2<f64> {
    a.slice(s![..;-1, ..]).to_owned()
}

fn transpose(a: &Array2<f64>) -> Array2<f64> {
    a.t().as_standard_layout().to_owned()
}

fn close(a: f64, b: f64, tolerance: f64) -> bool {
    (a - b).abs() <= tolerance * a.abs().max(b.abs())
}

/// `got`, a solve of the transformed surface, against `want`, the original's with its field
/// transformed: fields within [`SAME`] of the largest pressure, the same contact set.
fn same_contact(got: &Contact, want: &Contact, field: &Array2<f64>, what: &str) -> Result<(), TestCaseError> {
    prop_assert_eq!(got.pressure.dim(), field.dim(), "{}: field shape", what);
    let worst = got.pressure.iter().zip(field.iter()).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    prop_assert!(
        worst <= SAME * want.max_pressure,
        "{what}: pressures differ by {worst:e} Pa of {:e}",
        want.max_pressure
    );
    let set = |p: &Array2<f64>| p.iter().map(|v| *v > 0.0).collect::<Vec<_>>();
    prop_assert!(set(&got.pressure) == set(field), "{what}: another contact set");
    prop_assert_eq!(got.points, want.points, "{}: contact points", what);
    prop_assert!(close(got.area, want.area, 1e-12), "{what}: area {:e} vs {:e} m²", got.area, want.area);
    prop_assert!(close(got.force, want.force, SAME), "{what}: force {:e} vs {:e} N", got.force, want.force);
    prop_assert!(
        close(got.max_pressure, want.max_pressure, SAME),
        "{what}: largest pressure {:e} vs {:e} Pa",
        got.max_pressure,
        want.max_pressure
    );
    Ok(())
}

/// The onset's static force [N] on the pressure field `p` [Pa] of pixels of `pixel_area` [m²].
fn static_force(p: &Array2<f64>, pixel_area: f64) -> f64 {
    let law = FrictionLaw::new(0.6, 0.4).unwrap();
    Onset::new(&ElementLoads::from_pressure(p, pixel_area).unwrap(), &law).static_force
}

proptest! {
    // A fixed seed: a failure reproduces on every run and machine; 24 cases of five solves on
    // grids of at most 32² take about a second in release.
    #![proptest_config(ProptestConfig { cases: 24, rng_seed: RngSeed::Fixed(0x5eed), ..ProptestConfig::default() })]

    #[test]
    fn contact_and_onset_follow_a_roll_a_flip_and_a_transpose(
        surface in surface(),
        fraction in 0.05..0.5f64,
        shift in (0usize..32, 0usize..32),
    ) {
        let (lx, ly) = surface.size;
        let (ny, nx) = surface.heights.dim();
        let load = partial_load(&surface, fraction);
        let base = solve(&surface.heights, surface.size, load);
        prop_assert!(close(base.force, load, 1e-9), "force {:e} vs load {:e} N", base.force, load);
        let pixel = lx * ly / (nx * ny) as f64;
        let fs = static_force(&base.pressure, pixel);

        let shift = (shift.0 % ny, shift.1 % nx);
        let cases: [(&str, Transform, (f64, f64)); 3] =
            [("flip along x", flip_x, (lx, ly)), ("flip along y", flip_y, (lx, ly)), ("transpose", transpose, (ly, lx))];
        let rolled = (format!("roll by {shift:?}"), roll(&surface.heights, shift), roll(&base.pressure, shift), (lx, ly));
        let transformed = cases.iter().map(|(what, f, size)| (what.to_string(), f(&surface.heights), f(&base.pressure), *size));
        for (what, heights, field, size) in std::iter::once(rolled).chain(transformed) {
            let got = solve(&heights, size, load);
            same_contact(&got, &base, &field, &what)?;
            // The onset of the moved field is the original's: it sees the same forces.
            let moved = static_force(&field, size.0 * size.1 / (nx * ny) as f64);
            prop_assert!(close(moved, fs, 1e-12), "{what}: F_S of the moved field {moved:e} vs {fs:e} N");
            let solved = static_force(&got.pressure, size.0 * size.1 / (nx * ny) as f64);
            prop_assert!(close(solved, fs, SAME), "{what}: F_S {solved:e} vs {fs:e} N");
        }
    }

    #[test]
    fn heights_and_load_scaled_together_scale_the_pressures(
        surface in surface(),
        fraction in 0.05..0.5f64,
        scale in 0.1..10.0f64,
    ) {
        let load = partial_load(&surface, fraction);
        let base = solve(&surface.heights, surface.size, load);
        let got = solve(&surface.heights.mapv(|h| h * scale), surface.size, load * scale);
        let want = Contact {
            pressure: base.pressure.mapv(|p| p * scale),
            force: base.force * scale,
            max_pressure: base.max_pressure * scale,
            ..base
        };
        same_contact(&got, &want, &want.pressure, &format!("heights and load × {scale}"))?;
    }
}
