//! glTF beyond the core: every texture role with its sampler, uv set and
//! `KHR_texture_transform`; tangents and the second uv set;
//! `KHR_mesh_quantization`; `KHR_materials_clearcoat`;
//! `KHR_lights_punctual`; cameras; what is refused or ignored, and how it
//! is said; non-finite vertices.

use glam::{Affine2, Mat4, Vec2, Vec3, Vec4};
use sahara_formats::Sky;
use sahara_formats::SkyUsed;
use sahara_formats::{gltf_camera, gltf_light, LUMENS_PER_WATT};
use sahara_formats::{gltf_material, TextureCache};
use sahara_formats::{load_mesh_scene, load_mesh_scene_with, CameraChoice};
use sahara_readers::gltf::{load_gltf, GltfLightKind, GltfWrap};
use sahara_render::{Bsdf, Light};
use sahara_render::{Channel, Wrap};

use crate::common::TempDir;
use crate::gltf_data::{base64, f32s};

/// A 2x1 RGBA PNG: an opaque orange texel and a half-transparent blue one.
fn png() -> Vec<u8> {
    let mut out = Vec::new();
    let img = image::RgbaImage::from_raw(2, 1, vec![255, 128, 0, 255, 0, 0, 255, 128]).unwrap();
    img.write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)
        .unwrap();
    out
}

