//! What `sahara render` renders: the built-in Cornell box, a scene file
//! (TOML, pbrt or Mitsuba) or a mesh file, as a renderer scene with the
//! settings its file asks for and the problems found while reading it
//! (`sahara_formats::load`, which chooses the reader by the extension).

use std::path::Path;

use anyhow::{anyhow, bail, Result};
use sahara_formats::{load, load_builtin, LoadOptions, Loaded};

/// A scene to render, with what its file says about rendering it. Its
/// problems, those of the finished scene among them (triangles skipped, no
/// light), are [`Loaded::problems`]: every command that loads a scene says
/// them.
pub(crate) type Input = Loaded;

/// The scene to render: the built-in Cornell box, a scene file or a mesh
/// file, seen by `camera` (`--camera`) and lit as `sky` (`--sky`) says;
/// `defines` are a Mitsuba scene's parameters (`-D name=value`).
pub(crate) fn load_input(
    path: Option<&Path>,
    camera: Option<&str>,
    sky: Option<&str>,
    defines: &[(String, String)],
) -> Result<Input> {
    if path.is_none() && !defines.is_empty() {
        bail!("-D sets parameters of a Mitsuba scene (.xml); no scene file is given");
    }
    let options = LoadOptions {
        camera: camera.map(str::to_owned),
        sky: sky.map(str::to_owned),
        defines: defines.to_vec(),
    };
    // A `FormatError`'s message already names the file and place.
    let loading = crate::status::Step::start(match path {
        Some(path) => format!("loading {}", path.display()),
        None => "loading the built-in scene".to_owned(),
    });
    let loaded = match path {
        Some(path) => load(path, &options),
        None => load_builtin(&options),
    };
    drop(loading);
    let input = loaded.map_err(|e| anyhow!("{e}"))?;
    if let Some(framing) = &input.framing {
        eprintln!("{framing}");
    }
    Ok(input)
}
