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
//!                                 # device = "cpu" | "gpu" (a build with the gpu feature);
//!                                 # adhesion = { work, stress | range, law } (solved besides)
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
//!
//! One file per section holds its keys, their defaults, units and checks: `surfaces.rs`
//! (`[[topography]]`), `material.rs`, `contact.rs`, `loads.rs`, `laws.rs` (`[[law]]`),
//! `model.rs`, `output.rs`, `limits.rs`. They build on `defaults.rs` (the default study),
//! `quantities.rs` (numbers with units) and `places.rs` (where in the file an error is), and
//! never on this file, which ties them: [`StudyConfig`] and the parse. Nothing here imports the
//! study's runner, nor `plot`, `report`, `cli` or `python`.

mod contact;
mod defaults;
mod laws;
mod limits;
mod loads;
mod material;
mod model;
mod output;
mod places;
mod quantities;
mod surfaces;

use std::ops::Range;
use std::path::Path;

use serde::{Deserialize, Serialize};
use toml::de::DeTable;

pub use self::contact::{AdhesionSpec, ContactSpec, Plastic};
pub use self::defaults::DEFAULT_STUDY;
use self::laws::check_laws;
pub use self::laws::LawSpec;
pub use self::limits::LimitsSpec;
pub use self::loads::{log_spaced, LoadsSpec, MAX_LOADS};
pub use self::material::{Counterface, MaterialSpec};
pub use self::model::{ModelSpec, Sharing};
pub use self::output::{FigureKind, OutputSpec, MAX_SNAPSHOT_FRACTIONS};
use self::places::{key, line_column, one_line, path_at, render, span_of, Checked};
pub use self::quantities::{Force, Length, Size, Stress, Time};
use self::surfaces::check_topographies;
pub use self::surfaces::{CropSpec, SurfaceSpec};
use crate::contact::{Boundary, Material};
use crate::error::{Error, Result};
use crate::plausible::{self, Spelling};
use crate::topography::detrend::Detrend;

/// The grid of `asperity run --quick` \[points].
pub const QUICK_GRID: (usize, usize) = (256, 256);

/// The number of loads of `asperity run --quick`.
pub const QUICK_LOADS: usize = 7;

pub use crate::friction::DEFAULT_SLIP_DISTANCE_M;

/// A study as its file describes it. Serialised, it is the study as run (`DIR/study.toml`):
/// paths absolute, loads and laws resolved to explicit values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(expecting = "a study file")]
pub struct StudyConfig {
    /// The `[[topography]]` tables: each surface is solved at every load with every law.
    #[serde(rename = "topography", default = "default_topographies")]
    pub topographies: Vec<SurfaceSpec>,
    /// `[material]`: the elastic body and counter-body.
    #[serde(default = "default_material")]
    pub material: MaterialSpec,
    /// `[contact]`: the normal contact solver.
    #[serde(default = "default_contact")]
    pub contact: ContactSpec,
    /// `[loads]`: the normal loads \[N].
    #[serde(default = "default_loads")]
    pub loads: LoadsSpec,
    /// The `[[law]]` tables: the local (element-scale) friction laws.
    #[serde(rename = "law", default = "default_laws")]
    pub laws: Vec<LawSpec>,
    /// `[model]`: how the tangential force is shared among the contact elements.
    #[serde(default, skip_serializing_if = "ModelSpec::is_default")]
    pub model: ModelSpec,
    /// `[output]`: what is written besides the results table.
    #[serde(default = "default_output")]
    pub output: OutputSpec,
    /// `[limits]`: how large inputs and grids may be.
    #[serde(default, skip_serializing_if = "LimitsSpec::is_default")]
    pub limits: LimitsSpec,
}

/// The sections of the default study, for a study file that leaves some out (keys the default
/// study leaves unset stay unset).
fn default_topographies() -> Vec<SurfaceSpec> {
    defaults::section("topography")
}

fn default_material() -> MaterialSpec {
    defaults::section("material")
}

fn default_contact() -> ContactSpec {
    defaults::section("contact")
}

fn default_loads() -> LoadsSpec {
    defaults::section("loads")
}

fn default_laws() -> Vec<LawSpec> {
    defaults::section("law")
}