/// A quad with positions as unnormalized shorts, uv 0 as normalized
/// unsigned shorts, uv 1 as floats, normals as normalized bytes and float
/// tangents; a material using every texture role; three lights, two
/// cameras, and an extension Sahara ignores.
fn full_quad() -> String {
    let shorts = |v: &[i16]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let mut bin = shorts(&[0, 0, 0, 0, 2, 0, 0, 0, 2, 2, 0, 0, 0, 2, 0, 0]); // 0..32
    bin.extend(
        [0u16, 0, 65535, 0, 65535, 65535, 0, 65535]
            .iter()
            .flat_map(|x| x.to_le_bytes()),
    ); // 32..48
    bin.extend(f32s(&[0., 0., 2., 0., 2., 2., 0., 2.])); // 48..80
    bin.extend([0u8, 0, 127, 0].repeat(4)); // 80..96
    bin.extend(f32s(&[1., 0., 0., -1.].repeat(4))); // 96..160
    bin.extend(shorts(&[0, 1, 2, 0, 2, 3])); // 160..172
    let transform = r#""extensions": {"KHR_texture_transform": {"offset": [0.5, 0.25], "scale": [2, 4], "texCoord": 1}}"#;
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_mesh_quantization", "KHR_texture_transform", "KHR_materials_clearcoat",
                     "KHR_lights_punctual", "KHR_materials_sheen", "EXT_lights_image_based"],
  "extensionsRequired": ["KHR_mesh_quantization", "KHR_texture_transform", "KHR_lights_punctual"],
  "extensions": {{"KHR_lights_punctual": {{"lights": [
    {{"type": "point", "color": [1, 0.5, 0.25], "intensity": 683}},
    {{"type": "spot", "intensity": 1366, "spot": {{"innerConeAngle": 0.25, "outerConeAngle": 0.5}}}},
    {{"type": "directional", "intensity": 6830}}]}}}},
  "buffers": [{{"byteLength": {len}, "uri": "data:application/octet-stream;base64,{data}"}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 32, "byteStride": 8}},
    {{"buffer": 0, "byteOffset": 32, "byteLength": 16}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": 32}},
    {{"buffer": 0, "byteOffset": 80, "byteLength": 16, "byteStride": 4}},
    {{"buffer": 0, "byteOffset": 96, "byteLength": 64}},
    {{"buffer": 0, "byteOffset": 160, "byteLength": 12}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5122, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [2, 2, 0]}},
    {{"bufferView": 1, "componentType": 5123, "normalized": true, "count": 4, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 3, "componentType": 5120, "normalized": true, "count": 4, "type": "VEC3"}},
    {{"bufferView": 4, "componentType": 5126, "count": 4, "type": "VEC4"}},
    {{"bufferView": 5, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2,
      "NORMAL": 3, "TANGENT": 4}}, "indices": 5, "material": 0}}]}}],
  "materials": [{{"name": "everything",
    "pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0}},
       "metallicRoughnessTexture": {{"index": 1, "texCoord": 1}}, "metallicFactor": 0.5}},
    "normalTexture": {{"index": 2, "scale": 0.75, {transform}}},
    "occlusionTexture": {{"index": 0, "strength": 0.5}},
    "emissiveTexture": {{"index": 1}}, "emissiveFactor": [1, 1, 1],
    "extensions": {{"KHR_materials_clearcoat": {{"clearcoatFactor": 0.8, "clearcoatRoughnessFactor": 0.3,
        "clearcoatTexture": {{"index": 0}}, "clearcoatRoughnessTexture": {{"index": 1}}}},
      "KHR_materials_sheen": {{"sheenColorFactor": [1, 0, 0]}}}}}},
    {{"extensions": {{"KHR_materials_sheen": {{}}}}}}],
  "textures": [{{"source": 0, "sampler": 0}}, {{"source": 0, "sampler": 1}}, {{"source": 0}}],
  "samplers": [{{"wrapS": 33071, "wrapT": 33648}}, {{"wrapS": 33648, "wrapT": 10497}}],
  "images": [{{"uri": "data:image/png;base64,{image}"}}],
  "cameras": [
    {{"type": "perspective", "name": "front", "perspective": {{"yfov": 0.5, "znear": 0.1}}}},
    {{"type": "perspective", "name": "top", "perspective": {{"yfov": 1.0, "znear": 0.1}}}},
    {{"type": "orthographic", "orthographic": {{"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}}}],
  "nodes": [
    {{"mesh": 0}},
    {{"extensions": {{"KHR_lights_punctual": {{"light": 0}}}}, "translation": [1, 2, 3]}},
    {{"extensions": {{"KHR_lights_punctual": {{"light": 1}}}}, "translation": [0, 5, 0],
      "rotation": [-0.7071068, 0, 0, 0.7071068]}},
    {{"extensions": {{"KHR_lights_punctual": {{"light": 2}}}}}},
    {{"camera": 0, "translation": [1, 1, 10]}},
    {{"camera": 1, "translation": [1, 10, 1], "rotation": [-0.7071068, 0, 0, 0.7071068]}},
    {{"camera": 2}}],
  "scenes": [{{"nodes": [0, 1, 2, 3, 4, 5, 6]}}]
}}"#,
        len = bin.len(),
        data = base64(&bin),
        image = base64(&png()),
    )
}

#[test]
fn every_role_attribute_light_and_camera_is_read() {
    let dir = TempDir::new("gltf-full");
    let path = dir.write("full.gltf", full_quad());
    let g = load_gltf(&path).unwrap();
    let mesh = &g.meshes[0];
    // KHR_mesh_quantization: shorts as their values, normalized types
    // mapped to [0, 1] and [-1, 1].
    assert_eq!(mesh.mesh.positions[2], Vec3::new(2.0, 2.0, 0.0));
    assert_eq!(mesh.uvs.as_ref().unwrap()[2], Vec2::ONE);
    assert_eq!(mesh.uvs1.as_ref().unwrap()[1], Vec2::new(2.0, 0.0));
    assert_eq!(mesh.normals.as_ref().unwrap()[0], Vec3::Z);
    assert_eq!(
        mesh.tangents.as_ref().unwrap()[3],
        Vec4::new(1., 0., 0., -1.)
    );
    let m = &g.materials[0];
    let base = m.base_color_texture.as_ref().unwrap();
    assert_eq!(base.wrap, [GltfWrap::Clamp, GltfWrap::MirroredRepeat]);
    assert_eq!((base.tex_coord, base.transform), (0, Affine2::IDENTITY));
    let mr = m.metallic_roughness_texture.as_ref().unwrap();
    assert_eq!(
        (mr.tex_coord, mr.wrap),
        (1, [GltfWrap::MirroredRepeat, GltfWrap::Repeat])
    );
    let (normal, scale) = m.normal_texture.as_ref().unwrap();
    assert_eq!((normal.tex_coord, *scale), (1, 0.75));
    assert_eq!(
        normal.transform,
        Affine2::from_scale_angle_translation(Vec2::new(2.0, 4.0), 0.0, Vec2::new(0.5, 0.25))
    );
    assert_eq!(m.occlusion_texture.as_ref().unwrap().1, 0.5);
    assert!(m.emissive_texture.is_some());
    let coat = m.clearcoat.as_ref().unwrap();
    assert_eq!((coat.factor, coat.roughness), (0.8, 0.3));
    assert!(coat.texture.is_some() && coat.roughness_texture.is_some());
    // Lights, with their nodes' transforms.
    assert_eq!(g.lights.len(), 3);
    assert_eq!(g.lights[0].kind, GltfLightKind::Point);
    assert_eq!(
        gltf_light(&g.lights[0], Mat4::IDENTITY),
        Light::point(Vec3::new(1.0, 2.0, 3.0), Vec3::new(1.0, 0.5, 0.25))
    );
    match gltf_light(&g.lights[1], Mat4::IDENTITY) {
        Light::Spot {
            position,
            direction,
            intensity,
            cos_inner,
            cos_outer,
        } => {
            assert_eq!(position, Vec3::new(0.0, 5.0, 0.0));
            // The node turns -Z to -Y: the spot shines down.
            assert!((direction - Vec3::NEG_Y).length() < 1e-5, "{direction}");
            assert_eq!(intensity, Vec3::splat(1366.0 / LUMENS_PER_WATT));
            assert!((cos_inner - 0.25f32.cos()).abs() < 1e-6);
            assert!((cos_outer - 0.5f32.cos()).abs() < 1e-6);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        gltf_light(&g.lights[2], Mat4::IDENTITY),
        Light::directional(Vec3::NEG_Z, Vec3::splat(10.0))
    );
    // Perspective cameras by name; the orthographic one skipped, said so.
    let names: Vec<_> = g.cameras.iter().map(|c| c.name.clone().unwrap()).collect();
    assert_eq!(names, ["front", "top"]);
    let top = gltf_camera(&g.cameras[1]);
    assert!(
        (top.forward - Vec3::NEG_Y).length() < 1e-5
            && (top.vfov_deg - 1f32.to_degrees()).abs() < 1e-4
    );
    let says = |what: &str| g.warnings.iter().any(|w| w.contains(what));
    assert!(says("1 orthographic camera"), "{:?}", g.warnings);
    // Ignored optional extensions: one warning each, with their uses.
    assert!(
        says("extension KHR_materials_sheen is not supported and is ignored (2 uses)"),
        "{:?}",
        g.warnings
    );
    assert!(says(
        "extension EXT_lights_image_based is not supported and is ignored (0 uses)"
    ));
    assert_eq!(g.warnings.len(), 3, "{:?}", g.warnings);

    // As a renderer material: encodings per role, channels, the transform
    // in Sahara's uv space (v up: the offset's v becomes 1 - 0.25 - 4 =
    // -3.25 for the flipped scale).
    let mut cache = TextureCache::new();
    let mut warnings = Vec::new();
    let r = gltf_material(m, "full.gltf", &mut cache, &mut warnings);
    assert!(warnings.is_empty(), "{warnings:?}");
    let t = &r.textures;
    let base = t.base_color.as_ref().unwrap();
    // Base colour: sRGB (code 128 is 0.2158605), alpha linear.
    let texel = base.texture.texel_rgba(0, 0, 0, [Wrap::Clamp; 2]);
    assert!(
        (texel.y - 0.215_860_5).abs() < 1e-6 && texel.w == 1.0,
        "{texel}"
    );
    let blue = base.texture.texel_rgba(0, 1, 0, [Wrap::Clamp; 2]);
    assert!((blue.w - 128.0 / 255.0).abs() < 1e-6);
    // Metallic-roughness: the same image read linear, B and G.
    let metal = t.metallic.as_ref().unwrap();
    let rough = t.roughness.as_ref().unwrap();
    assert_eq!((metal.channel, rough.channel), (Channel::B, Channel::G));
    let lin = metal.map.texture.texel_rgba(0, 0, 0, [Wrap::Clamp; 2]);
    assert!((lin.y - 128.0 / 255.0).abs() < 1e-6, "{lin}");
    assert_eq!(metal.map.uv_set, 1);
    // Two decodings of one image: sRGB and linear.
    assert_eq!(cache.len(), 2);
    let n = t.normal.as_ref().unwrap();
    assert_eq!((n.scale, n.map.uv_set), (0.75, 1));
    let flipped = n.map.transform;
    assert!((flipped.transform_point2(Vec2::ZERO) - Vec2::new(0.5, -3.25)).length() < 1e-6);
    assert_eq!(t.occlusion.as_ref().unwrap().map.channel, Channel::R);
    assert!(t.emission.is_some());
    let coat = r.clearcoat.as_ref().unwrap();
    assert_eq!(coat.factor_map.as_ref().unwrap().channel, Channel::R);
    assert_eq!(coat.roughness_map.as_ref().unwrap().channel, Channel::G);
    assert!(matches!(r.bsdf, Bsdf::MetallicRoughness { metallic, .. } if metallic == 0.5));
}

#[test]
fn a_mesh_file_brings_its_cameras_and_lights() {
    let dir = TempDir::new("gltf-camera");
    let path = dir.write("full.gltf", full_quad());
    // The first camera by default; its lights, strong enough to need no sky.
    let s = load_mesh_scene(&path).unwrap();
    assert_eq!(s.scene.camera.eye, Vec3::new(1.0, 1.0, 10.0));
    assert!(
        s.camera_source.contains("camera 'front'"),
        "{}",
        s.camera_source
    );
    assert_eq!(s.scene.lights.len(), 3);
    assert_eq!(s.sky, SkyUsed::Own);
    // The quad has tangents from the file: none are generated.
    assert_eq!(s.scene.meshes[0].tangents.as_ref().unwrap()[0].w, -1.0);
    // By name.
    let top = load_mesh_scene_with(&path, &CameraChoice::Named("top".into()), &Sky::Auto).unwrap();
    assert_eq!(top.scene.camera.eye, Vec3::new(1.0, 10.0, 1.0));
    // A name the file lacks: the names it has.
    let e = load_mesh_scene_with(&path, &CameraChoice::Named("side".into()), &Sky::Auto)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("full.gltf")
            && e.contains("no camera named 'side' (the file's cameras: 'front', 'top')"),
        "{e}"
    );
    // --camera's value: a file, or a name.
    let sidecar = dir.write("view.json", "{}");
    assert_eq!(
        CameraChoice::from_arg(sidecar.to_str().unwrap()),
        CameraChoice::Sidecar(sidecar.clone())
    );
    assert_eq!(
        CameraChoice::from_arg("front"),
        CameraChoice::Named("front".into())
    );
    // --sky default adds the sky and sun to the file's own lights.
    let lit = load_mesh_scene_with(&path, &CameraChoice::Auto, &Sky::Default).unwrap();
    assert_eq!(lit.scene.lights.len(), 4);
    assert!(lit.scene.environment.is_some());
}

#[test]
fn what_sahara_cannot_render_is_said_in_words() {
    let dir = TempDir::new("gltf-refused");
    let refused = |file: &str, text: &[u8]| {
        let path = dir.write(file, text);
        load_gltf(&path).unwrap_err().to_string()
    };
    let at = |file: &str| dir.0.join(file).display().to_string();
    let one = refused(
        "old.gltf",
        br#"{"asset": {"version": "1.0"}, "meshes": {"box": {"primitives": []}}}"#,
    );
    assert_eq!(
        one,
        format!(
            "{}: glTF 1.0 is not supported; convert it to glTF 2.0",
            at("old.gltf")
        )
    );
    // An empty file (a failed download, an unfetched LFS object).
    assert_eq!(
        refused("empty.glb", b""),
        format!("{}: the file is empty", at("empty.glb"))
    );
    // glTF 1.0 without a version, and the binary container version 1.
    assert!(
        refused("nover.gltf", br#"{"meshes": {"box": {}}}"#).contains("glTF 1.0 is not supported")
    );
    let mut glb1 = b"glTF".to_vec();
    glb1.extend(1u32.to_le_bytes());
    glb1.extend(20u32.to_le_bytes());
    glb1.extend([0u8; 8]);
    assert_eq!(
        refused("old.glb", &glb1),
        format!(
            "{}: glTF 1.0 is not supported; convert it to glTF 2.0",
            at("old.glb")
        )
    );
    let required = |ext: &str| {
        let file = format!("{ext}.gltf");
        refused(
            &file,
            format!(
                r#"{{"asset": {{"version": "2.0"}}, "extensionsUsed": ["{ext}"], "extensionsRequired": ["{ext}"]}}"#
            )
            .as_bytes(),
        )
    };
    assert_eq!(
        required("KHR_draco_mesh_compression"),
        format!(
            "{}: Draco-compressed meshes (KHR_draco_mesh_compression) are not supported; \
             save the file without mesh compression",
            at("KHR_draco_mesh_compression.gltf")
        )
    );
    assert!(required("EXT_meshopt_compression").ends_with(
        "meshopt-compressed buffers (EXT_meshopt_compression) are not supported; save the file without buffer compression"
    ));
    assert_eq!(
        required("EXT_mesh_gpu_instancing"),
        format!(
            "{}: requires the glTF extension EXT_mesh_gpu_instancing, which Sahara does not support",
            at("EXT_mesh_gpu_instancing.gltf")
        )
    );
    // A broken KTX2 image named directly (no extension): a warning naming
    // it, untextured.
    let ktx = dir.write(
        "t.ktx2",
        [0xAB, b'K', b'T', b'X', b' ', b'2', b'0', 0xBB, 0, 0],
    );
    let mut cache = TextureCache::new();
    let mut warnings = Vec::new();
    let t = cache.file(&ktx, sahara_render::Encoding::Srgb, &mut warnings);
    assert!(t.is_none());
    assert!(
        warnings[0].contains("t.ktx2") && warnings[0].contains("cannot read the KTX2 texture"),
        "{warnings:?}"
    );
}

#[test]
fn triangles_with_non_finite_corners_are_skipped_and_framing_ignores_them() {
    // Two triangles; the second has a corner at +infinity.
    let mut bin = f32s(&[0., 0., 0., 1., 0., 0., 0., 1., 0., f32::INFINITY, 5., 0.]);
    bin.extend([0u16, 1, 2, 1, 3, 2].iter().flat_map(|x| x.to_le_bytes()));
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}},
  "buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 12}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"}},
                {{"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}],
  "nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}]}}"#,
        bin.len(),
        base64(&bin)
    );
    let dir = TempDir::new("gltf-inf");
    let path = dir.write("inf.gltf", json);
    let s = load_mesh_scene(&path).unwrap();
    // Framed on the finite triangle: the camera looks at its bounds' centre,
    // from the front (+Z, glTF's front) and a little above, as glTF
    // viewers show a model.
    let centre = Vec3::new(0.5, 0.5, 0.0);
    assert!(((centre - s.scene.camera.eye).normalize() - s.scene.camera.forward).length() < 1e-5);
    let from = (s.scene.camera.eye - centre).normalize();
    assert!(
        from.x.abs() < 1e-5 && (from.y - 15f32.to_radians().sin()).abs() < 1e-5,
        "{from}"
    );
    assert_eq!(
        s.scene.diagnostics(),
        ["1 of 2 triangles skipped (1 with a NaN or infinite corner)"]
    );
    // An OBJ, the same.
    let obj = dir.write(
        "inf.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv inf 5 0\nf 1 2 3\nf 2 4 3\n",
    );
    let s = load_mesh_scene(&obj).unwrap();
    assert!(((centre - s.scene.camera.eye).normalize() - s.scene.camera.forward).length() < 1e-5);
    // An OBJ says nothing of its front: the three-quarter view, from the
    // right and above.
    let from = (s.scene.camera.eye - centre).normalize();
    assert!(from.x > 0.2 && from.y > 0.4, "{from}");
    assert_eq!(
        s.scene.diagnostics(),
        ["1 of 2 triangles skipped (1 with a NaN or infinite corner)"]
    );
}

