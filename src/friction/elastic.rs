//! The onset of sliding with elastic interaction between the contact points: the body is
//! displaced rigidly by δ along x, quasi-statically and increasing, and the shear tractions
//! follow from the constrained tangential solve ([`TangentialSolver`]) instead of being shared
//! equally among the stuck elements.
//!
//! The local law has memory: a point's friction coefficient is mu_s until it first slips and
//! falls to mu_d after (the paper's instant drop), or falls linearly from mu_s to mu_d over an
//! accumulated slip d_c ([`Weakening::Linear`]), or follows a measured μ(slip) curve
//! ([`Weakening::Curve`]). Each displacement step is one increment: targets b_i = δ e_x − c_i
//! (c_i the slip accumulated so far), bounds μ_i p_i; when the solve makes points slip, their
//! coefficients are updated from the new slip and the step is solved again at the same δ
//! (a slip cascade) until no bound moves by more than the solve resolves. F(δ) = Σ q_x · a;
//! F_S is its largest value along the path. A coarse step overestimates the force before its
//! cascade, so the step holding the largest force is repeated from its start with finer
//! steps, until that force lies in a step of the finest length; the path from δ = 0 takes
//! longer steps while its force is far below μ_d N (for a law whose coefficients only fall),
//! which F_S is never below, so that they hold no force worth refining. Once every point
//! slides, the tractions turn towards x as δ grows and F tends to the sliding force Σ μ p a (μ_d N for the
//! instant drop): F_S is never below it, though the path stops at total sliding with tractions
//! still turned by the elastic coupling.

use serde::Serialize;

use super::{stuck_stiffness, ClassShare};
use crate::contact::tangential::magnitude;
use crate::contact::{Proceed, TangentialReport, TangentialSolver};
use crate::error::{Error, Result};

/// Displacement steps up to the stuck estimate of the peak, μ_s N / k_t (the path's longer
/// first steps aside). More do not make the drop converge: at 1500² with its wafer, 10 mN,
/// mu_s 0.6, mu_d 0.4, 16, 32, 64, 128, 256, 1 024 and 4 096 steps give drops within
/// 1.00114–1.00121 (16: 1.0011937), as the order of the cascades, and with it the one that
/// peaks highest, changes with the steps; at 0.1 and 1 mN within 4e-6 (16 to 256). 64 rather
/// than 16 (with one refinement less, the same finest step): a coarse step overestimates its
/// force by about its length times the path's stiffness, and every coarse step whose
/// overestimate passes F_S is refined; shorter ones leave fewer to refine. Measured (stand-in
/// ball, mu_s 0.6, mu_d 0.4; with the refinement of one step alone, below): 512², 10 and
/// 100 mN, d_c 2 nm 2 444 → 1 906 and 7 757 → 5 180 applications, instant drop 1 078 → 714 and
/// 1 598 → 1 075; 1500², 100 mN instant 2 214 → 1 659; 1500², 1 mN, d_c 2 nm 4 431 → 4 302;
/// drops moved by 2e-6 to 7e-6, and by 3.0e-5 at 512², 100 mN instant (another cascade peaks).
const STEPS: usize = 64;
/// A step holding the largest force is refined up to this many times, each time in steps this
/// many times finer: F_S located to 1/(64·4⁶) = 1/262144 of μ_s N / k_t.
const REFINEMENTS: usize = 6;
const REFINE: usize = 4;
/// The path from δ = 0 solves to this many times the tolerance: it only carries the memory
/// (which points slipped, and how far) to the step holding F_S, whose refinements solve to the
/// tolerance. Against all solves at the tolerance (1e-6), F_S moves by at most 7e-6 (256² at
/// 10 and 100 mN, 1500² at 0.1, 0.3 and 1 mN) for 0.64–0.74 of the applications, 0.67 at
/// 1500², 10 mN (1.2e-6); at 1000 times, by up to 5e-5, as do looser refinements.
const COARSE_TOLERANCE: f64 = 100.0;
/// ... but never looser than this (measured above) nor than the tolerance itself: with
/// `--tolerance 1e-4` a path at 1e-2 moved the drop by 9e-4.
const COARSEST: f64 = 1e-4;
/// The rounds of a cascade after its first solve solve to this many times the tolerance of
/// their step (never looser than [`COARSEST`] nor than the step's own): like the path from
/// δ = 0 they carry the memory (which points slipped, and how far) to the next step, while the
/// largest force of a step is that of its first solve, before the cascade lowers bounds (a
/// measured μ(slip) that rises again aside), where the snapshot is taken. Measured (mu_s 0.6,
/// mu_d 0.4, against all rounds at the step's tolerance): 1500² with its wafer, 10 mN 9 % fewer
/// applications, the drop moved by 2e-7; 31.6 mN 13 %, 4e-7; 256², 100 mN 11 %, < 1e-7. At
/// 100 times: 9–20 % fewer, but drops moved by up to 4e-6.
const CASCADE_TOLERANCE: f64 = 10.0;
/// Steps of a force ramp up to its stuck estimate Q / k_t.
const RAMP_STEPS: usize = 64;
/// Steps after which a path that has not reached total sliding is an error: 100 μ_s N / k_t.
const MAX_STEPS: usize = 100 * STEPS;
/// Steps after which a force ramp that has not reached its force is an error: 25 Q / k_t.
const MAX_RAMP_STEPS: usize = 25 * RAMP_STEPS;
/// Solves of one cascade after which it is an error.
const MAX_CASCADE: usize = 2000;
/// A cascade has settled when no bound changes by more than this fraction, plus, for a bound
/// that depends on the slip, [`NOISE`] times what the solve's tolerance leaves in it.
const SETTLED: f64 = 1e-6;
/// The solve leaves an error of about its tolerance times the target's RMS in the slips; a
/// bound that moves with the slip (the law's slope) by less than this many times that has
/// settled. Without it a steep weakening (d_c a hundredth of the peak's δ, at 128² and the
/// default tolerance) never settled: its bounds followed the solves' errors round after round.
const NOISE: f64 = 10.0;
/// A traction within this fraction of its bound is on it (slipping).
const ON_BOUND: f64 = 1e-9;
/// The range, in SI units, that the path's tractions [Pa], forces [N] and displacement steps
/// [m] must lie in: the solves' norms sum their squares over up to 2^28 points, which must stay
/// normal floats. Beyond it they underflow to zero or overflow (mu_s = mu_d = 1e-200 at 2 mN
/// ended "no total sliding after 1600 displacement steps", 1e200 broke the solve down).
const SMALLEST: f64 = 1e-140;
const LARGEST: f64 = 1e140;
/// F_S / N may leave [mu_d, mu_s] by this relative amount, from rounding alone.
const ROUNDING: f64 = 1e-9;

