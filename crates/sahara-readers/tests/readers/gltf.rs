//! glTF: external/embedded buffers, GLB, node hierarchies, materials, errors.

use glam::{Mat4, Vec2, Vec3, Vec4};
use sahara_readers::gltf::{load_gltf, GltfImage, GltfMaterial};

use crate::common::TempDir;
use crate::gltf_data::{base64, f32s, triangle_buffer, triangle_json};

const MATERIAL_WITH_FILE_TEXTURE: &str = r#"
  "materials": [{"name": "paint",
    "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.2, 0.1, 1.0], "metallicFactor": 0.25,
       "roughnessFactor": 0.5, "baseColorTexture": {"index": 0}},
    "emissiveFactor": [1.0, 0.5, 0.25],
    "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}},
    "doubleSided": true}],
  "extensionsUsed": ["KHR_materials_emissive_strength"],
  "textures": [{"source": 0}],
  "images": [{"uri": "tex%20a.png"}],
  "nodes": [{"mesh": 0, "translation": [1.0, 2.0, 3.0]}],
  "scenes": [{"nodes": [0]}],
  "scene": 0"#;

#[test]
fn triangle_with_an_external_bin_and_a_textured_material() {
    let dir = TempDir::new("gltf-ext");
    let bin = triangle_buffer();
    dir.write("tri.bin", &bin);
    dir.write("tex a.png", b"only has to exist");
    let path = dir.write(
        "tri.gltf",
        triangle_json(
            r#""uri": "tri.bin","#,
            bin.len(),
            MATERIAL_WITH_FILE_TEXTURE,
        ),
    );
    let scene = load_gltf(&path).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.meshes.len(), 1);
    let mesh = &scene.meshes[0];
    assert_eq!(mesh.name.as_deref(), Some("tri"));
    assert_eq!(mesh.mesh.positions, vec![Vec3::ZERO, Vec3::X, Vec3::Y]);
    assert_eq!(mesh.mesh.indices, vec![[0, 1, 2]]);
    assert_eq!(mesh.normals, Some(vec![Vec3::Z; 3]));
    assert_eq!(
        mesh.uvs,
        Some(vec![
            Vec2::new(0., 0.),
            Vec2::new(1., 0.),
            Vec2::new(0., 1.)
        ])
    );
    assert_eq!(mesh.material_ids, vec![0]);
    assert_eq!(scene.instances.len(), 1);
    assert_eq!(scene.instances[0].mesh, 0);
    assert_eq!(
        scene.instances[0].transform,
        Mat4::from_translation(Vec3::new(1., 2., 3.))
    );
    let m = &scene.materials[0];
    assert_eq!(m.name.as_deref(), Some("paint"));
    assert_eq!(m.base_color, [0.8, 0.2, 0.1, 1.0]);
    assert_eq!((m.metallic, m.roughness), (0.25, 0.5));
    assert_eq!(m.emissive, [4.0, 2.0, 1.0]);
    assert!(m.double_sided);
    let texture = m.base_color_texture.as_ref().unwrap();
    assert_eq!(texture.image, GltfImage::File(dir.0.join("tex a.png")));
    assert_eq!(texture.tex_coord, 0);
}

