//! Load control and the pull-off search of the adhesive solver: a march and a bracketing
//! regula falsi (Illinois) on the separation to reach a load, and the sweep of the separation
//! that finds the pull-off force (see the parent module).
//!
//! Imports its parent (`adhesion`), `influence`, `options` and `solver` (the start without
//! adhesion) inside `contact`; must not import
//! friction, study, report, plot, shs, cli.

use std::time::Instant;

use super::{AdhesiveReport, AdhesiveSolver, PullOff};
use crate::contact::influence::Boundary;
use crate::contact::options::{Convergence, Device, SolverOptions};
use crate::contact::solver::ContactSolver;
use crate::error::{Error, Result};

/// The loosest tolerance of load control's steps far from the load sought.
const LOOSE: f64 = 1e-4;

/// Steps of the load control's secant before it gives up.
const MAX_SECANT: usize = 100;

/// Steps of the pull-off sweep, or of load control's march, before it gives up.
const MAX_SWEEP: usize = 400;

/// Iterations and solves at imposed separation, summed over a load-controlled solve or a sweep.
#[derive(Default)]
struct Tally {
    iterations: usize,
    solves: usize,
}

impl AdhesiveSolver {
    /// Solve for the normal load `load` \[N] (compressive positive, tensile negative), from
    /// the last state, or cold from a compressive one. A load below the pull-off force is
    /// refused with the pull-off force in the message.
    pub fn solve(&mut self, load: f64) -> Result<AdhesiveReport> {
        let start = Instant::now();
        if !load.is_finite() {
            return Err(Error::invalid("--load", format!("must be finite, got {load} N")));
        }
        let mut tally = Tally::default();
        self.pressure_scale = load.abs() / (self.size.0 * self.size.1);
        let last = self.reach_load(load, &mut tally)?;
        Ok(AdhesiveReport {
            iterations: tally.iterations,
            solves: tally.solves,
            seconds: start.elapsed().as_secs_f64(),
            ..last
        })
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
        let (_, pull_off) = self.sweep_to_pull_off(&mut tally)?;
        Ok(pull_off)
    }

    /// One solve at separation `s`, counted, to the tolerance set.
    fn at(&mut self, s: f64, tally: &mut Tally) -> Result<AdhesiveReport> {
        let report = self.at_separation(s)?;
        tally.iterations += report.iterations;
        tally.solves += 1;
        Ok(report)
    }

    /// A separation `step` \[m] closer than `s`: periodic, the mean gap stays positive.
    fn closer(&self, s: f64, step: f64) -> f64 {
        match self.boundary {
            Boundary::Periodic => (s - step).max(0.25 * s),
            Boundary::Free => s - step,
        }
    }

