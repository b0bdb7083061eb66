//! Scene files: a complete example, defaults, every error class, the shipped examples.

use std::path::{Path, PathBuf};

use super::file::*;
use super::{load_scene_file, parse_scene_file};
use glam::{Mat4, Quat, Vec3};
use sahara_render::{
    Bsdf, Distribution, Filter, FrameLayer, Integrator, Light, Material, SamplerKind, Shape,
    ToneMap,
};

use crate::description::SettingsLayer;
use crate::output::frame::OutputLayer;

use super::test_helpers::TempDir;

/// A folder with a mesh, a texture and an environment map for scenes to name.
fn assets() -> TempDir {
    let dir = TempDir::new("scene");
    std::fs::create_dir(dir.0.join("meshes")).unwrap();
    dir.write("meshes/tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    dir.write("wood.png", "exists");
    dir.write("sky.hdr", "exists");
    dir
}

const COMPLETE: &str = r#"
[camera]
eye = [0, 1, 5]
target = [0, 1, 0]
up = [0, 1, 0]
vfov = 40
aperture_radius = 0.05
focus_distance = 4.5
shutter_open = 0.25
shutter_close = 0.75

[[material]]
name = "wood"
type = "diffuse"
albedo = [0.6, 0.4, 0.2]
texture = "wood.png"

[[material]]
name = "gold"
type = "glossy"
color = [1.0, 0.8, 0.3]
roughness = 0.1

[[material]]
name = "mirror"
type = "mirror"

[[material]]
name = "glass"
type = "dielectric"
ior = 1.33

[[material]]
name = "frosted"
type = "rough_dielectric"
roughness = 0.4

[[material]]
name = "lamp"
type = "emission"
radiance = [5, 5, 4]
two_sided = true

[[object]]
type = "mesh"
file = "meshes/tri.obj"
material = "wood"
transform = { translate = [1, 2, 3], rotate = { axis = [0, 2, 0], degrees = 90 }, scale = [2, 2, 2] }

[[object]]
type = "sphere"
center = [0, 1, 0]
radius = 0.5
material = "glass"
motion = { open = { translate = [0, 0, 0] }, close = { translate = [1, 0, 0], scale = 2 } }

[[object]]
type = "quad"
corner = [-1, 0, -1]
edge_u = [2, 0, 0]
edge_v = [0, 0, 2]

[[object]]
type = "disc"
center = [0, 3, 0]
normal = [0, -1, 0]
radius = 0.3
material = "lamp"

[[object]]
type = "box"
min = [-1, -1, -1]
max = [1, 0, 1]
material = "gold"

[[light]]
type = "point"
position = [0, 4, 0]
intensity = [10, 10, 10]

[[light]]
type = "spot"
position = [0, 4, 0]
target = [0, 0, 0]
intensity = [20, 20, 20]
inner_angle = 20
outer_angle = 30

[[light]]
type = "directional"
direction = [0, -1, 0]
irradiance = [1, 1, 1]

[[light]]
type = "area"
shape = "quad"
corner = [-0.5, 3.9, -0.5]
edge_u = [1, 0, 0]
edge_v = [0, 0, 1]
radiance = [8, 8, 8]

[[light]]
type = "environment"
map = "sky.hdr"
scale = 0.5

[integrator]
name = "distribution"
max_depth = 6
light_samples = 4

[sampler]
name = "stratified"
spp = 64
seed = 42

[filter]
name = "mitchell"
radius = 2
b = 0.5
c = 0.25

[film]
width = 320
height = 240
exposure = -1
tonemap = "filmic"
output = "renders/out.EXR"
"#;

#[test]
fn a_complete_scene_parses_into_the_expected_values() {
    let dir = assets();
    let path = dir.write("scene.toml", COMPLETE);
    let s = load_scene_file(&path).unwrap();
    let at = |p: &str| dir.0.join(p);

    assert_eq!(
        s.camera,
        CameraSpec {
            eye: Vec3::new(0., 1., 5.),
            target: Vec3::new(0., 1., 0.),
            up: Vec3::Y,
            vfov_deg: 40.0,
            aperture_radius: 0.05,
            focus_distance: 4.5,
            shutter_open: 0.25,
            shutter_close: 0.75,
        }
    );
    let spec = |name: &str, material: Material, texture: Option<PathBuf>| MaterialSpec {
        name: name.into(),
        material,
        texture,
    };
    let mut lamp = Material::emitter(Vec3::new(5., 5., 4.));
    lamp.two_sided_emission = true;
    assert_eq!(
        s.materials,
        vec![
            spec(
                "wood",
                Material::diffuse(Vec3::new(0.6, 0.4, 0.2)),
                Some(at("wood.png"))
            ),
            spec(
                "gold",
                Material::conductor(Vec3::new(1.0, 0.8, 0.3), 0.1),
                None
            ),
            spec("mirror", Material::mirror(Vec3::ONE), None),
            spec("glass", Material::glass(1.33), None),
            spec("frosted", Material::rough_glass(1.5, 0.4), None),
            spec("lamp", lamp, None),
        ]
    );

    assert_eq!(s.objects.len(), 5);
    let mesh = &s.objects[0];
    assert_eq!(
        mesh.shape,
        ShapeSpec::Mesh {
            path: at("meshes/tri.obj")
        }
    );
    assert_eq!(mesh.material.as_deref(), Some("wood"));
    let Placement::Static(t) = mesh.placement else {
        panic!("{:?}", mesh.placement)
    };
    assert_eq!(t.rotate_axis, Vec3::Y, "the axis is normalised");
    // By hand: scale 2, then 90 degrees about y (x -> -z), then move by (1, 2, 3):
    // the point (1, 0, 0) goes to (2, 0, 0), (0, 0, -2), (1, 2, 1).
    let p = t.matrix().transform_point3(Vec3::X);
    assert!(p.abs_diff_eq(Vec3::new(1., 2., 1.), 1e-5), "{p}");
    let expected = Mat4::from_translation(Vec3::new(1., 2., 3.))
        * Mat4::from_quat(Quat::from_rotation_y(std::f32::consts::FRAC_PI_2))
        * Mat4::from_scale(Vec3::splat(2.));
    assert!(t.matrix().abs_diff_eq(expected, 1e-5));

    assert_eq!(
        s.objects[1].placement,
        Placement::Motion {
            open: TransformSpec::IDENTITY,
            close: TransformSpec {
                translate: Vec3::X,
                scale: Vec3::splat(2.0),
                ..TransformSpec::IDENTITY
            }
        }
    );
    assert_eq!(
        s.objects[2],
        ObjectSpec {
            shape: ShapeSpec::Builtin(Shape::Quad {
                corner: Vec3::new(-1., 0., -1.),
                edge_u: Vec3::new(2., 0., 0.),
                edge_v: Vec3::new(0., 0., 2.)
            }),
            material: None,
            placement: Placement::Static(TransformSpec::IDENTITY),
            name: None,
            interface: None,
        }
    );
    assert_eq!(
        s.objects[3].shape,
        ShapeSpec::Builtin(Shape::Disc {
            center: Vec3::new(0., 3., 0.),
            normal: Vec3::NEG_Y,
            radius: 0.3
        })
    );
    assert_eq!(
        s.objects[4].shape,
        ShapeSpec::Builtin(Shape::Box {
            min: Vec3::splat(-1.),
            max: Vec3::new(1., 0., 1.)
        })
    );

    assert_eq!(s.lights.len(), 5);
    assert_eq!(
        s.lights[1],
        LightSpec::Explicit(Light::spot(
            Vec3::new(0., 4., 0.),
            Vec3::ZERO,
            Vec3::splat(20.),
            20.,
            30.
        ))
    );
    assert!(matches!(
        &s.lights[3],
        LightSpec::Area { shape: ShapeSpec::Builtin(Shape::Quad { .. }), radiance, two_sided: false, material: None } if *radiance == Vec3::splat(8.)
    ));
    assert_eq!(
        s.lights[4],
        LightSpec::Environment(EnvironmentSpec::Map {
            path: at("sky.hdr"),
            scale: 0.5
        })
    );
    let f = s.settings.frame_settings();
    assert_eq!(
        f.integrator,
        Integrator::Distribution {
            max_depth: 6,
            light_samples: 4
        }
    );
    assert_eq!(
        (f.sampler, f.spp, f.seed, f.adaptive),
        (SamplerKind::Stratified, 64, 42, None)
    );
    assert_eq!(
        f.filter,
        Filter::Mitchell {
            radius: 2.,
            b: 0.5,
            c: 0.25
        }
    );
    assert_eq!((f.width, f.height), (320, 240));
    assert_eq!(
        s.settings.output,
        OutputLayer {
            exposure: Some(-1.),
            tonemap: Some(ToneMap::Filmic),
            aovs: None,
            denoise: None,
        }
    );
    assert_eq!(s.settings.path, Some(PathBuf::from("renders/out.EXR")));
}

#[test]
fn a_minimal_scene_gets_the_documented_defaults() {
    let text = "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n[film]\nwidth = 8\nheight = 4\n";
    let s = parse_scene_file(text, "min.toml", Path::new("")).unwrap();
    assert_eq!(s.camera.up, Vec3::Y);
    assert_eq!(s.camera.vfov_deg, 45.0);
    assert_eq!(s.camera.aperture_radius, 0.0);
    assert_eq!(s.camera.focus_distance, 3.0, "|target - eye|");
    assert_eq!((s.camera.shutter_open, s.camera.shutter_close), (0.0, 0.0));
    // The file gives its size alone: the rest is the defaults'.
    let given = SettingsLayer {
        frame: FrameLayer {
            width: Some(8),
            height: Some(4),
            ..Default::default()
        },
        ..Default::default()
    };
    assert_eq!(s.settings, given);
    let f = s.settings.frame_settings();
    assert_eq!(
        f.integrator,
        Integrator::Path {
            max_depth: 8,
            rr_depth: 3
        }
    );
    assert_eq!(
        (f.sampler, f.spp, f.seed, f.adaptive),
        (SamplerKind::Sobol, 64, 0, None)
    );
    assert_eq!(
        f.filter,
        Filter::Gaussian {
            radius: 1.5,
            sigma: 0.5
        }
    );
    assert!(s.objects.is_empty() && s.lights.is_empty() && s.materials.is_empty());
}

/// The error for `text` (a scene in the assets folder); checks it is one line naming the file.
fn error_of(text: &str) -> String {
    let dir = assets();
    let path = dir.write("bad.toml", text);
    let message = load_scene_file(&path).unwrap_err().to_string();
    assert!(message.contains("bad.toml"), "{message}");
    assert!(!message.contains('\n'), "{message}");
    message
}

const HEAD: &str = "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n[film]\nwidth = 8\nheight = 4\n";

/// `HEAD` (6 lines) followed by `rest`, so `rest`'s first line is line 7.
fn with_head(rest: &str) -> String {
    format!("{HEAD}{rest}")
}

#[test]
fn syntax_errors_and_unknown_keys_give_line_and_column() {
    let m = error_of("[camera]\neye = [0, 0, 3\ntarget = [0, 0, 0]\n");
    assert!(m.contains("line 2:") || m.contains("line 3:"), "{m}");

    let m = error_of(&with_head("[sampler]\nspp = 4\nsed = 1\n"));
    assert!(m.contains("line 9: column 1:") && m.contains("sed"), "{m}");

    let m = error_of(&with_head(
        "[[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\ncolour = \"red\"\n",
    ));
    assert!(
        m.contains("line 11: column 1:") && m.contains("colour"),
        "{m}"
    );

    let m = error_of(
        "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nfov = 30\n[film]\nwidth = 8\nheight = 4\n",
    );
    assert!(m.contains("line 4:") && m.contains("fov"), "{m}");

    let m = error_of(&with_head("[bogus]\nx = 1\n"));
    assert!(m.contains("line 7:") && m.contains("bogus"), "{m}");

    // A key that exists, but for another type.
    let m = error_of(&with_head(
        "[[material]]\nname = \"m\"\ntype = \"diffuse\"\nior = 1.5\n",
    ));
    assert!(
        m.contains("line 10: column 7:") && m.contains("`ior`") && m.contains("diffuse"),
        "{m}"
    );
    let m = error_of(&with_head(
        "[integrator]\nname = \"normals\"\nmax_depth = 3\n",
    ));
    assert!(
        m.contains("line 9:") && m.contains("max_depth") && m.contains("normals"),
        "{m}"
    );
    // The integrator's keys come from the renderer's list of its parameters.
    for (table, says) in [
        (
            "name = \"path\"\nmax_depth = 2.5\n",
            "`max_depth` must be a whole number",
        ),
        (
            "name = \"path\"\nmax_depth = 0\n",
            "must be a whole number of at least 1",
        ),
        (
            "name = \"path\"\nsamples = 4\n",
            "(its keys: max_depth, rr_depth)",
        ),
        (
            "name = \"ao\"\ndistance = -1\n",
            "`distance` is -1 but must be at least 0",
        ),
        ("max_depth = 4\n", "needs the key `name`"),
    ] {
        let m = error_of(&with_head(&format!("[integrator]\n{table}")));
        assert!(m.contains(says), "{table}: {m}");
    }

    // Wrong value types.
    let m = error_of(&with_head("[sampler]\nspp = \"many\"\n"));
    assert!(m.contains("line 8: column 7:"), "{m}");
    let m = error_of(&with_head(
        "[[light]]\ntype = \"point\"\nposition = [0, 1]\nintensity = [1, 1, 1]\n",
    ));
    assert!(m.contains("line 9:") && m.contains("3"), "{m}");
}

#[test]
fn unknown_names_are_errors_at_the_value() {
    let m = error_of(&with_head("[integrator]\nname = \"photon_mapping\"\n"));
    assert!(
        m.contains("line 8: column 8:") && m.contains("photon_mapping") && m.contains("path"),
        "{m}"
    );
    let m = error_of(&with_head("[sampler]\nname = \"halton\"\n"));
    assert!(
        m.contains("line 8:") && m.contains("halton") && m.contains("sobol"),
        "{m}"
    );
    let m = error_of(&with_head("[filter]\nname = \"lanczos\"\n"));
    assert!(m.contains("line 8:") && m.contains("lanczos"), "{m}");
    let m = error_of(&with_head(
        "[[material]]\nname = \"m\"\ntype = \"velvet\"\n",
    ));
    assert!(m.contains("line 9:") && m.contains("velvet"), "{m}");
    let m = error_of(&with_head("[[object]]\ntype = \"torus\"\n"));
    assert!(m.contains("line 8:") && m.contains("torus"), "{m}");
    let m = error_of(&with_head(
        "[[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"nope\"\n",
    ));
    assert!(m.contains("line 11:") && m.contains("'nope'"), "{m}");
    let m = error_of(&with_head("[film2]\n"));
    assert!(m.contains("film2"), "{m}");
}

#[test]
fn bad_values_are_errors_with_their_position() {
    let cases: &[(&str, &[&str])] = &[
        ("[sampler]\nspp = -4\n", &["line 8: column 7:", "spp", "-4", "at least 1"]),
        ("[sampler]\nspp = 0\n", &["line 8:", "spp"]),
        ("[sampler]\nseed = -1\n", &["line 8:", "seed"]),
        ("[integrator]\nname = \"path\"\nmax_depth = 0\n", &["line 9:", "max_depth"]),
        ("[integrator]\nname = \"ao\"\ndistance = -1\n", &["line 9:", "distance"]),
        ("[filter]\nname = \"box\"\nradius = 0\n", &["line 9:", "radius"]),
        ("[filter]\nname = \"box\"\nradius = \"x\"\n", &["line 9:", "`radius` must be a number"]),
        ("[sampler]\nspp = \"many\"\n", &["line 8:", "expected a whole number"]),
        ("[[material]]\nname = \"m\"\ntype = \"diffuse\"\ntwo_sided = 1\n", &["line 10:", "expected true or false"]),
        ("[[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = \"big\"\n", &["line 10:", "expected a number"]),
        ("[[material]]\nname = \"m\"\ntype = \"diffuse\"\nalbedo = [0.5, 1.5, 0]\n", &["line 10:", "albedo", "between 0 and 1"]),
        ("[[material]]\nname = \"m\"\ntype = \"dielectric\"\nior = -1\n", &["line 10:", "ior"]),
        ("[[material]]\nname = \"m\"\ntype = \"conductor\"\nroughness = 2\n", &["line 10:", "roughness"]),
        ("[[material]]\nname = \"m\"\ntype = \"emission\"\n", &["line 9:", "radiance"]),
        ("[[material]]\nname = \"m\"\ntype = \"mirror\"\n[[material]]\nname = \"m\"\ntype = \"mirror\"\n", &["line 11:", "already defined"]),
        ("[[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = -1\n", &["line 10:", "radius"]),
        ("[[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\n", &["line 7:", "radius"]),
        ("[[object]]\ntype = \"box\"\nmin = [0, 0, 0]\nmax = [1, 0, 1]\n", &["line 10:", "max"]),
        ("[[object]]\ntype = \"quad\"\ncorner = [0, 0, 0]\nedge_u = [1, 0, 0]\nedge_v = [2, 0, 0]\n", &["line 11:", "parallel"]),
        ("[[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\ntransform = { scale = [1, 0, 1] }\n", &["line 11:", "scale"]),
        ("[[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\ntransform = {}\nmotion = { open = {}, close = {} }\n", &["line 12:", "not both"]),
        ("[[light]]\ntype = \"spot\"\nposition = [0, 0, 0]\ntarget = [0, 0, -1]\nintensity = [1, 1, 1]\nouter_angle = 30\ninner_angle = 40\n", &["line 13:", "inner_angle"]),
        ("[[light]]\ntype = \"point\"\nposition = [0, 0, 0]\nintensity = [-1, 1, 1]\n", &["line 10:", "intensity", "negative"]),
        ("[[light]]\ntype = \"environment\"\n", &["line 7:", "radiance", "map"]),
        ("[[light]]\ntype = \"environment\"\nradiance = [1, 1, 1]\n[[light]]\ntype = \"environment\"\nradiance = [1, 1, 1]\n", &["line 10:", "at most one"]),
        ("[[light]]\ntype = \"area\"\nshape = \"box\"\nradiance = [1, 1, 1]\n", &["line 9:", "quad, disc or sphere"]),
        ("[[light]]\ntype = \"point\"\nposition = [0, 0, 0]\nintensity = [1, 1, 1]\nradius = 2\n", &["line 11:", "radius", "point"]),
        ("[[light]]\ntype = \"directional\"\ndirection = [0, 0, 0]\nirradiance = [1, 1, 1]\n", &["line 9:", "direction"]),
    ];
    for (rest, expected) in cases {
        let m = error_of(&with_head(rest));
        for e in *expected {
            assert!(m.contains(e), "{rest:?}: expected {e:?} in {m}");
        }
    }
    // Film and camera values.
    let m =
        error_of("[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n[film]\nwidth = 0\nheight = 4\n");
    assert!(
        m.contains("line 5: column 9:") && m.contains("width") && m.contains("between 1"),
        "{m}"
    );
    let m =
        error_of("[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n[film]\nwidth = 8\nheight = -2\n");
    assert!(m.contains("line 6:") && m.contains("height"), "{m}");
    let m = error_of("[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n[film]\nwidth = 8\nheight = 4\noutput = \"x.jpg\"\n");
    assert!(m.contains("line 7:") && m.contains(".png or .exr"), "{m}");
    let m =
        error_of("[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 3]\n[film]\nwidth = 8\nheight = 4\n");
    assert!(m.contains("line 3:") && m.contains("same point"), "{m}");
    let m = error_of("[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nup = [0, 0, 1]\n[film]\nwidth = 8\nheight = 4\n");
    assert!(m.contains("line 4:") && m.contains("parallel"), "{m}");
    let m = error_of("[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nvfov = 180\n[film]\nwidth = 8\nheight = 4\n");
    assert!(m.contains("line 4:") && m.contains("vfov"), "{m}");
    let m = error_of("[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nshutter_open = 1\nshutter_close = 0.5\n[film]\nwidth = 8\nheight = 4\n");
    assert!(m.contains("line 5:") && m.contains("shutter_close"), "{m}");
    let m = error_of("[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\naperture_radius = -0.1\n[film]\nwidth = 8\nheight = 4\n");
    assert!(
        m.contains("line 4:") && m.contains("aperture_radius"),
        "{m}"
    );
    let m = error_of("[film]\nwidth = 8\nheight = 4\n");
    assert!(m.contains("[camera]"), "{m}");
    let m = error_of("[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n");
    assert!(m.contains("[film]"), "{m}");
}

#[test]
fn missing_files_are_errors_naming_the_resolved_path() {
    let m = error_of(&with_head(
        "[[object]]\ntype = \"mesh\"\nfile = \"meshes/gone.obj\"\n",
    ));
    assert!(
        m.contains("line 9: column 8:") && m.contains("meshes/gone.obj") && m.contains("not found"),
        "{m}"
    );
    let m = error_of(&with_head("[[object]]\ntype = \"mesh\"\n"));
    assert!(m.contains("line 7:") && m.contains("`file`"), "{m}");
    let m = error_of(&with_head(
        "[[material]]\nname = \"m\"\ntype = \"diffuse\"\ntexture = \"nope.png\"\n",
    ));
    assert!(m.contains("line 10:") && m.contains("nope.png"), "{m}");
    let m = error_of(&with_head(
        "[[light]]\ntype = \"environment\"\nmap = \"nope.exr\"\n",
    ));
    assert!(m.contains("line 9:") && m.contains("nope.exr"), "{m}");
    // The mesh exists but is not a mesh format.
    let m = error_of(&with_head(
        "[[object]]\ntype = \"mesh\"\nfile = \"wood.png\"\n",
    ));
    assert!(m.contains("line 9:") && m.contains(".obj"), "{m}");
    let missing = load_scene_file(Path::new("/no/such/scene.toml"))
        .unwrap_err()
        .to_string();
    assert!(missing.contains("/no/such/scene.toml"), "{missing}");
}

#[test]
fn columns_count_characters_not_bytes() {
    // "é" is two bytes; the bad key starts at character 1 of line 8 either way,
    // and the value after a two-byte name is at column 8, not 9.
    let m = error_of(&with_head(
        "[[material]]\nname = \"é\"\ntype = \"mirror\"\n[sampler]\nspp = -1\n",
    ));
    assert!(m.contains("line 11: column 7:"), "{m}");
}

/// The workspace's `scenes/` folder.
fn example_scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

#[test]
fn every_example_scene_loads() {
    // Their meshes ship in scenes/assets, so this needs nothing outside the
    // repository.
    let mut found = 0;
    for entry in std::fs::read_dir(example_scenes()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let scene = load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
            assert!(!scene.objects.is_empty(), "{}", path.display());
            for object in &scene.objects {
                if let ShapeSpec::Mesh { path } = &object.shape {
                    assert!(path.is_file());
                }
            }
            found += 1;
        }
    }
    assert!(found >= 3, "{found} example scenes");

    // Each example shows what it is for.
    let load = |name: &str| load_scene_file(&example_scenes().join(name)).unwrap();
    let cornell = load("cornell_glossy_glass.toml");
    assert!(cornell
        .materials
        .iter()
        .any(|m| matches!(m.material.bsdf, Bsdf::Conductor { roughness, .. } if roughness > 0.0)));
    assert!(cornell
        .materials
        .iter()
        .any(|m| matches!(m.material.bsdf, Bsdf::Dielectric { .. })));
    assert!(matches!(
        cornell.settings.frame_settings().integrator,
        Integrator::Distribution { .. }
    ));
    let dof = load("bunny_dof.toml");
    assert!(dof.camera.aperture_radius > 0.0);
    let blur = load("motion_blur.toml");
    assert!(blur.camera.shutter_close > blur.camera.shutter_open);
    assert!(blur
        .objects
        .iter()
        .any(|o| matches!(o.placement, Placement::Motion { .. })));
}

