//! Scene files and mesh files as renderer scenes: material mapping, shared
//! meshes, shapes, lights, motion and errors.

use glam::{Affine3A, Vec3};
use sahara_formats::load_mesh_scene;
use sahara_formats::load_scene;
use sahara_formats::{gltf_bsdf, mtl_bsdf, phong_roughness};
use sahara_readers::gltf::GltfMaterial;
use sahara_readers::mtl::MtlMaterial;
use sahara_render::{AlphaMode, Bsdf, Distribution, Integrator, Light, Placement, Shape};

use crate::common::{scenes_dir, skip_note, TempDir};
use crate::gltf_data::{base64, triangle_buffer, triangle_json};

const QUAD_OBJ: &str = "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl MAT\nf 1/1 2/2 3/3 4/4\n";

/// A one-quad OBJ whose only material is the MTL block `mtl` (named `m`).
fn obj_with_mtl(dir: &TempDir, mtl: &str) -> std::path::PathBuf {
    dir.write("quad.mtl", format!("newmtl m\n{mtl}\n"));
    dir.write("quad.obj", QUAD_OBJ.replace("MAT", "m"))
}

fn mtl(f: impl FnOnce(&mut MtlMaterial)) -> MtlMaterial {
    let mut m = MtlMaterial::default_material();
    f(&mut m);
    m
}

#[test]
fn mtl_parameters_choose_the_bsdf() {
    assert_eq!(
        mtl_bsdf(&mtl(|m| {
            m.ni = 1.5;
            m.illum = 7
        })),
        Bsdf::Dielectric { ior: 1.5 }
    );
    assert_eq!(
        mtl_bsdf(&mtl(|m| {
            m.ni = 1.33;
            m.d = 0.4
        })),
        Bsdf::Dielectric { ior: 1.33 }
    );
    // Glass without an index of refraction gets 1.5.
    assert_eq!(
        mtl_bsdf(&mtl(|m| m.illum = 4)),
        Bsdf::Dielectric { ior: 1.5 }
    );
    assert_eq!(
        mtl_bsdf(&mtl(|m| {
            m.illum = 3;
            m.ks = [0.9, 0.8, 0.7]
        })),
        Bsdf::Mirror {
            color: Vec3::new(0.9, 0.8, 0.7)
        }
    );
    let glossy = mtl_bsdf(&mtl(|m| {
        m.kd = [0.1; 3];
        m.ks = [0.9, 0.6, 0.3];
        m.ns = 98.0
    }));
    // alpha = sqrt(2 / 100), roughness = sqrt(alpha).
    let r = 0.02f32.sqrt().sqrt();
    assert_eq!(
        glossy,
        Bsdf::Conductor {
            color: Vec3::new(0.9, 0.6, 0.3),
            roughness: r,
            distribution: Distribution::Ggx,
        }
    );
    assert!((phong_roughness(98.0) - r).abs() < 1e-7);
    assert!(phong_roughness(1e6) < 0.05 && phong_roughness(0.0) == 1.0);
    // illum 1 has no specular term; a Ks weaker than Kd is dropped.
    for illum in [1, 2] {
        assert_eq!(
            mtl_bsdf(&mtl(|m| {
                m.kd = [0.5, 0.4, 0.3];
                m.ks = [0.2; 3];
                m.illum = illum
            })),
            Bsdf::Diffuse {
                albedo: Vec3::new(0.5, 0.4, 0.3)
            }
        );
    }
}

#[test]
fn gltf_materials_become_the_metallic_roughness_bsdf_or_glass() {
    let mut m = GltfMaterial::default_material();
    m.base_color = [0.9, 0.5, 0.2, 1.0];
    m.roughness = 0.3;
    m.metallic = 0.25;
    m.ior = 1.4;
    m.specular = 0.5;
    m.specular_color = [1.0, 0.0, 0.0];
    assert_eq!(
        gltf_bsdf(&m),
        Bsdf::MetallicRoughness {
            base_color: Vec3::new(0.9, 0.5, 0.2),
            metallic: 0.25,
            roughness: 0.3,
            ior: 1.4,
            specular: 0.5,
            specular_color: Vec3::X,
        }
    );
    // Out-of-range factors are clamped, an ior below 1 is the default.
    m.metallic = 7.0;
    m.ior = 0.0;
    assert!(matches!(
        gltf_bsdf(&m),
        Bsdf::MetallicRoughness {
            metallic: 1.0,
            ior: 1.5,
            ..
        }
    ));
    // Transmission: a thin wall unless the material has a volume.
    m.metallic = 0.0;
    m.ior = 1.5;
    m.transmission = 1.0;
    assert_eq!(gltf_bsdf(&m), Bsdf::ThinDielectric { ior: 1.5 });
    m.thickness = 0.1;
    assert_eq!(
        gltf_bsdf(&m),
        Bsdf::RoughDielectric {
            ior: 1.5,
            roughness: 0.3,
            distribution: Distribution::Ggx,
        }
    );
    m.roughness = 0.0;
    assert_eq!(gltf_bsdf(&m), Bsdf::Dielectric { ior: 1.5 });
}

