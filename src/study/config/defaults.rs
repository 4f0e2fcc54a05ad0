//! The default study, [`DEFAULT_STUDY`] (`src/study/default.toml`): what a study file's
//! missing sections, and the keys its sections leave out, are taken from.
//!
//! The sections take their defaults from here: it must import none of them, nor the study's
//! runner, `plot`, `report`, `cli` or `python`.

use serde::de::DeserializeOwned;

/// The default study, as `asperity run --print-default` prints it: three synthetic silicon
/// balls against synthetic wafers, silicon, 13 loads from 0.1 to 100 mN, two placeholder laws.
pub const DEFAULT_STUDY: &str = include_str!("../default.toml");

/// Section `name` of the default study (for `topography` and `law`, its array of tables).
pub(super) fn section<T: DeserializeOwned>(name: &str) -> T {
    let mut study: toml::Table = toml::from_str(DEFAULT_STUDY).expect("the default study parses");
    let section = study.remove(name).expect("the default study gives every section it defaults");
    section.try_into().expect("the default study's sections parse")
}
