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

use std::fs;
use std::path::Path;

use sahara_readers::FormatError;

use crate::description::SceneDescription;
use file::SceneFile;

/// Reads a scene file as a description (meshes, textures and maps read
/// relative to it).
pub(crate) fn read_scene(path: &Path) -> Result<SceneDescription, FormatError> {
    describe::describe(&load_scene_file(path)?, &path.display().to_string())
}

/// Parses and checks scene TOML held in memory and describes it; `name` is
/// used in messages and relative file names resolve against `folder`.
pub(crate) fn read_scene_text(
    text: &str,
    name: &str,
    folder: &Path,
) -> Result<SceneDescription, FormatError> {
    describe::describe(&parse_scene_file(text, name, folder)?, name)
}

/// Reads and checks a scene file; paths in it are resolved relative to its folder.
pub(crate) fn load_scene_file(path: &Path) -> Result<SceneFile, FormatError> {
    let text = fs::read_to_string(path).map_err(|e| FormatError::io(path, e))?;
    let folder = path.parent().unwrap_or(Path::new(""));
    parse_scene_file(&text, &path.display().to_string(), folder)
}

/// Parses and checks scene TOML held in memory; `name` is used in errors, paths resolve against `folder`.
pub(crate) fn parse_scene_file(
    text: &str,
    name: &str,
    folder: &Path,
) -> Result<SceneFile, FormatError> {
    resolve::resolve(text, name, folder).map_err(sahara_readers::one_line)
}
