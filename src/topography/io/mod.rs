//! Reading topography files: one module per format behind one registry.
//!
//! The registry picks a file's format from its leading bytes (magic), falling back to its
//! extension, decodes its channels, and hands back the chosen one as a [`Topography`] in
//! metres, or the line profile a profile format decodes as a [`Profile`]. Each format module
//! knows only its own bytes; paths, options and the choice of channel are handled here once.
//! What needs a map reads with [`read`], which refuses a profile by name.
//!
//! In front of the registry, two layers serve every format: gzip data are inflated
//! (`gzip`), and a member of a zip container is named `archive.zip#member` (`container`,
//! whose members [`container_members`] lists). Both inflate within the input limits.
//!
//! The registry above the formats: the formats import the reading types of `reading`, never the
//! registry itself (`FORMATS`). Must not import contact, friction, study, report, plot, shs, cli.

mod al3d;
mod bcr;
mod binary;
mod columns;
mod container;
mod datx;
mod dektak;
mod frt;
mod gsf;
mod gwy;
mod gwyddion_txt;
mod gzip;
mod hdf5;
mod hfm;
mod hgt;
mod ibw;
mod jpk;
mod mat;
mod matrix;
mod mdt;
mod metropro;
mod mi;
mod mitutoyo;
mod mnt;
mod nanoscope;
mod netcdf;
mod nid;
mod nmm;
pub mod npy;
mod npz;
mod opd;
mod opdx;
mod plu;
mod profile;
mod ps;
mod reading;
mod sdf;
mod sur;
mod text;
mod tiff;
mod tmd;
mod wsxm;
mod x3p;
mod xyz;

pub use gsf::write_gsf;
pub use reading::{Channel, Format, ProfileData, ProfileFormat};

use std::path::{Path, PathBuf};

use super::map::{Provenance, Topography};
use super::profile::Profile;
use crate::error::{Error, Result};
use crate::limits::Limits;
use crate::plausible::{self, Spelling};
use crate::quantity::{self, metres_per};

/// What a topography file holds: a 2-D height map or a line profile (SurfaceTopography's `dim`
/// 2 or 1). What needs a map reads with [`read`], which refuses a profile.
#[derive(Debug, Clone, PartialEq)]
pub enum AnyTopography {
    /// A height map h(x, y) on a regular grid.
    Map(Topography),
    /// A line profile h(x).
    Profile(Profile),
}

/// A format of the registry: of maps (channels) or of a line profile.
#[derive(Clone, Copy)]
enum Reader {
    Map(&'static dyn Format),
    Profile(&'static dyn ProfileFormat),
}

impl Reader {
    fn name(self) -> &'static str {
        match self {
            Reader::Map(f) => f.name(),
            Reader::Profile(f) => f.name(),
        }
    }

    fn extensions(self) -> &'static [&'static str] {
        match self {
            Reader::Map(f) => f.extensions(),
            Reader::Profile(f) => f.extensions(),
        }
    }

    fn sniff(self, head: &[u8]) -> bool {
        match self {
            Reader::Map(f) => f.sniff(head),
            Reader::Profile(f) => f.sniff(head),
        }
    }

    fn sniff_all(self, bytes: &[u8]) -> bool {
        match self {
            Reader::Map(_) => false,
            Reader::Profile(f) => f.sniff_all(bytes),
        }
    }
}

