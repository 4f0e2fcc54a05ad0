//! Sliding onset with elastic interaction: the Cerruti operator against closed forms, the
//! constrained tangential solve against Cattaneo–Mindlin, the rough-contact stiffness ratio,
//! the limits in which the elastic onset must give the local law or equal sharing, and the
//! onset against an independent implementation on small rough contacts.

use asperity::contact::{
    Boundary, ContactSolver, Material, ShearCompliance, SolverOptions, TangentialInfluence, TangentialOptions,
    TangentialSolver,
};
use asperity::friction::{
    elastic_onset, element_stiffness, ramp_force, spring_slider_onset, ElementLoads, FrictionLaw, Onset, SlideClass,
    SlipLaw, Weakening, PEAK_TOLERANCE,
};
use ndarray::Array2;
use std::f64::consts::PI;

const SI: Material = Material { youngs: 130e9, poisson: 0.26 };

fn shear_modulus(m: &Material) -> f64 {
    m.youngs / (2.0 * (1.0 + m.poisson))
}

#[test]
fn periodic_cerruti_on_sinusoids() {
    // q_x = cos(k x): u_x = (1 − ν)/(G k) cos(k x), u_y = 0; q_x = cos(k y): u_x = cos(k y)/(G k).
    let (ny, nx, l) = (16, 32, 4e-6);
    let c = ShearCompliance::of(&[SI]);
    let g = shear_modulus(&SI);
    let mut op = TangentialInfluence::periodic(ny, nx, (l, l / 2.0), c);
    let k = 2.0 * PI * 4.0 / l;
    for along_x in [true, false] {
        let q: Vec<f64> = (0..ny * nx)
            .map(|i| {
                if along_x {
                    (k * (i % nx) as f64 * l / nx as f64).cos()
                } else {
                    (k * (i / nx) as f64 * l / nx as f64).cos()
                }
            })
            .collect();
        let zero = vec![0.0; ny * nx];
        let (mut ux, mut uy) = (vec![0.0; ny * nx], vec![0.0; ny * nx]);
        op.apply([&q, &zero], [&mut ux, &mut uy]);
        let amp = if along_x { (1.0 - SI.poisson) / (g * k) } else { 1.0 / (g * k) };
        for i in 0..ny * nx {
            assert!((ux[i] - amp * q[i]).abs() < 1e-10 * amp, "u_x at {i}: {} vs {}", ux[i], amp * q[i]);
            assert!(uy[i].abs() < 1e-10 * amp, "u_y at {i}: {}", uy[i]);
        }
    }
}

#[test]
fn free_cerruti_far_field_is_the_point_force() {
    // One sheared pixel seen from afar: Cerruti's point force Q = q·a,
    // u_x = Q/(2πG) [(1 − ν)/ρ + ν x²/ρ³], u_y = Q/(2πG) ν x y/ρ³.
    let (n, l) = (96, 96e-6);
    let dx = l / n as f64;
    let c = ShearCompliance::of(&[SI]);
    let g = shear_modulus(&SI);
    let mut op = TangentialInfluence::free(n, n, (l, l), c);
    let mut qx = vec![0.0; n * n];
    qx[0] = 1e6;
    let zero = vec![0.0; n * n];
    let (mut ux, mut uy) = (vec![0.0; n * n], vec![0.0; n * n]);
    op.apply([&qx, &zero], [&mut ux, &mut uy]);
    let force = 1e6 * dx * dx;
    for &(i, j) in &[(0usize, 80usize), (60, 45), (90, 10), (70, 70)] {
        let (x, y) = (j as f64 * dx, i as f64 * dx);
        let r = x.hypot(y);
        let want_x = force / (2.0 * PI * g) * ((1.0 - SI.poisson) / r + SI.poisson * x * x / r.powi(3));
        let want_y = force / (2.0 * PI * g) * SI.poisson * x * y / r.powi(3);
        assert!((ux[i * n + j] - want_x).abs() < 1e-3 * want_x, "u_x at ({i},{j})");
        assert!((uy[i * n + j] - want_y).abs() < 1e-3 * want_x, "u_y at ({i},{j})");
    }
    // And y traction gives the mirror image.
    let (mut vx, mut vy) = (vec![0.0; n * n], vec![0.0; n * n]);
    op.apply([&zero, &qx], [&mut vx, &mut vy]);
    for i in 0..n {
        for j in 0..n {
            assert!((vy[i * n + j] - ux[j * n + i]).abs() < 1e-12 * ux[0], "mirror at ({i},{j})");
            assert!((vx[i * n + j] - uy[j * n + i]).abs() < 1e-12 * ux[0], "cross at ({i},{j})");
        }
    }
}

#[test]
fn box_operator_is_the_window_operator_inside_the_box() {
    // Tractions inside a box of the window: the box operator (padded grid, or the periodic
    // grid along an axis where the box is more than half the window, or along both) gives the displacements
    // of the whole window's operator at every point of the box.
    let (ny, nx, l) = (48, 64, 6.4e-6);
    let size = (l, l * ny as f64 / nx as f64);
    let c = ShearCompliance::of(&[SI]);
    for (boundary, (by, bx), (y0, x0)) in [
        (Boundary::Periodic, (9, 13), (20, 30)),
        (Boundary::Periodic, (30, 7), (5, 50)),
        (Boundary::Periodic, (30, 40), (10, 12)),
        (Boundary::Free, (9, 13), (31, 2)),
    ] {
        let mut whole = match boundary {
            Boundary::Periodic => TangentialInfluence::periodic(ny, nx, size, c),
            Boundary::Free => TangentialInfluence::free(ny, nx, size, c),
        };
        let mut part = TangentialInfluence::window((ny, nx), size, c, boundary, (by, bx));
        let (sy, sx) = part.shape();
        assert!(sy <= ny && sx <= nx && (sy, sx) != (ny, nx), "{boundary:?} {by}×{bx}: shape {sy}×{sx}");
        let (y0, x0) = (y0.min(ny - sy), x0.min(nx - sx));
        let value = |i: usize, j: usize, k: usize| 1e6 * (((i * 31 + j * 17 + k * 7) % 23) as f64 - 11.0);
        let (mut qx, mut qy) = (vec![0.0; ny * nx], vec![0.0; ny * nx]);
        let (mut px, mut py) = (vec![0.0; sy * sx], vec![0.0; sy * sx]);
        for i in 0..by {
            for j in 0..bx {
                qx[(y0 + i) * nx + x0 + j] = value(i, j, 0);
                qy[(y0 + i) * nx + x0 + j] = value(i, j, 1);
                px[i * sx + j] = value(i, j, 0);
                py[i * sx + j] = value(i, j, 1);
            }
        }
        let (mut ux, mut uy) = (vec![0.0; ny * nx], vec![0.0; ny * nx]);
        whole.apply([&qx, &qy], [&mut ux, &mut uy]);
        let (mut vx, mut vy) = (vec![0.0; sy * sx], vec![0.0; sy * sx]);
        part.apply([&px, &py], [&mut vx, &mut vy]);
        let scale = ux.iter().chain(&uy).fold(0.0f64, |m, u| m.max(u.abs()));
        for i in 0..by {
            for j in 0..bx {
                let (w, b) = ((y0 + i) * nx + x0 + j, i * sx + j);
                assert!((ux[w] - vx[b]).abs() < 1e-10 * scale, "{boundary:?} u_x at ({i},{j}): {} vs {}", ux[w], vx[b]);
                assert!((uy[w] - vy[b]).abs() < 1e-10 * scale, "{boundary:?} u_y at ({i},{j}): {} vs {}", uy[w], vy[b]);
            }
        }
    }
}

