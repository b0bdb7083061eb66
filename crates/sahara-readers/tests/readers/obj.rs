//! OBJ: fan order across objects, relative indices, errors with lines.

use glam::Vec3;
use sahara_readers::obj::{load_obj, parse_obj};
use sahara_readers::{load_mesh, FormatError};

use crate::common::{corners, TempDir};

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

#[test]
fn quad_and_pentagon_are_fanned_from_the_first_corner_in_file_order() {
    let text = "\
# five points on a pentagon
v 0 0 0
v 1 0 0
v 2 1 0
v 1 2 0
v 0 1 0
o first
f 1 2 3 4
g second
usemtl something
f 1 2 3 4 5
o third
f 5 4 3
";
    let mesh = parse_obj(text.as_bytes(), "fan.obj").unwrap();
    let p = [
        v(0., 0., 0.),
        v(1., 0., 0.),
        v(2., 1., 0.),
        v(1., 2., 0.),
        v(0., 1., 0.),
    ];
    assert_eq!(
        corners(&mesh),
        vec![
            [p[0], p[1], p[2]],
            [p[0], p[2], p[3]],
            [p[0], p[1], p[2]],
            [p[0], p[2], p[3]],
            [p[0], p[3], p[4]],
            [p[4], p[3], p[2]],
        ]
    );
    assert_eq!(mesh.triangle_count(), 6);
}

#[test]
fn negative_indices_are_relative_to_the_vertices_so_far() {
    let text = "\
v 0 0 0
v 1 0 0
v 0 1 0
f -3 -2 -1
v 5 5 5
f -4/-1 -1 -2
vt 0.5 0.5
f 2/1 -1/1 3/-1
";
    let mesh = parse_obj(text.as_bytes(), "neg.obj").unwrap();
    let (a, b, c, d) = (v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.), v(5., 5., 5.));
    assert_eq!(corners(&mesh), vec![[a, b, c], [a, d, c], [b, d, c]]);
}

#[test]
fn texture_and_normal_indices_do_not_change_positions() {
    let text = "\
v 0 0 0
v 1 0 0
v 0 1 0
v 1 1 0
vt 0 0
vt 1 1
vn 0 0 1
f 1/1/1 2/2/1 4/2/1 3/1/1
f 1//1 4//1 3//1
";
    let mesh = parse_obj(text.as_bytes(), "vtn.obj").unwrap();
    let (a, b, c, d) = (v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.), v(1., 1., 0.));
    assert_eq!(corners(&mesh), vec![[a, b, d], [a, d, c], [a, d, c]]);
}

#[test]
fn points_and_polylines_give_no_triangles() {
    let text = "\
v 0 0 0
v 1 0 0
v 0 1 0
p 1
l 1 2 3
  l 3 2 1
f 1 2
f 1 2 3
";
    let mesh = parse_obj(text.as_bytes(), "lines.obj").unwrap();
    assert_eq!(mesh.indices.len(), 1);
    assert_eq!(
        corners(&mesh),
        vec![[v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.)]]
    );
}

#[test]
fn empty_obj_loads_as_empty() {
    let mesh = parse_obj(b"# nothing here\n", "empty.obj").unwrap();
    assert!(mesh.positions.is_empty() && mesh.indices.is_empty());
    let mesh = parse_obj(b"", "empty.obj").unwrap();
    assert!(mesh.indices.is_empty());
}

fn error_of(text: &str) -> String {
    let message = parse_obj(text.as_bytes(), "bad.obj")
        .expect_err("expected an error")
        .to_string();
    assert!(!message.contains('\n'), "{message:?}");
    message
}

#[test]
fn errors_name_the_file_and_line() {
    let cases: &[(&str, &[&str])] = &[
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n",
            &["bad.obj: line 5:", "'9'", "only 3"],
        ),
        (
            "v 0 0 0\nv 1 0 0\n\nf -3 1 2\n",
            &["bad.obj: line 4:", "-3", "only 2"],
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
            &["bad.obj: line 4:", "index 0"],
        ),
        (
            "v 0 0 0\nv 1 zero 0\n",
            &["bad.obj: line 2:", "'v 1 zero 0'"],
        ),
        ("v 0 0 0\nv 1 0 0 0\n", &["bad.obj: line 2:", "w = 0"]),
        ("v 0 0 0\nvn 1 0\n", &["bad.obj: line 2:", "normal"]),
        ("v 0 0 0\nf 1 1 x\n", &["bad.obj: line 2:", "'x'"]),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n",
            &["bad.obj: line 5:", "texture coordinate 2"],
        ),
        ("v 0 0 0\nusemtl\n", &["bad.obj: line 2:", "usemtl"]),
    ];
    for (text, needles) in cases {
        let message = error_of(text);
        for needle in needles.iter() {
            assert!(message.contains(needle), "{message:?} lacks {needle:?}");
        }
    }
}

#[test]
fn invalid_utf8_is_reported_with_its_line() {
    let mut bytes = b"v 0 0 0\n# caf".to_vec();
    bytes.push(0xe9);
    bytes.extend(b"\nv 1 0 0\n");
    let message = parse_obj(&bytes, "latin1.obj").unwrap_err().to_string();
    assert!(message.starts_with("latin1.obj: line 2:"), "{message}");
}

#[test]
fn files_are_read_and_dispatched_by_extension() {
    let dir = TempDir::new("obj");
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let lower = dir.write("tri.obj", text);
    let upper = dir.write("TRI.OBJ", text);
    let expected = load_obj(&lower).unwrap();
    assert_eq!(expected.indices.len(), 1);
    assert_eq!(load_mesh(&lower).unwrap(), expected);
    assert_eq!(load_mesh(&upper).unwrap(), expected);

    let stl = dir.write("tri.stl", "solid nothing");
    match load_mesh(&stl) {
        Err(e @ FormatError::UnsupportedExtension { .. }) => {
            let message = e.to_string();
            assert!(message.contains("tri.stl"), "{message}");
            assert!(message.contains(".obj, .ply, .gltf or .glb"), "{message}");
        }
        other => panic!("expected UnsupportedExtension, got {other:?}"),
    }
    match load_mesh(&dir.0.join("noextension")) {
        Err(e @ FormatError::UnsupportedExtension { .. }) => {
            assert!(e.to_string().contains("has no extension"), "{e}");
        }
        other => panic!("expected UnsupportedExtension, got {other:?}"),
    }

    let missing = dir.0.join("missing.obj");
    match load_mesh(&missing) {
        Err(e @ FormatError::Io { .. }) => {
            assert!(e.to_string().contains("missing.obj"), "{e}");
        }
        other => panic!("expected an I/O error, got {other:?}"),
    }
}

#[test]
fn ply_files_are_dispatched_case_insensitively() {
    let dir = TempDir::new("ply");
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                element face 1\nproperty list uchar int vertex_indices\nend_header\n\
                0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let path = dir.write("tri.Ply", text);
    let mesh = load_mesh(&path).unwrap();
    assert_eq!(
        corners(&mesh),
        vec![[v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.)]]
    );
    let obj = dir.write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    assert_eq!(corners(&load_mesh(&obj).unwrap()), corners(&mesh));
}