/// Every format, in the order magic bytes are tried (most specific first).
static FORMATS: &[Reader] = &[
    Reader::Map(&npy::Npy),
    Reader::Map(&gwy::Gwy),
    Reader::Map(&nanoscope::Nanoscope),
    Reader::Map(&nid::Nid),
    Reader::Map(&mi::Mi),
    Reader::Map(&x3p::X3p),
    Reader::Map(&npz::Npz),
    Reader::Map(&netcdf::NetCdf),
    Reader::Map(&datx::Datx),
    Reader::Map(&hdf5::Hdf5),
    Reader::Map(&mat::Mat),
    Reader::Map(&ibw::Ibw),
    Reader::Map(&metropro::MetroPro),
    Reader::Map(&sur::Sur),
    Reader::Map(&al3d::Al3d),
    Reader::Map(&opd::Opd),
    Reader::Map(&mnt::Mnt),
    Reader::Map(&mdt::Mdt),
    Reader::Profile(&opdx::Opdx),
    // Sensofar files have no magic number: known by their extension only.
    Reader::Map(&plu::Plu),
    Reader::Map(&frt::Frt),
    Reader::Map(&tmd::Tmd),
    Reader::Map(&wsxm::Wsxm),
    Reader::Map(&bcr::Bcr),
    Reader::Map(&jpk::Jpk),
    Reader::Map(&ps::Ps),
    // Bare heights, told by their extension only.
    Reader::Map(&hgt::Hgt),
    // Zip formats told by their extension or their members.
    Reader::Profile(&mitutoyo::Mitutoyo),
    Reader::Profile(&nmm::Nmm),
    // Text formats after the binary ones; among them, a Gwyddion header or a Dektak export
    // before x y z points (tables of three columns) and profiles (of two) before any other
    // table of numbers.
    Reader::Map(&gsf::Gsf),
    Reader::Map(&sdf::Sdf),
    Reader::Map(&gwyddion_txt::GwyddionTxt),
    Reader::Profile(&dektak::Dektak),
    Reader::Profile(&hfm::Hfm),
    Reader::Map(&xyz::Xyz),
    Reader::Profile(&profile::ProfileText),
    Reader::Map(&matrix::Matrix),
];

/// What a file decodes to, with the format that decoded it.
enum Decoded {
    Maps(&'static dyn Format, Vec<Channel>),
    Profile(&'static dyn ProfileFormat, ProfileData),
}

/// How to read a file: all fields optional.
#[derive(Debug, Clone, Default)]
pub struct ReadOptions {
    /// Format name, overriding detection.
    pub format: Option<String>,
    /// Channel by name or by 0-based index; default the first height channel.
    pub channel: Option<String>,
    /// Physical size (lx, ly) \[m]: required for bare formats, checked against the file's
    /// otherwise.
    pub physical_size: Option<(f64, f64)>,
    /// Height unit of a file that states none (a bare array's default: metres); of a line
    /// profile's positions too, unless `position_unit` gives theirs.
    pub height_unit: Option<String>,
    /// Unit of a line profile's positions when the file states none.
    pub position_unit: Option<String>,
    /// The largest grid and file accepted.
    pub limits: Limits,
}

/// The formats the registry knows, for `--help` texts and error messages.
pub fn format_names() -> Vec<&'static str> {
    FORMATS.iter().map(|f| f.name()).collect()
}

/// One format of the registry as `asperity topo formats` lists it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FormatInfo {
    /// The name `--format` takes.
    pub name: &'static str,
    /// File name endings it is known by (lower case, no dot); empty when only its content tells it.
    pub extensions: &'static [&'static str],
    /// `"map"` or `"profile"`.
    pub kind: &'static str,
    /// The instrument or software that writes it.
    pub instrument: &'static str,
    /// What is read from it.
    pub reads: &'static str,
}