#[test]
fn single_precision_operator_is_the_double_within_its_round_off() {
    // The loose solves apply K in single precision: it must be the same operator to about
    // f32's round-off (and really single: not bit for bit the double).
    let (ny, nx, l) = (96, 128, 12.8e-6);
    let size = (l, l * ny as f64 / nx as f64);
    let c = ShearCompliance::of(&[SI]);
    for (boundary, (by, bx)) in
        [(Boundary::Periodic, (96, 128)), (Boundary::Periodic, (60, 90)), (Boundary::Free, (20, 30))]
    {
        let mut double = TangentialInfluence::window((ny, nx), size, c, boundary, (by, bx));
        let mut single = double.single();
        let (sy, sx) = double.shape();
        let value = |i: usize, k: usize| 1e8 * ((((i * 7919 + k * 31) % 101) as f64 / 101.0) - 0.4);
        let (qx, qy): (Vec<f64>, Vec<f64>) = (0..sy * sx).map(|i| (value(i, 0), value(i, 1))).unzip();
        let (mut ux, mut uy, mut vx, mut vy) =
            (vec![0.0; sy * sx], vec![0.0; sy * sx], vec![0.0; sy * sx], vec![0.0; sy * sx]);
        double.apply([&qx, &qy], [&mut ux, &mut uy]);
        single.apply([&qx, &qy], [&mut vx, &mut vy]);
        let diff: f64 = ux.iter().zip(&vx).chain(uy.iter().zip(&vy)).map(|(a, b)| (a - b).powi(2)).sum();
        let norm: f64 = ux.iter().chain(&uy).map(|a| a * a).sum();
        let relative = (diff / norm).sqrt();
        assert!(relative < 1e-6 && relative > 1e-10, "{boundary:?} {by}×{bx}: relative L2 difference {relative:.2e}");
    }
}

/// A Hertz contact on a free boundary: elastic sphere (radius R) of `material` on a rigid flat.
struct Hertz {
    material: Material,
    pressure: Vec<f64>,
    n: usize,
    l: f64,
    load: f64,
    a: f64,
    p0: f64,
}

fn hertz(n: usize, material: Material) -> Hertz {
    let (l, radius): (f64, f64) = (10e-6, 1e-3);
    let e_star = material.plane_strain_modulus();
    let a = 0.3 * l;
    let load = 4.0 * e_star * a.powi(3) / (3.0 * radius);
    let dx = l / n as f64;
    let heights: Vec<f64> = (0..n * n)
        .map(|i| {
            let (x, y) = (((i % n) as f64 + 0.5 - n as f64 / 2.0) * dx, ((i / n) as f64 + 0.5 - n as f64 / 2.0) * dx);
            -(x * x + y * y) / (2.0 * radius)
        })
        .collect();
    let mut solver =
        ContactSolver::new(&heights, (n, n), (l, l), e_star, Boundary::Free, SolverOptions::default()).unwrap();
    solver.solve(load, |_, _| {}).unwrap();
    Hertz { material, pressure: solver.pressure().to_vec(), n, l, load, a, p0: 3.0 * load / (2.0 * PI * a * a) }
}

/// A partial-slip state of the Hertz contact against Cattaneo–Mindlin, as fractions: of a
/// pixel (stick radius), of δ, and of the peak shear μ p0.
#[derive(Debug)]
struct Mindlin {
    /// Stick radius (the radius of a disk of the stuck points' area) minus c [pixels].
    stick_radius: f64,
    /// Relative error of the displacement δ.
    displacement: f64,
    /// Largest |q − q_CM| (both components) on the pixels the stick circle r = c crosses
    /// (centre within half a diagonal of it), and on all the others.
    shear_on_circle: f64,
    shear_off_circle: f64,
    /// Root mean square of |q − q_CM| over the contact.
    shear_rms: f64,
    /// Largest |q_y| (zero in the closed form).
    shear_y: f64,
}

