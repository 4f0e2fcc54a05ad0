//! gzip (`.gz`): a layer in front of the registry, for any format. A compressed file (or
//! container member) is inflated as a stream, never past what an input within the limits may
//! hold, and the format is then detected from the inflated bytes and the name without `.gz`.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::io::Read;

use crate::limits::{check_memory, reserve, Limits};

/// The magic bytes of a gzip member (RFC 1952).
const MAGIC: &[u8] = b"\x1f\x8b";

/// The most a deflate stream inflates per byte (RFC 1951: 258 bytes per 2 bits, about 1032).
pub(super) const MAX_INFLATION: usize = 1032;

/// The bytes read as one chunk while inflating.
const CHUNK: usize = 64 << 10;

/// Whether `bytes` start as gzip data.
pub(super) fn is_gzip(bytes: &[u8]) -> bool {
    bytes.starts_with(MAGIC)
}

/// `bytes` inflated when they are gzip data (every member of a multi-member file), with `name`
/// less its `.gz` ending; as they are otherwise.
pub(super) fn unwrap(bytes: Vec<u8>, name: String, limits: &Limits) -> Result<(Vec<u8>, String), String> {
    if !is_gzip(&bytes) {
        return Ok((bytes, name));
    }
    let inflated = read_within(flate2::read::MultiGzDecoder::new(&bytes[..]), limits, bytes.len() as u64 * 4)
        .map_err(|e| format!("gzip: {e}"))?;
    let stem = match name.len().checked_sub(3) {
        Some(n) if name.is_char_boundary(n) && name[n..].eq_ignore_ascii_case(".gz") => name[..n].to_string(),
        _ => name,
    };
    Ok((inflated, stem))
}

/// Everything `reader` yields, as the bytes of one input file: refused once it passes
/// [`Limits::max_file_bytes`] (a decompression bomb stops there, having held at most that many
/// bytes) or the memory available. `hint` [bytes] is the room made beforehand.
pub(super) fn read_within(mut reader: impl Read, limits: &Limits, hint: u64) -> Result<Vec<u8>, String> {
    let cap = limits.max_file_bytes();
    let mut out = Vec::new();
    reserve(&mut out, usize::try_from(hint.min(cap)).unwrap_or(0), "the inflated bytes")?;
    let mut chunk = vec![0u8; CHUNK];
    loop {
        let n = match reader.read(&mut chunk) {
            Ok(0) => return Ok(out),
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e.to_string()),
        };
        let len = out.len() as u64 + n as u64;
        if len > cap {
            return Err(format!(
                "inflates past {cap} bytes, the most an input within the limit of {} points can need (raise it \
                 with --max-points)",
                limits.max_points
            ));
        }
        if out.len() + n > out.capacity() {
            // Grow by doubling, each step checked against the memory left: the bytes and their
            // decoded values, as for a file read whole.
            let room = (out.capacity() as u64 * 2).max(len).min(cap);
            check_memory(room.saturating_mul(2), &format!("inflating {room} bytes and decoding them"))?;
            let more = room as usize - out.len();
            reserve(&mut out, more, "the inflated bytes")?;
        }
        out.extend_from_slice(&chunk[..n]);
    }
}

#[cfg(test)]
mod tests {
    use std::io::Write;

    use super::*;

    fn gz(data: &[u8]) -> Vec<u8> {
        let mut w = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        w.write_all(data).unwrap();
        w.finish().unwrap()
    }

    #[test]
    fn inflates_and_strips_the_ending() {
        let (bytes, name) = unwrap(gz(b"1 2\n3 4\n"), "m.TXT.GZ".into(), &Limits::default()).unwrap();
        assert_eq!((bytes.as_slice(), name.as_str()), (&b"1 2\n3 4\n"[..], "m.TXT"));
        // Not gzip: as it was, name included.
        let (bytes, name) = unwrap(b"1 2".to_vec(), "a.gz".into(), &Limits::default()).unwrap();
        assert_eq!((bytes.as_slice(), name.as_str()), (&b"1 2"[..], "a.gz"));
        // Two members, as `cat a.gz b.gz` makes.
        let two = [gz(b"1 2\n"), gz(b"3 4\n")].concat();
        assert_eq!(unwrap(two, "m".into(), &Limits::default()).unwrap().0, b"1 2\n3 4\n");
    }

    #[test]
    fn a_bomb_stops_at_the_limit() {
        // 64 MiB of zeros in about 64 kB; a limit of 1000 points allows 16 MiB + 128 kB.
        let bomb = gz(&vec![0u8; 64 << 20]);
        assert!(bomb.len() < 1 << 20);
        let limits = Limits::new(1000, "--max-points").unwrap();
        let e = unwrap(bomb, "b.gz".into(), &limits).unwrap_err();
        assert!(e.contains(&format!("past {} bytes", limits.max_file_bytes())) && e.contains("--max-points"), "{e}");
        // Corrupt data: a reason, not a panic.
        let mut bad = gz(b"1 2\n3 4\n");
        bad.truncate(12);
        assert!(unwrap(bad, "t.gz".into(), &Limits::default()).unwrap_err().starts_with("gzip: "));
    }
}
