//! The shared scene set (see `shared/scenes/CATALOGUE.md`), when present.

use std::path::PathBuf;

use glam::Vec3;
use sahara_readers::camera::{read_sidecar, sidecar_path};
use sahara_readers::load_mesh;

use crate::common::{corners, scenes_dir, skip_note};

/// `<scenes>/<name>/<file>`, or `None` (with a note) if the scene set is absent.
fn scene(name: &str, file: &str) -> Option<PathBuf> {
    let path = scenes_dir().join(name).join(file);
    if path.exists() {
        Some(path)
    } else {
        skip_note(&format!(
            "the shared scene set's {name} ({} not found; set SAHARA_SCENES)",
            path.display()
        ));
        None
    }
}

#[test]
fn cornell_box_matches_the_catalogue() {
    let Some(path) = scene("cornell_box", "cornell_box.obj") else {
        return;
    };
    let mesh = load_mesh(&path).unwrap();
    assert_eq!(mesh.triangle_count(), 32);
    let bounds = mesh.clone().bounds();
    assert_eq!(bounds.min, Vec3::ZERO);
    assert_eq!(bounds.max, Vec3::new(556.0, 548.8, 559.2));
    // The first object is the floor: "f 1 2 3" over the first three vertices.
    assert_eq!(
        corners(&mesh)[0],
        [
            Vec3::new(552.8, 0.0, 0.0),
            Vec3::ZERO,
            Vec3::new(0.0, 0.0, 559.2)
        ]
    );
    let camera = read_sidecar(&sidecar_path(&path)).unwrap();
    assert_eq!(camera.eye, Vec3::new(278.0, 273.0, -800.0));
    assert_eq!(camera.vfov_deg, 39.308);
}

#[test]
fn bunny_obj_and_ply_are_the_same_triangles() {
    let (Some(obj), Some(ply)) = (scene("bunny", "bunny.obj"), scene("bunny", "bunny.ply")) else {
        return;
    };
    let from_obj = load_mesh(&obj).unwrap();
    let from_ply = load_mesh(&ply).unwrap();
    assert_eq!(from_obj.triangle_count(), 69451);
    assert_eq!(from_ply.triangle_count(), 69451);
    assert_eq!(from_ply.positions.len(), 34834);
    // Every vertex is used, so tobj's per-object compaction keeps them all.
    assert_eq!(from_obj.positions.len(), 34834);
    assert!(corners(&from_obj) == corners(&from_ply));
    let b = from_ply.bounds();
    assert!(
        (b.min - Vec3::new(-0.09469, 0.03299, -0.06187))
            .abs()
            .max_element()
            < 1e-5
    );
    assert!(
        (b.max - Vec3::new(0.06101, 0.1873, 0.0588))
            .abs()
            .max_element()
            < 1e-4
    );
}

#[test]
fn every_scene_sidecar_reads() {
    for name in ["bunny", "cornell_box", "dragon", "sponza", "teapot_stadium"] {
        let Some(path) = scene(name, &format!("{name}.camera.json")) else {
            continue;
        };
        read_sidecar(&path).unwrap();
    }
}

/// The large scenes, too slow for every run: `cargo test -- --ignored`.
#[test]
#[ignore]
fn large_scenes_match_the_catalogue() {
    for (name, file, triangles) in [
        ("dragon", "dragon.obj", 871_414),
        ("dragon", "dragon.ply", 871_414),
        ("sponza", "sponza.obj", 66_454),
        ("teapot_stadium", "teapot_stadium.obj", 18_650),
    ] {
        let Some(path) = scene(name, file) else {
            continue;
        };
        let start = std::time::Instant::now();
        let mesh = load_mesh(&path).unwrap();
        println!(
            "{file}: {} triangles in {:?}",
            mesh.triangle_count(),
            start.elapsed()
        );
        assert_eq!(mesh.triangle_count(), triangles, "{file}");
    }
    if let (Some(obj), Some(ply)) = (scene("dragon", "dragon.obj"), scene("dragon", "dragon.ply")) {
        let (obj, ply) = (load_mesh(&obj).unwrap(), load_mesh(&ply).unwrap());
        assert!(
            corners(&obj) == corners(&ply),
            "dragon.obj and dragon.ply differ"
        );
    }
}