/// Ramp the force to Q/μN = `ratio` under Coulomb friction μ and compare with Cattaneo–Mindlin:
/// c = a(1 − Q/μN)^{1/3}, δ = 3μN(2 − ν)/(16 G a) [1 − (1 − Q/μN)^{2/3}], q_x = μ p0/a
/// [√(a² − r²) − √(c² − r²)] (the second term inside the stick zone), q_y = 0. The first term,
/// μ times the Hertz pressure, is taken with the normal solve's own pressure: that isolates the
/// tangential solve from the normal solve's pixels at the contact edge.
fn mindlin(h: &Hertz, solver: &mut TangentialSolver, mu: f64, ratio: f64) -> Mindlin {
    let (g, nu) = (shear_modulus(&h.material), h.material.poisson);
    let dx = h.l / h.n as f64;
    let q = ratio * mu * h.load;
    let (state, _) = ramp_force(solver, mu, q).unwrap();
    assert!((state.point.force_n - q).abs() < 1e-5 * q);
    let c = h.a * (1.0 - ratio).powf(1.0 / 3.0);
    let stuck = state.classes.iter().filter(|k| **k == SlideClass::Stuck).count();
    let delta = 3.0 * mu * h.load * (2.0 - nu) / (16.0 * g * h.a) * (1.0 - (1.0 - ratio).powf(2.0 / 3.0));
    let peak = mu * h.p0;
    let (mut on, mut off, mut sum, mut qy) = (0.0f64, 0.0f64, 0.0, 0.0f64);
    for (k, &i) in solver.points().iter().enumerate() {
        let (x, y) =
            (((i % h.n) as f64 + 0.5 - h.n as f64 / 2.0) * dx, ((i / h.n) as f64 + 0.5 - h.n as f64 / 2.0) * dx);
        let r2 = x * x + y * y;
        let stick = mu * h.p0 / h.a * (c * c - r2).max(0.0).sqrt();
        let [qx_num, qy_num] = state.traction[k];
        let e = (qx_num - (mu * solver.pressure()[k] - stick)).hypot(qy_num) / peak;
        if (r2.sqrt() - c).abs() < dx / 2f64.sqrt() {
            on = on.max(e);
        } else {
            off = off.max(e);
        }
        sum += e * e;
        qy = qy.max(qy_num.abs() / peak);
    }
    Mindlin {
        stick_radius: ((stuck as f64 / PI).sqrt() * dx - c) / dx,
        displacement: (state.point.displacement_m - delta) / delta,
        shear_on_circle: on,
        shear_off_circle: off,
        shear_rms: (sum / solver.points().len() as f64).sqrt(),
        shear_y: qy,
    }
}

fn mindlin_solver(h: &Hertz) -> TangentialSolver {
    let options = TangentialOptions { tolerance: 1e-9, ..Default::default() };
    let compliance = ShearCompliance::of(&[h.material]);
    TangentialSolver::new(&h.pressure, (h.n, h.n), (h.l, h.l), compliance, Boundary::Free, options).unwrap()
}

/// At ν = 0, where the closed form is exact (Cerruti's kernel is then isotropic: q_y = 0 and a
/// circular stick zone; for ν ≠ 0 neither holds, Munisamy, Hills & Nowell 1994), at 384²
/// (a = 115.2 px), one test per Q/μN so that the harness runs them side by side. Measured at
/// Q/μN = 0.25, 0.5, 0.75: stick radius 0.15, 0.15, 0.09 px off; δ 3e-7, 9e-7, 2e-7; shear
/// within 1.65, 1.23, 1.63 % of its peak on the pixels the stick circle crosses, 0.39, 0.43,
/// 0.34 % on the others, RMS 0.087, 0.072, 0.057 %. So the target of 2 % of the peak holds on
/// every contact pixel (asserted), and off the circle by far (asserted 0.6 %).
///
/// The error on the circle is the pixel-wise stick boundary: a pixel is stuck or slipping as a
/// whole, and the worst one (at 128², Q/μN 0.25 and 0.5) is stuck with its centre 0.02–0.03 px
/// outside c, where the closed form is 0, carrying 2.3–3.0 % of the peak less than μp. The
/// closed form's stick term rises from 0 at c like μp0/a √(2c(c − r)), so a boundary a fixed
/// fraction of a pixel off costs a fraction of the peak ∝ √(pixel/a): the worst of the three
/// ratios falls from 3.0 % at 128² (a = 38.4 px; 2.3, 3.0, 1.4 %) to 2.3 % at 256² (2.2, 2.3,
/// 1.5 %) and 1.65 % at 384², close to √(1/3). Off the circle the worst is 0.65, 0.48, 0.43 %,
/// and the RMS falls about like the pixel, 0.28, 0.13, 0.087 % at 0.25. It is not a
/// pixel-average effect: at 128², against the closed form's stick term averaged over each
/// pixel's square (the exact integral of √(c² − r²)₊), the circle gives 2.3, 2.6, 2.7 % and the
/// rest fits worse, off the circle 0.77, 0.95, 0.54 %: the slipping pixels just outside c carry
/// none of the average.
///
/// What the asserts catch (measured at 384², the comparison's c moved): a stick radius one
/// pixel off gives 4.9–12 % off the circle and 1.4–2.1 % RMS, half a pixel 2.8–5.7 % and
/// 0.71–1.1 %; the compliance 1 % wrong leaves the shear unchanged (force control) and moves δ
/// by 1.0 %, ten times its bound.
fn cattaneo_mindlin_at_zero_poisson(ratio: f64) {
    let h = hertz(384, Material { youngs: 130e9, poisson: 0.0 });
    let m = mindlin(&h, &mut mindlin_solver(&h), 0.3, ratio);
    eprintln!("ν = 0, Q/μN {ratio}: {m:?}");
    assert!(m.stick_radius.abs() < 0.5, "Q/μN {ratio}: {m:?}");
    assert!(m.displacement.abs() < 1e-3, "Q/μN {ratio}: {m:?}");
    assert!(m.shear_on_circle < 0.02, "the target of 2 % of the peak, Q/μN {ratio}: {m:?}");
    assert!(m.shear_off_circle < 0.006 && m.shear_rms < 0.0015, "Q/μN {ratio}: {m:?}");
    assert!(m.shear_y < 1e-9, "Q/μN {ratio}: {m:?}");
}

#[test]
fn cattaneo_mindlin_partial_slip_at_a_quarter_of_mu_n() {
    cattaneo_mindlin_at_zero_poisson(0.25);
}

#[test]
fn cattaneo_mindlin_partial_slip_at_half_of_mu_n() {
    cattaneo_mindlin_at_zero_poisson(0.5);
}

#[test]
fn cattaneo_mindlin_partial_slip_at_three_quarters_of_mu_n() {
    cattaneo_mindlin_at_zero_poisson(0.75);
}

/// Silicon's ν = 0.26: the closed form neglects q_y, which the solve finds at 2.2 % of the peak
/// shear (Q/μN = 0.25, 128²; 3.1 and 3.7 % at 0.5 and 0.75), and assumes a circular stick zone;
/// δ moves by 4e-5 (3e-4 and 5e-4 at 0.5 and 0.75, against 8e-6 to 9e-5 at ν = 0 and 128²).
#[test]
fn cattaneo_mindlin_partial_slip_at_silicon_poisson_ratio() {
    let h = hertz(128, SI);
    let mut solver = mindlin_solver(&h);
    let m = mindlin(&h, &mut solver, 0.3, 0.25);
    eprintln!("ν = 0.26, Q/μN 0.25: {m:?}");
    assert!(m.stick_radius.abs() < 2.0 && m.displacement.abs() < 0.02, "{m:?}");
    assert!(m.shear_y > 0.01 && m.shear_y < 0.03, "{m:?}");
    assert!(m.shear_off_circle < 0.03 && m.shear_on_circle < 0.035, "{m:?}");
}

