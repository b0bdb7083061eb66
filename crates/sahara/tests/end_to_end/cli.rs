//! End-to-end tests of the `sahara` binary on small generated files.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;

use serde_json::Value;

use crate::common::{sahara, temp_dir};

fn stdout_json(out: &Output) -> Value {
    assert!(
        out.status.success(),
        "sahara failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "stdout is not one JSON object ({e}):\n{}",
            String::from_utf8_lossy(&out.stdout)
        )
    })
}

/// Half the side of the test quad.
const HALF: f64 = 2.5;
/// Distance from the eye to the quad.
const DIST: f64 = 10.0;

/// A square quad `[-2.5, 2.5]^2` at z = 0 facing +z (one OBJ polygon, fanned
/// into 2 triangles), with a sidecar camera at z = 10 looking down -z with a
/// 90 degree field of view.
fn write_quad_scene(dir: &Path) -> PathBuf {
    let obj = dir.join("quad.obj");
    fs::write(
        &obj,
        "# test quad\nv -2.5 -2.5 0\nv 2.5 -2.5 0\nv 2.5 2.5 0\nv -2.5 2.5 0\nf 1 2 3 4\n",
    )
    .unwrap();
    fs::write(
        dir.join("quad.camera.json"),
        r#"{"eye":[0,0,10],"target":[0,0,0],"up":[0,1,0],"vfov_deg":90}"#,
    )
    .unwrap();
    obj
}

/// Brute force, in f64, independent of the crate: the primary rays of the
/// 1024 x 1024 image that hit the quad, and the sum of their distances.
fn brute_force_primary() -> (u64, f64) {
    let n = 1024;
    let h = (45f64).to_radians().tan();
    let (mut hits, mut t_sum) = (0u64, 0.0f64);
    for y in 0..n {
        for x in 0..n {
            let a = (2.0 * (x as f64 + 0.5) / n as f64 - 1.0) * h;
            let b = (1.0 - 2.0 * (y as f64 + 0.5) / n as f64) * h;
            // Direction (a, b, -1) before normalising: it meets z = 0 at
            // (10 a, 10 b), at distance 10 |(a, b, -1)|.
            let (px, py) = (DIST * a, DIST * b);
            if px.abs() <= HALF && py.abs() <= HALF {
                hits += 1;
                t_sum += DIST * (a * a + b * b + 1.0).sqrt();
            }
        }
    }
    (hits, t_sum)
}

#[test]
fn bench_json_matches_a_brute_force_count() {
    let dir = temp_dir("bench");
    let obj = write_quad_scene(&dir);
    let out = sahara(&[
        "bench",
        obj.to_str().unwrap(),
        "--json",
        "--runs",
        "1",
        "--threads",
        "2",
        "--counters",
        "--accel",
        "kd",
    ]);
    let j = stdout_json(&out);
    for key in [
        "mesh",
        "triangles",
        "builder",
        "build_ms",
        "memory_bytes",
        "sah_cost",
        "threads",
        "sets",
    ] {
        assert!(j.get(key).is_some(), "missing {key} in {j}");
    }
    assert_eq!(j["triangles"], 2);
    assert_eq!(j["builder"], "kd-tree (sah)");
    assert_eq!(j["threads"], 2);
    assert_eq!(j["camera"]["vfov_deg"], 90.0);
    let sets = &j["sets"];
    for set in ["primary", "shadow", "diffuse", "random"] {
        for key in ["rays", "hits", "t_sum", "mrays_1t", "mrays_all"] {
            assert!(sets[set].get(key).is_some(), "missing sets.{set}.{key}");
        }
        assert!(sets[set]["counters"]["mean_triangles"].is_number());
    }

    let (hits, t_sum) = brute_force_primary();
    // Pixel centres lie 1/1024 of the half-width away from the quad's edges,
    // far more than f32 rounding: the counts must agree exactly.
    assert_eq!(hits, 256 * 256);
    let p = &sets["primary"];
    assert_eq!(p["rays"], 1024 * 1024);
    // The packet path ran (it fails the command if its hits differ).
    assert!(p["mrays_packet_1t"].as_f64().unwrap() > 0.0);
    assert!(p["mrays_packet_1t_cpu"].as_f64().unwrap() > 0.0);
    assert!(p["mrays_packet16_1t"].as_f64().unwrap() > 0.0);
    assert!(p["mrays_packet16_1t_cpu"].as_f64().unwrap() > 0.0);
    assert!(sets["random"].get("mrays_packet_1t").is_none());
    assert_eq!(p["hits"].as_u64().unwrap(), hits);
    let got = p["t_sum"].as_f64().unwrap();
    assert!(
        ((got - t_sum) / t_sum).abs() < 1e-6,
        "t_sum {got} vs brute force {t_sum}"
    );
    // One shadow and one diffuse ray per primary hit; they leave the quad's
    // front towards a light in front of it or into the open hemisphere.
    assert_eq!(sets["shadow"]["rays"].as_u64().unwrap(), hits);
    assert_eq!(sets["shadow"]["hits"], 0);
    assert_eq!(sets["shadow"]["t_sum"], 0.0);
    assert_eq!(sets["diffuse"]["rays"].as_u64().unwrap(), hits);
    assert_eq!(sets["diffuse"]["hits"], 0);
    assert_eq!(sets["random"]["rays"], 1_048_576);
    fs::remove_dir_all(dir).unwrap();
}