#[test]
fn a_missing_texture_is_a_warning_and_a_missing_bin_an_error() {
    let dir = TempDir::new("gltf-missing");
    let bin = triangle_buffer();
    dir.write("tri.bin", &bin);
    let path = dir.write(
        "tri.gltf",
        triangle_json(
            r#""uri": "tri.bin","#,
            bin.len(),
            MATERIAL_WITH_FILE_TEXTURE,
        ),
    );
    let scene = load_gltf(&path).unwrap();
    assert_eq!(scene.materials[0].base_color_texture, None);
    assert_eq!(scene.warnings.len(), 1);
    assert!(
        scene.warnings[0].contains("tri.gltf") && scene.warnings[0].contains("tex a.png"),
        "{}",
        scene.warnings[0]
    );

    let path = dir.write(
        "nobin.gltf",
        triangle_json(
            r#""uri": "gone.bin","#,
            bin.len(),
            MATERIAL_WITH_FILE_TEXTURE,
        ),
    );
    let err = load_gltf(&path).unwrap_err().to_string();
    assert!(
        err.contains("nobin.gltf") && err.contains("gone.bin"),
        "{err}"
    );
    // A buffer shorter than it says.
    dir.write("short.bin", &bin[..50]);
    let path = dir.write(
        "short.gltf",
        triangle_json(
            r#""uri": "short.bin","#,
            bin.len(),
            MATERIAL_WITH_FILE_TEXTURE,
        ),
    );
    let err = load_gltf(&path).unwrap_err().to_string();
    assert!(err.contains("104") && err.contains("50"), "{err}");
    // Never the network.
    let path = dir.write(
        "web.gltf",
        triangle_json(
            r#""uri": "https://example.com/tri.bin","#,
            bin.len(),
            MATERIAL_WITH_FILE_TEXTURE,
        ),
    );
    let err = load_gltf(&path).unwrap_err().to_string();
    assert!(
        err.contains("https") && err.contains("not supported"),
        "{err}"
    );
}

