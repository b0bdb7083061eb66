//! Mitsuba scene files (`.xml`: Mitsuba 3, and 2.x and 0.x where they
//! differ only by name) as Sahara scenes.
//!
//! - [`xml`]: the file as a tree of elements with line and column
//!   (`roxmltree`); [`expand`]: `<include>`, `<default>` and `$name`
//!   ([`defaults`]), 0.x names; [`properties`]: an element as a typed
//!   object ([`spectra`] for colours, [`transform`] for transforms).
//! - The mapping to Sahara's [`SceneDescription`]: [`build`] (the walk)
//!   over [`builder`] (ids, what is made once), [`shapes`] (with
//!   [`serialized`] meshes), [`bsdfs`] (the one
//!   material table), [`textures`], [`emitters`], [`sensor`] (camera,
//!   film, filter, sampler) and [`integrator`].
//! - Every error is one line, `file: line L: column C: what`; everything
//!   Sahara approximates or leaves out is a warning, one per kind with a
//!   count, naming the first place (`file:line:column`).
//!
//! What is supported and how each feature maps is documented in
//! `docs/mitsuba.md` at the repository root.

mod bsdfs;
mod build;
mod builder;
mod defaults;
mod emitters;
mod expand;
mod integrator;
mod media;
mod metals;
mod properties;
mod sensor;
mod serialized;
mod shapes;
mod spectra;
mod textures;
mod transform;
mod xml;

#[cfg(test)]
mod tests;

use std::path::Path;

use sahara_readers::FormatError;

use crate::common::warnings::Warnings;
use crate::description::SceneDescription;

/// True if `path` names a Mitsuba scene file (`.xml`, any case).
pub(crate) fn is_mitsuba_path(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("xml"))
}

/// Reads a Mitsuba scene file (and the files it includes, meshes and
/// images) as a scene description, with scene parameters given as on
/// Mitsuba's command line (`-D name=value`): they win over the file's
/// `<default>`s.
pub(crate) fn read_mitsuba_with(
    path: &Path,
    params: &[(String, String)],
) -> Result<SceneDescription, FormatError> {
    let mut w = Warnings::default();
    let name = path.display().to_string();
    let root = xml::read_file(path, &name, &mut w)?;
    let folder = path.parent().unwrap_or(Path::new(""));
    described(root, &name, folder, params, w)
}

/// Parses and describes a Mitsuba scene held in memory; `name` is used in
/// messages and relative file names resolve against `folder`.
pub(crate) fn read_mitsuba_text(
    text: &[u8],
    name: &str,
    folder: &Path,
) -> Result<SceneDescription, FormatError> {
    let mut w = Warnings::default();
    let root = xml::parse_text(text, name, folder, &mut w)?;
    described(root, name, folder, &[], w)
}

/// The description of the file whose root element is `root`.
fn described(
    root: xml::Node,
    name: &str,
    folder: &Path,
    params: &[(String, String)],
    mut w: Warnings,
) -> Result<SceneDescription, FormatError> {
    let mut d = defaults::Defaults::given(params);
    let mut search = expand::Search::new(folder);
    let scene = expand::expand_scene(root, &mut d, &mut search, &mut w)?;
    build::build(&scene, name, search, w)
}
