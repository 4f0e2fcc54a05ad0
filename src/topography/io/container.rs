//! Containers: a zip of several topography files (as contact.engineering exports them, or as
//! a user packs a series of scans). A layer in front of the registry: a member is named
//! `archive.zip#member` (its path inside the archive) and read as a file of its own, gzip and
//! format detection included; the archive's own metadata (`meta.yml`) is not applied.
//!
//! Members are inflated as streams within the input limits ([`super::gzip::read_within`]), one
//! at a time; their names are only looked up in the archive, never used as paths, and a name
//! that would leave a folder (`../x`, `/etc/x`) is refused.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::io::{Cursor, Read};
use std::path::{Path, PathBuf};

use super::gzip;
use crate::error::{Error, Result};
use crate::limits::Limits;

/// The magic bytes of a zip file's first local header.
const ZIP_MAGIC: &[u8] = b"PK\x03\x04";

/// Whether `bytes` start as a zip archive.
pub(super) fn is_zip(bytes: &[u8]) -> bool {
    bytes.starts_with(ZIP_MAGIC)
}

/// The archive and member that `path` names as `archive#member`: `None` when `path` is a file
/// itself (a name may hold `#`) or no prefix before a `#` is one.
pub(super) fn split(path: &Path) -> Option<(PathBuf, String)> {
    if path.symlink_metadata().is_ok() {
        return None;
    }
    let text = path.to_str()?;
    text.match_indices('#')
        .map(|(i, _)| (Path::new(&text[..i]), &text[i + 1..]))
        .find(|(archive, member)| archive.is_file() && !member.is_empty())
        .map(|(archive, member)| (archive.to_path_buf(), member.to_string()))
}

/// The bytes at `path` and the name their format is told from: the file's, or the member's
/// of `archive#member`; gzip data inflated (and `.gz` dropped from the name).
pub(super) fn load(path: &Path, limits: &Limits) -> Result<(Vec<u8>, String)> {
    let (bytes, name) = match split(path) {
        Some((archive, member)) => {
            // The archive may itself be gzip data (`scans.zip.gz#member`), as `topo info` lists it.
            let (zip, _) = gzip::unwrap(limits.read_file(&archive)?, String::new(), limits)
                .map_err(|reason| Error::file(&archive, reason))?;
            (member_bytes(&zip, &member, limits).map_err(|reason| Error::file(path, reason))?, member)
        }
        None => {
            let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            (limits.read_file(path)?, name)
        }
    };
    gzip::unwrap(bytes, name, limits).map_err(|reason| Error::file(path, reason))
}

/// A zip archive open for reading its members: its central directory parsed once, so that
/// listing and reading members is linear in their number.
pub(super) struct Archive<'a>(zip::ZipArchive<Cursor<&'a [u8]>>);

impl<'a> Archive<'a> {
    /// The archive `zip`, refused when two entries share a name (which one is meant would be
    /// ambiguous) or share bytes (overlapping entries, a zip bomb's way of inflating one
    /// block many times over).
    pub(super) fn open(zip: &'a [u8]) -> std::result::Result<Self, String> {
        let mut archive =
            zip::ZipArchive::new(Cursor::new(zip)).map_err(|e| format!("not a readable zip archive: {e}"))?;
        if archive.has_duplicate_names() {
            let name = duplicate_name(zip, archive.central_directory_start()).unwrap_or_default();
            return Err(format!(
                "member {} appears twice in the archive: which one is meant is ambiguous",
                crate::quantity::quoted(&name)
            ));
        }
        if archive.has_overlapping_entries().map_err(|e| format!("not a readable zip archive: {e}"))? {
            return Err("members of the archive share their bytes (overlapping entries, as zip bombs are made): \
                        refused"
                .into());
        }
        Ok(Archive(archive))
    }