#[test]
fn a_glass_mtl_becomes_a_dielectric_in_the_scene() {
    let dir = TempDir::new("load-glass");
    let obj = obj_with_mtl(&dir, "Kd 1 1 1\nNi 1.5\nd 0.1\nillum 7");
    let s = load_mesh_scene(&obj).unwrap();
    assert_eq!(s.scene.materials.len(), 1);
    assert_eq!(s.scene.materials[0].bsdf, Bsdf::Dielectric { ior: 1.5 });
    assert_eq!(s.scene.meshes[0].material_ids, Some(vec![0, 0]));
    assert!(
        s.default_light(),
        "no emitter: the default sky and sun light it"
    );
    assert!(s.scene.environment.is_some() && s.scene.lights.len() == 1);
    assert_eq!(s.camera_source, "auto (framing the one object)");
    s.scene.validate().unwrap();
}

#[test]
fn an_emissive_mtl_is_an_emitter_and_needs_no_default_light() {
    let dir = TempDir::new("load-ke");
    let obj = obj_with_mtl(&dir, "Kd 0.78 0.78 0.78\nKe 17 12 4\nillum 1");
    let s = load_mesh_scene(&obj).unwrap();
    let m = &s.scene.materials[0];
    assert_eq!(m.emission, Vec3::new(17.0, 12.0, 4.0));
    assert_eq!(
        m.bsdf,
        Bsdf::Diffuse {
            albedo: Vec3::splat(0.78)
        }
    );
    assert!(!s.default_light());
    assert!(s.scene.environment.is_none() && s.scene.lights.is_empty());
}

#[test]
fn the_shared_cornell_box_light_emits_17_12_4() {
    let path = scenes_dir().join("cornell_box/cornell_box.obj");
    if !path.exists() {
        skip_note(&format!(
            "the shared Cornell box's light ({} not found; set SAHARA_SCENES)",
            path.display()
        ));
        return;
    }
    let s = load_mesh_scene(&path).unwrap();
    let emitters: Vec<_> = s
        .scene
        .materials
        .iter()
        .filter(|m| m.is_emissive())
        .collect();
    assert_eq!(emitters.len(), 1);
    assert_eq!(emitters[0].emission, Vec3::new(17.0, 12.0, 4.0));
    assert!(!s.default_light());
    assert!(s.camera_source.ends_with("cornell_box.camera.json"));
    assert_eq!(s.scene.camera.eye, Vec3::new(278.0, 273.0, -800.0));
}

#[test]
fn textures_load_once_and_a_missing_one_is_a_warning() {
    let dir = TempDir::new("load-tex");
    // A 2x1 PNG: red then blue.
    let png = dir.0.join("t.png");
    image::RgbImage::from_raw(2, 1, vec![255, 0, 0, 0, 0, 255])
        .unwrap()
        .save(&png)
        .unwrap();
    dir.write(
        "quad.mtl",
        "newmtl a\nKd 1 1 1\nmap_Kd t.png\nnewmtl b\nKd 1 1 1\nmap_Kd t.png\nnewmtl c\nKd 0.5 0.5 0.5\nmap_Kd gone.png\n",
    );
    let obj = dir.write(
        "quad.obj",
        "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl a\nf 1 2 3\nusemtl b\nf 1 3 2\nusemtl c\nf 2 1 3\n",
    );
    let s = load_mesh_scene(&obj).unwrap();
    let [a, b, c] = [0, 1, 2].map(|i| {
        s.scene.materials[i]
            .textures
            .base_color
            .as_ref()
            .map(|m| m.texture.clone())
    });
    let (a, b) = (a.unwrap(), b.unwrap());
    assert!(std::sync::Arc::ptr_eq(&a, &b), "one file, one texture");
    assert_eq!((a.width, a.height), (2, 1));
    assert_eq!(a.texel(0, 0), Vec3::new(1.0, 0.0, 0.0));
    assert!(c.is_none());
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    assert!(s.warnings[0].contains("gone.png"), "{}", s.warnings[0]);
}