#[test]
fn node_hierarchy_world_transforms_and_shared_meshes() {
    let dir = TempDir::new("gltf-tree");
    let bin = triangle_buffer();
    let uri = format!(
        r#""uri": "data:application/octet-stream;base64,{}","#,
        base64(&bin)
    );
    let s = std::f32::consts::FRAC_1_SQRT_2;
    // Scene 1 (the default): parent (TRS: scale 2, 90 degrees about +z, then
    // move by (10, 0, 0)) with a child whose matrix moves by (0, 1, 0); both
    // use mesh 0. Node 2 uses the mesh too but is only in scene 0.
    let nodes = format!(
        r#""nodes": [
    {{"mesh": 0, "translation": [10, 0, 0], "rotation": [0, 0, {s}, {s}], "scale": [2, 2, 2], "children": [1]}},
    {{"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,1,0,1]}},
    {{"mesh": 0}}
  ],
  "scenes": [{{"nodes": [2]}}, {{"nodes": [0]}}],
  "scene": 1"#
    );
    let json = triangle_json(&uri, bin.len(), &nodes).replace(r#", "material": 0"#, "");
    let path = dir.write("tree.gltf", json);
    let scene = load_gltf(&path).unwrap();
    assert_eq!(scene.meshes.len(), 1, "the mesh is stored once");
    assert_eq!(scene.instances.len(), 2);
    assert!(scene.instances.iter().all(|i| i.mesh == 0));
    // The primitive has no material here: the glTF default is used.
    assert_eq!(scene.materials, vec![GltfMaterial::default_material()]);
    assert_eq!(scene.meshes[0].material_ids, vec![0]);

    // By hand: R(90 about z) maps x to y and y to -x; S doubles.
    let parent = Mat4::from_cols(
        Vec4::new(0., 2., 0., 0.),
        Vec4::new(-2., 0., 0., 0.),
        Vec4::new(0., 0., 2., 0.),
        Vec4::new(10., 0., 0., 1.),
    );
    // The child's origin (0, 1, 0) in the parent's frame: 10 + (-2 * 1) = 8.
    let child = Mat4::from_cols(
        Vec4::new(0., 2., 0., 0.),
        Vec4::new(-2., 0., 0., 0.),
        Vec4::new(0., 0., 2., 0.),
        Vec4::new(8., 0., 0., 1.),
    );
    assert!(
        scene.instances[0].transform.abs_diff_eq(parent, 1e-6),
        "{}",
        scene.instances[0].transform
    );
    assert!(
        scene.instances[1].transform.abs_diff_eq(child, 1e-6),
        "{}",
        scene.instances[1].transform
    );
    // The triangle's corner (1, 0, 0) lands at (8, 2, 0) under the child.
    let p = scene.instances[1].transform.transform_point3(Vec3::X);
    assert!(p.abs_diff_eq(Vec3::new(8., 2., 0.), 1e-6), "{p}");
}

#[test]
fn load_mesh_merges_every_node_use_in_scene_order_with_its_transform() {
    let dir = TempDir::new("gltf-merged");
    let bin = triangle_buffer();
    let uri = format!(
        r#""uri": "data:application/octet-stream;base64,{}","#,
        base64(&bin)
    );
    let nodes = r#""nodes": [
    {"mesh": 0, "translation": [10, 0, 0]},
    {"mesh": 0, "translation": [0, 5, 0]}
  ],
  "scenes": [{"nodes": [1, 0]}],
  "scene": 0"#;
    let json = triangle_json(&uri, bin.len(), nodes).replace(r#", "material": 0"#, "");
    let path = dir.write("two.gltf", json);
    let (mesh, warnings) = sahara_readers::load_mesh_with_warnings(&path).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(mesh.indices.len(), 2);
    let corner = |t: usize, k: usize| mesh.positions[mesh.indices[t][k] as usize];
    // Scene order: node 1 (moved up by 5) first, then node 0 (moved by 10 in x).
    assert_eq!(corner(0, 1), Vec3::new(1., 5., 0.));
    assert_eq!(corner(1, 1), Vec3::new(11., 0., 0.));
    assert_eq!(sahara_readers::load_mesh(&path).unwrap(), mesh);
}

/// A GLB file: 12-byte header, JSON chunk (space-padded), BIN chunk (zero-padded).
fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut json = json.as_bytes().to_vec();
    json.resize(json.len().div_ceil(4) * 4, b' ');
    let mut bin = bin.to_vec();
    bin.resize(bin.len().div_ceil(4) * 4, 0);
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

#[test]
fn glb_with_an_embedded_image_and_a_triangle_strip() {
    // Four vertices of a unit square as a strip: triangles (0 1 2) and (2 1 3).
    let mut bin = f32s(&[0., 0., 0., 1., 0., 0., 0., 1., 0., 1., 1., 0.]); // 0..48
    let image = b"\x89PNG fake image bytes".to_vec();
    let image_at = bin.len();
    bin.extend(&image);
    let json = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "buffers": [{{"byteLength": {}}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": {image_at}, "byteLength": {}}}
  ],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "mode": 5, "material": 0}}]}}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0}}}}}}],
  "textures": [{{"source": 0}}],
  "images": [{{"bufferView": 1, "mimeType": "image/png"}}],
  "nodes": [{{"mesh": 0}}],
  "scenes": [{{"nodes": [0]}}]
}}"#,
        bin.len(),
        image.len()
    );
    let dir = TempDir::new("glb");
    let path = dir.write("square.glb", glb(&json, &bin));
    let scene = load_gltf(&path).unwrap();
    let mesh = &scene.meshes[0];
    assert_eq!(mesh.mesh.indices, vec![[0, 1, 2], [2, 1, 3]]);
    assert_eq!(mesh.normals, None);
    assert_eq!(mesh.uvs, None);
    assert_eq!(scene.instances[0].transform, Mat4::IDENTITY);
    let m = &scene.materials[0];
    // glTF defaults for factors that are not given.
    assert_eq!(
        (m.base_color, m.metallic, m.roughness),
        ([1.0; 4], 1.0, 1.0)
    );
    assert_eq!(
        m.base_color_texture.as_ref().unwrap().image,
        GltfImage::Embedded {
            mime_type: Some("image/png".into()),
            bytes: image
        }
    );
}