fn instant(mu_s: f64, mu_d: f64) -> SlipLaw {
    SlipLaw { mu_s, mu_d, weakening: Weakening::Instant }
}

fn periodic_solver(pressure: &[f64], n: usize, l: f64) -> TangentialSolver {
    TangentialSolver::new(
        pressure,
        (n, n),
        (l, l),
        ShearCompliance::of(&[SI]),
        Boundary::Periodic,
        TangentialOptions { tolerance: 1e-10, ..Default::default() },
    )
    .unwrap()
}

#[test]
fn one_element_follows_the_local_law() {
    let (n, l) = (32, 3.2e-6);
    let mut p = vec![0.0; n * n];
    p[5 * n + 9] = 2e9;
    let mut solver = periodic_solver(&p, n, l);
    let onset = elastic_onset(&mut solver, &instant(0.6, 0.4), PEAK_TOLERANCE, |_| {}).unwrap();
    let area = (l / n as f64).powi(2);
    // The last stable state before the snap, located to the peak tolerance.
    let below = 1.0 - onset.static_force / (0.6 * 2e9 * area);
    assert!((0.0..PEAK_TOLERANCE).contains(&below), "{below:e}");
    assert!(onset.friction_drop() <= 1.5 && onset.friction_drop() > 1.5 * (1.0 - PEAK_TOLERANCE));
    assert_eq!(onset.classes.critical.count + onset.classes.stuck.count, 1);
    assert_eq!(onset.classes.weakened.count + onset.classes.weakening.count, 0);
    // After the peak it slides at mu_d.
    let last = onset.curve.last().unwrap();
    assert!((last.force_n - 0.4 * 2e9 * area).abs() < 1e-9 * last.force_n);
}

/// Single-pixel contacts `spacing` pixels apart on an `n`² grid, at pressures of 1–3 GPa.
fn isolated_pixels(n: usize, spacing: usize) -> Array2<f64> {
    let mut p = Array2::<f64>::zeros((n, n));
    let mut k = 0;
    for i in (0..n).step_by(spacing) {
        for j in (0..n).step_by(spacing) {
            k += 1;
            p[[i, j]] = 1e9 * (1.0 + ((k * 7919) % 97) as f64 / 48.0);
        }
    }
    p
}

#[test]
fn isolated_elements_share_equally() {
    // Single-pixel contacts 32 pixels apart: each carries the same shear while stuck, as in
    // the equal-sharing model.
    let (n, l, spacing) = (256, 25.6e-6, 32);
    let p = isolated_pixels(n, spacing);
    let area = (l / n as f64).powi(2);
    let law = FrictionLaw::new(0.6, 0.4).unwrap();
    let equal = Onset::new(&ElementLoads::from_pressure(&p, area).unwrap(), &law);
    let mut solver = periodic_solver(p.as_slice().unwrap(), n, l);
    let elastic = elastic_onset(&mut solver, &instant(0.6, 0.4), PEAK_TOLERANCE, |_| {}).unwrap();
    let rel = (elastic.static_force - equal.static_force).abs() / equal.static_force;
    eprintln!("isolated: elastic {:.6e} N, equal {:.6e} N, rel {rel:.2e}", elastic.static_force, equal.static_force);
    assert!(rel < 0.01);
}

/// A small rough contact: a few patches of a periodic random surface.
fn rough_pressure(n: usize, l: f64, load: f64) -> Vec<f64> {
    let mut heights = vec![0.0; n * n];
    let mut seed = 12345u64;
    let mut rnd = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    // A sum of random long-wavelength modes, amplitude falling as 1/k².
    for kx in 0..8i32 {
        for ky in -8..8i32 {
            if kx == 0 && ky <= 0 {
                continue;
            }
            let k = ((kx * kx + ky * ky) as f64).sqrt();
            let (amp, phase) = (1e-9 / (k * k), 2.0 * PI * rnd());
            for i in 0..n {
                for j in 0..n {
                    let arg = 2.0 * PI * (kx as f64 * j as f64 + ky as f64 * i as f64) / n as f64 + phase;
                    heights[i * n + j] += amp * arg.cos();
                }
            }
        }
    }
    let e_star = SI.plane_strain_modulus();
    let mut solver =
        ContactSolver::new(&heights, (n, n), (l, l), e_star, Boundary::Periodic, SolverOptions::default()).unwrap();
    solver.solve(load, |_, _| {}).unwrap();
    solver.pressure().to_vec()
}

/// The tangential solver on the contact set of [`rough_pressure`].
fn rough_solver(n: usize, l: f64, load: f64) -> TangentialSolver {
    periodic_solver(&rough_pressure(n, l, load), n, l)
}

#[test]
fn rough_contact_stiffness_ratio() {
    // Campañá, Persson & Müser (2011): k_t / k_n → 2(1 − ν)/(2 − ν). The normal stiffness of
    // the same contact set is the stuck solve with the isotropic normal kernel (B = 0).
    let (n, l) = (128, 12.8e-6);
    let p = rough_pressure(n, l, 2e-3);
    let c = ShearCompliance::of(&[SI]);
    let stiffness = |c: ShearCompliance| {
        let mut s =
            TangentialSolver::new(&p, (n, n), (l, l), c, Boundary::Periodic, TangentialOptions::default()).unwrap();
        let m = s.points().len();
        s.solve(&vec![[1e-9, 0.0]; m], &vec![f64::INFINITY; m]).unwrap();
        s.force()[0] / 1e-9
    };
    let kt = stiffness(c);
    let kn = stiffness(ShearCompliance { a: c.normal(), b: 0.0 });
    let want = 2.0 * (1.0 - SI.poisson) / (2.0 - SI.poisson);
    let contact = p.iter().filter(|p| **p > 0.0).count();
    eprintln!("stiffness ratio {:.5} vs {want:.5} ({contact} contact points)", kt / kn);
    assert!((kt / kn - want).abs() < 0.03 * want);
}

