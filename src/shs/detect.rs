//! Finding holds and restarts in a trace, and measuring each restart.
//!
//! The friction signal splits the trace into holds and slides; a measured displacement then
//! confirms that nothing moved during each hold. Levels are relative to the trace's own sliding
//! friction, so the same defaults work from micronewtons to newtons:
//!
//! 1. The sliding level is the median of the upper class of a two-class (Ridler–Calvard) split
//!    of the friction values; the sensor noise is estimated from sample-to-sample differences
//!    (robust to the level changes between holds and slides).
//! 2. On a 5-sample running median of the friction, with hysteresis, a hold begins when the
//!    friction falls below `hold_fraction` × the sliding level and ends when it rises above
//!    `slide_fraction` × the sliding level. Holds or slides shorter than `min_duration` are
//!    noise (a dip, a burst) and are merged into their neighbours, shortest first.
//! 3. Each hold's edges are then placed on the raw signal: the hold lasts from the first sample
//!    at which friction has settled at the hold level (within 4 robust standard deviations of
//!    its median over the hold, or 2 % of the sliding level) to the last sample at that level
//!    before the restart's rise, plus half a sample interval at each end. The hold time is the
//!    time spent at zero shear.
//! 4. After the restart, F_S is the largest friction sample within `peak_within` of sliding
//!    displacement. F_D and N are their means over `window` of displacement from the peak,
//!    located between samples by a parabola through the peak sample and its neighbours, with
//!    the signals interpolated linearly between samples; the window must end before sliding
//!    stops.

use super::{Analysis, Cycle, ShsOptions, Trace};
use crate::error::{Error, Result};

/// Half-width [samples] of the running median the hold/slide decision is made on.
const SMOOTH_HALF: usize = 2;
/// Standard deviation of a normal distribution per median absolute deviation.
const MAD_TO_SIGMA: f64 = 1.4826;
/// A hold may creep forward by at most this fraction of the sliding speed.
const HOLD_CREEP: f64 = 0.1;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    Hold,
    Slide,
}

/// A maximal stretch of samples `start..=end` in one state.
#[derive(Clone, Copy, Debug)]
struct Run {
    state: State,
    start: usize,
    end: usize,
}

pub(super) fn analyse(trace: &Trace, options: &ShsOptions) -> Result<Analysis> {
    options.validate()?;
    let (t, f) = (trace.time(), trace.friction());
    let fail = |reason: String| Error::file(trace.source(), reason);

    let smooth = running_median(f, SMOOTH_HALF);
    let split = two_class_threshold(&smooth);
    let sliding = median(&mut smooth.iter().copied().filter(|&v| v >= split).collect::<Vec<_>>());
    let diffs: Vec<f64> = f.windows(2).map(|w| w[1] - w[0]).collect();
    let noise = mad_sigma(&diffs) / std::f64::consts::SQRT_2;
    if sliding.is_nan() || sliding <= 10.0 * noise {
        return Err(fail(format!(
            "friction never rises clearly above its noise (sliding level {sliding:.3e} N, noise {noise:.3e} N)"
        )));
    }
    let hold_below = options.hold_fraction * sliding;
    let slide_above = options.slide_fraction * sliding;

    let runs = merge_short_runs(classify(&smooth, hold_below, slide_above), t, options.min_duration);
    let slide_speed = match trace.displacement() {
        Some(x) => {
            let v = median(
                &mut runs
                    .iter()
                    .filter(|r| r.state == State::Slide)
                    .flat_map(|r| r.start..r.end)
                    .map(|i| (x[i + 1] - x[i]) / (t[i + 1] - t[i]))
                    .collect::<Vec<_>>(),
            );
            if v.is_nan() || v <= 0.0 {
                return Err(fail(format!("displacement does not increase while sliding (median speed {v:.3e} m/s)")));
            }
            v
        }
        None => options.speed,
    };

    let mut analysis = Analysis { cycles: Vec::new(), groups: Vec::new(), skipped: Vec::new() };
    let mut holds = 0;
    // The first run, hold or slide, is the trace's start: a hold needs a slide before it.
    for k in 1..runs.len() {
        if runs[k].state != State::Hold {
            continue;
        }
        holds += 1;
        match runs.get(k + 1) {
            None => analysis
                .skipped
                .push(format!("hold from {:.2} s: the trace ends before sliding restarts", t[runs[k].start])),
            Some(slide) => match measure(trace, &smooth, runs[k], *slide, slide_above, sliding, slide_speed, options) {
                Ok(cycle) => analysis.cycles.push(cycle),
                Err(reason) => analysis.skipped.push(reason),
            },
        }
    }
    if analysis.cycles.is_empty() {
        return Err(fail(if holds == 0 {
            format!(
                "no hold found: friction never stays below {hold_below:.3e} N ({} × the sliding level \
                 {sliding:.3e} N) for {} s after sliding",
                options.hold_fraction, options.min_duration
            )
        } else {
            format!("no complete restart after {holds} hold(s): {}", analysis.skipped.join("; "))
        }));
    }
    analysis.groups = super::group_by_hold(&analysis.cycles, options.group_tolerance);
    Ok(analysis)
}

