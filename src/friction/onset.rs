//! The onset of sliding: static friction force and coefficient, friction drop, and the
//! classes of the elements at the critical state, exactly, in O(M log M).
//!
//! Must not import study, shs, plot or report: friction builds on contact and the base row.

use ndarray::{Array2, ArrayBase, Data, Ix2};
use rayon::slice::ParallelSliceMut;
use serde::Serialize;

use super::law::FrictionLaw;
use crate::error::{Error, Result};

/// Below this many elements a serial sort beats rayon's parallel one.
const PARALLEL_SORT_MIN: usize = 1 << 15;

/// The normal forces n_i \[N] of the M contact elements, sorted ascending: the order in which
/// they slip. Equal forces reach mu_s together; their order among themselves is arbitrary
/// (unstable sort) and irrelevant, since they slip in one event (see [`Onset`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ElementLoads {
    sorted: Vec<f64>,
    total: f64,
}

impl ElementLoads {
    /// The elements of a pressure map \[Pa], shape (ny, nx): every pixel with `p > 0` carries
    /// `n = p · pixel_area`. A NaN, infinite or negative pressure, or a map without contact,
    /// is an error (named "pressure map"; callers reading a file name the file instead).
    pub fn from_pressure<S: Data<Elem = f64>>(pressure: &ArrayBase<S, Ix2>, pixel_area: f64) -> Result<Self> {
        if !(pixel_area.is_finite() && pixel_area > 0.0) {
            return Err(Error::invalid("--pixel-area", format!("must be positive and finite, got {pixel_area} m²")));
        }
        let mut loads = Vec::with_capacity(pressure.len());
        for &p in pressure.iter() {
            if p > 0.0 && p.is_finite() {
                loads.push(p * pixel_area);
            } else if p != 0.0 {
                return Err(bad_pressure(pressure));
            }
        }
        if let Some(i) = loads.iter().position(|n| !(*n > 0.0 && n.is_finite())) {
            let p = pressure.iter().filter(|p| **p > 0.0).nth(i).expect("one load per contact pixel");
            return Err(Error::invalid(
                "pressure map",
                format!("a pressure of {p} Pa on a pixel of {pixel_area} m² is a force no float represents"),
            ));
        }
        Self::from_unsorted(loads, "pressure map", "no contact: every pressure is zero")
    }

    /// Elements given by their normal forces \[N], each positive and finite.
    pub fn from_forces(forces: &[f64]) -> Result<Self> {
        if let Some((i, f)) = forces.iter().enumerate().find(|(_, f)| !(f.is_finite() && **f > 0.0)) {
            return Err(Error::invalid(
                "normal forces",
                format!("element {i} has force {f} N; each must be positive and finite"),
            ));
        }
        Self::from_unsorted(forces.to_vec(), "normal forces", "no element")
    }

    fn from_unsorted(mut sorted: Vec<f64>, what: &str, empty: &str) -> Result<Self> {
        if sorted.is_empty() {
            return Err(Error::invalid(what, empty));
        }
        // Every force here is a non-negative float (p, a > 0), and these order as their bit
        // patterns do (as f64::total_cmp orders them): integer keys sort a third faster.
        if sorted.len() >= PARALLEL_SORT_MIN {
            sorted.par_sort_unstable_by_key(|n| n.to_bits());
        } else {
            sorted.sort_unstable_by_key(|n| n.to_bits());
        }
        let total: f64 = sorted.iter().sum();
        if !(total.is_finite() && total > 0.0) {
            return Err(Error::invalid(
                what,
                format!("the total normal force {total} N is not positive and finite (not representable)"),
            ));
        }
        Ok(ElementLoads { sorted, total })
    }

    /// Number of elements M.
    pub fn len(&self) -> usize {
        self.sorted.len()
    }

    /// Never true: a value has at least one element.
    pub fn is_empty(&self) -> bool {
        self.sorted.is_empty()
    }

    /// The normal forces n_(0) ≤ … ≤ n_(M−1) \[N].
    pub fn sorted(&self) -> &[f64] {
        &self.sorted
    }

    /// The total normal force N = Σ n_i \[N].
    pub fn total(&self) -> f64 {
        self.total
    }
}