#[test]
fn dumped_rays_traced_again_give_the_same_hits() {
    let dir = temp_dir("dump");
    let obj = write_quad_scene(&dir);
    let (rays, hits, again) = (
        dir.join("p.rays"),
        dir.join("p.hits"),
        dir.join("again.hits"),
    );
    let out = sahara(&[
        "bench",
        obj.to_str().unwrap(),
        "--json",
        "--runs",
        "1",
        "--sets",
        "primary",
        "--dump-rays",
        "primary",
        rays.to_str().unwrap(),
        "--dump",
        "primary",
        hits.to_str().unwrap(),
    ]);
    let j = stdout_json(&out);
    assert!(j["sets"].get("shadow").is_none());
    assert_eq!(fs::metadata(&rays).unwrap().len(), 32 * 1024 * 1024);
    let h = fs::read(&hits).unwrap();
    assert_eq!(h.len(), 8 * 1024 * 1024);
    let n_hits = h
        .chunks_exact(8)
        .filter(|c| u32::from_le_bytes([c[4], c[5], c[6], c[7]]) != u32::MAX)
        .count() as u64;
    assert_eq!(n_hits, j["sets"]["primary"]["hits"].as_u64().unwrap());

    let out = sahara(&[
        "bench",
        obj.to_str().unwrap(),
        "--json",
        "--runs",
        "1",
        "--rays",
        rays.to_str().unwrap(),
        "--dump",
        "file",
        again.to_str().unwrap(),
    ]);
    let k = stdout_json(&out);
    assert_eq!(k["sets"]["file"]["hits"], j["sets"]["primary"]["hits"]);
    assert_eq!(k["sets"]["file"]["t_sum"], j["sets"]["primary"]["t_sum"]);
    assert!(k.get("camera").is_none());
    assert_eq!(fs::read(&again).unwrap(), h);
    fs::remove_dir_all(dir).unwrap();
}

#[test]
fn stats_json_has_the_tree_statistics() {
    let dir = temp_dir("stats");
    let obj = write_quad_scene(&dir);
    let out = sahara(&[
        "stats",
        obj.to_str().unwrap(),
        "--json",
        "--accel",
        "kd",
        "--builder",
        "binned",
    ]);
    let j = stdout_json(&out);
    assert_eq!(j["triangles"], 2);
    assert_eq!(j["builder"], "binned");
    for key in [
        "build_ms",
        "nodes",
        "leaves",
        "max_depth",
        "memory_bytes",
        "wide_node_bytes",
        "sah_cost",
        "expected_triangles",
    ] {
        assert!(j[key].is_number(), "missing {key} in {j}");
    }
    assert!(j["nodes"].as_u64().unwrap() >= 1);
    fs::remove_dir_all(dir).unwrap();
}

#[test]
fn human_output_has_a_header_and_a_table() {
    let dir = temp_dir("human");
    let obj = write_quad_scene(&dir);
    let bench = |extra: &[&str]| {
        let base = [
            "bench",
            obj.to_str().unwrap(),
            "--runs",
            "1",
            "--sets",
            "primary",
            "--accel",
            "kd",
        ];
        let out = sahara(&[&base[..], extra].concat());
        assert!(out.status.success());
        String::from_utf8(out.stdout).unwrap()
    };
    let text = bench(&[]);
    for needle in [
        "triangles  2",
        "builder    kd-tree (sah)",
        "SAH cost",
        "primary    1,048,576",
        "  batch    (one call of the set)",
        "t-sum: the sum of the hit distances",
        "1T CPU: the same by the thread's CPU time",
    ] {
        assert!(text.contains(needle), "no {needle:?} in:\n{text}");
    }
    // One thread: no second column of the same figure.
    let text = bench(&["--threads", "1"]);
    let header = text.lines().find(|l| l.starts_with("set ")).unwrap();
    assert_eq!(header.matches("Mrays/s").count(), 1, "{header}");
    assert!(
        text.lines().all(|l| l == l.trim_end()),
        "trailing blanks:\n{text}"
    );
    fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_missing_mesh_is_an_error_naming_the_file() {
    let dir = temp_dir("missing");
    let missing = dir.join("no_such_mesh.obj");
    for cmd in ["bench", "stats"] {
        let out = sahara(&[cmd, missing.to_str().unwrap()]);
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("no_such_mesh.obj"), "{cmd}: {err}");
        assert!(out.stdout.is_empty());
    }
    fs::remove_dir_all(dir).unwrap();
}

