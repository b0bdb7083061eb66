//! Tests of the Mitsuba reader as a whole: each construct of the format,
//! the one-line errors of bad files, the mapping of shapes, bsdfs,
//! textures, emitters, sensor and integrator, and a Mitsuba scene
//! rendering as the same scene written in Sahara's TOML.

use std::path::{Path, PathBuf};

use glam::{Affine3A, Vec3};
use sahara_readers::FormatError;
use sahara_render::{
    AlphaMode, Bsdf, Distribution, Environment, Filter, Integrator, Light, Material, SamplerKind,
    Shape,
};

use super::{described, read_mitsuba_with, xml};
use crate::common::test_scenes::image;
use crate::common::warnings::Warnings;
use crate::description::{CameraRequest, FileCrop, Geometry, ObjectPlacement, SceneDescription};
use crate::{load_mitsuba, load_scene};

/// A fresh folder for a test's files.
fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sahara-mitsuba-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The description of `body` inside a Mitsuba 3 `<scene>`, files read
/// from `dir`.
fn describe_in(body: &str, dir: &Path) -> Result<SceneDescription, FormatError> {
    let text = format!("<scene version=\"3.0.0\">\n{body}\n</scene>\n");
    let mut w = Warnings::default();
    let root = xml::parse_text(text.as_bytes(), "t.xml", dir, &mut w)?;
    described(root, "t.xml", dir, &[], w)
}

fn describe(body: &str) -> SceneDescription {
    describe_in(body, Path::new("/nonexistent")).unwrap_or_else(|e| panic!("{e}"))
}

fn err(body: &str) -> String {
    match describe_in(body, Path::new("/nonexistent")) {
        Ok(_) => panic!("expected an error for {body:?}"),
        Err(e) => e.to_string(),
    }
}

/// The material of the description's object `i`.
fn material(d: &SceneDescription, i: usize) -> &Material {
    &d.materials[d.objects[i].material.expect("a material") as usize]
}

