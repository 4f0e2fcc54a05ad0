//! Load control and the pull-off search of the adhesive solver.
//!
//! Load control is the difference-of-convex algorithm (DCA; Pham Dinh & Le Thi, Acta Math.
//! Vietnam. 22, 1997; the concave–convex procedure of Yuille & Rangarajan, Neural Comput. 15,
//! 2003): the energy is the elastic energy with the contact constraint and the load's work
//! (convex) plus the cohesive potential Σφ(g) (concave: the tension falls as the gap opens).
//! Each step freezes the cohesive tension τ = t(g) of the last gap, which linearises the concave
//! part, and minimises what is left exactly: a contact without adhesion under the load N + Στ
//! on the heights shifted by the frozen tension's displacement Gτ, solved by the non-adhesive
//! solver (Polonsky & Keer, load control inside its conjugate gradient) from its last pressure.
//! A linearised concave term lies above the term itself, so every step lowers the energy: the
//! steps converge to an equilibrium, the Maugis–Dugdale law's in finitely many (its tension
//! takes two values), and what they reach is the one downhill of the start, the branch a ball
//! follows when the load is applied. Where no equilibrium holds the load the contact opens
//! (the frozen tension no longer carries the load): the pull-off decides, found by the sweep.
//!
//! The pull-off sweep runs at imposed separation, on the parent module's iteration: the
//! separation, not the load, is what passes the least load of a branch.
//!
//! Imports its parent (`adhesion`), `influence`, `options` and `solver` (the steps without
//! adhesion) inside `contact`; must not import friction, study, report, plot, shs, cli.

use std::time::Instant;

use super::{AdhesiveReport, AdhesiveSolver, PullOff};
use crate::contact::influence::Boundary;
use crate::contact::options::{Device, SolverOptions};
use crate::contact::solver::ContactSolver;
use crate::error::{Error, Result};

/// The loosest tolerance of the steps without adhesion far from the equilibrium sought.
const LOOSE: f64 = 1e-3;

/// Steps of the DCA before it gives up.
const MAX_STEPS: usize = 2_000;

/// Doublings of the first press of a cold start before it gives up.
const MAX_PRESS: usize = 60;

/// Steps of the pull-off sweep before it gives up.
const MAX_SWEEP: usize = 400;

/// Iterations and solves, summed over a load-controlled solve or a sweep.
#[derive(Default)]
struct Tally {
    iterations: usize,
    solves: usize,
}

/// Load control's state: the solver without adhesion on the heights shifted by the frozen
/// tension's displacement, and that tension.
pub(super) struct Frozen {
    plain: ContactSolver,
    /// The window's heights \[m], as the adhesive solver holds them.
    heights: Vec<f64>,
    /// The frozen tension τ \[Pa] on the window.
    tension: Vec<f64>,
    /// The next step's tension \[Pa], the shifted heights h + Gτ \[m] and the gap of the last
    /// step \[m].
    next: Vec<f64>,
    shifted: Vec<f64>,
    gap: Vec<f64>,
    /// Whether the solver's heights are shifted by the tension frozen now.
    shifted_now: bool,
    /// Whether `plain` and `tension` hold the adhesive solver's state.
    pub(super) current: bool,
}

impl AdhesiveSolver {
    /// Solve for the normal load `load` \[N] (compressive positive, tensile negative), from
    /// the last state, or cold from the equilibrium without adhesion at a compressive load. A
    /// load below the pull-off force is refused with the pull-off force in the message.
    pub fn solve(&mut self, load: f64) -> Result<AdhesiveReport> {
        let start = Instant::now();
        if !load.is_finite() {
            return Err(Error::invalid("--load", format!("must be finite, got {load} N")));
        }
        let mut tally = Tally::default();
        self.pressure_scale = load.abs() / (self.size.0 * self.size.1);
        let held = match self.hold_load(load, &mut tally)? {
            Some(report) => report,
            None => {
                // Apart: below the pull-off, or past the end of the branch the start led to.
                let pull_off = self.sweep_to_pull_off(&mut tally)?;
                if load < pull_off.load {
                    return Err(Error::invalid(
                        "--load",
                        format!(
                            "{} N is below the pull-off force {} N of the branch reached from the last \
                             state: no equilibrium on it holds the surfaces together",
                            crate::quantity::human(load),
                            crate::quantity::human(pull_off.load)
                        ),
                    ));
                }
                // The sweep left the solver at the pull-off, on the branch: unload from there.
                self.pressure_scale = load.abs() / (self.size.0 * self.size.1);
                self.hold_load(load, &mut tally)?.ok_or(Error::NotConverged {
                    solver: "adhesive load control",
                    iterations: tally.solves,
                    residual: 1.0,
                    tolerance: self.convergence.tolerance,
                })?
            }
        };
        Ok(AdhesiveReport {
            iterations: tally.iterations,
            solves: tally.solves,
            seconds: start.elapsed().as_secs_f64(),
            ..held
        })
    }

