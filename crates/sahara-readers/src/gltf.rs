//! glTF 2.0 scenes (`.gltf` with external or embedded buffers, and `.glb`).
//!
//! What is read: the default scene (else the first; else every root node),
//! each node's world transform (parent * local, `matrix` or TRS), every
//! triangle primitive (`TRIANGLES`, `TRIANGLE_STRIP`, `TRIANGLE_FAN`) of
//! the meshes those nodes use (`POSITION`, `NORMAL`, `TANGENT`,
//! `TEXCOORD_0`, `TEXCOORD_1`, indices, in float or in the integer forms
//! of `KHR_mesh_quantization`), the metallic-roughness materials with all
//! their textures and the extensions in [`extensions::SUPPORTED`], the
//! perspective cameras and the `KHR_lights_punctual` lights the scene's
//! nodes carry. Points and lines are skipped with a warning, and so are
//! orthographic cameras.
//!
//! A glTF mesh (all its primitives merged, with per-triangle material ids)
//! becomes one [`GltfMesh`], stored once however many nodes use it; each use
//! is a [`GltfInstance`]. Buffers and images are only read from local files
//! or `data:` URIs, never from the network. Every error names the file.

mod accessor;
pub mod extensions;
mod texture_info;
mod uri;

use std::collections::HashMap;
use std::fs;
use std::path::{Path, PathBuf};

use ::gltf::mesh::Mode;
use glam::{Affine2, Mat4, Quat, Vec2, Vec3, Vec4};
use sahara_kd::Mesh;
use serde_json::Value;

use crate::error::FormatError;
use uri::UriTarget;

/// Everything read from a glTF file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GltfScene {
    /// The meshes used by the scene's nodes, each stored once.
    pub meshes: Vec<GltfMesh>,
    /// One entry per node that uses a mesh: which mesh, and where.
    pub instances: Vec<GltfInstance>,
    /// The materials the meshes' `material_ids` refer to (a default is appended if needed).
    pub materials: Vec<GltfMaterial>,
    /// The perspective cameras of the scene's nodes, in scene order.
    pub cameras: Vec<GltfCamera>,
    /// The `KHR_lights_punctual` lights of the scene's nodes.
    pub lights: Vec<GltfLight>,
    /// Problems that did not stop loading, one line each.
    pub warnings: Vec<String>,
}

/// One glTF mesh: its triangle primitives merged into one triangle list.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GltfMesh {
    /// The mesh's name in the file, if any.
    pub name: Option<String>,
    /// Positions and triangles (primitives in file order).
    pub mesh: Mesh,
    /// Per-vertex normals, parallel to `mesh.positions`, if every primitive has them.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex `TEXCOORD_0`, parallel to `mesh.positions`, if any primitive has them (others get 0, 0).
    pub uvs: Option<Vec<Vec2>>,
    /// Per-vertex `TEXCOORD_1`, likewise.
    pub uvs1: Option<Vec<Vec2>>,
    /// Per-vertex `TANGENT` (xyz and the handedness w), if every primitive has them.
    pub tangents: Option<Vec<Vec4>>,
    /// Per-triangle index into [`GltfScene::materials`], parallel to `mesh.indices`.
    pub material_ids: Vec<u32>,
}

/// A use of a mesh by a node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GltfInstance {
    /// Index into [`GltfScene::meshes`].
    pub mesh: usize,
    /// Object-to-world transform (the product of the node's ancestors' transforms and its own).
    pub transform: Mat4,
}

