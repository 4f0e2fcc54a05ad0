//! `[[topography]]`: the surfaces of the study, each generated (`synthetic`) or read from a
//! `file` and prepared (crop, filling, levelling, resampling, a cap), with an optional
//! `wafer` as counter-surface; their keys, how they are read, and their checks.
//!
//! Of the study file it may import only `defaults`, `quantities` and `places`; it must not
//! import `config/mod.rs`, which ties the sections, nor the study's runner, `plot`, `report`,
//! `cli` or `python`.

use std::fmt;
use std::path::PathBuf;

use serde::de::{self, Deserializer, Visitor};
use serde::{Deserialize, Serialize};

use super::places::{at, key, Checked, Segment};
use super::quantities::{Length, Size};
use crate::error::Error;
use crate::limits::Limits;
use crate::plausible::{self, Spelling};
use crate::quantity::{self, LENGTH};
use crate::topography::detrend::Detrend;
use crate::topography::prepare::Preparation;
use crate::topography::resample::CropWindow;
use crate::topography::synth::{Amplitude, Cap, SyntheticSurface};

/// A surface: a topography of the study (with its `name`) or its wafer (without).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(expecting = "a [[topography]] table")]
pub struct SurfaceSpec {
    /// The topography's unique label in rows and folder names (required for a topography,
    /// absent for a wafer).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// A generated surface; lengths in keys ending in `_m` may carry units.
    #[serde(default, skip_serializing_if = "Option::is_none", deserialize_with = "synthetic")]
    pub synthetic: Option<SyntheticSurface>,
    /// A measured surface: the file to read.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    /// File format, overriding detection.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub format: Option<String>,
    /// Channel by name or 0-based index.
    #[serde(default, skip_serializing_if = "Option::is_none", deserialize_with = "channel")]
    pub channel: Option<String>,
    /// Physical size (lx, ly) \[m].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<Size>,
    /// Height unit of a file that states none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_unit: Option<String>,
    /// Window to keep.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crop: Option<CropSpec>,
    /// Fill missing points harmonically rather than refuse them.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub fill_missing: bool,
    /// Levelling: `none`, `mean`, `plane`, `poly:N` or `sphere`, or line by line `line:N` or
    /// `line:median`, optionally then the whole map (`line:1,plane`) (files: default `plane`).
    #[serde(default, skip_serializing_if = "Option::is_none", deserialize_with = "detrend")]
    pub detrend: Option<String>,
    /// Pixel size to resample to \[m].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pixel_size: Option<Length>,
    /// A spherical cap added to a measured scan after levelling (`cap = { radius_m = "1.5 mm" }`),
    /// for a ball scanned with its curvature levelled away. A synthetic surface has its own.
    #[serde(default, skip_serializing_if = "Option::is_none", deserialize_with = "cap")]
    pub cap: Option<Cap>,
    /// The counter-surface, compounded as h = h_ball − h_wafer.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wafer: Option<Box<SurfaceSpec>>,
}

/// A physical window (`x`, `y` \[m]) or a pixel window (`columns`, `rows`, end excluded).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(expecting = "a crop table: { x, y } or { columns, rows }")]
pub struct CropSpec {
    /// Physical range [x0, x1) \[m].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x: Option<[Length; 2]>,
    /// Physical range [y0, y1) \[m].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y: Option<[Length; 2]>,
    /// Column range, 0-based, end excluded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub columns: Option<[usize; 2]>,
    /// Row range, 0-based, end excluded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rows: Option<[usize; 2]>,
}