/// The one-line error for the first NaN, infinite or negative pixel of a pressure map.
fn bad_pressure<S: Data<Elem = f64>>(pressure: &ArrayBase<S, Ix2>) -> Error {
    let ((row, col), p) =
        pressure.indexed_iter().find(|(_, p)| !(p.is_finite() && **p >= 0.0)).expect("a bad pixel exists");
    let what = if p.is_nan() { "NaN".to_string() } else { format!("{p} Pa") };
    Error::invalid("pressure map", format!("pressure at row {row}, column {col} is {what}; it must be finite and ≥ 0"))
}

/// A set of equal normal forces in the sorted order. They reach mu_s together and slip in
/// one event: within the set F_k falls by (mu_s − mu_d)·n per element, so only its first
/// index can be a maximiser.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Group {
    /// Sorted index of its first element.
    pub start: usize,
    /// Their common normal force [N].
    pub n: f64,
    /// How many elements share it.
    pub count: usize,
    /// Σ_{j<start} n_(j) [N], summed element by element in slipping order.
    pub prefix: f64,
    /// Σ_{j<start+count} n_(j) [N], continuing the same sum.
    pub prefix_after: f64,
}

/// The groups of equal forces of a sorted slice, in slipping order.
pub(crate) fn groups(sorted: &[f64]) -> impl Iterator<Item = Group> + '_ {
    let mut start = 0;
    let mut prefix = 0.0;
    std::iter::from_fn(move || {
        let n = *sorted.get(start)?;
        let count = sorted[start..].iter().take_while(|&&x| x == n).count();
        let before = prefix;
        for &x in &sorted[start..start + count] {
            prefix += x;
        }
        let g = Group { start, n, count, prefix: before, prefix_after: prefix };
        start += count;
        Some(g)
    })
}

/// The tangential force [N] at which the weakest stuck element, of normal force `n`,
/// reaches mu_s while `stuck` elements share the shear and the slipped ones (normal force
/// `slipped` in total) carry mu_d: F = mu_d · slipped + mu_s · n · stuck.
pub(crate) fn slip_force(law: &FrictionLaw, slipped: f64, n: f64, stuck: usize) -> f64 {
    law.mu_d * slipped + law.mu_s * n * stuck as f64
}

/// What one element is at the critical state, with its code in `classes.npy`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(i8)]
pub enum ElementClass {
    /// Not in contact (pressure 0).
    NoContact = 0,
    /// Already slipped before the peak: stress ratio mu_d.
    PreSliding = 1,
    /// Stuck at stress ratio mu_s: n_i = n_(k*).
    Critical = 2,
    /// Stuck below mu_s, at mu_0 = mu_s · n_(k*) / n_i: made to slip by the others' failure.
    Subcritical = 3,
}

/// Count and shares of one class of elements at the critical state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ClassShare {
    /// Number of elements in the class.
    pub count: usize,
    /// Fraction of the normal load N they carry.
    pub normal_fraction: f64,
    /// Fraction of the static friction force F_S they carry.
    pub friction_fraction: f64,
}

impl ClassShare {
    /// The share of a class of `count` elements that carry `normal` \[N] of the normal load
    /// `totals.0` \[N] and `friction` \[N] of the friction force `totals.1` \[N].
    pub fn new(count: usize, normal: f64, friction: f64, totals: (f64, f64)) -> ClassShare {
        ClassShare { count, normal_fraction: normal / totals.0, friction_fraction: friction / totals.1 }
    }

    /// The share of the elements of `class` among `elements` (class, normal force \[N],
    /// friction force \[N]), their forces summed in the order given; `totals` as for
    /// [`ClassShare::new`].
    pub fn tally<C: PartialEq>(
        elements: impl IntoIterator<Item = (C, f64, f64)>,
        class: C,
        totals: (f64, f64),
    ) -> ClassShare {
        let (mut count, mut normal, mut friction) = (0, 0.0, 0.0);
        for (c, n, f) in elements {
            if c == class {
                count += 1;
                normal += n;
                friction += f;
            }
        }
        ClassShare::new(count, normal, friction, totals)
    }
}