/// Measure the restart after `hold`, sliding on through `slide`; `Err` says why it cannot be.
#[allow(clippy::too_many_arguments)]
fn measure(
    trace: &Trace,
    smooth: &[f64],
    hold: Run,
    slide: Run,
    slide_above: f64,
    sliding: f64,
    slide_speed: f64,
    options: &ShsOptions,
) -> std::result::Result<Cycle, String> {
    let (t, f, normal) = (trace.time(), trace.friction(), trace.normal());
    let core = &f[hold.start..=hold.end];
    let level = median(&mut core.to_vec());
    let band = level + (4.0 * mad_sigma(core)).max(0.02 * sliding);
    let first = (hold.start.saturating_sub(SMOOTH_HALF)..=hold.end).find(|&i| f[i] <= band);
    let last = (hold.start..=(hold.end + SMOOTH_HALF).min(slide.end)).rev().find(|&i| f[i] <= band);
    let (Some(hold_start), Some(restart)) = (first, last) else {
        return Err(format!("hold from {:.2} s: friction never settles at its hold level", t[hold.start]));
    };
    // The hold began within the sample interval before its first sample and ended within the
    // one after its last: count half of each.
    let hold_s = t[restart] - t[hold_start]
        + 0.5 * (t[hold_start] - t[hold_start.saturating_sub(1)])
        + 0.5 * (t[(restart + 1).min(t.len() - 1)] - t[restart]);

    let displacement = |i: usize| match trace.displacement() {
        Some(x) => x[i] - x[restart],
        None => options.speed * (t[i] - t[restart]),
    };
    if let Some(x) = trace.displacement() {
        let edge = 5.min(restart - hold_start + 1);
        let x0 = median(&mut x[hold_start..hold_start + edge].to_vec());
        let x1 = median(&mut x[restart + 1 - edge..=restart].to_vec());
        let creep = (x1 - x0) / hold_s;
        if creep > HOLD_CREEP * slide_speed {
            return Err(format!(
                "{:.2}–{:.2} s: friction near zero but displacement kept progressing ({:.3e} m/s while sliding \
                 at {slide_speed:.3e} m/s): not a hold",
                t[hold_start], t[restart], creep
            ));
        }
    }

    // Sliding stops where the smoothed friction last stands at the sliding level.
    let stroke_end = (slide.start..=slide.end).rev().find(|&i| smooth[i] >= slide_above).unwrap_or(slide.end);
    let peak = (restart + 1..=stroke_end)
        .take_while(|&i| displacement(i) <= options.peak_within)
        .max_by(|&a, &b| f[a].total_cmp(&f[b]))
        .ok_or_else(|| format!("restart at {:.2} s: no sliding follows the hold", t[restart]))?;
    // The window starts at the peak located between samples (at 20 Hz a sample is 1.5 % of a
    // 1 µm window, and the samples next to the peak are nearly as high as it).
    let start = peak_position(&displacement, f, peak, restart + 1, stroke_end);
    let window_end = (peak + 1..=stroke_end).find(|&i| displacement(i) - start >= options.window * (1.0 - 1e-9));
    let Some(window_end) = window_end else {
        let reach = (peak + 1..=stroke_end).map(|i| displacement(i) - start).fold(0.0, f64::max);
        return Err(format!(
            "restart at {:.2} s: sliding stops {:.3e} m after the peak, before the {:.3e} m window ends",
            t[restart], reach, options.window
        ));
    };
    let first = peak.saturating_sub(1).max(restart);
    let mean = |v: &[f64]| window_mean(&displacement, v, first..=window_end, start, start + options.window);
    let (static_force, dynamic_force, normal_force) = (f[peak], mean(f), mean(normal));
    if !(normal_force > 0.0 && dynamic_force > 0.0) {
        return Err(format!(
            "restart at {:.2} s: mean normal force {normal_force:.3e} N and dynamic friction {dynamic_force:.3e} N \
             must be positive",
            t[restart]
        ));
    }
    Ok(Cycle {
        hold_s,
        static_force_n: static_force,
        dynamic_force_n: dynamic_force,
        normal_force_n: normal_force,
        static_coefficient: static_force / normal_force,
        dynamic_coefficient: dynamic_force / normal_force,
        friction_drop: static_force / dynamic_force,
        hold_start_s: t[hold_start],
        restart_s: t[restart],
        peak_s: t[peak],
        window_end_s: t[window_end],
    })
}

