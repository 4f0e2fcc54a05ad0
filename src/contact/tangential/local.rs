//! The local solves after a change of a few bounds: the tractions near them first, as small
//! dense problems of their own.
//!
//! Imports its parent (`tangential`), `disk` and `operator` inside `contact`; must not import
//! friction, study, report, plot, shs, cli.

use super::disk::cut_onto_disks;
use super::operator::ShearOperator;
use super::{TangentialReport, TangentialSolver};
use crate::error::Result;

/// After a change of a few bounds, the points within this many pixels of them are solved for
/// first ([`TangentialSolver::solve_after_change`]), in groups of at most [`LOCAL_POINTS`],
/// [`LOCAL_TOTAL`] in all. Measured on the sliding onset at 1500², 31.6 mN (stand-in ball
/// with its wafer, mu_s 0.6, mu_d 0.4; applications, seconds on 2 cores): without 3 357,
/// 56 s; radius 6 2 849, 47 s; 8 2 805, 45 s; groups of 512 2 862, 48 s; one group of 1 024
/// at most 3 073, 51 s; 8 192 in all 2 778, 49 s (the dense solves' cost).
const LOCAL_RADIUS: i64 = 8;

/// The largest group: its dense operator holds 1 024² pairs of three coefficients, 24 MiB.
const LOCAL_POINTS: usize = 1024;

/// Local solves are made while their groups' pairs (Σ n²) are at most this many times g·log₂g
/// for a transform grid of g points (a dense application costs about as much as a transform
/// pair when n² is 0.4 g·log₂g, and a local solve takes some ten of them to save about five
/// applications). Measured: 256², 100 mN (2 546 points, the transforms cheap) 2.2 s without
/// local solves, 2.9 s with all, 1.9 s with this (2.0 s at 0.05 and 0.2); 1500², 10 mN the same
/// 2 310 applications at 0.1 and 0.2.
const LOCAL_WORK: f64 = 0.1;

/// The most points solved for first in all; more, and the whole is solved at once.
const LOCAL_TOTAL: usize = 4096;

impl TangentialSolver {
    /// [`solve_within`](Self::solve_within) after the bounds changed at the points `changed`
    /// (indices into the contact points) alone, as in a round of a slip cascade. The traction
    /// changes mostly near them (K's inverse is short-ranged), so the tractions within
    /// `LOCAL_RADIUS` pixels of them are first solved for, with the others held, to half the
    /// tolerance: each group of nearby points as a dense problem of its own, the groups side
    /// by side (their interaction left to what follows). The whole is then solved from there,
    /// as before, and often has converged at the one application that checks it (with one
    /// group of at most 1 024 points, 108 of the 180 rounds at 1500², 31.6 mN solved near
    /// first, 176 of which lowered fewer than 10 bounds; those took 2 applications each, 6.5
    /// before). The result is the whole's, to its tolerance: at
    /// 1500², 10 mN the drop with and without is 1.0011956 either way at a tolerance of 1e-7
    /// (2e-8 apart), 1.0011958 and 1.0011981 at 1e-6 (the path's cascades differ within it).
    /// The iterations reported include those of the groups' solves; the applications, of the
    /// transforms only.
    pub fn solve_after_change(
        &mut self,
        target: &[[f64; 2]],
        bound: &[f64],
        tolerance: f64,
        changed: &[usize],
    ) -> Result<TangentialReport> {
        let mut applications = 0;
        let mut iterations = 0;
        let groups = match &self.operator {
            // Worth it against the transforms only: a dense operator is as cheap on the whole.
            ShearOperator::Grid { influence, .. } => {
                let groups = self.near_groups(changed, LOCAL_RADIUS, LOCAL_POINTS, LOCAL_TOTAL);
                let g = influence.transform_points() as f64;
                let work: usize = groups.iter().map(|group| group.len() * group.len()).sum();
                if work as f64 <= LOCAL_WORK * g * g.log2() {
                    groups
                } else {
                    Vec::new()
                }
            }
            ShearOperator::Dense { .. } => Vec::new(),
        };
        if !groups.is_empty() {
            let cuts = cut_onto_disks(&mut self.traction, bound);
            self.take_cuts(&cuts, false, &mut applications);
            self.lipschitz(&mut applications);
            let solved: Vec<_> = groups.iter().map(|near| self.solve_near(near, target, bound, tolerance)).collect();
            for (near, result) in groups.iter().zip(solved) {
                // A group that does not converge keeps its tractions: the whole's solve follows.
                if let Ok((traction, its)) = result {
                    near.iter().zip(traction).for_each(|(&i, q)| self.traction[i] = q);
                    iterations += its;
                }
            }
            self.refresh();
            applications += 1;
        }
        let mut report = self.solve_within(target, bound, tolerance)?;
        report.applications += applications;
        report.iterations += iterations;
        Ok(report)
    }