/// The instrument and what is read, for each format's name (`topo formats`; `docs/formats.md`
/// says more).
const ABOUT: &[(&str, &str, &str)] = &[
    ("npy", "NumPy array", "the 2-D array (ny, nx); size and unit from the options"),
    ("gwy", "Gwyddion native", "every data field, its size and units"),
    ("nanoscope", "Bruker / Veeco NanoScope", "every channel through its Z scale chain; default Height"),
    ("nid", "Nanosurf", "the topography channels (length units)"),
    ("mi", "Agilent / Molecular Imaging PicoView", "every buffer, scaled to its range"),
    ("x3p", "ISO 25178-71 / ISO 5436-2", "the height layer; invalid points missing"),
    ("npz", "NumPy archive", "each 2-D array a channel; size and unit from the options"),
    ("netcdf", "NetCDF classic (SurfaceTopography, contact.engineering)", "heights, length, unit; mask missing"),
    (
        "datx",
        "Zygo Mx (MetroPro, Mx)",
        "/Data/Surface in metres (fringes × wavelength × scale factor), lateral resolution; no-data missing",
    ),
    ("hdf5", "HDF5", "each 2-D dataset at the root; size and unit from the options"),
    ("mat", "MATLAB level 5", "each 2-D real variable; size and unit from the options"),
    ("ibw", "Igor binary wave (Asylum Research)", "every layer; its unit when stated"),
    ("metropro", "Zygo MetroPro", "the phase map as heights, lateral resolution; invalid phase missing"),
    ("sur", "Digital Surf / MountainsMap", "the first object in its units; special points missing"),
    ("al3d", "Alicona InfiniteFocus", "the depth image, pixel size; invalid pixels missing"),
    ("opd", "Bruker / Wyko Vision", "the height array × wavelength, pixel size"),
    ("mnt", "Digital Surf Mountains document", "every measured surface in a length unit; mask missing"),
    (
        "mdt",
        "NT-MDT (Nova, Solver, Ntegra)",
        "the 2-D images of MDA frames in their units; a frame not in a length unit is never heights",
    ),
    ("opdx", "Bruker Dektak OPDx (Vision64)", "the height profile"),
    ("plu", "Sensofar", "topography layers in µm; 1000001 missing"),
    ("frt", "FRT MicroProf", "the topography block; stored 1 missing"),
    ("tmd", "TrueMap (TrueGage)", "one channel in mm"),
    ("wsxm", "WSxM (Nanotec)", "one image, size and Z amplitude"),
    ("bcr", "BCR-STM / BCRF (SPIP)", "one channel, its units; void values missing"),
    (
        "jpk",
        "JPK Instruments (.jpk scans, QI images)",
        "each channel in its default slot (calibrated height); invalid pixels missing",
    ),
    ("ps", "Park Systems (XEI)", "the measurement tags (not the preview image)"),
    ("hgt", "SRTM elevation tile (NASA)", "heights in metres; voids missing; no physical size (1° is about 111 km)"),
    ("mitutoyo", "Mitutoyo SurfTest Excel export", "positions and heights, their units"),
    ("nmm", "Nanomeasuring Machine (SIOS), zip of .dat and .dsc", "the height -Lz+Az along x (Lx) in metres"),
    ("gsf", "Gwyddion Simple Field", "the field, its size and units"),
    ("sdf", "ISO 25178-71 Surface Data File", "the field and its scales; BAD missing"),
    ("gwyddion-txt", "Gwyddion ASCII export with its header", "each channel, its size and units"),
    ("dektak", "Bruker Dektak CSV export", "the profile in its columns' units"),
    ("hfm", "HFM line profile", "the profile, its units; invalid points missing"),
    ("xyz", "x y z points on a regular grid", "the grid; no units (from the options)"),
    ("profile", "two-column line profile (stylus exports, CSV)", "the profile, units from the column names"),
    (
        "matrix",
        "plain-text matrix, with or without a header",
        "one row of heights per line; a header's grid, size and units",
    ),
];

/// Every format of the registry, in the order detection tries them.
pub fn formats() -> Vec<FormatInfo> {
    FORMATS
        .iter()
        .map(|f| {
            let (_, instrument, reads) =
                ABOUT.iter().find(|(name, ..)| *name == f.name()).copied().unwrap_or((f.name(), "", ""));
            let kind = match f {
                Reader::Map(_) => "map",
                Reader::Profile(_) => "profile",
            };
            FormatInfo { name: f.name(), extensions: f.extensions(), kind, instrument, reads }
        })
        .collect()
}

/// The format of the file at `path` with contents `bytes`, told from its leading bytes, else
/// from the ending of `name` (the file's or the member's name, less `.gz`); and whether
/// `--format` forced it.
fn detect(path: &Path, name: &str, bytes: &[u8], forced: Option<&str>) -> Result<(Reader, bool)> {
    if let Some(name) = forced {
        return FORMATS
            .iter()
            .copied()
            .find(|f| f.name() == name)
            .map(|f| (f, true))
            .ok_or_else(|| Error::invalid("--format", format!("unknown format '{name}' ({FORMATS_POINTER})")));
    }
    let head = &bytes[..bytes.len().min(4096)];
    let ext = Path::new(name).extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if let Some(reason) = near_miss(head, &ext) {
        return Err(Error::file(path, reason));
    }
    if let Some(f) = FORMATS.iter().copied().find(|f| f.sniff(head)) {
        return Ok((f, false));
    }
    if let Some(f) = FORMATS.iter().copied().find(|f| f.sniff_all(bytes)) {
        return Ok((f, false));
    }
    if let Some(f) = FORMATS.iter().copied().find(|f| f.extensions().contains(&ext.as_str())) {
        return Ok((f, false));
    }
    if container::is_zip(bytes) {
        return Err(Error::file(
            path,
            format!(
                "a zip container, not one topography: name a member as {}#MEMBER ('asperity topo info {}' lists them)",
                path.display(),
                path.display()
            ),
        ));
    }
    Err(Error::file(path, format!("not a topography file asperity can read ({FORMATS_POINTER})")))
}

