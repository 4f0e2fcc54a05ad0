//! What the fuzzing targets run: asperity's readers on raw bytes, within small limits. A panic,
//! an abort, a hang, memory past libFuzzer's limit, or an error that is not one line is a
//! finding; any other outcome (a topography, a profile, a one-line error) is the reader's due.

use std::path::PathBuf;
use std::sync::OnceLock;

use asperity::limits::Limits;
use asperity::topography::io::{container_members, read_any, read_any_bytes, ReadOptions};

/// The largest grid the targets accept [points]: 512 × 512, the largest grid among the seed
/// files that is read in full, so that a header claiming more is refused, not allocated.
const MAX_POINTS: usize = 1 << 18;

/// The longest error a user should have to read [characters]: one line of a few hundred, with
/// the file's name and, when nothing was detected, the list of formats.
const LONGEST_ERROR: usize = 1000;

fn options(format: Option<&str>) -> ReadOptions {
    let limits = Limits::new(MAX_POINTS, "MAX_POINTS").expect("within the smallest grid");
    ReadOptions { format: format.map(str::to_string), limits, ..ReadOptions::default() }
}

/// Panic (a finding) unless `message` is one line of at most [`LONGEST_ERROR`] characters.
fn check_one_line(message: &str) {
    assert!(
        !message.is_empty() && !message.contains('\n') && message.chars().count() <= LONGEST_ERROR,
        "an error that is not one short line: {message:?}"
    );
}

/// Read `data` as the format named `format` (as `--format` names it), or as detected from the
/// content when `None`; gzip data are inflated first, as for a file.
pub fn read_as(format: Option<&str>, data: &[u8]) {
    if let Err(e) = read_any_bytes(format.unwrap_or("input"), data.to_vec(), &options(format)) {
        check_one_line(&e.to_string());
    }
}

/// Read `data` as a zip container: list its members, each decoded, and read each readable
/// one as `archive#member`. A container is read from a file, written here for each input.
pub fn read_container(data: &[u8]) {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    let dir = DIR.get_or_init(|| tempfile::tempdir().expect("a temporary folder"));
    let path = dir.path().join("input.zip");
    std::fs::write(&path, data).expect("the input written to the temporary folder");
    let members = match container_members(&path, &options(None).limits) {
        Ok(Some(members)) => members,
        Ok(None) => return,
        Err(e) => return check_one_line(&e.to_string()),
    };
    for member in members {
        match member.content {
            Ok(_) => {
                let named = PathBuf::from(format!("{}#{}", path.display(), member.name));
                if let Err(e) = read_any(&named, &options(None)) {
                    check_one_line(&e.to_string());
                }
            }
            Err(reason) => check_one_line(&reason),
        }
    }
}