/// Displacement of the peak between samples: the vertex of the parabola through the peak
/// sample `p` and its neighbours (within `lo..=hi`), kept within half a sample of `p`.
fn peak_position(x: &impl Fn(usize) -> f64, f: &[f64], p: usize, lo: usize, hi: usize) -> f64 {
    if p <= lo || p >= hi {
        return x(p);
    }
    let (left, right) = (x(p) - x(p - 1), x(p + 1) - x(p));
    let curvature = f[p - 1] - 2.0 * f[p] + f[p + 1];
    if !(curvature < 0.0 && left > 0.0 && right > 0.0) {
        return x(p);
    }
    let offset = 0.25 * (left + right) * (f[p - 1] - f[p + 1]) / curvature;
    x(p) + offset.clamp(-0.5 * left, 0.5 * right)
}

/// Mean of `v` over displacement from `x0` to `x1`, linearly interpolated between the samples
/// `samples` (whose displacements increase; a segment that does not advance adds nothing).
fn window_mean(
    x: &impl Fn(usize) -> f64,
    v: &[f64],
    samples: std::ops::RangeInclusive<usize>,
    x0: f64,
    x1: f64,
) -> f64 {
    let (mut integral, mut length) = (0.0, 0.0);
    for i in *samples.start()..*samples.end() {
        let (xa, xb) = (x(i), x(i + 1));
        let (lo, hi) = (xa.max(x0), xb.min(x1));
        if hi > lo {
            let at = |u: f64| v[i] + (v[i + 1] - v[i]) * (u - xa) / (xb - xa);
            integral += 0.5 * (at(lo) + at(hi)) * (hi - lo);
            length += hi - lo;
        }
    }
    integral / length
}

/// Hold/slide state of each sample with hysteresis: below `hold_below` is a hold, above
/// `slide_above` a slide, in between the state carries on (the first decided state extends
/// back to the start).
fn classify(smooth: &[f64], hold_below: f64, slide_above: f64) -> Vec<Run> {
    let decide = |v: f64| {
        if v < hold_below {
            Some(State::Hold)
        } else if v >= slide_above {
            Some(State::Slide)
        } else {
            None
        }
    };
    let mut state = smooth.iter().find_map(|&v| decide(v)).unwrap_or(State::Slide);
    let mut runs = vec![Run { state, start: 0, end: 0 }];
    for (i, &v) in smooth.iter().enumerate().skip(1) {
        state = decide(v).unwrap_or(state);
        let last = runs.last_mut().expect("runs start non-empty");
        if state == last.state {
            last.end = i;
        } else {
            runs.push(Run { state, start: i, end: i });
        }
    }
    runs
}

/// Merge runs shorter than `min_duration` [s] into their neighbours, shortest first, so that a
/// brief dip never makes a hold and a brief burst never makes a restart.
fn merge_short_runs(mut runs: Vec<Run>, t: &[f64], min_duration: f64) -> Vec<Run> {
    let n = t.len();
    // A run lasts until the next run's first sample; the last one, one interval past its end.
    let next = |i: usize| if i + 1 < n { t[i + 1] } else { 2.0 * t[n - 1] - t[n - 2] };
    let duration = |r: &Run| next(r.end) - t[r.start];
    while runs.len() > 1 {
        let Some((k, _)) = runs
            .iter()
            .enumerate()
            .filter(|(_, r)| duration(r) < min_duration)
            .min_by(|a, b| duration(a.1).total_cmp(&duration(b.1)))
        else {
            break;
        };
        let (lo, hi) = (k.saturating_sub(1), (k + 1).min(runs.len() - 1));
        // The short run takes its neighbours' state and joins them.
        let state = if k == 0 { runs[1].state } else { runs[k - 1].state };
        let merged = Run { state, start: runs[lo].start, end: runs[hi].end };
        runs.splice(lo..=hi, [merged]);
    }
    runs
}