    /// Solve for the compressive load `load` \[N] from the equilibrium without adhesion at that
    /// load: its `pressure` \[Pa] and `gap` \[m] (row-major (ny, nx)), as [`ContactSolver`]
    /// solves them on the same heights to the same tolerance. That is the loading of a ball
    /// pressed onto its counterface, whatever state is held; a study's sweep has the
    /// equilibrium at hand, so the adhesive solve costs its steps alone.
    pub fn solve_from(&mut self, load: f64, pressure: &[f64], gap: &[f64]) -> Result<AdhesiveReport> {
        let start = Instant::now();
        if !(load > 0.0 && load.is_finite()) {
            return Err(Error::invalid(
                "--load",
                format!("must be compressive to start from a solve without adhesion, got {load} N"),
            ));
        }
        let (ny, nx) = (self.ny, self.nx);
        if gap.len() != ny * nx {
            return Err(Error::invalid("warm start", format!("{} gaps for a {ny}×{nx} grid", gap.len())));
        }
        self.lose_state();
        self.make_frozen()?;
        let law = self.law;
        let f = self.frozen.as_mut().expect("made");
        f.plain.warm_start(pressure)?;
        f.tension.iter_mut().zip(gap).for_each(|(t, g)| *t = law.tension(*g));
        f.shifted_now = false;
        f.current = true;
        let report = self.solve(load)?;
        Ok(AdhesiveReport { seconds: start.elapsed().as_secs_f64(), ..report })
    }

    /// The pull-off force: the least load along the branch that unloads from the equilibrium
    /// at zero load as the separation grows. A sweep with steps that keep each change of the
    /// load near 5 % of the adhesive force at zero load, until the load rises, refined twice by
    /// eight steps around the least load. Where the load jumps with the separation (a cohesive
    /// zone of a few pixels or less), a lower load may lie past the first rise: the pull-off
    /// is that of the branch up to it. The solver is left at the pull-off.
    pub fn pull_off(&mut self) -> Result<PullOff> {
        let mut tally = Tally::default();
        self.pressure_scale = 0.0;
        let pull_off = self.sweep_to_pull_off(&mut tally)?;
        Ok(pull_off)
    }

    /// One solve at separation `s`, counted.
    fn at(&mut self, s: f64, tally: &mut Tally) -> Result<AdhesiveReport> {
        let report = self.at_separation(s)?;
        tally.iterations += report.iterations;
        tally.solves += 1;
        Ok(report)
    }

    /// The equilibrium at `load` \[N] downhill of the state held (or of a cold start), or
    /// `None` where the contact opens on the way.
    fn hold_load(&mut self, load: f64, tally: &mut Tally) -> Result<Option<AdhesiveReport>> {
        if !self.frozen.as_ref().is_some_and(|f| f.current) {
            let held = self.warm && self.forces().contact_points > 0;
            self.make_frozen()?;
            if held {
                self.freeze()?;
            } else {
                self.press(load, tally)?;
            }
        }
        self.descend(load, tally)
    }

    /// The load control's state, made on first use.
    fn make_frozen(&mut self) -> Result<()> {
        if self.frozen.is_none() {
            let heights = self.window_map(|s, i| s.heights[i]);
            let options = SolverOptions { convergence: self.convergence, device: Device::Cpu };
            let mut plain = ContactSolver::new(&heights, self.shape(), self.size, self.e_star, self.boundary, options)?;
            plain.set_rescaled_start(true);
            let n = heights.len();
            self.frozen = Some(Frozen {
                plain,
                heights,
                tension: vec![0.0; n],
                next: vec![0.0; n],
                shifted: vec![0.0; n],
                gap: vec![0.0; n],
                shifted_now: false,
                current: false,
            });
        }
        Ok(())
    }