/// Where a refusal sends the user for the formats asperity reads.
const FORMATS_POINTER: &str = "'asperity topo formats' lists the formats it reads";

/// Why a file of a format asperity knows of but does not read is refused, told from its head
/// or its extension (lower case).
fn near_miss(head: &[u8], ext: &str) -> Option<String> {
    if head.starts_with(b"GWYO") {
        return Some("a Gwyddion 1 file (magic GWYO), not read: re-save it in Gwyddion 2 (.gwy)".into());
    }
    if ext == "nms" {
        return Some(
            "a Nanofocus .nms file, not read: it states its point spacing without a unit (SurfaceTopography \
             assumes mm), and asperity does not guess units; export it as .sur or .x3p"
                .into(),
        );
    }
    None
}

/// Read the file at `path` and decode all its channels (within the default [`Limits`]);
/// returns the format's name with them. A line profile has no channels: it is refused.
pub fn read_channels(path: &Path, format: Option<&str>) -> Result<(&'static str, Vec<Channel>)> {
    match decode(path, format, &Limits::default())?.1 {
        Decoded::Maps(fmt, channels) => Ok((fmt.name(), channels)),
        Decoded::Profile(_, p) => Err(Error::file(
            path,
            format!("a line profile ({} points along x), not a map of channels", p.heights.len()),
        )),
    }
}

/// Whether `--format` forced the format of the file at `path` (or `archive#member`, gzip data
/// or not), and what the file holds, each grid within `limits`.
fn decode(path: &Path, format: Option<&str>, limits: &Limits) -> Result<(bool, Decoded)> {
    let (bytes, name) = container::load(path, limits)?;
    decode_bytes(path, &name, &bytes, format, limits)
}

/// [`decode`] of `bytes`, the content of `path` whose format `name`'s ending may tell.
fn decode_bytes(
    path: &Path,
    name: &str,
    bytes: &[u8],
    format: Option<&str>,
    limits: &Limits,
) -> Result<(bool, Decoded)> {
    let (reader, forced) = detect(path, name, bytes, format)?;
    let decoded = match reader {
        Reader::Map(fmt) => {
            let channels = fmt.read_within(bytes, limits).map_err(|reason| Error::file(path, reason))?;
            if channels.is_empty() {
                return Err(Error::file(path, "the file holds no data channel"));
            }
            if let Some(reason) = channels.iter().find_map(|c| limits.check_grid(c.data.ncols(), c.data.nrows()).err())
            {
                return Err(Error::file(path, reason));
            }
            Decoded::Maps(fmt, channels)
        }
        Reader::Profile(fmt) => {
            let data = fmt.read_within(bytes, limits).map_err(|reason| Error::file(path, reason))?;
            limits.check_grid(data.heights.len(), 1).map_err(|reason| Error::file(path, reason))?;
            Decoded::Profile(fmt, data)
        }
    };
    Ok((forced, decoded))
}

/// One member of a zip container and what it holds.
#[derive(Debug, Clone, PartialEq)]
pub struct Member {
    /// Its path inside the archive, as `archive.zip#member` names it.
    pub name: String,
    /// What it holds, or the reason it is not read as a topography.
    pub content: std::result::Result<MemberContent, String>,
}

/// What a container's member holds.
#[derive(Debug, Clone, PartialEq)]
pub struct MemberContent {
    /// The format that reads it.
    pub format: &'static str,
    /// `"map"` or `"profile"`.
    pub kind: &'static str,
    /// Its grid (nx, ny) (the first channel's, for a map of several); a profile's points and 1.
    pub grid: (usize, usize),
}

