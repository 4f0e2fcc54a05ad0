//! The study file: a TOML description of a study — topographies, material, contact solver,
//! loads, local friction laws and outputs — that can replace every part of the default study.
//!
//! The reference of the format is the default study itself, [`DEFAULT_STUDY`], which
//! `asperity run --print-default` prints with every key explained. In short:
//!
//! ```toml
//! [[topography]]                  # one per surface, solved at every load with every law
//! name = "ball-1"
//! synthetic = { size_m = [31.13e-6, 31.13e-6], grid = [1500, 1500], seed = 1,
//!               roughness = { hurst = 0.8, rms_height_m = 22e-9 }, cap = { radius_m = 1.5e-3 } }
//! # or: file = "ball.spm", format, channel, size, height_unit, crop, fill_missing, detrend,
//! #     pixel_size, cap = { radius_m = "1.5 mm" } (added after levelling)
//! wafer = { file = "wafer.spm" }  # optional counter-surface: h = h_ball − h_wafer
//!
//! [material]                      # youngs [Pa], poisson; counterface = "rigid" | "same" |
//! youngs = "130 GPa"              # { youngs, poisson }; hardness [Pa]
//! poisson = 0.26
//!
//! [contact]                       # boundary "periodic" | "free", tolerance, max_iterations, grid;
//! boundary = "periodic"           # plastic = true | [false, true] (needs material.hardness);
//!                                 # device = "cpu" | "gpu" (a build with the gpu feature)
//!
//! [loads]                         # values = [...], or min, max, count (log-spaced) [N]
//! min = "0.1 mN"
//! max = "100 mN"
//! count = 13
//!
//! [[law]]                         # mu_s + mu_d (+ name) | preset | curve (+ window)
//! preset = "hold 100 s"
//!
//! [model]                         # sharing of the tangential force: "equal" (the paper's),
//! sharing = ["equal", "elastic"]  # "elastic" (the half-space's; costly), or both;
//! slip_distance = "2 nm"          # elastic sharing's slip-weakening distance d_c (0: instant)
//!
//! [output]                        # pressure_maps, experiments, figures, snapshot_fractions
//!
//! [limits]                        # max_points: the largest grid read, generated or solved
//! max_points = 268435456          # (the default, 2^28; `asperity run --max-points` overrides)
//! ```
//!
//! Quantities: a bare number is in SI units (m, N, Pa); a string carries its unit ("0.1 mN",
//! "31.13 µm", "130 GPa"). A unit of the wrong kind for its key is refused. Unknown keys are
//! refused everywhere. A section left out takes the default study's. Relative paths are
//! relative to the study file's folder.
//!
//! Every error is one line naming the place: `study.toml:12:3: loads.min: …` for what the file
//! says (checked here, before anything is read or solved), `study.toml: topography "ball-1":
//! …` for what building the study finds (files, see [`super::run`]).

use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::de::{self, Deserializer, Visitor};
use serde::{Deserialize, Serialize};
use toml::de::{DeTable, DeValue};
use toml::Spanned;

use super::{FigureKind, Sharing};
use crate::contact::{Boundary, Convergence, Device, Material};
use crate::error::{Error, Result};
use crate::friction::{slip_curve_file, FrictionLaw, Weakening};
use crate::limits::{Limits, DEFAULT_MAX_POINTS};
use crate::plausible::{self, Spelling};
use crate::quantity::{self, Dimension, FORCE, LENGTH, PRESSURE, TIME};
use crate::topography::detrend::Detrend;
use crate::topography::prepare::Preparation;
use crate::topography::resample::CropWindow;
use crate::topography::synth::{Amplitude, Cap, SyntheticSurface};

/// The default study, as `asperity run --print-default` prints it: three synthetic silicon
/// balls against synthetic wafers, silicon, 13 loads from 0.1 to 100 mN, two placeholder laws.
pub const DEFAULT_STUDY: &str = include_str!("default.toml");

/// The grid of `asperity run --quick` \[points].
pub const QUICK_GRID: (usize, usize) = (256, 256);

/// The number of loads of `asperity run --quick`.
pub const QUICK_LOADS: usize = 7;

pub use crate::friction::DEFAULT_SLIP_DISTANCE_M;

/// The most loads a study takes: each is a contact solve of every topography.
pub const MAX_LOADS: usize = 1000;

/// The most `[output] snapshot_fractions`: each is a row of 400 pixels in the stress-ratio
/// snapshot figure.
pub const MAX_SNAPSHOT_FRACTIONS: usize = 12;

/// A study as its file describes it. Serialised, it is the study as run (`DIR/study.toml`):
/// paths absolute, loads and laws resolved to explicit values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudyConfig {
    /// The `[[topography]]` tables: each surface is solved at every load with every law.
    #[serde(rename = "topography", default = "defaults::topographies")]
    pub topographies: Vec<SurfaceSpec>,
    /// `[material]`: the elastic body and counter-body.
    #[serde(default = "defaults::material")]
    pub material: MaterialSpec,
    /// `[contact]`: the normal contact solver.
    #[serde(default = "defaults::contact")]
    pub contact: ContactSpec,
    /// `[loads]`: the normal loads \[N].
    #[serde(default = "defaults::loads")]
    pub loads: LoadsSpec,
    /// The `[[law]]` tables: the local (element-scale) friction laws.
    #[serde(rename = "law", default = "defaults::laws")]
    pub laws: Vec<LawSpec>,
    /// `[model]`: how the tangential force is shared among the contact elements.
    #[serde(default, skip_serializing_if = "ModelSpec::is_default")]
    pub model: ModelSpec,
    /// `[output]`: what is written besides the results table.
    #[serde(default = "defaults::output")]
    pub output: OutputSpec,
    /// `[limits]`: how large inputs and grids may be.
    #[serde(default, skip_serializing_if = "LimitsSpec::is_default")]
    pub limits: LimitsSpec,
}

/// A surface: a topography of the study (with its `name`) or its wafer (without).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
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

/// The elastic body and its counter-body.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Young's modulus E \[Pa].
    #[serde(default = "defaults::youngs")]
    pub youngs: Stress,
    /// Poisson's ratio ν.
    #[serde(default = "defaults::poisson")]
    pub poisson: f64,
    /// The counter-body: rigid (the paper's, by default), of the same material, or an elastic
    /// body of its own.
    #[serde(default, skip_serializing_if = "Counterface::is_rigid")]
    pub counterface: Counterface,
    /// Hardness H \[Pa] of the softer body (silicon ≈ 12 GPa): the load carried at p ≥ H is
    /// reported and warned about; the cap on the pressure of plastic solves. None by default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hardness: Option<Stress>,
    /// Uncertainty ΔE of `youngs` \[Pa]: the friction-drop figure's band also covers E ± ΔE.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub youngs_uncertainty: Option<Stress>,
}

/// `counterface = "rigid" | "same" | { youngs, poisson }`: what the elastic body presses on.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub enum Counterface {
    /// A rigid flat, as in the paper: E* = E / (1 − ν²).
    #[default]
    Rigid,
    /// A body of the same material (silicon on silicon): E* = E / (2 (1 − ν²)).
    Same,
    /// An elastic body of Young's modulus `youngs` \[Pa] and Poisson's ratio `poisson`:
    /// 1/E* = (1 − ν²)/E + (1 − ν₂²)/E₂.
    Body {
        /// Young's modulus E₂ \[Pa].
        youngs: Stress,
        /// Poisson's ratio ν₂.
        poisson: f64,
    },
}

impl Counterface {
    fn is_rigid(&self) -> bool {
        *self == Counterface::Rigid
    }
}

/// A counter-body's table: both keys, nothing else.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct CounterBody {
    youngs: Stress,
    poisson: f64,
}

