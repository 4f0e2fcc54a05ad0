//! The friction–displacement curve under increasing imposed tangential displacement δ, in
//! two loading modes, built from slip events in O(M) on the sorted forces.
//!
//! Convention: each element is a tangential spring of stiffness k_t [N/m] (one value for
//! all) between the rigid slider and its contact point, so all stuck elements carry the same
//! shear s = k_t · δ [N], δ [m] being the slider's displacement. A slipped element carries
//! mu_d · n_i. The curve is computed in s, which needs no k_t: δ = s / k_t and
//! δ / δ_peak = s / s*, with s* = mu_s · n_(k*).
//!
//! - Equal load sharing (the paper's model): the tangential force is held while elements
//!   slip; the excess s − mu_d · n_i released by a slipping element goes to the elements
//!   still stuck (the slider advances at constant force), which may slip in turn. The curve
//!   rises until the weakest stuck element reaches mu_s, then runs on a plateau of constant
//!   force while the slips cascade; at the peak the cascade reaches total sliding.
//! - Rigid displacement control: δ is imposed and nothing is redistributed; an element slips
//!   when k_t · δ reaches mu_s · n_i, and the force drops by (mu_s − mu_d) · n_i.
//!
//! Why both peak at F_S, at the same δ_peak: in every equilibrium state of either mode, the
//! elements with mu_s · n_i < s have slipped and the others carry s, so the force is one
//! function F(s) = mu_d · Σ_{mu_s n_i < s} n_i + s · #{mu_s n_i ≥ s}. Rigid control visits
//! every s; F(s) rises between slips and drops at each, so its maxima are the values just
//! before the slips, F_k, and its peak is max_k F_k = F_S at s* = mu_s · n_(k*). Equal load
//! sharing visits only the s where F(s) is a record (a plateau bridges each dip of F(s) at
//! constant force): the running maximum of F(s), whose peak is the same max_k F_k.
//!
//! Must not import study, shs, plot or report: friction builds on contact and the base row.

use std::path::Path;

use serde::Serialize;

use super::law::FrictionLaw;
use super::onset::{groups, slip_force, ElementLoads};
use crate::error::{Error, Result};
use crate::output::write_atomic;

/// How the tangential loading is imposed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Loading {
    /// Force held during slips, released excess redistributed over the stuck elements.
    EqualLoadSharing,
    /// Displacement imposed on every stuck element, no redistribution.
    RigidDisplacement,
}

impl Loading {
    /// Both modes, in the order `curve.csv` lists them.
    pub const ALL: [Loading; 2] = [Loading::EqualLoadSharing, Loading::RigidDisplacement];

    /// The name `curve.csv` uses in its `mode` column.
    pub fn name(self) -> &'static str {
        match self {
            Loading::EqualLoadSharing => "equal_load_sharing",
            Loading::RigidDisplacement => "rigid_displacement",
        }
    }
}

/// One vertex of a friction–displacement curve (the curve is straight between vertices
/// unless it was decimated).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvePoint {
    /// s = k_t · δ: the shear force on every stuck element \[N].
    pub element_shear: f64,
    /// The tangential (friction) force F \[N].
    pub force: f64,
    /// How many elements are stuck.
    pub stuck: usize,
}

/// A friction–displacement curve from δ = 0 to total sliding.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// The loading mode.
    pub loading: Loading,
    /// The normal load N \[N], for the coefficient F / N.
    pub normal_force: f64,
    /// Vertices in order of the loading path; a slip at fixed δ gives two vertices at the
    /// same δ (before and after).
    pub points: Vec<CurvePoint>,
    /// Index in `points` of the peak: the first vertex of maximal force, (s*, F_S).
    pub peak: usize,
}

impl Curve {
    /// The curve of `loads` under `law` and `loading`, with at most `max_points` vertices
    /// (at least 4): when there are more, every k-th is kept, and always the first, the
    /// peak, the vertex after it and the last, so the peak is exact.
    pub fn new(loads: &ElementLoads, law: &FrictionLaw, loading: Loading, max_points: usize) -> Curve {
        let walk = |visit: &mut dyn FnMut(CurvePoint)| match loading {
            Loading::EqualLoadSharing => walk_equal_load_sharing(loads, law, visit),
            Loading::RigidDisplacement => walk_rigid(loads, law, visit),
        };
        // Two passes over the events, so that 2 million elements never hold 4 million vertices.
        let (mut count, mut peak, mut best) = (0usize, 0usize, f64::NEG_INFINITY);
        walk(&mut |p| {
            if p.force > best {
                best = p.force;
                peak = count;
            }
            count += 1;
        });
        let max_points = max_points.max(4);
        let stride = if count <= max_points { 1 } else { count.div_ceil(max_points - 3) };
        let mut points = Vec::with_capacity(count.min(max_points));
        let (mut i, mut kept_peak) = (0usize, 0usize);
        walk(&mut |p| {
            if i % stride == 0 || i == peak || i == peak + 1 || i + 1 == count {
                if i == peak {
                    kept_peak = points.len();
                }
                points.push(p);
            }
            i += 1;
        });
        Curve { loading, normal_force: loads.total(), points, peak: kept_peak }
    }