/// How a point's friction coefficient falls from mu_s to mu_d as it slips.
#[derive(Debug, Clone, PartialEq)]
pub enum Weakening {
    /// At once on the first slip (the paper's law).
    Instant,
    /// Linearly over an accumulated slip d_c \[m].
    Linear(f64),
    /// A measured μ(slip): (slip \[m] from the onset of slip, μ) pairs, slip increasing from 0;
    /// beyond the last point μ stays at its last value.
    Curve(Vec<(f64, f64)>),
}

/// The local law of the sliding onset.
#[derive(Debug, Clone, PartialEq)]
pub struct SlipLaw {
    /// Static coefficient mu_s: the bound of a point that has never slipped.
    pub mu_s: f64,
    /// Dynamic coefficient mu_d: the bound once weakened.
    pub mu_d: f64,
    /// How the bound falls from mu_s to mu_d once a point slips.
    pub weakening: Weakening,
}

impl SlipLaw {
    /// The coefficient of a point that has slipped `slip` \[m] in all (path length), `slipped`
    /// whether it has slipped at all.
    pub fn mu(&self, slip: f64, slipped: bool) -> f64 {
        match &self.weakening {
            Weakening::Instant => {
                if slipped {
                    self.mu_d
                } else {
                    self.mu_s
                }
            }
            Weakening::Linear(dc) => self.mu_s - (self.mu_s - self.mu_d) * (slip / dc).min(1.0),
            Weakening::Curve(points) => {
                let i = points.partition_point(|(s, _)| *s <= slip);
                if i == 0 {
                    points[0].1
                } else if i == points.len() {
                    points[i - 1].1
                } else {
                    let ((s0, m0), (s1, m1)) = (points[i - 1], points[i]);
                    m0 + (m1 - m0) * (slip - s0) / (s1 - s0)
                }
            }
        }
    }

    /// The largest coefficient a point can have from now on, having slipped `slip` [m]
    /// (`slipped` whether at all): no later force exceeds the sum of these bounds.
    fn ceiling(&self, slip: f64, slipped: bool) -> f64 {
        match &self.weakening {
            Weakening::Instant | Weakening::Linear(_) => self.mu(slip, slipped),
            Weakening::Curve(points) => {
                let later = points.iter().filter(|(s, _)| *s > slip).map(|p| p.1);
                later.fold(self.mu(slip, slipped), f64::max)
            }
        }
    }

    /// |dμ/ds| at an accumulated slip `slip` [1/m]: how fast the bound moves with the slip.
    fn slope(&self, slip: f64) -> f64 {
        match &self.weakening {
            Weakening::Instant => 0.0,
            Weakening::Linear(dc) => {
                if slip < *dc {
                    (self.mu_s - self.mu_d) / dc
                } else {
                    0.0
                }
            }
            Weakening::Curve(points) => {
                let i = points.partition_point(|(s, _)| *s <= slip);
                if i == 0 || i == points.len() {
                    0.0
                } else {
                    let ((s0, m0), (s1, m1)) = (points[i - 1], points[i]);
                    ((m1 - m0) / (s1 - s0)).abs()
                }
            }
        }
    }

