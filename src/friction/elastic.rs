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
//! (a slip cascade) until no bound moves by more than the solve resolves. The settled force
//! F(δ) = Σ q_x · a of these states is the curve, and F_S its largest value: a march from
//! δ = 0 in coarse steps (longer while the force is far below μ_d N, which F_S is never below,
//! for a law whose coefficients only fall) brackets it, and a line search in δ locates it, or
//! the last stable state before a snap. Once every point slides, the tractions turn towards x
//! as δ grows and F tends to the sliding force Σ μ p a (μ_d N for the instant drop): F_S is
//! never below it, though the path stops at total sliding with tractions still turned by the
//! elastic coupling.
//!
//! Must not import study, shs, plot or report: friction builds on contact and the base row.

use ndarray::Array2;
use serde::Serialize;

use super::slide_class::{SlideClass, SlideClasses};
use super::slip_law::{SlipLaw, Weakening};
use super::stiffness::stuck_stiffness;
use crate::contact::tangential::magnitude;
use crate::contact::{Proceed, TangentialReport, TangentialSolver};
use crate::error::{Error, Result};

/// Displacement steps of the march up to the stuck estimate of the peak, μ_s N / k_t (the
/// longer first steps aside). The march only brackets the largest settled force, which the
/// search then locates.
const STEPS: usize = 64;

/// The default fraction of F_S within which the forces of the search's bracket agree when it
/// ends ([`elastic_onset`]'s `peak_tolerance`).
pub const PEAK_TOLERANCE: f64 = 1e-4;
/// The march from δ = 0 solves to this many times the tolerance: it only carries the memory
/// (which points slipped, and how far) to the bracket of F_S, whose search solves to the
/// tolerance. A march at the tolerance itself moved the drop by 5e-6 and 7e-6 at 1500², 1
/// and 10 mN, d_c 2 nm, for 2.1 and 1.9 times the march's applications.
const COARSE_TOLERANCE: f64 = 100.0;
/// ... but never looser than this (measured above) nor than the tolerance itself: with
/// `--tolerance 1e-4` a path at 1e-2 moved the drop by 9e-4.
const COARSEST: f64 = 1e-4;
/// The rounds of a cascade after its first solve solve to this many times the tolerance of
/// their step (never looser than [`COARSEST`] nor than the step's own). Measured with a
/// search that took F_S from first solves (mu_s 0.6, mu_d 0.4, against all rounds at the
/// step's tolerance): 1500² with its wafer, 10 mN 9 % fewer applications, the drop moved by
/// 2e-7; 31.6 mN 13 %, 4e-7; 256², 100 mN 11 %, < 1e-7; at 100 times, drops moved by up to
/// 4e-6. With F_S from settled states the drops of 256² and 1500² (1 and 10 mN) stay within
/// 6e-5 of that search's at its finest steps.
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

impl Snapshot {
    /// The state as maps on the solver's grid: shear traction along x and along y \[Pa], and
    /// the class of every pixel (int8: 0 no contact, else its [`SlideClass`]).
    pub fn maps(&self, solver: &TangentialSolver) -> (Array2<f64>, Array2<f64>, Array2<i8>) {
        let (ny, nx) = solver.shape();
        let (mut sx, mut sy) = (Array2::<f64>::zeros((ny, nx)), Array2::<f64>::zeros((ny, nx)));
        let mut classes = Array2::<i8>::zeros((ny, nx));
        for ((&i, q), c) in solver.points().iter().zip(&self.traction).zip(&self.classes) {
            let at = (i / nx, i % nx);
            sx[at] = q[0];
            sy[at] = q[1];
            classes[at] = *c as i8;
        }
        (sx, sy, classes)
    }
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
    /// The classes of the points at the peak: count and shares of N and F_S of each.
    pub classes: SlideClasses,
    /// The settled force F(δ), in increasing δ: the march from δ = 0 and the probes of the
    /// search near the peak (each settled from the settled state just below it). F_S is the
    /// largest of the search's, solved to the tolerance (or the sliding limit); the march's,
    /// solved to 100 times it (at most 1e-4), may lie above F_S by about that fraction.
    pub curve: Vec<SlidePoint>,
    /// The fully stuck tangential stiffness K_t of the contact \[N/m].
    pub stuck_stiffness: f64,
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