/// The materials of `rest` (after `HEAD`).
fn materials_of(rest: &str) -> Vec<MaterialSpec> {
    let dir = assets();
    let path = dir.write("m.toml", with_head(rest));
    load_scene_file(&path).unwrap().materials
}

#[test]
fn layered_conductor_and_thin_materials_parse_with_defaults() {
    let m = materials_of(
        "[[material]]\nname = \"a\"\ntype = \"metallic_roughness\"\n\
         [[material]]\nname = \"b\"\ntype = \"metallic_roughness\"\nbase_color = [1, 0, 0]\nmetallic = 1\nroughness = 0.3\nior = 1.4\nspecular = 0.5\nspecular_color = [0, 1, 0]\ntwo_sided = false\n\
         [[material]]\nname = \"c\"\ntype = \"coated_diffuse\"\n\
         [[material]]\nname = \"d\"\ntype = \"thin_dielectric\"\nior = 1.52\n\
         [[material]]\nname = \"e\"\ntype = \"conductor\"\nmetal = \"gold\"\nroughness = 0.1\n\
         [[material]]\nname = \"f\"\ntype = \"conductor\"\neta = [0.2, 0.9, 1.1]\nk = [3.9, 2.4, 2.1]\nmultiple_scattering = false\n",
    );
    assert_eq!(
        m[0].material.bsdf,
        Bsdf::MetallicRoughness {
            base_color: Vec3::splat(0.8),
            metallic: 0.0,
            roughness: 0.5,
            ior: 1.5,
            specular: 1.0,
            specular_color: Vec3::ONE,
        }
    );
    assert!(m[0].material.two_sided);
    assert_eq!(
        m[1].material.bsdf,
        Bsdf::MetallicRoughness {
            base_color: Vec3::X,
            metallic: 1.0,
            roughness: 0.3,
            ior: 1.4,
            specular: 0.5,
            specular_color: Vec3::Y,
        }
    );
    assert!(!m[1].material.two_sided);
    assert_eq!(m[0].material.alpha_mode, sahara_render::AlphaMode::Opaque);
    assert_eq!(m[0].material.alpha, 1.0);
    assert_eq!(
        m[2].material.bsdf,
        Bsdf::CoatedDiffuse {
            albedo: Vec3::splat(0.5),
            ior: 1.5,
            roughness: 0.1,
            distribution: Distribution::Ggx,
        }
    );
    assert_eq!(m[3].material.bsdf, Bsdf::ThinDielectric { ior: 1.52 });
    let (eta, k) = sahara_render::metals::preset("gold").unwrap();
    assert_eq!(
        m[4].material.bsdf,
        Bsdf::ComplexConductor {
            eta,
            k,
            roughness: 0.1,
            distribution: Distribution::Ggx,
            multiple_scattering: true,
        }
    );
    assert_eq!(
        m[5].material.bsdf,
        Bsdf::ComplexConductor {
            eta: Vec3::new(0.2, 0.9, 1.1),
            k: Vec3::new(3.9, 2.4, 2.1),
            roughness: 0.2,
            distribution: Distribution::Ggx,
            multiple_scattering: false,
        }
    );
}