/// The onset of sliding of an interface under equal load sharing.
///
/// The imposed tangential force is shared equally by the stuck elements; a slipped element
/// carries mu_d · n_i and the excess it releases goes to the elements still stuck. Elements
/// thus slip in order of increasing n, and element k (sorted) slips, once the k weaker ones
/// have, at
///
/// ```text
/// F_k = mu_d · Σ_{j<k} n_(j) + mu_s · n_(k) · (M − k).
/// ```
///
/// The interface fails at F_S = max_k F_k; k* is the first maximiser: the force first
/// reaches F_S there, after which F_k ≤ F_S for every k > k* and the held force slips them
/// all (an avalanche to total sliding). Ties: elements of equal n reach mu_s at the same
/// force, and once one slips the excess it hands on, (mu_s − mu_d)·n, pushes the others
/// past mu_s, so they slip in one event (at mu_s = mu_d nothing is handed on, and nothing
/// depends on it); their order within it (arbitrary here, lowest
/// pixel index first in the tests' reference simulation) changes no force and no class.
/// Hence k* is always the first of its group: all elements with n_i = n_(k*) are critical
/// and none of them is pre-sliding.
#[derive(Debug, Clone, PartialEq)]
pub struct Onset {
    /// The local law.
    pub law: FrictionLaw,
    /// Number of elements M.
    pub elements: usize,
    /// The normal load N \[N].
    pub normal_force: f64,
    /// The static friction force F_S \[N] (infinite when mu_s · N is past the largest float).
    pub static_force: f64,
    /// The static friction coefficient F_S / N, computed on scaled forces: always finite.
    pub static_coefficient: f64,
    /// k*: the sorted index of the first critical element (= number of pre-sliding ones).
    pub critical_index: usize,
    /// n_(k*): the normal force of the critical elements \[N].
    pub critical_normal_force: f64,
    /// Elements stuck at mu_s.
    pub critical: ClassShare,
    /// Elements slipped before the peak.
    pub pre_sliding: ClassShare,
    /// Elements stuck below mu_s.
    pub subcritical: ClassShare,
}

/// `x` · 2^`k`, exactly unless the result leaves the range of floats.
fn times_power_of_two(x: f64, k: i32) -> f64 {
    // 2^k itself may not be a float (k < −1022 or k > 1023): multiply in steps.
    let (mut x, mut k) = (x, k);
    while k != 0 {
        let step = k.clamp(-1000, 1000);
        x *= 2f64.powi(step);
        k -= step;
    }
    x
}

impl Onset {
    /// The onset for elements `loads` with local law `law`: O(M) on the sorted forces.
    ///
    /// The forces are scaled by a power of two (exact) that brings N into [1/2, 1) before any
    /// product is formed: subnormal forces keep their digits, and mu_s · n · (M − k) ≤ mu_s · N
    /// cannot overflow. So mu_d ≤ F_S / N ≤ mu_s holds for any representable input.
    pub fn new(loads: &ElementLoads, law: &FrictionLaw) -> Onset {
        let sorted = loads.sorted();
        let m = sorted.len();
        let n_total = loads.total();
        let shift = -(n_total.log2().floor() as i32) - 1;
        let scaled = |x: f64| times_power_of_two(x, shift);
        let total = scaled(n_total);
        let mut best: Option<(f64, Group)> = None;
        for g in groups(sorted) {
            let f = slip_force(law, scaled(g.prefix), scaled(g.n), m - g.start);
            if best.is_none_or(|(fs, _)| f > fs) {
                best = Some((f, g));
            }
        }
        let (fs, g) = best.expect("ElementLoads is never empty");
        let subcritical_count = m - g.start - g.count;
        let subcritical_normal = sorted[g.start + g.count..].iter().fold(0.0, |sum, &x| sum + x);
        let stuck_shear = law.mu_s * scaled(g.n);
        // Rounding may put the last bit outside [mu_d, mu_s], where the exact value never is.
        let static_coefficient = (fs / total).clamp(law.mu_d, law.mu_s);
        Onset {
            law: law.clone(),
            elements: m,
            normal_force: n_total,
            static_force: times_power_of_two(fs, -shift),
            static_coefficient,
            critical_index: g.start,
            critical_normal_force: g.n,
            critical: ClassShare::new(g.count, scaled(g.n) * g.count as f64, stuck_shear * g.count as f64, (total, fs)),
            pre_sliding: ClassShare::new(g.start, g.prefix, law.mu_d * scaled(g.prefix), (n_total, fs)),
            subcritical: ClassShare::new(
                subcritical_count,
                subcritical_normal,
                stuck_shear * subcritical_count as f64,
                (n_total, fs),
            ),
        }
    }