#[test]
fn a_missing_mtl_is_a_warning_and_the_default_material() {
    let dir = TempDir::new("load-nomtl");
    let obj = dir.write("quad.obj", QUAD_OBJ.replace("MAT", "m"));
    let s = load_mesh_scene(&obj).unwrap();
    assert!(
        s.warnings.iter().any(|w| w.contains("quad.mtl")),
        "{:?}",
        s.warnings
    );
    assert_eq!(
        s.scene.materials[0].bsdf,
        Bsdf::Diffuse {
            albedo: Vec3::splat(0.8)
        }
    );
}

/// A scene file header: camera and film.
const HEADER: &str =
    "[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\n\n[film]\nwidth = 8\nheight = 4\n\n";

#[test]
fn objects_sharing_a_mesh_file_share_one_mesh() {
    let dir = TempDir::new("load-shared");
    obj_with_mtl(&dir, "Kd 0.2 0.4 0.6");
    std::fs::create_dir_all(dir.0.join("sub")).unwrap();
    let toml = format!(
        "{HEADER}[[material]]\nname = \"red\"\ntype = \"diffuse\"\nalbedo = [1, 0, 0]\n\n\
         [[object]]\ntype = \"mesh\"\nfile = \"quad.obj\"\n\n\
         [[object]]\ntype = \"mesh\"\nfile = \"sub/../quad.obj\"\nmaterial = \"red\"\n\
         transform = {{ translate = [2, 0, 0] }}\n"
    );
    let path = dir.write("s.toml", toml);
    let l = load_scene(&path).unwrap();
    let scene = &l.scene;
    assert_eq!(scene.meshes.len(), 1, "the mesh is loaded once");
    assert_eq!(scene.instances.len(), 2);
    assert!(scene.instances.iter().all(|i| i.mesh == 0));
    // The first keeps the MTL material, the second is overridden.
    assert_eq!(scene.instances[0].material, None);
    let red = scene.instances[1].material.unwrap() as usize;
    assert_eq!(
        scene.materials[red].bsdf,
        Bsdf::Diffuse {
            albedo: Vec3::new(1.0, 0.0, 0.0)
        }
    );
    let own = scene.meshes[0].material_ids.as_ref().unwrap()[0] as usize;
    assert_eq!(
        scene.materials[own].bsdf,
        Bsdf::Diffuse {
            albedo: Vec3::new(0.2, 0.4, 0.6)
        }
    );
    assert_eq!(
        scene.instances[1].placement,
        Placement::Static(Affine3A::from_translation(Vec3::new(2.0, 0.0, 0.0)))
    );
    assert_eq!(scene.camera.aspect, 2.0);
    scene.validate().unwrap();
}

#[test]
fn gltf_nodes_become_instances_of_one_mesh_placed_by_the_object() {
    let dir = TempDir::new("load-gltf");
    let bin = triangle_buffer();
    let uri = format!(
        r#""uri": "data:application/octet-stream;base64,{}","#,
        base64(&bin)
    );
    let extra = r#""materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 0.8],
      "metallicFactor": 0}, "emissiveFactor": [2, 2, 2], "alphaMode": "MASK", "alphaCutoff": 0.3,
      "extensions": {"KHR_materials_ior": {"ior": 1.7}}}],
  "extensionsUsed": ["KHR_materials_ior"],
  "nodes": [{"mesh": 0, "translation": [1, 0, 0]}, {"mesh": 0, "translation": [0, 1, 0]}],
  "scenes": [{"nodes": [0, 1]}], "scene": 0"#;
    dir.write("two.gltf", triangle_json(&uri, bin.len(), extra));
    let toml = format!(
        "{HEADER}[[object]]\ntype = \"mesh\"\nfile = \"two.gltf\"\ntransform = {{ translate = [0, 0, 10] }}\n\n\
         [[object]]\ntype = \"mesh\"\nfile = \"two.gltf\"\n"
    );
    let l = load_scene(&dir.write("s.toml", toml)).unwrap();
    let scene = &l.scene;
    assert_eq!(scene.meshes.len(), 1);
    assert_eq!(scene.instances.len(), 4);
    let Placement::Static(a) = scene.instances[1].placement else {
        panic!("static expected")
    };
    assert!(a
        .transform_point3(Vec3::ZERO)
        .abs_diff_eq(Vec3::new(0.0, 1.0, 10.0), 1e-6));
    let m = &scene.materials[scene.material_of(0, 0) as usize];
    assert_eq!(m.emission, Vec3::splat(2.0));
    assert!(matches!(
        m.bsdf,
        Bsdf::MetallicRoughness { base_color, metallic: 0.0, ior: 1.7, .. } if base_color == Vec3::splat(0.5)
    ));
    assert_eq!(m.alpha_mode, AlphaMode::Mask { cutoff: 0.3 });
    assert_eq!(m.alpha, 0.8);
    assert!(!m.two_sided, "glTF materials are single-sided by default");
    // glTF's v runs downwards; the scene's upwards.
    let uvs = scene.meshes[0].uvs.as_ref().unwrap();
    assert_eq!(uvs[1], glam::Vec2::new(1.0, 1.0));
}