#[test]
fn bad_conductor_and_layered_keys_are_errors_at_the_value() {
    let m = error_of(&with_head(
        "[[material]]\nname = \"m\"\ntype = \"conductor\"\nmetal = \"brass\"\n",
    ));
    assert!(
        m.contains("line 10: column 9:") && m.contains("'brass'") && m.contains("gold"),
        "{m}"
    );
    let m = error_of(&with_head(
        "[[material]]\nname = \"m\"\ntype = \"conductor\"\ncolor = [1, 1, 1]\nmetal = \"gold\"\n",
    ));
    assert!(m.contains("line 11:") && m.contains("not both"), "{m}");
    let m = error_of(&with_head(
        "[[material]]\nname = \"m\"\ntype = \"conductor\"\neta = [1, 1, 1]\n",
    ));
    assert!(m.contains("`k`"), "{m}");
    let m = error_of(&with_head(
        "[[material]]\nname = \"m\"\ntype = \"conductor\"\ncolor = [1, 1, 1]\nmultiple_scattering = false\n",
    ));
    assert!(
        m.contains("line 11:") && m.contains("`multiple_scattering` applies to"),
        "{m}"
    );
    let m = error_of(&with_head(
        "[[material]]\nname = \"m\"\ntype = \"metallic_roughness\"\nmetallic = 2\n",
    ));
    assert!(m.contains("line 10:") && m.contains("metallic"), "{m}");
    let m = error_of(&with_head(
        "[[material]]\nname = \"m\"\ntype = \"thin_dielectric\"\nroughness = 0.2\n",
    ));
    assert!(
        m.contains("line 10:") && m.contains("thin_dielectric"),
        "{m}"
    );
    let m = error_of(&with_head(
        "[[material]]\nname = \"m\"\ntype = \"coated_diffuse\"\nior = 1\n",
    ));
    assert!(
        m.contains("line 10:") && m.contains("greater than 1"),
        "{m}"
    );
}

