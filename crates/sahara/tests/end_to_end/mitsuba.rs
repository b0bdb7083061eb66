//! End-to-end tests of `sahara render` on Mitsuba scene files (`.xml`):
//! the file's film and samples, `-D` parameters, warnings, one-line
//! errors and crop windows.

use std::fs;
use std::path::Path;
use std::process::Output;

use sahara_formats::load_rgb_f32;

use crate::common::{sahara, temp_dir};

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The mean of an image's channels, checking its size.
fn checked_mean(path: &Path, width: u32, height: u32) -> f32 {
    let (w, h, rgb) = load_rgb_f32(path).unwrap();
    assert_eq!((w, h), (width, height), "{}", path.display());
    assert!(rgb.iter().all(|v| v.is_finite()), "{}", path.display());
    rgb.iter().sum::<f32>() / rgb.len() as f32
}

/// A sphere under a white sky, seen by a 16 x 12 camera; `FILM` is
/// replaced by the film's extra properties.
const SCENE: &str = r#"<scene version="3.0.0">
  <default name="spp" value="2"/>
  <default name="width" value="12"/>
  <sensor type="perspective">
    <float name="fov" value="45"/>
    <transform name="to_world"><lookat origin="0, 0, 3" target="0, 0, 0" up="0, 1, 0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    <film type="hdrfilm"><integer name="width" value="$width"/><integer name="height" value="6"/>FILM</film>
  </sensor>
  <emitter type="constant"><rgb name="radiance" value="1, 1, 1"/></emitter>
  <shape type="sphere"><bsdf type="dielectric"><rgb name="specular_reflectance" value="0.5"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="2" y="0" z="0"/><bsdf type="dielectric"><rgb name="specular_reflectance" value="0.5"/></bsdf></shape>
</scene>
"#;

#[test]
fn a_mitsuba_scene_renders_with_its_film_parameters_and_warnings_counted() {
    let dir = temp_dir("mitsuba");
    let scene = dir.join("s.xml");
    fs::write(&scene, SCENE.replace("FILM", "")).unwrap();
    let png = dir.join("s.png");
    let out = sahara(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("s.xml:11:24: bsdf 'dielectric': a tinted 'specular_reflectance' is not supported; clear (2 times; the first here)"),
        "{err}"
    );
    assert!(err.contains("2 spp"), "{err}");
    let mean = checked_mean(&png, 12, 6);
    assert!(mean > 0.1, "a lit sphere on a white sky: {mean}");
    // -D sets a parameter over the file's default.
    let out = sahara(&[
        "render",
        scene.to_str().unwrap(),
        "-D",
        "width=5",
        "-D",
        "spp=3",
        "-o",
        png.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("3 spp"), "{err}");
    checked_mean(&png, 5, 6);
    // -D is for Mitsuba scenes only, and is NAME=VALUE.
    let toml = dir.join("s.toml");
    fs::write(
        &toml,
        "[[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n",
    )
    .unwrap();
    let out = sahara(&["render", toml.to_str().unwrap(), "-D", "spp=3"]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("-D sets parameters of Mitsuba scenes (.xml), not of this file"),
        "{}",
        stderr(&out)
    );
    let out = sahara(&["render", scene.to_str().unwrap(), "-D", "spp"]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("'spp' is not NAME=VALUE"),
        "{}",
        stderr(&out)
    );
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_bad_mitsuba_file_is_one_line_naming_file_line_and_column() {
    let dir = temp_dir("mitsuba-bad");
    for (name, text, want) in [
        (
            "unclosed.xml",
            "<scene version=\"3.0.0\">\n  <shape type=\"sphere\">\n</scene>\n",
            "unclosed.xml: line 3: column 1: </scene> closes <shape>: <shape> is not closed",
        ),
        (
            "plugin.xml",
            "<scene version=\"3.0.0\">\n  <shape type=\"teapot\"/>\n</scene>\n",
            "plugin.xml: line 2: column 3: unknown shape type 'teapot'",
        ),
        (
            "ref.xml",
            "<scene version=\"3.0.0\">\n  <shape type=\"sphere\"><ref id=\"gold\"/></shape>\n</scene>\n",
            "ref.xml: line 2: column 24: <ref id=\"gold\">: no object has the id \"gold\"",
        ),
        (
            "param.xml",
            "<scene version=\"3.0.0\">\n  <shape type=\"sphere\"><float name=\"radius\" value=\"$r\"/></shape>\n</scene>\n",
            "param.xml: line 2: column 24: parameter '$r' has no value (give it a <default name=\"r\" value=\"...\"/> or -D r=...)",
        ),
    ] {
        let path = dir.join(name);
        fs::write(&path, text).unwrap();
        let out = sahara(&["render", path.to_str().unwrap()]);
        assert!(!out.status.success(), "{name}");
        let err = stderr(&out);
        assert!(err.contains(want), "{name}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{name}: {err}");
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_mitsuba_crop_window_renders_those_pixels_of_the_whole_frame() {
    let dir = temp_dir("mitsuba-crop");
    let render = |name: &str, film: &str| {
        let scene = dir.join(format!("{name}.xml"));
        fs::write(
            &scene,
            SCENE
                .replace("FILM", film)
                .replace("\"$width\"", "\"16\"")
                .replace("value=\"6\"", "value=\"12\""),
        )
        .unwrap();
        let exr = dir.join(format!("{name}.exr"));
        let out = sahara(&[
            "render",
            scene.to_str().unwrap(),
            "-o",
            exr.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        load_rgb_f32(&exr).unwrap()
    };
    let (w, h, whole) = render("whole", "");
    assert_eq!((w, h), (16, 12));
    let (cw, ch, part) = render(
        "crop",
        "<integer name=\"crop_offset_x\" value=\"5\"/><integer name=\"crop_offset_y\" value=\"3\"/>\
         <integer name=\"crop_width\" value=\"8\"/><integer name=\"crop_height\" value=\"5\"/>",
    );
    assert_eq!((cw, ch), (8, 5));
    for y in 0..5usize {
        for x in 0..8usize {
            let (i, j) = (3 * (y * 8 + x), 3 * ((y + 3) * 16 + x + 5));
            assert_eq!(part[i..i + 3], whole[j..j + 3], "pixel {x}, {y}");
        }
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn the_example_mitsuba_scenes_render_without_warnings() {
    let dir = temp_dir("mitsuba-example");
    for name in ["cornell_box.xml", "wax_bunny.xml"] {
        let scene = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../scenes")
            .join(name);
        let png = dir.join(name).with_extension("png");
        let out = sahara(&[
            "render",
            scene.to_str().unwrap(),
            "-D",
            "res=16",
            "-D",
            "spp=2",
            "-o",
            png.to_str().unwrap(),
        ]);
        let err = stderr(&out);
        assert!(out.status.success(), "{name}: {err}");
        assert!(!err.contains("warning"), "{name}: {err}");
        let mean = checked_mean(&png, 16, 16);
        assert!(mean > 0.05, "{name}: a lit box: {mean}");
    }
    let _ = fs::remove_dir_all(&dir);
}
