//! Any file Sahara renders, by its extension: a scene file (TOML, pbrt,
//! Mitsuba) or a mesh file (OBJ, PLY, glTF), read, described and assembled
//! into a renderer scene with the settings its file asks for; and the
//! built-in Cornell box. The command line and the Python package both load
//! scenes through [`load`] and [`load_builtin`].
//!
//! Each reader gives a [`SceneDescription`]; this module is where a
//! description meets [`assemble`], so no reader depends on the assembly:
//! the per-format loaders ([`load_scene`], [`load_pbrt`], [`load_mitsuba`],
//! [`load_mesh_scene`]) and their in-memory forms ([`parse_scene`],
//! [`parse_pbrt`], [`parse_mitsuba`]) are here too.

use std::path::Path;

use sahara_readers::camera::read_sidecar;
use sahara_readers::FormatError;
use sahara_render::{builtin, Camera, Scene};

use crate::assembly::{assemble, sky, AssembledScene, SceneNames};
use crate::description::{SceneDescription, SettingsLayer, Sky};
use crate::mesh::{read_mesh_scene, CameraChoice};
use crate::toml::read_scene;

/// What may be asked of a scene besides its file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoadOptions {
    /// For a mesh file or the built-in scene: a camera sidecar file (a
    /// value that names an existing file or ends in `.json`) or the name of
    /// one of a glTF file's cameras; an error for a scene file, which has
    /// its own camera.
    pub camera: Option<String>,
    /// What lights the scene besides its own lights: `auto`, `default`,
    /// `none` or an environment image's path; None keeps the file's choice
    /// (`auto` for a mesh).
    pub sky: Option<String>,
    /// A Mitsuba scene's parameters (`$name` takes the value); an error
    /// for any other file.
    pub defines: Vec<(String, String)>,
}

/// A scene ready to render, with what its file says about rendering it.
pub struct Loaded {
    /// The scene (the camera's aspect as the file gave it, 1 for a camera
    /// chosen automatically: the caller sets it from the image size).
    pub scene: Scene,
    /// The render settings of a scene file (None: a mesh or the built-in scene).
    pub settings: Option<SettingsLayer>,
    /// The scene's name: the file name without its extension
    /// (`scene.pbrt.gz` is `scene`), `cornell_box` for the built-in scene.
    pub name: String,
    /// What a log calls it: the path, or `the built-in Cornell box`.
    pub description: String,
    /// The file it was read from (None: the built-in scene).
    pub path: Option<std::path::PathBuf>,
    /// What the scene's objects and materials are called.
    pub names: SceneNames,
    /// Problems that did not stop loading, one line each, naming the file.
    pub warnings: Vec<String>,
    /// For a mesh file (or the built-in scene with a camera sidecar):
    /// where the camera and the light came from, one line for the log
    /// (`camera: auto; light: default sky and sun ...`).
    pub framing: Option<String>,
}

impl Loaded {
    /// Its problems, one line each: those found reading it, then those of
    /// the finished scene (triangles skipped, lights that light nothing),
    /// named after its file.
    pub fn problems(&self) -> Vec<String> {
        let mut out = self.warnings.clone();
        out.extend(
            self.scene
                .diagnostics()
                .into_iter()
                .map(|d| match &self.path {
                    Some(p) => format!("{}: {d}", p.display()),
                    None => d,
                }),
        );
        out
    }
}

/// The file kinds [`load`] reads, for messages.
const EXPECTED: &str =
    "expected a scene file (.toml, .pbrt, .pbrt.gz, .xml) or a mesh (.obj, .ply, .gltf, .glb)";

/// An error about `path` as a whole.
fn in_file(path: &Path, message: String) -> FormatError {
    FormatError::InFile {
        path: path.display().to_string(),
        message,
    }
}