#[test]
fn slip_weakening_distance_to_zero_is_the_instant_drop() {
    let (n, l) = (32, 3.2e-6);
    let mut solver = rough_solver(n, l, 5e-5);
    let inst = elastic_onset(&mut solver, &instant(0.6, 0.4), PEAK_TOLERANCE, |_| {}).unwrap();
    let scale = inst.peak.point.displacement_m;
    let mut errors = Vec::new();
    for f in [1e-1, 1e-2, 1e-3] {
        let law = SlipLaw { mu_s: 0.6, mu_d: 0.4, weakening: Weakening::Linear(f * scale) };
        let onset = elastic_onset(&mut solver, &law, PEAK_TOLERANCE, |_| {}).unwrap();
        errors.push((onset.static_force - inst.static_force).abs() / inst.static_force);
    }
    eprintln!("d_c → 0: F_S {:.6e} N, relative differences {errors:?}", inst.static_force);
    assert!(errors[2] < 2e-3, "{errors:?}");
    assert!(errors[2] <= errors[0], "{errors:?}");
}

/// A weakening far steeper than the solve resolves (d_c a hundredth of the peak's δ, at the
/// default tolerance): each solve leaves errors in the slips that move such bounds by more than
/// a millionth, so a cascade that waits for its bounds to stop moving never ended ("did not
/// settle after 2000 solves" at 128²); now bound changes within what the tolerance leaves in
/// the slip are settled, and a bound is lowered at once to where its own extra slip leaves it.
/// Measured: 575 solves, F_S 3.5e-6 from the instant drop's, which it must approach (both paths
/// from δ = 0 at 100 times the tolerance, which moves F_S by up to 7e-6).
#[test]
fn steep_slip_weakening_settles() {
    let (n, l) = (128, 12.8e-6);
    let p = rough_pressure(n, l, 2e-3);
    let c = ShearCompliance::of(&[SI]);
    let options = TangentialOptions::default();
    let mut solver = TangentialSolver::new(&p, (n, n), (l, l), c, Boundary::Periodic, options).unwrap();
    let inst = elastic_onset(&mut solver, &instant(0.6, 0.4), PEAK_TOLERANCE, |_| {}).unwrap();
    let dc = 1e-2 * inst.peak.point.displacement_m;
    let law = SlipLaw { mu_s: 0.6, mu_d: 0.4, weakening: Weakening::Linear(dc) };
    let onset = elastic_onset(&mut solver, &law, PEAK_TOLERANCE, |_| {}).unwrap();
    let error = (onset.static_force - inst.static_force) / inst.static_force;
    eprintln!("d_c = {dc:.3e} m: F_S {error:.3e} from the instant drop's, {:?}", onset.work);
    assert!(error.abs() < 2e-5, "{error:e}");
    assert!(onset.work.solves < 1500, "{:?}", onset.work);
}

/// Under Coulomb friction (mu_s = mu_d) the path stops at total sliding with the tractions
/// still turned off x by the elastic coupling (ν > 0), so its last force lies below μN; F_S is
/// the sliding force the path tends to as δ grows: μN, a friction drop of exactly 1.
#[test]
fn coulomb_friction_gives_the_sliding_force() {
    let (n, l) = (64, 6.4e-6);
    let mut solver = rough_solver(n, l, 5e-4);
    let onset = elastic_onset(&mut solver, &instant(0.5, 0.5), PEAK_TOLERANCE, |_| {}).unwrap();
    let last = onset.curve.last().unwrap();
    let largest = onset.curve.iter().map(|c| c.force_n).fold(0.0, f64::max);
    eprintln!(
        "Coulomb: path's largest force {:.9} μN, last {:.9} μN, {} points",
        largest / (0.5 * onset.normal_force),
        last.force_n / (0.5 * onset.normal_force),
        solver.points().len()
    );
    assert!(largest < 0.5 * onset.normal_force * (1.0 - 1e-6), "the path itself stays below μN");
    // Exactly: a coefficient below mu_d by round-off would be an impossible result.
    assert_eq!(onset.friction_drop(), 1.0);
    assert_eq!(onset.static_coefficient(), 0.5);
    assert!(onset.peak.point.displacement_m.is_infinite());
    assert_eq!(onset.classes.weakened.count, solver.points().len());
    assert!(onset
        .peak
        .traction
        .iter()
        .zip(solver.pressure())
        .all(|(q, p)| q[1] == 0.0 && (q[0] - 0.5 * p).abs() <= 1e-12 * p));
}

/// F_S is the largest force on the curve, in a stretch of the finest steps: a coarse step's
/// force before its cascade, which finer steps lower, is never taken for it.
#[test]
fn the_first_step_leaps_to_the_floor_and_stays_below_it() {
    // The path from δ = 0 starts with one step to μ_d N / k_t: its force cannot pass μ_d N,
    // which F_S is never below, so it is never refined; the following steps shorten towards
    // the coarse length as the force nears μ_d N.
    let (n, load) = (64, 2e-3);
    let l = n as f64 * 1e-7;
    let mut solver = rough_solver(n, l, load);
    let m = solver.points().len();
    solver.solve(&vec![[1e-9, 0.0]; m], &vec![f64::INFINITY; m]).unwrap();
    let kt = solver.force()[0] / 1e-9;
    let onset = elastic_onset(&mut solver, &instant(0.6, 0.4), PEAK_TOLERANCE, |_| {}).unwrap();
    let floor = 0.4 * onset.normal_force;
    let first = onset.curve[1];
    eprintln!("first step to δ {:.6e} m, F {:.6e} N, floor {floor:.6e} N", first.displacement_m, first.force_n);
    assert!((first.displacement_m / (floor / kt) - 1.0).abs() < 1e-6, "{first:?}");
    assert!(first.force_n < floor && first.force_n > 0.5 * floor, "{first:?}");
    assert!(onset.static_force >= floor);
    // Step lengths never grow along the path from δ = 0 (the curve's coarse part).
    let coarse: Vec<f64> = onset.curve.iter().map(|c| c.displacement_m).collect();
    let h0 = 0.6 * onset.normal_force / kt / 64.0;
    assert!(coarse.windows(2).all(|w| w[1] - w[0] <= floor / kt * (1.0 + 1e-9)), "{coarse:?}");
    assert!(coarse.windows(2).any(|w| (w[1] - w[0] - h0).abs() < 1e-6 * h0), "coarse steps of μ_s N / (64 k_t)");
}