impl Serialize for Counterface {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match *self {
            Counterface::Rigid => s.serialize_str("rigid"),
            Counterface::Same => s.serialize_str("same"),
            Counterface::Body { youngs, poisson } => CounterBody { youngs, poisson }.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for Counterface {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct CounterfaceVisitor;
        impl<'de> Visitor<'de> for CounterfaceVisitor {
            type Value = Counterface;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("\"rigid\", \"same\" or a table { youngs, poisson }")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Counterface, E> {
                match v {
                    "rigid" => Ok(Counterface::Rigid),
                    "same" => Ok(Counterface::Same),
                    _ => Err(E::invalid_value(de::Unexpected::Str(v), &self)),
                }
            }
            fn visit_map<A: de::MapAccess<'de>>(self, map: A) -> Result<Counterface, A::Error> {
                let body = CounterBody::deserialize(de::value::MapAccessDeserializer::new(map))?;
                Ok(Counterface::Body { youngs: body.youngs, poisson: body.poisson })
            }
        }
        d.deserialize_any(CounterfaceVisitor)
    }
}

/// Contact solver settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// `"periodic"` (the window repeats, as the paper's computation; the default) or `"free"`
    /// (an isolated window on an infinite half-space).
    #[serde(with = "boundary", default = "defaults::boundary")]
    pub boundary: Boundary,
    /// Relative residual at which a normal solve has converged (default 1e-8; see
    /// [`crate::contact`]'s solver).
    #[serde(default = "defaults::tolerance")]
    pub tolerance: f64,
    /// Iterations after which a solve that has not converged is an error (default 20 000).
    #[serde(default = "defaults::max_iterations")]
    pub max_iterations: usize,
    /// Solve every topography on this grid (nx, ny) over the same physical window.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid: Option<(usize, usize)>,
    /// Elastic (false), elastic–perfectly-plastic with p ≤ `material.hardness` (true), or a
    /// list of both: each its own load sweep, told apart by the results' `plastic` column.
    #[serde(default, skip_serializing_if = "Plastic::is_elastic")]
    pub plastic: Plastic,
    /// Where the normal solves run: "cpu" or "gpu" (a build with the `gpu` feature).
    #[serde(default, skip_serializing_if = "is_cpu")]
    pub device: Device,
}

fn is_cpu(device: &Device) -> bool {
    *device == Device::Cpu
}

/// `plastic = false | true | [false, true]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Plastic {
    /// One sweep: elastic (`false`) or elastic–perfectly-plastic (`true`).
    One(bool),
    /// One sweep per entry, in this order.
    Each(Vec<bool>),
}

impl Default for Plastic {
    fn default() -> Self {
        Plastic::One(false)
    }
}

impl Plastic {
    fn is_elastic(&self) -> bool {
        *self == Plastic::One(false)
    }

    /// The solves to run, in the order given: plastic or not.
    pub fn modes(&self) -> Vec<bool> {
        match self {
            Plastic::One(p) => vec![*p],
            Plastic::Each(list) => list.clone(),
        }
    }
}

/// The normal loads: a list, or `count` log-spaced from `min` to `max`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
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

/// A local friction law: `name` + `mu_s` + `mu_d`, a `preset`, or a measured `curve`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LawSpec {
    /// The law's label in the results (relabels a preset; a curve's default is its file name).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Local static coefficient mu_s (≥ mu_d).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu_s: Option<f64>,
    /// Local dynamic coefficient mu_d (> 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu_d: Option<f64>,
    /// A named (mu_s, mu_d) pair, such as `"hold 100 s"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// A measured nanoscale friction curve (CSV of displacement, friction coefficient): mu_s is
    /// its peak, mu_d its mean past the peak.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curve: Option<PathBuf>,
    /// (start, end) past the curve's peak over which mu_d is averaged, in the curve's
    /// displacement unit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window: Option<(f64, f64)>,
    /// The displacement unit of `curve` as a length \[m]: with it, elastic sharing follows the
    /// curve past its peak as μ(slip) (the curve's own slip weakening) instead of
    /// `[model] slip_distance`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curve_unit: Option<Length>,
    /// The AFM hold time the law was measured at \[s] (t₀ of an aging law).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hold_time: Option<Time>,
    /// β of an aging law, mu_s(t) = mu_s(t₀) + β·log10(t/t₀) with mu_d fixed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aging: Option<f64>,
    /// The hold times \[s] an aging law is evaluated at: one law of the study each.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hold_times: Option<Vec<Time>>,
}

/// The friction model's settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    /// How the tangential force is shared among the contact elements: each listed sharing
    /// gives its own rows (the `sharing` column), in this order.
    #[serde(default = "equal_sharing")]
    pub sharing: Vec<Sharing>,
    /// Elastic sharing's slip-weakening distance d_c \[m]: μ falls linearly from mu_s to mu_d
    /// over an accumulated slip d_c (0: at once on the first slip, the paper's law, whose
    /// onset depends on the pixel). A `curve` law with its `curve_unit` follows its curve.
    #[serde(default = "default_slip_distance")]
    pub slip_distance: Length,
}

impl Default for ModelSpec {
    fn default() -> Self {
        ModelSpec { sharing: equal_sharing(), slip_distance: default_slip_distance() }
    }
}

impl ModelSpec {
    fn is_default(&self) -> bool {
        *self == ModelSpec::default()
    }

    /// The slip weakening of elastic sharing for the law `spec` (checked, paths resolved): its
    /// measured curve past the peak when it gives a `curve_unit`, else a linear fall over
    /// `slip_distance`, or the instant drop for a `slip_distance` of 0. Reads the curve file.
    pub fn weakening(&self, spec: &LawSpec) -> Result<Weakening> {
        match (&spec.curve, spec.curve_unit) {
            (Some(path), Some(unit)) => Ok(Weakening::Curve(slip_curve_file(path, unit.0)?)),
            _ if self.slip_distance.0 == 0.0 => Ok(Weakening::Instant),
            _ => Ok(Weakening::Linear(self.slip_distance.0)),
        }
    }
}

fn default_slip_distance() -> Length {
    Length(DEFAULT_SLIP_DISTANCE_M)
}

fn equal_sharing() -> Vec<Sharing> {
    vec![Sharing::Equal]
}

/// What to write besides the results table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Also keep every full pressure map \[Pa] as `DIR/pressure/<topography>/NN.npy`.
    #[serde(default)]
    pub pressure_maps: bool,
    /// A CSV of measured points (as `asperity shs --out` writes it) to overlay on the figures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub experiments: Option<PathBuf>,
    /// The figures to draw (default: all).
    #[serde(default = "all_figures")]
    pub figures: Vec<FigureKind>,
    /// δ/δ_peak of the stress-ratio snapshots, each in (0, 1] (default 0.25, 0.5, 0.75, 1).
    #[serde(default = "default_fractions")]
    pub snapshot_fractions: Vec<f64>,
    /// Loads \[N] of the hold-time figure.
    #[serde(default = "default_hold_time_loads")]
    pub hold_time_loads: Vec<Force>,
    /// p(σ) on a logarithmic density axis.
    #[serde(default)]
    pub log_density: bool,
}

/// How large the study's inputs and grids may be (see [`crate::limits`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LimitsSpec {
    /// The largest grid read from a file, generated, resampled or solved \[points].
    #[serde(default = "defaults::max_points")]
    pub max_points: usize,
}

impl Default for LimitsSpec {
    fn default() -> Self {
        LimitsSpec { max_points: DEFAULT_MAX_POINTS }
    }
}

impl LimitsSpec {
    fn is_default(&self) -> bool {
        *self == LimitsSpec::default()
    }

    /// The limits the study's inputs are held to.
    pub fn limits(&self) -> Limits {
        Limits { max_points: self.max_points }
    }
}

fn all_figures() -> Vec<FigureKind> {
    FigureKind::ALL.to_vec()
}