/// The KTX2 textures of `crates/sahara-readers/tests/data/` (written by its
/// `make_ktx2.py` with the reference Basis Universal encoder).
fn ktx2_data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../sahara-readers/tests/data")
        .join(name)
}

#[test]
fn a_texture_stored_only_as_ktx2_is_read_through_khr_texture_basisu() {
    // A square whose one texture is a UASTC KTX2 image named only by the
    // extension (no PNG fallback), as files exported for the web are.
    let s = sahara_formats::load_mesh_scene(&ktx2_data("quad_basisu.gltf")).unwrap();
    assert!(
        s.warnings
            .iter()
            .all(|w| !w.contains("KTX2") && !w.contains("basisu")),
        "{:?}",
        s.warnings
    );
    let base = s.scene.materials[0]
        .textures
        .base_color
        .as_ref()
        .expect("the base colour texture is read");
    // A texel of each 4 x 4 quadrant (rows from the top): the texture's
    // colours, red, green / blue, white, as linear values.
    assert_eq!((base.texture.width, base.texture.height), (8, 8));
    for ((x, y), want) in [
        ((1, 1), glam::Vec3::X),
        ((5, 1), glam::Vec3::Y),
        ((1, 5), glam::Vec3::Z),
        ((5, 5), glam::Vec3::ONE),
    ] {
        let t = base.texture.texel(x, y);
        assert!(
            (t - want).abs().max_element() < 1e-3,
            "({x}, {y}): {t} != {want}"
        );
    }
}

