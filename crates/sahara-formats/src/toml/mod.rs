//! Sahara's own scene files (TOML, documented in `docs/scene-format.md`)
//! as scene descriptions.
//!
//! - [`raw`]: the TOML shape serde reads; [`resolve`]: its checks, with
//!   positioned errors, into a [`file::SceneFile`] ([`file`]: the checked
//!   file's types);
//! - [`describe`]: the checked file as a [`SceneDescription`] (with
//!   [`placement`] for transforms and motion).

mod describe;
mod file;
mod placement;
mod raw;
mod resolve;

#[cfg(test)]
mod tests;
// The temporary folders of `sahara-readers`' tests (one copy of the helpers).
#[cfg(test)]
#[allow(dead_code)]
#[path = "../../../sahara-readers/tests/readers/common.rs"]
mod test_helpers;

use std::path::Path;

use crate::description::SceneDescription;
use crate::FormatError;

pub(crate) use describe::read_scene;

/// Parses and checks scene TOML held in memory and describes it; `name` is
/// used in messages and relative file names resolve against `folder`.
pub(crate) fn read_scene_text(
    text: &str,
    name: &str,
    folder: &Path,
) -> Result<SceneDescription, FormatError> {
    describe::describe(&file::parse_scene_file(text, name, folder)?, name)
}