    /// The static friction coefficient F_S / N, between mu_d and mu_s.
    pub fn static_coefficient(&self) -> f64 {
        self.static_coefficient
    }

    /// The dynamic friction coefficient of the interface: mu_d (all elements sliding).
    pub fn dynamic_coefficient(&self) -> f64 {
        self.law.mu_d
    }

    /// The friction drop F_S / (mu_d · N), between 1 and mu_s / mu_d.
    pub fn friction_drop(&self) -> f64 {
        self.static_coefficient / self.law.mu_d
    }

    /// s* = mu_s · n_(k*) \[N]: the shear of every stuck element at the critical state, so
    /// δ_peak = s* / k_t for an element shear stiffness k_t.
    pub fn critical_shear(&self) -> f64 {
        self.law.mu_s * self.critical_normal_force
    }

    /// The class at the critical state of an element of normal force `n` \[N].
    pub fn class_of(&self, n: f64) -> ElementClass {
        match n.total_cmp(&self.critical_normal_force) {
            std::cmp::Ordering::Less => ElementClass::PreSliding,
            std::cmp::Ordering::Equal => ElementClass::Critical,
            std::cmp::Ordering::Greater => ElementClass::Subcritical,
        }
    }

    /// The local stress ratio (shear / normal force) of an element of normal force `n` \[N]
    /// at the imposed displacement δ = `fraction` · δ_peak, 0 < fraction ≤ 1: elements with
    /// mu_s · n below the stuck shear s = fraction · s* have slipped (mu_d); the others are
    /// stuck at s / n = mu_s · fraction · n_(k*) / n. At fraction = 1 these are the ratios
    /// mu_d, mu_s and mu_0 of the critical state. Before the peak both loading modes pass
    /// through the same states, so this holds for either.
    pub fn stress_ratio_of(&self, n: f64, fraction: f64) -> f64 {
        if self.has_slipped(n, fraction) {
            self.law.mu_d
        } else {
            self.law.mu_s * (fraction * self.critical_normal_force / n)
        }
    }

    /// Whether an element of normal force `n` \[N] has slipped at δ = `fraction` · δ_peak,
    /// 0 < fraction ≤ 1: whether mu_s · n is below the stuck shear fraction · s*.
    pub fn has_slipped(&self, n: f64, fraction: f64) -> bool {
        n < fraction * self.critical_normal_force
    }

    /// The class of every pixel of `pressure` \[Pa] (the map the onset was computed from,
    /// with the same `pixel_area` \[m²]): codes of [`ElementClass`], 0 where p = 0.
    pub fn class_map<S: Data<Elem = f64>>(&self, pressure: &ArrayBase<S, Ix2>, pixel_area: f64) -> Array2<i8> {
        pressure.mapv(|p| if p > 0.0 { self.class_of(p * pixel_area) as i8 } else { ElementClass::NoContact as i8 })
    }

    /// The local stress ratio of every pixel at δ = `fraction` · δ_peak (see
    /// [`Onset::stress_ratio_of`]); NaN where there is no contact.
    pub fn stress_ratio_map<S: Data<Elem = f64>>(
        &self,
        pressure: &ArrayBase<S, Ix2>,
        pixel_area: f64,
        fraction: f64,
    ) -> Result<Array2<f64>> {
        if !(fraction > 0.0 && fraction <= 1.0) {
            return Err(Error::invalid("--snapshots", format!("δ/δ_peak must lie in (0, 1], got {fraction}")));
        }
        Ok(pressure.mapv(|p| if p > 0.0 { self.stress_ratio_of(p * pixel_area, fraction) } else { f64::NAN }))
    }
}

#[cfg(test)]
mod tests {
    use ndarray::array;

    use super::*;

    fn law(mu_s: f64, mu_d: f64) -> FrictionLaw {
        FrictionLaw::new(mu_s, mu_d).unwrap()
    }

    fn onset(forces: &[f64], law: &FrictionLaw) -> Onset {
        Onset::new(&ElementLoads::from_forces(forces).unwrap(), law)
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 4.0 * f64::EPSILON * b.abs()
    }