fn default_output() -> OutputSpec {
    defaults::section("output")
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
        let tree = DeTable::parse(text).map_err(|e| {
            // toml's message names no key: the one given twice is at the span.
            let key = e.span().and_then(|s| text.get(s)).map(str::trim).filter(|k| !k.is_empty());
            match (e.message(), key) {
                ("duplicate key", Some(key)) => {
                    located(e.span(), "", &format!("`{key}` is set twice in its table: keep one of them"))
                }
                _ => located(e.span(), "", e.message()),
            }
        })?;
        let mut config: StudyConfig = toml::from_str(text).map_err(|e| {
            let path = e.span().map(|s| path_at(tree.get_ref(), s.start)).unwrap_or_default();
            located(e.span(), &render(&path), e.message())
        })?;
        // A sweep keeps the default's bounds and count for those it leaves out; a list of
        // `values` replaces the sweep.
        if config.loads.values.is_none() {
            let default = default_loads();
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
        if let Some(a) = &self.contact.adhesion {
            note("contact.adhesion.work".into(), plausible::adhesion_work(a.work.0, Spelling::StudyFile));
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
    fn check(&self) -> Checked {
        check_topographies(&self.topographies)?;
        self.material.check()?;
        self.contact.check(self.material.hardness)?;
        self.loads.check()?;
        check_laws(&self.laws)?;
        self.model.check()?;
        self.limits.check()?;
        self.output.check()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::Device;
    use crate::friction::Weakening;
    use crate::topography::detrend::{LineFit, WholeMap};
    use crate::topography::synth::{SelfAffine, SyntheticSurface};

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
        // The default is left out of the study as run.
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
        assert!(e.starts_with("study.toml:2:1: model.slip_distance: -1 nm is not a length ≥ 0"), "{e}");
        let e = err("[model]\nslip_distance = \"2 nm\"\nslip_distance = \"1 nm\"\n");
        assert_eq!(e, "study.toml:3:1: `slip_distance` is set twice in its table: keep one of them");
        let e = err("[model]\nslip_distance = \"1 mN\"\n");
        assert!(e.contains("model.slip_distance: '1 mN' is a force"), "{e}");
        let e = err("[[law]]\nname = \"x\"\nmu_s = 0.6\nmu_d = 0.4\ncurve_unit = \"1 nm\"\n");
        assert!(e.contains("law[0]: `curve_unit` applies to a `curve` only"), "{e}");
        let e = err("[[law]]\ncurve = \"a.csv\"\ncurve_unit = 0\n");
        assert!(e.contains("law[0]: curve_unit: 0 m is not a positive length"), "{e}");
    }

    #[test]
    fn the_band_of_slip_distances_brackets_d_c_and_needs_elastic_sharing() {
        // Off by default, and left out of the study as run.
        assert_eq!(StudyConfig::default_study().model.slip_distance_band, None);
        assert!(StudyConfig::default_study().model.band().is_empty());
        let elastic = "[model]\nsharing = [\"equal\", \"elastic\"]\n";
        let c = StudyConfig::parse(elastic, "s.toml").unwrap();
        assert!(!toml::to_string(&c).unwrap().contains("slip_distance_band"));
        // Units as slip_distance takes them; reads back as itself.
        let c = StudyConfig::parse(&format!("{elastic}slip_distance_band = [\"1 nm\", 5e-9]\n"), "s.toml").unwrap();
        assert_eq!(c.model.slip_distance_band, Some(vec![Length(1e-9), Length(5e-9)]));
        assert_eq!(c.model.band(), [1e-9, 5e-9]);
        assert_eq!(StudyConfig::parse(&toml::to_string(&c).unwrap(), "s.toml").unwrap(), c);
        let text = format!("{elastic}slip_distance = \"10 nm\"\nslip_distance_band = [\"5 nm\", \"0.02 µm\"]\n");
        assert_eq!(StudyConfig::parse(&text, "s.toml").unwrap().model.band(), [5e-9, 2e-8]);

        // Refused in one line at the key, with the reason.
        let band = |b: &str| err(&format!("{elastic}slip_distance_band = {b}\n"));
        let e = band("[\"3 nm\", \"5 nm\"]");
        assert!(
            e.starts_with(
                "study.toml:3:1: model.slip_distance_band: [3 nm, 5 nm] does not bracket slip_distance = 2 nm"
            ),
            "{e}"
        );
        let e = band("[\"1 nm\", \"2 nm\"]");
        assert!(e.contains("model.slip_distance_band: [1 nm, 2 nm] does not bracket"), "{e}");
        let e = band("[\"5 nm\", \"1 nm\"]");
        assert!(e.contains("does not bracket"), "{e}");
        let e = band("[\"1 nm\"]");
        assert!(
            e.starts_with("study.toml:3:1: model.slip_distance_band: give two lengths, low and high, not 1"),
            "{e}"
        );
        let e = band("[\"1 nm\", \"3 nm\", \"5 nm\"]");
        assert!(e.contains("model.slip_distance_band: give two lengths, low and high, not 3"), "{e}");
        let e = band("\"1 nm\"");
        assert!(e.contains("model.slip_distance_band: invalid type"), "{e}");
        let e = band("[\"1 mN\", \"5 nm\"]");
        assert!(e.contains("model.slip_distance_band") && e.contains("'1 mN' is a force"), "{e}");
        let e = band("[0, \"5 nm\"]");
        assert!(e.contains("model.slip_distance_band[0]: 0 m is not a positive length"), "{e}");
        let e = band("[\"1 nm\", \"5 m\"]");
        assert!(e.starts_with("study.toml:3:") && e.contains("model.slip_distance_band[1]: "), "{e}");
        // Without elastic sharing there is nothing to band, and d_c = 0 has no band around it.
        let e = err("[model]\nslip_distance_band = [\"1 nm\", \"5 nm\"]\n");
        assert!(e.starts_with("study.toml:2:1: model.slip_distance_band: a band of d_c needs elastic sharing"), "{e}");
        let e = err(&format!("{elastic}slip_distance = 0\nslip_distance_band = [\"1 nm\", \"5 nm\"]\n"));
        assert!(e.contains("does not bracket slip_distance = 0 m"), "{e}");
        for e in [e, band("[\"1 nm\"]"), band("[\"5 nm\", \"1 nm\"]")] {
            assert!(!e.contains('\n') && e.len() < 300, "{e}");
        }
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