    /// See [`solve`](Self::solve): the last solve's report.
    fn reach_load(&mut self, target: f64, tally: &mut Tally) -> Result<AdhesiveReport> {
        // Far from the load sought a step needs no more than a rough solve: the tolerance of
        // each is a hundredth of the last relative load error, between the convergence's and
        // LOOSE, so that the solve that is accepted has the convergence's.
        let tight = self.convergence.tolerance;
        self.tolerance = LOOSE.max(tight);
        // A state held in contact is the start; one apart (past a pull-off) carries no load to
        // start a branch from, and a cold start presses first.
        let held_state = if self.warm { Some(self.forces()).filter(|r| r.contact_points > 0) } else { None };
        let held = held_state.is_some();
        // The first step's stiffness −dN/ds [N/m], where known.
        let (mut current, stiffness) = match held_state {
            Some(state) => (state, None),
            None if target > 0.0 => {
                // The equilibrium without adhesion at the load sought is near the adhesive one
                // (adhesion adds the tension of a thin zone around the contact): the march and
                // the secant start a few steps from it, not from the first touch.
                let k = Some(self.seed(target)?).filter(|k| k.is_finite() && *k > 0.0);
                (self.at(self.separation, tally)?, k)
            }
            None => {
                self.warm = false;
                let s = match self.boundary {
                    Boundary::Periodic => self.touching,
                    Boundary::Free => 0.0,
                };
                let mut r = self.at(s, tally)?;
                // Pressed first, so that a tensile load is reached unloading.
                let mut step = self.law.range();
                while r.load < target.max(0.0) {
                    r = self.at(self.closer(r.separation, step), tally)?;
                    step *= 2.0;
                }
                (r, None)
            }
        };
        let tolerance = |r: &AdhesiveReport, c: &Convergence| {
            (100.0 * c.tolerance).max(1e-13) * (r.compressive_force + r.adhesive_force)
        };
        let loosen = |this: &mut Self, r: &AdhesiveReport| {
            let error = (r.load - target).abs() / (r.compressive_force + r.adhesive_force).max(f64::MIN_POSITIVE);
            this.tolerance = (0.01 * error).clamp(tight, LOOSE.max(tight));
        };
        if held && (current.load - target).abs() <= tolerance(&current, &self.convergence) {
            // The state held (at the tolerance its solve had) already carries the load.
            return Ok(current);
        }
        loosen(self, &current);
        // March towards the target, each step the secant's estimate of the distance left
        // (at first the law's range), at most twice the last and at least a thousandth of the
        // range, until the load crosses it: the first crossing from the state held. Bracket:
        // (separation, load) closer, with the load above the target, and farther, at or below.
        let outward = current.load > target;
        let range = self.law.range();
        let mut step = range;
        let mut last_step = f64::INFINITY;
        let mut slope: Option<f64> = stiffness;
        let mut marched = 0;
        let (mut near, mut far) = loop {
            marched += 1;
            if marched > MAX_SWEEP {
                return Err(Error::NotConverged {
                    solver: "adhesive load control",
                    iterations: MAX_SWEEP,
                    residual: (current.load - target).abs() / target.abs().max(f64::MIN_POSITIVE),
                    tolerance: 100.0 * self.convergence.tolerance,
                });
            }
            if let Some(k) = slope {
                step = (1.2 * (current.load - target).abs() / k).min(2.0 * last_step).max(1e-3 * range);
            }
            let s = if outward { current.separation + step } else { self.closer(current.separation, step) };
            let next = self.at(s, tally)?;
            if outward && next.load <= target {
                break ((current.separation, current.load), (next.separation, next.load));
            }
            if !outward && next.load >= target {
                break ((next.separation, next.load), (current.separation, current.load));
            }
            if outward && target < 0.0 && next.load >= current.load {
                // Past the least load of the branch, or apart, or a jump of the load: the
                // pull-off decides (a load of zero or more lies above it: no sweep, whose own
                // first step is the load zero).
                let (zero, pull_off) = self.sweep_to_pull_off(tally)?;
                if target < pull_off.load {
                    return Err(Error::invalid(
                        "--load",
                        format!(
                            "{} N is below the pull-off force {} N: no equilibrium holds the surfaces together",
                            crate::quantity::human(target),
                            crate::quantity::human(pull_off.load)
                        ),
                    ));
                }
                break ((zero, 0.0), (pull_off.separation, pull_off.load));
            }
            loosen(self, &next);
            let k = ((next.load - current.load) / (next.separation - current.separation)).abs();
            slope = Some(k).filter(|k| *k > 0.0);
            last_step = (next.separation - current.separation).abs();
            current = next;
        };
        // Regula falsi, Illinois: the end that stays has its load difference halved. A solve
        // that meets the load loosely is done again at the convergence's tolerance; a bracket
        // narrower than a billionth of the law's range ends it (the Maugis–Dugdale law's load
        // jumps where a pixel leaves its zone: the load nearest the target is returned).
        let (mut f_near, mut f_far) = (near.1 - target, far.1 - target);
        let mut side = 0;
        for _ in 0..MAX_SECANT {
            let s = far.0 - f_far * (far.0 - near.0) / (f_far - f_near);
            let mut r = self.at(s, tally)?;
            let narrow = (far.0 - near.0).abs() <= 1e-9 * self.law.range();
            if ((r.load - target).abs() <= tolerance(&r, &self.convergence) || narrow) && self.tolerance > tight {
                self.tolerance = tight;
                r = self.at(s, tally)?;
            }
            if (r.load - target).abs() <= tolerance(&r, &self.convergence) || narrow {
                return Ok(r);
            }
            loosen(self, &r);
            let f = r.load - target;
            if f > 0.0 {
                (near, f_near) = ((s, r.load), f);
                if side == 1 {
                    f_far *= 0.5;
                }
                side = 1;
            } else {
                (far, f_far) = ((s, r.load), f);
                if side == -1 {
                    f_near *= 0.5;
                }
                side = -1;
            }
        }
        Err(Error::NotConverged {
            solver: "adhesive load control",
            iterations: MAX_SECANT,
            residual: (near.1 - target).abs().min((far.1 - target).abs()) / target.abs().max(f64::MIN_POSITIVE),
            tolerance: 100.0 * self.convergence.tolerance,
        })
    }

    /// Start from the equilibrium without adhesion at the compressive load `load` \[N]:
    /// its gap, and its separation (periodic, the mean gap; free, the rigid body's position
    /// from the first touch of the highest point, minus the mean of u − h over the contact).
    /// Returns the contact's stiffness there, −dN/ds \[N/m], from a second solve at a load 1 %
    /// lower: the first step of load control. Solved to the loosest tolerance of load
    /// control's steps: the adhesive solves refine it.
    fn seed(&mut self, load: f64) -> Result<f64> {
        let heights = self.window_map(|s, i| s.heights[i]);
        let options = SolverOptions {
            convergence: Convergence { tolerance: LOOSE, max_iterations: self.convergence.max_iterations },
            device: Device::Cpu,
        };
        let mut plain = ContactSolver::new(&heights, self.shape(), self.size, self.e_star, self.boundary, options)?;
        let boundary = self.boundary;
        let separation = |plain: &ContactSolver, gap: &[f64]| match boundary {
            Boundary::Periodic => gap.iter().sum::<f64>() / gap.len() as f64,
            Boundary::Free => {
                let (u, p) = (plain.displacement(), plain.pressure());
                let (sum, count) = (0..gap.len())
                    .filter(|&i| p[i] > 0.0)
                    .fold((0.0, 0usize), |(sum, count), i| (sum + u[i] - heights[i], count + 1));
                -sum / count.max(1) as f64
            }
        };
        let lighter = 0.99 * load;
        plain.solve(lighter, |_, _| ())?;
        let apart = separation(&plain, &plain.gap());
        plain.solve(load, |_, _| ())?;
        let gap = plain.gap();
        let at = separation(&plain, &gap);
        drop(plain);
        self.warm_start(&gap, at)?;
        Ok((load - lighter) / (apart - at))
    }

    /// The sweep of [`pull_off`](Self::pull_off): (the separation at zero load, the pull-off).
    fn sweep_to_pull_off(&mut self, tally: &mut Tally) -> Result<(f64, PullOff)> {
        let zero = self.reach_load(0.0, tally)?;
        self.tolerance = self.convergence.tolerance;
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
        Ok((
            zero.separation,
            PullOff { load: best.1, separation: best.0, contact_points: best.2, solves: tally.solves },
        ))
    }
}