/// F_S is the largest settled force on the curve, and the search's tolerance bounds what it
/// leaves: a search to a hundredth of it finds no force higher by more than the tolerance.
/// (A golden-section search on the settled curve, which is a sawtooth, left up to 7e-4 at
/// 1500²; here a search that stopped at the march's largest force misses by 1e-3 to 7e-3.)
#[test]
fn static_force_is_the_largest_settled_force_within_the_tolerance() {
    for (n, load) in [(64, 5e-4), (64, 2e-3)] {
        let l = n as f64 * 1e-7;
        let mut solver = rough_solver(n, l, load);
        let dc = SlipLaw { mu_s: 0.6, mu_d: 0.4, weakening: Weakening::Linear(2e-10) };
        for law in [instant(0.6, 0.4), dc] {
            let onset = elastic_onset(&mut solver, &law, PEAK_TOLERANCE, |_| {}).unwrap();
            let fine = elastic_onset(&mut solver, &law, PEAK_TOLERANCE / 100.0, |_| {}).unwrap();
            let top =
                onset.curve.iter().copied().fold(onset.curve[0], |b, c| if c.force_n > b.force_n { c } else { b });
            let rel = fine.static_force / onset.static_force - 1.0;
            eprintln!(
                "{n}², {load} N, {:?}: F_S {:.9e} N at δ {:.6e} m ({} steps), at a hundredth of the tolerance {rel:.2e} ({} steps)",
                law.weakening,
                onset.static_force,
                onset.peak.point.displacement_m,
                onset.work.steps,
                fine.work.steps
            );
            assert_eq!(onset.peak.point, top);
            assert_eq!(onset.static_force, top.force_n);
            assert!(rel.abs() < PEAK_TOLERANCE, "{rel:e}");
        }
    }
}

/// Equal sharing with the same slip weakening (spring–sliders of K_t / n) against elastic
/// sharing on single-pixel contacts 128 pixels apart, each its own patch, so that their
/// interaction is small: with d_c = 0.4 nm some elements weaken stably (k_t > (mu_s − mu_d)
/// n / d_c) and the others snap. Measured: d_c 0.2, 0.4, 1 nm (1, 9, 16 of 16 stable):
/// elastic against equal 2.6e-4, 2.0e-4, −7.6e-4; at 64 pixels apart (64 contacts) 6.1e-4,
/// 5.6e-4, −1.8e-3, the interaction through the half-space.
#[test]
fn isolated_elements_weaken_as_spring_sliders() {
    let (n, l, spacing) = (512, 51.2e-6, 128);
    let p = isolated_pixels(n, spacing);
    let area = (l / n as f64).powi(2);
    let loads = ElementLoads::from_pressure(&p, area).unwrap();
    let mut solver = periodic_solver(p.as_slice().unwrap(), n, l);
    for dc in [2e-10, 4e-10, 1e-9] {
        let law = SlipLaw { mu_s: 0.6, mu_d: 0.4, weakening: Weakening::Linear(dc) };
        let elastic = elastic_onset(&mut solver, &law, PEAK_TOLERANCE, |_| {}).unwrap();
        let stiffness = element_stiffness(elastic.stuck_stiffness, loads.len());
        let equal = spring_slider_onset(&loads, &law, stiffness).unwrap();
        let stable = loads.sorted().iter().filter(|n| stiffness > 0.2 * **n / dc).count();
        let rel = elastic.static_force / equal.static_force_n - 1.0;
        eprintln!(
            "d_c {dc:e} m: elastic {:.6e} N, equal with the same weakening {:.6e} N, rel {rel:.2e}; {stable} of {} stable",
            elastic.static_force,
            equal.static_force_n,
            loads.len()
        );
        assert!(rel.abs() < 1e-3, "{rel:e}");
    }
}

/// Two elements far apart, n_2 = 2 n_1, as spring–sliders of k = K_t/2 each, μ falling
/// linearly by Δμ = mu_s − mu_d over d_c = c δ_1 (δ_1 = mu_s n_1/k, where the first slips):
/// the first weakens stably (a = Δμ n_1/d_c below k/2) and has slipped s_1 = δ_1/(1 − a/k)
/// when the second reaches its bound at δ_2 = 2 δ_1, the peak. For c = 4 that is 0.27 d_c:
/// the first is weakening, F_S = mu_s n_2 + (mu_s − Δμ s_1/d_c) n_1; for c = 0.8 it would be
/// 2.1 d_c: the first is fully weakened, F_S = mu_s n_2 + mu_d n_1, as under the instant drop.
/// The second is at its bound at the peak, on it (critical) or just below (stuck).
#[test]
fn two_elements_have_the_classes_of_two_spring_sliders() {
    let (n, l) = (256, 25.6e-6);
    let mut p = vec![0.0; n * n];
    let (p1, p2) = (1e9, 2e9);
    p[64 * n + 64] = p1;
    p[192 * n + 192] = p2;
    let area = (l / n as f64).powi(2);
    let (n1, n2) = (p1 * area, p2 * area);
    let mut solver = periodic_solver(&p, n, l);
    let (mu_s, mu_d) = (0.6, 0.4);
    let inst = elastic_onset(&mut solver, &instant(mu_s, mu_d), PEAK_TOLERANCE, |_| {}).unwrap();
    let k = element_stiffness(inst.stuck_stiffness, 2);
    let delta1 = mu_s * n1 / k;
    let first = |o: &asperity::friction::ElasticOnset| {
        let i = solver_index(&p, 64 * n + 64);
        (o.peak.classes[i], o.peak.classes[1 - i])
    };
    let cases = [(0.0, SlideClass::Weakened), (4.0, SlideClass::Weakening), (0.8, SlideClass::Weakened)];
    for (c, class) in cases {
        let onset = if c == 0.0 {
            inst.clone()
        } else {
            let law = SlipLaw { mu_s, mu_d, weakening: Weakening::Linear(c * delta1) };
            elastic_onset(&mut solver, &law, PEAK_TOLERANCE, |_| {}).unwrap()
        };
        let s1 = delta1 / (1.0 - (mu_s - mu_d) / (mu_s * c));
        let mu1 = if c > 0.0 && s1 < c * delta1 { mu_s - (mu_s - mu_d) * s1 / (c * delta1) } else { mu_d };
        let want = mu_s * n2 + mu1 * n1;
        let (one, two) = first(&onset);
        eprintln!("c = {c}: F_S {:.6e} N against {want:.6e} N; classes {one:?}, {two:?}", onset.static_force);
        assert!((onset.static_force / want - 1.0).abs() < 2e-3, "c = {c}: {} against {want}", onset.static_force);
        assert_eq!(one, class, "c = {c}");
        assert!(matches!(two, SlideClass::Critical | SlideClass::Stuck), "c = {c}: {two:?}");
        let c_ = &onset.classes;
        assert_eq!(c_.stuck.count + c_.critical.count + c_.weakening.count + c_.weakened.count, 2);
    }
}