    /// One increment from the path's state to `delta`, with its cascade: the first solve holds
    /// the state's bounds, then rounds move the bounds of the points that slipped until they
    /// settle. Returns the first solve's force [N] and the settled point, the path's state then
    /// the settled one. For a law whose coefficients only fall a round only lowers the force:
    /// once it is below `abandon` [N] the settled force will be too, and the step stops there
    /// (`None`, the path's state left as it was).
    fn step(&mut self, delta: f64, abandon: f64) -> Result<(f64, Option<SlidePoint>)> {
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
            let force = self.solver.force()[0];
            if first.is_none() {
                let change = self.solver.traction().iter().zip(&self.state.traction);
                self.first_change =
                    Some((delta - self.state.delta, change.map(|(q, q0)| [q[0] - q0[0], q[1] - q0[1]]).collect()));
                first = Some(force);
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
            if force < abandon && self.law.only_falls() {
                return Ok((first.unwrap_or(force), None));
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
        Ok((first.unwrap_or(settled.force_n), Some(settled)))
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

    /// The snapshot of the settled state at `point`, reached from a state whose points
    /// `before` had slipped ([`SlideClass::of`]).
    fn snapshot(&self, before: &[bool], point: SlidePoint) -> Snapshot {
        let q = self.solver.traction();
        let at = |i: usize| at_bound(q[i], self.bound[i]);
        let classes = (0..q.len()).map(|i| SlideClass::of(self.law, before[i], at(i), self.state.path[i])).collect();
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
            classes: (0..p.len()).map(|i| SlideClass::of(self.law, true, true, st.path[i])).collect(),
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

/// Where a path is, after each settled state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlideProgress {
    /// The march from δ = 0, or the search for the peak near the march's largest force.
    pub stage: SlideStage,
    /// The settled state reached.
    pub point: SlidePoint,
    /// The largest settled force so far \[N].
    pub largest_force_n: f64,
    /// Work done so far.
    pub work: SlideWork,
}

/// The stage of a path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlideStage {
    /// Settled states from δ = 0 in coarse steps, to total sliding or until no later state can
    /// exceed the largest settled force.
    March,
    /// The line search for the largest settled force, in the bracket around the march's.
    Search,
}

/// A settled state of the path, to go on from.
struct Probe {
    point: SlidePoint,
    state: State,
}

/// A stretch of δ from a settled state to `to` [m] in which no settled force exceeds `bound`
/// [N]: the force of the first solve from `start` to `to` (the bounds held; a cascade only
/// lowers it), and at most start's force plus k_t times the stretch.
struct Stretch {
    start: Probe,
    to: f64,
    bound: f64,
}

/// The search for the largest settled force: a branch and bound over the stretches of the
/// march. The settled curve is a sawtooth (each cascade of first slips is a small snap, even
/// with a slip-weakening distance: at 1500², 10 mN, d_c 2 nm, a tooth of 7e-4 F stood between
/// two steps of the march), so a line search on it finds a tooth but not the highest: each
/// stretch whose bound exceeds the largest settled force found is halved instead, the probe at
/// its middle settling from its start, until every bound is within the tolerance of it.
struct Search<'p> {
    /// The fully stuck stiffness k_t [N/m]: no settled force rises faster with δ.
    stiffness: f64,
    /// The search ends when no stretch may hold a settled force more than this fraction above
    /// the largest found.
    tolerance: f64,
    /// The largest settled force found and its snapshot.
    peak: Option<Snapshot>,
    /// Every settled point found.
    curve: Vec<SlidePoint>,
    progress: &'p mut dyn FnMut(SlideProgress) -> bool,
}

/// Probes of one search after which it is an error.
const MAX_PROBES: usize = 20_000;

impl Search<'_> {
    fn largest(&self) -> f64 {
        self.peak.as_ref().map_or(0.0, |s| s.point.force_n)
    }

    /// Whether a stretch bounded by `bound` [N] may hold a force above the largest found, or
    /// above `limit` [N] (the sliding force), beyond the tolerance.
    fn open(&self, bound: f64, limit: f64) -> bool {
        bound > self.largest().max(limit) * (1.0 + self.tolerance)
    }

    /// Halve the stretches that may hold F_S, the most promising first, until none may.
    fn run(&mut self, path: &mut Path, mut stretches: Vec<Stretch>, limit: f64) -> Result<()> {
        for _ in 0..MAX_PROBES {
            stretches.retain(|s| self.open(s.bound, limit));
            let Some(i) = (0..stretches.len()).max_by(|&i, &j| stretches[i].bound.total_cmp(&stretches[j].bound))
            else {
                return Ok(());
            };
            let Stretch { start, to, bound } = stretches.swap_remove(i);
            let from = start.point.displacement_m;
            let mid = 0.5 * (from + to);
            if !(mid > from && mid < to) {
                continue;
            }
            // A settled force below this leaves the upper half nothing to hold.
            let abandon = self.largest().max(limit) * (1.0 + self.tolerance) - self.stiffness * (to - mid);
            path.go_back(&start.state);
            let (first, settled) = path.step(mid, abandon)?;
            let lower = first.min(start.point.force_n + self.stiffness * (mid - from));
            if let Some(point) = settled {
                self.curve.push(point);
                if point.force_n > self.largest() {
                    self.peak = Some(path.snapshot(&start.state.slipped, point));
                }
                let report = SlideProgress {
                    stage: SlideStage::Search,
                    point,
                    largest_force_n: self.largest(),
                    work: path.work,
                };
                if !(self.progress)(report) {
                    return Err(Error::Interrupted { what: "sliding onset".into() });
                }
                let upper = bound.min(point.force_n + self.stiffness * (to - mid));
                stretches.push(Stretch { start: Probe { point, state: path.state.clone() }, to, bound: upper });
            }
            stretches.push(Stretch { start, to: mid, bound: lower });
        }
        Err(Error::invalid("sliding onset", format!("the search for the peak did not end after {MAX_PROBES} probes")))
    }
}

/// The march from δ = 0 in steps of `h` [m] on settled states, to total sliding or until no
/// later state can exceed the largest settled force. For a law whose coefficients only fall a
/// step is longer while the force is far below `floor` [N], which F_S is never below: (floor
/// − F)/k, the first with k = `stiffness` k_t, the next ones with the rise per unit δ of the
/// last step's first solve, as the path softens (at 1500², 100 mN 1.3 k_t/k after the first
/// step, 14 after the sixth). Returns the stretches of its steps that may still hold F_S (a
/// bound above the largest settled force, for the search, which solves them to the
/// tolerance), the settled points, and whether the path reached total sliding.
fn march(
    path: &mut Path,
    h: f64,
    floor: f64,
    stiffness: f64,
    tolerance: f64,
    progress: &mut dyn FnMut(SlideProgress) -> bool,
) -> Result<(Vec<Stretch>, Vec<SlidePoint>, bool)> {
    let leap = path.law.only_falls();
    let mut previous = Probe { point: path.point(0.0), state: path.state.clone() };
    let (mut curve, mut stretches) = (Vec::new(), Vec::new());
    let (mut rising, mut largest) = (stiffness, 0.0_f64);
    for _ in 0..MAX_STEPS {
        let (from, force) = (previous.point.displacement_m, previous.point.force_n);
        let length = if leap { h.max((floor - force) / rising) } else { h };
        let (first, settled) = path.step(from + length, f64::NEG_INFINITY)?;
        let point = settled.expect("a step that is never abandoned settles");
        let rise = (first - force) / length;
        rising = if rise > 0.0 { rise.min(stiffness) } else { stiffness };
        curve.push(point);
        largest = largest.max(point.force_n);
        // A measured law's bounds may rise in a cascade: its stretches keep no bound.
        let bound = if path.law.only_falls() { first.min(force + stiffness * length) } else { f64::INFINITY };
        let here = Probe { point, state: path.state.clone() };
        stretches.push(Stretch { start: std::mem::replace(&mut previous, here), to: point.displacement_m, bound });
        // The march's forces are solved to a looser tolerance than the search's: a stretch is
        // dropped only once it is clear of the largest by more than either could move it.
        stretches.retain(|s| s.bound > largest * (1.0 - COARSEST - tolerance));
        let report = SlideProgress { stage: SlideStage::March, point, largest_force_n: largest, work: path.work };
        if !progress(report) {
            return Err(Error::Interrupted { what: "sliding onset".into() });
        }
        let sliding = path.sliding(&point);
        if sliding || path.ceiling() <= largest {
            return Ok((stretches, curve, sliding));
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

/// The sliding onset of the contact set of `solver` under `law`. F_S is the largest force of
/// the settled curve F(δ), the force once every cascade has settled, along a rigid displacement
/// δ that increases quasi-statically: the march from δ = 0 in coarse steps brackets the largest
/// settled force, and a line search in δ (golden sections, each probe one increment with its
/// cascade from the settled state just below it) narrows the bracket until its forces agree
/// within `peak_tolerance` of F_S; a fall past the largest force that is steeper than k_t is a
/// snap, and the search bisects for the last stable state before it. F_S is the sliding force
/// instead when the path reaches total sliding and no step before comes up to it.
/// `progress` hears of every settled state and answers `()`, or a
/// [`ControlFlow`](std::ops::ControlFlow) whose `Break` stops the path there with
/// [`Error::Interrupted`]. An error, instead of a result, when the law's tractions, forces or
/// steps leave what the solves represent, or when F_S / N leaves [mu_d, mu_s] (a measured
/// μ(slip) whose tail falls below its mean mu_d).
pub fn elastic_onset<R: Proceed>(
    solver: &mut TangentialSolver,
    law: &SlipLaw,
    peak_tolerance: f64,
    mut progress: impl FnMut(SlideProgress) -> R,
) -> Result<ElasticOnset> {
    check_peak_tolerance(peak_tolerance)?;
    let mut progress = |p: SlideProgress| progress(p).proceed();
    let area = solver.pixel_area();
    let normal_force = solver.normal_force();
    let option = if law.mu_s == law.mu_d { "--mu-s" } else { "--mu-d" };
    check_scales(option, &traction_scales(law.lowest(), law.mu_s, solver.pressure(), normal_force))?;
    let mut path = Path::new(solver, law);
    let k = path.stuck_stiffness()?;
    let h0 = law.mu_s * normal_force / k / STEPS as f64;
    let floor = law.lowest() * normal_force;
    check_scales(
        "--peak-tolerance",
        &[
            ("the shortest bracket of the search, peak_tolerance · mu_d N / k_t,", peak_tolerance * floor / k, "m"),
            ("the longest path", MAX_STEPS as f64 * h0, "m"),
        ],
    )?;
    let tolerance = path.solver.tolerance();
    path.tolerance = (COARSE_TOLERANCE * tolerance).min(COARSEST).max(tolerance);
    path.cascade_tolerance = (CASCADE_TOLERANCE * tolerance).min(COARSEST).max(path.tolerance);
    let (stretches, mut curve, sliding) = march(&mut path, h0, floor, k, peak_tolerance, &mut progress)?;
    // Past total sliding the tractions turn towards x: F tends to the sliding force Σ μ p a,
    // reached as δ → ∞.
    let limit = sliding.then(|| path.sliding_limit());
    path.tolerance = tolerance;
    path.cascade_tolerance = (CASCADE_TOLERANCE * tolerance).min(COARSEST).max(tolerance);
    let mut search =
        Search { stiffness: k, tolerance: peak_tolerance, peak: None, curve: Vec::new(), progress: &mut progress };
    search.run(&mut path, stretches, limit.as_ref().map_or(0.0, |l| l.point.force_n))?;
    let found = search.peak.take();
    curve.append(&mut search.curve);
    let peak = match (found, limit) {
        (Some(found), Some(limit)) if limit.point.force_n > found.point.force_n => limit,
        (None, Some(limit)) => limit,
        (Some(found), _) => found,
        (None, None) => return Err(Error::invalid("sliding onset", "the search found no settled state")),
    };
    curve.sort_by(|a, b| a.displacement_m.total_cmp(&b.displacement_m));
    curve.insert(
        0,
        SlidePoint { displacement_m: 0.0, force_n: 0.0, stick_points: path.solver.points().len(), slip_points: 0 },
    );
    let elements = peak
        .classes
        .iter()
        .zip(&peak.traction)
        .zip(path.solver.pressure())
        .map(|((c, q), p)| (*c, p * area, q[0] * area));
    check_coefficient(law, peak.point.force_n / normal_force, peak.point.displacement_m)?;
    let classes = SlideClasses::tally(elements, (normal_force, peak.point.force_n));
    Ok(ElasticOnset {
        normal_force,
        static_force: peak.point.force_n,
        mu_d: law.mu_d,
        classes,
        peak,
        curve,
        stuck_stiffness: k,
        work: path.work,
    })
}

/// An error unless `peak_tolerance` (the fraction of F_S the search for it leaves) lies in
/// (0, 0.1).
pub fn check_peak_tolerance(peak_tolerance: f64) -> Result<()> {
    if peak_tolerance > 0.0 && peak_tolerance < 0.1 {
        Ok(())
    } else {
        Err(Error::invalid("--peak-tolerance", format!("must lie in (0, 0.1), got {peak_tolerance}")))
    }
}

/// An error unless the tangential force `force` \[N] of a partial-slip state (as `option`)
/// lies in (0, μN), for the Coulomb coefficient `mu` and the normal force `normal_force` \[N].
pub fn check_partial_slip_force(force: f64, mu: f64, normal_force: f64, option: &str) -> Result<()> {
    if force > 0.0 && force < mu * normal_force {
        Ok(())
    } else {
        Err(Error::invalid(
            option,
            format!("must lie in (0, μN) = (0, {:.6e}) N for a partial-slip state, got {force:e} N", mu * normal_force),
        ))
    }
}

/// A partial-slip state under Coulomb friction (coefficient `mu`): the tangential force ramped
/// to `force` \[N] by increasing δ, located to a relative 1e-6.
pub fn ramp_force(solver: &mut TangentialSolver, mu: f64, force: f64) -> Result<(Snapshot, SlideWork)> {
    let normal_force = solver.normal_force();
    check_partial_slip_force(force, mu, normal_force, "--tangential-force")?;
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
    // Step until the force passes `force`, then bisect that last step from the state before it.
    let mut before = path.state.clone();
    let (mut lo, mut hi) = ((0.0, 0.0), (0.0, 0.0));
    for k in 1..=MAX_RAMP_STEPS {
        before = path.state.clone();
        lo = hi;
        let point = path.step(h * k as f64, f64::NEG_INFINITY)?.1.expect("a step that is never abandoned settles");
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
    Ok((path.snapshot(&path.state.slipped, point), path.work))
}

/// The force after one increment from `start` to `delta`.
fn force_at(path: &mut Path, start: &State, delta: f64) -> Result<f64> {
    path.go_back(start);
    Ok(path.step(delta, f64::NEG_INFINITY)?.1.expect("a step that is never abandoned settles").force_n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{Boundary, Material, ShearCompliance, TangentialOptions};
    use crate::friction::curve::displacement;
    use crate::friction::law::FrictionLaw;
    use crate::friction::onset::{ElementLoads, Onset};
    use crate::friction::stiffness::element_stiffness;

    /// Four equal elements at the corners of a square share the shear equally by symmetry, as
    /// the model's elements do: the elastic onset rises with K_t and peaks, all slipping at
    /// once, at the model's δ_peak = n s*/K_t with k_t = K_t/n.
    #[test]
    fn four_equal_elements_peak_at_the_models_delta_peak() {
        let si = Material { youngs: 130e9, poisson: 0.26 };
        let (n, l) = (80, 8e-6);
        let mut pressure = vec![0.0; n * n];
        for (y, x) in [(20, 20), (20, 60), (60, 20), (60, 60)] {
            pressure[y * n + x] = 1e9;
        }
        let mut solver = TangentialSolver::new(
            &pressure,
            (n, n),
            (l, l),
            ShearCompliance::of(&[si]),
            Boundary::Free,
            TangentialOptions::default(),
        )
        .unwrap();
        let (k, _) = stuck_stiffness(&mut solver).unwrap();
        let loads = ElementLoads::from_forces(&[1e9 * 1e-14; 4]).unwrap();
        let model = Onset::new(&loads, &FrictionLaw::new(0.6, 0.4).unwrap());
        let delta_peak = displacement(model.critical_shear(), element_stiffness(k, 4));
        assert!((delta_peak / (4.0 * 0.6 * 1e-5 / k) - 1.0).abs() < 1e-12);

        let law = SlipLaw { mu_s: 0.6, mu_d: 0.4, weakening: Weakening::Instant };
        let elastic = elastic_onset(&mut solver, &law, PEAK_TOLERANCE, |_| {}).unwrap();
        for p in elastic.curve.iter().filter(|p| p.slip_points == 0 && p.displacement_m > 0.0) {
            assert!((p.force_n / p.displacement_m / k - 1.0).abs() < 1e-5, "stuck slope {p:?}, K_t {k} N/m");
        }
        let peak = elastic.peak.point;
        eprintln!("K_t {k:.6e} N/m, δ_peak {delta_peak:.6e} m, the elastic onset's peak at {peak:?}");
        assert!((peak.displacement_m / delta_peak - 1.0).abs() < 1e-4, "{peak:?} against δ_peak {delta_peak} m");
        assert!((elastic.static_force / (0.6 * 4e-5) - 1.0).abs() < 1e-4);
    }
}