#[test]
fn rough_materials_take_a_microfacet_distribution() {
    let m = materials_of(
        "[[material]]\nname = \"a\"\ntype = \"conductor\"\nmetal = \"copper\"\ndistribution = \"beckmann\"\n\
         [[material]]\nname = \"b\"\ntype = \"rough_dielectric\"\ndistribution = \"ggx\"\n\
         [[material]]\nname = \"c\"\ntype = \"coated_diffuse\"\ndistribution = \"beckmann\"\n\
         [[material]]\nname = \"d\"\ntype = \"conductor\"\n",
    );
    let dist: Vec<_> = m
        .iter()
        .map(|m| match m.material.bsdf {
            Bsdf::ComplexConductor { distribution, .. }
            | Bsdf::RoughDielectric { distribution, .. }
            | Bsdf::CoatedDiffuse { distribution, .. }
            | Bsdf::Conductor { distribution, .. } => distribution,
            ref other => panic!("{other:?}"),
        })
        .collect();
    use Distribution::{Beckmann, Ggx};
    assert_eq!(dist, [Beckmann, Ggx, Beckmann, Ggx]);
    let m = error_of(&with_head(
        "[[material]]\nname = \"m\"\ntype = \"conductor\"\ndistribution = \"phong\"\n",
    ));
    assert!(
        m.contains("line 10:") && m.contains("'phong'; expected ggx or beckmann"),
        "{m}"
    );
    let m = error_of(&with_head(
        "[[material]]\nname = \"m\"\ntype = \"diffuse\"\ndistribution = \"ggx\"\n",
    ));
    assert!(m.contains("`distribution` does not apply"), "{m}");
}