/// A glTF metallic-roughness material.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfMaterial {
    /// The material's name in the file, if any.
    pub name: Option<String>,
    /// Linear base colour factor (RGBA).
    pub base_color: [f32; 4],
    /// Base colour texture (sRGB), multiplied by `base_color`.
    pub base_color_texture: Option<GltfTexture>,
    /// Metallic (blue channel) and roughness (green channel), linear,
    /// multiplied by `metallic` and `roughness`.
    pub metallic_roughness_texture: Option<GltfTexture>,
    /// Tangent-space normal map (linear), with its `scale`.
    pub normal_texture: Option<(GltfTexture, f32)>,
    /// Ambient occlusion (red channel, linear), with its `strength`.
    pub occlusion_texture: Option<(GltfTexture, f32)>,
    /// Emissive texture (sRGB), multiplied by `emissive`.
    pub emissive_texture: Option<GltfTexture>,
    /// `KHR_materials_clearcoat`, if the material has it.
    pub clearcoat: Option<GltfClearcoat>,
    /// Metalness factor in `[0, 1]`.
    pub metallic: f32,
    /// Perceptual roughness factor in `[0, 1]`.
    pub roughness: f32,
    /// Emitted radiance: `emissiveFactor` times `KHR_materials_emissive_strength`.
    pub emissive: [f32; 3],
    /// Whether back faces are visible.
    pub double_sided: bool,
    /// Index of refraction of the dielectric part (`KHR_materials_ior`;
    /// 1.5 without it).
    pub ior: f32,
    /// Strength of the dielectric's specular layer
    /// (`KHR_materials_specular`; 1 without it).
    pub specular: f32,
    /// Colour of the dielectric's specular layer (`KHR_materials_specular`;
    /// white without it).
    pub specular_color: [f32; 3],
    /// Fraction of light transmitted through the surface
    /// (`KHR_materials_transmission`; 0 without it).
    pub transmission: f32,
    /// Thickness of the volume the surface bounds (`KHR_materials_volume`;
    /// 0, a thin wall, without it).
    pub thickness: f32,
    /// The colour white light becomes after crossing
    /// `attenuation_distance` inside the volume (`KHR_materials_volume`;
    /// white without it).
    pub attenuation_color: [f32; 3],
    /// The distance over which light inside the volume becomes
    /// `attenuation_color` (`KHR_materials_volume`; infinite, no
    /// attenuation, without it).
    pub attenuation_distance: f32,
    /// How the base colour's alpha cuts the surface (`alphaMode`, with
    /// `alphaCutoff` for `MASK`).
    pub alpha_mode: GltfAlphaMode,
}

impl GltfMaterial {
    /// The glTF default material: white, fully metallic, fully rough, no emission.
    pub fn default_material() -> GltfMaterial {
        GltfMaterial {
            name: None,
            base_color: [1.0; 4],
            base_color_texture: None,
            metallic_roughness_texture: None,
            normal_texture: None,
            occlusion_texture: None,
            emissive_texture: None,
            clearcoat: None,
            metallic: 1.0,
            roughness: 1.0,
            emissive: [0.0; 3],
            double_sided: false,
            ior: 1.5,
            specular: 1.0,
            specular_color: [1.0; 3],
            transmission: 0.0,
            thickness: 0.0,
            attenuation_color: [1.0; 3],
            attenuation_distance: f32::INFINITY,
            alpha_mode: GltfAlphaMode::Opaque,
        }
    }
}

/// How a material's alpha cuts the surface (glTF's `alphaMode`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum GltfAlphaMode {
    /// `OPAQUE`: alpha is ignored.
    #[default]
    Opaque,
    /// `MASK`: the surface is absent where alpha is below `cutoff`.
    Mask {
        /// `alphaCutoff` (0.5 without it).
        cutoff: f32,
    },
    /// `BLEND`: alpha is the surface's opacity.
    Blend,
}

/// A sampler's wrap mode along one texture axis (glTF's `wrapS`, `wrapT`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GltfWrap {
    /// `REPEAT`: the image tiles the plane.
    #[default]
    Repeat,
    /// `CLAMP_TO_EDGE`: the edge texels extend outwards.
    Clamp,
    /// `MIRRORED_REPEAT`: the image tiles the plane, every other tile mirrored.
    MirroredRepeat,
}

/// `KHR_materials_clearcoat`: a clear coat over the material.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfClearcoat {
    /// `clearcoatFactor`.
    pub factor: f32,
    /// `clearcoatRoughnessFactor`.
    pub roughness: f32,
    /// `clearcoatTexture` (red channel), multiplying `factor`.
    pub texture: Option<GltfTexture>,
    /// `clearcoatRoughnessTexture` (green channel), multiplying `roughness`.
    pub roughness_texture: Option<GltfTexture>,
    /// `clearcoatNormalTexture`, with its `scale`.
    pub normal_texture: Option<(GltfTexture, f32)>,
}

/// A texture reference: the image, how it is sampled and which uv set it
/// uses.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfTexture {
    /// Where the image is.
    pub image: GltfImage,
    /// The image's index in the file (textures sharing an image share it).
    pub image_index: usize,
    /// Which `TEXCOORD_n` set (0 and 1 are loaded).
    pub tex_coord: u32,
    /// The sampler's wrap modes along u (`wrapS`) and v (`wrapT`).
    pub wrap: [GltfWrap; 2],
    /// `KHR_texture_transform`, in glTF's uv space (v running down the
    /// image); the identity without it.
    pub transform: Affine2,
}

