//! Camera sidecars: parsing, defaults, errors, paths.

use std::path::{Path, PathBuf};

use glam::Vec3;
use sahara_readers::camera::{read_sidecar, sidecar_path, CameraSidecar};
use sahara_readers::FormatError;

use crate::common::TempDir;

#[test]
fn full_sidecar_parses() {
    let dir = TempDir::new("camera");
    let path = dir.write(
        "box.camera.json",
        r#"{"eye":[278,273,-800],"target":[278,273,0],"up":[0,2,0.5],"vfov_deg":39.308}"#,
    );
    assert_eq!(
        read_sidecar(&path).unwrap(),
        CameraSidecar {
            eye: Vec3::new(278.0, 273.0, -800.0),
            target: Vec3::new(278.0, 273.0, 0.0),
            up: Vec3::new(0.0, 2.0, 0.5),
            vfov_deg: 39.308,
        }
    );
}

#[test]
fn up_and_vfov_have_defaults() {
    let dir = TempDir::new("camera");
    let path = dir.write(
        "a.camera.json",
        "{\n  \"eye\": [1, 2, 3],\n  \"target\": [0, 0, 0]\n}\n",
    );
    let camera = read_sidecar(&path).unwrap();
    assert_eq!(camera.up, Vec3::new(0.0, 1.0, 0.0));
    assert_eq!(camera.vfov_deg, 45.0);
    assert_eq!(camera.eye, Vec3::new(1.0, 2.0, 3.0));
}

#[test]
fn round_trips_through_serde() {
    let camera = CameraSidecar {
        eye: Vec3::new(1.0, 2.0, 3.0),
        target: Vec3::new(0.5, 0.0, -1.0),
        up: Vec3::Y,
        vfov_deg: 60.0,
    };
    let json = serde_json::to_string(&camera).unwrap();
    assert_eq!(
        json,
        r#"{"eye":[1.0,2.0,3.0],"target":[0.5,0.0,-1.0],"up":[0.0,1.0,0.0],"vfov_deg":60.0}"#
    );
    assert_eq!(
        serde_json::from_str::<CameraSidecar>(&json).unwrap(),
        camera
    );
}

#[test]
fn bad_sidecars_name_the_file_and_line() {
    let dir = TempDir::new("camera");
    let cases: &[(&str, &[&str])] = &[
        (
            "{\n \"target\": [0,0,0]\n}",
            &["line 3:", "missing field `eye`"],
        ),
        (
            "{\"eye\": [0,0], \"target\": [0,0,1]}",
            &["line 1:", "column 13", "length 3"],
        ),
        (
            "{\"eye\": [0,0,0],\n\"target\": [0,0,1],\n\"vfov\": 30}",
            &["line 3:", "vfov"],
        ),
        ("{\"eye\": [0,0,0], \"target\": [0,0,1]", &["line 1:"]),
        (
            "{\"eye\": [0,0,0],\n\"target\": [0,0,1],\n\"vfov_deg\": 180}",
            &["line 3:", "vfov_deg is 180"],
        ),
        (
            "{\"eye\": [0,0,0],\n\"target\": [0,0,0]}",
            &["line 2:", "same point"],
        ),
        ("{\"eye\": [0,0,0],\n\"target\": [0,5,0]}", &["parallel"]),
    ];
    for (text, needles) in cases {
        let path = dir.write("bad.camera.json", text);
        let message = read_sidecar(&path).unwrap_err().to_string();
        assert!(message.contains("bad.camera.json"), "{message}");
        assert!(!message.contains('\n'), "{message:?}");
        for needle in needles.iter() {
            assert!(message.contains(needle), "{message:?} lacks {needle:?}");
        }
    }
    let missing = dir.0.join("missing.camera.json");
    match read_sidecar(&missing) {
        Err(e @ FormatError::Io { .. }) => assert!(e.to_string().contains("missing.camera.json")),
        other => panic!("expected an I/O error, got {other:?}"),
    }
}

#[test]
fn sidecar_sits_next_to_the_mesh() {
    assert_eq!(
        sidecar_path(Path::new("/scenes/bunny/bunny.obj")),
        PathBuf::from("/scenes/bunny/bunny.camera.json")
    );
    assert_eq!(
        sidecar_path(Path::new("dragon.PLY")),
        PathBuf::from("dragon.camera.json")
    );
    assert_eq!(
        sidecar_path(Path::new("a/scan.v2.ply")),
        PathBuf::from("a/scan.v2.camera.json")
    );
}