    /// The names of the archive's files (folders left out), in archive order; a name that
    /// would leave a folder is refused.
    pub(super) fn members(&mut self) -> std::result::Result<Vec<String>, String> {
        let mut names = Vec::new();
        for i in 0..self.0.len() {
            let file = self.0.by_index_raw(i).map_err(|e| format!("zip entry {i}: {e}"))?;
            if file.is_dir() {
                continue;
            }
            names.push(safe(&file)?);
        }
        Ok(names)
    }

    /// The inflated bytes of the member `name`, within `limits`: refused by its declared size
    /// before inflating, and never inflated past it (the zip reader stops there).
    pub(super) fn read(&mut self, name: &str, limits: &Limits) -> std::result::Result<Vec<u8>, String> {
        let quoted = crate::quantity::quoted(name);
        let Some(index) = self.0.index_for_name(name) else {
            let names = self.members().map(|n| n.join("', '")).unwrap_or_default();
            return Err(format!("no member {quoted} in the archive (members: '{names}')"));
        };
        let file = self.0.by_index(index).map_err(|e| format!("member {quoted}: {e}"))?;
        safe(&file)?;
        if file.is_dir() {
            return Err(format!("member {quoted} is a folder"));
        }
        if file.size() > limits.max_file_bytes() {
            return Err(format!(
                "member {quoted} declares {} bytes, more than the {} an input within the limit of {} points can \
                 need (raise it with --max-points)",
                file.size(),
                limits.max_file_bytes(),
                limits.max_points
            ));
        }
        // Room for what the member's compressed bytes can plausibly inflate to; past that the
        // buffer grows only with bytes actually inflated.
        let hint = file.compressed_size().saturating_mul(4).min(file.size());
        gzip::read_within(file, limits, hint).map_err(|e| format!("member {quoted}: {e}"))
    }
}

/// The first name that two entries of the central directory starting at `start` in `zip`
/// share (the parsed archive keeps only one of them).
fn duplicate_name(zip: &[u8], start: u64) -> Option<String> {
    let mut seen = std::collections::HashSet::new();
    let mut at = usize::try_from(start).ok()?;
    // Each entry: its signature, fixed fields, then name, extra field and comment (APPNOTE 4.3.12).
    while zip.get(at..at + 4)? == b"PK\x01\x02" {
        let u16_at = |i: usize| zip.get(at + i..at + i + 2).map(|b| usize::from(u16::from_le_bytes([b[0], b[1]])));
        let (name_len, extra, comment) = (u16_at(28)?, u16_at(30)?, u16_at(32)?);
        let name = zip.get(at + 46..at + 46 + name_len)?;
        if !seen.insert(name) {
            return Some(String::from_utf8_lossy(name).into_owned());
        }
        at += 46 + name_len + extra + comment;
    }
    None
}

/// The inflated bytes of the member `name` of the zip `zip`, within `limits` ([`Archive::read`]).
pub(super) fn member_bytes(zip: &[u8], name: &str, limits: &Limits) -> std::result::Result<Vec<u8>, String> {
    Archive::open(zip)?.read(name, limits)
}

/// Refuse a zip whose members inflate, together, past what an input within `limits` may hold
/// (a zip bomb), before a parser of the whole archive reads it: each member is inflated as a
/// stream and its bytes counted, never held.
pub(super) fn check_inflated(zip: &[u8], limits: &Limits) -> std::result::Result<(), String> {
    let cap = limits.max_file_bytes();
    let mut archive = Archive::open(zip)?.0;
    let mut total = 0u64;
    for i in 0..archive.len() {
        let file = archive.by_index(i).map_err(|e| format!("zip entry {i}: {e}"))?;
        let name = safe(&file)?;
        let left = cap - total;
        let n = std::io::copy(&mut file.take(left.saturating_add(1)), &mut std::io::sink())
            .map_err(|e| format!("member {}: {e}", crate::quantity::quoted(&name)))?;
        total += n;
        if total > cap {
            return Err(format!(
                "inflates past {cap} bytes, the most an input within the limit of {} points can need (raise it \
                 with --max-points)",
                limits.max_points
            ));
        }
    }
    Ok(())
}