    /// The bound [Pa] that a point on its bound `bound` [Pa], under pressure `pressure` [Pa],
    /// settles at, having slipped `slip` [m] in all: lowering its bound by Δ lets it slip about
    /// `compliance` Δ more (its own compliance [m/Pa], K's diagonal; the others' response is
    /// left to the next solve), so the bound solves g = μ(slip + compliance (bound − g)) p.
    /// Taking μ(slip) p instead lowers a steep weakening's bounds a little at each solve.
    fn settling_bound(&self, slip: f64, bound: f64, pressure: f64, compliance: f64) -> f64 {
        let after = |g: f64| self.mu(slip + compliance * (bound - g), true) * pressure;
        let first = after(bound);
        if first >= bound || self.weakening == Weakening::Instant {
            return first;
        }
        // after(g) − g is negative at the bound and not negative at the law's lowest μ.
        let (mut lo, mut hi) = (self.lowest() * pressure, bound);
        for _ in 0..64 {
            let mid = 0.5 * (lo + hi);
            if after(mid) >= mid {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// The lowest coefficient a point can ever have: no path ends below Σ lowest · p a.
    fn lowest(&self) -> f64 {
        match &self.weakening {
            Weakening::Curve(points) => points.iter().map(|p| p.1).fold(f64::INFINITY, f64::min),
            _ => self.mu_d,
        }
    }

    /// Whether a point's coefficient never rises as it slips, so that a cascade only lowers the
    /// force (a measured μ(slip) may rise again).
    fn only_falls(&self) -> bool {
        !matches!(self.weakening, Weakening::Curve(_))
    }

    /// Whether nothing changes once every point has slipped this far [m].
    fn settled(&self, slip: f64) -> bool {
        match &self.weakening {
            Weakening::Instant => true,
            Weakening::Linear(dc) => slip >= *dc,
            Weakening::Curve(points) => slip >= points.last().map_or(0.0, |p| p.0),
        }
    }
}

/// What a contact point is in a state of the path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[repr(i8)]
pub enum SlideClass {
    /// Slipped before this state (its coefficient follows the weakening).
    Slipped = 1,
    /// Not slipped before, on its bound now: about to slip.
    Critical = 2,
    /// Not slipped before, below its bound.
    Stuck = 3,
}

/// One state along the path.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SlidePoint {
    /// Rigid displacement δ of the body \[m].
    pub displacement_m: f64,
    /// Tangential force F = Σ q_x · a \[N].
    pub force_n: f64,
    /// Points below their bound.
    pub stick_points: usize,
    /// Points on their bound.
    pub slip_points: usize,
}

/// A state of the path: tractions and the memory of every point.
#[derive(Clone)]
struct State {
    delta: f64,
    traction: Vec<[f64; 2]>,
    /// Slip accumulated so far, as a vector c_i [m] and as a path length s_i [m].
    slip: Vec<[f64; 2]>,
    path: Vec<f64>,
    slipped: Vec<bool>,
}

/// A solved state worth keeping: the largest force, or the end of a force ramp.
#[derive(Debug, Clone)]
pub struct Snapshot {
    /// Displacement, force and point counts of the state.
    pub point: SlidePoint,
    /// Shear traction \[Pa] at each contact point.
    pub traction: Vec<[f64; 2]>,
    /// Class of each contact point.
    pub classes: Vec<SlideClass>,
}

/// Work done by the path's solves.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct SlideWork {
    /// Displacement steps.
    pub steps: usize,
    /// Tangential solves (a step solves once more per cascade round).
    pub solves: usize,
    /// Conjugate-gradient iterations, summed.
    pub iterations: usize,
    /// Operator applications (two FFT pairs each), summed.
    pub applications: usize,
}

/// The sliding onset with elastic sharing.
#[derive(Debug, Clone)]
pub struct ElasticOnset {
    /// N = Σ p · a \[N].
    pub normal_force: f64,
    /// F_S: the largest tangential force along the path, or, when the path reaches total
    /// sliding below it, the sliding force Σ μ p a it tends to as δ → ∞ \[N].
    pub static_force: f64,
    /// The dynamic coefficient mu_d of the law the path was solved with.
    pub mu_d: f64,
    /// The state at the largest force (the steady sliding state at δ = ∞ when that is it).
    pub peak: Snapshot,
    /// Stuck points at the peak (never slipped, below their bound): count and shares of N and F_S.
    pub stuck: ClassShare,
    /// Critical points at the peak (never slipped, on their bound mu_s p): count and shares.
    pub critical: ClassShare,
    /// Slipped points at the peak (weakened towards mu_d): count and shares.
    pub slipped: ClassShare,
    /// F(δ) along the path, in increasing δ: the coarse path with each refined step replaced by
    /// its finer steps; at a δ where a cascade happens, the force before it and after it (at the
    /// end of refined steps, after it the coarse path's, from which the path goes on). Its
    /// largest force is F_S unless that is the sliding limit.
    pub curve: Vec<SlidePoint>,
    /// Steps, solves and iterations the path took.
    pub work: SlideWork,
}

impl ElasticOnset {
    /// F_S / N, as mu_d times the drop: exactly mu_d when F_S is the sliding force μ_d N.
    pub fn static_coefficient(&self) -> f64 {
        self.mu_d * self.friction_drop()
    }

    /// F_S / (mu_d N).
    pub fn friction_drop(&self) -> f64 {
        self.static_force / (self.mu_d * self.normal_force)
    }
}

/// The path driver over one tangential solver.
struct Path<'a> {
    solver: &'a mut TangentialSolver,
    law: &'a SlipLaw,
    state: State,
    target: Vec<[f64; 2]>,
    bound: Vec<f64>,
    work: SlideWork,
    /// The last step's length [m] and the change of the traction over its first solve (before
    /// its cascade) [Pa]. The next step starts from the settled traction plus that change,
    /// scaled to its length: the response of nearly the same free set to a like increment
    /// (exactly the line through the two settled states when there was no cascade). Measured:
    /// the first solves take about 40 % fewer applications; from the line through the settled
    /// states after a cascade (their change holds the cascade's drops) they took more.
    first_change: Option<(f64, Vec<[f64; 2]>)>,
    /// Relative norm of the projected gradient the solves stop at: a step's first solve, and
    /// the rounds of its cascade.
    tolerance: f64,
    cascade_tolerance: f64,
}

impl<'a> Path<'a> {
    fn new(solver: &'a mut TangentialSolver, law: &'a SlipLaw) -> Self {
        let m = solver.points().len();
        let tolerance = solver.tolerance();
        solver.set_traction(&vec![[0.0; 2]; m]);
        let state = State {
            delta: 0.0,
            traction: vec![[0.0; 2]; m],
            slip: vec![[0.0; 2]; m],
            path: vec![0.0; m],
            slipped: vec![false; m],
        };
        Path {
            solver,
            law,
            state,
            target: vec![[0.0; 2]; m],
            bound: vec![0.0; m],
            work: SlideWork::default(),
            first_change: None,
            tolerance,
            cascade_tolerance: tolerance,
        }
    }