/// A perspective camera of a node.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfCamera {
    /// The camera's name in the file, if any.
    pub name: Option<String>,
    /// The node's world transform (the camera looks down its -Z, +Y up).
    pub transform: Mat4,
    /// Vertical field of view, radians.
    pub yfov: f32,
    /// Width over height, if the file gives it.
    pub aspect_ratio: Option<f32>,
}

/// What a `KHR_lights_punctual` light is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GltfLightKind {
    /// Emits in all directions (intensity in candela).
    Point,
    /// A cone (intensity in candela), angles in radians from the axis.
    Spot {
        /// Where the falloff starts.
        inner_cone_angle: f32,
        /// Where the light ends.
        outer_cone_angle: f32,
    },
    /// From infinitely far (intensity in lux).
    Directional,
}

/// A `KHR_lights_punctual` light of a node.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfLight {
    /// The light's name in the file, if any.
    pub name: Option<String>,
    /// Point, spot or directional.
    pub kind: GltfLightKind,
    /// Linear RGB colour.
    pub color: [f32; 3],
    /// Candela (point, spot) or lux (directional).
    pub intensity: f32,
    /// Distance beyond which the light is cut off, if given.
    pub range: Option<f32>,
    /// The node's world transform (spot and directional lights shine down
    /// its -Z).
    pub transform: Mat4,
}

/// Where a texture's image is: a file, or bytes inside the glTF.
#[derive(Clone, Debug, PartialEq)]
pub enum GltfImage {
    /// An image file, resolved relative to the glTF file (it exists).
    File(PathBuf),
    /// An encoded image embedded in a buffer view or a `data:` URI.
    Embedded {
        /// The MIME type given in the file (`image/png`, `image/jpeg`), if any.
        mime_type: Option<String>,
        /// The encoded image file's bytes.
        bytes: Vec<u8>,
    },
}

/// Loads a `.gltf` or `.glb` file (the format is recognised by content).
pub fn load_gltf(path: &Path) -> Result<GltfScene, FormatError> {
    load(path).map_err(crate::error::one_line)
}

fn load(path: &Path) -> Result<GltfScene, FormatError> {
    let bytes = fs::read(path).map_err(|e| FormatError::io(path, e))?;
    let name = path.display().to_string();
    if bytes.is_empty() {
        // A failed download or an unfetched Git LFS object; the JSON
        // parser's "EOF while parsing" would not say so.
        return Err(FormatError::in_file(&name, "the file is empty"));
    }
    let folder = path.parent().unwrap_or(Path::new(""));
    let pre = extensions::prescan(&bytes, &name)?;
    // Textures stored only as KTX2 (KHR_texture_basisu) name that image as
    // their source, which the `gltf` crate requires.
    let patched = pre
        .as_ref()
        .and_then(|p| extensions::with_basisu_sources(&bytes, &p.json));
    let ::gltf::Gltf { document, blob } = parse(patched.as_deref().unwrap_or(&bytes), &name)?;
    let buffers = load_buffers(&document, blob, folder, &name)?;
    let (json, warnings) = match pre {
        Some(p) => (p.json, p.warnings),
        None => (Value::Null, Vec::new()),
    };
    let mut loader = Loader {
        name: &name,
        folder,
        buffers: &buffers,
        document: &document,
        json: &json,
        scene: GltfScene {
            warnings,
            ..GltfScene::default()
        },
        mesh_slot: HashMap::new(),
        material_slot: HashMap::new(),
        default_material: None,
    };
    let mut orthographic = 0;
    for (node, transform) in scene_nodes(&document, &name)? {
        if let Some(mesh) = node.mesh() {
            let slot = loader.mesh(&mesh)?;
            loader.scene.instances.push(GltfInstance {
                mesh: slot,
                transform,
            });
        }
        if let Some(camera) = node.camera() {
            match camera.projection() {
                ::gltf::camera::Projection::Perspective(p) => {
                    loader.scene.cameras.push(GltfCamera {
                        name: camera.name().map(str::to_owned),
                        transform,
                        yfov: p.yfov(),
                        aspect_ratio: p.aspect_ratio(),
                    })
                }
                ::gltf::camera::Projection::Orthographic(_) => orthographic += 1,
            }
        }
        if let Some(light) = node.light() {
            use ::gltf::khr_lights_punctual::Kind;
            let kind = match light.kind() {
                Kind::Point => GltfLightKind::Point,
                Kind::Directional => GltfLightKind::Directional,
                Kind::Spot {
                    inner_cone_angle,
                    outer_cone_angle,
                } => GltfLightKind::Spot {
                    inner_cone_angle,
                    outer_cone_angle,
                },
            };
            loader.scene.lights.push(GltfLight {
                name: light.name().map(str::to_owned),
                kind,
                color: light.color(),
                intensity: light.intensity(),
                range: light.range(),
                transform,
            });
        }
    }
    if orthographic > 0 {
        loader.scene.warnings.push(format!(
            "{name}: {orthographic} orthographic camera(s) skipped (only perspective cameras are supported)"
        ));
    }
    Ok(loader.scene)
}

