//! Properties of the stick-slip transition model, and its agreement with a brute-force,
//! element-by-element simulation of the equal-load-sharing dynamics in exact arithmetic.

use asperity::friction::{Curve, ElementClass, ElementLoads, FrictionLaw, Loading, Onset};
use ndarray::Array2;
use proptest::prelude::*;

/// An exact rational number, enough for a dozen elements with small integer forces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Q {
    num: i128,
    den: i128,
}

fn gcd(a: i128, b: i128) -> i128 {
    if b == 0 {
        a.abs()
    } else {
        gcd(b, a % b)
    }
}

impl Q {
    fn new(num: i128, den: i128) -> Q {
        let g = gcd(num, den).max(1) * den.signum();
        Q { num: num / g, den: den / g }
    }
    fn int(n: i128) -> Q {
        Q { num: n, den: 1 }
    }
    fn add(self, o: Q) -> Q {
        Q::new(self.num.checked_mul(o.den).unwrap() + o.num.checked_mul(self.den).unwrap(), self.den * o.den)
    }
    fn sub(self, o: Q) -> Q {
        self.add(Q { num: -o.num, den: o.den })
    }
    fn mul(self, o: Q) -> Q {
        Q::new(self.num.checked_mul(o.num).unwrap(), self.den.checked_mul(o.den).unwrap())
    }
    fn div(self, o: Q) -> Q {
        Q::new(self.num.checked_mul(o.den).unwrap(), self.den.checked_mul(o.num).unwrap())
    }
    fn f64(self) -> f64 {
        self.num as f64 / self.den as f64
    }
}

impl PartialOrd for Q {
    fn partial_cmp(&self, o: &Q) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Q {
    fn cmp(&self, o: &Q) -> std::cmp::Ordering {
        (self.num * o.den).cmp(&(o.num * self.den))
    }
}

/// What the brute-force dynamics finds.
struct Dynamics {
    /// (shear of the stuck elements, force, stuck count) at the end of each loading ramp and
    /// of each arrested cascade, from (0, 0, M).
    vertices: Vec<(Q, Q, usize)>,
    static_force: Q,
    classes: Vec<ElementClass>,
    ratios: Vec<Q>,
}

/// Equal load sharing element by element, in O(M²), without sorting: ramps add the same
/// shear to every stuck element until one reaches mu_s · n_i; then, at held force, any stuck
/// element at or above mu_s · n_i slips (the weakest first, then the lowest index), drops to
/// mu_d · n_i and hands its excess to the stuck elements in equal parts. The critical state is
/// the first state of maximal force.
fn simulate(n: &[i128], mu_s: Q, mu_d: Q) -> Dynamics {
    let m = n.len();
    let strength: Vec<Q> = n.iter().map(|&x| mu_s.mul(Q::int(x))).collect();
    let mut shear = vec![Q::int(0); m];
    let mut stuck = vec![true; m];
    let mut force = Q::int(0);
    let mut vertices = vec![(force, force, m)];
    let mut best: Option<(Q, Vec<ElementClass>, Vec<Q>)> = None;
    loop {
        let stuck_ids: Vec<usize> = (0..m).filter(|&i| stuck[i]).collect();
        if stuck_ids.is_empty() {
            break;
        }
        let d = stuck_ids.iter().map(|&i| strength[i].sub(shear[i])).min().unwrap();
        for &i in &stuck_ids {
            shear[i] = shear[i].add(d);
        }
        force = force.add(d.mul(Q::int(stuck_ids.len() as i128)));
        vertices.push((shear[stuck_ids[0]], force, stuck_ids.len()));
        if best.as_ref().is_none_or(|b| force > b.0) {
            let classes = (0..m)
                .map(|i| match (stuck[i], shear[i] == strength[i]) {
                    (false, _) => ElementClass::PreSliding,
                    (true, true) => ElementClass::Critical,
                    (true, false) => ElementClass::Subcritical,
                })
                .collect();
            let ratios = (0..m).map(|i| shear[i].div(Q::int(n[i]))).collect();
            best = Some((force, classes, ratios));
        }
        while let Some(i) = (0..m).filter(|&i| stuck[i] && shear[i] >= strength[i]).min_by_key(|&i| (n[i], i)) {
            let kinetic = mu_d.mul(Q::int(n[i]));
            let excess = shear[i].sub(kinetic);
            shear[i] = kinetic;
            stuck[i] = false;
            let rest: Vec<usize> = (0..m).filter(|&j| stuck[j]).collect();
            for &j in &rest {
                shear[j] = shear[j].add(excess.div(Q::int(rest.len() as i128)));
            }
            if let Some(&j) = rest.first() {
                let total = shear.iter().fold(Q::int(0), |a, &s| a.add(s));
                assert_eq!(total, force, "redistribution conserves the held force");
                if rest.iter().all(|&k| shear[k] < strength[k]) {
                    vertices.push((shear[j], force, rest.len()));
                }
            }
        }
    }
    let (static_force, classes, ratios) = best.unwrap();
    Dynamics { vertices, static_force, classes, ratios }
}

fn rel_close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs())
}