#[test]
fn alpha_keys_parse_and_apply_to_reflectors_only() {
    let m = materials_of(
        "[[material]]\nname = \"leaf\"\ntype = \"diffuse\"\nalpha_mode = \"mask\"\nalpha_cutoff = 0.3\n\
         [[material]]\nname = \"veil\"\ntype = \"metallic_roughness\"\nalpha_mode = \"blend\"\nalpha = 0.25\n",
    );
    assert_eq!(
        m[0].material.alpha_mode,
        sahara_render::AlphaMode::Mask { cutoff: 0.3 }
    );
    assert_eq!(m[1].material.alpha_mode, sahara_render::AlphaMode::Blend);
    assert_eq!(m[1].material.alpha, 0.25);
    let e = error_of(&with_head(
        "[[material]]\nname = \"m\"\ntype = \"dielectric\"\nalpha = 0.5\n",
    ));
    assert!(e.contains("line 10:") && e.contains("`alpha`"), "{e}");
    let e = error_of(&with_head(
        "[[material]]\nname = \"m\"\ntype = \"diffuse\"\nalpha_cutoff = 0.5\n",
    ));
    assert!(e.contains("line 10:") && e.contains("mask"), "{e}");
    let e = error_of(&with_head(
        "[[material]]\nname = \"m\"\ntype = \"diffuse\"\nalpha = 2\n",
    ));
    assert!(
        e.contains("line 10:") && e.contains("between 0 and 1"),
        "{e}"
    );
}