/// Loads the scene or mesh file `path`, choosing the reader by its
/// extension (`.toml`; `.pbrt`, `.pbrt.gz`; `.xml`; `.obj`, `.ply`,
/// `.gltf`, `.glb`), and assembles it. Every error is one line naming the
/// file and, where the file is at fault, the line or byte offset: a folder,
/// a missing file, an image or archive under a scene's extension, an
/// unknown extension, `options` that do not apply to the file, a mesh
/// without triangles.
pub fn load(path: &Path, options: &LoadOptions) -> Result<Loaded, FormatError> {
    if path.is_dir() {
        return Err(in_file(path, format!("is a folder; {EXPECTED}")));
    }
    if !path.exists() {
        return Err(in_file(path, "not found".into()));
    }
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if let Some(what) = sahara_readers::sniff::foreign_kind(path) {
        return Err(in_file(
            path,
            format!("is {what}, not a scene or mesh file; {EXPECTED}"),
        ));
    }
    let pbrt = crate::pbrt::is_pbrt_path(path);
    let mitsuba = crate::mitsuba::is_mitsuba_path(path);
    if !options.defines.is_empty() && !mitsuba {
        return Err(in_file(
            path,
            "-D sets parameters of Mitsuba scenes (.xml), not of this file".into(),
        ));
    }
    let camera = options.camera.as_deref();
    let own_camera = |what: &str| {
        Err(in_file(
            path,
            format!("--camera applies to meshes and the built-in scene; {what}"),
        ))
    };
    let mesh = matches!(ext.as_str(), "obj" | "ply" | "gltf" | "glb");
    let mut desc = match ext.as_str() {
        _ if pbrt && camera.is_some() => return own_camera("a pbrt file has its own Camera"),
        _ if pbrt => crate::pbrt::read_pbrt(path)?,
        _ if mitsuba && camera.is_some() => {
            return own_camera("a Mitsuba file has its own <sensor>")
        }
        _ if mitsuba => crate::mitsuba::read_mitsuba_with(path, &options.defines)?,
        "toml" if camera.is_some() => return own_camera("a scene file has its own [camera]"),
        "toml" => read_scene(path)?,
        _ if mesh => {
            let camera = camera.map_or(CameraChoice::Auto, CameraChoice::from_arg);
            read_mesh_scene(path, &camera)?
        }
        "" => {
            return Err(in_file(
                path,
                format!("the file name has no extension; {EXPECTED}"),
            ))
        }
        _ => {
            return Err(in_file(
                path,
                format!("cannot render .{ext} files; {EXPECTED}"),
            ))
        }
    };
    if let Some(s) = &options.sky {
        desc.sky = Sky::parse(s, Path::new(""));
    }
    let a = assemble(desc)?;
    let mut framing = None;
    if mesh {
        if a.scene.meshes.iter().all(|m| m.mesh.indices.is_empty()) {
            return Err(in_file(path, "the mesh has no triangles".into()));
        }
        let rule = a.sky_share.map_or_else(String::new, |share| {
            format!(
                " (auto: own lights at {share:.3} of the default sky and sun's power, {} {})",
                if share < sky::WEAK_FRACTION {
                    "below"
                } else {
                    "at least"
                },
                sky::WEAK_FRACTION
            )
        });
        framing = Some(format!(
            "camera: {}; light: {}{rule}",
            a.camera_source, a.sky
        ));
    }
    Ok(Loaded {
        scene: a.scene,
        settings: a.settings,
        name: stem(path),
        description: path.display().to_string(),
        path: Some(path.to_path_buf()),
        names: a.names,
        warnings: a.warnings,
        framing,
    })
}

/// The built-in Cornell box, seen by `options.camera` (a sidecar file) if
/// given and lit as `options.sky` says. `options.defines` must be empty
/// (the caller says so in its own words).
pub fn load_builtin(options: &LoadOptions) -> Result<Loaded, FormatError> {
    let mut scene = builtin::cornell_box();
    let mut framing = None;
    if let Some(file) = &options.camera {
        let c = read_sidecar(Path::new(file))?;
        scene.camera = Camera::look_at(c.eye, c.target, c.up, c.vfov_deg, 1.0);
        framing = Some(format!("camera: {file}"));
    }
    if let Some(s) = &options.sky {
        sky::apply(&mut scene, &Sky::parse(s, Path::new("")))?;
    }
    Ok(Loaded {
        names: SceneNames::numbered(&scene),
        scene,
        settings: None,
        name: "cornell_box".into(),
        description: "the built-in Cornell box".into(),
        path: None,
        warnings: Vec::new(),
        framing,
    })
}

/// True if `path` names a scene file (TOML, pbrt or Mitsuba) by its
/// extension, rather than a mesh or anything else.
pub fn is_scene_file(path: &Path) -> bool {
    crate::pbrt::is_pbrt_path(path)
        || crate::mitsuba::is_mitsuba_path(path)
        || path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
}

/// Reads a scene file (TOML) and assembles its scene (meshes, textures
/// and maps read relative to it); its settings are always there.
pub fn load_scene(path: &Path) -> Result<AssembledScene, FormatError> {
    assemble(read_scene(path)?)
}

/// Parses, checks and assembles scene TOML held in memory; `name` is used
/// in messages and relative file names resolve against `folder`.
pub fn parse_scene(text: &str, name: &str, folder: &Path) -> Result<AssembledScene, FormatError> {
    assemble(crate::toml::read_scene_text(text, name, folder)?)
}