/// The members of the zip container at `path`, each read within `limits`; `None` when the
/// file is not a container (a format reads it, or `path` names a member as `archive#member`).
pub fn container_members(path: &Path, limits: &Limits) -> Result<Option<Vec<Member>>> {
    use std::io::Read;
    if container::split(path).is_some() || !path.metadata().is_ok_and(|m| m.is_file()) {
        return Ok(None);
    }
    // Only a zip, or gzip data, can be a container: other files are read once, by the reader.
    let mut head = [0u8; 4];
    let n = std::fs::File::open(path).and_then(|mut f| f.read(&mut head)).map_err(|e| Error::io(path, e))?;
    if !(container::is_zip(&head[..n]) || gzip::is_gzip(&head[..n])) {
        return Ok(None);
    }
    let (zip, name) = container::load(path, limits)?;
    if !container::is_zip(&zip) || detect(path, &name, &zip, None).is_ok() {
        return Ok(None);
    }
    let mut archive = container::Archive::open(&zip).map_err(|reason| Error::file(path, reason))?;
    let names = archive.members().map_err(|reason| Error::file(path, reason))?;
    let members = names
        .into_iter()
        .map(|name| {
            let member = PathBuf::from(format!("{}#{name}", path.display()));
            let content = archive
                .read(&name, limits)
                .and_then(|bytes| gzip::unwrap(bytes, name.clone(), limits))
                .and_then(|(bytes, inner)| {
                    let (_, decoded) = decode_bytes(&member, &inner, &bytes, None, limits).map_err(reason)?;
                    Ok(match decoded {
                        Decoded::Maps(fmt, channels) => {
                            let grid = (channels[0].data.ncols(), channels[0].data.nrows());
                            MemberContent { format: fmt.name(), kind: "map", grid }
                        }
                        Decoded::Profile(fmt, data) => {
                            MemberContent { format: fmt.name(), kind: "profile", grid: (data.heights.len(), 1) }
                        }
                    })
                });
            Member { name, content }
        })
        .collect();
    Ok(Some(members))
}

/// The reason of a file's error, without the path a listing already shows.
fn reason(e: Error) -> String {
    match e {
        Error::File { reason, .. } => reason,
        e => e.to_string(),
    }
}

/// Read one channel of the file at `path` as a 2-D map in metres; a line profile is refused
/// naming the file ([`read_listing`]).
pub fn read(path: &Path, opts: &ReadOptions) -> Result<Topography> {
    read_listing(path, opts).map(|(topo, _)| topo)
}

/// Read one channel of the file at `path` as a 2-D map in metres, with the names of all the
/// file's channels. The one gate of what needs a map (contact, sliding, the study): a line
/// profile is refused naming the file, before any option is applied to it, and never reshaped
/// into a map.
pub fn read_listing(path: &Path, opts: &ReadOptions) -> Result<(Topography, Vec<String>)> {
    match decode(path, opts.format.as_deref(), &opts.limits)? {
        (_, Decoded::Maps(fmt, channels)) => map(path, fmt, channels, opts),
        (forced, Decoded::Profile(_, data)) => {
            decided(path, forced, &data)?;
            Err(Error::file(
                path,
                format!(
                    "a line profile ({} points along x), not a 2-D map: contact, slide and a study need a 2-D map of heights \
                     (topo info, topo psd and topo convert read profiles)",
                    data.heights.len()
                ),
            ))
        }
    }
}

/// Read the file at `path` as what it holds, a 2-D map (one channel, in metres) or a line
/// profile, with the names of all its channels.
pub fn read_any(path: &Path, opts: &ReadOptions) -> Result<(AnyTopography, Vec<String>)> {
    any(path, decode(path, opts.format.as_deref(), &opts.limits)?, opts)
}

/// [`read_any`] of `bytes`, the content of a file named `name`, without the file: gzip data
/// inflated, the format told from the content, then from `name`'s ending, unless `opts.format`
/// names it; errors name `name`. What the fuzzing targets (`fuzz/`) read their inputs with.
pub fn read_any_bytes(name: &str, bytes: Vec<u8>, opts: &ReadOptions) -> Result<(AnyTopography, Vec<String>)> {
    let path = Path::new(name);
    let (bytes, inner) =
        gzip::unwrap(bytes, name.to_string(), &opts.limits).map_err(|reason| Error::file(path, reason))?;
    any(path, decode_bytes(path, &inner, &bytes, opts.format.as_deref(), &opts.limits)?, opts)
}

/// What `decoded`, read from `path`, holds: a map (one channel, in metres) or a line profile.
fn any(path: &Path, decoded: (bool, Decoded), opts: &ReadOptions) -> Result<(AnyTopography, Vec<String>)> {
    match decoded {
        (_, Decoded::Maps(fmt, channels)) => {
            map(path, fmt, channels, opts).map(|(map, names)| (AnyTopography::Map(map), names))
        }
        (forced, Decoded::Profile(fmt, data)) => {
            decided(path, forced, &data)?;
            let names = vec![data.name.clone()];
            profile(path, fmt.name(), data, opts).map(|p| (AnyTopography::Profile(p), names))
        }
    }
}