/// A `.vol` file of three channels is a density per colour channel: each
/// scales its channel's `sigma_a` and `sigma_s`.
#[test]
fn three_channel_grids_are_a_density_per_channel() {
    use sahara_render::{ColourGrid, ColourVolume, GridCoefficients};
    let dir = assets();
    let values: Vec<f32> = (0..8).flat_map(|i| [i as f32, 1.0, 0.5]).collect();
    let grid = sahara_readers::vol::VolGrid {
        size: [2, 2, 2],
        channels: 3,
        bounds_min: [-1.0; 3],
        bounds_max: [1.0; 3],
        values: values.clone(),
    };
    std::fs::write(dir.0.join("rgb.vol"), sahara_readers::vol::vol_bytes(&grid)).unwrap();
    let path = dir.write(
        "rgb.toml",
        with_head(
            "[[medium]]\nname = \"smoke\"\ntype = \"grid\"\nfile = \"rgb.vol\"\nsigma_a = [1, 2, 3]\nsigma_s = [2, 2, 2]\n\
             [[object]]\ntype = \"box\"\nmin = [-1, -1, -1]\nmax = [1, 1, 1]\nmedium_inside = \"smoke\"\n",
        ),
    );
    let s = load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
    let sahara_render::Medium::Grid(g) = &s.media[0].medium else {
        panic!("{:?}", s.media[0].medium)
    };
    let colours = |k: Vec3| {
        let v: Vec<Vec3> = values.chunks(3).map(|c| Vec3::from_slice(c) * k).collect();
        ColourVolume::Grid(ColourGrid::new([2, 2, 2], v).unwrap())
    };
    let want = GridCoefficients::absorption_scattering(
        colours(Vec3::new(1.0, 2.0, 3.0)),
        colours(Vec3::splat(2.0)),
        1.0,
    );
    assert_eq!(g.coefficients, want);
}