    #[test]
    fn one_element_drops_by_the_local_ratio() {
        for (mu_s, mu_d, n) in [(0.6, 0.4, 2.5e-6), (0.9, 0.1, 7.0), (0.5, 0.5, 1.0)] {
            let o = onset(&[n], &law(mu_s, mu_d));
            assert!(close(o.friction_drop(), mu_s / mu_d), "{}", o.friction_drop());
            assert!(close(o.static_coefficient(), mu_s));
            assert_eq!((o.critical.count, o.pre_sliding.count, o.subcritical.count), (1, 0, 0));
        }
    }

    #[test]
    fn equal_elements_are_all_critical() {
        let o = onset(&[3.0; 7], &law(0.6, 0.4));
        assert!(close(o.friction_drop(), 1.5));
        assert_eq!(o.critical_index, 0);
        assert_eq!((o.critical.count, o.pre_sliding.count, o.subcritical.count), (7, 0, 0));
        assert_eq!((o.critical.normal_fraction, o.critical.friction_fraction), (1.0, 1.0));
    }

    #[test]
    fn shares_tallied_element_by_element_are_the_closed_forms() {
        let forces = [0.3, 1.0, 2.0, 2.0, 2.1, 2.3, 2.6, 3.1, 2.4, 0.9, 2.5];
        let o = onset(&forces, &law(0.5, 0.3));
        assert!(o.pre_sliding.count > 0 && o.critical.count == 2 && o.subcritical.count > 0);
        // At the critical state a slipped element carries mu_d · n, a stuck one s*.
        let elements = forces.iter().map(|&n| {
            let class = o.class_of(n);
            (class, n, if class == ElementClass::PreSliding { 0.3 * n } else { o.critical_shear() })
        });
        let totals = (o.normal_force, o.static_force);
        for (class, closed) in [
            (ElementClass::PreSliding, o.pre_sliding),
            (ElementClass::Critical, o.critical),
            (ElementClass::Subcritical, o.subcritical),
        ] {
            let t = ClassShare::tally(elements.clone(), class, totals);
            let near = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b;
            assert_eq!(t.count, closed.count, "{class:?}");
            assert!(near(t.normal_fraction, closed.normal_fraction), "{class:?}: {t:?} vs {closed:?}");
            assert!(near(t.friction_fraction, closed.friction_fraction), "{class:?}: {t:?} vs {closed:?}");
        }
    }

    // Two elements n1 < n2: F_0 = 2 mu_s n1 (both stuck, the weaker at mu_s) and
    // F_1 = mu_d n1 + mu_s n2 (the weaker slipped). The weaker is pre-sliding at the peak iff
    // F_1 > F_0, i.e. n2/n1 > 2 − mu_d/mu_s; otherwise the stronger is subcritical. With
    // mu_s = 1/2, mu_d = 1/4 the boundary is n2/n1 = 3/2.
    const MU_S: f64 = 0.5;
    const MU_D: f64 = 0.25;

    #[test]
    fn two_elements_one_pre_sliding() {
        let (n1, n2) = (1.0, 2.0);
        let o = onset(&[n2, n1], &law(MU_S, MU_D));
        let mu = (MU_D * n1 + MU_S * n2) / (n1 + n2); // the paper's (mu_d N^D + mu_s N^S) / N
        assert_eq!(mu, 5.0 / 12.0);
        assert_eq!(o.static_coefficient(), mu);
        assert_eq!(o.friction_drop(), 5.0 / 3.0);
        assert_eq!(o.critical_index, 1);
        assert_eq!(o.pre_sliding, ClassShare { count: 1, normal_fraction: 1.0 / 3.0, friction_fraction: 0.2 });
        assert_eq!(o.critical, ClassShare { count: 1, normal_fraction: 2.0 / 3.0, friction_fraction: 0.8 });
        assert_eq!(o.subcritical.count, 0);
        let p = array![[n2, 0.0, n1]];
        assert_eq!(o.class_map(&p, 1.0), array![[2, 0, 1]]);
        let r = o.stress_ratio_map(&p, 1.0, 1.0).unwrap();
        assert_eq!((r[[0, 0]], r[[0, 2]]), (MU_S, MU_D));
        assert!(r[[0, 1]].is_nan());
    }