    /// A cold start: the equilibrium without adhesion at the load sought (a compressive one),
    /// or at a load pressed harder (four times at a time, from the larger of the load's size
    /// and one pixel at the cohesive strength) until the tension of its gap carries the load
    /// sought, so that a tensile load is reached unloading.
    fn press(&mut self, load: f64, tally: &mut Tally) -> Result<()> {
        let pixel = self.size.0 * self.size.1 / (self.ny * self.nx) as f64;
        let law = self.law;
        let f = self.frozen.as_mut().expect("made");
        f.plain.set_heights(&f.heights)?;
        f.shifted_now = false;
        f.plain.set_tolerance(LOOSE.max(self.convergence.tolerance))?;
        f.plain.reset();
        let mut press = if load > 0.0 { load } else { (-load).max(law.strength() * pixel) };
        for _ in 0..MAX_PRESS {
            let report = f.plain.solve(press, |_, _| ())?;
            tally.iterations += report.iterations;
            tally.solves += 1;
            let gap = f.plain.gap();
            f.tension.iter_mut().zip(&gap).for_each(|(t, g)| *t = law.tension(*g));
            if load + pixel * f.tension.iter().sum::<f64>() > 0.0 {
                f.current = true;
                return Ok(());
            }
            press *= 4.0;
        }
        Err(Error::NotConverged {
            solver: "adhesive load control's press",
            iterations: MAX_PRESS,
            residual: 1.0,
            tolerance: 0.0,
        })
    }

    /// Load control's state from the equilibrium held at imposed separation: the tension of
    /// its gap, frozen, and its compressive pressure, σ + τ where the surfaces touch.
    fn freeze(&mut self) -> Result<()> {
        let gap = self.gap();
        let traction = self.traction();
        let law = self.law;
        let f = self.frozen.as_mut().expect("made");
        f.tension.iter_mut().zip(&gap).for_each(|(t, g)| *t = law.tension(*g));
        f.shifted_now = false;
        let pressure: Vec<f64> =
            (0..gap.len()).map(|i| if gap[i] <= 0.0 { (traction[i] + f.tension[i]).max(0.0) } else { 0.0 }).collect();
        self.shift_heights()?;
        let f = self.frozen.as_mut().expect("made");
        if pressure.iter().any(|p| *p > 0.0) {
            f.plain.warm_start(&pressure)?;
        } else {
            f.plain.reset();
        }
        f.current = true;
        Ok(())
    }

    /// The frozen solver's heights: h + Gτ, unless they are already.
    fn shift_heights(&mut self) -> Result<()> {
        let f = self.frozen.as_mut().expect("made");
        if !f.shifted_now {
            self.fft_plan.apply(&f.tension, &mut f.shifted);
            f.shifted.iter_mut().zip(&f.heights).for_each(|(s, h)| *s += h);
            f.plain.set_heights(&f.shifted)?;
            f.shifted_now = true;
        }
        Ok(())
    }

    /// The DCA's steps at `load` \[N] from the frozen state, until the tension of the gap
    /// reached is the one frozen: the residual of the parent module (σ + t(g) where the
    /// surfaces are apart) within the tolerance.
    fn descend(&mut self, load: f64, tally: &mut Tally) -> Result<Option<AdhesiveReport>> {
        let n = self.ny * self.nx;
        let pixel = self.size.0 * self.size.1 / n as f64;
        let floor = self.law.strength().max(self.pressure_scale) * (n as f64).sqrt();
        let law = self.law;
        let tight = self.convergence.tolerance;
        let mut residual = f64::INFINITY;
        // Each step is solved to a hundredth of the last residual, between the convergence's
        // tolerance and LOOSE: the step whose tension is reached is solved again to the
        // convergence's before it is accepted.
        let mut inner = LOOSE.max(tight);
        for _ in 0..MAX_STEPS {
            let carried = load + pixel * self.frozen.as_ref().expect("made").tension.iter().sum::<f64>();
            if !(carried > 0.0) {
                self.lose_state();
                return Ok(None);
            }
            self.shift_heights()?;
            let f = self.frozen.as_mut().expect("made");
            f.plain.set_tolerance(inner)?;
            let report = match f.plain.solve(carried, |_, _| ()) {
                Ok(report) => report,
                Err(e) => {
                    self.lose_state();
                    return Err(e);
                }
            };
            tally.iterations += report.iterations;
            tally.solves += 1;
            f.plain.gap_into(&mut f.gap);
            let (gap, pressure) = (&f.gap, f.plain.pressure());
            if !pressure.iter().any(|p| *p > 0.0) {
                self.lose_state();
                return Ok(None);
            }
            let (mut change, mut traction) = (0.0, 0.0);
            for i in 0..n {
                let (old, new) = (f.tension[i], law.tension(gap[i]));
                f.next[i] = new;
                if pressure[i] == 0.0 {
                    change += (new - old) * (new - old);
                }
                traction += (pressure[i] - old) * (pressure[i] - old);
            }
            residual = change.sqrt() / (traction.sqrt() + floor);
            if residual <= tight && inner > tight {
                inner = tight;
                continue;
            }
            inner = (0.01 * residual).clamp(tight, LOOSE.max(tight));
            if residual <= tight {
                let traction: Vec<f64> = pressure.iter().zip(&f.tension).map(|(p, t)| p - t).collect();
                let gap = std::mem::take(&mut f.gap);
                self.adopt(&traction, &gap, load);
                self.frozen.as_mut().expect("made").gap = gap;
                return Ok(Some(AdhesiveReport { residual, ..self.forces() }));
            }
            std::mem::swap(&mut f.tension, &mut f.next);
            f.shifted_now = false;
        }
        self.lose_state();
        Err(Error::NotConverged {
            solver: "adhesive load control",
            iterations: MAX_STEPS,
            residual,
            tolerance: self.convergence.tolerance,
        })
    }