/// The object-to-world transform of object `i`.
fn placed(d: &SceneDescription, i: usize) -> Affine3A {
    match d.objects[i].placement {
        ObjectPlacement::Static(m) => m,
        ObjectPlacement::World => Affine3A::IDENTITY,
        other => panic!("{other:?}"),
    }
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

const SPHERE: &str = "<shape type=\"sphere\"/>";

#[test]
fn defaults_fill_in_names_and_the_command_line_wins() {
    let body = "<default name=\"r\" value=\"0.5\"/>\n<default name=\"r\" value=\"9\"/>\n\
                <shape type=\"sphere\"><float name=\"radius\" value=\"$r\"/></shape>";
    let d = describe(body);
    assert_eq!(
        d.objects[0].geometry,
        Geometry::Shape(Shape::Sphere {
            center: Vec3::ZERO,
            radius: 0.5
        })
    );
    let dir = folder("defaults");
    let path = dir.join("s.xml");
    std::fs::write(&path, format!("<scene version=\"3.0.0\">{body}</scene>")).unwrap();
    let d = read_mitsuba_with(&path, &[("r".into(), "2".into())]).unwrap();
    assert_eq!(
        d.objects[0].geometry,
        Geometry::Shape(Shape::Sphere {
            center: Vec3::ZERO,
            radius: 2.0
        })
    );
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(
        err("<shape type=\"sphere\">\n  <float name=\"radius\" value=\"$size\"/></shape>"),
        "t.xml: line 3: column 3: parameter '$size' has no value (give it a <default name=\"size\" value=\"...\"/> or -D size=...)"
    );
}

#[test]
fn includes_splice_files_read_from_their_own_folder() {
    let dir = folder("include");
    std::fs::create_dir_all(dir.join("parts")).unwrap();
    std::fs::write(
        dir.join("parts/a.xml"),
        "<scene version=\"3.0.0\"><include filename=\"b.xml\"/>\
         <shape type=\"sphere\"><float name=\"radius\" value=\"$r\"/></shape></scene>",
    )
    .unwrap();
    std::fs::write(
        dir.join("parts/b.xml"),
        "<scene version=\"3.0.0\"><shape type=\"disk\"/></scene>",
    )
    .unwrap();
    let d = describe_in(
        "<default name=\"r\" value=\"3\"/><include filename=\"parts/a.xml\"/>",
        &dir,
    )
    .unwrap();
    assert_eq!(d.objects.len(), 2);
    assert!(matches!(
        d.objects[0].geometry,
        Geometry::Shape(Shape::Disc { .. })
    ));
    assert!(matches!(
        d.objects[1].geometry,
        Geometry::Shape(Shape::Sphere { radius, .. }) if radius == 3.0
    ));
    std::fs::write(
        dir.join("loop.xml"),
        "<scene version=\"3.0.0\"><include filename=\"loop.xml\"/></scene>",
    )
    .unwrap();
    let e = describe_in("<include filename=\"loop.xml\"/>", &dir)
        .unwrap_err()
        .to_string();
    assert!(e.contains("<include> nests more than 16 deep"), "{e}");
    let e = describe_in("\n  <include filename=\"missing.xml\"/>", &dir)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("t.xml: line 3: column 3: <include filename=\"missing.xml\">: ")
            && e.contains("cannot read"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_path_element_adds_a_folder_to_look_in_and_sensors_refer_to_their_parts() {
    let dir = folder("path");
    std::fs::create_dir_all(dir.join("common/meshes")).unwrap();
    write_meshes(&dir.join("common/meshes"));
    std::fs::create_dir_all(dir.join("scenes")).unwrap();
    let d = describe_in(
        "<path value=\"common\"/>\n\
         <shape type=\"ply\"><string name=\"filename\" value=\"meshes/q.ply\"/></shape>\n\
         <sampler type=\"stratified\" id=\"s\"><integer name=\"sample_count\" value=\"9\"/></sampler>\n\
         <film type=\"hdrfilm\" id=\"f\"><integer name=\"width\" value=\"32\"/></film>\n\
         <sensor type=\"perspective\"><ref id=\"s\"/><ref id=\"f\"/></sensor>",
        &dir,
    )
    .unwrap();
    assert!(matches!(d.objects[0].geometry, Geometry::Mesh(_)));
    let s = d.settings.as_ref().unwrap().frame_settings();
    assert_eq!(
        (s.sampler, s.spp, s.width),
        (SamplerKind::Stratified, 9, 32)
    );
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn ids_and_refs_share_one_material() {
    let d = describe(
        "<bsdf type=\"diffuse\" id=\"red\"><rgb name=\"reflectance\" value=\"0.8, 0.1, 0.1\"/></bsdf>\n\
         <shape type=\"sphere\"><ref id=\"red\"/></shape>\n\
         <shape type=\"disk\"><ref name=\"bsdf\" id=\"red\"/></shape>",
    );
    assert_eq!(d.objects[0].material, d.objects[1].material);
    assert_eq!(
        material(&d, 0).bsdf,
        Bsdf::Diffuse {
            albedo: Vec3::new(0.8, 0.1, 0.1)
        }
    );
    assert_eq!(
        err("<shape type=\"sphere\">\n    <ref id=\"nothing\"/>\n</shape>"),
        "t.xml: line 3: column 5: <ref id=\"nothing\">: no object has the id \"nothing\""
    );
    assert_eq!(
        err("<bsdf type=\"diffuse\" id=\"a\"/>\n<bsdf type=\"diffuse\" id=\"a\"/>"),
        "t.xml: line 3: column 1: id \"a\" is given twice (first at line 2)"
    );
    assert_eq!(
        err("<texture type=\"checkerboard\" id=\"t\"/>\n<shape type=\"sphere\"><ref id=\"t\"/></shape>"),
        "t.xml: line 3: column 22: expected a <bsdf> or <emitter> here, found a <texture> (id \"t\")"
    );
}

#[test]
fn an_area_emitter_with_an_id_lights_the_shapes_that_refer_to_it() {
    // As Mitsuba's own Cornell boxes write it: the emitter after the shape.
    let d = describe(
        "<shape type=\"rectangle\"><ref id=\"e\"/></shape>\n\
         <emitter type=\"area\" id=\"e\"><rgb name=\"radiance\" value=\"2\"/></emitter>",
    );
    assert_eq!(material(&d, 0).emission, Vec3::splat(2.0));
    assert!(d.lights.is_empty() && d.environment.is_none());
    assert_eq!(
        err("<emitter type=\"area\"/>"),
        "t.xml: line 2: column 1: an 'area' emitter belongs inside a <shape>"
    );
}

#[test]
fn bad_files_say_what_and_where_in_one_line() {
    // Unclosed tag.
    let e = err("<shape type=\"sphere\">\n<bsdf type=\"diffuse\">\n</shape>");
    assert_eq!(
        e,
        "t.xml: line 4: column 1: </shape> closes <bsdf>: <bsdf> is not closed"
    );
    // Unknown plugin types.
    assert_eq!(
        err("<shape type=\"teapot\"/>"),
        "t.xml: line 2: column 1: unknown shape type 'teapot'"
    );
    assert_eq!(
        err("<shape type=\"sphere\"><bsdf type=\"velvet\"/></shape>"),
        "t.xml: line 2: column 22: unknown bsdf type 'velvet'"
    );
    assert_eq!(
        err("<emitter type=\"laser\"/>"),
        "t.xml: line 2: column 1: unknown emitter type 'laser'"
    );
    assert_eq!(
        err("<shape type=\"sphere\"/>\n<sensor type=\"orthographic\"/>"),
        "t.xml: line 3: column 1: sensor 'orthographic' is not supported (Sahara has perspective cameras only)"
    );
    // Unknown elements, missing attributes.
    assert_eq!(
        err("<light type=\"point\"/>"),
        "t.xml: line 2: column 1: unknown element <light> in <scene> (expected shape, bsdf, texture, emitter, sensor, integrator, default or include)"
    );
    assert_eq!(
        err("<shape type=\"obj\"/>"),
        "t.xml: line 2: column 1: shape 'obj' needs a 'filename' string"
    );
    assert_eq!(
        err("<shape type=\"sphere\"><float name=\"radius\" value=\"big\"/></shape>"),
        "t.xml: line 2: column 22: expected a number, found 'big'"
    );
    assert_eq!(
        err("<shape type=\"sphere\"><string name=\"radius\" value=\"1\"/></shape>"),
        "t.xml: line 2: column 22: 'radius': expected a <float>, found a <string>"
    );
    let e = describe_in("", Path::new("/x"))
        .map(|d| d.objects.len())
        .unwrap();
    assert_eq!(e, 0);
    let mut w = Warnings::default();
    let e = xml::parse_text(
        b"<shape type=\"sphere\"/>",
        "t.xml",
        Path::new("/x"),
        &mut w,
    )
    .and_then(|root| described(root, "t.xml", Path::new("/x"), &[], Warnings::default()))
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "t.xml: line 1: column 1: expected <scene version=\"3.0.0\"> as the file's root, found <shape>"
    );
}

#[test]
fn mitsuba_0_6_names_are_read_as_mitsuba_3_names() {
    let text = "<scene version=\"0.6.0\">\n\
        <integrator type=\"path\"><integer name=\"maxDepth\" value=\"4\"/></integrator>\n\
        <sensor type=\"perspective\"><float name=\"fov\" value=\"45\"/>\
        <transform name=\"toWorld\"><lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform>\
        <sampler type=\"independent\"><integer name=\"sampleCount\" value=\"9\"/></sampler></sensor>\n\
        <shape type=\"sphere\"><bsdf type=\"dielectric\"><string name=\"intIOR\" value=\"water\"/>\
        <float name=\"extIOR\" value=\"1\"/></bsdf></shape></scene>";
    let mut w = Warnings::default();
    let root = xml::parse_text(text.as_bytes(), "t.xml", Path::new("/x"), &mut w).unwrap();
    let d = described(root, "t.xml", Path::new("/x"), &[], w).unwrap();
    let s = d.settings.as_ref().unwrap().frame_settings();
    assert_eq!(
        s.integrator,
        Integrator::Path {
            max_depth: 3,
            rr_depth: 5
        }
    );
    assert_eq!(s.spp, 9);
    assert_eq!(material(&d, 0).bsdf, Bsdf::Dielectric { ior: 1.333 });
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
}

#[test]
fn transforms_place_shapes_as_mitsuba_composes_them() {
    let d = describe(
        "<shape type=\"rectangle\"><transform name=\"to_world\">\
         <scale x=\"2\" y=\"3\"/><rotate z=\"1\" angle=\"90\"/><translate value=\"1, 2, 3\"/>\
         </transform></shape>\n\
         <shape type=\"cube\"><transform name=\"to_world\"><matrix value=\"1 0 0 5  0 2 0 6  0 0 1 7  0 0 0 1\"/></transform></shape>",
    );
    // (1, 0, 0): scaled to (2, 0, 0), turned to (0, 2, 0), moved to (1, 4, 3).
    let m = placed(&d, 0);
    assert!(close(m.transform_point3(Vec3::X), Vec3::new(1.0, 4.0, 3.0)));
    assert!(matches!(
        d.objects[0].geometry,
        Geometry::Shape(Shape::Quad { corner, edge_u, edge_v })
            if corner == Vec3::new(-1.0, -1.0, 0.0) && edge_u == Vec3::new(2.0, 0.0, 0.0) && edge_v == Vec3::new(0.0, 2.0, 0.0)
    ));
    let m = placed(&d, 1);
    assert!(close(
        m.transform_point3(Vec3::ONE),
        Vec3::new(6.0, 8.0, 8.0)
    ));
    assert_eq!(
        d.objects[1].geometry,
        Geometry::Shape(Shape::Box {
            min: Vec3::splat(-1.0),
            max: Vec3::ONE
        })
    );
}

#[test]
fn analytic_shapes_keep_mitsubas_fronts_under_mirrors_and_flips() {
    let d = describe(
        "<shape type=\"rectangle\"><transform name=\"to_world\"><scale x=\"-1\"/></transform></shape>\n\
         <shape type=\"rectangle\"><boolean name=\"flip_normals\" value=\"true\"/></shape>\n\
         <shape type=\"disk\"><transform name=\"to_world\"><scale z=\"-1\"/></transform></shape>\n\
         <shape type=\"sphere\"><point name=\"center\" x=\"1\" y=\"2\" z=\"3\"/><float name=\"radius\" value=\"0.5\"/>\
         <transform name=\"to_world\"><scale value=\"2\"/></transform></shape>\n\
         <shape type=\"sphere\"><boolean name=\"flip_normals\" value=\"true\"/></shape>\n\
         <shape type=\"cylinder\"><float name=\"radius\" value=\"0.5\"/></shape>",
    );
    // The front in world space: the transformed edges' cross product.
    let front = |i: usize| match d.objects[i].geometry {
        Geometry::Shape(Shape::Quad { edge_u, edge_v, .. }) => {
            let m = placed(&d, i);
            m.transform_vector3(edge_u)
                .cross(m.transform_vector3(edge_v))
                .normalize()
        }
        ref g => panic!("{g:?}"),
    };
    // Mitsuba's rectangle faces its normal transformed as a normal: +z
    // under a mirror in x, -z when flipped.
    assert!(close(front(0), Vec3::Z));
    assert!(close(front(1), -Vec3::Z));
    // The disc mirrored in z faces -z as Mitsuba's does (the assembly
    // turns its normal by the transform and the mirror's sign).
    let Geometry::Shape(Shape::Disc { normal, .. }) = d.objects[2].geometry else {
        panic!()
    };
    let m = placed(&d, 2);
    assert!(close(m.transform_vector3(normal) * -1.0, -Vec3::Z));
    assert_eq!(
        d.objects[3].geometry,
        Geometry::Shape(Shape::Sphere {
            center: Vec3::new(2.0, 4.0, 6.0),
            radius: 1.0
        })
    );
    assert_eq!(d.objects[3].placement, ObjectPlacement::World);
    // A flipped sphere is a mesh facing in.
    let Geometry::Mesh(i) = d.objects[4].geometry else {
        panic!()
    };
    let mesh = &d.meshes[i as usize];
    let t = mesh.mesh.indices[mesh.mesh.indices.len() / 2];
    let [a, b, c] = t.map(|k| mesh.mesh.positions[k as usize]);
    assert!((b - a).cross(c - a).dot(a + b + c) < 0.0);
    assert!(matches!(d.objects[5].geometry, Geometry::Mesh(_)));
    assert!(
        d.warnings
            .iter()
            .any(|w| w.contains("cylinder: tessellated (128 segments")),
        "{:?}",
        d.warnings
    );
}

/// Writes a small OBJ and PLY (a unit quad in z = 0 with uvs) into `dir`.
fn write_meshes(dir: &Path) {
    std::fs::write(
        dir.join("q.obj"),
        "mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 0.25\nf 1/1 2/2 3/3 4/4\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("q.ply"),
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
         property float u\nproperty float v\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
         0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 0.25\n4 0 1 2 3\n",
    )
    .unwrap();
}

#[test]
fn mesh_files_load_once_with_mitsubas_normals_and_uvs() {
    let dir = folder("meshes");
    write_meshes(&dir);
    let s = super::serialized::write_serialized(
        &[
            (
                vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                vec![[0, 1, 2]],
                0,
            ),
            (
                vec![[0.0; 3], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
                vec![[0, 1, 2]],
                0,
            ),
        ],
        false,
    );
    std::fs::write(dir.join("m.serialized"), s).unwrap();
    let d = describe_in(
        "<shape type=\"obj\"><string name=\"filename\" value=\"q.obj\"/></shape>\n\
         <shape type=\"obj\"><string name=\"filename\" value=\"q.obj\"/><transform name=\"to_world\"><translate x=\"2\"/></transform></shape>\n\
         <shape type=\"ply\"><string name=\"filename\" value=\"q.ply\"/><boolean name=\"face_normals\" value=\"true\"/></shape>\n\
         <shape type=\"ply\"><string name=\"filename\" value=\"q.ply\"/><boolean name=\"flip_normals\" value=\"true\"/></shape>\n\
         <shape type=\"serialized\"><string name=\"filename\" value=\"m.serialized\"/><integer name=\"shape_index\" value=\"1\"/></shape>",
        &dir,
    )
    .unwrap();
    let mesh = |i: usize| match d.objects[i].geometry {
        Geometry::Mesh(m) => m,
        ref g => panic!("{g:?}"),
    };
    // The same file with the same options is one mesh.
    assert_eq!(mesh(0), mesh(1));
    assert_eq!(d.meshes.len(), 4);
    let obj = &d.meshes[mesh(0) as usize];
    // Smooth normals where the file has none; the OBJ's v flipped.
    assert_eq!(obj.normals.as_ref().unwrap()[0], Vec3::Z);
    assert_eq!(obj.uvs.as_ref().unwrap()[3], glam::Vec2::new(0.0, 0.75));
    let ply = &d.meshes[mesh(2) as usize];
    assert!(ply.normals.is_none());
    assert_eq!(ply.uvs.as_ref().unwrap()[3], glam::Vec2::new(0.0, 0.25));
    let flipped = &d.meshes[mesh(3) as usize];
    assert_eq!(flipped.normals.as_ref().unwrap()[0], -Vec3::Z);
    assert_eq!(flipped.mesh.indices[0], [0, 2, 1]);
    let ser = &d.meshes[mesh(4) as usize];
    assert_eq!(ser.mesh.positions[1], Vec3::Y);
    // Mitsuba never reads an OBJ's materials.
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_shapegroup_is_one_mesh_shown_by_each_instance() {
    let d = describe(
        "<shape type=\"shapegroup\" id=\"g\">\
           <shape type=\"rectangle\"><bsdf type=\"diffuse\"/></shape>\
           <shape type=\"cube\"><transform name=\"to_world\"><translate z=\"3\"/></transform>\
             <bsdf type=\"conductor\"/></shape>\
         </shape>\n\
         <shape type=\"instance\"><ref id=\"g\"/><transform name=\"to_world\"><translate x=\"5\"/></transform></shape>\n\
         <shape type=\"instance\"><ref id=\"g\"/></shape>",
    );
    assert_eq!(d.objects.len(), 2);
    let (Geometry::Mesh(a), Geometry::Mesh(b)) = (&d.objects[0].geometry, &d.objects[1].geometry)
    else {
        panic!()
    };
    assert_eq!(a, b);
    assert_eq!(d.objects[0].material, None);
    let m = &d.meshes[*a as usize];
    let ids = m.material_ids.as_ref().unwrap();
    assert_eq!(ids.len(), 2 + 12);
    assert_ne!(ids[0], ids[2]);
    let zmax = m
        .mesh
        .positions
        .iter()
        .map(|p| p.z)
        .fold(f32::MIN, f32::max);
    assert_eq!(zmax, 4.0);
    assert!(close(
        placed(&d, 0).transform_point3(Vec3::ZERO),
        Vec3::new(5.0, 0.0, 0.0)
    ));
}

#[test]
fn bsdfs_map_onto_sahara_materials() {
    let d = describe(
        "<shape type=\"sphere\"><bsdf type=\"diffuse\"/></shape>\n\
         <shape type=\"sphere\"><bsdf type=\"twosided\"><bsdf type=\"diffuse\"><spectrum name=\"reflectance\" value=\"0.25\"/></bsdf></bsdf></shape>\n\
         <shape type=\"sphere\"><bsdf type=\"roughconductor\"><string name=\"material\" value=\"Au\"/>\
           <float name=\"alpha\" value=\"0.04\"/><string name=\"distribution\" value=\"ggx\"/></bsdf></shape>\n\
         <shape type=\"sphere\"><bsdf type=\"conductor\"/></shape>\n\
         <shape type=\"sphere\"><bsdf type=\"roughdielectric\"><string name=\"int_ior\" value=\"bk7\"/>\
           <string name=\"ext_ior\" value=\"air\"/><float name=\"alpha\" value=\"0.09\"/><string name=\"distribution\" value=\"ggx\"/></bsdf></shape>\n\
         <shape type=\"sphere\"><bsdf type=\"thindielectric\"><float name=\"int_ior\" value=\"1.5\"/><float name=\"ext_ior\" value=\"1\"/></bsdf></shape>\n\
         <shape type=\"sphere\"><bsdf type=\"plastic\"><rgb name=\"diffuse_reflectance\" value=\"0.5 0.25 0.125\"/><boolean name=\"nonlinear\" value=\"true\"/>\
           <float name=\"int_ior\" value=\"1.5\"/><float name=\"ext_ior\" value=\"1\"/></bsdf></shape>\n\
         <shape type=\"sphere\"><bsdf type=\"principled\"><rgb name=\"base_color\" value=\"0.9 0.5 0.1\"/>\
           <float name=\"metallic\" value=\"1\"/><float name=\"roughness\" value=\"0.3\"/><float name=\"sheen\" value=\"0.5\"/></bsdf></shape>\n\
         <shape type=\"sphere\"><bsdf type=\"mask\"><float name=\"opacity\" value=\"0.25\"/><bsdf type=\"diffuse\"/></bsdf></shape>\n\
         <shape type=\"sphere\"><bsdf type=\"blendbsdf\"><float name=\"weight\" value=\"0.25\"/>\
           <bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"1 0 0\"/></bsdf>\
           <bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0 0 1\"/></bsdf></bsdf></shape>\n\
         <shape type=\"sphere\"><bsdf type=\"null\"/></shape>\n\
         <shape type=\"sphere\"><bsdf type=\"bumpmap\"><texture type=\"checkerboard\"/><bsdf type=\"diffuse\"/></bsdf></shape>",
    );
    // null: no surface, no object.
    assert_eq!(d.objects.len(), 11);
    let m = material(&d, 0);
    assert_eq!(
        (m.bsdf, m.two_sided),
        (
            Bsdf::Diffuse {
                albedo: Vec3::splat(0.5)
            },
            false
        )
    );
    let m = material(&d, 1);
    assert_eq!(
        (m.bsdf, m.two_sided),
        (
            Bsdf::Diffuse {
                albedo: Vec3::splat(0.25)
            },
            true
        )
    );
    let Bsdf::ComplexConductor {
        roughness,
        multiple_scattering: false,
        eta,
        ..
    } = material(&d, 2).bsdf
    else {
        panic!("{:?}", material(&d, 2).bsdf)
    };
    assert!((roughness - 0.2).abs() < 1e-6);
    assert!(eta.z > eta.x, "gold's blue index is the larger: {eta}");
    // Mitsuba's default conductor is a perfect mirror.
    let Bsdf::ComplexConductor { eta, k, .. } = material(&d, 3).bsdf else {
        panic!()
    };
    let f = sahara_render::fresnel::conductor(0.3, eta, k);
    assert!(f.min_element() > 0.999, "{f}");
    let Bsdf::RoughDielectric { ior, roughness, .. } = material(&d, 4).bsdf else {
        panic!()
    };
    assert!((ior - 1.5046 / 1.00028).abs() < 1e-6 && (roughness - 0.3).abs() < 1e-6);
    assert_eq!(material(&d, 5).bsdf, Bsdf::ThinDielectric { ior: 1.5 });
    assert_eq!(
        material(&d, 6).bsdf,
        Bsdf::CoatedDiffuse {
            albedo: Vec3::new(0.5, 0.25, 0.125),
            ior: 1.5,
            roughness: 0.0,
            distribution: Distribution::Ggx,
        }
    );
    let Bsdf::MetallicRoughness {
        metallic,
        roughness,
        base_color,
        ..
    } = material(&d, 7).bsdf
    else {
        panic!()
    };
    assert_eq!((metallic, roughness), (1.0, 0.3));
    assert_eq!(base_color, Vec3::new(0.9, 0.5, 0.1));
    let m = material(&d, 8);
    assert_eq!((m.alpha_mode, m.alpha), (AlphaMode::Blend, 0.25));
    assert!(material(&d, 10).textures.normal.is_some());
    assert_eq!(
        material(&d, 9).bsdf,
        Bsdf::Diffuse {
            albedo: Vec3::new(0.75, 0.0, 0.25)
        }
    );
    let w = d.warnings.join("\n");
    assert!(
        w.contains("bsdf 'principled': sheen not supported; left out"),
        "{w}"
    );
    assert!(
        w.contains("bsdf 'bumpmap': bumps become a normal map"),
        "{w}"
    );
    assert!(!w.contains("Beckmann"), "{w}");
    assert!(
        err("<shape type=\"sphere\"><bsdf type=\"conductor\"><string name=\"material\" value=\"Xy\"/></bsdf></shape>")
            .contains("unknown conductor material 'Xy' (Mitsuba's: none, Ag, Al,"),
    );
}

#[test]
fn the_rough_bsdfs_take_their_distribution_beckmann_by_default() {
    let d = describe(
        "<shape type=\"sphere\"><bsdf type=\"roughconductor\"/></shape>\n\
         <shape type=\"disk\"><bsdf type=\"roughdielectric\"><string name=\"distribution\" value=\"ggx\"/></bsdf></shape>\n\
         <shape type=\"disk\"><bsdf type=\"roughplastic\"><string name=\"distribution\" value=\"beckmann\"/></bsdf></shape>",
    );
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
    let dist = |i| match material(&d, i).bsdf {
        Bsdf::ComplexConductor { distribution, .. }
        | Bsdf::RoughDielectric { distribution, .. }
        | Bsdf::CoatedDiffuse { distribution, .. } => distribution,
        other => panic!("{other:?}"),
    };
    assert_eq!(
        [dist(0), dist(1), dist(2)],
        [
            Distribution::Beckmann,
            Distribution::Ggx,
            Distribution::Beckmann
        ]
    );
    assert!(err(
        "<shape type=\"sphere\"><bsdf type=\"roughconductor\"><string name=\"distribution\" value=\"phong\"/></bsdf></shape>"
    )
    .contains("unknown microfacet distribution 'phong' (expected beckmann or ggx)"));
}

#[test]
fn textures_are_images_and_baked_checkerboards_read_with_mitsubas_v() {
    let dir = folder("textures");
    // A 2 x 2 image: top row red, bottom row blue.
    let img =
        image::RgbImage::from_raw(2, 2, vec![255, 0, 0, 255, 0, 0, 0, 0, 255, 0, 0, 255]).unwrap();
    img.save(dir.join("t.png")).unwrap();
    let d = describe_in(
        "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\">\
           <string name=\"filename\" value=\"t.png\"/><boolean name=\"raw\" value=\"true\"/>\
           <string name=\"wrap_mode\" value=\"clamp\"/>\
           <transform name=\"to_uv\"><scale x=\"2\"/></transform></texture></bsdf></shape>\n\
         <shape type=\"rectangle\"><bsdf type=\"diffuse\"><texture type=\"checkerboard\" name=\"reflectance\">\
           <rgb name=\"color0\" value=\"1 1 1\"/><rgb name=\"color1\" value=\"0 0 0\"/></texture></bsdf></shape>",
        &dir,
    )
    .unwrap();
    let look = |i: usize, u: f32, v: f32| {
        let m = material(&d, i);
        let map = m.textures.base_color.as_ref().unwrap();
        let uv = glam::Vec2::new(u, v);
        map.lookup_sharp(&[uv, uv]).truncate()
    };
    // Mitsuba's v = 0 is the image's top row.
    assert!(close(look(0, 0.1, 0.05), Vec3::X), "{}", look(0, 0.1, 0.05));
    assert!(close(look(0, 0.1, 0.95), Vec3::Z));
    assert_eq!(
        material(&d, 0).textures.base_color.as_ref().unwrap().wrap,
        [sahara_render::Wrap::Clamp; 2]
    );
    // Checks: color0 where u and v are in the same half.
    assert!(close(look(1, 0.2, 0.2), Vec3::ONE));
    assert!(close(look(1, 0.7, 0.2), Vec3::ZERO));
    assert!(close(look(1, 0.7, 0.7), Vec3::ONE));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn emitters_are_area_materials_lights_and_environments() {
    let dir = folder("emitters");
    std::fs::write(
        dir.join("env.pfm"),
        [b"PF\n4 2\n-1\n".as_slice(), &[0u8; 4 * 2 * 3 * 4]].concat(),
    )
    .unwrap();
    let d = describe_in(
        "<shape type=\"rectangle\"><emitter type=\"area\"><rgb name=\"radiance\" value=\"4 3 2\"/></emitter></shape>\n\
         <emitter type=\"point\"><point name=\"position\" x=\"1\" y=\"2\" z=\"3\"/><rgb name=\"intensity\" value=\"5\"/></emitter>\n\
         <emitter type=\"spot\"><transform name=\"to_world\"><lookat origin=\"0 1 0\" target=\"0 0 0\"/></transform>\
           <float name=\"cutoff_angle\" value=\"30\"/><float name=\"beam_width\" value=\"20\"/></emitter>\n\
         <emitter type=\"directional\"><vector name=\"direction\" x=\"0\" y=\"-1\" z=\"0\"/><spectrum name=\"irradiance\" value=\"2\"/></emitter>\n\
         <emitter type=\"constant\"><blackbody name=\"radiance\" temperature=\"6500K\"/></emitter>\n\
         <emitter type=\"envmap\"><string name=\"filename\" value=\"env.pfm\"/><float name=\"scale\" value=\"3\"/></emitter>",
        &dir,
    )
    .unwrap();
    let m = material(&d, 0);
    assert_eq!(
        (m.emission, m.two_sided_emission),
        (Vec3::new(4.0, 3.0, 2.0), false)
    );
    // Mitsuba's emitters without a bsdf reflect nothing.
    assert_eq!(m.bsdf, Bsdf::Diffuse { albedo: Vec3::ZERO });
    assert_eq!(
        d.lights[0],
        Light::point(Vec3::new(1.0, 2.0, 3.0), Vec3::splat(5.0))
    );
    let Light::Spot {
        position,
        direction,
        cos_inner,
        cos_outer,
        ..
    } = d.lights[1]
    else {
        panic!()
    };
    assert!(close(position, Vec3::Y) && close(direction, -Vec3::Y));
    assert!((cos_inner - 20f32.to_radians().cos()).abs() < 1e-6);
    assert!((cos_outer - 30f32.to_radians().cos()).abs() < 1e-6);
    assert_eq!(d.lights[2], Light::directional(-Vec3::Y, Vec3::splat(2.0)));
    let Some(Environment::Map { texture, scale }) = &d.environment else {
        panic!()
    };
    assert_eq!((texture.width, texture.height, *scale), (4, 2, 3.0));
    let w = d.warnings.join("\n");
    assert!(
        w.contains("more than one environment emitter: the last one is used"),
        "{w}"
    );
    assert!(w.contains("spot: Mitsuba's falloff"), "{w}");
    assert!(w.contains("blackbody: normalised to luminance 1"), "{w}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every Mitsuba emitter takes a `sampling_weight` (how often Mitsuba picks
/// it); Sahara picks lights by power, which changes the noise and not the
/// image, so the weight is read without a warning, and a bad one is an
/// error.
#[test]
fn every_emitter_takes_a_sampling_weight() {
    let weight = "<float name=\"sampling_weight\" value=\"2.5\"/>";
    let d = describe(&format!(
        "<shape type=\"rectangle\"><emitter type=\"area\">{weight}</emitter></shape>\n\
         <emitter type=\"point\">{weight}</emitter>\n\
         <emitter type=\"spot\">{weight}<float name=\"beam_width\" value=\"15\"/></emitter>\n\
         <emitter type=\"directional\"><vector name=\"direction\" value=\"0 -1 0\"/>{weight}</emitter>\n\
         <emitter type=\"constant\">{weight}</emitter>"
    ));
    assert_eq!(d.lights.len(), 3);
    assert!(d.environment.is_some());
    let unknown: Vec<_> = d
        .warnings
        .iter()
        .filter(|w| w.contains("unknown"))
        .collect();
    assert!(unknown.is_empty(), "{unknown:?}");
    let e =
        err("<emitter type=\"constant\"><float name=\"sampling_weight\" value=\"-1\"/></emitter>");
    assert!(
        e.contains("'sampling_weight' must be a finite number >= 0"),
        "{e}"
    );
    let e =
        err("<emitter type=\"point\"><string name=\"sampling_weight\" value=\"a lot\"/></emitter>");
    assert!(e.contains("sampling_weight"), "{e}");
}

#[test]
fn the_sensor_sees_as_mitsubas_and_sets_film_sampler_filter_and_depth() {
    let d = describe(
        "<integrator type=\"path\"><integer name=\"max_depth\" value=\"6\"/><integer name=\"rr_depth\" value=\"2\"/></integrator>\n\
         <sensor type=\"thinlens\"><float name=\"fov\" value=\"60\"/><string name=\"fov_axis\" value=\"x\"/>\
         <float name=\"aperture_radius\" value=\"0.1\"/><float name=\"focus_distance\" value=\"4\"/>\
         <transform name=\"to_world\"><lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform>\
         <sampler type=\"stratified\"><integer name=\"sample_count\" value=\"16\"/><integer name=\"seed\" value=\"7\"/></sampler>\
         <film type=\"hdrfilm\"><integer name=\"width\" value=\"200\"/><integer name=\"height\" value=\"100\"/>\
         <integer name=\"crop_offset_x\" value=\"10\"/><integer name=\"crop_offset_y\" value=\"20\"/>\
         <integer name=\"crop_width\" value=\"30\"/><integer name=\"crop_height\" value=\"40\"/>\
         <rfilter type=\"gaussian\"><float name=\"stddev\" value=\"0.25\"/></rfilter></film></sensor>",
    );
    let CameraRequest::Given { camera: c, .. } = d.camera else {
        panic!()
    };
    // Looking down -z with y up: the image's right is +x, as in Mitsuba.
    assert!(close(c.forward, -Vec3::Z) && close(c.right, Vec3::X) && close(c.up, Vec3::Y));
    // A 60 degree horizontal field on a 2:1 image.
    let want = 2.0 * ((30f32.to_radians()).tan() / 2.0).atan().to_degrees();
    assert!((c.vfov_deg - want).abs() < 1e-4, "{}", c.vfov_deg);
    assert_eq!((c.lens_radius, c.focus_distance), (0.1, 4.0));
    let layer = d.settings.unwrap();
    let s = layer.frame_settings();
    assert_eq!(
        s.integrator,
        Integrator::Path {
            max_depth: 5,
            rr_depth: 2
        }
    );
    assert_eq!((s.sampler, s.spp, s.seed), (SamplerKind::Stratified, 16, 7));
    assert_eq!((s.width, s.height), (200, 100));
    assert_eq!(layer.crop_window, Some(FileCrop::Pixels([10, 40, 20, 60])));
    assert_eq!(
        s.filter,
        Filter::Gaussian {
            radius: 1.0,
            sigma: 0.25
        }
    );
    // A mirroring transform mirrors the image, as in Mitsuba.
    let d = describe(
        "<sensor type=\"perspective\"><transform name=\"to_world\"><scale x=\"-1\"/>\
         <lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform></sensor>",
    );
    let CameraRequest::Given { camera: c, .. } = d.camera else {
        panic!()
    };
    assert!(close(c.right, -Vec3::X));
    // Mitsuba's defaults: 768 x 576, 4 independent samples, a Gaussian,
    // unlimited depth; a 50 mm lens on the diagonal.
    let s = d.settings.unwrap().frame_settings();
    assert_eq!(
        (s.width, s.height, s.spp, s.sampler),
        (768, 576, 4, SamplerKind::Independent)
    );
    assert_eq!(
        s.integrator,
        Integrator::Path {
            max_depth: 1 << 16,
            rr_depth: 5
        }
    );
    let x_fov = 2.0 * (c.tan_half_fov() * 768.0 / 576.0).atan().to_degrees();
    assert!((x_fov - 38.1848).abs() < 1e-3, "{x_fov}");
    // No sensor: the automatic camera.
    assert_eq!(describe(SPHERE).camera, CameraRequest::Automatic);
    // Direct light: one bounce.
    let d = describe("<integrator type=\"direct\"/>");
    assert!(matches!(
        d.settings.unwrap().frame_settings().integrator,
        Integrator::Path { max_depth: 1, .. }
    ));
}

/// Mitsuba's particle tracer is light tracing; Mitsuba 0.6's `bdpt`,
/// `sppm` and `photonmapper` map onto bidirectional path tracing and SPPM
/// (depth counted in bounces, as for `path`), its Metropolis plugins onto
/// `bdpt` with a warning.
#[test]
fn light_tracing_bidirectional_and_photon_integrators_map_onto_saharas() {
    let integrator = |xml: &str| {
        let d = describe(xml);
        (d.settings.unwrap().frame_settings().integrator, d.warnings)
    };
    let (i, w) = integrator(
        "<integrator type=\"ptracer\"><integer name=\"max_depth\" value=\"6\"/></integrator>",
    );
    assert_eq!(i, Integrator::LightPath { max_depth: 5 });
    assert!(w.is_empty(), "{w:?}");
    let (i, _) = integrator(
        "<integrator type=\"bdpt\"><integer name=\"max_depth\" value=\"9\"/></integrator>",
    );
    assert_eq!(i, Integrator::Bdpt { max_depth: 8 });
    let (i, _) = integrator(
        "<integrator type=\"sppm\"><integer name=\"max_depth\" value=\"4\"/>\
         <float name=\"initial_radius\" value=\"0.5\"/><integer name=\"photon_count\" value=\"1000\"/></integrator>",
    );
    assert_eq!(
        i,
        Integrator::Sppm {
            max_depth: 3,
            radius: 0.5,
            photons: 1000
        }
    );
    let (i, w) = integrator(
        "<integrator type=\"pssmlt\"><integer name=\"max_depth\" value=\"3\"/></integrator>",
    );
    assert_eq!(i, Integrator::Bdpt { max_depth: 2 });
    assert!(
        w.iter().any(|w| w.contains("bidirectional path tracing")),
        "{w:?}"
    );
}

#[test]
fn approximations_are_warned_once_per_kind_with_a_count() {
    let d = describe(
        "<shape type=\"sphere\"><bsdf type=\"diffuse\"><float name=\"roughness\" value=\"0.5\"/></bsdf></shape>\n\
         <shape type=\"sphere\"><bsdf type=\"diffuse\"><float name=\"roughness\" value=\"0.5\"/></bsdf></shape>\n\
         <integrator type=\"prbvolpath\"/>\n\
         <shape type=\"bsplinecurve\"><string name=\"filename\" value=\"c.txt\"/></shape>",
    );
    assert_eq!(
        d.warnings,
        vec![
            "t.xml:2:43: bsdf 'diffuse': unknown parameter 'roughness', ignored (2 times; the first here)",
            "t.xml:5:1: shape 'bsplinecurve' is not supported; skipped",
            "t.xml:4:1: integrator 'prbvolpath' is rendered by Sahara's path tracer",
        ]
    );
}

/// A Cornell box: walls of rectangles placed by exact matrices, two
/// cubes, a glass sphere, a metal block and a light.
const CORNELL_XML: &str = r#"<scene version="3.0.0">
  <sensor type="perspective">
    <float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, 1, 3.5" target="0, 1, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/></film>
  </sensor>
  <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.75, 0.75, 0.75"/></bsdf></bsdf>
  <bsdf type="twosided" id="red"><bsdf type="diffuse"><rgb name="reflectance" value="0.63 0.065 0.05"/></bsdf></bsdf>
  <bsdf type="twosided" id="green"><bsdf type="diffuse"><rgb name="reflectance" value="0.14 0.45 0.091"/></bsdf></bsdf>
  <shape type="rectangle"><transform name="to_world"><matrix value="1 0 0 0  0 0 1 0  0 -1 0 0  0 0 0 1"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><matrix value="1 0 0 0  0 0 -1 2  0 1 0 0  0 0 0 1"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><translate x="0" y="1" z="-1"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><matrix value="0 0 1 -1  0 1 0 1  -1 0 0 0  0 0 0 1"/></transform><ref id="red"/></shape>
  <shape type="rectangle"><transform name="to_world"><matrix value="0 0 -1 1  0 1 0 1  1 0 0 0  0 0 0 1"/></transform><ref id="green"/></shape>
  <shape type="cube">
    <transform name="to_world"><scale x="0.25" y="0.5" z="0.25"/><translate x="-0.375" y="0.5" z="-0.25"/></transform>
    <bsdf type="twosided"><bsdf type="roughconductor"><string name="distribution" value="ggx"/><float name="alpha" value="0.25"/>
      <rgb name="eta" value="0.2 0.9 1.1"/><rgb name="k" value="3.9 2.4 2.1"/></bsdf></bsdf>
  </shape>
  <shape type="sphere"><point name="center" x="0.5" y="0.25" z="0.25"/><float name="radius" value="0.25"/>
    <bsdf type="dielectric"><float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/></bsdf>
  </shape>
  <shape type="rectangle">
    <transform name="to_world"><matrix value="0.25 0 0 0  0 0 -0.25 1.984375  0 0.25 0 0  0 0 0 1"/></transform>
    <bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf></bsdf>
    <emitter type="area"><rgb name="radiance" value="17 12 4"/></emitter>
  </shape>
</scene>
"#;

/// The same box in Sahara's TOML.
const CORNELL_TOML: &str = r#"
[camera]
eye = [0, 1, 3.5]
target = [0, 1, 0]
vfov = 40

[[material]]
name = "white"
type = "diffuse"
albedo = [0.75, 0.75, 0.75]

[[material]]
name = "red"
type = "diffuse"
albedo = [0.63, 0.065, 0.05]

[[material]]
name = "green"
type = "diffuse"
albedo = [0.14, 0.45, 0.091]

[[material]]
name = "metal"
type = "conductor"
eta = [0.2, 0.9, 1.1]
k = [3.9, 2.4, 2.1]
roughness = 0.5
multiple_scattering = false

[[material]]
name = "glass"
type = "dielectric"
ior = 1.5

[[object]]
type = "quad"
corner = [-1, 0, 1]
edge_u = [2, 0, 0]
edge_v = [0, 0, -2]
material = "white"

[[object]]
type = "quad"
corner = [-1, 2, -1]
edge_u = [2, 0, 0]
edge_v = [0, 0, 2]
material = "white"

[[object]]
type = "quad"
corner = [-1, 0, -1]
edge_u = [2, 0, 0]
edge_v = [0, 2, 0]
material = "white"

[[object]]
type = "quad"
corner = [-1, 0, 1]
edge_u = [0, 0, -2]
edge_v = [0, 2, 0]
material = "red"

[[object]]
type = "quad"
corner = [1, 0, -1]
edge_u = [0, 0, 2]
edge_v = [0, 2, 0]
material = "green"

[[object]]
type = "box"
min = [-0.625, 0, -0.5]
max = [-0.125, 1, 0]
material = "metal"

[[object]]
type = "sphere"
center = [0.5, 0.25, 0.25]
radius = 0.25
material = "glass"

[[light]]
type = "area"
shape = "quad"
corner = [-0.25, 1.984375, -0.25]
edge_u = [0.5, 0, 0]
edge_v = [0, 0, 0.5]
radiance = [17, 12, 4]

[film]
width = 24
height = 24
"#;

#[test]
fn a_mitsuba_cornell_box_renders_the_same_bytes_as_its_toml_twin() {
    let dir = folder("cornell");
    std::fs::write(dir.join("cbox.xml"), CORNELL_XML).unwrap();
    std::fs::write(dir.join("cbox.toml"), CORNELL_TOML).unwrap();
    let m = load_mitsuba(&dir.join("cbox.xml")).unwrap();
    let t = load_scene(&dir.join("cbox.toml")).unwrap();
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    assert_eq!(m.scene.shapes.len(), t.scene.shapes.len());
    let (a, b) = (image(&m.scene, 4), image(&t.scene, 4));
    assert!(
        b.iter().any(|v| v.max_element() > 0.0),
        "the reference image is black"
    );
    assert!(a == b, "the images differ");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The bytes of a Mitsuba `.vol` file of `channels` channels.
fn vol_bytes(size: [u32; 3], channels: u32, values: &[f32]) -> Vec<u8> {
    let mut b = b"VOL\x03".to_vec();
    for v in [1, size[0], size[1], size[2], channels] {
        b.extend(v.to_le_bytes());
    }
    for v in [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0].iter().chain(values) {
        b.extend(v.to_le_bytes());
    }
    b
}

const MEDIA_XML: &str = r#"<scene version="3.0.0">
  <integrator type="volpath"><integer name="max_depth" value="6"/></integrator>
  <medium type="homogeneous" id="fog">
    <rgb name="sigma_t" value="0.25 0.5 1"/><float name="albedo" value="0.5"/>
    <phase type="hg"><float name="g" value="0.25"/></phase>
  </medium>
  <sensor type="perspective">
    <float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, 0, 0" target="0, 0, 1" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/></film>
    <ref id="fog"/>
  </sensor>
  <emitter type="point"><point name="position" x="1" y="2" z="0"/><rgb name="intensity" value="5 5 5"/></emitter>
  <shape type="sphere"><float name="radius" value="20"/><bsdf type="null"/><ref name="interior" id="fog"/></shape>
  <shape type="sphere"><point name="center" x="0" y="1" z="4"/><float name="radius" value="1.8"/>
    <medium type="heterogeneous" name="interior">
      <volume type="gridvolume" name="sigma_t"><string name="filename" value="smoke.vol"/>
        <transform name="to_world"><scale value="2"/><translate x="-1" y="0" z="3"/></transform></volume>
      <float name="scale" value="4"/><rgb name="albedo" value="0.75 0.75 0.75"/>
    </medium>
    <ref name="exterior" id="fog"/>
  </shape>
  <shape type="sphere"><point name="center" x="0" y="-1.5" z="5"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.5 0.5 0.5"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="1.25" y="-0.5" z="4"/><float name="radius" value="0.5"/>
    <bsdf type="dielectric"><float name="int_ior" value="1.4"/><float name="ext_ior" value="1"/></bsdf>
    <medium type="homogeneous" name="interior"><float name="sigma_t" value="2"/><float name="albedo" value="0.5"/></medium>
    <ref name="exterior" id="fog"/>
  </shape>
</scene>
"#;

const MEDIA_TOML: &str = r#"
[camera]
eye = [0, 0, 0]
target = [0, 0, 1]
vfov = 40
medium = "fog"

[[medium]]
name = "fog"
type = "homogeneous"
sigma_a = [0.125, 0.25, 0.5]
sigma_s = [0.125, 0.25, 0.5]
g = 0.25

[[medium]]
name = "smoke"
type = "grid"
file = "smoke.vol"
min = [-1, 0, 3]
max = [1, 2, 5]
sigma_a = [1, 1, 1]
sigma_s = [3, 3, 3]

[[medium]]
name = "wax"
type = "homogeneous"
sigma_a = [1, 1, 1]
sigma_s = [1, 1, 1]

[[material]]
name = "grey"
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[[material]]
name = "boundary"
type = "dielectric"
ior = 1.4

[[object]]
type = "sphere"
center = [0, 0, 0]
radius = 20
medium_inside = "fog"

[[object]]
type = "sphere"
center = [0, 1, 4]
radius = 1.8
medium_inside = "smoke"
medium_outside = "fog"

[[object]]
type = "sphere"
center = [0, -1.5, 5]
radius = 1
material = "grey"

[[object]]
type = "sphere"
center = [1.25, -0.5, 4]
radius = 0.5
material = "boundary"
medium_inside = "wax"
medium_outside = "fog"

[[light]]
type = "point"
position = [1, 2, 0]
intensity = [5, 5, 5]

[integrator]
name = "path"
max_depth = 5

[film]
width = 24
height = 24
"#;

#[test]
fn mitsuba_and_toml_media_make_the_same_scene_and_image() {
    let dir = folder("media");
    std::fs::write(dir.join("m.xml"), MEDIA_XML).unwrap();
    std::fs::write(dir.join("m.toml"), MEDIA_TOML).unwrap();
    std::fs::write(
        dir.join("smoke.vol"),
        vol_bytes([2, 1, 2], 1, &[0.0, 1.0, 2.0, 0.5]),
    )
    .unwrap();
    let m = load_mitsuba(&dir.join("m.xml")).unwrap();
    let t = load_scene(&dir.join("m.toml")).unwrap();
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    crate::common::test_scenes::assert_same_media(&m.scene, &t.scene, 3, 3);
    crate::common::test_scenes::assert_same_render(&m.scene, &t.scene);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_media_are_errors_naming_the_line() {
    let dir = folder("bad-media");
    std::fs::write(
        dir.join("rgb.vol"),
        vol_bytes([1, 1, 1], 3, &[1.0, 1.0, 1.0]),
    )
    .unwrap();
    std::fs::write(dir.join("short.vol"), &vol_bytes([2, 2, 2], 1, &[1.0])[..]).unwrap();
    std::fs::write(dir.join("neg.vol"), vol_bytes([1, 1, 1], 1, &[-1.0])).unwrap();
    std::fs::write(
        dir.join("bright.vol"),
        vol_bytes([1, 1, 1], 3, &[1.0, 2.0, 1.0]),
    )
    .unwrap();
    let e = |body: &str| match describe_in(body, &dir) {
        Ok(_) => panic!("expected an error for {body:?}"),
        Err(e) => e.to_string(),
    };
    let shape = |medium: &str| format!("<shape type=\"sphere\">\n{medium}\n</shape>");
    let m = e(&shape("<medium type=\"homogeneous\" name=\"interior\"><float name=\"albedo\" value=\"1.5\"/></medium>"));
    assert!(
        m.contains("t.xml") && m.contains("line 3") && m.contains("'albedo'"),
        "{m}"
    );
    let m = e(&shape("<medium type=\"homogeneous\" name=\"interior\"><float name=\"sigma_t\" value=\"-1\"/></medium>"));
    assert!(
        m.contains("line 3") && m.contains("must be finite and not negative"),
        "{m}"
    );
    let m = e(&shape("<medium type=\"homogeneous\" name=\"inside\"/>"));
    assert!(
        m.contains("line 3") && m.contains("'interior' or 'exterior'"),
        "{m}"
    );
    let m = e(&shape("<medium type=\"clouds\" name=\"interior\"/>"));
    assert!(m.contains("medium type 'clouds' is not supported"), "{m}");
    let m = e(&shape("<ref name=\"interior\" id=\"nothing\"/>"));
    assert!(m.contains("no object has the id \"nothing\""), "{m}");
    let grid = |file: &str, name: &str| {
        shape(&format!("<medium type=\"heterogeneous\" name=\"interior\"><volume type=\"gridvolume\" name=\"{name}\"><string name=\"filename\" value=\"{file}\"/></volume></medium>"))
    };
    let m = e(&grid("short.vol", "sigma_t"));
    assert!(m.contains("short.vol"), "{m}");
    let m = e(&grid("neg.vol", "sigma_t"));
    assert!(m.contains("neg.vol': value 0 is -1"), "{m}");
    let m = e(&grid("rgb.vol", "albedo"));
    assert!(m.contains("albedo grid under a constant 'sigma_t'"), "{m}");
    let both = |albedo: &str, albedo_to_world: &str| {
        shape(&format!("<medium type=\"heterogeneous\" name=\"interior\">\
            <volume type=\"gridvolume\" name=\"sigma_t\"><string name=\"filename\" value=\"rgb.vol\"/></volume>\
            <volume type=\"gridvolume\" name=\"albedo\"><string name=\"filename\" value=\"{albedo}\"/>{albedo_to_world}</volume></medium>"))
    };
    let m = e(&both("bright.vol", ""));
    assert!(m.contains("albedo reaches 2"), "{m}");
    let m = e(&both(
        "rgb.vol",
        "<transform name=\"to_world\"><scale value=\"2\"/></transform>",
    ));
    assert!(m.contains("must span the same box"), "{m}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A three-channel `sigma_t` grid and an albedo grid (one channel, used
/// in all three) make a medium of colours per voxel, `sigma_t` times
/// `scale`.
#[test]
fn colour_grids_make_a_medium_of_colours_per_voxel() {
    use sahara_render::{ColourGrid, ColourVolume, GridCoefficients};
    let dir = folder("colour-media");
    let st = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
    std::fs::write(dir.join("st.vol"), vol_bytes([2, 1, 1], 3, &st)).unwrap();
    std::fs::write(dir.join("a.vol"), vol_bytes([2, 1, 1], 1, &[0.25, 0.5])).unwrap();
    let body = "<shape type=\"sphere\"><medium type=\"heterogeneous\" name=\"interior\">\
        <float name=\"scale\" value=\"2\"/>\
        <volume type=\"gridvolume\" name=\"sigma_t\"><string name=\"filename\" value=\"st.vol\"/></volume>\
        <volume type=\"gridvolume\" name=\"albedo\"><string name=\"filename\" value=\"a.vol\"/></volume>\
        </medium></shape>";
    let s = describe_in(body, &dir).unwrap();
    let sahara_render::Medium::Grid(g) = &s.media[0] else {
        panic!("{:?}", s.media)
    };
    let colours = |v: &[f32]| {
        let v: Vec<Vec3> = v.chunks(3).map(Vec3::from_slice).collect();
        ColourGrid::new([2, 1, 1], v).unwrap()
    };
    let want = GridCoefficients::extinction_albedo(
        ColourVolume::Grid(colours(&st)),
        ColourVolume::Grid(colours(&[0.25, 0.25, 0.25, 0.5, 0.5, 0.5])),
        2.0,
    );
    assert_eq!(g.coefficients, want);
    let _ = std::fs::remove_dir_all(&dir);
}