/// Running median over `2·half + 1` samples (fewer at the ends).
fn running_median(x: &[f64], half: usize) -> Vec<f64> {
    let mut window = Vec::with_capacity(2 * half + 1);
    (0..x.len())
        .map(|i| {
            window.clear();
            window.extend_from_slice(&x[i.saturating_sub(half)..(i + half + 1).min(x.len())]);
            median(&mut window)
        })
        .collect()
}

/// The threshold that splits `values` into two classes whose means it lies midway between
/// (Ridler & Calvard's iterative selection).
fn two_class_threshold(values: &[f64]) -> f64 {
    let (lo, hi) = values.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let mut threshold = 0.5 * (lo + hi);
    for _ in 0..100 {
        let (mut s0, mut n0, mut s1, mut n1) = (0.0, 0usize, 0.0, 0usize);
        for &v in values {
            if v < threshold {
                (s0, n0) = (s0 + v, n0 + 1);
            } else {
                (s1, n1) = (s1 + v, n1 + 1);
            }
        }
        if n0 == 0 || n1 == 0 {
            break;
        }
        let next = 0.5 * (s0 / n0 as f64 + s1 / n1 as f64);
        if (next - threshold).abs() <= 1e-12 * (hi - lo) {
            break;
        }
        threshold = next;
    }
    threshold
}

/// Median of `v` (reordered in place); NaN for an empty slice.
pub(super) fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mid = v.len() / 2;
    let (_, &mut upper, _) = v.select_nth_unstable_by(mid, f64::total_cmp);
    if v.len() % 2 == 1 {
        upper
    } else {
        let lower = v[..mid].iter().copied().fold(f64::NEG_INFINITY, f64::max);
        0.5 * (lower + upper)
    }
}

/// Robust standard deviation: the median absolute deviation scaled to a normal distribution.
fn mad_sigma(v: &[f64]) -> f64 {
    let m = median(&mut v.to_vec());
    MAD_TO_SIGMA * median(&mut v.iter().map(|x| (x - m).abs()).collect::<Vec<_>>())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn runs_of(states: &[(State, usize, usize)]) -> Vec<Run> {
        states.iter().map(|&(state, start, end)| Run { state, start, end }).collect()
    }

    #[test]
    fn short_runs_merge_into_their_neighbours() {
        use State::*;
        let t: Vec<f64> = (0..100).map(|i| i as f64 * 0.1).collect();
        // A 0.2 s dip inside a slide and a 0.3 s burst inside a hold, with a 1 s minimum.
        let runs = runs_of(&[
            (Slide, 0, 19),
            (Hold, 20, 21),
            (Slide, 22, 39),
            (Hold, 40, 69),
            (Slide, 70, 72),
            (Hold, 73, 84),
            (Slide, 85, 99),
        ]);
        let merged = merge_short_runs(runs, &t, 1.0);
        let got: Vec<_> = merged.iter().map(|r| (r.state, r.start, r.end)).collect();
        assert_eq!(got, vec![(Slide, 0, 39), (Hold, 40, 84), (Slide, 85, 99)]);
    }

    #[test]
    fn hysteresis_keeps_the_state_between_thresholds() {
        let s = [1.0, 0.4, 0.1, 0.3, 0.45, 0.6, 0.15, 0.3];
        let got: Vec<_> = classify(&s, 0.2, 0.5).iter().map(|r| (r.state, r.start, r.end)).collect();
        assert_eq!(got, vec![(State::Slide, 0, 1), (State::Hold, 2, 4), (State::Slide, 5, 5), (State::Hold, 6, 7)]);
    }

    #[test]
    fn robust_statistics() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(running_median(&[0.0, 9.0, 0.0, 0.0, 5.0, 5.0, 5.0], 1), vec![4.5, 0.0, 0.0, 0.0, 5.0, 5.0, 5.0]);
        let t = two_class_threshold(&[0.0, 0.1, -0.1, 0.05, 1.0, 1.1, 0.9]);
        assert!((t - 0.5).abs() < 0.05, "{t}");
        assert!((mad_sigma(&[1.0, 2.0, 3.0, 4.0, 100.0]) - 1.4826).abs() < 1e-12);
    }
}
