//! Tests of the pbrt reader as a whole: directives, transforms, includes,
//! instancing, compressed files, errors, and pbrt scenes rendering as the
//! same scenes written in Sahara's TOML.

use std::io::Write;
use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};
use sahara_render::Placement;

use super::declarations::Declarations;
use super::parser::parse_bytes;
use crate::common::test_scenes::image;
use crate::common::warnings::Warnings;
use crate::{load_pbrt, load_scene, parse_pbrt};

fn parse(text: &str) -> Result<(Declarations, Warnings), sahara_readers::FormatError> {
    let mut w = Warnings::default();
    let d = parse_bytes(
        text.as_bytes().to_vec(),
        "t.pbrt",
        Path::new("/nonexistent"),
        &mut w,
    )?;
    Ok((d, w))
}

fn err(text: &str) -> String {
    match parse_pbrt(text.as_bytes(), "t.pbrt", Path::new("/nonexistent")) {
        Ok(_) => panic!("expected an error for {text:?}"),
        Err(e) => e.to_string(),
    }
}

/// A fresh folder for a test's files.
fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sahara-pbrt-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn a_known_point_goes_through_the_transform_stack() {
    let (d, _) = parse(
        "AttributeBegin\n Translate 1 2 3\n Rotate 90 0 0 1\n Scale 2 2 2\n CoordinateSystem \"mine\"\n Shape \"sphere\"\nAttributeEnd\n\
         Shape \"sphere\"\n\
         CoordSysTransform \"mine\" ConcatTransform [1 0 0 0 0 1 0 0 0 0 1 0 0 0 1 1] Shape \"sphere\"\n\
         Transform 1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1 Shape \"sphere\"\n\
         Identity LookAt 0 0 0  0 0 1  0 1 0 Shape \"sphere\"\n\
         Identity LookAt 0 0 0  1 0 0  0 1 0 Shape \"sphere\"",
    )
    .unwrap();
    let p = |i: usize, v: [f64; 3]| d.shapes[i].xform.m[0].transform_point3(DVec3::from_array(v));
    let close = |a: DVec3, b: [f64; 3]| (a - DVec3::from_array(b)).length() < 1e-12;
    // Scale, then rotate about z, then translate.
    assert!(
        close(p(0, [1.0, 0.0, 0.0]), [1.0, 4.0, 3.0]),
        "{}",
        p(0, [1.0, 0.0, 0.0])
    );
    // AttributeEnd restored the identity.
    assert!(close(p(1, [1.0, 0.0, 0.0]), [1.0, 0.0, 0.0]));
    // The named system, then a translation of 1 along its z (scaled by 2).
    assert!(
        close(p(2, [0.0, 0.0, 0.0]), [1.0, 2.0, 5.0]),
        "{}",
        p(2, [0.0; 3])
    );
    // Transform replaces: columns, translation last.
    assert!(close(p(3, [0.0, 0.0, 0.0]), [5.0, 6.0, 7.0]));
    // LookAt is world to camera, +x = up x forward.
    assert!(close(p(4, [1.0, 0.0, 0.0]), [1.0, 0.0, 0.0]));
    // Looking down +x with y up: camera +z is world +x, camera +x (up x
    // forward) is world -z, so world +x is at camera (0, 0, 1).
    assert!(
        close(p(5, [1.0, 0.0, 0.0]), [0.0, 0.0, 1.0]),
        "{}",
        p(5, [1.0, 0.0, 0.0])
    );
    assert!(close(p(5, [0.0, 0.0, -1.0]), [1.0, 0.0, 0.0]));
}

#[test]
fn motion_orientation_and_blocks() {
    let (d, w) = parse(
        "TransformTimes 0 2\nActiveTransform EndTime\nTranslate 4 0 0\nActiveTransform All\nReverseOrientation\n\
         AttributeBegin ReverseOrientation Shape \"disk\" AttributeEnd\nShape \"disk\"\nTransformBegin Translate 1 1 1 TransformEnd\n\
         AttributeBegin",
    )
    .unwrap();
    assert_eq!(d.transform_times, (0.0, 2.0));
    let s = &d.shapes[1];
    assert!(s.xform.is_animated());
    assert_eq!(s.xform.m[0].transform_point3(DVec3::ZERO), DVec3::ZERO);
    assert_eq!(
        s.xform.m[1].transform_point3(DVec3::ZERO),
        DVec3::new(4.0, 0.0, 0.0)
    );
    assert!(s.reverse && !d.shapes[0].reverse);
    assert_eq!(w.count("AttributeBegin without AttributeEnd"), 1);
}

#[test]
fn every_error_names_file_line_and_column() {
    assert_eq!(
        err("WorldBegin\n  Shapee \"sphere\""),
        "t.pbrt: line 2: column 3: unknown directive 'Shapee'"
    );
    assert_eq!(
        err("Shape \"sphere\" \"string radius\" \"x\""),
        "t.pbrt: line 1: column 16: parameter \"string radius\": expected type float"
    );
    assert_eq!(
        err("Shape \"sphere\"\n\"float radius\" [1 2]"),
        "t.pbrt: line 2: column 1: parameter \"float radius\": expected one value, found 2"
    );
    assert_eq!(
        err("Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0] \"integer indices\" [0 1 4]"),
        "t.pbrt: line 1: column 59: parameter \"integer indices\": index 4 is out of range (4 vertices)"
    );
    assert_eq!(
        err("Translate 1 2"),
        "t.pbrt: line 1: column 1: the file ends where 3 numbers is expected"
    );
    assert_eq!(
        err("Translate 1 2 x"),
        "t.pbrt: line 1: column 15: expected a number, found 'x'"
    );
    assert_eq!(
        err("AttributeEnd"),
        "t.pbrt: line 1: column 1: AttributeEnd without a block to close"
    );
    let e = err("\n Include \"missing.pbrt\"");
    assert!(
        e.starts_with("t.pbrt: line 2: column 2: Include: /nonexistent/missing.pbrt: cannot read"),
        "{e}"
    );
    assert_eq!(
        err("NamedMaterial \"nope\" Shape \"sphere\""),
        "t.pbrt: line 1: column 1: unknown named material \"nope\""
    );
    assert_eq!(
        err("ObjectInstance \"nope\""),
        "t.pbrt: line 1: column 1: ObjectInstance of unknown object \"nope\""
    );
    assert_eq!(
        err("Camera \"orthographic\""),
        "t.pbrt: line 1: column 1: the 'orthographic' camera is not supported (Sahara has perspective cameras only)"
    );
    assert!(err("Shape \"sphere\" \"rgb\" [1 2 3]").contains("expected a parameter declaration"));
    assert!(err("Film \"rgb\" \"integer xresolution\" [0]").contains("must be in 1..=65536"));
}

#[test]
fn unknown_parameters_and_unsupported_features_are_counted_warnings() {
    let text = "Shape \"sphere\" \"float radius\" 1 \"float wobble\" 3\nShape \"sphere\" \"float wobble\" 2\n\
                Shape \"curve\" \"point3 P\" [0 0 0 1 1 1 2 2 2 3 3 3]\nShape \"curve\" \"point3 P\" [0 0 0 1 1 1 2 2 2 3 3 3]\n\
                Material \"hair\" Shape \"sphere\"\nLightSource \"point\"";
    let s = parse_pbrt(text.as_bytes(), "t.pbrt", Path::new("/nonexistent")).unwrap();
    let w = &s.warnings;
    assert!(w.contains(&"t.pbrt:1:33: shape 'sphere': unknown parameter \"float wobble\", ignored (2 times; the first here)".to_owned()), "{w:#?}");
    assert!(
        w.contains(
            &"t.pbrt:3:1: shape 'curve' is not supported; skipped (2 times; the first here)"
                .to_owned()
        ),
        "{w:#?}"
    );
    assert!(
        w.iter()
            .any(|l| l.contains("material 'hair': not supported; replaced by a diffuse material")),
        "{w:#?}"
    );
    assert_eq!(s.scene.lights.len(), 1);
}