    #[test]
    fn two_elements_one_subcritical() {
        let (n1, n2) = (1.0, 1.25);
        let o = onset(&[n1, n2], &law(MU_S, MU_D));
        let mu_0 = MU_S * n1 / n2;
        assert_eq!(mu_0, 0.4);
        let mu = (mu_0 * n2 + MU_S * n1) / (n1 + n2); // the paper's (mu_0 N^0 + mu_s N^S) / N
        assert_eq!(mu, 4.0 / 9.0);
        assert_eq!(o.static_coefficient(), mu);
        assert_eq!(o.friction_drop(), 16.0 / 9.0);
        assert_eq!(o.critical_index, 0);
        assert_eq!((o.critical.count, o.pre_sliding.count, o.subcritical.count), (1, 0, 1));
        assert_eq!((o.critical.friction_fraction, o.subcritical.friction_fraction), (0.5, 0.5));
        assert_eq!((o.critical.normal_fraction, o.subcritical.normal_fraction), (1.0 / 2.25, 1.25 / 2.25));
        let r = o.stress_ratio_map(&array![[n1, n2]], 1.0, 1.0).unwrap();
        assert_eq!(r, array![[MU_S, mu_0]]);
    }

    #[test]
    fn two_element_boundary_from_both_sides() {
        let boundary = 2.0 - MU_D / MU_S;
        assert_eq!(boundary, 1.5);
        let below = onset(&[1.0, boundary - 1e-9], &law(MU_S, MU_D));
        assert_eq!((below.pre_sliding.count, below.subcritical.count), (0, 1));
        let above = onset(&[1.0, boundary + 1e-9], &law(MU_S, MU_D));
        assert_eq!((above.pre_sliding.count, above.subcritical.count), (1, 0));
        // On it F_0 = F_1: the force first reaches F_S with both stuck, so the stronger is
        // subcritical (at mu_0 = mu_s / 1.5), and both formulas give mu = 0.4.
        let on = onset(&[1.0, boundary], &law(MU_S, MU_D));
        assert_eq!((on.critical_index, on.subcritical.count), (0, 1));
        assert_eq!(on.static_coefficient(), 0.4);
        assert_eq!((MU_D * 1.0 + MU_S * boundary) / 2.5, 0.4);
        // The coefficient is continuous across the boundary.
        assert!((below.static_coefficient() - 0.4).abs() < 1e-9 && (above.static_coefficient() - 0.4).abs() < 1e-9);
    }

    #[test]
    fn ties_make_one_critical_group() {
        // Groups 1,1 | 2,2,2 | 9, with mu_s = 1/2, mu_d = 1/4, at the group starts:
        // F_0 = 0.5·1·6 = 3, F_2 = 0.25·2 + 0.5·2·4 = 4.5, F_5 = 0.25·8 + 0.5·9 = 6.5.
        let o = onset(&[2.0, 1.0, 9.0, 2.0, 1.0, 2.0], &law(MU_S, MU_D));
        assert_eq!(o.static_force, 6.5);
        assert_eq!((o.critical_index, o.critical.count, o.pre_sliding.count), (5, 1, 5));
        let o = onset(&[2.0, 1.0, 2.5, 2.0, 1.0, 2.0], &law(MU_S, MU_D));
        // F_0 = 3, F_2 = 0.5 + 0.5·2·4 = 4.5, F_5 = 0.25·8 + 0.5·2.5 = 3.25.
        assert_eq!(o.static_force, 4.5);
        assert_eq!((o.critical_index, o.critical.count, o.pre_sliding.count, o.subcritical.count), (2, 3, 2, 1));
        assert_eq!(o.class_of(2.0), ElementClass::Critical);
    }

    #[test]
    fn bad_pressure_maps_are_one_line_errors() {
        let msg = |p: Array2<f64>| ElementLoads::from_pressure(&p, 1e-16).unwrap_err().to_string();
        let e = msg(array![[0.0, 1.0], [f64::NAN, 2.0]]);
        assert_eq!(e, "pressure map: pressure at row 1, column 0 is NaN; it must be finite and ≥ 0");
        assert!(msg(array![[0.0, -3.0]]).contains("row 0, column 1 is -3 Pa"));
        assert!(msg(array![[f64::INFINITY, 1.0]]).contains("inf Pa"));
        assert!(msg(Array2::zeros((4, 4))).contains("no contact"));
        let e = ElementLoads::from_pressure(&array![[1.0]], 0.0).unwrap_err().to_string();
        assert!(e.starts_with("--pixel-area:"), "{e}");
        assert!(ElementLoads::from_forces(&[1.0, 0.0]).unwrap_err().to_string().contains("element 1"));
    }