#[test]
fn khr_materials_volume_attenuation_fills_solid_glass_with_an_absorbing_medium() {
    // A closed tetrahedron (mesh 0) in solid glass attenuating to
    // (0.5, 0.25, 1) over 2 units, and the same tetrahedron (mesh 1) in
    // thin-walled glass (no thickness): only the first bounds a medium.
    let mut bin = f32s(&[0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1.]);
    bin.extend(
        [0u16, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]
            .iter()
            .flat_map(|x| x.to_le_bytes()),
    );
    let glass = |volume: &str| {
        format!(
            r#"{{"pbrMetallicRoughness": {{"metallicFactor": 0, "roughnessFactor": 0}},
               "extensions": {{"KHR_materials_transmission": {{"transmissionFactor": 1}}{volume}}}}}"#
        )
    };
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_volume"],
  "buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 24}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]}},
                {{"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}}],
  "materials": [{}, {}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0}}]}},
             {{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 1}}]}}],
  "nodes": [{{"mesh": 0}}, {{"mesh": 1, "translation": [3, 0, 0]}}], "scenes": [{{"nodes": [0, 1]}}]}}"#,
        bin.len(),
        base64(&bin),
        glass(
            r#", "KHR_materials_volume": {"thicknessFactor": 0.5, "attenuationColor": [0.5, 0.25, 1], "attenuationDistance": 2}"#
        ),
        glass(
            r#", "KHR_materials_volume": {"attenuationColor": [0.5, 0.25, 1], "attenuationDistance": 2}"#
        ),
    );
    let dir = TempDir::new("gltf-volume");
    let path = dir.write("volume.gltf", json);
    let s = load_mesh_scene(&path).unwrap();
    assert!(
        s.warnings
            .iter()
            .all(|w| !w.contains("KHR_materials_volume")),
        "{:?}",
        s.warnings
    );
    assert_eq!(s.scene.media.len(), 1);
    let sahara_render::Medium::Homogeneous(h) = &s.scene.media[0] else {
        panic!("{:?}", s.scene.media)
    };
    // Crossing the attenuation distance keeps the attenuation colour.
    let kept = (-h.sigma_a * 2.0).exp();
    assert!(
        (kept - Vec3::new(0.5, 0.25, 1.0)).abs().max_element() < 1e-6,
        "{kept}"
    );
    assert_eq!(h.sigma_s, Vec3::ZERO);
    assert_eq!(s.scene.medium_interfaces.len(), 1);
    let (instance, mi) = s.scene.medium_interfaces[0];
    assert_eq!(s.scene.instances[instance as usize].mesh, 0);
    assert_eq!(
        (mi.inside, mi.outside, mi.index_matched),
        (Some(0), None, false)
    );
}