    /// Neither state holds an equilibrium any more.
    pub(super) fn lose_state(&mut self) {
        self.warm = false;
        if let Some(f) = self.frozen.as_mut() {
            f.current = false;
        }
    }

    /// The sweep of [`pull_off`](Self::pull_off).
    fn sweep_to_pull_off(&mut self, tally: &mut Tally) -> Result<PullOff> {
        self.pressure_scale = 0.0;
        let zero = match self.hold_load(0.0, tally)? {
            Some(zero) => zero,
            // Nothing holds at zero load: from the first touch.
            None => {
                let s = match self.boundary {
                    Boundary::Periodic => self.touching,
                    Boundary::Free => 0.0,
                };
                self.at(s, tally)?
            }
        };
        let scale = zero.adhesive_force.max(f64::MIN_POSITIVE);
        // States kept: the sample before the least load, and the last sample.
        let mut before = self.x.clone();
        let mut last = self.x.clone();
        let (mut s_before, mut s_last, mut load_last) = (zero.separation, zero.separation, zero.load);
        let mut best = (zero.separation, zero.load, zero.contact_points);
        let mut step = self.law.range();
        let mut after = None;
        for _ in 0..MAX_SWEEP {
            let r = self.at(s_last + step, tally)?;
            if r.load < best.1 {
                best = (r.separation, r.load, r.contact_points);
                before.copy_from_slice(&last);
                s_before = s_last;
            } else if r.load > best.1 {
                after = Some(r.separation);
                break;
            }
            step *= (0.05 * scale / (r.load - load_last).abs().max(f64::MIN_POSITIVE)).clamp(0.5, 2.0);
            last.copy_from_slice(&self.x);
            (s_last, load_last) = (r.separation, r.load);
        }
        let mut end = after.ok_or_else(|| Error::NotConverged {
            solver: "pull-off sweep",
            iterations: MAX_SWEEP,
            residual: 1.0,
            tolerance: 0.0,
        })?;
        // Refine: from the state before the least load, eight steps to the sample after it.
        for _ in 0..2 {
            self.x.copy_from_slice(&before);
            (self.separation, self.warm) = (s_before, true);
            let (start, width) = (s_before, (end - s_before) / 8.0);
            let mut previous = (s_before, before.clone());
            end = start + 8.0 * width;
            for k in 1..=8 {
                let s = start + k as f64 * width;
                let r = self.at(s, tally)?;
                if r.load < best.1 {
                    best = (s, r.load, r.contact_points);
                    before.copy_from_slice(&previous.1);
                    s_before = previous.0;
                    end = s + width;
                } else if r.load > best.1 && s > best.0 {
                    end = end.min(s);
                    break;
                }
                previous.0 = s;
                previous.1.copy_from_slice(&self.x);
            }
        }
        self.x.copy_from_slice(&before);
        (self.separation, self.warm) = (s_before, true);
        self.at(best.0, tally)?;
        Ok(PullOff { load: best.1, separation: best.0, contact_points: best.2, solves: tally.solves })
    }
}