#[test]
fn media_parse_and_bind_to_objects_and_the_camera() {
    let dir = assets();
    let grid = sahara_readers::vol::VolGrid {
        size: [2, 2, 2],
        channels: 1,
        bounds_min: [-1.0; 3],
        bounds_max: [1.0; 3],
        values: vec![0.5; 8],
    };
    std::fs::write(
        dir.0.join("blob.vol"),
        sahara_readers::vol::vol_bytes(&grid),
    )
    .unwrap();
    let path = dir.write(
        "media.toml",
        with_head(
            "[[medium]]\nname = \"fog\"\ntype = \"homogeneous\"\nsigma_s = [0.5, 0.5, 0.5]\nsigma_a = [0.1, 0.2, 0.3]\nscale = 2\ng = 0.4\n\
             [[medium]]\nname = \"cloud\"\ntype = \"grid\"\nfile = \"blob.vol\"\nsigma_s = [1, 1, 1]\nemission = [1, 2, 3]\nemission_scale = 0.5\n\
             [[material]]\nname = \"glass\"\ntype = \"dielectric\"\n\
             [[object]]\ntype = \"box\"\nmin = [-2, -2, -2]\nmax = [2, 2, 2]\nmedium_inside = \"fog\"\n\
             [[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"glass\"\nmedium_inside = \"cloud\"\nmedium_outside = \"fog\"\n",
        )
        .replace("[film]", "[film]\n")
        .replacen("target = [0, 0, 0]\n", "target = [0, 0, 0]\nmedium = \"fog\"\n", 1),
    );
    let s = load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.media.len(), 2);
    assert_eq!(s.camera_medium, Some(0));
    match &s.media[0].medium {
        sahara_render::Medium::Homogeneous(h) => {
            assert_eq!(h.sigma_s, Vec3::splat(1.0));
            assert_eq!(h.sigma_a, Vec3::new(0.2, 0.4, 0.6));
            assert_eq!(h.phase.g, 0.4);
        }
        m => panic!("{m:?}"),
    }
    assert!(matches!(s.media[1].medium, sahara_render::Medium::Grid(_)));
    assert_eq!(s.media[0].medium.emission(), Vec3::ZERO);
    assert_eq!(s.media[1].medium.emission(), Vec3::new(0.5, 1.0, 1.5));
    let fog_box = s.objects[0].interface.unwrap();
    assert_eq!((fog_box.inside, fog_box.outside), (Some(0), None));
    assert!(
        fog_box.index_matched,
        "a box without a material only bounds its medium"
    );
    let ball = s.objects[1].interface.unwrap();
    assert_eq!((ball.inside, ball.outside), (Some(1), Some(0)));
    assert!(!ball.index_matched);
}

#[test]
fn bad_media_are_errors_at_the_value() {
    let m = error_of(&with_head(
        "[[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmedium_inside = \"fog\"\n",
    ));
    assert!(
        m.contains("line 11:") && m.contains("no [[medium]] is named 'fog'"),
        "{m}"
    );
    let m = error_of(&with_head(
        "[[medium]]\nname = \"fog\"\ntype = \"homogeneous\"\nsigma_s = [1, -1, 1]\n",
    ));
    assert!(
        m.contains("line 10:") && m.contains("must not be negative"),
        "{m}"
    );
    let m = error_of(&with_head(
        "[[medium]]\nname = \"fog\"\ntype = \"homogeneous\"\nemission = [1, -1, 1]\n",
    ));
    assert!(
        m.contains("line 10:") && m.contains("`emission`") && m.contains("must not be negative"),
        "{m}"
    );
    let m = error_of(&with_head(
        "[[medium]]\nname = \"fog\"\ntype = \"homogeneous\"\ng = 1\n",
    ));
    assert!(m.contains("line 10:") && m.contains("`g` is 1"), "{m}");
    let m = error_of(&with_head(
        "[[medium]]\nname = \"fog\"\ntype = \"homogeneous\"\n[[medium]]\nname = \"fog\"\ntype = \"homogeneous\"\n",
    ));
    assert!(
        m.contains("line 11:") && m.contains("already defined"),
        "{m}"
    );
    let m = error_of(&with_head(
        "[[medium]]\nname = \"fog\"\ntype = \"homogeneous\"\nfile = \"x.vol\"\n",
    ));
    assert!(
        m.contains("`file` does not apply to a homogeneous medium"),
        "{m}"
    );
    let m = error_of(&with_head(
        "[[medium]]\nname = \"cloud\"\ntype = \"grid\"\n",
    ));
    assert!(m.contains("a grid medium needs the key `file`"), "{m}");
    // A grid file whose header promises more values than it holds.
    let dir = assets();
    let mut bytes = sahara_readers::vol::vol_bytes(&sahara_readers::vol::VolGrid {
        size: [2, 2, 2],
        channels: 1,
        bounds_min: [0.0; 3],
        bounds_max: [1.0; 3],
        values: vec![1.0; 8],
    });
    bytes.truncate(bytes.len() - 4);
    std::fs::write(dir.0.join("short.vol"), bytes).unwrap();
    let path = dir.write(
        "bad.toml",
        with_head("[[medium]]\nname = \"cloud\"\ntype = \"grid\"\nfile = \"short.vol\"\n"),
    );
    let m = load_scene_file(&path).unwrap_err().to_string();
    assert!(
        m.contains("short.vol: byte 48:") && m.contains("needs 80 bytes"),
        "{m}"
    );
}