/// Parses and validates the JSON (and GLB container), tolerating only
/// missing `POSITION` bounds (`min`/`max`), which many exporters leave out.
fn parse(bytes: &[u8], name: &str) -> Result<::gltf::Gltf, FormatError> {
    // The gltf crate computes `length - 12` unchecked: a GLB header whose
    // total length is below its own 12 bytes overflowed (a panic where
    // overflow is checked; found by fuzzing).
    if let Some(length) = bytes
        .strip_prefix(b"glTF")
        .and_then(|rest| rest.get(4..8))
        .map(|l| u32::from_le_bytes([l[0], l[1], l[2], l[3]]))
    {
        if length < 12 {
            return Err(FormatError::at_byte(
                name,
                8,
                format!("invalid GLB header: total length {length} is less than the header's own 12 bytes"),
            ));
        }
    }
    // gltf-json's validation indexes `accessors[POSITION]` unchecked: a
    // POSITION naming a missing accessor panicked, in every build (found by
    // fuzzing). Read without validation first and check those indices here.
    if let Ok(unchecked) = ::gltf::Gltf::from_slice_without_validation(bytes) {
        check_position_accessors(unchecked.document.as_json(), name)?;
        check_image_sources(unchecked.document.as_json(), name)?;
    }
    match ::gltf::Gltf::from_slice(bytes) {
        Err(::gltf::Error::Validation(problems))
            if problems.iter().all(|(path, e)| tolerated(path.as_str(), e)) =>
        {
            ::gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| describe_error(name, e))
        }
        other => other.map_err(|e| describe_error(name, e)),
    }
}

/// True for the validation problems Sahara reads past: missing `POSITION`
/// bounds, and required extensions that Sahara supports but the `gltf`
/// crate does not know (the prescan refused every other one).
fn tolerated(path: &str, e: &::gltf::json::validation::Error) -> bool {
    use ::gltf::json::validation::Error;
    match e {
        Error::Missing => path.ends_with(".min") || path.ends_with(".max"),
        Error::Unsupported => path.starts_with("extensionsRequired"),
        _ => false,
    }
}