    /// Solve the increment, after the bounds changed at the points `changed` alone (a
    /// cascade's round) or at all (a step's first solve: `changed` empty).
    fn solve(&mut self, tolerance: f64, changed: &[usize]) -> Result<()> {
        let report = if changed.is_empty() {
            self.solver.solve_within(&self.target, &self.bound, tolerance)?
        } else {
            self.solver.solve_after_change(&self.target, &self.bound, tolerance, changed)?
        };
        self.count(report);
        Ok(())
    }

    fn count(&mut self, report: TangentialReport) {
        self.work.solves += 1;
        self.work.iterations += report.iterations;
        self.work.applications += report.applications;
    }

    /// The fully stuck tangential stiffness k_t = dF/dδ [N/m] ([`stuck_stiffness`]), its
    /// solve counted in the path's work; the path's traction is restored.
    fn stuck_stiffness(&mut self) -> Result<f64> {
        let (k, report) = stuck_stiffness(self.solver)?;
        self.count(report);
        self.solver.set_traction(&self.state.traction);
        Ok(k)
    }

    fn go_back(&mut self, state: &State) {
        self.first_change = None;
        self.state = state.clone();
        self.solver.set_traction(&state.traction);
    }

    /// One increment to `delta`, with its cascade. `visit` sees every solved state (the state
    /// before its memory is updated) with its point on the curve. Returns the first state
    /// (before the cascade) and the settled one; without `cascade`, the settled one only when
    /// the first solve has no cascade to follow (else the path's state is left as before).
    fn step(
        &mut self,
        delta: f64,
        cascade: bool,
        visit: &mut impl FnMut(&Self, SlidePoint),
    ) -> Result<(SlidePoint, Option<SlidePoint>)> {
        self.work.steps += 1;
        let p = self.solver.pressure();
        let st = &self.state;
        for (i, (target, bound)) in self.target.iter_mut().zip(&mut self.bound).enumerate() {
            *target = [delta - st.slip[i][0], -st.slip[i][1]];
            *bound = self.law.mu(st.path[i], st.slipped[i]) * p[i];
        }
        if let Some((h, change)) = &self.first_change {
            let t = (delta - st.delta) / h;
            let guess: Vec<[f64; 2]> =
                st.traction.iter().zip(change).map(|(q, d)| [q[0] + t * d[0], q[1] + t * d[1]]).collect();
            self.solver.set_traction_within(&guess, &self.bound);
            self.work.applications += 1;
        }
        let mut slipped = st.slipped.clone();
        let rms =
            (self.target.iter().map(|b| b[0] * b[0] + b[1] * b[1]).sum::<f64>() / st.traction.len() as f64).sqrt();
        let compliance = self.solver.diagonal(&mut self.work.applications);
        let mut rounds = 0;
        let mut first = None;
        let mut changed = Vec::new();
        loop {
            let tolerance = if rounds == 0 { self.tolerance } else { self.cascade_tolerance };
            self.solve(tolerance, &changed)?;
            changed.clear();
            let slip_noise = tolerance * rms;
            let point = self.point(delta);
            visit(self, point);
            if first.is_none() {
                let change = self.solver.traction().iter().zip(&self.state.traction);
                self.first_change =
                    Some((delta - self.state.delta, change.map(|(q, q0)| [q[0] - q0[0], q[1] - q0[1]]).collect()));
                first = Some(point);
            }
            // The slip of this increment, and the bounds it implies.
            let (q, u, p) = (self.solver.traction(), self.solver.displacement(), self.solver.pressure());
            let mut same = true;
            for i in 0..p.len() {
                if !at_bound(q[i], self.bound[i]) {
                    continue;
                }
                let d = [self.target[i][0] - u[i][0], self.target[i][1] - u[i][1]];
                slipped[i] = true;
                let s = self.state.path[i] + magnitude(d);
                let g = self.law.settling_bound(s, self.bound[i], p[i], compliance);
                // The solve leaves an error of about `slip_noise` in the slips; a bound change
                // no larger than it carries would follow it round after round.
                let noise = NOISE * self.law.slope(s) * p[i] * slip_noise;
                if (g - self.bound[i]).abs() > SETTLED * self.bound[i] + noise {
                    same = false;
                    self.bound[i] = g;
                    changed.push(i);
                }
            }
            rounds += 1;
            if same {
                break;
            }
            if !cascade {
                return Ok((point, None));
            }
            if rounds == MAX_CASCADE {
                return Err(Error::invalid(
                    "sliding onset",
                    format!("a slip cascade at δ = {delta:.3e} m did not settle after {MAX_CASCADE} solves"),
                ));
            }
        }
        let (q, u) = (self.solver.traction(), self.solver.displacement());
        let st = &mut self.state;
        for i in 0..q.len() {
            if at_bound(q[i], self.bound[i]) {
                let d = [self.target[i][0] - u[i][0], self.target[i][1] - u[i][1]];
                st.slip[i] = [st.slip[i][0] + d[0], st.slip[i][1] + d[1]];
                st.path[i] += magnitude(d);
            }
        }
        st.slipped = slipped;
        st.traction = q.to_vec();
        st.delta = delta;
        let settled = self.point(delta);
        Ok((first.unwrap_or(settled), Some(settled)))
    }

    /// The curve point of the solver's current state.
    fn point(&self, delta: f64) -> SlidePoint {
        let q = self.solver.traction();
        let slip = q.iter().zip(&self.bound).filter(|(q, g)| at_bound(**q, **g)).count();
        SlidePoint {
            displacement_m: delta,
            force_n: self.solver.force()[0],
            stick_points: q.len() - slip,
            slip_points: slip,
        }
    }