/// A law with mu_d in (0.01, 1] and mu_s/mu_d in [1, 4].
fn any_law() -> impl Strategy<Value = FrictionLaw> {
    (0.01f64..=1.0, 1.0f64..=4.0).prop_map(|(mu_d, r)| FrictionLaw::new(mu_d * r, mu_d).unwrap())
}

/// A pressure map [Pa] with some pixels out of contact and at least one in contact.
fn any_pressure() -> impl Strategy<Value = Array2<f64>> {
    (1usize..8, 1usize..8)
        .prop_flat_map(|(ny, nx)| {
            (Just((ny, nx)), prop::collection::vec(prop_oneof![1 => Just(0.0), 3 => 1e3f64..1e9], ny * nx))
        })
        .prop_filter("some contact", |(_, v)| v.iter().any(|&p| p > 0.0))
        .prop_map(|(shape, v)| Array2::from_shape_vec(shape, v).unwrap())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn drop_lies_between_one_and_the_local_drop(p in any_pressure(), law in any_law()) {
        let o = Onset::new(&ElementLoads::from_pressure(&p, 1e-16).unwrap(), &law);
        prop_assert!(o.friction_drop() >= 1.0 - 1e-12, "{}", o.friction_drop());
        prop_assert!(o.friction_drop() <= law.drop() * (1.0 + 1e-12), "{} > {}", o.friction_drop(), law.drop());
    }

    #[test]
    fn class_fractions_sum_to_one(p in any_pressure(), law in any_law()) {
        let o = Onset::new(&ElementLoads::from_pressure(&p, 2.5e-15).unwrap(), &law);
        let shares = [o.critical, o.pre_sliding, o.subcritical];
        prop_assert_eq!(shares.iter().map(|s| s.count).sum::<usize>(), o.elements);
        prop_assert!((shares.iter().map(|s| s.normal_fraction).sum::<f64>() - 1.0).abs() < 1e-12);
        prop_assert!((shares.iter().map(|s| s.friction_fraction).sum::<f64>() - 1.0).abs() < 1e-12);
        prop_assert!(o.critical.count >= 1);
        // The class map agrees with the counts.
        let classes = o.class_map(&p, 2.5e-15);
        for (class, share) in [(2, o.critical), (1, o.pre_sliding), (3, o.subcritical)] {
            prop_assert_eq!(classes.iter().filter(|&&c| c == class).count(), share.count);
        }
    }

    #[test]
    fn invariant_under_scaling_pressure_and_pixel_size(
        p in any_pressure(), law in any_law(), c in 1e-4f64..1e4, area in 1e-18f64..1e-12, c_area in 1e-3f64..1e3,
    ) {
        let base = Onset::new(&ElementLoads::from_pressure(&p, area).unwrap(), &law);
        let scaled_p = p.mapv(|x| x * c);
        for (map, a, factor) in [(&scaled_p, area, c), (&p, area * c_area, c_area)] {
            let o = Onset::new(&ElementLoads::from_pressure(map, a).unwrap(), &law);
            prop_assert!(rel_close(o.friction_drop(), base.friction_drop(), 1e-12));
            prop_assert!(rel_close(o.static_coefficient(), base.static_coefficient(), 1e-12));
            prop_assert!(rel_close(o.static_force, base.static_force * factor, 1e-12));
            prop_assert_eq!(o.critical_index, base.critical_index);
            for (x, y) in [(o.critical, base.critical), (o.pre_sliding, base.pre_sliding), (o.subcritical, base.subcritical)] {
                prop_assert_eq!(x.count, y.count);
                prop_assert!((x.normal_fraction - y.normal_fraction).abs() < 1e-12);
                prop_assert!((x.friction_fraction - y.friction_fraction).abs() < 1e-12);
            }
            prop_assert_eq!(o.class_map(map, a), base.class_map(&p, area));
        }
    }

    #[test]
    fn both_loading_modes_share_the_peak(p in any_pressure(), law in any_law()) {
        let loads = ElementLoads::from_pressure(&p, 1e-16).unwrap();
        let o = Onset::new(&loads, &law);
        let els = Curve::new(&loads, &law, Loading::EqualLoadSharing, usize::MAX);
        let rigid = Curve::new(&loads, &law, Loading::RigidDisplacement, usize::MAX);
        for c in [&els, &rigid] {
            prop_assert!(rel_close(c.peak_point().force, o.static_force, 1e-12));
            prop_assert_eq!(c.peak_point().element_shear, o.critical_shear());
            prop_assert_eq!(c.peak_point().stuck, o.elements - o.critical_index);
            prop_assert!(c.points.iter().all(|q| q.force <= c.peak_point().force));
        }
        // Before the peak the held-force path is the running maximum of the rigid one: at
        // each of its vertices the rigid state has the same force, and no earlier rigid
        // state exceeds it.
        let n = loads.sorted();
        for q in &els.points[..=els.peak] {
            let slipped: f64 = n.iter().filter(|&&x| law.mu_s * x < q.element_shear).sum();
            let stuck = n.iter().filter(|&&x| law.mu_s * x >= q.element_shear).count();
            prop_assert!(rel_close(q.force, law.mu_d * slipped + q.element_shear * stuck as f64, 1e-9));
            let earlier = rigid.points.iter().filter(|r| r.element_shear <= q.element_shear);
            prop_assert!(earlier.clone().all(|r| r.force <= q.force * (1.0 + 1e-12)));
        }
        // Past the peak both end in total sliding at mu_d N.
        for c in [&els, &rigid] {
            let last = c.points.last().unwrap();
            prop_assert!(last.stuck == 0 && rel_close(last.force, law.mu_d * loads.total(), 1e-12));
        }
    }

    #[test]
    fn ties_are_one_critical_group(v in prop::collection::vec(0u8..5, 1..40), law in any_law()) {
        prop_assume!(v.iter().any(|&x| x > 0));
        let p = Array2::from_shape_vec((1, v.len()), v.iter().map(|&x| f64::from(x) * 1e6).collect()).unwrap();
        let loads = ElementLoads::from_pressure(&p, 1e-12).unwrap();
        let o = Onset::new(&loads, &law);
        let n = loads.sorted();
        let star = o.critical_normal_force;
        prop_assert_eq!(o.critical.count, n.iter().filter(|&&x| x == star).count());
        prop_assert!(o.critical_index == 0 || n[o.critical_index - 1] < star);
        prop_assert_eq!(o.pre_sliding.count, n.iter().filter(|&&x| x < star).count());
    }

    #[test]
    fn onset_and_curve_match_the_brute_force_dynamics(
        n in prop::collection::vec(1i128..=12, 1..10), a in 1i128..=8, b in 0i128..=8,
    ) {
        // Dyadic coefficients and integer forces: the library's floating-point sums are exact.
        let (mu_d, mu_s) = (Q::new(a, 8), Q::new(a + b, 8));
        let law = FrictionLaw::new(mu_s.f64(), mu_d.f64()).unwrap();
        let truth = simulate(&n, mu_s, mu_d);
        let p = Array2::from_shape_vec((1, n.len()), n.iter().map(|&x| x as f64).collect()).unwrap();
        let loads = ElementLoads::from_pressure(&p, 1.0).unwrap();
        let o = Onset::new(&loads, &law);
        prop_assert_eq!(o.static_force, truth.static_force.f64());
        let classes: Vec<i8> = o.class_map(&p, 1.0).iter().copied().collect();
        let expected: Vec<i8> = truth.classes.iter().map(|&c| c as i8).collect();
        prop_assert_eq!(classes, expected);
        let ratios = o.stress_ratio_map(&p, 1.0, 1.0).unwrap();
        for (r, q) in ratios.iter().zip(&truth.ratios) {
            prop_assert!(rel_close(*r, q.f64(), 1e-14), "{} vs {}", r, q.f64());
        }
        // The curve's vertices up to total sliding are the simulation's.
        let els = Curve::new(&loads, &law, Loading::EqualLoadSharing, usize::MAX);
        let sliding = els.points.iter().position(|q| q.stuck == 0).unwrap();
        prop_assert_eq!(sliding, truth.vertices.len());
        for (q, (s, f, k)) in els.points.iter().zip(&truth.vertices) {
            prop_assert!(rel_close(q.element_shear, s.f64(), 1e-14), "{} vs {}", q.element_shear, s.f64());
            prop_assert_eq!(q.force, f.f64());
            prop_assert_eq!(q.stuck, *k);
        }
    }
}

#[test]
fn brute_force_reproduces_the_paper_two_element_cases() {
    // Guard the reference itself: n = 1, 2 and n = 4, 5 with mu_s = 1/2, mu_d = 1/4
    // (boundary n2/n1 = 3/2): one pre-sliding, then one subcritical at mu_0 = (1/2)·4/5.
    let (mu_s, mu_d) = (Q::new(1, 2), Q::new(1, 4));
    let d = simulate(&[1, 2], mu_s, mu_d);
    assert_eq!(d.static_force, Q::new(5, 4));
    assert_eq!(d.classes, [ElementClass::PreSliding, ElementClass::Critical]);
    let d = simulate(&[4, 5], mu_s, mu_d);
    assert_eq!(d.static_force, Q::int(4));
    assert_eq!(d.classes, [ElementClass::Critical, ElementClass::Subcritical]);
    assert_eq!(d.ratios[1], Q::new(2, 5));
}