    /// The contact points within `radius` pixels (each way) of the points `of` (indices into
    /// the contact points, increasing), in groups of at most `most` (each point in one): the
    /// neighbourhoods of consecutive points of `of` go into one group until it is full. None
    /// when they are more than `total` in all.
    fn near_groups(&self, of: &[usize], radius: i64, most: usize, total: usize) -> Vec<Vec<usize>> {
        let (ny, nx) = (self.shape.0 as i64, self.shape.1 as i64);
        let mut claimed = vec![false; self.points.len()];
        let mut groups: Vec<Vec<usize>> = vec![Vec::new()];
        let mut count = 0;
        for &c in of {
            let (y, x) = ((self.points[c] / nx as usize) as i64, (self.points[c] % nx as usize) as i64);
            let mut own = Vec::new();
            for yy in (y - radius).max(0)..=(y + radius).min(ny - 1) {
                let lo = (yy * nx + (x - radius).max(0)) as usize;
                let hi = (yy * nx + (x + radius).min(nx - 1)) as usize;
                let from = self.points.partition_point(|&p| p < lo);
                let to = self.points.partition_point(|&p| p <= hi);
                for (k, claimed) in claimed.iter_mut().enumerate().take(to).skip(from) {
                    if !*claimed {
                        *claimed = true;
                        own.push(k);
                    }
                }
            }
            count += own.len();
            if count > total {
                return Vec::new();
            }
            let last = groups.last_mut().expect("one group at least");
            if !last.is_empty() && last.len() + own.len() > most {
                groups.push(own);
            } else {
                last.extend(own);
            }
        }
        groups.retain(|g| !g.is_empty());
        groups.iter_mut().for_each(|g| g.sort_unstable());
        groups
    }

    /// The tractions at the points `near` that solve the problem with the others' held, to
    /// half the `tolerance` of the whole (relative to its target), and the iterations it took.
    fn solve_near(
        &self,
        near: &[usize],
        target: &[[f64; 2]],
        bound: &[f64],
        tolerance: f64,
    ) -> Result<(Vec<[f64; 2]>, usize)> {
        let mut sub = Self::assemble(
            self.shape,
            self.size,
            self.operator.subset(near),
            self.options,
            near.iter().map(|&i| self.points[i]).collect(),
            near.iter().map(|&i| self.pressure[i]).collect(),
            self.near_inverse.subset(near, self.points.len()),
        );
        near.iter().zip(&mut sub.traction).for_each(|(&i, q)| *q = self.traction[i]);
        // K's largest eigenvalue on a subset is at most that on the whole.
        sub.lipschitz = self.lipschitz;
        sub.diagonal = self.diagonal;
        sub.refresh();
        // The targets less what the held tractions displace there.
        let sub_target: Vec<[f64; 2]> = near
            .iter()
            .zip(&sub.displacement)
            .map(|(&i, w)| {
                let (b, u) = (target[i], self.displacement[i]);
                [b[0] - (u[0] - w[0]), b[1] - (u[1] - w[1])]
            })
            .collect();
        let sub_bound: Vec<f64> = near.iter().map(|&i| bound[i]).collect();
        let norm = |v: &[[f64; 2]]| v.iter().map(|b| b[0] * b[0] + b[1] * b[1]).sum::<f64>().sqrt();
        let local_tolerance = 0.5 * tolerance * norm(target) / norm(&sub_target);
        let report = sub.solve_within(&sub_target, &sub_bound, local_tolerance.min(0.5))?;
        Ok((sub.traction, report.iterations))
    }
}