    fn snapshot(&self, point: SlidePoint) -> Snapshot {
        let q = self.solver.traction();
        let classes = (0..q.len())
            .map(|i| {
                if self.state.slipped[i] {
                    SlideClass::Slipped
                } else if at_bound(q[i], self.bound[i]) {
                    SlideClass::Critical
                } else {
                    SlideClass::Stuck
                }
            })
            .collect();
        Snapshot { point, traction: q.to_vec(), classes }
    }

    /// The largest tangential force any later state can carry [N]: Σ μ_max p a.
    fn ceiling(&self) -> f64 {
        let st = &self.state;
        let p = self.solver.pressure();
        let sum: f64 = (0..p.len()).map(|i| self.law.ceiling(st.path[i], st.slipped[i]) * p[i]).sum();
        sum * self.solver.pixel_area()
    }

    /// The steady sliding state the path tends to once the interface slides as a whole: every
    /// traction at its bound along x, at δ = ∞.
    fn sliding_limit(&self) -> Snapshot {
        let st = &self.state;
        let p = self.solver.pressure();
        let traction: Vec<[f64; 2]> =
            (0..p.len()).map(|i| [self.law.mu(st.path[i], st.slipped[i]) * p[i], 0.0]).collect();
        // μ_d N (the onset's N) plus what the points off mu_d add: a fully weakened interface
        // gives μ_d N to the bit, a drop of exactly 1, not 1 − 2e-15.
        let excess: f64 = traction.iter().zip(p).map(|(q, p)| q[0] - self.law.mu_d * p).sum();
        let force = self.law.mu_d * self.solver.normal_force() + excess * self.solver.pixel_area();
        Snapshot {
            point: SlidePoint { displacement_m: f64::INFINITY, force_n: force, stick_points: 0, slip_points: p.len() },
            traction,
            classes: vec![SlideClass::Slipped; p.len()],
        }
    }

    /// Whether the interface slides as a whole and nothing changes any more.
    fn sliding(&self, point: &SlidePoint) -> bool {
        point.stick_points == 0
            && self.state.slipped.iter().all(|s| *s)
            && self.state.path.iter().all(|s| self.law.settled(*s))
    }
}

fn at_bound(q: [f64; 2], g: f64) -> bool {
    magnitude(q) >= g * (1.0 - ON_BOUND)
}

/// Where a path is, after each displacement step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlideProgress {
    /// The refinement level of the step: 0 on the path from δ = 0, k = 1..=[`SLIDE_LEVELS`] on
    /// a step k times refined (four times finer each time); a few more in the rare case that a
    /// longer step of the path from δ = 0 is refined (its force came up to the floor of F_S).
    pub level: usize,
    /// The state after the step (its cascade settled).
    pub point: SlidePoint,
    /// The largest force reached so far \[N].
    pub largest_force_n: f64,
    /// Work done so far.
    pub work: SlideWork,
}

/// The finest refinement level (the largest [`SlideProgress::level`]).
pub const SLIDE_LEVELS: usize = REFINEMENTS;

/// One displacement step of the path at a refinement level (0 on the path from δ = 0).
struct Step {
    level: usize,
    /// δ at its start [m].
    from: f64,
    /// δ at its end [m]: the next step's start, bit for bit.
    to: f64,
    /// Its points on the curve: the force before its cascade, the largest force it reached
    /// when that is another (a measured law can raise bounds), and the settled force.
    points: Vec<SlidePoint>,
    /// The largest force it reached.
    largest: SlidePoint,
    /// Its state after the cascade, from which the next step goes on.
    settled: SlidePoint,
    /// While the step may hold F_S: the state at its start and the snapshot at `largest`.
    kept: Option<Box<(State, Snapshot)>>,
}

impl Step {
    fn length(&self) -> f64 {
        self.to - self.from
    }

    /// The state at its start and the snapshot at its largest force, which only a step far
    /// below the largest force lacks.
    fn kept(&self) -> Result<&(State, Snapshot)> {
        self.kept.as_deref().ok_or_else(|| {
            Error::invalid(
                "sliding onset",
                format!("the state before the largest force (δ = {:.3e} m) was not kept", self.from),
            )
        })
    }
}

/// Where a refined run ends.
#[derive(Clone, Copy)]
struct RunEnd {
    /// δ [m] at its end.
    at: f64,
    /// The coarse path's settled point there, when the path goes on from it.
    coarse: Option<SlidePoint>,
}

/// The steps of a path: the coarse path with each refined step replaced by its finer steps.
struct Steps {
    live: Vec<Step>,
    /// The fully stuck tangential stiffness k_t [N/m]: no step raises the force by more than
    /// k_t times its length before its cascade (fixed bounds only soften the response).
    stiffness: f64,
    /// A force [N] F_S is never below: Σ μ_lowest p a, as every bound stays at or above
    /// μ_lowest p, so that the sliding force and the ceiling are at least that.
    floor: f64,
    /// The largest force any step reached [N].
    largest: f64,
    /// The largest settled force [N]: the path from δ = 0 ends once no later state can exceed it.
    settled: f64,
    /// Steps more than this below `largest` [N] can never hold F_S; their states are dropped.
    band: f64,
    /// How far below `largest` [N] a step may still hold F_S: `band`, or twice k_t times the
    /// length of the step that reached `largest` when it is longer (a leap whose force passed
    /// the floor, which refinement may lower by up to k_t times its length).
    reach: f64,
}