#[test]
fn shapes_lights_motion_and_settings_are_converted() {
    let dir = TempDir::new("load-shapes");
    let toml = format!(
        "{HEADER}[[material]]\nname = \"lamp\"\ntype = \"emission\"\nradiance = [5, 5, 5]\n\n\
         [[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"lamp\"\n\
         transform = {{ translate = [0, 3, 0], scale = 2 }}\n\n\
         [[object]]\ntype = \"box\"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\n\
         motion = {{ open = {{ translate = [0, 0, 0] }}, close = {{ translate = [1, 0, 0] }} }}\n\n\
         [[light]]\ntype = \"area\"\nshape = \"quad\"\ncorner = [0, 5, 0]\nedge_u = [1, 0, 0]\nedge_v = [0, 0, 1]\nradiance = [3, 3, 3]\n\n\
         [[light]]\ntype = \"spot\"\nposition = [0, 4, 0]\ntarget = [0, 0, 0]\nintensity = [1, 1, 1]\nouter_angle = 30\n\n\
         [[light]]\ntype = \"environment\"\nradiance = [0.1, 0.2, 0.3]\n\n\
         [integrator]\nname = \"distribution\"\nlight_samples = 3\n\n[sampler]\nspp = 7\nseed = 9\n"
    );
    let l = load_scene(&dir.write("s.toml", toml)).unwrap();
    let scene = &l.scene;
    // The emissive sphere, transformed exactly, and the area light are analytic shapes.
    assert_eq!(scene.shapes.len(), 2);
    assert_eq!(
        scene.shapes[0].shape,
        Shape::Sphere {
            center: Vec3::new(0.0, 3.0, 0.0),
            radius: 2.0
        }
    );
    assert!(matches!(scene.shapes[1].shape, Shape::Quad { .. }));
    // The moving box is a moving instance with the default material.
    let moving: Vec<_> = scene
        .instances
        .iter()
        .filter(|i| i.placement.is_moving())
        .collect();
    assert_eq!(moving.len(), 1);
    assert!(matches!(scene.lights[0], Light::Spot { .. }));
    assert!(scene.environment.is_some());
    assert_eq!(
        l.settings.as_ref().unwrap().frame_settings().integrator,
        Integrator::Distribution {
            max_depth: 8,
            light_samples: 3
        }
    );
    assert_eq!(
        (
            l.settings.as_ref().unwrap().frame_settings().spp,
            l.settings.as_ref().unwrap().frame_settings().seed
        ),
        (7, 9)
    );
    assert_eq!(
        (
            l.settings.as_ref().unwrap().frame_settings().width,
            l.settings.as_ref().unwrap().frame_settings().height
        ),
        (8, 4)
    );
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    scene.validate().unwrap();
}

#[test]
fn a_missing_mesh_names_the_scene_line_and_the_path() {
    let dir = TempDir::new("load-missing");
    let toml = format!("{HEADER}[[object]]\ntype = \"mesh\"\nfile = \"meshes/nowhere.obj\"\n");
    let path = dir.write("s.toml", toml);
    let e = load_scene(&path).unwrap_err().to_string();
    assert!(e.starts_with(&path.display().to_string()), "{e}");
    assert!(e.contains("line 11"), "{e}");
    assert!(e.contains("meshes/nowhere.obj"), "{e}");
}

#[test]
fn a_broken_mesh_is_an_error_naming_the_scene_and_the_mesh() {
    let dir = TempDir::new("load-broken");
    dir.write("bad.obj", "v 0 0 0\nf 1 2 3\n");
    let toml = format!("{HEADER}[[object]]\ntype = \"mesh\"\nfile = \"bad.obj\"\n");
    let path = dir.write("s.toml", toml);
    let e = load_scene(&path).unwrap_err().to_string();
    assert!(e.starts_with(&path.display().to_string()), "{e}");
    assert!(e.contains("bad.obj"), "{e}");
}