    /// The peak vertex: (s*, F_S).
    pub fn peak_point(&self) -> CurvePoint {
        self.points[self.peak]
    }
}

/// Rigid displacement control: at each group's threshold s = mu_s · n, the vertex just
/// before its elements slip and the one just after.
fn walk_rigid(loads: &ElementLoads, law: &FrictionLaw, visit: &mut dyn FnMut(CurvePoint)) {
    let m = loads.len();
    visit(CurvePoint { element_shear: 0.0, force: 0.0, stuck: m });
    for g in groups(loads.sorted()) {
        let s = law.mu_s * g.n;
        let stuck = m - g.start;
        visit(CurvePoint { element_shear: s, force: slip_force(law, g.prefix, g.n, stuck), stuck });
        let stuck = stuck - g.count;
        visit(CurvePoint { element_shear: s, force: slip_force(law, g.prefix_after, g.n, stuck), stuck });
    }
}

/// Equal load sharing at held force: the end of each loading ramp (the weakest stuck element
/// at mu_s) and the end of each plateau (the cascade of slips arrested), then total sliding.
fn walk_equal_load_sharing(loads: &ElementLoads, law: &FrictionLaw, visit: &mut dyn FnMut(CurvePoint)) {
    let n = loads.sorted();
    let m = n.len();
    visit(CurvePoint { element_shear: 0.0, force: 0.0, stuck: m });
    let (mut next, mut slipped, mut peak_shear) = (0usize, 0.0f64, 0.0f64);
    while next < m {
        // Loading: the force rises, shared by the stuck elements, until the weakest slips.
        let force = slip_force(law, slipped, n[next], m - next);
        peak_shear = law.mu_s * n[next];
        visit(CurvePoint { element_shear: peak_shear, force, stuck: m - next });
        // At that force: each slip hands its excess to the elements still stuck; the next
        // one slips too unless holding it at mu_s would take more than the held force.
        loop {
            slipped += n[next];
            next += 1;
            if next == m {
                break;
            }
            let stuck = m - next;
            if slip_force(law, slipped, n[next], stuck) > force {
                let shared = (force - law.mu_d * slipped) / stuck as f64;
                visit(CurvePoint { element_shear: shared, force, stuck });
                break;
            }
        }
    }
    // The last ramp ended at the peak, whose cascade slipped every element: the interface
    // slides at mu_d · N, shown up to where rigid control reaches total sliding.
    let sliding = law.mu_d * slipped;
    visit(CurvePoint { element_shear: peak_shear, force: sliding, stuck: 0 });
    let end = law.mu_s * n[m - 1];
    if end > peak_shear {
        visit(CurvePoint { element_shear: end, force: sliding, stuck: 0 });
    }
}

/// One row of `curve.csv`.
#[derive(Serialize)]
struct CurveRow {
    mode: &'static str,
    delta_over_peak: f64,
    delta_m: Option<f64>,
    element_shear_n: Option<f64>,
    force_n: Option<f64>,
    coefficient: f64,
    stuck: usize,
}

/// δ = s / k_t \[m]: the slider's displacement at which every stuck element carries the shear
/// `element_shear` s \[N], for an element shear stiffness `shear_stiffness` k_t [N/m].
pub fn displacement(element_shear: f64, shear_stiffness: f64) -> f64 {
    element_shear / shear_stiffness
}