/// A two-column table whose content leaves open whether it is a profile or a map two points
/// wide is refused unless `--format` said which.
fn decided(path: &Path, forced: bool, data: &ProfileData) -> Result<()> {
    if forced || data.decided {
        return Ok(());
    }
    Err(Error::file(
        path,
        format!(
            "a two-column table of {} rows could be a line profile or a map 2 points wide: say which with \
             --format profile or --format matrix",
            data.heights.len()
        ),
    ))
}

/// The line profile of `data` read from `path` by `format`, positions and heights in metres
/// when their units are known: the file's, else `--position-unit` and `--height-unit` for what
/// the file leaves without, on the grid the header states when the positions agree with it
/// ([`Profile::adopt_stated_step`]).
fn profile(path: &Path, format: &str, data: ProfileData, opts: &ReadOptions) -> Result<Profile> {
    if opts.physical_size.is_some() {
        return Err(Error::invalid(
            "--size",
            format!("{} is a line profile: its positions give its length", path.display()),
        ));
    }
    if let Some(c) = opts.channel.as_deref().filter(|&c| c != data.name && c != "0") {
        return Err(Error::file(path, format!("no channel '{c}' (channels: '{}')", data.name)));
    }
    // A unit the user gives applies where the file states none; the heights' to the positions
    // too unless --position-unit gives theirs (SurfaceTopography's one unit of a line scan).
    let given = |option: &str, unit: Option<&str>, stated: bool, what: &str| -> Result<Option<(String, f64)>> {
        let Some(u) = unit else { return Ok(None) };
        if stated {
            return Err(Error::invalid(option, format!("{} states the unit of its {what}", path.display())));
        }
        let metres = metres_per(u).ok_or_else(|| Error::invalid(option, format!("'{u}' is not a length unit")))?;
        Ok(Some((u.to_string(), metres)))
    };
    let (states_x, states_z) = (data.position_unit.is_some(), data.height_unit.is_some());
    let z_user = given(
        "--height-unit",
        opts.height_unit.as_deref(),
        states_z && (states_x || opts.position_unit.is_some()),
        "heights",
    )?;
    let x_user = match given("--position-unit", opts.position_unit.as_deref(), states_x, "positions")? {
        Some(u) => Some(u),
        None if states_x => None,
        None => given("--height-unit", opts.height_unit.as_deref(), false, "positions")?,
    };
    // A stated unit is a length (the readers take only those); the user's applies to what the
    // file leaves without one.
    let unit = |stated: Option<String>, user: Option<(String, f64)>| match stated {
        Some(u) => {
            let metres = columns::metres_per(&u).expect("readers state length units only");
            (Some(u), Some(metres))
        }
        None => (user.as_ref().map(|(u, _)| u.clone()), user.as_ref().map(|(_, m)| *m)),
    };
    let (position_unit, x_scale) = unit(data.position_unit, x_user);
    let (height_unit, z_scale) = unit(data.height_unit, z_user);
    let mut p = Profile::new(data.positions, data.heights).map_err(|reason| Error::file(path, reason))?;
    if let Some(stated) = data.stated_step.filter(|_| p.step().is_none()) {
        p.adopt_stated_step(stated);
    }
    p.scale(x_scale.unwrap_or(1.0), z_scale.unwrap_or(1.0));
    p.require_representable().map_err(|reason| Error::file(path, reason))?;
    if x_scale.is_some() {
        stated_side(p.length(), p.points()).map_err(|reason| {
            let length = quantity::show(p.length(), &quantity::LENGTH);
            Error::file(path, format!("the length {length} its positions state: {reason}"))
        })?;
    }
    p.position_unit_known = x_scale.is_some();
    p.height_unit_known = z_scale.is_some();
    p.position_unit = position_unit;
    p.channel = data.name;
    p.provenance = Provenance { file: Some(path.to_path_buf()), format: format.to_string(), height_unit };
    Ok(p)
}