/// An error for the first mesh primitive whose `POSITION` attribute names an
/// accessor that does not exist.
fn check_position_accessors(root: &::gltf::json::Root, name: &str) -> Result<(), FormatError> {
    let position = ::gltf::json::validation::Checked::Valid(::gltf::Semantic::Positions);
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(index) = primitive.attributes.get(&position) {
                if index.value() >= root.accessors.len() {
                    return Err(FormatError::in_file(
                        name,
                        format!(
                            "invalid glTF: meshes[{m}].primitives[{p}].attributes.POSITION: accessor {} does not exist ({} accessors)",
                            index.value(),
                            root.accessors.len()
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// `gltf::Image::source` unwraps what the specification requires of an
/// image: a `uri`, or a `bufferView` (that exists) with a `mimeType`. An
/// image without them panicked (found by fuzzing); it is an error here.
fn check_image_sources(root: &::gltf::json::Root, name: &str) -> Result<(), FormatError> {
    for (i, image) in root.images.iter().enumerate() {
        let problem = match (&image.buffer_view, &image.mime_type, &image.uri) {
            (Some(view), _, _) if view.value() >= root.buffer_views.len() => format!(
                "buffer view {} does not exist ({} buffer views)",
                view.value(),
                root.buffer_views.len()
            ),
            (Some(_), None, _) => "a bufferView without a mimeType".to_owned(),
            (None, _, None) => "neither a uri nor a bufferView".to_owned(),
            _ => continue,
        };
        return Err(FormatError::in_file(
            name,
            format!("invalid glTF: images[{i}]: {problem}"),
        ));
    }
    Ok(())
}

/// One line for an error of the `gltf` crate (JSON errors get their line and column).
fn describe_error(name: &str, error: ::gltf::Error) -> FormatError {
    match error {
        ::gltf::Error::Deserialize(e) => FormatError::at_line(
            name,
            e.line().max(1),
            format!(
                "column {}: invalid glTF JSON: {}",
                e.column(),
                crate::error::in_words(&e.to_string())
            ),
        ),
        ::gltf::Error::Validation(problems) => {
            let shown: Vec<String> = problems
                .iter()
                .take(3)
                .map(|(path, e)| format!("{}: {e}", path.as_str()))
                .collect();
            let more = problems.len().saturating_sub(3);
            FormatError::in_file(
                name,
                format!(
                    "invalid glTF: {}{}",
                    shown.join("; "),
                    if more > 0 {
                        format!(" (and {more} more)")
                    } else {
                        String::new()
                    }
                ),
            )
        }
        other => FormatError::in_file(name, format!("invalid glTF: {other}")),
    }
}

/// Reads every buffer: the GLB binary chunk, a `data:` URI, or a file next to the glTF.
fn load_buffers(
    document: &::gltf::Document,
    mut blob: Option<Vec<u8>>,
    folder: &Path,
    name: &str,
) -> Result<Vec<Vec<u8>>, FormatError> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let i = buffer.index();
        let (data, what) = match buffer.source() {
            ::gltf::buffer::Source::Bin => (
                blob.take().ok_or_else(|| {
                    FormatError::in_file(
                        name,
                        format!("buffer {i} refers to the GLB binary chunk, which is missing"),
                    )
                })?,
                "the GLB binary chunk".to_owned(),
            ),
            ::gltf::buffer::Source::Uri(uri) => match uri::resolve(uri, folder)
                .map_err(|e| FormatError::in_file(name, format!("buffer {i}: {e}")))?
            {
                UriTarget::Data(data) => (data, "its data URI".to_owned()),
                UriTarget::File(file) => {
                    let data = fs::read(&file).map_err(|e| {
                        FormatError::in_file(
                            name,
                            format!("buffer {i}: cannot read {}: {e}", file.display()),
                        )
                    })?;
                    (data, file.display().to_string())
                }
            },
        };
        if data.len() < buffer.length() {
            return Err(FormatError::in_file(
                name,
                format!(
                    "buffer {i} should have {} bytes but {what} has {}",
                    buffer.length(),
                    data.len()
                ),
            ));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// The nodes of the default scene (else the first, else all roots) with their world transforms.
fn scene_nodes<'a>(
    document: &'a ::gltf::Document,
    name: &str,
) -> Result<Vec<(::gltf::Node<'a>, Mat4)>, FormatError> {
    let roots: Vec<::gltf::Node> = match document
        .default_scene()
        .or_else(|| document.scenes().next())
    {
        Some(scene) => scene.nodes().collect(),
        None => {
            let mut is_child = vec![false; document.nodes().len()];
            for node in document.nodes() {
                for child in node.children() {
                    is_child[child.index()] = true;
                }
            }
            document.nodes().filter(|n| !is_child[n.index()]).collect()
        }
    };
    let mut visited = vec![false; document.nodes().len()];
    let mut out = Vec::new();
    let mut stack: Vec<(::gltf::Node, Mat4)> = roots
        .into_iter()
        .rev()
        .map(|n| (n, Mat4::IDENTITY))
        .collect();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut visited[node.index()], true) {
            return Err(FormatError::in_file(
                name,
                format!(
                    "node {} is reached twice from the scene (a cycle, or two parents); glTF nodes must form a tree",
                    node.index()
                ),
            ));
        }
        let world = parent * local_transform(&node);
        let children: Vec<_> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world)));
        out.push((node, world));
    }
    Ok(out)
}

/// A node's own transform: its `matrix`, or translation * rotation * scale.
fn local_transform(node: &::gltf::Node) -> Mat4 {
    match node.transform() {
        ::gltf::scene::Transform::Matrix { matrix } => Mat4::from_cols_array_2d(&matrix),
        ::gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => Mat4::from_scale_rotation_translation(
            Vec3::from_array(scale),
            Quat::from_array(rotation),
            Vec3::from_array(translation),
        ),
    }
}

/// State while converting meshes and materials, each once.
struct Loader<'a> {
    name: &'a str,
    folder: &'a Path,
    buffers: &'a [Vec<u8>],
    document: &'a ::gltf::Document,
    /// The file's plain JSON (null if the prescan could not read it).
    json: &'a Value,
    scene: GltfScene,
    mesh_slot: HashMap<usize, usize>,
    material_slot: HashMap<usize, u32>,
    default_material: Option<u32>,
}