fn default_fractions() -> Vec<f64> {
    vec![0.25, 0.5, 0.75, 1.0]
}

fn default_hold_time_loads() -> Vec<Force> {
    vec![Force(1e-4), Force(1e-3), Force(1e-2)]
}

/// The sections of the default study, and the keys of its sections, for a study file that
/// leaves some out: a key left out of a section takes the default study's value (keys the
/// default study leaves unset stay unset).
mod defaults {
    use super::*;

    // Keys: called only for a key a file leaves out, so the default study itself, which gives
    // every one, never recurses into them.
    pub fn youngs() -> Stress {
        material().youngs
    }
    pub fn poisson() -> f64 {
        material().poisson
    }
    pub fn boundary() -> Boundary {
        contact().boundary
    }
    pub fn tolerance() -> f64 {
        contact().tolerance
    }
    pub fn max_iterations() -> usize {
        contact().max_iterations
    }
    pub fn max_points() -> usize {
        DEFAULT_MAX_POINTS
    }

    fn default_study() -> StudyConfig {
        toml::from_str(DEFAULT_STUDY).expect("the default study parses")
    }

    pub fn topographies() -> Vec<SurfaceSpec> {
        default_study().topographies
    }
    pub fn material() -> MaterialSpec {
        default_study().material
    }
    pub fn contact() -> ContactSpec {
        default_study().contact
    }
    pub fn loads() -> LoadsSpec {
        default_study().loads
    }
    pub fn laws() -> Vec<LawSpec> {
        default_study().laws
    }
    pub fn output() -> OutputSpec {
        default_study().output
    }
}

impl StudyConfig {
    /// The default study ([`DEFAULT_STUDY`]).
    pub fn default_study() -> StudyConfig {
        StudyConfig::parse(DEFAULT_STUDY, "default study").expect("the default study is valid")
    }

    /// Parse and check a study file's `text`; `origin` names it in errors (its path).
    pub fn parse(text: &str, origin: &str) -> Result<StudyConfig> {
        let located = |span: Option<Range<usize>>, path: &str, reason: &str| {
            let place = match span {
                Some(span) => {
                    let (line, column) = line_column(text, span.start);
                    format!("{origin}:{line}:{column}")
                }
                None => origin.to_string(),
            };
            let reason = if path.is_empty() { reason.to_string() } else { format!("{path}: {reason}") };
            Error::invalid(place, one_line(&reason))
        };
        let tree = DeTable::parse(text).map_err(|e| located(e.span(), "", e.message()))?;
        let mut config: StudyConfig = toml::from_str(text).map_err(|e| {
            let path = e.span().map(|s| path_at(tree.get_ref(), s.start)).unwrap_or_default();
            located(e.span(), &render(&path), e.message())
        })?;
        // A sweep keeps the default's bounds and count for those it leaves out; a list of
        // `values` replaces the sweep.
        if config.loads.values.is_none() {
            let default = defaults::loads();
            let l = &mut config.loads;
            l.min = l.min.or(default.min);
            l.max = l.max.or(default.max);
            l.count = l.count.or(default.count);
        }
        config.check().map_err(|(path, reason)| located(span_of(tree.get_ref(), &path), &render(&path), &reason))?;
        // Chosen by name (not in a list of every figure, each drawn where its data is), the
        // sharing figure needs elastic sharing beside the equal one.
        let figures = [key("output"), key("figures")];
        let named = span_of(tree.get_ref(), &figures);
        let every = FigureKind::ALL.iter().all(|f| config.output.figures.contains(f));
        if named.is_some()
            && !every
            && config.output.figures.contains(&FigureKind::FrictionDropSharing)
            && !config.model.sharing.contains(&Sharing::Elastic)
        {
            return Err(located(
                named,
                &render(&figures),
                "\"friction-drop-sharing\" compares equal with elastic sharing: add \"elastic\" to [model] sharing, \
                 or leave the figure out",
            ));
        }
        Ok(config)
    }

    /// Read and check the study file at `path`; its relative paths become relative to its
    /// folder.
    pub fn from_file(path: &Path) -> Result<StudyConfig> {
        let text = crate::limits::Limits::default().read_text(path)?;
        let config = StudyConfig::parse(&text, &path.display().to_string())?;
        let base = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        Ok(config.with_paths_from(&std::path::absolute(base).map_err(|e| Error::io(base, e))?))
    }

    /// The same study on the `--quick` scale: every topography on [`QUICK_GRID`] over the
    /// same window, [`QUICK_LOADS`] loads over the same range.
    pub fn quick(mut self) -> StudyConfig {
        self.contact.grid = Some(QUICK_GRID);
        let loads = self.load_values();
        let (min, max) = (loads[0], loads[loads.len() - 1]);
        self.loads = LoadsSpec {
            values: Some(
                log_spaced(min, max, if min < max { QUICK_LOADS } else { 1 }).into_iter().map(Force).collect(),
            ),
            min: None,
            max: None,
            count: None,
        };
        self
    }

    /// The loads \[N], ascending.
    pub fn load_values(&self) -> Vec<f64> {
        let mut loads: Vec<f64> = match (&self.loads.values, self.loads.min, self.loads.max, self.loads.count) {
            (Some(values), ..) => values.iter().map(|f| f.0).collect(),
            (None, Some(min), Some(max), Some(count)) => log_spaced(min.0, max.0, count),
            _ => unreachable!("checked by StudyConfig::check"),
        };
        loads.sort_by(f64::total_cmp);
        loads
    }

    /// Relative paths made relative to `base` (the study file's folder).
    pub fn with_paths_from(mut self, base: &Path) -> StudyConfig {
        fn surface(s: &mut SurfaceSpec, base: &Path) {
            if let Some(f) = &mut s.file {
                *f = base.join(&*f);
            }
            if let Some(w) = &mut s.wafer {
                surface(w, base);
            }
        }
        self.topographies.iter_mut().for_each(|t| surface(t, base));
        for law in &mut self.laws {
            if let Some(c) = &mut law.curve {
                // The law keeps the name the file gave it.
                law.name.get_or_insert_with(|| c.display().to_string());
                *c = base.join(&*c);
            }
        }
        if let Some(e) = &mut self.output.experiments {
            *e = base.join(&*e);
        }
        self
    }