impl SurfaceSpec {
    fn check(&self, here: &[Segment]) -> std::result::Result<(), (Vec<Segment>, String)> {
        let at = |k: &str, reason: String| {
            let mut path = here.to_vec();
            path.push(key(k));
            Err((path, reason))
        };
        match (&self.synthetic, &self.file) {
            (Some(s), None) => {
                let (lx, ly) = s.size;
                for l in [lx, ly] {
                    plausible::window(l, Spelling::StudyFile)
                        .map(drop)
                        .or_else(|r| at("synthetic", format!("size_m: {r}")))?;
                }
                if let Some(cap) = &s.cap {
                    plausible::radius(cap.radius, Spelling::StudyFile)
                        .map(drop)
                        .or_else(|r| at("synthetic", format!("cap.radius_m: {r}")))?;
                }
                if let Some(Amplitude::RmsHeight(h)) = s.roughness.as_ref().map(|r| r.amplitude) {
                    plausible::roughness(h, Spelling::StudyFile)
                        .map(drop)
                        .or_else(|r| at("synthetic", format!("roughness.rms_height_m: {r}")))?;
                }
                let file_only = [
                    ("format", self.format.is_some()),
                    ("channel", self.channel.is_some()),
                    ("size", self.size.is_some()),
                    ("height_unit", self.height_unit.is_some()),
                    ("crop", self.crop.is_some()),
                    ("fill_missing", self.fill_missing),
                    ("detrend", self.detrend.is_some()),
                    ("pixel_size", self.pixel_size.is_some()),
                    ("cap", self.cap.is_some()),
                ];
                if let Some((k, _)) = file_only.iter().find(|(_, given)| *given) {
                    return at(k, "applies to a `file` only, not to a synthetic surface".into());
                }
                check_synthetic(s).or_else(|r| at("synthetic", r))
            }
            (None, Some(_)) => {
                if let Some(Size(lx, ly)) = self.size {
                    if !(lx.0 > 0.0 && ly.0 > 0.0) {
                        return at(
                            "size",
                            format!(
                                "must be positive, got {} × {}",
                                quantity::show(lx.0, &LENGTH),
                                quantity::show(ly.0, &LENGTH)
                            ),
                        );
                    }
                    for l in [lx, ly] {
                        plausible::window(l.0, Spelling::StudyFile).map(drop).or_else(|r| at("size", r))?;
                    }
                }
                if let Some(unit) = &self.height_unit {
                    if crate::quantity::metres_per(unit).is_none() {
                        return at("height_unit", format!("'{unit}' is not a length unit"));
                    }
                }
                if let Some(p) = self.pixel_size {
                    if p.0.is_nan() || p.0 <= 0.0 {
                        return at("pixel_size", format!("must be positive, got {}", quantity::show(p.0, &LENGTH)));
                    }
                    plausible::pixel(p.0, Spelling::StudyFile).map(drop).or_else(|r| at("pixel_size", r))?;
                }
                if let Some(c) = &self.crop {
                    c.check().or_else(|r| at("crop", r))?;
                }
                if let Some(cap) = &self.cap {
                    if !(cap.radius > 0.0 && cap.radius.is_finite()) {
                        return at(
                            "cap",
                            format!("radius_m must be positive, got {}", quantity::show(cap.radius, &LENGTH)),
                        );
                    }
                    plausible::radius(cap.radius, Spelling::StudyFile)
                        .map(drop)
                        .or_else(|r| at("cap", format!("radius_m: {r}")))?;
                }
                Ok(())
            }
            _ => Err((here.to_vec(), "give exactly one of `synthetic` and `file`".into())),
        }
    }

    /// The levelling of a file (default: a plane).
    pub fn detrend(&self) -> Detrend {
        self.detrend.as_deref().map_or(Detrend::Polynomial(1), |d| d.parse().expect("checked when parsed"))
    }

    /// How a file is prepared for contact, on the study's `grid` if any, within `limits`.
    pub fn preparation(&self, grid: Option<(usize, usize)>, limits: Limits) -> Preparation {
        Preparation {
            limits,
            crop: self.crop.as_ref().map(CropSpec::window),
            fill_missing: self.fill_missing,
            detrend: self.detrend(),
            pixel_size: self.pixel_size.map(|p| p.0),
            grid,
            cap: self.cap,
        }
    }
}

impl CropSpec {
    /// The window to crop to.
    pub fn window(&self) -> CropWindow {
        match (self.x, self.y, self.columns, self.rows) {
            (Some(x), Some(y), ..) => CropWindow::Physical { x: (x[0].0, x[1].0), y: (y[0].0, y[1].0) },
            (_, _, Some(cols), Some(rows)) => CropWindow::Pixels { x: cols[0]..cols[1], y: rows[0]..rows[1] },
            _ => unreachable!("checked: a crop is physical or in pixels"),
        }
    }

    fn check(&self) -> std::result::Result<(), String> {
        let ordered = |r: [Length; 2]| r[0].0 >= 0.0 && r[0].0 < r[1].0;
        match (self.x, self.y, self.columns, self.rows) {
            (Some(x), Some(y), None, None) if ordered(x) && ordered(y) => Ok(()),
            (Some(_), Some(_), None, None) => Err("each of x and y must be [start, end] with 0 ≤ start < end".into()),
            (None, None, Some(c), Some(r)) if c[0] < c[1] && r[0] < r[1] => Ok(()),
            (None, None, Some(_), Some(_)) => {
                Err("each of columns and rows must be [start, end] with start < end".into())
            }
            _ => Err("give either `x` and `y` (lengths) or `columns` and `rows` (pixels)".into()),
        }
    }
}

/// Topography names become folder names: keep them plain.
fn check_name(name: &str) -> std::result::Result<(), String> {
    let plain = |c: char| c.is_alphanumeric() || " ._-+".contains(c);
    if name.trim().is_empty() || name.starts_with('.') || !name.chars().all(plain) {
        return Err(format!(
            "\"{name}\" is not a plain name (letters, digits, . _ - + and spaces, not starting with .)"
        ));
    }
    Ok(())
}

