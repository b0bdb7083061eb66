//! pbrt scene files (pbrt-v4, and pbrt-v3 where it differs), `.pbrt` or
//! gzip-compressed `.pbrt.gz`, as Sahara scenes.
//!
//! The reader is written here rather than taken from a crate: no
//! maintained Rust crate parses the pbrt-v4 format, and the format's edge
//! (errors with places, warnings with counts) is what a reader must own.
//!
//! - [`lexer`]: tokens with line and column; [`params`]: typed parameter
//!   lists; [`parser`]: the directives, graphics state and transforms,
//!   into a [`description`] of the file.
//! - The mapping to Sahara's [`SceneDescription`]: [`build`] (camera,
//!   settings, shapes, objects and instances), [`shapes`] (with [`subdivision`]), [`materials`] (the
//!   one material table), [`textures`], [`lights`] (with [`envmap`]),
//!   with what the Mitsuba reader shares in [`crate::common`] (spectra
//!   to RGB, tints and blends, warnings, positions).
//! - Every error is one line, `file: line L: column C: what`; everything
//!   Sahara approximates or leaves out is a warning, one per kind with a
//!   count, naming the first place.
//!
//! What is supported and how each feature maps is documented in
//! `docs/pbrt.md` at the repository root.

mod build;
mod declarations;
mod envmap;
mod lexer;
mod lights;
mod materials;
mod measured_media;
mod media;
mod params;
mod parser;
mod shapes;
mod subdivision;
mod textures;

#[cfg(test)]
mod tests;

use std::path::Path;

use sahara_readers::FormatError;

use crate::common::warnings::Warnings;
use crate::description::SceneDescription;

/// True if `path` names a pbrt file (`.pbrt` or `.pbrt.gz`, any case).
pub(crate) fn is_pbrt_path(path: &Path) -> bool {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    name.ends_with(".pbrt") || name.ends_with(".pbrt.gz")
}

/// Reads a pbrt file (and the files it includes, meshes and images) as
/// a scene description.
pub(crate) fn read_pbrt(path: &Path) -> Result<SceneDescription, FormatError> {
    let mut w = Warnings::default();
    let desc = parser::parse_file(path, &mut w)?;
    let folder = path.parent().unwrap_or(Path::new(""));
    let name = path.display().to_string();
    Ok(described(build::build(&desc, &name, folder, &mut w)?, w))
}

/// Parses and describes a pbrt file held in memory; `name` is used in
/// messages and relative file names resolve against `folder`.
pub(crate) fn read_pbrt_text(
    text: &[u8],
    name: &str,
    folder: &Path,
) -> Result<SceneDescription, FormatError> {
    let mut w = Warnings::default();
    let desc = parser::parse_bytes(text.to_vec(), name, folder, &mut w)?;
    Ok(described(build::build(&desc, name, folder, &mut w)?, w))
}

/// The description with the reader's warnings, one line per kind.
fn described(mut desc: SceneDescription, w: Warnings) -> SceneDescription {
    desc.warnings = w.into_lines();
    desc
}
