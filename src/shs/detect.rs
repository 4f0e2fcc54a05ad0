//! Finding holds and restarts in a trace, and measuring each restart.
//!
//! A hold is a stretch of at least `min_duration` during which the interface does not slide,
//! after a slide. When the trace records displacement, holds are found on it — the stage stopped
//! — whatever the friction does (released to zero, or held loaded and relaxing); without it,
//! on the friction signal, which then must fall near zero during each hold.
//!
//! 1. Both signals are split the same way. On a 5-sample running median of the signal (the
//!    stage's speed between samples, or the friction), the sliding level is the median of the
//!    upper class of a two-class (Ridler–Calvard) split of its values, and the noise is
//!    estimated from sample-to-sample differences of the raw signal (robust to the level changes
//!    between holds and slides). With hysteresis, a hold begins when the signal falls below a
//!    fraction of the sliding level and ends when it rises above another: for the stage,
//!    `STAGE_STOPPED` (0.1) and `STAGE_MOVING` (0.5) × the sliding speed; for the friction,
//!    `hold_fraction` and `slide_fraction`. Holds or slides shorter than `min_duration` are
//!    merged into their neighbours, shortest first; each hold so dropped is reported.
//! 2. Each hold's edges are then placed on the raw signal. From the stage: the hold lasts from
//!    the instant the stage stopped to the instant it moved again, each located between samples
//!    by the sliding speed (the line through the last moving sample at that speed meets the rest
//!    position). From the friction: from the first sample at which friction has settled at the
//!    hold level (within 4 robust standard deviations of its median over the hold, or 2 % of the
//!    sliding level) to the last sample at that level before the restart's rise, plus half a
//!    sample interval at each end — the time spent at zero shear, which is shorter than the
//!    stage's hold by the time the friction takes to relax.
//! 3. After the restart, F_S is the largest friction sample within `peak_within` of sliding
//!    displacement. F_D and N are their means over `window` of displacement from the peak,
//!    located between samples by a parabola through the peak sample and its neighbours, with
//!    the signals interpolated linearly between samples; the window must end before sliding
//!    stops.
//! 4. A coefficient F_S/N or F_D/N that is not finite, or above `MAX_COEFFICIENT`, is no
//!    friction coefficient (a unit or column mistake): the trace is refused, naming the row.
//!
//! Must not import topography, contact, friction, study, plot or report: a trace is its own input.

use super::analysis::{group_by_hold, Analysis, Cycle, ShsOptions, Skipped};
use super::trace::Trace;
use crate::error::{Error, Result};

/// Half-width [samples] of the running median the hold/slide decision is made on.
const SMOOTH_HALF: usize = 2;
/// Standard deviation of a normal distribution per median absolute deviation.
const MAD_TO_SIGMA: f64 = 1.4826;
/// The stage is stopped below this fraction of its sliding speed …
const STAGE_STOPPED: f64 = 0.1;
/// … and moving again above this one.
const STAGE_MOVING: f64 = 0.5;
/// The largest friction coefficient a trace may yield (the one bound of every coefficient):
/// beyond it a force column is in the wrong unit or the wrong column.
const MAX_COEFFICIENT: f64 = crate::plausible::MAX_FRICTION_COEFFICIENT;

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

/// Where a hold lies and where the slide after it goes.
struct Hold {
    /// When the hold began and ended [s].
    start_s: f64,
    end_s: f64,
    /// The last sample at rest before the restart.
    restart: usize,
    /// The last sample of the slide after it.
    stroke_end: usize,
    /// Displacement [m] at rest before the restart, from which `peak_within` and the window are
    /// measured (with a displacement column; without, displacement is counted in time from
    /// `restart` at the sliding speed).
    origin: f64,
}

/// A signal split into holds and slides.
struct Split {
    runs: Vec<Run>,
    /// The running median the split was made on.
    smooth: Vec<f64>,
    /// Its sliding level (a speed [m/s] or a force [N]).
    sliding: f64,
    /// Signal level above which it slides.
    slide_above: f64,
}