/// A synthetic surface's parameters, with its keys named as the file writes them.
fn check_synthetic(s: &SyntheticSurface) -> std::result::Result<(), String> {
    let renamed = |e: Error| match e {
        Error::Invalid { option, reason } => {
            let key = match option.as_str() {
                "--hurst" => "roughness.hurst",
                "--rms" => "roughness.rms_height_m",
                "--rms-slope" => "roughness.rms_slope",
                "--rolloff" => "roughness.rolloff_wavelength_m",
                "--cutoff" => "roughness.short_cutoff_wavelength_m",
                "--long-cutoff" => "roughness.long_cutoff_wavelength_m",
                "--sphere-radius" => "cap.radius_m",
                "--size" => "size_m",
                other => other,
            };
            format!("{key}: {reason}")
        }
        other => other.to_string(),
    };
    let (nx, ny) = s.grid;
    if nx < 2 || ny < 2 {
        return Err(format!("grid: {nx}×{ny} is too small: at least 2×2 points"));
    }
    if s.roughness.is_none() && s.cap.is_none() {
        return Err("neither roughness nor cap: nothing to generate".into());
    }
    if let Some(r) = &s.roughness {
        r.validate().map_err(renamed)?;
    }
    if let Some(cap) = &s.cap {
        // The cap's own checks (radius, coverage of the window) on the smallest grid.
        cap.heights(s.size, (2, 2)).map_err(renamed)?;
    }
    Ok(())
}

/// `synthetic = { … }`: [`SyntheticSurface`], with units allowed in its `_m` keys.
fn synthetic<'de, D: Deserializer<'de>>(d: D) -> Result<Option<SyntheticSurface>, D::Error> {
    with_lengths(d)
}

fn cap<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Cap>, D::Error> {
    with_lengths(d)
}

/// A table whose keys ending in `_m` are lengths that may carry units (`"1.5 mm"`), at any depth.
fn with_lengths<'de, D: Deserializer<'de>, T: de::DeserializeOwned>(d: D) -> Result<Option<T>, D::Error> {
    fn lengths(table: &mut toml::Table) -> std::result::Result<(), String> {
        for (k, v) in table.iter_mut() {
            let convert = |v: &mut toml::Value| -> std::result::Result<(), String> {
                if let toml::Value::String(s) = v {
                    *v = toml::Value::Float(quantity::parse(s, &LENGTH, false).map_err(|r| format!("{k}: {r}"))?);
                }
                Ok(())
            };
            match v {
                toml::Value::Table(t) => lengths(t).map_err(|r| format!("{k}.{r}"))?,
                toml::Value::Array(items) if k.ends_with("_m") => items.iter_mut().try_for_each(convert)?,
                _ if k.ends_with("_m") => convert(v)?,
                _ => {}
            }
        }
        Ok(())
    }
    let mut table = toml::Table::deserialize(d)?;
    lengths(&mut table).map_err(de::Error::custom)?;
    toml::Value::Table(table).try_into().map(Some).map_err(|e: toml::de::Error| de::Error::custom(e.message()))
}

/// `channel = "Height"` or `channel = 0`.
fn channel<'de, D: Deserializer<'de>>(d: D) -> Result<Option<String>, D::Error> {
    struct Channel;
    impl Visitor<'_> for Channel {
        type Value = String;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("a channel name or a 0-based index")
        }
        fn visit_str<E: de::Error>(self, v: &str) -> Result<String, E> {
            Ok(v.to_string())
        }
        fn visit_i64<E: de::Error>(self, v: i64) -> Result<String, E> {
            if v < 0 {
                return Err(E::custom(format!("channel index {v} is negative")));
            }
            Ok(v.to_string())
        }
    }
    d.deserialize_any(Channel).map(Some)
}

/// `detrend = "plane"`, checked as it is read.
fn detrend<'de, D: Deserializer<'de>>(d: D) -> Result<Option<String>, D::Error> {
    let s = String::deserialize(d)?;
    s.parse::<Detrend>().map_err(de::Error::custom)?;
    Ok(Some(s))
}

/// The `[[topography]]` tables: at least one, each with a plain name of its own, each surface
/// and its wafer checked.
pub(super) fn check_topographies(topographies: &[SurfaceSpec]) -> Checked {
    if topographies.is_empty() {
        return at(&[key("topography")], "no topography: give at least one [[topography]]".into());
    }
    for (i, t) in topographies.iter().enumerate() {
        let here = [key("topography"), Segment::Index(i)];
        let name = t.name.as_deref().ok_or_else(|| (here.to_vec(), "needs a `name`".to_string()))?;
        check_name(name).or_else(|r| at(&[key("topography"), Segment::Index(i), key("name")], r))?;
        if topographies[..i].iter().any(|o| o.name.as_deref() == Some(name)) {
            return at(&[key("topography"), Segment::Index(i), key("name")], format!("\"{name}\" is used twice"));
        }
        t.check(&here)?;
        if let Some(w) = &t.wafer {
            let wafer = [key("topography"), Segment::Index(i), key("wafer")];
            if w.name.is_some() {
                return at(&wafer, "a wafer takes no `name`".into());
            }
            if w.wafer.is_some() {
                return at(&wafer, "a wafer has no wafer of its own".into());
            }
            w.check(&wafer)?;
        }
    }
    Ok(())
}