/// The index among the contact points (in the order of the grid) of the pixel `at`.
fn solver_index(pressure: &[f64], at: usize) -> usize {
    pressure[..at].iter().filter(|p| **p > 0.0).count()
}

/// A small rough contact near 0.1 mN: the classes at the peak cover every contact point, their
/// shares of N and F_S sum to 1; under d_c = 2 nm some points are weakening at the peak, under
/// the instant drop none.
#[test]
fn the_classes_cover_a_rough_contact() {
    let (n, l) = (128, 12.8e-6);
    let mut solver = rough_solver(n, l, 1e-4);
    let points = solver.points().len();
    for weakening in [Weakening::Linear(2e-9), Weakening::Instant] {
        let law = SlipLaw { mu_s: 0.6, mu_d: 0.4, weakening: weakening.clone() };
        let onset = elastic_onset(&mut solver, &law, PEAK_TOLERANCE, |_| {}).unwrap();
        let c = &onset.classes;
        let shares = [c.stuck, c.critical, c.weakening, c.weakened];
        eprintln!("{weakening:?}: {points} points, δ_peak {:.3e} m, {shares:?}", onset.peak.point.displacement_m);
        assert_eq!(shares.iter().map(|s| s.count).sum::<usize>(), points);
        for fraction in [shares.map(|s| s.normal_fraction), shares.map(|s| s.friction_fraction)] {
            assert!((fraction.iter().sum::<f64>() - 1.0).abs() < 1e-9, "{fraction:?}");
        }
        let counted = |class| onset.peak.classes.iter().filter(|k| **k == class).count();
        assert_eq!(counted(SlideClass::Weakening), c.weakening.count);
        if weakening == Weakening::Instant {
            assert_eq!(c.weakening.count, 0);
        } else {
            assert!(c.weakening.count > 0, "{shares:?}");
        }
    }
}

/// An independent elastic onset, written from the problem's statement and sharing no code with
/// `elastic_onset`: the periodic Cerruti matrix between the contact points by a direct inverse
/// DFT of its kernel (k = 0 left out, the cross term zero on the Nyquist lines, as
/// `TangentialInfluence::periodic` states), each displacement step solved by projected block
/// Gauss–Seidel, in uniform steps without refinement.
struct IndependentOnset {
    /// Pressure [Pa] at the contact points.
    p: Vec<f64>,
    /// K between contact points i, j (xx, xy, yy) at i·m + j [m/Pa].
    k: Vec<[f64; 3]>,
    /// Pixel area [m²].
    area: f64,
}

impl IndependentOnset {
    fn new(pressure: &[f64], n: usize, l: f64) -> Self {
        let g = shear_modulus(&SI);
        let (a, b) = (1.0 / g, SI.poisson / g);
        let points: Vec<(usize, usize)> = (0..n * n).filter(|k| pressure[*k] > 0.0).map(|k| (k / n, k % n)).collect();
        let signed = |k: usize| if k >= n / 2 { k as f64 - n as f64 } else { k as f64 };
        let mut table = vec![[0.0; 3]; n * n];
        for (o, entry) in table.iter_mut().enumerate() {
            let (dy, dx) = ((o / n) as f64, (o % n) as f64);
            for ky in 0..n {
                for kx in 0..n {
                    let (qx, qy) = (2.0 * PI * signed(kx) / l, 2.0 * PI * signed(ky) / l);
                    let q2 = qx * qx + qy * qy;
                    if q2 == 0.0 {
                        continue;
                    }
                    let q = q2.sqrt();
                    let c = (2.0 * PI * (signed(kx) * dx + signed(ky) * dy) / n as f64).cos() / (n * n) as f64;
                    entry[0] += (a - b * qx * qx / q2) / q * c;
                    if kx != n / 2 && ky != n / 2 {
                        entry[1] += -b * qx * qy / q2 / q * c;
                    }
                    entry[2] += (a - b * qy * qy / q2) / q * c;
                }
            }
        }
        let m = points.len();
        let k = (0..m * m)
            .map(|ij| {
                let ((yi, xi), (yj, xj)) = (points[ij / m], points[ij % m]);
                table[(yi + n - yj) % n * n + (xi + n - xj) % n]
            })
            .collect();
        let p = points.iter().map(|&(i, j)| pressure[i * n + j]).collect();
        IndependentOnset { p, k, area: (l / n as f64).powi(2) }
    }

    /// (K q)_i [m].
    fn displacement(&self, q: &[[f64; 2]], i: usize) -> [f64; 2] {
        let row = &self.k[i * q.len()..(i + 1) * q.len()];
        row.iter()
            .zip(q)
            .fold([0.0; 2], |u, ([xx, xy, yy], q)| [u[0] + xx * q[0] + xy * q[1], u[1] + xy * q[0] + yy * q[1]])
    }

    /// Minimise ½ qᵀKq − bᵀq on the disks |q_i| ≤ g_i, from `q`: each point in turn takes its
    /// exact minimiser with the others held (K's diagonal block is a multiple of the identity),
    /// until no traction moves by more than 1e-11 of `scale`.
    fn solve(&self, q: &mut [[f64; 2]], target: &[[f64; 2]], bound: &[f64], scale: f64) {
        let d = self.k[0][0];
        for _ in 0..1_000_000 {
            let mut moved: f64 = 0.0;
            for i in 0..q.len() {
                let u = self.displacement(q, i);
                let mut t = [q[i][0] + (target[i][0] - u[0]) / d, q[i][1] + (target[i][1] - u[1]) / d];
                let r = t[0].hypot(t[1]);
                if r > bound[i] {
                    t = [t[0] * bound[i] / r, t[1] * bound[i] / r];
                }
                moved = moved.max((t[0] - q[i][0]).abs().max((t[1] - q[i][1]).abs()));
                q[i] = t;
            }
            if moved < 1e-11 * scale {
                return;
            }
        }
        panic!("Gauss–Seidel did not converge");
    }