pub(super) fn analyse(trace: &Trace, options: &ShsOptions) -> Result<Analysis> {
    options.validate()?;
    let t = trace.time();
    let fail = |reason: String| Error::file(trace.source(), reason);
    let stage = trace.displacement().map(|x| stage_speed(t, x));
    let (signal, stopped, moving) = match &stage {
        Some(speed) => (&speed[..], STAGE_STOPPED, STAGE_MOVING),
        None => (trace.friction(), options.hold_fraction, options.slide_fraction),
    };
    let (split, dropped) = split(signal, t, stopped, moving, options.min_duration).map_err(|(level, noise)| {
        fail(match stage {
            Some(_) => format!(
                "displacement never advances clearly above its noise (sliding speed {level:.3e} m/s, noise \
                 {noise:.3e} m/s)"
            ),
            None => {
                format!(
                    "friction never rises clearly above its noise (sliding level {level:.3e} N, noise {noise:.3e} N)"
                )
            }
        })
    })?;

    let mut analysis = Analysis {
        holds_from: if stage.is_some() { "displacement" } else { "friction" },
        holds_found: dropped.len(),
        cycles: Vec::new(),
        groups: Vec::new(),
        skipped: Vec::new(),
    };
    // In time order: the holds too short to count, then each hold that gave no restart.
    let mut skipped: Vec<Skipped> = dropped
        .iter()
        .map(|&(start_s, length)| Skipped {
            start_s,
            end_s: start_s + length,
            reason: format!(
                "hold from {start_s:.2} s: {length:.2} s at rest, shorter than the minimum duration {} s",
                options.min_duration
            ),
        })
        .collect();
    let runs = &split.runs;
    let last = t.len() - 1;
    // The first run, hold or slide, is the trace's start: a hold needs a slide before it.
    for k in 1..runs.len() {
        if runs[k].state != State::Hold {
            continue;
        }
        analysis.holds_found += 1;
        let start_s = t[runs[k].start];
        // The hold lasts until the next run's first sample.
        let end_s = t[(runs[k].end + 1).min(last)];
        let Some(&slide) = runs.get(k + 1) else {
            let reason = format!("hold from {start_s:.2} s: the trace ends before sliding restarts");
            skipped.push(Skipped { start_s, end_s, reason });
            continue;
        };
        let hold = match trace.displacement() {
            Some(x) => Ok(stage_hold(t, x, runs[k - 1], runs[k], slide, split.sliding)),
            None => friction_hold(trace, &split, runs[k], slide),
        };
        match hold.and_then(|hold| measure(trace, &hold, options)) {
            Ok(cycle) => analysis.cycles.push(cycle),
            Err(reason) => skipped.push(Skipped { start_s, end_s, reason }),
        }
    }
    skipped.sort_by(|a, b| a.start_s.total_cmp(&b.start_s));
    analysis.skipped = skipped;
    if analysis.cycles.is_empty() {
        return Err(fail(if analysis.holds_found == 0 {
            match stage {
                Some(_) => format!(
                    "no hold found: the stage (displacement) never stays below {STAGE_STOPPED} × its sliding speed \
                     {:.3e} m/s for {} s after sliding",
                    split.sliding, options.min_duration
                ),
                None => format!(
                    "no hold found: friction never stays below {:.3e} N ({} × the sliding level {:.3e} N) for {} s \
                     after sliding; if the force stays loaded during holds, give the stage's displacement column \
                     (displacement_m, or --displacement-column)",
                    options.hold_fraction * split.sliding,
                    options.hold_fraction,
                    split.sliding,
                    options.min_duration
                ),
            }
        } else {
            let reasons: Vec<&str> = analysis.skipped.iter().map(|s| s.reason.as_str()).collect();
            format!("no complete restart after {} hold(s): {}", analysis.holds_found, reasons.join("; "))
        }));
    }
    for c in &analysis.cycles {
        check_coefficients(trace, c)?;
    }
    analysis.groups = group_by_hold(&analysis.cycles, options.group_tolerance);
    Ok(analysis)
}

/// The stage's speed [m/s] at each sample, over the `SMOOTH_HALF` intervals on each side (fewer
/// at the ends): an encoder's noise matters less over several intervals than over one.
fn stage_speed(t: &[f64], x: &[f64]) -> Vec<f64> {
    let n = t.len();
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(SMOOTH_HALF), (i + SMOOTH_HALF).min(n - 1));
            (x[b] - x[a]) / (t[b] - t[a])
        })
        .collect()
}

/// Split `signal` into holds (below `stopped` × its sliding level) and slides (above `moving` ×
/// it), with runs shorter than `min_duration` merged away; also the holds so dropped (start
/// [s], duration [s]). `Err((sliding level, noise))` when the signal never rises clearly above
/// its noise.
#[allow(clippy::type_complexity)]
fn split(
    signal: &[f64],
    t: &[f64],
    stopped: f64,
    moving: f64,
    min_duration: f64,
) -> std::result::Result<(Split, Vec<(f64, f64)>), (f64, f64)> {
    let smooth = running_median(signal, SMOOTH_HALF);
    let threshold = two_class_threshold(&smooth);
    let sliding = median(&mut smooth.iter().copied().filter(|&v| v >= threshold).collect::<Vec<_>>());
    let diffs: Vec<f64> = signal.windows(2).map(|w| w[1] - w[0]).collect();
    let noise = mad_sigma(&diffs) / std::f64::consts::SQRT_2;
    if sliding.is_nan() || sliding <= 10.0 * noise {
        return Err((sliding, noise));
    }
    let slide_above = moving * sliding;
    let (runs, dropped) = merge_short_runs(classify(&smooth, stopped * sliding, slide_above), t, min_duration);
    Ok((Split { runs, smooth, sliding, slide_above }, dropped))
}