impl Steps {
    /// Steps from `start` with length `h` to `until`, or (`None`) to total sliding or until no
    /// later state can exceed the largest settled force. Returns whether the path reached total
    /// sliding. On the path from δ = 0 of a law whose coefficients only fall, a step is longer
    /// while the force is far below [`floor`](Self::floor): (floor − F)/k, so that its force
    /// before the cascade stays below the floor, which F_S is not below: such a step does not
    /// hold F_S and is not refined. The first step takes k = k_t, which its force cannot pass;
    /// the next ones the rise per unit δ of the last step's first solve, as the path softens
    /// (at 1500², 100 mN 1.3 k_t/k after the first step, 14 after the sixth): in the cases
    /// measured no such step passed the floor, and one that did would be refined as any other.
    /// Measured at 1500² with its wafer, mu_d 0.4, against coarse steps from δ = 0: at 10, 31.6 and 100 mN 44, 37 and
    /// 49 % fewer applications with mu_s 0.6, 51, 49 and 68 % with 0.5 (the last also spared
    /// refinements below the sliding force); the drops moved by −1.5e-6 to −4.0e-6 (with k_t
    /// throughout, by −1.1e-6 to +1.4e-6, for 23–48 % fewer): the memory these steps leave
    /// (which points slipped, and how far) matters little.
    fn run(
        &mut self,
        path: &mut Path,
        level: usize,
        start: &State,
        h: f64,
        until: Option<RunEnd>,
        progress: &mut impl FnMut(SlideProgress) -> bool,
    ) -> Result<bool> {
        path.go_back(start);
        let tolerance = path.solver.tolerance();
        path.tolerance =
            if level == 0 { (COARSE_TOLERANCE * tolerance).min(COARSEST).max(tolerance) } else { tolerance };
        path.cascade_tolerance = (CASCADE_TOLERANCE * tolerance).min(COARSEST).max(path.tolerance);
        let leap = until.is_none() && path.law.only_falls();
        // The settled force at the path's state, the end of the last step, and the stiffness
        // the next leap is sized by.
        let (mut force, mut to, mut stiffness) = (0.0, start.delta, self.stiffness);
        for k in 1..=MAX_STEPS {
            let before = path.state.clone();
            let from = to;
            let length = if leap { h.max((self.floor - force) / stiffness) } else { h };
            // Uniform steps from their start; a refined run's last ends where the step it
            // refines ended, to the bit, so that no curve points are a rounding apart.
            let uniform = start.delta + h * k as f64;
            to = match until {
                _ if leap => from + length,
                Some(end) if uniform >= end.at * (1.0 - 1e-12) => end.at,
                _ => uniform,
            };
            let delta = to;
            let floor = self.largest - self.reach;
            let mut largest: Option<SlidePoint> = None;
            let mut snapshot = None;
            let mut visit = |p: &Path, point: SlidePoint| {
                if largest.is_none_or(|l| point.force_n > l.force_n) {
                    largest = Some(point);
                    if point.force_n >= floor {
                        snapshot = Some(p.snapshot(point));
                    }
                }
            };
            let last = until.is_some_and(|end| delta >= end.at * (1.0 - 1e-12));
            // The cascade of a refined run's last step would only lead to the coarse path's
            // state at its end, from which the following steps go on: its settled point on the
            // curve is the coarse path's.
            let coarse = until.and_then(|end| end.coarse).filter(|_| last && path.law.only_falls());
            let (first, settled) = path.step(delta, coarse.is_none(), &mut visit)?;
            let settled = settled.or(coarse).expect("a step without its cascade has the coarse path's point");
            let largest = largest.expect("a step solves");
            let mut points = vec![first];
            for p in [largest, settled] {
                if !points.contains(&p) {
                    points.push(p);
                }
            }
            if largest.force_n > self.largest {
                self.largest = largest.force_n;
                self.reach = self.band.max(2.0 * self.stiffness * (to - from));
                let floor = self.largest - self.reach;
                for s in self.live.iter_mut().filter(|s| s.largest.force_n < floor) {
                    s.kept = None;
                }
            }
            self.settled = self.settled.max(settled.force_n);
            let rise = (first.force_n - force) / length;
            stiffness = if rise > 0.0 { rise.min(self.stiffness) } else { self.stiffness };
            force = settled.force_n;
            let kept = snapshot.map(|s| Box::new((before, s)));
            self.live.push(Step { level, from, to, points, largest, settled, kept });
            if !progress(SlideProgress { level, point: settled, largest_force_n: self.largest, work: path.work }) {
                return Err(Error::Interrupted { what: "sliding onset".into() });
            }
            if last {
                return Ok(false);
            } else if until.is_none() && path.sliding(&settled) {
                return Ok(true);
            } else if until.is_none() && path.ceiling() <= self.settled {
                return Ok(false);
            }
        }
        let reached = format!("no total sliding after {MAX_STEPS} displacement steps (δ = {:.3e} m)", path.state.delta);
        Err(Error::invalid(
            "sliding onset",
            match path.law.weakening {
                Weakening::Linear(dc) if dc > path.state.delta => {
                    format!("{reached}: the slip-weakening distance {dc:.3e} m is longer; give a shorter one")
                }
                _ => reached,
            },
        ))
    }

    /// The live step with the largest force (the first of equals).
    fn peak(&self) -> usize {
        let mut best = 0;
        for (i, s) in self.live.iter().enumerate() {
            if s.largest.force_n > self.live[best].largest.force_n {
                best = i;
            }
        }
        best
    }
}

/// An error naming `option` unless each of `scales` (what, value with its unit) lies in
/// [[`SMALLEST`], [`LARGEST`]]: the path cannot represent it.
fn check_scales(option: &str, scales: &[(&str, f64, &str)]) -> Result<()> {
    match scales.iter().find(|(_, v, _)| !(*v >= SMALLEST && *v <= LARGEST)) {
        Some((what, v, unit)) => Err(Error::invalid(
            option,
            format!(
                "{what} would be {v:.3e} {unit}, outside the {SMALLEST:e} to {LARGEST:e} that the tangential solves represent (their squares must stay normal floats)"
            ),
        )),
        None => Ok(()),
    }
}