/// One channel of a map file as a topography in metres, with the names of all its channels.
fn map(
    path: &Path,
    fmt: &dyn Format,
    mut channels: Vec<Channel>,
    opts: &ReadOptions,
) -> Result<(Topography, Vec<String>)> {
    let names = channels.iter().map(|c| c.name.clone()).collect();
    let index = choose_channel(&channels, opts.channel.as_deref()).map_err(|r| Error::file(path, r))?;
    if opts.channel.is_none() {
        no_heights(&channels[index], &channels).map_err(|r| Error::file(path, r))?;
    }
    let mut ch = channels.swap_remove(index);

    let physical_size = match (ch.physical_size, opts.physical_size) {
        (_, Some((lx, ly))) if !(lx > 0.0 && ly > 0.0 && lx.is_finite() && ly.is_finite()) => {
            return Err(Error::invalid("--size", format!("sizes must be positive and finite, got {lx},{ly}")));
        }
        (Some(file), Some(user)) if !same_size(file, user) => {
            return Err(Error::invalid(
                "--size",
                format!(
                    "{},{} m does not match the size {},{} m stated in {}",
                    user.0,
                    user.1,
                    file.0,
                    file.1,
                    path.display()
                ),
            ));
        }
        (Some(file), _) => Some(file),
        (None, user) => user,
    };
    if let Some(size) = ch.physical_size {
        stated_size(fmt, size, (ch.data.ncols(), ch.data.nrows())).map_err(|reason| Error::file(path, reason))?;
    }
    if fmt.is_bare() && physical_size.is_none() {
        return Err(Error::file(path, "a bare array carries no physical size: give it with --size LX[,LY] (metres)"));
    }
    if opts.position_unit.is_some() {
        return Err(Error::invalid(
            "--position-unit",
            format!("{} is a 2-D map: its lateral size comes from the file or --size", path.display()),
        ));
    }
    // The user's height unit (metres for a bare array) applies to a channel that states none.
    if let Some(unit) = opts.height_unit.as_deref().or(fmt.is_bare().then_some("m")) {
        if ch.unit.is_some() {
            return Err(Error::invalid("--height-unit", format!("{} states its own height unit", path.display())));
        }
        let scale = metres_per(unit)
            .ok_or_else(|| Error::invalid("--height-unit", format!("'{unit}' is not a length unit")))?;
        ch.data.mapv_inplace(|h| h * scale);
        ch.unit = Some(unit.to_string());
    }
    // Readers convert a channel in a length unit to metres; any other is as stored.
    let height_unit_known = ch.unit.as_deref().and_then(metres_per).is_some();
    let topo = Topography {
        heights: ch.data,
        physical_size,
        periodic: false,
        height_unit_known,
        channel: ch.name,
        provenance: Provenance { file: Some(path.to_path_buf()), format: fmt.name().to_string(), height_unit: ch.unit },
    };
    topo.require_representable()?;
    Ok((topo, names))
}

/// A physical size (lx, ly) [m] that a file of `fmt` states for a grid of (nx, ny) points,
/// judged as `--size` and `--pixel-size` are ([`stated_side`]); the reason names the header's
/// fields and the value.
fn stated_size(fmt: &dyn Format, (lx, ly): (f64, f64), (nx, ny): (usize, usize)) -> std::result::Result<(), String> {
    stated_side(lx, nx).and(stated_side(ly, ny)).map_err(|reason| {
        format!(
            "the physical size {} × {} stated by {}: {reason}",
            quantity::show(lx, &quantity::LENGTH),
            quantity::show(ly, &quantity::LENGTH),
            fmt.size_field()
        )
    })
}

/// A length `l` [m] read from a file, `steps` pixels long: plausible as a measured window's side,
/// and each step as a pixel.
fn stated_side(l: f64, steps: usize) -> std::result::Result<(), String> {
    plausible::window(l, Spelling::CommandLine)?;
    let pixel = l / steps as f64;
    plausible::pixel(pixel, Spelling::CommandLine)
        .map(drop)
        .map_err(|e| format!("a pixel of {l:e} m / {steps} points: {e}"))
}

/// Sizes agree to 1e-6 relative (files round their sizes when they print them).
fn same_size(a: (f64, f64), b: (f64, f64)) -> bool {
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-6 * x.abs().max(y.abs());
    close(a.0, b.0) && close(a.1, b.1)
}

/// Refuse `default`, the channel chosen when none is named, when it states a unit that is not a
/// length (then none of `channels` holds heights): a current in nA is never heights. The reason
/// lists every channel with its unit.
fn no_heights(default: &Channel, channels: &[Channel]) -> std::result::Result<(), String> {
    match default.unit.as_deref() {
        Some(u) if !default.is_height && metres_per(u).is_none() => {
            let list = channels
                .iter()
                .map(|c| {
                    format!(
                        "{} ({})",
                        quantity::quoted(&c.name),
                        quantity::printable(c.unit.as_deref().unwrap_or("no unit"))
                    )
                })
                .collect::<Vec<_>>()
                .join(", ");
            Err(format!(
                "no channel holds heights (a length unit): {list}; --channel NAME reads one as stored, not as a topography in metres"
            ))
        }
        _ => Ok(()),
    }
}