/// A per-vertex attribute gathered over a mesh's primitives: present if
/// some primitive has it (the others padded with `fill`).
struct Gathered<T> {
    values: Option<Vec<T>>,
    fill: T,
}

impl<T: Copy> Gathered<T> {
    fn new(fill: T) -> Self {
        Self { values: None, fill }
    }

    /// Adds a primitive's values (`None`: it has none) after `base`
    /// vertices of earlier primitives, `count` of its own.
    fn add(&mut self, base: usize, count: usize, values: Option<Vec<T>>) {
        match values {
            Some(v) => {
                let all = self.values.get_or_insert_with(|| vec![self.fill; base]);
                all.extend(v);
            }
            None => {
                if let Some(all) = &mut self.values {
                    all.resize(base + count, self.fill);
                }
            }
        }
    }
}

impl Loader<'_> {
    /// The index in `scene.meshes` of glTF mesh `mesh`, converting it on first use.
    ///
    /// One piece: its primitives are merged into one mesh in one loop whose
    /// attribute buffers (normals, tangents, two uv sets) are kept only if
    /// every primitive has them, decided as the loop goes.
    fn mesh(&mut self, mesh: &::gltf::Mesh) -> Result<usize, FormatError> {
        if let Some(&slot) = self.mesh_slot.get(&mesh.index()) {
            return Ok(slot);
        }
        let mut out = GltfMesh {
            name: mesh.name().map(str::to_owned),
            ..GltfMesh::default()
        };
        let mut all_normals = true;
        let mut all_tangents = true;
        let mut normals = Vec::new();
        let mut tangents = Vec::new();
        let mut uvs = Gathered::new(Vec2::ZERO);
        let mut uvs1 = Gathered::new(Vec2::ZERO);
        for primitive in mesh.primitives() {
            let fail = |e: String| {
                FormatError::in_file(
                    self.name,
                    format!("mesh {} primitive {}: {e}", mesh.index(), primitive.index()),
                )
            };
            let mode = primitive.mode();
            if !matches!(
                mode,
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                self.scene.warnings.push(format!(
                    "{}: mesh {} primitive {}: {mode:?} primitives are skipped (only triangles are rendered)",
                    self.name,
                    mesh.index(),
                    primitive.index()
                ));
                continue;
            }
            let positions = primitive
                .get(&::gltf::Semantic::Positions)
                .ok_or_else(|| fail("no POSITION attribute".to_owned()))?;
            let positions = accessor::read_floats(&positions, self.buffers, 3).map_err(fail)?;
            let count = positions.len() / 3;
            let base = out.mesh.positions.len();
            if base + count > u32::MAX as usize {
                return Err(fail("more than 2^32 vertices in one mesh".to_owned()));
            }
            out.mesh
                .positions
                .extend(positions.chunks_exact(3).map(Vec3::from_slice));
            let per_vertex = |semantic: ::gltf::Semantic, n: usize, what: &str| {
                primitive
                    .get(&semantic)
                    .map(|a| {
                        let v = accessor::read_floats(&a, self.buffers, n).map_err(fail)?;
                        if v.len() / n != count {
                            return Err(fail(format!(
                                "{} {what} for {count} positions",
                                v.len() / n
                            )));
                        }
                        Ok(v)
                    })
                    .transpose()
            };
            match per_vertex(::gltf::Semantic::Normals, 3, "normals")? {
                Some(n) if all_normals => normals.extend(n.chunks_exact(3).map(Vec3::from_slice)),
                _ => all_normals = false,
            }
            match per_vertex(::gltf::Semantic::Tangents, 4, "tangents")? {
                Some(t) if all_tangents => tangents.extend(t.chunks_exact(4).map(Vec4::from_slice)),
                _ => all_tangents = false,
            }
            let tex = |set| -> Result<Option<Vec<Vec2>>, FormatError> {
                Ok(per_vertex(::gltf::Semantic::TexCoords(set), 2, "uvs")?
                    .map(|t| t.chunks_exact(2).map(Vec2::from_slice).collect()))
            };
            uvs.add(base, count, tex(0)?);
            uvs1.add(base, count, tex(1)?);
            let indices = match primitive.indices() {
                Some(a) => accessor::read_indices(&a, self.buffers).map_err(fail)?,
                None => (0..count as u32).collect(),
            };
            if let Some(bad) = indices.iter().find(|&&i| i as usize >= count) {
                return Err(fail(format!("index {bad} but only {count} vertices")));
            }
            let before = out.mesh.indices.len();
            let b = base as u32;
            match mode {
                Mode::Triangles => out.mesh.indices.extend(
                    indices
                        .chunks_exact(3)
                        .map(|t| [b + t[0], b + t[1], b + t[2]]),
                ),
                // Every other strip triangle is flipped to keep one winding.
                Mode::TriangleStrip => {
                    out.mesh
                        .indices
                        .extend(indices.windows(3).enumerate().map(|(k, t)| {
                            if k % 2 == 0 {
                                [b + t[0], b + t[1], b + t[2]]
                            } else {
                                [b + t[1], b + t[0], b + t[2]]
                            }
                        }))
                }
                _ => {
                    if let Some((&first, rest)) = indices.split_first() {
                        out.mesh
                            .indices
                            .extend(rest.windows(2).map(|w| [b + first, b + w[0], b + w[1]]));
                    }
                }
            }
            let material = self.material(&primitive.material())?;
            let added = out.mesh.indices.len() - before;
            out.material_ids
                .extend(std::iter::repeat_n(material, added));
        }
        let nv = out.mesh.positions.len();
        for g in [&mut uvs, &mut uvs1] {
            if let Some(v) = &mut g.values {
                v.resize(nv, Vec2::ZERO);
            }
        }
        out.normals = (all_normals && nv > 0).then_some(normals);
        out.tangents = (all_tangents && nv > 0).then_some(tangents);
        out.uvs = uvs.values;
        out.uvs1 = uvs1.values;
        let slot = self.scene.meshes.len();
        self.scene.meshes.push(out);
        self.mesh_slot.insert(mesh.index(), slot);
        Ok(slot)
    }

    /// The index in `scene.materials` of a primitive's material, converting it on first use.
    fn material(&mut self, material: &::gltf::Material) -> Result<u32, FormatError> {
        let Some(index) = material.index() else {
            let next = self.scene.materials.len() as u32;
            let id = *self.default_material.get_or_insert(next);
            if id == next {
                self.scene.materials.push(GltfMaterial::default_material());
            }
            return Ok(id);
        };
        if let Some(&id) = self.material_slot.get(&index) {
            return Ok(id);
        }
        let pbr = material.pbr_metallic_roughness();
        let strength = material.emissive_strength().unwrap_or(1.0);
        let raw = &self.json["materials"][index];
        let raw_pbr = &raw["pbrMetallicRoughness"];
        let clearcoat = &raw["extensions"]["KHR_materials_clearcoat"];
        let mut texture = |parent: &Value, key: &str, amount: &str| -> Result<_, FormatError> {
            match texture_info::read(parent, key, amount) {
                Some(info) => Ok(self.texture(&info, index, key)?.map(|t| (t, info.amount))),
                None => Ok(None),
            }
        };
        let factor = |v: &Value, key: &str, default: f32| {
            v.get(key)
                .and_then(Value::as_f64)
                .map_or(default, |x| x as f32)
        };
        let base_color_texture = texture(raw_pbr, "baseColorTexture", "")?.map(|t| t.0);
        let metallic_roughness_texture =
            texture(raw_pbr, "metallicRoughnessTexture", "")?.map(|t| t.0);
        let normal_texture = texture(raw, "normalTexture", "scale")?;
        let occlusion_texture = texture(raw, "occlusionTexture", "strength")?;
        let emissive_texture = texture(raw, "emissiveTexture", "")?.map(|t| t.0);
        let clearcoat = if clearcoat.is_object() {
            Some(GltfClearcoat {
                factor: factor(clearcoat, "clearcoatFactor", 0.0),
                roughness: factor(clearcoat, "clearcoatRoughnessFactor", 0.0),
                texture: texture(clearcoat, "clearcoatTexture", "")?.map(|t| t.0),
                roughness_texture: texture(clearcoat, "clearcoatRoughnessTexture", "")?
                    .map(|t| t.0),
                normal_texture: texture(clearcoat, "clearcoatNormalTexture", "scale")?,
            })
        } else {
            None
        };
        let converted = GltfMaterial {
            name: material.name().map(str::to_owned),
            base_color: pbr.base_color_factor(),
            base_color_texture,
            metallic_roughness_texture,
            normal_texture,
            occlusion_texture,
            emissive_texture,
            clearcoat,
            metallic: pbr.metallic_factor(),
            roughness: pbr.roughness_factor(),
            emissive: material.emissive_factor().map(|e| e * strength),
            double_sided: material.double_sided(),
            ior: material.ior().unwrap_or(1.5),
            specular: material.specular().map_or(1.0, |s| s.specular_factor()),
            specular_color: material
                .specular()
                .map_or([1.0; 3], |s| s.specular_color_factor()),
            transmission: material
                .transmission()
                .map_or(0.0, |t| t.transmission_factor()),
            thickness: material.volume().map_or(0.0, |v| v.thickness_factor()),
            attenuation_color: material
                .volume()
                .map_or([1.0; 3], |v| v.attenuation_color()),
            attenuation_distance: material
                .volume()
                .map_or(f32::INFINITY, |v| v.attenuation_distance()),
            alpha_mode: match material.alpha_mode() {
                ::gltf::material::AlphaMode::Opaque => GltfAlphaMode::Opaque,
                ::gltf::material::AlphaMode::Mask => GltfAlphaMode::Mask {
                    cutoff: material.alpha_cutoff().unwrap_or(0.5),
                },
                ::gltf::material::AlphaMode::Blend => GltfAlphaMode::Blend,
            },
        };
        let id = self.scene.materials.len() as u32;
        self.scene.materials.push(converted);
        self.material_slot.insert(index, id);
        Ok(id)
    }

    /// The texture a `textureInfo` names (`role`, in material `material`,
    /// for messages); `None` (with a warning) when its image file is
    /// missing or the texture has no image Sahara can read.
    fn texture(
        &mut self,
        info: &texture_info::TextureInfo,
        material: usize,
        role: &str,
    ) -> Result<Option<GltfTexture>, FormatError> {
        let texture = self.document.textures().nth(info.index).ok_or_else(|| {
            FormatError::in_file(
                self.name,
                format!(
                    "materials[{material}].{role}: texture {} does not exist ({} textures)",
                    info.index,
                    self.document.textures().len()
                ),
            )
        })?;
        let wrap = |w: ::gltf::texture::WrappingMode| match w {
            ::gltf::texture::WrappingMode::ClampToEdge => GltfWrap::Clamp,
            ::gltf::texture::WrappingMode::MirroredRepeat => GltfWrap::MirroredRepeat,
            ::gltf::texture::WrappingMode::Repeat => GltfWrap::Repeat,
        };
        let sampler = texture.sampler();
        let image = texture.source();
        let image_index = image.index();
        Ok(self
            .image(&image, material, role)?
            .map(|image| GltfTexture {
                image,
                image_index,
                tex_coord: info.tex_coord,
                wrap: [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())],
                transform: info.transform,
            }))
    }

    /// Where an image is; a missing file is a warning (the material is then untextured).
    fn image(
        &mut self,
        image: &::gltf::Image,
        material: usize,
        role: &str,
    ) -> Result<Option<GltfImage>, FormatError> {
        let fail =
            |e: String| FormatError::in_file(self.name, format!("image {}: {e}", image.index()));
        match image.source() {
            ::gltf::image::Source::View { view, mime_type } => {
                let bytes = self
                    .buffers
                    .get(view.buffer().index())
                    .and_then(|b| b.get(view.offset()..view.offset().checked_add(view.length())?))
                    .ok_or_else(|| {
                        fail(format!(
                            "buffer view {} lies outside its buffer",
                            view.index()
                        ))
                    })?;
                Ok(Some(GltfImage::Embedded {
                    mime_type: Some(mime_type.to_owned()),
                    bytes: bytes.to_vec(),
                }))
            }
            ::gltf::image::Source::Uri { uri, mime_type } => {
                match uri::resolve(uri, self.folder).map_err(fail)? {
                    UriTarget::Data(bytes) => Ok(Some(GltfImage::Embedded {
                        mime_type: mime_type.map(str::to_owned),
                        bytes,
                    })),
                    UriTarget::File(file) if file.is_file() => Ok(Some(GltfImage::File(file))),
                    UriTarget::File(file) => {
                        self.scene.warnings.push(format!(
                            "{}: material {material}: {role} {} not found; the material goes without it",
                            self.name,
                            file.display()
                        ));
                        Ok(None)
                    }
                }
            }
        }
    }
}