#[test]
fn glb_textures_stored_as_ktx2_are_read_through_khr_texture_basisu() {
    // A square with two materials' textures: one given only as a KTX2 image
    // in the binary chunk (KHR_texture_basisu, no `source`), one with a KTX2
    // image and a PNG fallback as its `source`, which stays the image read.
    let ktx2 = std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/quad_uastc.ktx2"),
    )
    .unwrap();
    let mut bin = f32s(&[0., 0., 0., 1., 0., 0., 0., 1., 0., 1., 1., 0.]); // 0..48
    bin.extend(&ktx2);
    let json = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_texture_basisu"],
  "extensionsRequired": ["KHR_texture_basisu"],
  "buffers": [{{"byteLength": {}}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": {}}}
  ],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"}}],
  "meshes": [
    {{"primitives": [{{"attributes": {{"POSITION": 0}}, "mode": 5, "material": 0}}]}},
    {{"primitives": [{{"attributes": {{"POSITION": 0}}, "mode": 5, "material": 1}}]}}
  ],
  "materials": [
    {{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0}}}}}},
    {{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": 1}}}}}}
  ],
  "textures": [
    {{"extensions": {{"KHR_texture_basisu": {{"source": 0}}}}}},
    {{"source": 1, "extensions": {{"KHR_texture_basisu": {{"source": 0}}}}}}
  ],
  "images": [{{"bufferView": 1, "mimeType": "image/ktx2"}}, {{"uri": "fallback.png"}}],
  "nodes": [{{"mesh": 0}}, {{"mesh": 1}}],
  "scenes": [{{"nodes": [0, 1]}}]
}}"#,
        bin.len(),
        ktx2.len()
    );
    let dir = TempDir::new("glb-ktx2");
    let fallback = dir.write("fallback.png", b"\x89PNG");
    let path = dir.write("square.glb", glb(&json, &bin));
    let scene = load_gltf(&path).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let texture = |m: usize| scene.materials[m].base_color_texture.as_ref().unwrap();
    assert_eq!(
        (&texture(0).image, texture(0).image_index),
        (
            &GltfImage::Embedded {
                mime_type: Some("image/ktx2".into()),
                bytes: ktx2
            },
            0
        )
    );
    assert_eq!(
        (&texture(1).image, texture(1).image_index),
        (&GltfImage::File(fallback), 1)
    );
}

#[test]
fn malformed_files_are_errors_naming_the_file() {
    let dir = TempDir::new("gltf-bad");
    let bin = triangle_buffer();
    dir.write("tri.bin", &bin);
    let error = |file: &str, text: String| {
        let path = dir.write(file, text);
        let message = load_gltf(&path).unwrap_err().to_string();
        assert!(message.contains(file), "{message}");
        assert!(!message.contains('\n'), "{message}");
        message
    };
    let scene = r#""nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]"#;
    let good =
        triangle_json(r#""uri": "tri.bin","#, bin.len(), scene).replace(r#", "material": 0"#, "");

    // Broken JSON: the line of the problem.
    let broken = good.replacen("\"VEC2\"}", "\"VEC2\" oops}", 1);
    let line = 1 + broken[..broken.find("oops").unwrap()].matches('\n').count();
    let message = error("json.gltf", broken);
    assert!(message.contains(&format!("line {line}:")), "{message}");

    // An accessor running past its buffer view (count 30 instead of 3).
    let message = error(
        "count.gltf",
        good.replacen(
            r#""count": 3, "type": "VEC2""#,
            r#""count": 30, "type": "VEC2""#,
            1,
        ),
    );
    assert!(
        message.contains("accessor 2") && message.contains("past the end"),
        "{message}"
    );

    // An index beyond the vertices (buffer patched: index 2 becomes 7).
    let mut patched = bin.clone();
    patched[100] = 7;
    dir.write("bad-index.bin", &patched);
    let message = error("index.gltf", good.replace("tri.bin", "bad-index.bin"));
    assert!(
        message.contains("index 7") && message.contains("3 vertices"),
        "{message}"
    );

    // A node that is its own child.
    let message = error(
        "cycle.gltf",
        triangle_json(
            r#""uri": "tri.bin","#,
            bin.len(),
            r#""nodes": [{"mesh": 0, "children": [1]}, {"children": [0]}], "scenes": [{"nodes": [0]}]"#,
        )
        .replace(r#", "material": 0"#, ""),
    );
    assert!(message.contains("reached twice"), "{message}");

    // Positions stored as integers.
    let message = error(
        "type.gltf",
        good.replacen(
            r#""componentType": 5126, "count": 3, "type": "VEC3"}"#,
            r#""componentType": 5125, "count": 3, "type": "VEC3"}"#,
            1,
        ),
    );
    assert!(
        message.contains("accessor 0") && message.contains("FLOAT"),
        "{message}"
    );

    // Not glTF at all.
    let message = error("junk.glb", "glTF but not really".to_owned());
    assert!(message.contains("invalid glTF"), "{message}");
}