/// The name of a member, refused when it is absolute or climbs out of the archive's folder.
fn safe<R: Read>(file: &zip::read::ZipFile<'_, R>) -> std::result::Result<String, String> {
    let name = file.name().map_err(|e| format!("a member's name: {e}"))?;
    // Absolute (`/x`, a backslash first, `C:x`), climbing (`..`) or holding NUL, whatever the zip crate
    // makes of it.
    let climbs = name.split(['/', '\\']).any(|c| c == "..");
    let absolute = name.starts_with(['/', '\\']) || name.as_bytes().get(1) == Some(&b':');
    match file.enclosed_name() {
        Some(_) if !climbs && !absolute && !name.contains('\0') => Ok(name.into_owned()),
        _ => Err(format!(
            "member {} has an unsafe name (absolute, or leaving the archive's folder): refused",
            crate::quantity::quoted(&name)
        )),
    }
}

#[cfg(test)]
mod tests {
    use std::io::Write;

    use super::*;

    fn zip_of(files: &[(&str, &[u8])]) -> Vec<u8> {
        let mut w = zip::ZipWriter::new(Cursor::new(Vec::new()));
        let opts = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
        for (name, content) in files {
            w.start_file(*name, opts).unwrap();
            w.write_all(content).unwrap();
        }
        w.finish().unwrap().into_inner()
    }

    #[test]
    fn members_are_listed_and_read() {
        let zip = zip_of(&[("a.txt", b"1 2\n3 4\n"), ("sub/b.txt", b"5 6\n")]);
        assert_eq!(Archive::open(&zip).unwrap().members().unwrap(), ["a.txt", "sub/b.txt"]);
        assert_eq!(member_bytes(&zip, "sub/b.txt", &Limits::default()).unwrap(), b"5 6\n");
        let e = member_bytes(&zip, "c.txt", &Limits::default()).unwrap_err();
        assert!(e.contains("no member 'c.txt'") && e.contains("'a.txt', 'sub/b.txt'"), "{e}");
    }

    #[test]
    fn path_tricks_and_bombs_are_refused() {
        let zip = zip_of(&[("../../etc/passwd", b"1 2\n"), ("/abs.txt", b"1 2\n")]);
        assert!(Archive::open(&zip).unwrap().members().unwrap_err().contains("unsafe name"));
        for name in ["../../etc/passwd", "/abs.txt"] {
            let e = member_bytes(&zip, name, &Limits::default()).unwrap_err();
            assert!(e.contains("unsafe name"), "{e}");
        }
        // 64 MiB of zeros in about 64 kB: inflating stops at the limit's bytes.
        let zeros = vec![0u8; 64 << 20];
        let bomb = zip_of(&[("bomb.txt", &zeros)]);
        assert!(bomb.len() < 1 << 20);
        let limits = Limits::new(1000, "--max-points").unwrap();
        let e = member_bytes(&bomb, "bomb.txt", &limits).unwrap_err();
        assert!(e.contains("declares 67108864 bytes") && e.contains("--max-points"), "{e}");
    }

    #[test]
    fn a_member_lying_about_its_size_stops_at_the_limit() {
        // Declared small in the central directory, inflating to 64 MiB: the stream is cut at
        // the limit whatever the header says.
        let zeros = vec![0u8; 64 << 20];
        let mut bomb = zip_of(&[("bomb.txt", &zeros)]);
        let cd = bomb.windows(4).rposition(|w| w == b"PK\x01\x02").unwrap();
        bomb[cd + 24..cd + 28].copy_from_slice(&16u32.to_le_bytes());
        let limits = Limits::new(1000, "--max-points").unwrap();
        let e = member_bytes(&bomb, "bomb.txt", &limits).unwrap_err();
        assert!(e.contains("member 'bomb.txt'"), "{e}");
        assert!(!e.contains("declares"), "{e}");
    }
}
