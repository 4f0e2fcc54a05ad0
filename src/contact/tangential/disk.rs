//! The Coulomb bound at one point, the disk |q_i| ≤ g_i: projections onto it and the
//! gradient's parts on it.
//!
//! Imports nothing inside `contact`; must not import friction, study, report, plot, shs, cli.

use rayon::prelude::*;

/// Contact points per parallel task: below this, threads cost more than they save.
pub(super) const CHUNK: usize = 4096;

/// Cut every traction onto its disk |q_i| ≤ g_i; the cuts (point, change) the displacement
/// must follow, round-off left out.
pub(super) fn cut_onto_disks(traction: &mut [[f64; 2]], bound: &[f64]) -> Vec<(usize, [f64; 2])> {
    traction
        .par_iter_mut()
        .zip(bound.par_iter())
        .enumerate()
        .with_min_len(CHUNK)
        .filter_map(|(i, (q, g))| {
            let n = magnitude(*q);
            if n <= *g {
                return None;
            }
            let s = g / n;
            let cut = [q[0] * (s - 1.0), q[1] * (s - 1.0)];
            *q = [q[0] * s, q[1] * s];
            (magnitude(cut) > ROUND_OFF * n).then_some((i, cut))
        })
        .collect()
}

/// A cut of a traction onto its bound below this fraction of the traction is round-off: the
/// displacement does not follow it.
const ROUND_OFF: f64 = 1e-12;

/// Project every traction onto its disk |q_i| ≤ g_i; the norm of the changes [Pa] (0 when
/// none changed).
pub(super) fn project(traction: &mut [[f64; 2]], bound: &[f64]) -> f64 {
    traction
        .par_iter_mut()
        .zip(bound.par_iter())
        .with_min_len(CHUNK)
        .map(|(q, g)| {
            let qn = magnitude(*q);
            if qn > *g {
                let cut = qn - g;
                let s = g / qn;
                *q = [q[0] * s, q[1] * s];
                cut * cut
            } else {
                0.0
            }
        })
        .sum::<f64>()
        .sqrt()
}

/// A traction within this fraction of its bound is on it.
pub(super) const ON_BOUND: f64 = 1e-12;

/// |v| of a traction [Pa] or displacement [m]: without `hypot`'s guard against overflow and
/// underflow, which these never come near (|v|² within 1e-300..1e300), and which made `hypot` 6 %
/// of a sliding onset's time at 1500², 100 mN.
pub(crate) fn magnitude(v: [f64; 2]) -> f64 {
    (v[0] * v[0] + v[1] * v[1]).sqrt()
}

pub(super) fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// The gradient r = u − b at one point split into its free part φ (the whole gradient at a
/// point below its bound; on it, the part along the bound, which turns the traction) and its
/// chopped part β (on the bound, the radial part that pulls the traction into its disk).
pub(super) fn gradient_parts(q: [f64; 2], u: [f64; 2], b: [f64; 2], g: f64) -> ([f64; 2], [f64; 2]) {
    let r = [u[0] - b[0], u[1] - b[1]];
    let qn = magnitude(q);
    if qn < g * (1.0 - ON_BOUND) {
        return (r, [0.0; 2]);
    }
    let n = [q[0] / qn, q[1] / qn];
    let radial = dot(r, n);
    let along = [r[0] - radial * n[0], r[1] - radial * n[1]];
    // The descent −r points into the disk where the radial part is positive.
    (along, if radial > 0.0 { [radial * n[0], radial * n[1]] } else { [0.0; 2] })
}

/// q projected onto the disk |q| ≤ g.
pub(super) fn onto_disk(q: [f64; 2], g: f64) -> [f64; 2] {
    let qn = magnitude(q);
    if qn > g {
        [q[0] * g / qn, q[1] * g / qn]
    } else {
        q
    }
}

/// The reduced free gradient: the part of a step of length ᾱ along −φ that the bound lets
/// through, per unit step (φ itself where the whole step fits).
pub(super) fn reduced_free_gradient(q: [f64; 2], phi: [f64; 2], g: f64, step: f64) -> [f64; 2] {
    if step == 0.0 || phi == [0.0; 2] {
        return phi;
    }
    let z = onto_disk([q[0] - step * phi[0], q[1] - step * phi[1]], g);
    [(q[0] - z[0]) / step, (q[1] - z[1]) / step]
}

/// The largest α with |q − α p| ≤ g, for q inside its disk; unlimited on the bound, where p
/// turns the traction along it.
pub(super) fn feasible_step(q: [f64; 2], p: [f64; 2], g: f64) -> f64 {
    let pp = dot(p, p);
    if pp == 0.0 || g.is_infinite() || magnitude(q) >= g * (1.0 - ON_BOUND) {
        return f64::INFINITY;
    }
    let room = (g * g - dot(q, q)).max(0.0);
    let qp = dot(q, p);
    let root = (qp * qp + pp * room).sqrt();
    // Two forms of the same root: each free of cancellation on its side.
    if qp >= 0.0 {
        (qp + root) / pp
    } else {
        room / (root - qp)
    }
}

/// The bound's curvature term at a point held on it: the slip s = −r·n over the bound g
/// [m/Pa]; zero below the bound or where the gradient pulls the point off it.
pub(super) fn turning(q: [f64; 2], u: [f64; 2], b: [f64; 2], g: f64) -> f64 {
    let qn = magnitude(q);
    if qn < g * (1.0 - ON_BOUND) {
        return 0.0;
    }
    let slip = -dot([u[0] - b[0], u[1] - b[1]], [q[0] / qn, q[1] / qn]);
    (slip / g).max(0.0)
}

/// p without its radial part where the traction is held on its bound.
pub(super) fn tangent_if_held(p: [f64; 2], q: [f64; 2], g: f64) -> [f64; 2] {
    let qn = magnitude(q);
    if qn < g * (1.0 - ON_BOUND) {
        return p;
    }
    let n = [q[0] / qn, q[1] / qn];
    let radial = dot(p, n);
    [p[0] - radial * n[0], p[1] - radial * n[1]]
}