/// Index of the channel named (or numbered) by `wanted`, or else of the default channel.
///
/// SurfaceTopography and Gwyddion both default to the first channel in file order (of those in
/// a length unit, for SurfaceTopography). A length unit alone does not make a topography (a
/// NanoScope `AmplitudeError` is in nm), so the default ranks the channels, file order within
/// a rank: the topography the feedback recorded (`Height`, `Topography`, Nanosurf `Z-Axis`),
/// then a height sensor's (`ZSensor`, `Height Sensor`, `Z-AxisSensor`), then any other channel
/// in a length unit, then the first channel.
fn choose_channel(channels: &[Channel], wanted: Option<&str>) -> std::result::Result<usize, String> {
    let names = || channels.iter().map(|c| format!("'{}'", c.name)).collect::<Vec<_>>().join(", ");
    let rank = |c: &Channel| {
        let name = c.name.to_lowercase();
        let topography = ["height", "topograph", "z-axis"].iter().any(|t| name.contains(t))
            || name == "z"
            || name.contains("zsensor");
        match (c.is_height, topography, name.contains("sensor")) {
            (true, true, false) => 0,
            (true, true, true) => 1,
            (true, false, _) => 2,
            (false, ..) => 3,
        }
    };
    match wanted {
        None => Ok((0..channels.len()).min_by_key(|&i| (rank(&channels[i]), i)).unwrap_or(0)),
        Some(w) => channels
            .iter()
            .position(|c| c.name == w)
            .or_else(|| w.parse::<usize>().ok().filter(|&i| i < channels.len()))
            .ok_or_else(|| format!("no channel '{w}' (channels: {})", names())),
    }
}

#[cfg(test)]
mod tests {
    use super::text::testing;
    use super::*;

    #[test]
    fn every_format_is_described_once() {
        let formats = formats();
        assert_eq!(formats.len(), ABOUT.len());
        for f in &formats {
            assert!(!f.instrument.is_empty() && !f.reads.is_empty(), "{} is not described", f.name);
        }
        let hgt = formats.iter().find(|f| f.name == "hgt").unwrap();
        assert_eq!((hgt.extensions, hgt.kind), (&["hgt"][..], "map"));
        assert_eq!(formats.iter().find(|f| f.name == "nmm").unwrap().kind, "profile");
    }

    #[test]
    fn exactly_one_format_claims_each_sample() {
        let expected = [
            ("gwyddion-export-english.txt", "gwyddion-txt"),
            ("matrix-3.txt", "gwyddion-txt"),
            ("matrix-6.txt", "gwyddion-txt"),
            ("xyz-1.txt", "xyz"),
            ("xyz-2.txt", "xyz"),
            ("sdf-1.sdf", "sdf"),
            ("wafer-roughness.gsf", "gsf"),
            ("example-2d.npy", "npy"),
            ("xy-1.txt", "profile"),
            ("xy-2.txt", "profile"),
            ("xy-5.txt", "profile"),
            ("nonuniform.asc", "profile"),
            ("opdx-3.txt", "profile"),
            ("csv-1.csv", "profile"),
            ("csv-2.csv", "profile"),
            ("csv-3.csv", "profile"),
            ("dektak-1.csv", "dektak"),
        ];
        for (file, format) in expected {
            let bytes = testing::sample(file);
            let head = &bytes[..bytes.len().min(4096)];
            let claims: Vec<&str> = FORMATS.iter().filter(|f| f.sniff(head)).map(|f| f.name()).collect();
            assert_eq!(claims, [format], "{file}");
        }
        let headless_matrix = b"1 2 3 4\n5 6 7 8\n";
        let claims: Vec<&str> = FORMATS.iter().filter(|f| f.sniff(headless_matrix)).map(|f| f.name()).collect();
        assert_eq!(claims, ["matrix"]);
        for file in ["nonsense_txt_file.txt", "wrongnpyfile.npy"] {
            let bytes = testing::sample(file);
            assert!(FORMATS.iter().all(|f| !f.sniff(&bytes)), "{file}");
        }
    }
}