/// An image renamed as a mesh is said to be an image by every command
/// that loads meshes, in one line naming the file (not "invalid glTF JSON"
/// or "not valid UTF-8").
#[test]
fn bench_and_stats_say_a_renamed_image_is_an_image() {
    let dir = temp_dir("renamed");
    for name in ["model.glb", "model.obj", "model.ply"] {
        let fake = dir.join(name);
        fs::write(&fake, b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0\0\x01").unwrap();
        for cmd in ["bench", "stats"] {
            let out = sahara(&[cmd, fake.to_str().unwrap()]);
            assert_eq!(out.status.code(), Some(1));
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(err.trim_end().lines().count(), 1, "{cmd}: {err}");
            assert!(
                err.contains(name) && err.contains("is a PNG image, not a mesh"),
                "{cmd}: {err}"
            );
        }
    }
    fs::remove_dir_all(dir).unwrap();
}

#[test]
fn an_unknown_builder_is_a_clear_error() {
    let dir = temp_dir("builder");
    let obj = write_quad_scene(&dir);
    let out = sahara(&["bench", obj.to_str().unwrap(), "--builder", "octree"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("unknown builder 'octree'"), "{err}");
    assert!(err.contains("sah"), "the error lists the builders: {err}");
    fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_truncated_ray_file_is_a_clear_error() {
    let dir = temp_dir("rays");
    let obj = write_quad_scene(&dir);
    let bad = dir.join("bad.rays");
    fs::write(&bad, [0u8; 33]).unwrap();
    let out = sahara(&[
        "bench",
        obj.to_str().unwrap(),
        "--rays",
        bad.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.rays") && err.contains("33 bytes"),
        "{err}"
    );
    // --dump of a set that is not traced is refused before any work.
    let out = sahara(&[
        "bench",
        obj.to_str().unwrap(),
        "--sets",
        "primary",
        "--dump",
        "random",
        dir.join("r.hits").to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--dump random"));
    fs::remove_dir_all(dir).unwrap();
}

/// An OBJ of two triangles, one with a NaN corner.
fn write_nan_obj(dir: &Path) -> PathBuf {
    let obj = dir.join("nan.obj");
    fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 1 1\nv 1 1 1\nv 0 1 1\nf 1 2 3\nf 4 5 6\n",
    )
    .unwrap();
    obj
}

#[test]
fn every_command_warns_about_skipped_triangles() {
    let dir = temp_dir("nan-warn");
    let obj = write_nan_obj(&dir);
    let obj = obj.to_str().unwrap();
    let png = dir.join("nan.png");
    for args in [
        &[
            "bench",
            obj,
            "--runs",
            "1",
            "--threads",
            "1",
            "--sets",
            "primary",
        ][..],
        &["stats", obj],
        &["stats", obj, "--json"],
        &[
            "render",
            obj,
            "--width",
            "8",
            "--height",
            "8",
            "--spp",
            "1",
            "-o",
            png.to_str().unwrap(),
        ],
    ] {
        let out = sahara(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{args:?}: {err}");
        assert!(
            err.contains("nan.obj") && err.contains("1 of 2 triangles skipped"),
            "{args:?}: {err}"
        );
        assert!(err.contains("1 warning while loading"), "{args:?}: {err}");
    }
    // The count after skipping, and how many were skipped; the JSON on
    // stdout stays one object.
    let out = sahara(&["stats", obj]);
    assert!(
        String::from_utf8_lossy(&out.stdout)
            .contains("triangles   1 (1 of 2 skipped: no ray can hit them)\n"),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let out = sahara(&["stats", obj, "--json"]);
    assert_eq!(stdout_json(&out)["triangles"], 2);
    assert_eq!(stdout_json(&out)["skipped_triangles"], 1);
    // A scene file: the same warning as render, and the count after skipping.
    let scene = dir.join("nan.toml");
    fs::write(
        &scene,
        "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nvfov = 40\n\n\
         [film]\nwidth = 8\nheight = 8\n\n[[object]]\ntype = \"mesh\"\nfile = \"nan.obj\"\n",
    )
    .unwrap();
    let out = sahara(&["stats", scene.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("nan.toml: 1 of 2 triangles skipped (1 with a NaN or infinite corner)"),
        "{err}"
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("triangles  1 instanced (1 of 2 skipped: no ray can hit them)\n"),
        "{text}"
    );
    let out = sahara(&["stats", scene.to_str().unwrap(), "--json"]);
    assert_eq!(stdout_json(&out)["instanced_triangles"], 2);
    assert_eq!(stdout_json(&out)["skipped_triangles"], 1);
    fs::remove_dir_all(dir).unwrap();
}

/// A glTF file (external buffer) whose scene uses a one-triangle mesh from
/// two nodes, moved apart.
fn write_two_node_gltf(dir: &Path) -> PathBuf {
    let bin: Vec<u8> = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    fs::write(dir.join("tri.bin"), &bin).unwrap();
    let gltf = dir.join("two.gltf");
    fs::write(
        &gltf,
        r#"{
  "asset": {"version": "2.0"},
  "buffers": [{"uri": "tri.bin", "byteLength": 36}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "nodes": [{"mesh": 0}, {"mesh": 0, "translation": [3, 0, 0]}],
  "scenes": [{"nodes": [0, 1]}],
  "scene": 0
}"#,
    )
    .unwrap();
    gltf
}

#[test]
fn bench_and_stats_take_gltf_meshes() {
    let dir = temp_dir("gltf-cmds");
    let gltf = write_two_node_gltf(&dir);
    let gltf = gltf.to_str().unwrap();
    let j = stdout_json(&sahara(&["stats", gltf, "--json"]));
    assert_eq!(j["triangles"], 2, "both node uses are merged: {j}");
    let j = stdout_json(&sahara(&[
        "bench",
        gltf,
        "--json",
        "--runs",
        "1",
        "--threads",
        "1",
        "--sets",
        "primary",
    ]));
    assert_eq!(j["triangles"], 2, "{j}");
    // The auto camera frames both triangles: some primary rays hit.
    assert!(j["sets"]["primary"]["hits"].as_u64().unwrap() > 0, "{j}");
    fs::remove_dir_all(dir).unwrap();
}

#[test]
fn bench_help_points_at_the_repository_protocol() {
    let out = sahara(&["bench", "--help"]);
    let help = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(help.contains("docs/bench-protocol.md"), "{help}");
    assert!(!help.contains("shared/bench"), "{help}");
}

#[test]
fn stats_of_a_scene_file_says_how_many_trees_and_instances_it_built() {
    let dir = temp_dir("stats-scene");
    // Two unique static meshes (merged into the world tree), a mesh used
    // twice and an emissive sphere sampled analytically (both two-level).
    let obj = write_quad_scene(&dir);
    let scene = dir.join("scene.toml");
    fs::write(
        &scene,
        format!(
            r#"[camera]
eye = [0, 0, -5]
target = [0, 0, 0]

[film]
width = 8
height = 8

[[material]]
name = "lamp"
type = "emission"
radiance = [4, 4, 4]

[[object]]
type = "mesh"
file = "{obj}"

[[object]]
type = "box"
min = [-1, -1, 2]
max = [1, 1, 3]

[[object]]
type = "sphere"
center = [0, 3, 0]
radius = 0.5
material = "lamp"

[[object]]
type = "mesh"
file = "{obj}"
transform = {{ translate = [0, 0, 1] }}
"#,
            obj = obj.display()
        ),
    )
    .unwrap();
    let scene = scene.to_str().unwrap();
    let j = stdout_json(&sahara(&["stats", scene, "--json"]));
    assert_eq!(j["instances"], 4, "{j}");
    assert_eq!(j["merged_instances"], 1, "{j}");
    assert_eq!(j["two_level_instances"], 3, "{j}");
    // The world tree, the shared mesh's tree and the sphere's.
    assert_eq!(j["trees"], 3, "{j}");
    assert_eq!(j["world_triangles"], 12, "{j}");
    let out = sahara(&["stats", scene]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("instances  4: 1 merged into the world tree, 3 two-level"),
        "{text}"
    );
    fs::remove_dir_all(dir).unwrap();
}