/// The hold `hold` between the slides `before` and `after`, from the stage's displacement `x`
/// moving at `speed` [m/s] while it slides. The hysteresis places the run `hold` inside the
/// stage's rest; its edges are found on the raw displacement around it.
fn stage_hold(t: &[f64], x: &[f64], before: Run, hold: Run, after: Run, speed: f64) -> Hold {
    // The rest positions at the two ends of the hold (a stage may settle, or creep slowly).
    let edge = 5.min(hold.end - hold.start + 1);
    let rest_start = median(&mut x[hold.start..hold.start + edge].to_vec());
    let rest_end = median(&mut x[hold.end + 1 - edge..=hold.end].to_vec());
    // A sample more than a quarter of a sample's sliding advance from the rest position moves.
    let step = median(&mut t.windows(2).map(|w| w[1] - w[0]).collect::<Vec<_>>());
    let tolerance = 0.25 * speed * step;
    let last_moving = (before.start..hold.start).rev().find(|&i| x[i] < rest_start - tolerance);
    let first_moving = (hold.end + 1..=after.end).find(|&i| x[i] > rest_end + tolerance);
    // The stage moved at `speed` up to the instant it stopped, and from the instant it restarted.
    let start_s = last_moving.map_or(t[hold.start], |p| (t[p] + (rest_start - x[p]) / speed).min(t[hold.start]));
    let end_s = first_moving.map_or(t[hold.end], |q| (t[q] - (x[q] - rest_end) / speed).max(t[hold.end]));
    let restart = first_moving.map_or(hold.end, |q| q - 1);
    Hold { start_s, end_s, restart, stroke_end: after.end, origin: rest_end }
}

/// The hold `hold` before the slide `slide`, from the friction signal alone; `Err` says why it
/// cannot be placed.
fn friction_hold(trace: &Trace, split: &Split, hold: Run, slide: Run) -> std::result::Result<Hold, String> {
    let (t, f) = (trace.time(), trace.friction());
    let core = &f[hold.start..=hold.end];
    let level = median(&mut core.to_vec());
    let band = level + (4.0 * mad_sigma(core)).max(0.02 * split.sliding);
    let first = (hold.start.saturating_sub(SMOOTH_HALF)..=hold.end).find(|&i| f[i] <= band);
    let last = (hold.start..=(hold.end + SMOOTH_HALF).min(slide.end)).rev().find(|&i| f[i] <= band);
    let (Some(first), Some(restart)) = (first, last) else {
        return Err(format!("hold from {:.2} s: friction never settles at its hold level", t[hold.start]));
    };
    // The hold began within the sample interval before its first sample and ended within the
    // one after its last: count half of each.
    let start_s = t[first] - 0.5 * (t[first] - t[first.saturating_sub(1)]);
    let end_s = t[restart] + 0.5 * (t[(restart + 1).min(t.len() - 1)] - t[restart]);
    // Sliding stops where the smoothed friction last stands at the sliding level.
    let stroke_end =
        (slide.start..=slide.end).rev().find(|&i| split.smooth[i] >= split.slide_above).unwrap_or(slide.end);
    Ok(Hold { start_s, end_s, restart, stroke_end, origin: 0.0 })
}