/// Write `curves` as one CSV (long format, a block of rows per loading mode) with columns
/// `mode` ([`Loading::name`]), `delta_over_peak` (δ/δ_peak = s/s*, s* = `critical_shear`
/// \[N]), `delta_m` (δ = s/k_t \[m], empty without `shear_stiffness` k_t [N/m]),
/// `element_shear_n` (s \[N]), `force_n` (F \[N]), `coefficient` (F/N) and `stuck`. With
/// `in_newtons` false (forces from a map of unknown pixel area) the columns in newtons and
/// metres are left empty.
pub fn write_curves_csv(
    path: &Path,
    curves: &[Curve],
    critical_shear: f64,
    in_newtons: bool,
    shear_stiffness: Option<f64>,
) -> Result<()> {
    if let Some(k) = shear_stiffness {
        if !(k.is_finite() && k > 0.0) {
            return Err(Error::invalid("--shear-stiffness", format!("must be positive and finite, got {k} N/m")));
        }
    }
    write_atomic(path, |w| {
        let mut csv = csv::Writer::from_writer(w);
        for curve in curves {
            for p in &curve.points {
                let newtons = |x: f64| in_newtons.then_some(x);
                csv.serialize(CurveRow {
                    mode: curve.loading.name(),
                    delta_over_peak: p.element_shear / critical_shear,
                    delta_m: shear_stiffness.filter(|_| in_newtons).map(|k| displacement(p.element_shear, k)),
                    element_shear_n: newtons(p.element_shear),
                    force_n: newtons(p.force),
                    coefficient: p.force / curve.normal_force,
                    stuck: p.stuck,
                })?;
            }
        }
        csv.flush()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::friction::onset::Onset;

    fn loads(forces: &[f64]) -> ElementLoads {
        ElementLoads::from_forces(forces).unwrap()
    }

    fn pt(element_shear: f64, force: f64, stuck: usize) -> CurvePoint {
        CurvePoint { element_shear, force, stuck }
    }

    #[test]
    fn two_elements_by_hand() {
        // n = 1, 2 with mu_s = 1/2, mu_d = 1/4: F_0 = 1, F_1 = 1.25, N = 3.
        let law = FrictionLaw::new(0.5, 0.25).unwrap();
        let l = loads(&[2.0, 1.0]);
        let rigid = Curve::new(&l, &law, Loading::RigidDisplacement, 100);
        let expected = [pt(0.0, 0.0, 2), pt(0.5, 1.0, 2), pt(0.5, 0.75, 1), pt(1.0, 1.25, 1), pt(1.0, 0.75, 0)];
        assert_eq!(rigid.points, expected);
        assert_eq!(rigid.peak, 3);
        // Held force 1 after the first slip: the stuck element takes 1 − 0.25 = 0.75 < 1.
        let els = Curve::new(&l, &law, Loading::EqualLoadSharing, 100);
        let expected = [pt(0.0, 0.0, 2), pt(0.5, 1.0, 2), pt(0.75, 1.0, 1), pt(1.0, 1.25, 1), pt(1.0, 0.75, 0)];
        assert_eq!(els.points, expected);
        assert_eq!(els.peak, 3);
    }

    #[test]
    fn cascade_at_held_force() {
        // n = 1, 1.25 (the subcritical two-element case): after the first slip the stuck
        // element would need 0.25 + 0.625 = 0.875 < 1: it slips in the same cascade.
        let law = FrictionLaw::new(0.5, 0.25).unwrap();
        let els = Curve::new(&loads(&[1.0, 1.25]), &law, Loading::EqualLoadSharing, 100);
        let expected = [pt(0.0, 0.0, 2), pt(0.5, 1.0, 2), pt(0.5, 0.5625, 0), pt(0.625, 0.5625, 0)];
        assert_eq!(els.points, expected);
        assert_eq!(els.peak, 1);
    }

    #[test]
    fn decimation_keeps_the_exact_peak() {
        let law = FrictionLaw::new(0.6, 0.4).unwrap();
        // A smooth spread of forces, so the peak lies inside the sequence of events.
        let forces: Vec<f64> = (0..5000).map(|i| 1.0 + ((i * 7919) % 5000) as f64 / 1000.0).collect();
        let l = loads(&forces);
        let onset = Onset::new(&l, &law);
        for loading in Loading::ALL {
            let full = Curve::new(&l, &law, loading, usize::MAX);
            let small = Curve::new(&l, &law, loading, 200);
            assert!(full.points.len() > 5000, "{}", full.points.len());
            assert!(small.points.len() <= 200 && small.points.len() > 150, "{}", small.points.len());
            assert_eq!(small.peak_point(), full.peak_point());
            assert_eq!(small.peak_point().force, onset.static_force);
            assert_eq!(small.peak_point().element_shear, onset.critical_shear());
            assert_eq!(small.points.first(), full.points.first());
            assert_eq!(small.points.last(), full.points.last());
            assert_eq!(small.points[small.peak + 1], full.points[full.peak + 1]);
        }
    }

    #[test]
    fn csv_has_both_modes_and_optional_units() {
        let law = FrictionLaw::new(0.5, 0.25).unwrap();
        let l = loads(&[2.0, 1.0]);
        let curves: Vec<_> = Loading::ALL.iter().map(|&m| Curve::new(&l, &law, m, 100)).collect();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("curve.csv");
        write_curves_csv(&path, &curves, 1.0, true, Some(1000.0)).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<_> = text.lines().collect();
        assert_eq!(lines[0], "mode,delta_over_peak,delta_m,element_shear_n,force_n,coefficient,stuck");
        assert_eq!(lines.len(), 1 + 5 + 5);
        assert_eq!(lines[4], "equal_load_sharing,1.0,0.001,1.0,1.25,0.4166666666666667,1");
        write_curves_csv(&path, &curves, 1.0, false, Some(1000.0)).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.lines().nth(9).unwrap(), "rigid_displacement,1.0,,,,0.4166666666666667,1");
        let e = write_curves_csv(&path, &curves, 1.0, true, Some(-1.0)).unwrap_err().to_string();
        assert!(e.starts_with("--shear-stiffness:"), "{e}");
    }
}