    #[test]
    fn subnormal_and_huge_forces_keep_the_coefficient_between_mu_d_and_mu_s() {
        // Every element alike: a single-element interface's drop, mu_s / mu_d, at any scale.
        for n in [5e-324, 1e-310, 1e-300, 1.0, 1e300, 1.5e307] {
            let o = onset(&[n; 3], &law(0.6, 0.4));
            assert_eq!(o.static_coefficient(), 0.6, "n = {n}");
            assert!(close(o.friction_drop(), 1.5), "n = {n}: {}", o.friction_drop());
        }
        let p = Array2::from_elem((4, 4), 5e-324);
        let o = Onset::new(&ElementLoads::from_pressure(&p, 1.0).unwrap(), &law(0.6, 0.4));
        assert!(o.static_coefficient() == 0.6 && close(o.friction_drop(), 1.5));
        // Underflow to a zero force is refused, not counted.
        let e = ElementLoads::from_pressure(&p, 1e-16).unwrap_err().to_string();
        assert!(e.contains("no float represents"), "{e}");
        // Extreme laws: the coefficient stays finite and between the two.
        let o = onset(&[1.0, 2.0, 3.0], &law(1e300, 1e-7));
        assert!(o.static_coefficient() <= 1e300 && o.static_coefficient() >= 1e-7 && o.friction_drop().is_finite());
        assert!(FrictionLaw::new(1e308, 1e-300).unwrap_err().to_string().contains("not representable"));
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(256))]

        /// mu_d ≤ F_S / N ≤ mu_s for forces and laws over the whole range of floats.
        #[test]
        fn the_coefficient_lies_between_mu_d_and_mu_s(
            mantissas in proptest::collection::vec(1.0f64..2.0, 1..40),
            exponents in proptest::collection::vec(-1074i32..1000, 40),
            base in -1074i32..1000,
            spread in 0i32..60,
            mu_d_exp in -300i32..300,
            ratio in 1.0f64..1e6,
        ) {
            // Forces of one magnitude with a few decades of spread, or anywhere in the range.
            let forces: Vec<f64> = mantissas
                .iter()
                .zip(&exponents)
                .enumerate()
                .map(|(i, (m, e))| {
                    let e = if i % 2 == 0 { (base + e.rem_euclid(spread + 1)).min(1000) } else { *e };
                    times_power_of_two(*m, e)
                })
                .filter(|n| *n > 0.0)
                .collect();
            proptest::prop_assume!(!forces.is_empty() && forces.iter().sum::<f64>().is_finite());
            let mu_d = 10f64.powi(mu_d_exp);
            let law = law(mu_d * ratio, mu_d);
            let o = onset(&forces, &law);
            let c = o.static_coefficient();
            proptest::prop_assert!(c >= law.mu_d && c <= law.mu_s, "{} not in [{}, {}]", c, law.mu_d, law.mu_s);
            let drop = o.friction_drop();
            proptest::prop_assert!(drop >= 1.0 && drop <= ratio * (1.0 + 1e-12), "drop {}", drop);
            let shares = o.critical.normal_fraction + o.pre_sliding.normal_fraction + o.subcritical.normal_fraction;
            proptest::prop_assert!((shares - 1.0).abs() < 1e-9, "normal fractions sum to {}", shares);
            let shares = o.critical.friction_fraction + o.pre_sliding.friction_fraction + o.subcritical.friction_fraction;
            proptest::prop_assert!(shares <= 1.0 + 1e-9, "friction fractions sum to {}", shares);
        }
    }

    #[test]
    fn snapshot_fraction_is_checked() {
        let o = onset(&[1.0, 2.0], &law(MU_S, MU_D));
        let p = array![[1.0, 2.0]];
        assert!(o.stress_ratio_map(&p, 1.0, 0.0).is_err());
        assert!(o.stress_ratio_map(&p, 1.0, 1.5).is_err());
        // Half-way to the peak (s = 0.5 s* = 0.5 N): nothing slipped, ratios s/n.
        assert_eq!(o.stress_ratio_map(&p, 1.0, 0.5).unwrap(), array![[0.5, 0.25]]);
    }
}