/// Reads a pbrt file (and the files it includes, meshes and images) and
/// assembles its scene, checked (its settings are always there; the
/// film's `cropwindow` or `pixelbounds` is in their `crop`).
pub fn load_pbrt(path: &Path) -> Result<AssembledScene, FormatError> {
    checked(crate::pbrt::read_pbrt(path)?)
}

/// Parses and builds a pbrt file held in memory; `name` is used in
/// messages and relative file names resolve against `folder`.
pub fn parse_pbrt(text: &[u8], name: &str, folder: &Path) -> Result<AssembledScene, FormatError> {
    checked(crate::pbrt::read_pbrt_text(text, name, folder)?)
}

/// Reads a Mitsuba scene file and assembles its scene, checked.
pub fn load_mitsuba(path: &Path) -> Result<AssembledScene, FormatError> {
    checked(crate::mitsuba::read_mitsuba_with(path, &[])?)
}

/// Parses and builds a Mitsuba scene held in memory; `name` is used in
/// messages and relative file names resolve against `folder`.
pub fn parse_mitsuba(
    text: &[u8],
    name: &str,
    folder: &Path,
) -> Result<AssembledScene, FormatError> {
    checked(crate::mitsuba::read_mitsuba_text(text, name, folder)?)
}

/// Loads a mesh file with its materials, lights, camera and (if its own
/// lights are weak) the default sky and sun.
pub fn load_mesh_scene(path: &Path) -> Result<AssembledScene, FormatError> {
    load_mesh_scene_with(path, &CameraChoice::Auto, &Sky::Auto)
}

/// Loads a mesh file as [`load_mesh_scene`] does, seen by `camera` and
/// lit as `sky` says.
pub fn load_mesh_scene_with(
    path: &Path,
    camera: &CameraChoice,
    sky: &Sky,
) -> Result<AssembledScene, FormatError> {
    let mut desc = read_mesh_scene(path, camera)?;
    desc.sky = sky.clone();
    assemble(desc)
}

/// The assembled scene, checked.
fn checked(desc: SceneDescription) -> Result<AssembledScene, FormatError> {
    let name = desc.name.clone();
    let a = assemble(desc)?;
    a.scene
        .validate()
        .map_err(|e| FormatError::in_file(&name, e))?;
    Ok(a)
}

/// The scene's name: the file name without its extension (`scene.pbrt.gz`
/// is `scene`).
fn stem(path: &Path) -> String {
    let stem = path
        .file_stem()
        .map_or("render".into(), |s| s.to_string_lossy().into_owned());
    match stem.strip_suffix(".pbrt") {
        Some(s) if !s.is_empty() => s.to_owned(),
        _ => stem,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn message(r: Result<Loaded, FormatError>) -> String {
        match r {
            Ok(_) => panic!("loaded"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn the_reader_is_chosen_by_extension_and_refusals_name_the_file() {
        let dir = std::env::temp_dir().join(format!("sahara-load-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let obj = dir.join("tri.obj");
        std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let loaded = load(&obj, &LoadOptions::default()).unwrap();
        assert_eq!(loaded.name, "tri");
        assert!(loaded.settings.is_none());
        assert!(loaded.framing.unwrap().starts_with("camera: auto"));
        let toml = dir.join("s.pbrt.gz");
        std::fs::write(&toml, "").unwrap();
        assert_eq!(stem(&toml), "s");

        let missing = dir.join("nope.toml");
        assert_eq!(
            message(load(&missing, &LoadOptions::default())),
            format!("{}: not found", missing.display())
        );
        let odd = dir.join("x.stl");
        std::fs::write(&odd, "solid").unwrap();
        assert!(message(load(&odd, &LoadOptions::default())).contains("cannot render .stl files"));
        let defines = LoadOptions {
            defines: vec![("a".into(), "1".into())],
            ..Default::default()
        };
        assert!(message(load(&obj, &defines)).starts_with(&format!("{}: -D", obj.display())));
        assert!(message(load(&dir, &LoadOptions::default())).contains("is a folder"));
        let empty = dir.join("empty.obj");
        std::fs::write(&empty, "v 0 0 0\n").unwrap();
        assert!(
            message(load(&empty, &LoadOptions::default())).ends_with("the mesh has no triangles")
        );
        std::fs::remove_dir_all(&dir).unwrap();

        let cornell = load_builtin(&LoadOptions::default()).unwrap();
        assert_eq!(cornell.name, "cornell_box");
        assert!(cornell.framing.is_none());
    }
}