#[cfg(test)]
mod tests {
    use super::super::disk::magnitude;
    use super::super::TangentialOptions;
    use super::*;
    use crate::contact::influence::{Boundary, ShearCompliance};

    /// After a few bounds fall, solving near them first gives the whole's solution (to the
    /// tolerance) in fewer applications: a Hertz-like disk of every third pixel each way (704
    /// points, so that the neighbourhoods are small against the 128² window's transforms), its
    /// rim slipping, the three stuck points nearest their bounds made to slip.
    #[test]
    fn solving_near_changed_bounds_first_gives_the_same_solution() {
        let c = ShearCompliance { a: 1.0 / 50e9, b: 0.26 / 50e9 };
        let n = 128;
        let mut pressure = vec![0.0; n * n];
        for y in (1..n).step_by(3) {
            for x in (1..n).step_by(3) {
                let r2 = ((y as f64 - 64.0).powi(2) + (x as f64 - 61.5).powi(2)) / 45.0f64.powi(2);
                if r2 < 1.0 {
                    pressure[y * n + x] = 1e9 * (1.0 - r2).sqrt();
                }
            }
        }
        let options = TangentialOptions { tolerance: 1e-9, ..TangentialOptions::default() };
        let make = || {
            let mut s =
                TangentialSolver::new(&pressure, (n, n), (2.56e-6, 2.56e-6), c, Boundary::Periodic, options).unwrap();
            let m = s.points().len();
            // The stuck force per metre, then half the sliding force at mu = 0.5.
            s.solve(&vec![[1.0, 0.0]; m], &vec![f64::INFINITY; m]).unwrap();
            let k = s.force()[0];
            let bound: Vec<f64> = s.pressure().iter().map(|p| 0.5 * p).collect();
            let delta = 0.5 * 0.5 * s.normal_force() / k;
            let target = vec![[delta, 0.0]; m];
            s.set_traction(&vec![[0.0; 2]; m]);
            s.solve(&target, &bound).unwrap();
            (s, target, bound)
        };
        let (mut near, target, mut bound) = make();
        let (mut whole, ..) = make();
        assert!(matches!(near.operator, ShearOperator::Grid { .. }), "{} points: the transforms", near.points.len());
        let m = near.points.len();
        let q = near.traction().to_vec();
        let ratio = |i: usize| magnitude(q[i]) / bound[i];
        let slipping = (0..m).filter(|&i| ratio(i) > 1.0 - 1e-9).count();
        assert!(slipping > 100 && slipping < m / 2, "{slipping} of {m} slipping");
        let mut stuck: Vec<usize> = (0..m).filter(|&i| ratio(i) < 1.0 - 1e-6).collect();
        stuck.sort_by(|&a, &b| ratio(b).total_cmp(&ratio(a)));
        let changed: Vec<usize> = {
            let mut c = stuck[..3].to_vec();
            c.sort_unstable();
            c
        };
        changed.iter().for_each(|&i| bound[i] *= 0.5);
        let local = near.solve_after_change(&target, &bound, 1e-9, &changed).unwrap();
        let global = whole.solve_within(&target, &bound, 1e-9).unwrap();
        let norm = |v: &[[f64; 2]]| v.iter().map(|q| q[0] * q[0] + q[1] * q[1]).sum::<f64>().sqrt();
        let difference: Vec<[f64; 2]> =
            near.traction().iter().zip(whole.traction()).map(|(a, b)| [a[0] - b[0], a[1] - b[1]]).collect();
        let relative = norm(&difference) / norm(whole.traction());
        assert!(relative < 1e-7, "tractions {relative:.2e} apart");
        assert!(
            local.applications < global.applications,
            "{} applications near first, {} at once",
            local.applications,
            global.applications
        );
    }
}
