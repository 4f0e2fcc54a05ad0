//! The test data are in the repository: every file the manifest of `tests/data` lists is there.
//! A missing one fails here with one line naming all that are missing.

mod common;

#[test]
fn every_file_of_the_manifest_is_present() {
    let manifest = common::sample("manifest.json");
    let manifest: serde_json::Value = serde_json::from_slice(&std::fs::read(manifest).unwrap()).unwrap();
    let files: Vec<&str> = manifest["files"].as_array().unwrap().iter().map(|e| e["file"].as_str().unwrap()).collect();
    assert!(files.len() >= 20, "the manifest lists {} files", files.len());
    let missing: Vec<&&str> = files.iter().filter(|f| !common::data_dir().join(f).is_file()).collect();
    assert!(missing.is_empty(), "missing test data in tests/data (see its README): {missing:?}");
}
