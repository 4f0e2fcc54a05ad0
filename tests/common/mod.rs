//! The instrument files the tests read, in `tests/data/` (its README gives each file's origin
//! and licence).

use std::path::{Path, PathBuf};

/// The folder of the test data.
pub fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data")
}

/// The path of the test data file `name`; a missing file fails the test with one line.
pub fn sample(name: &str) -> PathBuf {
    let path = data_dir().join(name);
    assert!(path.is_file(), "missing test data file {} (see tests/data/README.md)", path.display());
    path
}