/// The tractions [Pa] and forces [N] of a law from `lowest` to `highest` (coefficients) on
/// `pressure` [Pa] whose sum times `area` [m²] is the normal force `normal_force` [N].
fn traction_scales(
    lowest: f64,
    highest: f64,
    pressure: &[f64],
    normal_force: f64,
) -> [(&'static str, f64, &'static str); 4] {
    let p_max = pressure.iter().copied().fold(0.0, f64::max);
    let root = (pressure.len() as f64).sqrt();
    [
        ("the lowest coefficient times the largest pressure", lowest * p_max, "Pa"),
        ("mu_s times the largest pressure, times √(contact points)", highest * p_max * root, "Pa"),
        ("the lowest coefficient times the normal force", lowest * normal_force, "N"),
        ("mu_s times the normal force", highest * normal_force, "N"),
    ]
}

/// An error unless F_S / N = `coefficient` lies in [mu_d, mu_s] (to [`ROUNDING`]): the path's
/// bounds keep it there, so a result outside is never written. A measured μ(slip) that falls
/// below its mean after the peak (the law's mu_d) is the one law that can give less: when its
/// slip scale is small against the path's slips, every point weakens to its tail at once, and
/// F_S tends to the tail's value (a curve of 1 Å gave the instant drop to it to 6e-5).
fn check_coefficient(law: &SlipLaw, coefficient: f64, peak_displacement: f64) -> Result<()> {
    if coefficient >= law.mu_d * (1.0 - ROUNDING) && coefficient <= law.mu_s * (1.0 + ROUNDING) {
        return Ok(());
    }
    let found = format!("F_S/N = {coefficient:.6} lies outside [mu_d, mu_s] = [{:.6}, {:.6}]", law.mu_d, law.mu_s);
    Err(match law.weakening {
        Weakening::Curve(_) if law.lowest() < law.mu_d => Error::invalid(
            "--curve",
            format!(
                "{found}: past its peak the curve falls to {:.6}, below its mean, and the onset's slips (δ_peak {peak_displacement:.2e} m) take every point there; take mu_d over its steady sliding (--window)",
                law.lowest()
            ),
        ),
        _ => Error::invalid("sliding onset", found),
    })
}

/// The sliding onset of the contact set of `solver` under `law`: displacement-controlled path
/// to total sliding (or until no later state can exceed the largest force seen). A coarse
/// step overestimates the force before its cascade (its points held bounds that finer steps
/// would have seen fall earlier), so the step with the largest force is repeated from its
/// start in steps four times finer, in its place, until the largest force lies in a step of
/// the finest length, 1/(64·4⁶) of μ_s N / k_t: F_S is the largest
/// force on the curve, or the sliding force when the path reaches total sliding and no step
/// (even before its refinement) comes up to it. `progress` hears of every step and answers
/// `()`, or a [`ControlFlow`](std::ops::ControlFlow) whose `Break` stops the path there with
/// [`Error::Interrupted`] (a step at 1500², 100 mN takes seconds, the path a quarter of an
/// hour). An error,
/// instead of a result, when the law's tractions, forces or steps leave what the solves
/// represent, or when F_S / N leaves [mu_d, mu_s] (a measured μ(slip) whose tail falls below
/// its mean mu_d).
pub fn elastic_onset<R: Proceed>(
    solver: &mut TangentialSolver,
    law: &SlipLaw,
    mut progress: impl FnMut(SlideProgress) -> R,
) -> Result<ElasticOnset> {
    let mut progress = |p: SlideProgress| progress(p).proceed();
    let area = solver.pixel_area();
    let normal_force = solver.normal_force();
    let option = if law.mu_s == law.mu_d { "--mu-s" } else { "--mu-d" };
    check_scales(option, &traction_scales(law.lowest(), law.mu_s, solver.pressure(), normal_force))?;
    let mut path = Path::new(solver, law);
    let k = path.stuck_stiffness()?;
    let h0 = law.mu_s * normal_force / k / STEPS as f64;
    let finest = h0 / (REFINE as f64).powi(REFINEMENTS as i32);
    check_scales(
        "--mu-s",
        &[
            ("the finest displacement step, mu_s N / k_t / 262144,", finest, "m"),
            ("the longest path", MAX_STEPS as f64 * h0, "m"),
        ],
    )?;
    // A step's force gain is at most k h (fixed bounds only soften it), and its refinement
    // reaches at least the force at its start: a step k h₀ below the largest force cannot hold
    // F_S. Twice that, for a measured law's rising bounds. (A longer step's force stays below
    // the floor, which F_S is not below.)
    let floor = law.lowest() * normal_force;
    let band = 2.0 * k * h0;
    let mut steps = Steps { live: Vec::new(), stiffness: k, floor, largest: 0.0, settled: 0.0, band, reach: band };
    let origin = path.state.clone();
    // Past total sliding the tractions turn towards x: F tends to the sliding force Σ μ p a,
    // reached as δ → ∞.
    let limit = steps.run(&mut path, 0, &origin, h0, None, &mut progress)?.then(|| path.sliding_limit());
    let peak = loop {
        let i = steps.peak();
        let step = &steps.live[i];
        // Refining only lowers a step's largest force: none comes up to the sliding force.
        if let Some(limit) = limit.as_ref().filter(|l| l.point.force_n > step.largest.force_n) {
            break limit.clone();
        }
        if step.length() <= finest * (1.0 + 1e-9) {
            break step.kept()?.1.clone();
        }
        let step = steps.live.swap_remove(i);
        let start = step.kept()?.0.clone();
        let h = step.length();
        // The step alone, back onto the coarse path at its end: the step after it keeps its
        // own largest force, and is refined in turn should that lead. (With the step after it
        // refined too, 10–20 % more applications for the same drops in 3 of 4 cases measured.)
        // Past the path's end, two steps' length.
        let end = if steps.live.iter().any(|s| (s.from - step.to).abs() <= 1e-9 * h) {
            RunEnd { at: step.to, coarse: Some(step.settled) }
        } else {
            RunEnd { at: step.from + 2.0 * h, coarse: None }
        };
        steps.run(&mut path, step.level + 1, &start, h / REFINE as f64, Some(end), &mut progress)?;
    };
    let mut live = steps.live;
    live.sort_by(|a, b| a.from.total_cmp(&b.from));
    let mut curve = vec![SlidePoint {
        displacement_m: 0.0,
        force_n: 0.0,
        stick_points: path.solver.points().len(),
        slip_points: 0,
    }];
    curve.extend(live.iter().flat_map(|s| s.points.iter().copied()));
    let elements = peak
        .classes
        .iter()
        .zip(&peak.traction)
        .zip(path.solver.pressure())
        .map(|((c, q), p)| (*c, p * area, q[0] * area));
    check_coefficient(law, peak.point.force_n / normal_force, peak.point.displacement_m)?;
    let share = |class| ClassShare::tally(elements.clone(), class, (normal_force, peak.point.force_n));
    let (stuck, critical, slipped) =
        (share(SlideClass::Stuck), share(SlideClass::Critical), share(SlideClass::Slipped));
    Ok(ElasticOnset {
        normal_force,
        static_force: peak.point.force_n,
        mu_d: law.mu_d,
        stuck,
        critical,
        slipped,
        peak,
        curve,
        work: path.work,
    })
}