    /// F_S [N] of the path δ = h, 2h, … with h = μ_s N / (k_t `steps`): at each step the
    /// targets are δ e_x − c_i (c_i the slip so far), the bounds μ(slip path, slipped) p_i; the
    /// points on their bounds lower them from their new slip and the step is solved again until
    /// none moves. F_S is the largest force of a step's first solve, or the sliding force
    /// μ_d N once every point has weakened fully.
    fn static_force(&self, law: &SlipLaw, steps: usize) -> f64 {
        let (m, p) = (self.p.len(), &self.p);
        let scale = law.mu_s * p.iter().copied().fold(0.0, f64::max);
        let force = |q: &[[f64; 2]]| q.iter().map(|q| q[0]).sum::<f64>() * self.area;
        let normal = p.iter().sum::<f64>() * self.area;
        let mut q = vec![[0.0; 2]; m];
        self.solve(&mut q, &vec![[1e-9, 0.0]; m], &vec![f64::INFINITY; m], scale);
        let h = law.mu_s * normal / (force(&q) / 1e-9) / steps as f64;
        let (mut c, mut path, mut slipped) = (vec![[0.0; 2]; m], vec![0.0; m], vec![false; m]);
        let mut q = vec![[0.0; 2]; m];
        let mut largest: f64 = 0.0;
        let on_bound = |q: [f64; 2], g: f64| q[0].hypot(q[1]) >= g * (1.0 - 1e-9);
        for step in 1..=100 * steps {
            let delta = step as f64 * h;
            let target: Vec<[f64; 2]> = c.iter().map(|c| [delta - c[0], -c[1]]).collect();
            let mut bound: Vec<f64> = (0..m).map(|i| law.mu(path[i], slipped[i]) * p[i]).collect();
            self.solve(&mut q, &target, &bound, scale);
            largest = largest.max(force(&q));
            let slip = loop {
                let slip: Vec<[f64; 2]> = (0..m)
                    .map(|i| {
                        let u = self.displacement(&q, i);
                        if on_bound(q[i], bound[i]) {
                            [target[i][0] - u[0], target[i][1] - u[1]]
                        } else {
                            [0.0; 2]
                        }
                    })
                    .collect();
                let mut lowered = false;
                for i in 0..m {
                    if !on_bound(q[i], bound[i]) {
                        continue;
                    }
                    let g = law.mu(path[i] + slip[i][0].hypot(slip[i][1]), true) * p[i];
                    if g < bound[i] * (1.0 - 1e-7) {
                        bound[i] = g;
                        lowered = true;
                    }
                }
                if !lowered {
                    break slip;
                }
                self.solve(&mut q, &target, &bound, scale);
            };
            for i in (0..m).filter(|i| on_bound(q[*i], bound[*i])) {
                slipped[i] = true;
                c[i] = [c[i][0] + slip[i][0], c[i][1] + slip[i][1]];
                path[i] += slip[i][0].hypot(slip[i][1]);
            }
            if (0..m).all(|i| slipped[i] && law.mu(path[i], true) == law.mu_d) {
                return largest.max(law.mu_d * normal);
            }
        }
        panic!("no total sliding after {} steps", 100 * steps);
    }
}

/// `slide`'s F_S against [`IndependentOnset`] on three rough contacts (32, 67 and 121 points),
/// with the instant drop and (on the first two: its creeping cascades make the reference slow)
/// with d_c = the instant drop's peak δ. The independent path's uniform steps overestimate F_S
/// by about their length times the path's stiffness, so it approaches from above, to first
/// order. Measured (1 000 and 4 000 steps, relative to `slide`): 32 points instant 1.84e-4,
/// 8.7e-5, linear 1.94e-4, 5.1e-5; 67 points instant 2.58e-5, 2.59e-5, linear 1.89e-4,
/// 4.9e-5; 121 points instant 7.9e-5, 3.6e-6 (linear 1.39e-4, 3.6e-5, not run: 70 s);
/// extrapolated to zero step, (4 F₄₀₀₀ − F₁₀₀₀)/3, within 2.1e-5 below to 5.5e-5 above. At 121
/// points elastic interaction matters: the drop is 1.0306 (instant) against 1.1226 under equal
/// sharing.
#[test]
fn an_independent_onset_gives_slides_static_force() {
    let (n, l) = (32, 3.2e-6);
    let area = (l / n as f64).powi(2);
    for load in [5e-5, 1.5e-4, 3e-4] {
        let pressure = rough_pressure(n, l, load);
        let mut solver = periodic_solver(&pressure, n, l);
        let independent = IndependentOnset::new(&pressure, n, l);
        assert_eq!(independent.p.len(), solver.points().len());
        let inst = elastic_onset(&mut solver, &instant(0.6, 0.4), PEAK_TOLERANCE, |_| {}).unwrap();
        let dc = inst.peak.point.displacement_m;
        let weakening = SlipLaw { mu_s: 0.6, mu_d: 0.4, weakening: Weakening::Linear(dc) };
        let laws = if load < 3e-4 { vec![instant(0.6, 0.4), weakening] } else { vec![instant(0.6, 0.4)] };
        for law in laws {
            let onset = elastic_onset(&mut solver, &law, PEAK_TOLERANCE, |_| {}).unwrap();
            let [coarse, fine] =
                [1000, 4000].map(|steps| independent.static_force(&law, steps) / onset.static_force - 1.0);
            let extrapolated = (4.0 * fine - coarse) / 3.0;
            eprintln!(
                "{load} N, {:?}, {} points: F_S {:.9e} N; independent, relative: {coarse:.2e} (1 000 steps), \
                 {fine:.2e} (4 000), {extrapolated:.2e} (extrapolated)",
                law.weakening,
                solver.points().len(),
                onset.static_force
            );
            // slide's F_S lies below the curve's largest force by at most the peak tolerance.
            assert!(fine < coarse + 2e-6 && fine > -2e-5 && fine < 1.2e-4 + PEAK_TOLERANCE, "{coarse:e} {fine:e}");
            assert!(extrapolated > -3e-5 && extrapolated < PEAK_TOLERANCE + 3e-5, "{extrapolated:e}");
        }
        if load == 3e-4 {
            let p = Array2::from_shape_vec((n, n), pressure).unwrap();
            let equal =
                Onset::new(&ElementLoads::from_pressure(&p, area).unwrap(), &FrictionLaw::new(0.6, 0.4).unwrap());
            let (elastic, equal) = (inst.friction_drop(), equal.static_force / (0.4 * inst.normal_force));
            eprintln!("drop: elastic {elastic:.4}, equal {equal:.4}");
            assert!(equal - elastic > 0.05, "{elastic} {equal}");
        }
    }
}