/// The keys of a family of described kinds as `docs/scene-format.md`
/// lists them: a row per key, from the renderer's table (`image`: what
/// the file's key for an image does to the textured key).
fn keys_table<K: sahara_render::Named + std::fmt::Display>(
    keys: fn(K) -> &'static [sahara_render::Key],
    image: &str,
) -> String {
    let mut out = String::from(
        "| `type` | key | takes | default | what it is |\n| --- | --- | --- | --- | --- |\n",
    );
    for &kind in K::ALL {
        for (i, k) in keys(kind).iter().enumerate() {
            let ty = if i == 0 {
                format!("`{kind}`")
            } else {
                String::new()
            };
            let default = match k.default_text().as_str() {
                "" => "none".to_string(),
                "required" => "required".to_string(),
                d => format!("`{d}`"),
            };
            let about = if k.textured {
                format!("{}; {image}", k.about)
            } else {
                k.about.to_string()
            };
            out += &format!(
                "| {ty} | `{}` | {} | {default} | {about} |\n",
                k.name,
                k.type_text()
            );
        }
    }
    out
}

/// The document's tables of material and light keys are the renderer's
/// (regenerate them from this test's message when a kind changes).
#[test]
fn the_documented_keys_are_the_described_kinds() {
    let doc = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/scene-format.md"),
    )
    .unwrap();
    for table in [
        keys_table(
            sahara_render::MaterialKind::keys,
            "times `texture`, an image file, if given",
        ),
        keys_table(
            sahara_render::LightKind::keys,
            "or instead `map`, a lat-long image file (`.hdr`, `.exr`, `.png`, `.jpg`)",
        ),
    ] {
        assert!(
            doc.contains(&table),
            "docs/scene-format.md should hold this table:\n{table}"
        );
    }
}

/// The repository's scene assets folder.
fn repo_assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/assets")
}

/// scenes/cloud.toml with its grid read from the .vdb twin of its .vol
/// file (scripts/make_vdb.py), or the NanoVDB twin of that, has the same
/// density everywhere in the world, within 1e-6, with the grid named or
/// not. (The renders differ by their noise alone: the majorant cells
/// span the .vdb's smaller active box.)
#[test]
fn vdb_grids_place_the_density_as_their_vol_twin() {
    let dir = TempDir::new("vdb");
    let assets = repo_assets();
    let text = std::fs::read_to_string(assets.join("../cloud.toml")).unwrap();
    // The file's own box for both (the .vdb's spans its active voxels).
    let text = text.replacen("min = [-1, 0.05, -1]\nmax = [1, 2.05, 1]\n", "", 1);
    let grid = |file: &str, extra: &str| {
        let t = text.replace(
            "file = \"assets/blob.vol\"",
            &format!(
                "file = {:?}{extra}",
                assets.join(file).display().to_string()
            ),
        );
        assert_ne!(t, text);
        let s = crate::load_scene(&dir.write(&format!("{file}.toml"), &t))
            .unwrap_or_else(|e| panic!("{e}"))
            .scene;
        let sahara_render::Medium::Grid(g) = &s.media[0] else {
            panic!("{:?}", s.media[0])
        };
        g.clone()
    };
    let vol = grid("blob.vol", "");
    let density = |g: &sahara_render::GridMedium, p: Vec3| {
        let sahara_render::GridCoefficients::Density { density, .. } = &g.coefficients else {
            panic!("{:?}", g.coefficients)
        };
        density.lookup(g.to_medium.transform_point3(p))
    };
    for (file, extra, tolerance) in [
        ("blob.vdb", "", 1e-6),
        ("blob.vdb", "\ngrid = \"density\"", 1e-6),
        ("blob.nvdb", "", 1e-6),
    ] {
        let vdb = grid(file, extra);
        let (mut worst, mut sum) = (0.0f32, 0.0f32);
        let mut f = 0.123f32;
        for _ in 0..50_000 {
            let mut r = || {
                f = (f * 9301.0 + 0.4929).fract();
                f
            };
            // The .vol file's box, [-1, 0, -1] to [1, 2, 1], and a margin.
            let p = Vec3::new(r() * 2.2 - 1.1, r() * 2.2 - 0.1, r() * 2.2 - 1.1);
            let want = density(&vol, p);
            worst = worst.max((density(&vdb, p) - want).abs());
            sum += want;
        }
        assert!(
            worst < tolerance,
            "{file}: the densities differ by up to {worst}"
        );
        assert!(sum > 1000.0, "{sum}");
    }
}

#[test]
fn vdb_grid_errors_name_the_file() {
    let assets = repo_assets();
    let dir = TempDir::new("vdb-errors");
    let grid = |file: &str, extra: &str| {
        let text = with_head(&format!(
            "[[medium]]\nname = \"c\"\ntype = \"grid\"\nfile = {:?}\n{extra}",
            assets.join(file).display().to_string()
        ));
        let path = dir.write("bad.toml", text);
        load_scene_file(&path).unwrap_err().to_string()
    };
    let e = grid("blob.vdb", "grid = \"smoke\"\n");
    assert!(
        e.contains("blob.vdb: no grid is named 'smoke'; the file holds 'density'"),
        "{e}"
    );
    let e = grid("blob.vol", "grid = \"density\"\n");
    assert!(
        e.contains("line 11") && e.contains("'grid' names a grid of a .vdb or .nvdb file"),
        "{e}"
    );
    let e = grid("blob_half.vdb", "");
    assert!(
        e.contains("blob_half.vdb: grid 'density' is saved as 16-bit"),
        "{e}"
    );
    let e = grid("vdb_huge.vdb", "");
    assert!(
        e.contains("vdb_huge.vdb: grid 'density': its active voxels span"),
        "{e}"
    );
}