/// Measure the restart after `hold`; `Err` says why it cannot be.
fn measure(trace: &Trace, hold: &Hold, options: &ShsOptions) -> std::result::Result<Cycle, String> {
    let (t, f, normal) = (trace.time(), trace.friction(), trace.normal());
    let (restart, stroke_end) = (hold.restart, hold.stroke_end);
    let displacement = |i: usize| match trace.displacement() {
        Some(x) => x[i] - hold.origin,
        None => options.speed * (t[i] - t[restart]),
    };
    let peak = (restart + 1..=stroke_end)
        .take_while(|&i| displacement(i) <= options.peak_within)
        .max_by(|&a, &b| f[a].total_cmp(&f[b]))
        .ok_or_else(|| format!("restart at {:.2} s: no sliding follows the hold", hold.end_s))?;
    // The window starts at the peak located between samples (at 20 Hz a sample is 1.5 % of a
    // 1 µm window, and the samples next to the peak are nearly as high as it).
    let start = peak_position(&displacement, f, peak, restart + 1, stroke_end);
    let (from, to) = (start + options.window_start, start + options.window_start + options.window);
    let window_end = (peak + 1..=stroke_end).find(|&i| displacement(i) - to >= -options.window * 1e-9);
    let Some(window_end) = window_end else {
        let reach = (peak + 1..=stroke_end).map(|i| displacement(i) - start).fold(0.0, f64::max);
        return Err(format!(
            "restart at {:.2} s: sliding stops {:.3e} m after the peak, before the {:.3e} m window ends",
            hold.end_s,
            reach,
            options.window_start + options.window
        ));
    };
    let first = peak.saturating_sub(1).max(restart);
    // The window's first sample: the peak's when it starts there.
    let window_start = if options.window_start == 0.0 {
        peak
    } else {
        (peak..=window_end).find(|&i| displacement(i) >= from).unwrap_or(window_end)
    };
    let mean = |v: &[f64]| window_mean(&displacement, v, first..=window_end, from, to);
    let (static_force, dynamic_force, normal_force) = (f[peak], mean(f), mean(normal));
    if !(normal_force > 0.0 && dynamic_force > 0.0) {
        return Err(format!(
            "restart at {:.2} s: mean normal force {normal_force:.3e} N and dynamic friction {dynamic_force:.3e} N \
             must be positive",
            hold.end_s
        ));
    }
    Ok(Cycle {
        hold_s: hold.end_s - hold.start_s,
        static_force_n: static_force,
        dynamic_force_n: dynamic_force,
        normal_force_n: normal_force,
        static_coefficient: static_force / normal_force,
        dynamic_coefficient: dynamic_force / normal_force,
        friction_drop: static_force / dynamic_force,
        hold_start_s: hold.start_s,
        restart_s: hold.end_s,
        peak_s: t[peak],
        window_start_s: t[window_start],
        window_end_s: t[window_end],
    })
}

/// Refuse a restart whose coefficients are no friction coefficients, naming the data row (the
/// first row after the header is row 1) of its peak or window.
fn check_coefficients(trace: &Trace, c: &Cycle) -> Result<()> {
    let t = trace.time();
    let row = |time: f64| t.partition_point(|&x| x < time) + 1;
    let checks = [
        ("mu_s = F_S/N", c.static_coefficient, "F_S", c.static_force_n, format!("row {}", row(c.peak_s))),
        (
            "mu_d = F_D/N",
            c.dynamic_coefficient,
            "F_D",
            c.dynamic_force_n,
            format!("rows {}–{}", row(c.window_start_s), row(c.window_end_s)),
        ),
    ];
    for (what, mu, force, value, rows) in checks {
        if !(mu.is_finite() && mu <= MAX_COEFFICIENT) {
            return Err(Error::file(
                trace.source(),
                format!(
                    "{rows} (restart at {:.2} s): {what} = {mu:.3e} ({force} {value:.3e} N, N {:.3e} N) is not a \
                     friction coefficient (at most {MAX_COEFFICIENT}): check the force columns and their units",
                    c.restart_s, c.normal_force_n
                ),
            ));
        }
    }
    Ok(())
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
/// brief dip never makes a hold and a brief burst never makes a restart; also the holds after a
/// slide so dropped (start [s], duration [s]), in time order.
fn merge_short_runs(mut runs: Vec<Run>, t: &[f64], min_duration: f64) -> (Vec<Run>, Vec<(f64, f64)>) {
    let n = t.len();
    // A run lasts until the next run's first sample; the last one, one interval past its end.
    let next = |i: usize| if i + 1 < n { t[i + 1] } else { 2.0 * t[n - 1] - t[n - 2] };
    let duration = |r: &Run| next(r.end) - t[r.start];
    let mut dropped = Vec::new();
    while runs.len() > 1 {
        let Some((k, _)) = runs
            .iter()
            .enumerate()
            .filter(|(_, r)| duration(r) < min_duration)
            .min_by(|a, b| duration(a.1).total_cmp(&duration(b.1)))
        else {
            break;
        };
        if k > 0 && runs[k].state == State::Hold {
            dropped.push((t[runs[k].start], duration(&runs[k])));
        }
        let (lo, hi) = (k.saturating_sub(1), (k + 1).min(runs.len() - 1));
        // The short run takes its neighbours' state and joins them.
        let state = if k == 0 { runs[1].state } else { runs[k - 1].state };
        let merged = Run { state, start: runs[lo].start, end: runs[hi].end };
        runs.splice(lo..=hi, [merged]);
    }
    dropped.sort_by(|a, b| a.0.total_cmp(&b.0));
    (runs, dropped)
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
        let (merged, dropped) = merge_short_runs(runs, &t, 1.0);
        // The 0.2 s dip was a hold after a slide, dropped; the burst was no hold.
        assert_eq!(dropped.len(), 1);
        assert!((dropped[0].0 - 2.0).abs() < 1e-12 && (dropped[0].1 - 0.2).abs() < 1e-12, "{dropped:?}");
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