#[test]
fn a_scene_file_integrator_without_parameters_gets_the_command_line_defaults() {
    let dir = TempDir::new("integrator-defaults");
    for name in ["path", "distribution", "ao", "normals", "depth", "cost"] {
        let path = dir.write(
            &format!("{name}.toml"),
            format!(
                "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n[film]\nwidth = 8\nheight = 4\n\
                 [integrator]\nname = \"{name}\"\n"
            ),
        );
        let l = load_scene(&path).unwrap();
        assert_eq!(
            Ok(l.settings.as_ref().unwrap().frame_settings().integrator),
            Integrator::named(name),
            "{name}"
        );
        assert_eq!(
            l.settings.as_ref().unwrap().frame_settings().spp,
            sahara_render::defaults::SPP,
            "{name}"
        );
    }
}

#[test]
fn an_area_light_carries_the_material_it_names() {
    let dir = TempDir::new("area-material");
    let scene = |light_extra: &str| {
        format!(
            "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n[film]\nwidth = 8\nheight = 4\n\
             [[material]]\nname = \"diffuser\"\ntype = \"diffuse\"\nalbedo = [0.78, 0.78, 0.78]\n\
             [[light]]\ntype = \"area\"\nshape = \"quad\"\ncorner = [0, 0, 0]\nedge_u = [1, 0, 0]\n\
             edge_v = [0, 1, 0]\nradiance = [17, 12, 4]\n{light_extra}"
        )
    };
    let with = dir.write("with.toml", scene("material = \"diffuser\"\n"));
    let l = load_scene(&with).unwrap();
    let m = l.scene.materials.iter().find(|m| m.is_emissive()).unwrap();
    assert_eq!(m.emission, Vec3::new(17.0, 12.0, 4.0));
    assert_eq!(
        m.bsdf,
        Bsdf::Diffuse {
            albedo: Vec3::splat(0.78)
        }
    );
    // Without a material the panel is black but for its emission, as before.
    let without = dir.write("without.toml", scene(""));
    let l = load_scene(&without).unwrap();
    let m = l.scene.materials.iter().find(|m| m.is_emissive()).unwrap();
    assert_eq!(m.bsdf, Bsdf::Diffuse { albedo: Vec3::ZERO });
    // An unknown name is an error at its line.
    let bad = dir.write("bad.toml", scene("material = \"nope\"\n"));
    let e = load_scene(&bad).unwrap_err().to_string();
    assert!(
        e.contains("bad.toml")
            && e.contains("line 18")
            && e.contains("no [[material]] is named 'nope'"),
        "{e}"
    );
}

#[test]
fn the_scene_files_sky_key_adds_what_it_names() {
    let dir = TempDir::new("load-sky");
    dir.write("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n");
    let scene = |sky: &str| {
        let toml = format!(
            "{sky}\n[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n\n[film]\nwidth = 4\nheight = 4\n\n\
             [[object]]\ntype = \"mesh\"\nfile = \"quad.obj\"\n\n\
             [[light]]\ntype = \"point\"\nposition = [0, 0, 2]\nintensity = [1e-3, 1e-3, 1e-3]\n"
        );
        load_scene(&dir.write("s.toml", toml))
    };
    // Without the key: the file's lights alone, however weak.
    let s = scene("").unwrap().scene;
    assert_eq!((s.lights.len(), s.environment.is_some()), (1, false));
    // auto: the point light is weak, so the default sky and sun come in.
    let s = scene("sky = \"auto\"").unwrap().scene;
    assert_eq!(s.lights.len(), 2);
    assert_eq!(
        s.environment,
        Some(sahara_render::Environment::Constant(
            sahara_formats::DEFAULT_SKY
        ))
    );
    let s = scene("sky = \"default\"").unwrap().scene;
    assert_eq!(s.lights.len(), 2);
    // A map relative to the scene file; one that is missing names the file.
    let mut hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n".to_vec();
    hdr.extend_from_slice(&[128, 64, 32, 129, 128, 64, 32, 129]);
    dir.write("env.hdr", hdr);
    let s = scene("sky = \"env.hdr\"").unwrap().scene;
    assert!(matches!(
        s.environment,
        Some(sahara_render::Environment::Map { .. })
    ));
    assert_eq!(s.lights.len(), 1);
    let e = scene("sky = \"gone.exr\"").unwrap_err().to_string();
    assert!(e.contains("s.toml") && e.contains("gone.exr"), "{e}");
}
