//! What `sahara render` renders: the built-in Cornell box, a scene file
//! (TOML, pbrt or Mitsuba) or a mesh file, as a renderer scene with the settings its
//! file asks for and the problems found while reading it.

use std::path::Path;

use anyhow::{anyhow, bail, Result};
use sahara_formats::assembly::{assemble, SceneNames};
use sahara_formats::description::FileSettings;
use sahara_formats::description::Sky;
use sahara_formats::mesh_scene::{read_mesh_scene, CameraChoice};
use sahara_formats::scene_load::read_scene;
use sahara_readers::camera::read_sidecar;
use sahara_render::{builtin, Camera, Scene};

/// A scene to render, with what its file says about rendering it.
pub(crate) struct Input {
    /// The scene.
    pub(crate) scene: Scene,
    /// The render settings of a scene file (None: a mesh or the built-in scene).
    pub(crate) file: Option<FileSettings>,
    /// The scene's name, for the default output file.
    pub(crate) name: String,
    /// What the log calls it.
    pub(crate) description: String,
    /// What the scene's objects and materials are called.
    pub(crate) names: SceneNames,
    /// Problems that did not stop loading, one line each.
    pub(crate) warnings: Vec<String>,
}

/// The scene to render: the built-in Cornell box, a scene file or a mesh
/// file, seen by `camera` (`--camera`) and lit as `sky` (`--sky`) says;
/// `defines` are a Mitsuba scene's parameters (`-D name=value`).
pub(crate) fn load_input(
    path: Option<&Path>,
    camera: Option<&str>,
    sky: Option<&str>,
    defines: &[(String, String)],
) -> Result<Input> {
    let flat = |e: sahara_formats::FormatError| anyhow!("{e}");
    let sky = sky.map(|s| Sky::parse(s, Path::new("")));
    let Some(path) = path else {
        if !defines.is_empty() {
            bail!("-D sets parameters of a Mitsuba scene (.xml); no scene file is given");
        }
        let mut scene = builtin::cornell_box();
        if let Some(file) = camera {
            let c = read_sidecar(Path::new(file)).map_err(flat)?;
            scene.camera = Camera::look_at(c.eye, c.target, c.up, c.vfov_deg, 1.0);
            eprintln!("camera: {file}");
        }
        if let Some(sky) = &sky {
            sahara_formats::assembly::sky::apply(&mut scene, sky).map_err(flat)?;
        }
        return Ok(Input {
            names: SceneNames::numbered(&scene),
            scene,
            file: None,
            name: "cornell_box".into(),
            description: "the built-in Cornell box".into(),
            warnings: Vec::new(),
        });
    };
    const EXPECTED: &str =
        "expected a scene file (.toml, .pbrt, .pbrt.gz, .xml) or a mesh (.obj, .ply, .gltf, .glb)";
    if path.is_dir() {
        bail!("{}: is a folder; {EXPECTED}", path.display());
    }
    if !path.exists() {
        bail!("{}: not found", path.display());
    }
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if let Some(what) = sahara_readers::sniff::foreign_kind(path) {
        bail!(
            "{}: is {what}, not a scene or mesh file; {EXPECTED}",
            path.display()
        );
    }
    // A `FormatError`'s message already names the file and place.
    let pbrt = sahara_formats::pbrt::is_pbrt_path(path);
    let mitsuba = sahara_formats::mitsuba::is_mitsuba_path(path);
    if !defines.is_empty() && !mitsuba {
        bail!(
            "{}: -D sets parameters of Mitsuba scenes (.xml), not of this file",
            path.display()
        );
    }
    let mesh = matches!(ext.as_str(), "obj" | "ply" | "gltf" | "glb");
    let mut desc = match ext.as_str() {
        _ if pbrt && camera.is_some() => bail!(
            "{}: --camera applies to meshes and the built-in scene; a pbrt file has its own Camera",
            path.display()
        ),
        _ if pbrt => sahara_formats::pbrt::read_pbrt(path).map_err(flat)?,
        _ if mitsuba && camera.is_some() => bail!(
            "{}: --camera applies to meshes and the built-in scene; a Mitsuba file has its own <sensor>",
            path.display()
        ),
        _ if mitsuba => {
            sahara_formats::mitsuba::read_mitsuba_with(path, defines).map_err(flat)?
        }
        "toml" if camera.is_some() => bail!(
            "{}: --camera applies to meshes and the built-in scene; a scene file has its own [camera]",
            path.display()
        ),
        "toml" => read_scene(path).map_err(flat)?,
        _ if mesh => {
            let camera = camera.map_or(CameraChoice::Auto, CameraChoice::from_arg);
            read_mesh_scene(path, &camera).map_err(flat)?
        }
        "" => bail!(
            "{}: the file name has no extension; {EXPECTED}",
            path.display()
        ),
        _ => bail!("{}: cannot render .{ext} files; {EXPECTED}", path.display()),
    };
    if let Some(sky) = sky {
        desc.sky = sky;
    }
    let a = assemble(desc).map_err(flat)?;
    if mesh {
        if a.scene.meshes.iter().all(|m| m.mesh.indices.is_empty()) {
            bail!("{}: the mesh has no triangles", path.display());
        }
        let rule = a.sky_share.map_or_else(String::new, |share| {
            format!(
                " (auto: own lights at {share:.3} of the default sky and sun's power, {} {})",
                if share < sahara_formats::assembly::sky::WEAK_FRACTION {
                    "below"
                } else {
                    "at least"
                },
                sahara_formats::assembly::sky::WEAK_FRACTION
            )
        });
        eprintln!("camera: {}; light: {}{rule}", a.camera_source, a.sky);
    }
    let (scene, file, warnings) = (a.scene, a.settings, a.warnings);
    Ok(Input {
        names: a.names,
        scene,
        file,
        name: stem(path),
        description: path.display().to_string(),
        warnings,
    })
}

/// The scene's name: the file name without its extension (`scene.pbrt.gz`
/// is `scene`).
fn stem(path: &Path) -> String {
    let stem = path
        .file_stem()
        .map_or("render".into(), |s| s.to_string_lossy().into_owned());
    // `scene.pbrt.gz` is the scene `scene`.
    match stem.strip_suffix(".pbrt") {
        Some(s) if !s.is_empty() => s.to_owned(),
        _ => stem,
    }
}