/// A partial-slip state under Coulomb friction (coefficient `mu`): the tangential force ramped
/// to `force` \[N] by increasing δ, located to a relative 1e-6.
pub fn ramp_force(solver: &mut TangentialSolver, mu: f64, force: f64) -> Result<(Snapshot, SlideWork)> {
    let normal_force = solver.normal_force();
    if !(force > 0.0 && force < mu * normal_force) {
        return Err(Error::invalid(
            "--tangential-force",
            format!("must lie in (0, μN) = (0, {:.6e}) N for a partial-slip state, got {force:e} N", mu * normal_force),
        ));
    }
    let law = SlipLaw { mu_s: mu, mu_d: mu, weakening: Weakening::Instant };
    check_scales("--mu-s", &traction_scales(mu, mu, solver.pressure(), normal_force))?;
    let mut path = Path::new(solver, &law);
    let k = path.stuck_stiffness()?;
    let h = force / k / RAMP_STEPS as f64;
    // Q far below μN: its displacements are below what the solves represent (1e-300 N took
    // 1600 steps of nothing and ended "not reached").
    check_scales(
        "--tangential-force",
        &[(
            &format!(
                "at {force:e} N, {:.3e} of μN, the displacement step Q / k_t / {RAMP_STEPS}",
                force / (mu * normal_force)
            ),
            h,
            "m",
        )],
    )?;
    let mut none = |_: &Path, _: SlidePoint| {};
    // Step until the force passes `force`, then bisect that last step from the state before it.
    let mut before = path.state.clone();
    let (mut lo, mut hi) = ((0.0, 0.0), (0.0, 0.0));
    for k in 1..=MAX_RAMP_STEPS {
        before = path.state.clone();
        lo = hi;
        let point = path.step(h * k as f64, true, &mut none)?.1.expect("a step with its cascade settles");
        hi = (point.displacement_m, point.force_n);
        if hi.1 >= force {
            break;
        }
        if path.sliding(&point) {
            // The elastic coupling keeps the tractions turned off x: F only tends to μN.
            return Err(Error::invalid(
                "--tangential-force",
                format!(
                    "the interface slides as a whole at {:.6e} N ({:.6} μN), below {force:e} N: a partial-slip state needs less",
                    point.force_n,
                    point.force_n / (mu * normal_force)
                ),
            ));
        }
    }
    if hi.1 < force {
        return Err(Error::invalid(
            "--tangential-force",
            format!("not reached after {MAX_RAMP_STEPS} displacement steps"),
        ));
    }
    let mut best = hi;
    for round in 0..200 {
        if (best.1 - force).abs() <= 1e-6 * force {
            break;
        }
        // Regula falsi, every third round a bisection so that neither end sticks.
        let mut d = lo.0 + (force - lo.1) / (hi.1 - lo.1) * (hi.0 - lo.0);
        if round % 3 == 2 || !(d > lo.0 && d < hi.0) {
            d = 0.5 * (lo.0 + hi.0);
        }
        let f = force_at(&mut path, &before, d)?;
        if f < force {
            lo = (d, f);
        } else {
            hi = (d, f);
        }
        if (f - force).abs() < (best.1 - force).abs() {
            best = (d, f);
        }
    }
    force_at(&mut path, &before, best.0)?;
    let point = path.point(best.0);
    Ok((path.snapshot(point), path.work))
}

/// The force after one increment from `start` to `delta`.
fn force_at(path: &mut Path, start: &State, delta: f64) -> Result<f64> {
    path.go_back(start);
    let mut none = |_: &Path, _: SlidePoint| {};
    Ok(path.step(delta, true, &mut none)?.1.expect("a step with its cascade settles").force_n)
}
