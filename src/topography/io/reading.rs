//! The reading types every format module implements or returns: a decoded [`Channel`] and
//! the map [`Format`] trait, a decoded [`ProfileData`] and the [`ProfileFormat`] trait. Below
//! the registry and every format; imports none of them.
//!
//! Must not import contact, friction, study, report, plot, shs, cli.

use ndarray::Array2;

use crate::limits::Limits;
use crate::topography::profile::StatedStep;

/// One decoded channel of a file.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// Name as the file gives it (instruments may repeat names).
    pub name: String,
    /// Values, shape (ny, nx); in metres when `is_height`, as stored otherwise. `NaN` marks
    /// a missing point.
    pub data: Array2<f64>,
    /// Physical size (lx, ly) \[m], when the file states one.
    pub physical_size: Option<(f64, f64)>,
    /// The data unit as the file writes it (`"nm"`, `"V"`, `"deg"`…), `None` if it gives none.
    pub unit: Option<String>,
    /// Whether the channel holds heights (its unit is a length, or the format only holds
    /// heights).
    pub is_height: bool,
}

/// A file format the registry can read.
pub trait Format: Sync {
    /// Short name, as `--format` takes it and provenance reports it.
    fn name(&self) -> &'static str;
    /// File name endings this format uses, lower case, without the dot.
    fn extensions(&self) -> &'static [&'static str];
    /// Whether a file's leading bytes identify this format.
    fn sniff(&self, head: &[u8]) -> bool;
    /// Decode every channel of the file. Errors are reasons; the registry adds the path.
    fn read(&self, bytes: &[u8]) -> std::result::Result<Vec<Channel>, String>;
    /// Decode every channel, refusing a grid over `limits` before allocating it. Only a format
    /// whose data can outgrow the file (compressed) needs the limits while it decodes; the
    /// others allocate no more than the file's length allows, and the registry checks their
    /// grids once decoded.
    fn read_within(&self, bytes: &[u8], limits: &Limits) -> std::result::Result<Vec<Channel>, String> {
        let _ = limits;
        self.read(bytes)
    }
    /// A bare format whose files carry neither physical size nor height unit: both come
    /// from the user (`--size`, `--height-unit`).
    fn is_bare(&self) -> bool {
        false
    }
    /// The header fields a channel's physical size comes from, as an error about it names them.
    fn size_field(&self) -> &'static str {
        "the header"
    }
}

/// A line profile as a format decodes it, in the units the file states.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileData {
    /// Name of the heights' column (`"default"` when the file names none).
    pub name: String,
    /// Positions along the profile, as stored, increasing.
    pub positions: Vec<f64>,
    /// Heights as stored; `NaN` marks a missing point.
    pub heights: Vec<f64>,
    /// The positions' length unit as the file writes it, if it does.
    pub position_unit: Option<String>,
    /// The heights' length unit as the file writes it, if it does.
    pub height_unit: Option<String>,
    /// Whether the content says it is a profile rather than a map two points wide (a header, a
    /// format of profiles, enough rows); an undecided file is read only when `--format` says so.
    pub decided: bool,
    /// The grid step the header states, in the positions' unit, if it does.
    pub stated_step: Option<StatedStep>,
}

/// A file format that holds a line profile.
pub trait ProfileFormat: Sync {
    /// Short name, as `--format` takes it and provenance reports it.
    fn name(&self) -> &'static str;
    /// File name endings this format uses, lower case, without the dot.
    fn extensions(&self) -> &'static [&'static str];
    /// Whether a file's leading bytes identify this format.
    fn sniff(&self, head: &[u8]) -> bool;
    /// Whether the whole file identifies this format when its head does not (a zip whose
    /// members tell it); tried after every format's [`ProfileFormat::sniff`].
    fn sniff_all(&self, bytes: &[u8]) -> bool {
        let _ = bytes;
        false
    }
    /// Decode the profile. Errors are reasons; the registry adds the path.
    fn read(&self, bytes: &[u8]) -> std::result::Result<ProfileData, String>;
    /// Decode the profile within `limits`: only a compressed format needs them while it
    /// decodes (see [`Format::read_within`]).
    fn read_within(&self, bytes: &[u8], limits: &Limits) -> std::result::Result<ProfileData, String> {
        let _ = limits;
        self.read(bytes)
    }
}
