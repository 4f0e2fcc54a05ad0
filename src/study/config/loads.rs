//! `[loads]`: the normal loads \[N], listed or log-spaced, and their checks.
//!
//! Of the study file it may import only `defaults`, `quantities` and `places`; it must not
//! import `config/mod.rs`, which ties the sections, nor the study's runner, `plot`, `report`,
//! `cli` or `python`.

use serde::{Deserialize, Serialize};

use super::places::{at, key, Checked, Segment};
use super::quantities::Force;

/// The most loads a study takes: each is a contact solve of every topography.
pub const MAX_LOADS: usize = 1000;

/// The normal loads: a list, or `count` log-spaced from `min` to `max`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(expecting = "the [loads] table")]
pub struct LoadsSpec {
    /// The loads \[N], listed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub values: Option<Vec<Force>>,
    /// The smallest load \[N] of a log-spaced range.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<Force>,
    /// The largest load \[N] of a log-spaced range.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<Force>,
    /// The number of loads of a log-spaced range.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<usize>,
}

/// `count` loads from `min` to `max` \[N], evenly spaced in log scale, rounded to 12
/// significant digits so that decades come out exact (1e-3, not 9.999999999999998e-4).
pub fn log_spaced(min: f64, max: f64, count: usize) -> Vec<f64> {
    if count == 1 {
        return vec![min];
    }
    let (a, b) = (min.log10(), max.log10());
    (0..count)
        .map(|i| {
            let v = 10f64.powf(a + (b - a) * i as f64 / (count - 1) as f64);
            format!("{v:.11e}").parse().expect("a formatted float parses")
        })
        .collect()
}

impl LoadsSpec {
    /// A list of distinct positive loads, or a log-spaced range, within [`MAX_LOADS`].
    pub(super) fn check(&self) -> Checked {
        let loads = key("loads");
        match (&self.values, self.min, self.max, self.count) {
            (Some(values), None, None, None) => {
                if values.is_empty() {
                    return at(&[loads, key("values")], "the load list is empty".into());
                }
                if values.len() > MAX_LOADS {
                    return at(
                        &[loads, key("values")],
                        format!("{} loads: a study takes at most {MAX_LOADS} (each is a contact solve)", values.len()),
                    );
                }
                for (i, v) in values.iter().enumerate() {
                    if v.0.is_nan() || v.0 <= 0.0 {
                        return at(&[loads, key("values"), Segment::Index(i)], format!("{} N is not positive", v.0));
                    }
                    if values[..i].contains(v) {
                        return at(&[loads, key("values"), Segment::Index(i)], format!("{} N is listed twice", v.0));
                    }
                }
            }
            (None, Some(min), Some(max), Some(count)) => {
                for (name, v) in [("min", min), ("max", max)] {
                    if v.0.is_nan() || v.0 <= 0.0 {
                        return at(&[loads, key(name)], format!("{} N is not positive", v.0));
                    }
                }
                if count == 0 || (count == 1 && min != max) {
                    return at(&[loads, key("count")], format!("{count} loads cannot span {} to {} N", min.0, max.0));
                }
                if count > MAX_LOADS {
                    return at(
                        &[loads, key("count")],
                        format!("{count} loads: a study takes at most {MAX_LOADS} (each is a contact solve)"),
                    );
                }
                if count > 1 && min.0 >= max.0 {
                    return at(&[loads, key("min")], format!("{} N is not below max {} N", min.0, max.0));
                }
            }
            _ => return at(&[loads], "give either `values`, or `min`, `max` and `count`".into()),
        }
        Ok(())
    }
}