#[test]
fn includes_resolve_from_the_main_folder_then_the_including_file() {
    let dir = folder("include");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    std::fs::write(
        dir.join("main.pbrt"),
        "Include \"sub/a.pbrt\"\nImport \"sub/b.pbrt\"\n",
    )
    .unwrap();
    // a.pbrt names c.pbrt relative to itself, b.pbrt names sub/ply relative to the main file.
    std::fs::write(dir.join("sub/a.pbrt"), "Include \"c.pbrt\"\n").unwrap();
    std::fs::write(dir.join("sub/c.pbrt"), "LightSource \"point\"\n").unwrap();
    let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
               0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n1 1 0 0 0 1 1 1\n0 1 0 0 0 1 0 1\n4 0 1 2 3\n";
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(ply.as_bytes()).unwrap();
    std::fs::write(dir.join("sub/quad.ply.gz"), gz.finish().unwrap()).unwrap();
    std::fs::write(
        dir.join("sub/b.pbrt"),
        "Shape \"plymesh\" \"string filename\" \"sub/quad.ply.gz\"\n",
    )
    .unwrap();
    let s = load_pbrt(&dir.join("main.pbrt")).unwrap();
    let scene = &s.scene;
    assert_eq!(scene.lights.len(), 1);
    assert_eq!(scene.meshes.len(), 1);
    let m = &scene.meshes[0];
    assert_eq!(m.mesh.indices.len(), 2, "the quad is two triangles");
    assert_eq!(m.normals.as_ref().unwrap()[2], Vec3::Z);
    assert_eq!(m.uvs.as_ref().unwrap()[2], glam::Vec2::ONE);
    // The whole file compressed reads the same.
    let text = std::fs::read(dir.join("main.pbrt")).unwrap();
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(&text).unwrap();
    std::fs::write(dir.join("main.pbrt.gz"), gz.finish().unwrap()).unwrap();
    let z = load_pbrt(&dir.join("main.pbrt.gz")).unwrap();
    assert_eq!(z.scene, s.scene);
    // A file that includes itself is an error, not a hang.
    std::fs::write(dir.join("loop.pbrt"), "Include \"loop.pbrt\"\n").unwrap();
    let e = load_pbrt(&dir.join("loop.pbrt")).unwrap_err().to_string();
    assert!(e.contains("nested more than"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn object_instances_share_one_mesh() {
    let text = "Material \"diffuse\" \"rgb reflectance\" [0.1 0.2 0.3]\nObjectBegin \"tri\"\n\
                Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\n\
                Material \"conductor\" Shape \"sphere\"\nObjectEnd\n\
                AttributeBegin Translate 5 0 0 ObjectInstance \"tri\" AttributeEnd\n\
                AttributeBegin Scale 2 2 2 ObjectInstance \"tri\" AttributeEnd\n\
                ActiveTransform EndTime Translate 0 1 0 ActiveTransform All ObjectInstance \"tri\"";
    let s = parse_pbrt(text.as_bytes(), "t.pbrt", Path::new("/nonexistent")).unwrap();
    let scene = &s.scene;
    assert_eq!(scene.meshes.len(), 1, "one mesh for the object");
    assert_eq!(scene.instances.len(), 3);
    assert!(scene
        .instances
        .iter()
        .all(|i| i.mesh == 0 && i.material.is_none()));
    let ids = scene.meshes[0].material_ids.as_ref().unwrap();
    assert_ne!(
        ids[0],
        *ids.last().unwrap(),
        "the triangle and the sphere keep their materials"
    );
    assert_eq!(
        scene.materials[ids[0] as usize].bsdf,
        sahara_render::Bsdf::Diffuse {
            albedo: Vec3::new(0.1, 0.2, 0.3)
        }
    );
    match scene.instances[0].placement {
        Placement::Static(a) => {
            assert_eq!(a.transform_point3(Vec3::ZERO), Vec3::new(5.0, 0.0, 0.0))
        }
        other => panic!("{other:?}"),
    }
    match scene.instances[2].placement {
        Placement::Moving { open, close } => {
            assert_eq!(open.translation, Vec3::ZERO);
            assert_eq!(close.translation, Vec3::Y);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn film_crop_windows_and_pixel_bounds_follow_pbrt_v4() {
    use crate::description::FileCrop;
    use sahara_render::PixelWindow;
    let film = |extra: &str| {
        let text = format!(
            "Film \"rgb\" \"integer xresolution\" 100 \"integer yresolution\" 50 {extra}\nWorldBegin"
        );
        parse_pbrt(text.as_bytes(), "t.pbrt", Path::new("/nonexistent"))
    };
    let window = |extra: &str| {
        let s = film(extra).unwrap();
        let c = s.settings.as_ref().unwrap().crop_window.expect("a crop");
        (c, c.window(100, 50), s.warnings)
    };
    // Pairs in either order; pixels from ceil(f * size).
    let (c, win, w) = window("\"float cropwindow\" [0.5 0.25 0.1 0.3]");
    assert_eq!(c, FileCrop::Fractions([0.25, 0.5, 0.1, 0.3]));
    assert_eq!(
        win,
        PixelWindow {
            x0: 25,
            x1: 50,
            y0: 5,
            y1: 15
        }
    );
    assert!(w.is_empty(), "{w:?}");
    // Pixel bounds are clipped to the image, with a warning.
    let (_, win, w) = window("\"integer pixelbounds\" [10 120 -3 20]");
    assert_eq!(
        win,
        PixelWindow {
            x0: 10,
            x1: 100,
            y0: 0,
            y1: 20
        }
    );
    assert!(
        w[0].contains("film 'pixelbounds' reach outside the image; clipped"),
        "{w:?}"
    );
    // Both: the crop window wins, as in pbrt-v4.
    let (c, _, w) = window("\"float cropwindow\" [0 1 0 0.5] \"integer pixelbounds\" [0 10 0 10]");
    assert_eq!(c, FileCrop::Fractions([0.0, 1.0, 0.0, 0.5]));
    assert!(
        w[0].contains("both 'cropwindow' and 'pixelbounds' given"),
        "{w:?}"
    );
    // Empty: an error at the parameter.
    let e = film("\"float cropwindow\" [0.2 0.2 0 1]")
        .unwrap_err()
        .to_string();
    assert_eq!(e, "t.pbrt: line 1: column 63: parameter \"float cropwindow\": holds no pixel of the 100x50 image");
}

#[test]
fn camera_fov_is_the_shorter_axis_and_settings_map() {
    let text = "Film \"rgb\" \"integer xresolution\" 100 \"integer yresolution\" 200 \"string filename\" \"out.exr\"\n\
                Sampler \"halton\" \"integer pixelsamples\" 8\nIntegrator \"volpath\" \"integer maxdepth\" 7\n\
                PixelFilter \"box\"\nLookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 60 \"float lensradius\" 0.1 \"float focaldistance\" 5\nWorldBegin";
    let s = parse_pbrt(text.as_bytes(), "t.pbrt", Path::new("/scenes")).unwrap();
    let layer = s.settings.as_ref().unwrap();
    let st = layer.frame_settings();
    assert_eq!((st.width, st.height, st.spp), (100, 200, 8));
    assert_eq!(
        st.integrator,
        sahara_render::Integrator::Path {
            max_depth: 7,
            rr_depth: 3
        }
    );
    assert_eq!(st.filter, sahara_render::Filter::Box { radius: 0.5 });
    assert_eq!(layer.path.as_deref(), Some(Path::new("/scenes/out.exr")));
    let c = &s.scene.camera;
    // Portrait: the 60 degrees span the width; tan(v/2) = tan(30) * 2.
    let expect = (2.0 * (30f64.to_radians().tan() * 2.0).atan()).to_degrees() as f32;
    assert!((c.vfov_deg - expect).abs() < 1e-4, "{}", c.vfov_deg);
    assert_eq!((c.lens_radius, c.focus_distance), (0.1, 5.0));
    assert!((c.eye - Vec3::new(0.0, 0.0, -5.0)).length() < 1e-6);
    // pbrt's image right is up x forward: +x here, looking down +z.
    assert!((c.right - Vec3::X).length() < 1e-6, "{}", c.right);
}

/// The same scene in pbrt and TOML renders the same image.
fn assert_same_image(pbrt: &str, toml: &str, name: &str, exact: bool) {
    let dir = folder(name);
    std::fs::write(dir.join("s.pbrt"), pbrt).unwrap();
    std::fs::write(dir.join("s.toml"), toml).unwrap();
    std::fs::write(
        dir.join("tri.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    )
    .unwrap();
    let p = load_pbrt(&dir.join("s.pbrt")).unwrap();
    let t = load_scene(&dir.join("s.toml")).unwrap();
    let (a, b) = (image(&p.scene, 4), image(&t.scene, 4));
    assert!(
        b.iter().any(|v| v.max_element() > 0.0),
        "the reference image is black"
    );
    if exact {
        assert!(a == b, "{name}: the images differ");
    } else {
        let worst = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (*x - *y).abs().max_element())
            .fold(0.0, f32::max);
        assert!(worst < 1e-3, "{name}: images differ by up to {worst}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn pbrt_and_toml_scenes_render_the_same_spheres_disc_light_and_camera() {
    let pbrt = "Scale -1 1 1\nLookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" 40\nWorldBegin\n\
                LightSource \"point\" \"rgb I\" [5 5 5] \"point3 from\" [1 2 0]\n\
                AttributeBegin Material \"diffuse\" \"rgb reflectance\" [0.5 0.2 0.2] Translate 0 0 5 Shape \"sphere\" AttributeEnd\n\
                AttributeBegin Material \"conductor\" \"rgb eta\" [0.2 0.9 1.1] \"rgb k\" [3.9 2.4 2.1] \"float roughness\" 0.0625 Translate 1.25 -0.5 4 Shape \"sphere\" \"float radius\" 0.5 AttributeEnd\n\
                AttributeBegin Material \"diffuse\" \"rgb reflectance\" [0 0 0]\nAreaLightSource \"diffuse\" \"rgb L\" [4 4 4]\n\
                Transform [1 0 0 0  0 0 1 0  0 -1 0 0  0 3 5 1] Shape \"disk\" \"float radius\" 1 AttributeEnd\n";
    let toml = "[camera]\neye = [0, 0, 0]\ntarget = [0, 0, 1]\nvfov = 40\n\
                [[material]]\nname = \"red\"\ntype = \"diffuse\"\nalbedo = [0.5, 0.2, 0.2]\n\
                [[material]]\nname = \"gold\"\ntype = \"conductor\"\neta = [0.2, 0.9, 1.1]\nk = [3.9, 2.4, 2.1]\nroughness = 0.5\nmultiple_scattering = false\n\
                [[object]]\ntype = \"sphere\"\ncenter = [0, 0, 5]\nradius = 1\nmaterial = \"red\"\n\
                [[object]]\ntype = \"sphere\"\ncenter = [1.25, -0.5, 4]\nradius = 0.5\nmaterial = \"gold\"\n\
                [[light]]\ntype = \"area\"\nshape = \"disc\"\ncenter = [0, 3, 5]\nnormal = [0, -1, 0]\nradius = 1\nradiance = [4, 4, 4]\n\
                [[light]]\ntype = \"point\"\nposition = [1, 2, 0]\nintensity = [5, 5, 5]\n\
                [film]\nwidth = 24\nheight = 24\n";
    assert_same_image(pbrt, toml, "spheres", true);
}

#[test]
fn pbrt_and_toml_scenes_render_the_same_instances_and_motion() {
    let pbrt = "Scale -1 1 1\nLookAt 0 1 -6  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 50\nWorldBegin\n\
                LightSource \"point\" \"rgb I\" [20 20 20] \"point3 from\" [0 4 -4]\n\
                ObjectBegin \"tet\"\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 0 0 1] \"integer indices\" [0 2 1 0 1 3 0 3 2 1 2 3]\nObjectEnd\n\
                AttributeBegin Translate -1.5 0 0 Rotate 30 0 1 0 Scale 1.5 1.5 1.5 ObjectInstance \"tet\" AttributeEnd\n\
                AttributeBegin Translate 1 0 0 ActiveTransform EndTime Translate 0 1 0 ActiveTransform All ObjectInstance \"tet\" AttributeEnd\n";
    let toml = "[camera]\neye = [0, 1, -6]\ntarget = [0, 0, 0]\nvfov = 50\nshutter_open = 0\nshutter_close = 1\n\
                [[object]]\ntype = \"mesh\"\nfile = \"tri.obj\"\ntransform = { translate = [-1.5, 0, 0], rotate = { axis = [0, 1, 0], degrees = 30 }, scale = 1.5 }\n\
                [[object]]\ntype = \"mesh\"\nfile = \"tri.obj\"\nmotion = { open = { translate = [1, 0, 0] }, close = { translate = [1, 1, 0] } }\n\
                [[light]]\ntype = \"point\"\nposition = [0, 4, -4]\nintensity = [20, 20, 20]\n\
                [film]\nwidth = 24\nheight = 24\n";
    // pbrt's default material is diffuse 0.5, the OBJ's (no MTL) Sahara's grey 0.8:
    // give the TOML objects pbrt's.
    let toml = toml.replace(
        "[[object]]\ntype = \"mesh\"\nfile = \"tri.obj\"\n",
        "[[object]]\ntype = \"mesh\"\nfile = \"tri.obj\"\nmaterial = \"half\"\n",
    ) + "[[material]]\nname = \"half\"\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n";
    assert_same_image(pbrt, &toml, "instances", false);
}

#[test]
fn the_fuzz_seed_with_every_directive_loads() {
    let seed = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/seeds/pbrt/scene.pbrt");
    let text = std::fs::read(&seed).unwrap();
    let s = parse_pbrt(&text, "seed.pbrt", Path::new("/nonexistent")).unwrap();
    let scene = &s.scene;
    let w = &s.warnings;
    assert_eq!(scene.lights.len(), 2, "spot and distant; {w:#?}");
    assert!(matches!(
        scene.environment,
        Some(sahara_render::Environment::Constant(_))
    ));
    // The tetrahedron object, instanced twice (once moving), subdivided twice.
    let tet = scene
        .meshes
        .iter()
        .position(|m| m.mesh.indices.len() == 4 * 16)
        .expect("the object mesh");
    let uses: Vec<_> = scene
        .instances
        .iter()
        .filter(|i| i.mesh as usize == tet)
        .collect();
    assert_eq!(uses.len(), 2);
    assert!(uses[1].placement.is_moving());
    assert!(scene
        .materials
        .iter()
        .any(|m| m.is_emissive() && m.two_sided_emission));
    assert_eq!(
        s.settings.as_ref().unwrap().crop_window,
        Some(crate::description::FileCrop::Fractions([
            0.0, 1.0, 0.0, 1.0
        ]))
    );
    // The mix picks gold (amount 0.3 < 0.5): the conductor of gold's
    // named spectra, and says so.
    let (eta, k) = (
        Vec3::new(0.3267, 0.4015, 1.5758),
        Vec3::new(36.1267, 2.3372, 1.7213),
    );
    assert!(scene.materials.iter().any(|m| matches!(m.bsdf,
        sahara_render::Bsdf::ComplexConductor { eta: e, k: kk, roughness, multiple_scattering: false, .. } if e == eta && kk == k && roughness == 0.1f32.sqrt().sqrt())));
    assert!(
        w.iter()
            .any(|l| l.contains("material 'mix': the blend is replaced")),
        "{w:#?}"
    );
}

#[test]
fn an_octahedral_environment_map_becomes_a_lat_long_map_through_the_light_transform() {
    let dir = folder("envmap");
    // A 2x2 equal-area map: the quadrant u > 1/2, v < 1/2 (directions with
    // x > 0, y < 0 in light space) red, the rest black.
    let texels: Vec<f32> = [[0.0; 3], [1.0, 0.0, 0.0], [0.0; 3], [0.0; 3]].concat();
    crate::output::image::write_exr(&dir.join("sky.exr"), 2, 2, &texels, &[]).unwrap();
    // Rotate 90 about z: light +x is world +y, light -y is world +x.
    std::fs::write(
        dir.join("s.pbrt"),
        "WorldBegin\nRotate 90 0 0 1\nLightSource \"infinite\" \"string filename\" \"sky.exr\" \"float scale\" 2\n",
    )
    .unwrap();
    let s = load_pbrt(&dir.join("s.pbrt")).unwrap();
    let Some(sahara_render::Environment::Map { texture, .. }) = &s.scene.environment else {
        panic!("no map")
    };
    assert_eq!((texture.width, texture.height), (4, 2));
    // World (1, 1, 0) normalised is light (1, -1, 0): red, at twice the value.
    let at = |w: Vec3| {
        let uv = sahara_render::environment_uv(w.normalize());
        texture.texel((uv.x * 4.0) as i64, (uv.y * 2.0) as i64)
    };
    assert_eq!(at(Vec3::new(1.0, 0.3, 0.0)), Vec3::new(2.0, 0.0, 0.0));
    assert_eq!(at(Vec3::new(-1.0, 0.3, 0.0)), Vec3::ZERO);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A little-endian PFM of `w x h` RGB texels given from the top row.
fn write_pfm(path: &Path, w: u32, h: u32, rgb_top_down: &[[f32; 3]]) {
    let mut b = format!("PF\n{w} {h}\n-1\n").into_bytes();
    for y in (0..h as usize).rev() {
        for px in &rgb_top_down[y * w as usize..(y + 1) * w as usize] {
            px.iter().for_each(|v| b.extend(v.to_le_bytes()));
        }
    }
    std::fs::write(path, b).unwrap();
}

/// The texture of the material of the one shape of `text`.
fn shape_material(dir: &Path, text: &str) -> (sahara_render::Material, Vec<String>) {
    std::fs::write(dir.join("s.pbrt"), text).unwrap();
    let s = load_pbrt(&dir.join("s.pbrt")).unwrap();
    let id = s.scene.instances[0].material.unwrap();
    (s.scene.materials[id as usize].clone(), s.warnings)
}

#[test]
fn tga_and_pfm_imagemaps_load_and_textures_combine_texel_by_texel() {
    let dir = folder("imagemaps");
    // A 2x1 TGA, 24-bit, top-down: red, then grey 128.
    let mut tga = vec![0u8, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 1, 0, 24, 0x20];
    tga.extend([0, 0, 255, 128, 128, 128]);
    std::fs::write(dir.join("a.tga"), &tga).unwrap();
    write_pfm(
        &dir.join("b.pfm"),
        2,
        1,
        &[[0.0, 0.0, 1.0], [4.0, 4.0, 4.0]],
    );
    let quad = "Shape \"bilinearmesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0] \"point2 uv\" [0 0 1 0 0 1 1 1]";
    let srgb = sahara_render::srgb8_to_linear;
    let (m, w) = shape_material(
        &dir,
        &format!("Texture \"a\" \"spectrum\" \"imagemap\" \"string filename\" \"a.tga\"\n\
                  Texture \"b\" \"spectrum\" \"imagemap\" \"string filename\" \"b.pfm\"\n\
                  Texture \"m\" \"spectrum\" \"mix\" \"texture tex1\" \"a\" \"texture tex2\" \"b\" \"float amount\" 0.25\n\
                  Material \"diffuse\" \"texture reflectance\" \"m\"\n{quad}"),
    );
    assert!(w.is_empty(), "{w:?}");
    let t = m.textures.base_color.expect("the mixed image").texture;
    assert_eq!((t.width, t.height), (2, 1));
    assert_eq!(t.texel(0, 0), Vec3::new(0.75, 0.0, 0.25));
    assert_eq!(t.texel(1, 0), Vec3::splat(0.75 * srgb(128) + 1.0));
    // "linear": the 8-bit values as they are stored.
    let (m, _) = shape_material(
        &dir,
        &format!("Texture \"a\" \"spectrum\" \"imagemap\" \"string filename\" \"a.tga\" \"string encoding\" \"linear\"\n\
                  Material \"diffuse\" \"texture reflectance\" \"a\"\n{quad}"),
    );
    assert_eq!(
        m.textures.base_color.unwrap().texture.texel(1, 0),
        Vec3::splat(128.0 / 255.0)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn imagemaps_keep_their_wrap_mode_and_uv_scale_and_offset() {
    let dir = folder("imagemap_sampling");
    let mut tga = vec![0u8, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 1, 0, 24, 0x20];
    tga.extend([0, 0, 255, 128, 128, 128]);
    std::fs::write(dir.join("a.tga"), &tga).unwrap();
    let quad = "Shape \"bilinearmesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0] \"point2 uv\" [0 0 1 0 0 1 1 1]";
    let (m, w) = shape_material(
        &dir,
        &format!("Texture \"a\" \"spectrum\" \"imagemap\" \"string filename\" \"a.tga\" \"string wrap\" \"clamp\" \"float uscale\" 2 \"float vscale\" 3 \"float udelta\" 0.25 \"float vdelta\" 0.5\n\
                  Material \"diffuse\" \"texture reflectance\" \"a\"\n{quad}"),
    );
    assert!(w.is_empty(), "{w:?}");
    let map = m.textures.base_color.as_ref().expect("the image");
    assert_eq!(map.wrap, [sahara_render::Wrap::Clamp; 2]);
    let uv = map.transform.transform_point2(glam::Vec2::new(1.0, 1.0));
    assert_eq!(uv, glam::Vec2::new(2.25, 3.5));
    // Past the right edge, clamping reads the last texel (grey), where
    // repeating would read the first (red).
    let grey = sahara_render::srgb8_to_linear(128);
    let point = sahara_render::UvFootprint::POINT;
    let far = glam::Vec2::new(0.9, 0.5);
    let tint = m.at(&[far, far], &point).bsdf.tint;
    assert!(
        (tint - Vec3::splat(grey)).abs().max_element() < 1e-6,
        "{tint}"
    );
    // pbrt's "black" border is not Sahara's: clamped, with a warning.
    let (m, w) = shape_material(
        &dir,
        &format!("Texture \"a\" \"spectrum\" \"imagemap\" \"string filename\" \"a.tga\" \"string wrap\" \"black\"\n\
                  Material \"diffuse\" \"texture reflectance\" \"a\"\n{quad}"),
    );
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].contains("wrap 'black'"), "{w:?}");
    assert_eq!(
        m.textures.base_color.unwrap().wrap,
        [sahara_render::Wrap::Clamp; 2]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn alpha_textures_cut_shapes_out() {
    let dir = folder("alpha");
    let quad = "Shape \"bilinearmesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0] \"point2 uv\" [0 0 1 0 0 1 1 1]";
    // A float checkerboard of 2 x 1 checks: opaque in u < 1/2 (tex1 = 1).
    let (m, w) = shape_material(
        &dir,
        &format!(
            "Texture \"c\" \"float\" \"checkerboard\" \"float uscale\" 2 \"float vscale\" 1\n\
                  Material \"diffuse\" \"rgb reflectance\" [0.2 0.4 0.6]\n\
                  AttributeBegin {quad} \"texture alpha\" \"c\" AttributeEnd\n"
        ),
    );
    assert!(w.is_empty(), "{w:?}");
    assert_eq!(m.alpha_mode, sahara_render::AlphaMode::Blend);
    for u in [0.0, 0.5, 0.999] {
        let at = glam::Vec2::new(0.1, 0.5);
        assert!(!m.passes(&[at, at], u), "opaque check");
        let hole = glam::Vec2::new(0.9, 0.5);
        assert!(m.passes(&[hole, hole], u), "the hole");
    }
    let hole = glam::Vec2::new(0.9, 0.5);
    let point = sahara_render::UvFootprint::POINT;
    assert_eq!(m.at(&[hole, hole], &point).bsdf.tint, Vec3::ONE);
    // An RGBA TGA as a float texture is its alpha; the colour texture keeps its texels.
    let mut tga = vec![0u8, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 1, 0, 32, 0x28];
    tga.extend([0, 0, 255, 255, 0, 255, 0, 0]);
    std::fs::write(dir.join("leaf.tga"), &tga).unwrap();
    let (m, _) = shape_material(
        &dir,
        &format!(
            "Texture \"leaf\" \"spectrum\" \"imagemap\" \"string filename\" \"leaf.tga\"\n\
                  Texture \"cut\" \"float\" \"imagemap\" \"string filename\" \"leaf.tga\"\n\
                  Material \"diffuse\" \"texture reflectance\" \"leaf\"\n\
                  AttributeBegin {quad} \"texture alpha\" \"cut\" AttributeEnd\n"
        ),
    );
    let t = &m.textures.base_color.as_ref().unwrap().texture;
    let rgba: Vec<_> = t.texels_rgba().collect();
    assert_eq!((rgba[0].w, rgba[1].w), (1.0, 0.0));
    assert_eq!(rgba[0].truncate(), Vec3::new(1.0, 0.0, 0.0));
    // A constant alpha of 0 removes the shape; 0.5 is half transparent.
    std::fs::write(dir.join("s.pbrt"), format!("AttributeBegin {quad} \"float alpha\" 0 AttributeEnd\nAttributeBegin {quad} \"float alpha\" 0.5 AttributeEnd\n")).unwrap();
    let s = load_pbrt(&dir.join("s.pbrt")).unwrap();
    assert_eq!(s.scene.instances.len(), 1);
    let m = &s.scene.materials[s.scene.instances[0].material.unwrap() as usize];
    assert_eq!(
        (m.alpha_mode, m.alpha),
        (sahara_render::AlphaMode::Blend, 0.5)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_fuzz_seed_with_every_material_warns_only_of_what_it_approximates() {
    use sahara_render::Bsdf;
    let seed = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/seeds/pbrt/materials.pbrt");
    let text = std::fs::read(&seed).unwrap();
    let s = parse_pbrt(&text, "seed.pbrt", Path::new("/nonexistent")).unwrap();
    let w = &s.warnings;
    // The approximations, one line each: nothing else is lost.
    let kinds: Vec<&str> = w
        .iter()
        .map(|l| l.split(": ").nth(1).unwrap_or(""))
        .collect();
    assert_eq!(
        kinds,
        [
            "material 'coatedconductor'",
            "material 'plastic'",
            "material 'substrate'",
            "material 'uber'",
            "material 'translucent'",
            "material 'dielectric'"
        ],
        "{w:#?}"
    );
    let m = &s.scene.materials;
    let has = |f: &dyn Fn(&sahara_render::Material) -> bool| m.iter().any(f);
    assert!(has(
        &|m| matches!(m.bsdf, Bsdf::CoatedDiffuse { ior, .. } if ior == 1.4)
            && m.alpha_mode == sahara_render::AlphaMode::Blend
    ));
    assert!(has(&|m| matches!(m.bsdf, Bsdf::ThinDielectric { .. })));
    assert!(has(
        &|m| matches!(m.bsdf, Bsdf::Dielectric { ior } if ior == 1.6727)
    ));
    assert!(has(
        &|m| matches!(m.bsdf, Bsdf::Diffuse { albedo } if albedo == Vec3::new(0.75, 0.0, 0.25))
    ));
    // The sampled conductor spectra were fitted: eta between the samples' extremes.
    assert!(has(
        &|m| matches!(m.bsdf, Bsdf::ComplexConductor { eta, roughness, .. }
        if eta.min_element() >= 0.2 && eta.max_element() <= 0.5 && roughness > 0.4)
    ));
    // 13 shapes: the sphere of alpha 0 is not there.
    assert_eq!(s.scene.instances.len(), 12);
}

/// pbrt's bidirectional and photon integrators map onto Sahara's: `bdpt`
/// and `lightpath` with their `maxdepth`, `mlt` onto `bdpt` with a
/// warning, `sppm` with its radius and photons (pbrt's `-1`: one per
/// pixel).
#[test]
fn bidirectional_integrators_map_onto_bdpt_and_light_tracing() {
    use sahara_render::Integrator;
    let integrator = |line: &str| {
        let text =
            format!("{line}\nLookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin");
        let s = parse_pbrt(text.as_bytes(), "t.pbrt", Path::new("/scenes")).unwrap();
        (
            s.settings.as_ref().unwrap().frame_settings().integrator,
            s.warnings.clone(),
        )
    };
    let (i, w) = integrator("Integrator \"bdpt\" \"integer maxdepth\" 7");
    assert_eq!(i, Integrator::Bdpt { max_depth: 7 });
    assert!(w.is_empty(), "{w:?}");
    let (i, _) = integrator("Integrator \"bdpt\"");
    assert_eq!(i, Integrator::Bdpt { max_depth: 5 });
    let (i, w) = integrator("Integrator \"lightpath\" \"integer maxdepth\" 3");
    assert_eq!(i, Integrator::LightPath { max_depth: 3 });
    assert!(w.is_empty(), "{w:?}");
    let (i, w) = integrator("Integrator \"mlt\" \"integer mutationsperpixel\" 100");
    assert_eq!(i, Integrator::Bdpt { max_depth: 5 });
    assert!(
        w.iter()
            .any(|w| w.contains("'mlt' is rendered by bidirectional path tracing")),
        "{w:?}"
    );
    let (i, _) = integrator(
        "Integrator \"sppm\" \"integer maxdepth\" 4 \"float radius\" 0.25 \"integer photonsperiteration\" 5000",
    );
    assert_eq!(
        i,
        Integrator::Sppm {
            max_depth: 4,
            radius: 0.25,
            photons: 5000
        }
    );
    let (i, _) = integrator("Integrator \"sppm\"");
    assert_eq!(
        i,
        Integrator::Sppm {
            max_depth: 5,
            radius: 1.0,
            photons: 0
        }
    );
    let (_, w) = integrator("Integrator \"bdpt\" \"bool visualizestrategies\" true");
    assert!(w.iter().any(|w| w.contains("visualizestrategies")), "{w:?}");
}

/// The bytes of a Mitsuba `.vol` file of one channel.
fn vol_bytes(size: [u32; 3], lo: [f32; 3], hi: [f32; 3], values: &[f32]) -> Vec<u8> {
    let mut b = b"VOL\x03".to_vec();
    for v in [1, size[0], size[1], size[2], 1] {
        b.extend(v.to_le_bytes());
    }
    for v in lo.iter().chain(&hi).chain(values) {
        b.extend(v.to_le_bytes());
    }
    b
}

#[test]
fn pbrt_and_toml_media_make_the_same_scene_and_image() {
    let pbrt = "Scale -1 1 1\nLookAt 0 0 0  0 0 1  0 1 0\nMediumInterface \"\" \"fog\"\nCamera \"perspective\" \"float fov\" 40\nWorldBegin\n\
                MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.02 0.03 0.04] \"rgb sigma_s\" [0.1 0.1 0.1] \"float scale\" 2 \"float g\" 0.3 \"rgb Le\" [0.5 0.25 1] \"float Lescale\" 2\n\
                AttributeBegin Translate 0 1 4 Scale 2 2 2\n\
                MakeNamedMedium \"smoke\" \"string type\" \"uniformgrid\" \"integer nx\" 2 \"integer ny\" 1 \"integer nz\" 2 \"float density\" [0 1 2 0.5] \
                \"point3 p0\" [-0.5 -0.5 -0.5] \"point3 p1\" [0.5 0.5 0.5] \"rgb sigma_s\" [3 3 3] \"rgb sigma_a\" [0.5 0.5 0.5]\nAttributeEnd\n\
                LightSource \"point\" \"rgb I\" [5 5 5] \"point3 from\" [1 2 0]\n\
                AttributeBegin MediumInterface \"fog\" \"\" Material \"interface\" Shape \"sphere\" \"float radius\" 20 AttributeEnd\n\
                AttributeBegin MediumInterface \"smoke\" \"fog\" Material \"interface\" Translate 0 1 4 Shape \"sphere\" \"float radius\" 1.8 AttributeEnd\n\
                AttributeBegin MediumInterface \"fog\" Material \"diffuse\" Translate 0 -1.5 5 Shape \"sphere\" AttributeEnd\n\
                AttributeBegin MediumInterface \"\" \"fog\" Material \"subsurface\" \"string name\" \"Skin1\" \"float scale\" 0.5 \"float eta\" 1.4\n\
                Translate 1.25 -0.5 4 Shape \"sphere\" \"float radius\" 0.5 AttributeEnd\n";
    let toml = "[camera]\neye = [0, 0, 0]\ntarget = [0, 0, 1]\nvfov = 40\nmedium = \"fog\"\n\
                [[medium]]\nname = \"fog\"\ntype = \"homogeneous\"\nsigma_a = [0.04, 0.06, 0.08]\nsigma_s = [0.2, 0.2, 0.2]\ng = 0.3\nemission = [0.5, 0.25, 1]\nemission_scale = 2\n\
                [[medium]]\nname = \"smoke\"\ntype = \"grid\"\nfile = \"smoke.vol\"\nmin = [-1, 0, 3]\nmax = [1, 2, 5]\nsigma_s = [3, 3, 3]\nsigma_a = [0.5, 0.5, 0.5]\n\
                [[medium]]\nname = \"skin\"\ntype = \"homogeneous\"\nsigma_a = [0.016, 0.085, 0.24]\nsigma_s = [0.37, 0.44, 0.505]\n\
                [[material]]\nname = \"grey\"\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\
                [[material]]\nname = \"boundary\"\ntype = \"dielectric\"\nior = 1.4\n\
                [[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 20\nmedium_inside = \"fog\"\n\
                [[object]]\ntype = \"sphere\"\ncenter = [0, 1, 4]\nradius = 1.8\nmedium_inside = \"smoke\"\nmedium_outside = \"fog\"\n\
                [[object]]\ntype = \"sphere\"\ncenter = [0, -1.5, 5]\nradius = 1\nmaterial = \"grey\"\n\
                [[object]]\ntype = \"sphere\"\ncenter = [1.25, -0.5, 4]\nradius = 0.5\nmaterial = \"boundary\"\nmedium_inside = \"skin\"\nmedium_outside = \"fog\"\n\
                [[light]]\ntype = \"point\"\nposition = [1, 2, 0]\nintensity = [5, 5, 5]\n\
                [film]\nwidth = 24\nheight = 24\n";
    let dir = folder("media");
    std::fs::write(dir.join("s.pbrt"), pbrt).unwrap();
    std::fs::write(dir.join("s.toml"), toml).unwrap();
    std::fs::write(
        dir.join("smoke.vol"),
        vol_bytes([2, 1, 2], [0.0; 3], [1.0; 3], &[0.0, 1.0, 2.0, 0.5]),
    )
    .unwrap();
    let p = load_pbrt(&dir.join("s.pbrt")).unwrap();
    let t = load_scene(&dir.join("s.toml")).unwrap();
    assert!(p.warnings.is_empty(), "{:#?}", p.warnings);
    // The sphere with the same medium on both sides bounds nothing.
    crate::common::test_scenes::assert_same_media(&p.scene, &t.scene, 3, 3);
    crate::common::test_scenes::assert_same_render(&p.scene, &t.scene);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_media_are_errors_naming_the_line() {
    let medium = |params: &str| {
        format!("WorldBegin\nMakeNamedMedium \"m\" {params}\nMediumInterface \"m\" \"\"\nMaterial \"interface\"\nShape \"sphere\"")
    };
    let e = err("WorldBegin\nMediumInterface \"nothing\" \"\"\nShape \"sphere\"");
    assert!(
        e.contains("t.pbrt: line 2") && e.contains("no MakeNamedMedium defines \"nothing\""),
        "{e}"
    );
    let e = err(&medium(
        "\"string type\" \"homogeneous\" \"rgb sigma_a\" [-1 0 0]",
    ));
    assert!(e.contains("line 2") && e.contains("absorption"), "{e}");
    let e = err(&medium("\"string type\" \"uniformgrid\" \"integer nx\" 2 \"integer ny\" 2 \"float density\" [1 1 1]"));
    assert!(
        e.contains("line 2") && e.contains("needs 4 density values but 3"),
        "{e}"
    );
    let e = err(&medium(
        "\"string type\" \"homogeneous\" \"rgb Le\" [1 -1 1]",
    ));
    assert!(
        e.contains("t.pbrt: line 2") && e.contains("emission"),
        "{e}"
    );
    let e = err(&medium(
        "\"string type\" \"homogeneous\" \"rgb Le\" [1 1 1] \"float Lescale\" -2",
    ));
    assert!(e.contains("line 2") && e.contains("Lescale"), "{e}");
    let e = err(&medium("\"string type\" \"uniformgrid\" \"integer nx\" 2 \"float density\" [1 1] \"rgb Le\" [1 1 1] \"float Lescale\" [1 2 3]"));
    assert!(
        e.contains("line 2") && e.contains("needs 2 \"Lescale\" values (or one) but 3"),
        "{e}"
    );
    let e = err(&medium(
        "\"string type\" \"homogeneous\" \"string preset\" \"Jam\"",
    ));
    assert!(e.contains("no measured medium is named \"Jam\""), "{e}");
    let e = err(&medium("\"string type\" \"nanovdb\""));
    assert!(
        e.contains("line 2") && e.contains("needs \"string filename\""),
        "{e}"
    );
    let e = err(&medium(
        "\"string type\" \"nanovdb\" \"string filename\" \"nothing.nvdb\"",
    ));
    assert!(e.contains("nothing.nvdb"), "{e}");
    for (params, want) in [
        ("", "needs \"rgb sigma_a\" or \"rgb sigma_s\""),
        (
            "\"integer nx\" 2 \"rgb sigma_a\" [1 1 1]",
            "needs 2 \"sigma_a\" colours but 1",
        ),
        (
            "\"rgb sigma_s\" [1 1 1] \"rgb Le\" [1 1 1]",
            "with \"Le\" needs \"rgb sigma_a\"",
        ),
        (
            "\"rgb sigma_a\" [1 -1 1]",
            "\"sigma_a\" grid value 0 is [1, -1, 1]",
        ),
        (
            "\"rgb sigma_a\" [1 1 1 1]",
            "not a whole number of 3-tuples",
        ),
    ] {
        let e = err(&medium(&format!("\"string type\" \"rgbgrid\" {params}")));
        assert!(e.contains("line 2") && e.contains(want), "{params}: {e}");
    }
    let e = err(&medium("\"float scale\" 2"));
    assert!(e.contains("has no \"string type\""), "{e}");
    let e = err(&medium(
        "\"string type\" \"cloud\" \"point3 p0\" [0 0 0] \"point3 p1\" [1 0 1]",
    ));
    assert!(
        e.contains("line 2") && e.contains("p1 must be above p0"),
        "{e}"
    );
    let e = err(&medium("\"string type\" \"cloud\" \"float g\" 1"));
    assert!(e.contains("line 2") && e.contains("asymmetry"), "{e}");
    let e = err(
        "WorldBegin\nMaterial \"subsurface\" \"rgb reflectance\" [0.5 0.5 0.5]\nShape \"sphere\"",
    );
    assert!(
        e.contains("line 2") && e.contains("\"reflectance\" form"),
        "{e}"
    );
    let e = err("WorldBegin\nMaterial \"subsurface\" \"float g\" 1\nShape \"sphere\"");
    assert!(e.contains("line 2") && e.contains("asymmetry"), "{e}");
}

#[test]
fn media_follow_the_graphics_state_and_presets_and_emit() {
    let text = "MediumInterface \"a\"\nCamera \"perspective\"\nWorldBegin\n\
                MakeNamedMedium \"a\" \"string type\" \"homogeneous\" \"string preset\" \"Ketchup\" \"float scale\" 10 \"rgb Le\" [1 1 1]\n\
                MakeNamedMedium \"b\" \"string type\" \"homogeneous\"\n\
                MakeNamedMedium \"c\" \"string type\" \"uniformgrid\" \"integer nx\" 2 \"float density\" [1 2] \"rgb Le\" [0 2 0] \"float Lescale\" [3 4] \"float temperaturescale\" 2\n\
                MakeNamedMedium \"d\" \"string type\" \"uniformgrid\" \"float density\" [1] \"rgb Le\" [1 1 1]\n\
                AttributeBegin MediumInterface \"b\" \"a\" Shape \"sphere\" AttributeEnd\n\
                Shape \"sphere\"\n\
                AttributeBegin Material \"interface\" Shape \"sphere\" AttributeEnd\n";
    let s = parse_pbrt(text.as_bytes(), "t.pbrt", Path::new("/nonexistent")).unwrap();
    // The camera's one-name interface: inside and outside "a".
    assert_eq!(s.scene.camera_medium, Some(0));
    let sahara_render::Medium::Homogeneous(a) = &s.scene.media[0] else {
        panic!()
    };
    assert!((a.sigma_s - Vec3::new(1.8, 0.7, 0.3)).abs().max_element() < 1e-6);
    assert!((a.sigma_a - Vec3::new(0.61, 9.7, 14.5)).abs().max_element() < 1e-5);
    assert_eq!(
        s.scene.media[1],
        sahara_render::Medium::homogeneous(Vec3::ONE, Vec3::ONE, 0.0)
    );
    // Only the first sphere bounds media; AttributeEnd restored none; the
    // interface sphere without media is not rendered.
    assert_eq!(s.scene.medium_interfaces.len(), 1);
    assert_eq!(s.scene.medium_interfaces[0].1.inside, Some(1));
    assert_eq!(s.scene.medium_interfaces[0].1.outside, Some(0));
    assert!(!s.scene.medium_interfaces[0].1.index_matched);
    // Emission: Le times Lescale; a grid's Lescale is a grid of its own
    // (pbrt's one-cell grid without one).
    assert_eq!(s.scene.media[0].emission(), Vec3::ONE);
    for (k, le, scale) in [
        (2, Vec3::new(0.0, 2.0, 0.0), vec![3.0, 4.0]),
        (3, Vec3::ONE, vec![1.0]),
    ] {
        let sahara_render::Medium::Grid(c) = &s.scene.media[k] else {
            panic!()
        };
        assert_eq!(c.emission, le);
        let grid = c.emission_scale.as_ref().unwrap();
        let want = [scale.len() as u32, 1, 1];
        assert_eq!(*grid, sahara_render::DensityGrid::new(want, scale).unwrap());
    }

    assert!(
        s.warnings
            .iter()
            .any(|l| l.contains("'interface' material (no surface) and no media")),
        "{:#?}",
        s.warnings
    );
}

/// A `uniformgrid`'s `temperature` grid emits as pbrt-v4's normalised
/// black body at `(t - offset) * scale` kelvin per voxel (nothing at 100 K
/// or below), in place of `Le`, times the `Lescale` grid; the colours
/// brighten and whiten as the temperature rises.
#[test]
fn temperature_grids_glow_as_black_bodies() {
    let text = "WorldBegin\n\
                MakeNamedMedium \"fire\" \"string type\" \"uniformgrid\" \"integer nx\" 4 \"float density\" [1 1 1 1] \"float temperature\" [10 150 300 650] \"float temperatureoffset\" 50 \"float temperaturescale\" 10 \"rgb Le\" [9 9 9]\n\
                MediumInterface \"fire\" \"\" Material \"interface\" Shape \"sphere\"\n";
    let s = parse_pbrt(text.as_bytes(), "t.pbrt", Path::new("/nonexistent")).unwrap();
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
    let sahara_render::Medium::Grid(g) = &s.scene.media[0] else {
        panic!("{:?}", s.scene.media)
    };
    assert_eq!(g.emission, Vec3::ONE);
    assert!(g.emission_scale.is_some());
    let colours = g.emission_colour.as_ref().unwrap();
    // The voxels' centres: 0 K (below 100), 1000 K, 2500 K, 6000 K.
    let c: Vec<Vec3> = (0..4)
        .map(|i| colours.lookup(Vec3::new((i as f32 + 0.5) / 4.0, 0.5, 0.5)))
        .collect();
    assert_eq!(c[0], Vec3::ZERO);
    let luminance = |v: Vec3| v.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    assert!(c[1].x > 0.0 && c[1].x > 10.0 * c[1].z, "{c:?}");
    assert!(
        luminance(c[1]) < luminance(c[2]) && luminance(c[2]) < luminance(c[3]),
        "{c:?}"
    );
    assert!(c[2].x / c[2].z > c[3].x / c[3].z, "{c:?}");
    // Near the peak of its spectrum in the visible, 6000 K is near white
    // and near 1.
    assert!(
        c[3].min_element() > 0.5 && c[3].max_element() < 1.2,
        "{c:?}"
    );
}

/// A `nanovdb` medium reads its grid from the `.nvdb` file (here the
/// NanoVDB twin of `blob.vdb`), placed by the file's map and then by the
/// transform in effect, with the coefficients times `scale`.
#[test]
fn nanovdb_media_read_their_grid() {
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/assets");
    let text = "WorldBegin\nTranslate 1 2 3\n\
                MakeNamedMedium \"smoke\" \"string type\" \"nanovdb\" \"string filename\" \"blob.nvdb\" \"rgb sigma_s\" [1 2 3] \"float scale\" 2\n\
                MediumInterface \"smoke\" \"\" Material \"interface\" Shape \"sphere\"\n";
    let s = parse_pbrt(text.as_bytes(), "t.pbrt", &assets).unwrap();
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
    let sahara_render::Medium::Grid(g) = &s.scene.media[0] else {
        panic!("{:?}", s.scene.media)
    };
    let vdb = sahara_readers::vdb::read_vdb(&assets.join("blob.vdb"), "density").unwrap();
    let want = sahara_render::GridMedium::new(
        sahara_render::DensityGrid::new(vdb.size, vdb.values.clone()).unwrap(),
        Vec3::splat(2.0),
        Vec3::new(2.0, 4.0, 6.0),
        sahara_render::HenyeyGreenstein::new(0.0),
        glam::Affine3A::from_translation(Vec3::new(1.0, 2.0, 3.0)) * vdb.to_world(),
    );
    assert_eq!(g.coefficients, want.coefficients);
    assert!(g.to_medium.abs_diff_eq(want.to_medium, 1e-6));
}

/// A `nanovdb` medium whose file holds a `temperature` grid glows: each
/// density voxel's emission colour is the normalised black body of the
/// temperature at the same voxel, times `Lescale` (or `LeScale`).
#[test]
fn nanovdb_temperature_grids_glow() {
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/assets");
    let text = "WorldBegin\n\
                MakeNamedMedium \"fire\" \"string type\" \"nanovdb\" \"string filename\" \"fireball.nvdb\" \"float Lescale\" 2\n\
                MakeNamedMedium \"old\" \"string type\" \"nanovdb\" \"string filename\" \"fireball.nvdb\" \"float LeScale\" 5\n\
                MediumInterface \"fire\" \"\" Material \"interface\" Shape \"sphere\" \"float radius\" 3\n";
    let s = parse_pbrt(text.as_bytes(), "t.pbrt", &assets).unwrap();
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
    let sahara_render::Medium::Grid(g) = &s.scene.media[0] else {
        panic!("{:?}", s.scene.media)
    };
    assert_eq!(g.emission, Vec3::splat(2.0));
    // pbrt-v4's first spelling, as in pbrt-v4-scenes' explosion.pbrt.
    assert_eq!(s.scene.media[1].emission(), Vec3::splat(5.0));
    let colours = g.emission_colour.as_ref().unwrap();
    let t = sahara_readers::nanovdb::read_nanovdb(&assets.join("fireball.nvdb"), "temperature")
        .unwrap();
    let d =
        sahara_readers::nanovdb::read_nanovdb(&assets.join("fireball.nvdb"), "density").unwrap();
    assert_eq!((t.size, t.index_min), (d.size, d.index_min));
    let n = d.size.map(|v| v as usize);
    let mut checked = 0;
    for (i, &kelvin) in t.values.iter().enumerate() {
        let (x, y, z) = (i % n[0], i / n[0] % n[1], i / (n[0] * n[1]));
        let centre = (Vec3::new(x as f32, y as f32, z as f32) + 0.5)
            / Vec3::new(n[0] as f32, n[1] as f32, n[2] as f32);
        let got = colours.lookup(centre);
        let want = if kelvin > 100.0 {
            let c = crate::common::spectrum::blackbody_radiance_rgb(f64::from(kelvin.round()));
            DVec3::from_array(c).as_vec3()
        } else {
            Vec3::ZERO
        };
        assert!((got - want).abs().max_element() < 1e-6, "{i}: {got} {want}");
        checked += usize::from(kelvin > 1000.0);
    }
    assert!(checked > 1000, "{checked}");
}

/// An `rgbgrid` keeps its colours per voxel: `sigma_a` and `sigma_s`
/// times `scale`, a missing one 1 throughout, `Le` as the emission's
/// colour times `Lescale`.
#[test]
fn rgb_grids_keep_their_colours_per_voxel() {
    use sahara_render::{ColourGrid, ColourVolume, GridCoefficients, GridMedium, HenyeyGreenstein};
    let text = "WorldBegin\n\
                MakeNamedMedium \"a\" \"string type\" \"rgbgrid\" \"integer nx\" 2 \"rgb sigma_a\" [1 2 3 4 5 6] \"rgb Le\" [0 1 0 1 0 0] \"float Lescale\" 3 \"float scale\" 2 \"float g\" 0.5 \"point3 p1\" [2 1 1]\n\
                MakeNamedMedium \"b\" \"string type\" \"rgbgrid\" \"rgb sigma_s\" [0.5 0.25 1]\n\
                MediumInterface \"a\" \"b\" Material \"interface\" Shape \"sphere\"\n";
    let s = parse_pbrt(text.as_bytes(), "t.pbrt", Path::new("/nonexistent")).unwrap();
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
    let colours = |v: &[[f32; 3]]| {
        let v: Vec<Vec3> = v.iter().map(|c| Vec3::from_array(*c)).collect();
        ColourGrid::new([v.len() as u32, 1, 1], v).unwrap()
    };
    let a = GridMedium::with_coefficients(
        GridCoefficients::absorption_scattering(
            ColourVolume::Grid(colours(&[[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])),
            ColourVolume::Constant(Vec3::ONE),
            2.0,
        ),
        HenyeyGreenstein::new(0.5),
        glam::Affine3A::from_scale(Vec3::new(2.0, 1.0, 1.0)),
    )
    .with_emission_colour(colours(&[[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]));
    let a = sahara_render::Medium::Grid(Box::new(a)).with_emission(Vec3::splat(3.0));
    assert_eq!(s.scene.media[0], a);
    let b = GridMedium::with_coefficients(
        GridCoefficients::absorption_scattering(
            ColourVolume::Constant(Vec3::ONE),
            ColourVolume::Grid(colours(&[[0.5, 0.25, 1.0]])),
            1.0,
        ),
        HenyeyGreenstein::new(0.0),
        glam::Affine3A::IDENTITY,
    );
    assert_eq!(s.scene.media[1], sahara_render::Medium::Grid(Box::new(b)));
}

/// A `cloud` medium gets its parameters (pbrt's defaults for those left
/// out) and its placement: the medium's space under the transform at
/// `MakeNamedMedium`.
#[test]
fn cloud_media_are_read_with_their_parameters_and_placement() {
    let text = "Camera \"perspective\"\nWorldBegin\n\
                AttributeBegin Translate 1 2 3 Scale 2 2 2\n\
                MakeNamedMedium \"c\" \"string type\" \"cloud\" \"float density\" 3 \"float g\" 0.6 \
                \"rgb sigma_s\" [2 3 4] \"float wispiness\" 0 \"point3 p0\" [-1 0 -1] \"point3 p1\" [1 1 1]\n\
                AttributeEnd\n\
                MakeNamedMedium \"d\" \"string type\" \"cloud\"\n";
    let s = parse_pbrt(text.as_bytes(), "t.pbrt", Path::new("/nonexistent")).unwrap();
    let sahara_render::Medium::Cloud(c) = &s.scene.media[0] else {
        panic!("{:?}", s.scene.media[0])
    };
    assert_eq!((c.density, c.wispiness, c.frequency), (3.0, 0.0, 5.0));
    assert_eq!(c.phase.g, 0.6);
    assert_eq!(c.sigma_a, Vec3::ONE);
    assert!((c.sigma_s - Vec3::new(2.0, 3.0, 4.0)).abs().max_element() < 1e-5);
    assert_eq!(
        (c.bounds_min, c.bounds_max),
        (Vec3::new(-1.0, 0.0, -1.0), Vec3::ONE)
    );
    let p = c.to_medium.transform_point3(Vec3::new(3.0, 4.0, 5.0));
    assert!((p - Vec3::ONE).abs().max_element() < 1e-6, "{p}");
    let sahara_render::Medium::Cloud(d) = &s.scene.media[1] else {
        panic!()
    };
    assert_eq!((d.density, d.wispiness, d.frequency), (1.0, 1.0, 5.0));
    assert_eq!((d.bounds_min, d.bounds_max), (Vec3::ZERO, Vec3::ONE));
}

/// scenes/fireball.pbrt renders: finite, without warnings, and the fire
/// brighter than the sky behind it.
#[test]
fn the_fireball_scene_renders() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/fireball.pbrt");
    let s = load_pbrt(&path).unwrap_or_else(|e| panic!("{e}"));
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
    let sahara_render::Medium::Grid(g) = &s.scene.media[0] else {
        panic!("{:?}", s.scene.media)
    };
    assert!(g.emission_colour.is_some());
    let (a, b) = centre_with_and_without_media(&s.scene);
    assert!(a.min_element() > 5.0 * b.max_element(), "{a} {b}");
}

/// The summed centre (6 x 6 pixels) of a small render of `scene`, and of
/// the same scene without its media; the render with media checked finite.
fn centre_with_and_without_media(scene: &sahara_render::Scene) -> (Vec3, Vec3) {
    let with = image(scene, 4);
    assert!(with.iter().all(|v| v.is_finite()));
    let mut clear = scene.clone();
    clear.media.clear();
    clear.medium_interfaces.clear();
    let without = image(&clear, 4);
    let centre = |img: &[Vec3]| {
        (9..15)
            .flat_map(|y| (9..15).map(move |x| y * 24 + x))
            .map(|i| img[i])
            .sum::<Vec3>()
    };
    (centre(&with), centre(&without))
}

/// scenes/noise_cloud.pbrt renders: finite, and the cloud in front of the
/// sky darker than the sky beside it would be without the medium.
#[test]
fn the_noise_cloud_scene_renders() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/noise_cloud.pbrt");
    let s = load_pbrt(&path).unwrap_or_else(|e| panic!("{e}"));
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
    assert!(matches!(s.scene.media[0], sahara_render::Medium::Cloud(_)));
    // The image's centre, where the cloud is.
    let (a, b) = centre_with_and_without_media(&s.scene);
    assert!(
        a.max_element() > 0.0 && (a - b).abs().max_element() > 0.1 * b.max_element(),
        "{a} {b}"
    );
}