    /// Every file the study reads: its topographies' and wafers' files, its laws' curves and
    /// its measured points.
    pub fn input_files(&self) -> Vec<&Path> {
        fn surface<'a>(s: &'a SurfaceSpec, found: &mut Vec<&'a Path>) {
            found.extend(s.file.as_deref());
            if let Some(w) = &s.wafer {
                surface(w, found);
            }
        }
        let mut found = Vec::new();
        self.topographies.iter().for_each(|t| surface(t, &mut found));
        found.extend(self.laws.iter().filter_map(|l| l.curve.as_deref()));
        found.extend(self.output.experiments.as_deref());
        found
    }

    /// The material's hardness \[Pa], if given.
    pub fn hardness(&self) -> Option<f64> {
        self.material.hardness.map(|h| h.0)
    }

    /// The elastic bodies: the body, and the counter-body when it is elastic.
    pub fn bodies(&self) -> Vec<Material> {
        let m = &self.material;
        let body = Material { youngs: m.youngs.0, poisson: m.poisson };
        match m.counterface {
            Counterface::Rigid => vec![body],
            Counterface::Same => vec![body, body],
            Counterface::Body { youngs, poisson } => vec![body, Material { youngs: youngs.0, poisson }],
        }
    }

    /// The effective modulus E* \[Pa].
    pub fn effective_modulus(&self) -> f64 {
        match self.bodies()[..] {
            [body, counter] => crate::contact::combined_modulus(&body, &counter),
            [body] => body.plane_strain_modulus(),
            _ => unreachable!("one or two bodies"),
        }
    }

    /// The values the file gives that are possible but unusual (a 5 MPa modulus, a friction
    /// coefficient of 5, a load pressing a synthetic window unusually hard), one line each,
    /// naming the key as the file writes it.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        let mut note = |place: String, verdict: plausible::Verdict| {
            if let Ok(Some(w)) = verdict {
                out.push(format!("{place}: {w}"));
            }
        };
        let m = &self.material;
        note("material.youngs".into(), plausible::modulus(m.youngs.0, Spelling::StudyFile));
        if let Counterface::Body { youngs, .. } = m.counterface {
            note("material.counterface.youngs".into(), plausible::modulus(youngs.0, Spelling::StudyFile));
        }
        if let Some(h) = m.hardness {
            note("material.hardness".into(), plausible::hardness(h.0, Spelling::StudyFile));
        }
        let heaviest = self.load_values().last().copied().unwrap_or(0.0);
        for (i, t) in self.topographies.iter().enumerate() {
            let here = format!("topography[{i}]");
            if let Some(s) = &t.synthetic {
                for l in [s.size.0, s.size.1] {
                    note(format!("{here}.synthetic.size_m"), plausible::window(l, Spelling::StudyFile));
                }
                if let Some(cap) = &s.cap {
                    note(format!("{here}.synthetic.cap.radius_m"), plausible::radius(cap.radius, Spelling::StudyFile));
                }
                let e_star = self.effective_modulus();
                note("loads".into(), plausible::load(heaviest, s.size, e_star, Spelling::StudyFile));
            }
            if let Some(Size(lx, ly)) = t.size {
                for l in [lx, ly] {
                    note(format!("{here}.size"), plausible::window(l.0, Spelling::StudyFile));
                }
            }
            if let Some(p) = t.pixel_size {
                note(format!("{here}.pixel_size"), plausible::pixel(p.0, Spelling::StudyFile));
            }
            if let Some(cap) = &t.cap {
                note(format!("{here}.cap.radius_m"), plausible::radius(cap.radius, Spelling::StudyFile));
            }
        }
        note("model.slip_distance".into(), plausible::slip_distance(self.model.slip_distance.0, Spelling::StudyFile));
        for (i, law) in self.laws.iter().enumerate() {
            for mu in [law.mu_s, law.mu_d].into_iter().flatten() {
                note(format!("law[{i}]"), plausible::friction_coefficient(mu));
            }
        }
        out.dedup();
        out
    }

    /// What the study file could still do to keep topography `name`'s contact inside its
    /// window, in its own words, leaving out what it does already.
    pub fn edge_remedies(&self, name: &str) -> Vec<String> {
        let Some(t) = self.topographies.iter().find(|t| t.name.as_deref() == Some(name)) else {
            return Vec::new();
        };
        let file = t.file.is_some();
        let capped = t.cap.is_some() || t.synthetic.as_ref().is_some_and(|s| s.cap.is_some());
        [
            (self.contact.boundary != Boundary::Free, "boundary = \"free\" in [contact]"),
            (file && t.crop.is_none(), "a `crop`"),
            (file && t.detrend() == Detrend::None, "detrend = \"plane\""),
            (!capped, "a cap (cap = { radius_m = … })"),
        ]
        .into_iter()
        .filter(|(left, _)| *left)
        .map(|(_, remedy)| remedy.to_string())
        .collect()
    }

    /// Everything the file can be wrong about by itself; the error is the key path and reason.
    fn check(&self) -> std::result::Result<(), (Vec<Segment>, String)> {
        let at = |path: &[Segment], reason: String| Err((path.to_vec(), reason));
        if self.topographies.is_empty() {
            return at(&[key("topography")], "no topography: give at least one [[topography]]".into());
        }
        for (i, t) in self.topographies.iter().enumerate() {
            let here = [key("topography"), Segment::Index(i)];
            let name = t.name.as_deref().ok_or_else(|| (here.to_vec(), "needs a `name`".to_string()))?;
            check_name(name).or_else(|r| at(&[key("topography"), Segment::Index(i), key("name")], r))?;
            if self.topographies[..i].iter().any(|o| o.name.as_deref() == Some(name)) {
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

        let m = &self.material;
        let material = key("material");
        Material::new(m.youngs.0, m.poisson, "material").map_err(|e| (vec![material.clone()], reason_of(e)))?;
        let counter_youngs = match m.counterface {
            Counterface::Body { youngs, .. } => Some(youngs),
            _ => None,
        };
        let judged = [
            (vec![key("youngs")], Some(m.youngs), plausible::modulus as fn(f64, Spelling) -> plausible::Verdict),
            (vec![key("counterface"), key("youngs")], counter_youngs, plausible::modulus),
            (vec![key("hardness")], m.hardness, plausible::hardness),
        ];
        for (path, value, judge) in judged {
            if let Some(v) = value {
                judge(v.0, Spelling::StudyFile)
                    .map(drop)
                    .or_else(|r| at(&[vec![material.clone()], path].concat(), r))?;
            }
        }
        // The E band is drawn through E ± ΔE: both must be moduli.
        if let Some(delta) = m.youngs_uncertainty {
            if !(delta.0 >= 0.0 && delta.0 < m.youngs.0) {
                return at(
                    &[material.clone(), key("youngs_uncertainty")],
                    format!(
                        "{} must lie in [0, youngs) = [0, {})",
                        quantity::show(delta.0, &PRESSURE),
                        quantity::show(m.youngs.0, &PRESSURE)
                    ),
                );
            }
        }
        if let Counterface::Body { youngs, poisson } = m.counterface {
            Material::new(youngs.0, poisson, "counter-body")
                .map_err(|e| (vec![material.clone(), key("counterface")], reason_of(e)))?;
        }

        let c = &self.contact;
        if let Err(e) = (Convergence { tolerance: c.tolerance, max_iterations: c.max_iterations }).check() {
            let field = if matches!(&e, Error::Invalid { option, .. } if option == "--max-iter") {
                "max_iterations"
            } else {
                "tolerance"
            };
            return at(&[key("contact"), key(field)], reason_of(e));
        }
        if c.device == Device::Gpu && !Device::GPU_BUILT {
            return at(&[key("contact"), key("device")], Device::UNAVAILABLE.into());
        }
        if let Some((nx, ny)) = c.grid {
            if nx < 2 || ny < 2 {
                return at(&[key("contact"), key("grid")], format!("{nx}×{ny} is too small: at least 2×2 points"));
            }
        }
        let modes = c.plastic.modes();
        let plastic = [key("contact"), key("plastic")];
        if modes.is_empty() || (1..modes.len()).any(|i| modes[..i].contains(&modes[i])) {
            return at(&plastic, "give true, false, or a list of both, each once".into());
        }
        match m.hardness {
            Some(h) if !(h.0 > 0.0 && h.0.is_finite()) => {
                return at(&[key("material"), key("hardness")], format!("must be positive, got {} Pa", h.0));
            }
            None if modes.contains(&true) => {
                return at(&plastic, "a plastic solve needs `hardness` in [material]".into());
            }
            _ => {}
        }

        let l = &self.loads;
        let loads = key("loads");
        match (&l.values, l.min, l.max, l.count) {
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

        if self.laws.is_empty() {
            return at(&[key("law")], "no friction law: give at least one [[law]]".into());
        }
        for (i, law) in self.laws.iter().enumerate() {
            let here = [key("law"), Segment::Index(i)];
            law.check().or_else(|r| at(&here, r))?;
            let (earlier, mine): (Vec<String>, Vec<String>) =
                (self.laws[..i].iter().flat_map(|o| o.names()).collect(), law.names());
            for (k, name) in mine.iter().enumerate() {
                if earlier.contains(name) || mine[..k].contains(name) {
                    return at(&here, format!("the name \"{name}\" is used twice"));
                }
            }
        }

        let sharing = &self.model.sharing;
        let path = [key("model"), key("sharing")];
        if sharing.is_empty() {
            return at(&path, "the list is empty: give \"equal\", \"elastic\" or both".into());
        }
        if let Some(i) = (1..sharing.len()).find(|&i| sharing[..i].contains(&sharing[i])) {
            let mut path = path.to_vec();
            path.push(Segment::Index(i));
            return at(&path, format!("\"{}\" is listed twice", sharing[i].name()));
        }
        let dc = self.model.slip_distance.0;
        if !(dc >= 0.0 && dc.is_finite()) {
            return at(&[key("model"), key("slip_distance")], format!("{dc} m is not a length ≥ 0 (0: instant drop)"));
        }
        plausible::slip_distance(dc, Spelling::StudyFile)
            .map(drop)
            .or_else(|r| at(&[key("model"), key("slip_distance")], r))?;

        Limits::new(self.limits.max_points, "max_points")
            .map_err(|e| (vec![key("limits"), key("max_points")], reason_of(e)))?;

        let fractions = self.output.snapshot_fractions.len();
        if fractions > MAX_SNAPSHOT_FRACTIONS {
            return at(
                &[key("output"), key("snapshot_fractions")],
                format!(
                    "{fractions} fractions: at most {MAX_SNAPSHOT_FRACTIONS} (each is a row of the snapshot figure)"
                ),
            );
        }
        if fractions == 0 && self.output.figures.contains(&FigureKind::StressRatioSnapshots) {
            return at(
                &[key("output"), key("snapshot_fractions")],
                "an empty list draws no stress-ratio snapshots: give at least one δ/δ_peak in (0, 1], or leave \
                 \"stress-ratio-snapshots\" out of figures"
                    .to_string(),
            );
        }
        for (i, f) in self.output.snapshot_fractions.iter().enumerate() {
            if !(*f > 0.0 && *f <= 1.0) {
                let path = [key("output"), key("snapshot_fractions"), Segment::Index(i)];
                return at(&path, format!("δ/δ_peak = {f} is not in (0, 1]"));
            }
        }
        Ok(())
    }
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
                        return at("size", format!("must be positive, got {} × {} m", lx.0, ly.0));
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
                        return at("pixel_size", format!("must be positive, got {} m", p.0));
                    }
                    plausible::pixel(p.0, Spelling::StudyFile).map(drop).or_else(|r| at("pixel_size", r))?;
                }
                if let Some(c) = &self.crop {
                    c.check().or_else(|r| at("crop", r))?;
                }
                if let Some(cap) = &self.cap {
                    if !(cap.radius > 0.0 && cap.radius.is_finite()) {
                        return at("cap", format!("radius_m must be positive, got {} m", cap.radius));
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

impl LawSpec {
    /// The law's name: its `name`, else its preset's, else its curve file's as written, else
    /// its coefficients ("mu_s 0.6, mu_d 0.4").
    pub fn name(&self) -> String {
        match (&self.name, &self.preset, &self.curve) {
            (Some(n), ..) => n.clone(),
            (None, Some(p), _) => p.clone(),
            (None, None, Some(c)) => c.display().to_string(),
            (None, None, None) => match (self.mu_s, self.mu_d) {
                (Some(mu_s), Some(mu_d)) => format!("mu_s {mu_s}, mu_d {mu_d}"),
                _ => String::new(),
            },
        }
    }

    /// The names of the laws this spec gives the study: its name, or for an aging law one
    /// per hold time ("hold 10 s", or "NAME, hold 10 s" when it has a name).
    pub fn names(&self) -> Vec<String> {
        match &self.hold_times {
            Some(times) => times
                .iter()
                .map(|t| match &self.name {
                    Some(n) => format!("{n}, hold {} s", t.0),
                    None => format!("hold {} s", t.0),
                })
                .collect(),
            None => vec![self.name()],
        }
    }

    /// The hold time of a law given by this spec: its `hold_time`, or the one a preset's name
    /// states ("hold 100 s").
    pub fn stated_hold_time(&self) -> Option<f64> {
        self.hold_time.map(|t| t.0).or_else(|| {
            let preset = self.preset.as_deref()?;
            preset.strip_prefix("hold ")?.strip_suffix(" s")?.parse().ok()
        })
    }

    fn check(&self) -> std::result::Result<(), String> {
        for (key, mu) in [("mu_s", self.mu_s), ("mu_d", self.mu_d)] {
            if let Some(mu) = mu {
                plausible::friction_coefficient(mu).map_err(|r| format!("{key}: {r}"))?;
            }
        }
        if let Some(t) = self.hold_time {
            if t.0.is_nan() || t.0 <= 0.0 {
                return Err(format!("hold_time: {} s is not positive", t.0));
            }
        }
        if self.curve_unit.is_some() && self.curve.is_none() {
            return Err("`curve_unit` applies to a `curve` only".into());
        }
        if self.aging.is_some() || self.hold_times.is_some() {
            return self.check_aging();
        }
        match (self.mu_s, self.mu_d, &self.preset, &self.curve) {
            (Some(mu_s), Some(mu_d), None, None) => {
                if self.window.is_some() {
                    return Err("`window` applies to a `curve` only".into());
                }
                FrictionLaw::new(mu_s, mu_d).map(drop).map_err(reason_of)
            }
            (None, None, Some(preset), None) => {
                if self.window.is_some() {
                    return Err("`window` applies to a `curve` only".into());
                }
                FrictionLaw::preset(preset).map(drop).map_err(reason_of)
            }
            (None, None, None, Some(_)) if self.curve_unit.is_some_and(|u| !(u.0 > 0.0 && u.0.is_finite())) => {
                Err(format!("curve_unit: {} m is not a positive length", self.curve_unit.map_or(0.0, |u| u.0)))
            }
            (None, None, None, Some(_)) => match self.window {
                Some((start, end)) if !(start >= 0.0 && start < end && end.is_finite()) => {
                    Err(format!("window must be [start, end] with 0 ≤ start < end, got [{start}, {end}]"))
                }
                _ => Ok(()),
            },
            _ => Err("give exactly one of `mu_s` and `mu_d` (with `name`), `preset` or `curve`".into()),
        }
    }

    /// An aging law: mu_s at `hold_time`, mu_d, `aging` and `hold_times`, nothing else.
    fn check_aging(&self) -> std::result::Result<(), String> {
        let (Some(mu_s), Some(mu_d), Some(t0), Some(beta), Some(times)) =
            (self.mu_s, self.mu_d, self.hold_time, self.aging, &self.hold_times)
        else {
            return Err("an aging law needs mu_s (at hold_time), mu_d, hold_time, aging and hold_times".into());
        };
        if self.preset.is_some() || self.curve.is_some() || self.window.is_some() {
            return Err("an aging law is given by mu_s, mu_d, hold_time, aging and hold_times only".into());
        }
        if times.is_empty() {
            return Err("hold_times is empty".into());
        }
        for (i, t) in times.iter().enumerate() {
            if t.0.is_nan() || t.0 <= 0.0 {
                return Err(format!("hold_times: {} s is not positive", t.0));
            }
            if times[..i].contains(t) {
                return Err(format!("hold_times: {} s is listed twice", t.0));
            }
            FrictionLaw::aged(mu_s, mu_d, t0.0, beta, t.0).map(drop).map_err(reason_of)?;
        }
        Ok(())
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

/// The reason of an error from the library's checks, without the CLI option it names.
fn reason_of(e: Error) -> String {
    match e {
        Error::Invalid { option, reason } if option.starts_with("--") => reason,
        Error::Invalid { option, reason } => format!("{option}: {reason}"),
        other => other.to_string(),
    }
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

// ── Quantities ─────────────────────────────────────────────────────────────────────────────

/// Deserialise a bare number (SI) or a string with its unit.
fn deserialize_quantity<'de, D: Deserializer<'de>>(d: D, dim: &'static Dimension) -> Result<f64, D::Error> {
    struct Quantity(&'static Dimension);
    impl Visitor<'_> for Quantity {
        type Value = f64;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            write!(f, "a {} (a number in {} or a string with a unit)", self.0.name, self.0.si)
        }
        fn visit_f64<E: de::Error>(self, v: f64) -> Result<f64, E> {
            quantity::finite(v, &v.to_string()).map_err(E::custom)
        }
        fn visit_i64<E: de::Error>(self, v: i64) -> Result<f64, E> {
            Ok(v as f64)
        }
        fn visit_u64<E: de::Error>(self, v: u64) -> Result<f64, E> {
            Ok(v as f64)
        }
        fn visit_str<E: de::Error>(self, v: &str) -> Result<f64, E> {
            quantity::parse(v, self.0, false).map_err(E::custom)
        }
    }
    d.deserialize_any(Quantity(dim))
}

macro_rules! quantity {
    ($(#[$doc:meta])* $name:ident, $dim:expr) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Serialize)]
        #[serde(transparent)]
        pub struct $name(pub f64);

        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                deserialize_quantity(d, &$dim).map($name)
            }
        }
    };
}

quantity!(
    /// A length \[m].
    Length,
    LENGTH
);
quantity!(
    /// A force \[N].
    Force,
    FORCE
);
quantity!(
    /// A stress or modulus \[Pa].
    Stress,
    PRESSURE
);
quantity!(
    /// A time \[s].
    Time,
    TIME
);

/// A physical size (lx, ly) \[m]: one length for a square, or two.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Size(pub Length, pub Length);

impl Serialize for Size {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        [self.0, self.1].serialize(s)
    }
}

impl<'de> Deserialize<'de> for Size {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct SizeVisitor;
        impl<'de> Visitor<'de> for SizeVisitor {
            type Value = Size;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a length, or [lx, ly]")
            }
            fn visit_seq<A: de::SeqAccess<'de>>(self, mut seq: A) -> Result<Size, A::Error> {
                let lx: Length = seq.next_element()?.ok_or_else(|| de::Error::invalid_length(0, &self))?;
                let ly: Length = seq.next_element()?.ok_or_else(|| de::Error::invalid_length(1, &self))?;
                if seq.next_element::<Length>()?.is_some() {
                    return Err(de::Error::invalid_length(3, &self));
                }
                Ok(Size(lx, ly))
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Size, E> {
                Ok(Size(Length(v), Length(v)))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Size, E> {
                self.visit_f64(v as f64)
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Size, E> {
                let l = Length(quantity::parse(v, &LENGTH, false).map_err(E::custom)?);
                Ok(Size(l, l))
            }
        }
        d.deserialize_any(SizeVisitor)
    }
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

/// `boundary = "periodic" | "free"`.
mod boundary {
    use super::*;

    pub fn serialize<S: serde::Serializer>(b: &Boundary, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(b.name())
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Boundary, D::Error> {
        match String::deserialize(d)?.as_str() {
            "periodic" => Ok(Boundary::Periodic),
            "free" => Ok(Boundary::Free),
            other => Err(de::Error::custom(format!("'{other}' is not \"periodic\" or \"free\""))),
        }
    }
}

// ── Places in the file ─────────────────────────────────────────────────────────────────────

/// One step of a key path: a key, or an index into an array (of tables).
#[derive(Debug, Clone, PartialEq)]
enum Segment {
    Key(String),
    Index(usize),
}

fn key(k: &str) -> Segment {
    Segment::Key(k.to_string())
}

/// `topography[1].wafer.file`.
fn render(path: &[Segment]) -> String {
    let mut out = String::new();
    for s in path {
        match s {
            Segment::Key(k) if out.is_empty() => out.push_str(k),
            Segment::Key(k) => {
                out.push('.');
                out.push_str(k);
            }
            Segment::Index(i) => out.push_str(&format!("[{i}]")),
        }
    }
    out
}

/// The key path of the most deeply nested key or value at byte `offset`.
fn path_at(root: &DeTable, offset: usize) -> Vec<Segment> {
    fn visit(value: &DeValue, offset: usize, path: &mut Vec<Segment>, best: &mut Vec<Segment>) {
        if let Some(table) = value.as_table() {
            for (k, v) in table.iter() {
                path.push(Segment::Key(k.get_ref().to_string()));
                if k.span().contains(&offset) || v.span().contains(&offset) {
                    note(path, best);
                }
                visit(v.get_ref(), offset, path, best);
                path.pop();
            }
        } else if let Some(array) = value.as_array() {
            for (i, item) in array.iter().enumerate() {
                path.push(Segment::Index(i));
                if item.span().contains(&offset) {
                    note(path, best);
                }
                visit(item.get_ref(), offset, path, best);
                path.pop();
            }
        }
    }
    fn note(path: &[Segment], best: &mut Vec<Segment>) {
        if path.len() > best.len() {
            *best = path.to_vec();
        }
    }
    let mut best = Vec::new();
    visit(&DeValue::Table(root.clone()), offset, &mut Vec::new(), &mut best);
    best
}

/// The span of the key (or array item) at `path`, or of the deepest part of it present.
fn span_of(root: &DeTable, path: &[Segment]) -> Option<Range<usize>> {
    let mut span = None;
    let mut node: Option<&DeValue> = None;
    for seg in path {
        let next: Option<(Range<usize>, &Spanned<DeValue>)> = match (seg, node) {
            (Segment::Key(k), None) => root.get(k.as_str()).map(|v| (key_span(root, k), v)),
            (Segment::Key(k), Some(v)) => v.as_table().and_then(|t| t.get(k.as_str()).map(|x| (key_span(t, k), x))),
            (Segment::Index(i), Some(v)) => v.as_array().and_then(|a| a.get(*i)).map(|x| (x.span(), x)),
            (Segment::Index(_), None) => None,
        };
        let Some((s, v)) = next else { break };
        span = Some(s);
        node = Some(v.get_ref());
    }
    span
}

fn key_span(table: &DeTable, k: &str) -> Range<usize> {
    table.iter().find(|(key, _)| key.get_ref() == k).map(|(key, _)| key.span()).unwrap_or(0..0)
}

/// 1-based line and column (in characters) of byte `offset` in `text`.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topography::detrend::{LineFit, WholeMap};
    use crate::topography::synth::SelfAffine;

    fn err(text: &str) -> String {
        StudyConfig::parse(text, "study.toml").unwrap_err().to_string()
    }

    #[test]
    fn the_default_study_is_the_papers_stand_in() {
        let c = StudyConfig::default_study();
        let names: Vec<_> = c.topographies.iter().map(|t| t.name.clone().unwrap()).collect();
        assert_eq!(names, ["ball-1", "ball-2", "ball-3"]);
        for (i, t) in c.topographies.iter().enumerate() {
            let s = t.synthetic.as_ref().unwrap();
            assert_eq!(*s, SyntheticSurface { seed: i as u64 + 1, ..SyntheticSurface::default() });
            let w = t.wafer.as_ref().unwrap().synthetic.as_ref().unwrap();
            assert_eq!(w.roughness, Some(SelfAffine::silicon_wafer()));
            assert!(w.cap.is_none() && w.size == s.size && w.grid == s.grid && w.seed != s.seed);
        }
        assert!((c.effective_modulus() - 130e9 / (1.0 - 0.26f64.powi(2))).abs() < 1.0);
        assert_eq!(c.contact.boundary, Boundary::Periodic);
        let loads = c.load_values();
        assert_eq!(loads.len(), 25);
        for l in [1e-7, 1e-6, 1e-4, 1e-3, 1e-2, 1e-1] {
            assert!(loads.contains(&l), "{l} not in {loads:?}");
        }
        let laws: Vec<_> = c.laws.iter().flat_map(LawSpec::names).collect();
        assert_eq!(laws, ["hold 100 s", "hold 10 s"]);
        assert_eq!(c.output.figures, FigureKind::ALL);
        assert!(DEFAULT_STUDY.contains("ILLUSTRATIVE PLACEHOLDERS"));
    }

    /// The counterface sets E*: the paper's rigid flat by default, the same silicon at half of
    /// it, another body by 1/E* = (1 − ν²)/E + (1 − ν₂²)/E₂; the study as run keeps it.
    #[test]
    fn the_counterface_sets_the_effective_modulus() {
        let rigid = 130e9 / (1.0 - 0.26f64.powi(2));
        let modulus =
            |text: &str| StudyConfig::parse(&format!("[material]\n{text}"), "s.toml").unwrap().effective_modulus();
        assert!((modulus("") / rigid - 1.0).abs() < 1e-15);
        assert!((modulus("counterface = \"rigid\"\n") / rigid - 1.0).abs() < 1e-15);
        assert!((modulus("counterface = \"same\"\n") / (rigid / 2.0) - 1.0).abs() < 1e-15);
        let steel = 1.0 / (1.0 / rigid + (1.0 - 0.3f64.powi(2)) / 210e9);
        let text = "counterface = { youngs = \"210 GPa\", poisson = 0.3 }\n";
        assert!((modulus(text) / steel - 1.0).abs() < 1e-15);
        let c = StudyConfig::parse(&format!("[material]\n{text}"), "s.toml").unwrap();
        assert_eq!(c.bodies().len(), 2);
        let again = StudyConfig::parse(&toml::to_string(&c).unwrap(), "again.toml").unwrap();
        assert_eq!(again.material.counterface, c.material.counterface);
        // Refused at the key, with what is allowed.
        let e = err("[material]\ncounterface = \"glass\"\n");
        assert!(
            e.contains("material.counterface") && e.contains("\"rigid\", \"same\" or a table { youngs, poisson }"),
            "{e}"
        );
        let e = err("[material]\ncounterface = { youngs = \"210 GPa\" }\n");
        assert!(e.contains("material.counterface") && e.contains("missing field `poisson`"), "{e}");
        let e = err("[material]\ncounterface = { youngs = \"210 GPa\", poisson = 0.3, hardness = 1 }\n");
        assert!(e.contains("unknown field `hardness`"), "{e}");
        let e = err("[material]\ncounterface = { youngs = \"210 GPa\", poisson = 0.7 }\n");
        assert!(e.contains("material.counterface") && e.contains("0.7"), "{e}");
        let e = err("[material]\ncounterface = { youngs = \"210 Pa\", poisson = 0.3 }\n");
        assert!(e.contains("material.counterface.youngs"), "{e}");
    }

    /// `device` picks where the solves run; a build without the GPU backend refuses "gpu" at
    /// its line, in the study file's terms.
    #[test]
    fn the_device_is_a_contact_key() {
        assert_eq!(StudyConfig::default_study().contact.device, Device::Cpu);
        let text = "[contact]\ndevice = \"gpu\"\n";
        if Device::GPU_BUILT {
            assert_eq!(StudyConfig::parse(text, "study.toml").unwrap().contact.device, Device::Gpu);
        } else {
            let e = err(text);
            assert!(
                e.starts_with("study.toml:2:1: contact.device: this asperity was built without the GPU backend"),
                "{e}"
            );
        }
        let e = err("[contact]\ndevice = \"tpu\"\n");
        assert!(e.starts_with("study.toml:2:") && e.contains("contact.device") && e.contains("tpu"), "{e}");
    }

    #[test]
    fn quick_keeps_the_window_and_the_load_range() {
        let q = StudyConfig::default_study().quick();
        assert_eq!(q.contact.grid, Some((256, 256)));
        let loads = q.load_values();
        assert_eq!(loads, [1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1]);
        assert_eq!(q.topographies, StudyConfig::default_study().topographies);
    }

    #[test]
    fn errors_name_line_column_and_key() {
        let e = err("[loads]\nmin = \"0.1 mm\"\nmax = \"1 mN\"\ncount = 3\n");
        assert!(e.starts_with("study.toml:2:7: loads.min: '0.1 mm' is a length, not a force"), "{e}");
        let e = err("[contact]\ntolerence = 1e-8\n");
        assert!(e.starts_with("study.toml:2:1: contact.tolerence: unknown field `tolerence`"), "{e}");
        let e = err("[loads]\nvalues = []\n");
        assert!(e.starts_with("study.toml:2:1: loads.values: the load list is empty"), "{e}");
        let e = err("[loads]\nvalues = [\"1 mN\", -2e-3]\n");
        assert!(e.starts_with("study.toml:2:19: loads.values[1]: -0.002 N is not positive"), "{e}");
        let e = err("[loads]\nmin = \"1 mN\"\nmax = \"0.1 mN\"\ncount = 3\n");
        assert!(e.starts_with("study.toml:2:1: loads.min: 0.001 N is not below max"), "{e}");
        let e = err("[[law]]\npreset = \"hold 1 s\"\n");
        assert!(e.starts_with("study.toml:1:1: law[0]: unknown law \"hold 1 s\""), "{e}");
        // Without a name, a law is named by its coefficients.
        let c = StudyConfig::parse("[[law]]\nmu_s = 0.6\nmu_d = 0.4\n", "study.toml").unwrap();
        assert_eq!(c.laws[0].names(), ["mu_s 0.6, mu_d 0.4"]);
        let e = err("[[law]]\nname = \"x\"\nmu_s = 0.3\nmu_d = 0.4\n");
        assert!(e.starts_with("study.toml:1:1: law[0]: the static friction coefficient 0.3 is below"), "{e}");
        let e = err("[[topography]]\nname = \"a\"\nsynthetic = { size_m = [\"3 mN\", 1e-5], grid = [8, 8], cap = { radius_m = 1 } }\n");
        assert!(e.starts_with("study.toml:3:13: topography[0].synthetic: size_m: '3 mN' is a force"), "{e}");
        let e = err("[[topography]]\nname = \"a\"\nfile = \"a.npy\"\nsize = \"10 µm\"\n[[topography]]\nname = \"a\"\nfile = \"b.npy\"\n");
        assert!(e.starts_with("study.toml:6:1: topography[1].name: \"a\" is used twice"), "{e}");
        let e = err("[[topography]]\nname = \"a\"\nfile = \"a.npy\"\ncrop = { x = [0, 1e-5] }\n");
        assert!(e.starts_with("study.toml:4:1: topography[0].crop: give either"), "{e}");
        let e = err("[[topography]]\nname = \"a\"\nfile = \"a.npy\"\ndetrend = \"cubic\"\n");
        assert!(e.starts_with("study.toml:4:11: topography[0].detrend: 'cubic' is not none"), "{e}");
        let e = err("[[topography]]\nname = \"a\"\nfile = \"a.npy\"\ndetrend = \"line:4,plane\"\n");
        assert!(e.starts_with("study.toml:4:11: topography[0].detrend: 'line:4,plane' is not none"), "{e}");
        let e = err("[[topography]]\nname = \"a\"\nsynthetic = { size_m = [1e-5, 1e-5], grid = [8, 8], roughness = { hurst = 2, rms_height_m = 1e-9 } }\n");
        assert!(e.starts_with("study.toml:3:1: topography[0].synthetic: roughness.hurst: must lie in (0, 1]"), "{e}");
        let e = err("[output]\nfigures = [\"friction-drops\"]\n");
        assert!(e.starts_with("study.toml:2:12: output.figures[0]: unknown variant `friction-drops`"), "{e}");
        let e = err("[material]\nyoungs = \"130 GPa\"\npoisson = 0.7\n");
        assert!(e.starts_with("study.toml:1:2: material: material Poisson's ratio: must lie in"), "{e}");
        let e = err("[loads\n");
        assert!(e.starts_with("study.toml:1:"), "{e}");
        for e in [e, err("[[law]]\nmu_s = 0.5\n")] {
            assert!(!e.contains('\n'), "{e}");
        }
    }

    #[test]
    fn model_sharing_parses_and_defaults_to_equal() {
        assert_eq!(StudyConfig::default_study().model.sharing, [Sharing::Equal]);
        let c = StudyConfig::parse("[model]\nsharing = [\"equal\", \"elastic\"]\n", "study.toml").unwrap();
        assert_eq!(c.model.sharing, [Sharing::Equal, Sharing::Elastic]);
        let c = StudyConfig::parse("[model]\nsharing = [\"elastic\"]\n", "study.toml").unwrap();
        assert_eq!(c.model.sharing, [Sharing::Elastic]);
        assert_eq!(StudyConfig::parse("[model]\n", "study.toml").unwrap().model.sharing, [Sharing::Equal]);
        // The default is left out of the study as run, so that earlier runs' fingerprints hold.
        let text = toml::to_string(&StudyConfig::default_study()).unwrap();
        assert!(!text.contains("[model]"), "{text}");
        let c = StudyConfig::parse("[model]\nsharing = [\"elastic\", \"equal\"]\n", "s.toml").unwrap();
        assert_eq!(StudyConfig::parse(&toml::to_string(&c).unwrap(), "s.toml").unwrap(), c);

        let e = err("[model]\nsharing = [\"equal\", \"elastics\"]\n");
        assert!(e.starts_with("study.toml:2:21: model.sharing[1]: unknown variant `elastics`"), "{e}");
        let e = err("[model]\nsharing = []\n");
        assert!(e.starts_with("study.toml:2:1: model.sharing: the list is empty"), "{e}");
        let e = err("[model]\nsharing = [\"elastic\", \"elastic\"]\n");
        assert!(e.starts_with("study.toml:2:23: model.sharing[1]: \"elastic\" is listed twice"), "{e}");
        let e = err("[model]\nsharing = \"elastic\"\n");
        assert!(e.starts_with("study.toml:2:11: model.sharing: invalid type"), "{e}");
        let e = err("[model]\nshare = [\"equal\"]\n");
        assert!(e.starts_with("study.toml:2:1: model.share: unknown field `share`"), "{e}");
        for e in [e, err("[model]\nsharing = [1]\n")] {
            assert!(!e.contains('\n') && e.len() < 300, "{e}");
        }
    }

    #[test]
    fn elastic_sharing_weakens_over_the_documented_slip_distance_by_default() {
        // Without a slip_distance, elastic sharing's laws fall from mu_s to mu_d over 2 nm (the
        // instant drop's onset moves with the pixel: tools/sharing-convergence.sh).
        assert_eq!(DEFAULT_SLIP_DISTANCE_M, 2e-9);
        let c = StudyConfig::parse("[model]\nsharing = [\"elastic\"]\n", "study.toml").unwrap();
        assert_eq!(c.model.slip_distance, Length(2e-9));
        assert_eq!(c.model.weakening(&c.laws[0]).unwrap(), Weakening::Linear(2e-9));
        assert_eq!(StudyConfig::default_study().model.slip_distance, Length(2e-9));
        let c = StudyConfig::parse("[model]\nsharing = [\"elastic\"]\nslip_distance = \"5 nm\"\n", "s.toml").unwrap();
        assert_eq!(c.model.weakening(&c.laws[0]).unwrap(), Weakening::Linear(5e-9));
        // Reads back as itself: the study as run records its d_c.
        assert!(toml::to_string(&c).unwrap().contains("slip_distance = "));
        assert_eq!(StudyConfig::parse(&toml::to_string(&c).unwrap(), "s.toml").unwrap(), c);
        let c = StudyConfig::parse("[model]\nsharing = [\"elastic\"]\nslip_distance = 0\n", "s.toml").unwrap();
        assert_eq!(c.model.weakening(&c.laws[0]).unwrap(), Weakening::Instant);

        // A measured curve with its displacement unit: its own weakening past the peak; without
        // the unit, the model's d_c.
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("afm.csv"), "x,mu\n0,0.1\n1,0.6\n2,0.5\n3,0.4\n").unwrap();
        let law = "[model]\nsharing = [\"elastic\"]\n[[law]]\ncurve = \"afm.csv\"\n";
        let c =
            StudyConfig::parse(&format!("{law}curve_unit = \"1 nm\"\n"), "s.toml").unwrap().with_paths_from(dir.path());
        assert_eq!(
            c.model.weakening(&c.laws[0]).unwrap(),
            Weakening::Curve(vec![(0.0, 0.6), (1e-9, 0.5), (2e-9, 0.4)])
        );
        let c = StudyConfig::parse(law, "s.toml").unwrap().with_paths_from(dir.path());
        assert_eq!(c.model.weakening(&c.laws[0]).unwrap(), Weakening::Linear(2e-9));

        let e = err("[model]\nslip_distance = \"-1 nm\"\n");
        assert!(e.starts_with("study.toml:2:1: model.slip_distance: -0.000000001 m is not a length ≥ 0"), "{e}");
        let e = err("[model]\nslip_distance = \"1 mN\"\n");
        assert!(e.contains("model.slip_distance: '1 mN' is a force"), "{e}");
        let e = err("[[law]]\nname = \"x\"\nmu_s = 0.6\nmu_d = 0.4\ncurve_unit = \"1 nm\"\n");
        assert!(e.contains("law[0]: `curve_unit` applies to a `curve` only"), "{e}");
        let e = err("[[law]]\ncurve = \"a.csv\"\ncurve_unit = 0\n");
        assert!(e.contains("law[0]: curve_unit: 0 m is not a positive length"), "{e}");
    }

    #[test]
    fn the_resolved_study_reads_back_as_itself() {
        let c = StudyConfig::default_study().quick().with_paths_from(Path::new("/data"));
        let text = toml::to_string(&c).unwrap();
        assert_eq!(StudyConfig::parse(&text, "study.toml").unwrap(), c);
        let text = "[[topography]]\nname = \"m\"\nfile = \"scans/m.npy\"\nsize = [\"10 µm\", 8e-6]\nheight_unit = \"nm\"\n\
                    pixel_size = \"20 nm\"\nwafer = { file = \"w.npy\", size = 1e-5 }\n[[law]]\ncurve = \"afm.csv\"\nwindow = [0.5, 1.5]\n";
        let c = StudyConfig::parse(text, "s.toml").unwrap().with_paths_from(Path::new("/data"));
        let t = &c.topographies[0];
        assert_eq!(t.file.as_deref(), Some(Path::new("/data/scans/m.npy")));
        assert_eq!(t.size, Some(Size(Length(10e-6), Length(8e-6))));
        assert_eq!(t.wafer.as_ref().unwrap().size, Some(Size(Length(1e-5), Length(1e-5))));
        assert_eq!(t.detrend(), Detrend::Polynomial(1));
        let lines = "[[topography]]\nname = \"m\"\nfile = \"m.npy\"\nsize = 1e-5\ndetrend = \"line:1,plane\"\n";
        let levelled = StudyConfig::parse(lines, "s.toml").unwrap();
        assert_eq!(levelled.topographies[0].detrend(), Detrend::Lines(LineFit::Polynomial(1), WholeMap::Polynomial(1)));
        assert_eq!(c.laws[0].name(), "afm.csv");
        assert_eq!(c.laws[0].curve.as_deref(), Some(Path::new("/data/afm.csv")));
        // Sections left out are the default study's.
        assert_eq!(c.loads, StudyConfig::default_study().loads);
        assert_eq!(StudyConfig::parse(&toml::to_string(&c).unwrap(), "s.toml").unwrap(), c);
    }
}
