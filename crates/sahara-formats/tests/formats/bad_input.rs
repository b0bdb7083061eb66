//! Bad input to the mesh readers: each kind has one defined outcome, asserted here.
//!
//! | input | outcome |
//! |---|---|
//! | a count (element, list length) larger than the rest of the file could hold | error naming the file and the line (ascii) or byte (binary) where the data should start, before anything is allocated for it |
//! | NaN or infinite coordinates (or finite ones beyond f32) | the mesh loads as written; the kd-tree never stores or hits those triangles (`Triangle::is_hittable` is false) |
//! | out-of-range, negative (PLY), zero (OBJ) or too-relative (OBJ) indices, indices beyond any integer type | error naming the file and the line or byte of the index |
//! | zero-area triangles (repeated index, collinear corners) | loads as written; never hit |
//! | empty meshes (no vertices, vertices without faces, faces with fewer than three corners) | loads with no triangles |
//! | glTF accessors out of their buffers, indices past the vertices | error naming the file and the accessor |
//!
//! Every error is one line starting with the file's name and the position:
//! `line N` (OBJ, ascii PLY, PLY header, scene TOML with its column, glTF JSON
//! syntax) or `byte N` (binary PLY); glTF content errors name the JSON object
//! (`mesh 0 primitive 0: accessor 1` ...), which is their position.
//!
//! A counting allocator records the largest single allocation of the test's
//! own thread, so "before allocating" is measured, not assumed.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use sahara_formats::decode_rgb_f32;
use sahara_formats::parse_scene;
use sahara_formats::FormatError;
use sahara_readers::gltf::load_gltf;
use sahara_readers::obj::parse_obj;
use sahara_readers::ply::parse_ply;

struct Counting;

thread_local! {
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

fn note(size: usize) {
    let _ = LARGEST.try_with(|l| l.set(l.get().max(size)));
}

// SAFETY: every call is passed on to the system allocator unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(new_size);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Runs `f`, returning its result and the largest single allocation it made (on this thread).
fn largest_allocation<T>(f: impl FnOnce() -> T) -> (T, usize) {
    LARGEST.with(|l| l.set(0));
    let out = f();
    (out, LARGEST.with(|l| l.get()))
}

#[test]
fn the_allocation_counter_sees_large_allocations() {
    let (v, largest) = largest_allocation(|| vec![1u8; 1 << 20]);
    assert_eq!(v.len(), 1 << 20);
    assert!(largest >= 1 << 20);
    let (bytes, _) = ply("ascii", &XYZ, ASCII_VERTICES);
    let (mesh, largest) = largest_allocation(|| parse_ply(&bytes, "ok.ply").unwrap());
    assert!(largest >= 3 * 12, "the positions were allocated: {mesh:?}");
}

/// Asserts `result` is an error, one line, starting with `prefix` (file and
/// position) and containing every needle; returns the message.
fn assert_error<T: std::fmt::Debug>(
    result: Result<T, FormatError>,
    prefix: &str,
    needles: &[&str],
) -> String {
    let message = result.expect_err("expected an error").to_string();
    assert!(
        message.starts_with(prefix),
        "{message:?} does not start with {prefix:?}"
    );
    assert!(!message.contains('\n'), "not one line: {message:?}");
    for needle in needles {
        assert!(message.contains(needle), "{message:?} lacks {needle:?}");
    }
    message
}

// ---------------------------------------------------------------- PLY files

/// A PLY file: header lines (without `ply`, `format` and `end_header`), then body bytes.
fn ply(format: &str, header: &[&str], body: &[u8]) -> (Vec<u8>, usize) {
    let mut text = format!("ply\nformat {format} 1.0\n");
    for line in header {
        text.push_str(line);
        text.push('\n');
    }
    text.push_str("end_header\n");
    let header_len = text.len();
    let mut bytes = text.into_bytes();
    bytes.extend_from_slice(body);
    (bytes, header_len)
}

const XYZ: [&str; 4] = [
    "element vertex 3",
    "property float x",
    "property float y",
    "property float z",
];

fn le_vertices() -> Vec<u8> {
    [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        .iter()
        .flat_map(|f| f.to_le_bytes())
        .collect()
}

const ASCII_VERTICES: &[u8] = b"0 0 0\n1 0 0\n0 1 0\n";

/// Parses `bytes`, which must fail fast, without any large allocation, with
/// the given prefix and needles.
fn huge_fails(bytes: &[u8], prefix: &str, needles: &[&str]) {
    assert!(bytes.len() < 1024, "the test file should be tiny");
    let start = Instant::now();
    let (result, largest) = largest_allocation(|| parse_ply(bytes, "huge.ply"));
    assert!(start.elapsed() < Duration::from_secs(1));
    let message = assert_error(result, prefix, needles);
    assert!(
        largest < 64 * 1024,
        "{message}: allocated {largest} bytes at once"
    );
}

#[test]
fn ply_huge_counts_anywhere_error_before_allocating() {
    let two40 = "1099511627776";
    // 2^40 vertices (the existing test covers this in every encoding; here
    // with allocation measured).
    let (bytes, h) = ply(
        "binary_little_endian",
        &[
            "element vertex 1099511627776",
            "property float x",
            "property float y",
            "property float z",
        ],
        &le_vertices(),
    );
    huge_fails(
        &bytes,
        &format!("huge.ply: byte {h}:"),
        &["element 'vertex'", "header line 3", two40],
    );

    // 2^40 faces after three good vertices.
    let mut header = XYZ.to_vec();
    header.extend([
        "element face 1099511627776",
        "property list uchar int vertex_indices",
    ]);
    let (bytes, h) = ply("binary_little_endian", &header, &le_vertices());
    huge_fails(
        &bytes,
        &format!("huge.ply: byte {}:", h + 36),
        &["element 'face'", "header line 7", two40],
    );
    let (bytes, h) = ply("binary_big_endian", &header, &[0; 36]);
    huge_fails(
        &bytes,
        &format!("huge.ply: byte {}:", h + 36),
        &["element 'face'", two40],
    );
    let (bytes, _) = ply("ascii", &header, ASCII_VERTICES);
    // Header is lines 1-9; vertices on 10-12; the face data would start on line 13.
    huge_fails(&bytes, "huge.ply: line 13:", &["element 'face'", two40]);

    // 2^40 records of an element Sahara does not read (skipped, but checked).
    let mut header = vec!["element normal 1099511627776", "property float nx"];
    header.extend(XYZ);
    let (bytes, h) = ply("binary_little_endian", &header, &le_vertices());
    huge_fails(
        &bytes,
        &format!("huge.ply: byte {h}:"),
        &["element 'normal'", "header line 3", two40],
    );

    // The largest u64 count: the size product must not overflow.
    let (bytes, h) = ply(
        "binary_little_endian",
        &[
            "element vertex 18446744073709551615",
            "property double x",
            "property double y",
            "property double z",
        ],
        &[],
    );
    huge_fails(
        &bytes,
        &format!("huge.ply: byte {h}:"),
        &["18446744073709551615"],
    );
    // Beyond u64: a header error.
    let (bytes, _) = ply(
        "ascii",
        &["element vertex 18446744073709551616", "property float x"],
        &[],
    );
    huge_fails(
        &bytes,
        "huge.ply: line 3:",
        &["18446744073709551616", "not a non-negative integer"],
    );
}

#[test]
fn ply_huge_list_lengths_error_before_allocating() {
    // A face claiming 2^32 - 1 indices (uint length) in binary and ascii.
    let mut header = XYZ.to_vec();
    header.extend(["element face 1", "property list uint int vertex_indices"]);
    let mut body = le_vertices();
    body.extend(u32::MAX.to_le_bytes());
    body.extend([0u8; 12]);
    let (bytes, h) = ply("binary_little_endian", &header, &body);
    huge_fails(
        &bytes,
        &format!("huge.ply: byte {}:", h + 36),
        &[
            "face 0: list 'vertex_indices' claims 4294967295 int values",
            "bytes are left",
        ],
    );
    let mut body = ASCII_VERTICES.to_vec();
    body.extend(b"4294967295 0 1 2\n");
    let (bytes, _) = ply("ascii", &header, &body);
    huge_fails(
        &bytes,
        "huge.ply: line 13:",
        &["claims 4294967295 int values"],
    );

    // A negative length (signed length type).
    let mut header = XYZ.to_vec();
    header.extend(["element face 1", "property list int int vertex_indices"]);
    let mut body = le_vertices();
    body.extend((-1i32).to_le_bytes());
    body.extend([0u8; 12]);
    let (bytes, h) = ply("binary_little_endian", &header, &body);
    huge_fails(
        &bytes,
        &format!("huge.ply: byte {}:", h + 36),
        &["face 0: list 'vertex_indices' has negative length -1"],
    );

    // A huge list inside the vertex element, and inside a skipped element.
    let header = [
        "element vertex 1",
        "property float x",
        "property float y",
        "property float z",
        "property list uint double weights",
    ];
    let mut body: Vec<u8> = [1.0f32, 2.0, 3.0]
        .iter()
        .flat_map(|f| f.to_le_bytes())
        .collect();
    body.extend(0x1000_0000u32.to_le_bytes());
    body.extend([0u8; 16]);
    let (bytes, h) = ply("binary_little_endian", &header, &body);
    huge_fails(
        &bytes,
        &format!("huge.ply: byte {}:", h + 12),
        &["vertex 0: list 'weights' claims 268435456 double values"],
    );
    let header = ["element edge 2", "property list ushort int path"];
    let (bytes, _) = ply("ascii", &header, b"2 0 1\n65535 1 2 3\n");
    huge_fails(
        &bytes,
        "huge.ply: line 7:",
        &["edge 1: list 'path' claims 65535 int values"],
    );
}

#[test]
fn ply_bad_indices_name_the_position() {
    let mut header = XYZ.to_vec();
    header.extend(["element face 1", "property list uchar uint vertex_indices"]);
    let face = |indices: [u32; 3]| {
        let mut body = le_vertices();
        body.push(3);
        body.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
        body
    };
    // The largest uint.
    let (bytes, h) = ply("binary_little_endian", &header, &face([0, 1, u32::MAX]));
    assert_error(
        parse_ply(&bytes, "idx.ply"),
        &format!("idx.ply: byte {}:", h + 36 + 1 + 8),
        &["face 0 has index 4294967295 but the file has 3 vertices"],
    );
    // Negative, as a signed char.
    let mut header = XYZ.to_vec();
    header.extend(["element face 1", "property list uchar char vertex_indices"]);
    let mut body = le_vertices();
    body.extend([3, 0, 0xfe, 1]);
    let (bytes, h) = ply("binary_little_endian", &header, &body);
    assert_error(
        parse_ply(&bytes, "idx.ply"),
        &format!("idx.ply: byte {}:", h + 36 + 2),
        &["face 0 has negative vertex index -2"],
    );
    // Ascii: beyond every integer type, beyond the type, not an integer.
    let mut header = XYZ.to_vec();
    header.extend(["element face 1", "property list uchar short vertex_indices"]);
    for (face, needle) in [
        (
            "3 0 1 99999999999999999999",
            "'99999999999999999999' is not a valid short value",
        ),
        ("3 0 1 -99999999999999999999", "is not a valid short value"),
        ("3 0 1 40000", "40000 is out of range for type short"),
        ("3 0 1 2.0", "'2.0' is not a valid short value"),
        ("3 0 1 -1", "face 0 has negative vertex index -1"),
        ("3 0 1 3", "face 0 has index 3 but the file has 3 vertices"),
    ] {
        let mut body = ASCII_VERTICES.to_vec();
        body.extend(face.as_bytes());
        let (bytes, _) = ply("ascii", &header, &body);
        assert_error(parse_ply(&bytes, "idx.ply"), "idx.ply: line 13:", &[needle]);
    }
}

#[test]
fn ply_non_finite_and_zero_area_triangles_load_and_are_never_hit() {
    let mut header = vec![
        "element vertex 5",
        "property double x",
        "property double y",
        "property double z",
    ];
    header.extend(["element face 4", "property list uchar int vertex_indices"]);
    // 1e300 is finite as a double but infinite as f32.
    let body = b"0 0 0\n1 0 0\n0 1 0\nnan 0 0\n1e300 0 0\n3 0 1 2\n3 0 1 3\n3 4 1 2\n3 0 0 1\n";
    let (bytes, _) = ply("ascii", &header, body);
    let mesh = parse_ply(&bytes, "odd.ply").unwrap();
    assert_eq!(
        mesh.indices,
        vec![[0, 1, 2], [0, 1, 3], [4, 1, 2], [0, 0, 1]]
    );
    assert!(mesh.positions[3].x.is_nan());
    assert_eq!(mesh.positions[4].x, f32::INFINITY);
    let hittable: Vec<bool> = mesh.triangles().iter().map(|t| t.is_hittable()).collect();
    assert_eq!(hittable, vec![true, false, false, false]);
}

#[test]
fn ply_empty_meshes_load_with_no_triangles() {
    // Vertices but no face element; faces of 0, 1, 2 corners; no elements at all.
    let (bytes, _) = ply("ascii", &XYZ, ASCII_VERTICES);
    let mesh = parse_ply(&bytes, "e.ply").unwrap();
    assert_eq!((mesh.positions.len(), mesh.indices.len()), (3, 0));
    let mut header = XYZ.to_vec();
    header.extend(["element face 3", "property list uchar int vertex_indices"]);
    let mut body = ASCII_VERTICES.to_vec();
    body.extend(b"0\n1 0\n2 0 1\n");
    let (bytes, _) = ply("ascii", &header, &body);
    assert!(parse_ply(&bytes, "e.ply").unwrap().indices.is_empty());
    let (bytes, _) = ply("binary_big_endian", &[], &[]);
    let mesh = parse_ply(&bytes, "e.ply").unwrap();
    assert!(mesh.positions.is_empty() && mesh.indices.is_empty());
}

// ---------------------------------------------------------------- OBJ files

#[test]
fn obj_bad_indices_name_the_line() {
    let three = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    for (face, needles) in [
        (
            "f 1 2 4",
            &["refers to vertex 4 but the file has only 3"][..],
        ),
        ("f 1 2 4294967297", &["refers to vertex 4294967297"]),
        (
            "f 1 2 99999999999999999999",
            &["bad face", "'99999999999999999999'"],
        ),
        ("f 1 2 -99999999999999999999", &["bad face"]),
        (
            "f 1 2 -4",
            &["relative index -4 but only 3 'v' lines come before it"],
        ),
        ("f 0 1 2", &["uses index 0; OBJ indices start at 1"]),
        ("f 1 2 3.5", &["bad face", "'3.5'"]),
    ] {
        let text = format!("{three}# a comment\n{face}\n");
        assert_error(
            parse_obj(text.as_bytes(), "idx.obj"),
            "idx.obj: line 5:",
            needles,
        );
    }
    // Texture indices are not read by `parse_obj` (positions only), so one
    // that points nowhere in a file without any `vt` is ignored.
    let text = format!("{three}f 1/9 2 3\n");
    assert_eq!(
        parse_obj(text.as_bytes(), "idx.obj").unwrap().indices,
        vec![[0, 1, 2]]
    );
    // A face before any vertex.
    assert_error(
        parse_obj(b"f 1 2 3\n", "idx.obj"),
        "idx.obj: line 1:",
        &["only 0"],
    );
}

#[test]
fn obj_non_finite_and_zero_area_triangles_load_and_are_never_hit() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 0 0\nv inf -inf 0\nv 1e39 0 0\nv 2 0 0\n\
                f 1 2 3\nf 1 2 4\nf 5 2 3\nf 6 2 3\nf 1 1 2\nf 1 2 7\n";
    let mesh = parse_obj(text.as_bytes(), "odd.obj").unwrap();
    assert_eq!(mesh.indices.len(), 6);
    let corners: Vec<_> = mesh
        .indices
        .iter()
        .map(|t| t.map(|i| mesh.positions[i as usize]))
        .collect();
    assert!(corners[1][2].x.is_nan());
    assert_eq!(corners[2][0].x, f32::INFINITY);
    assert_eq!(corners[2][0].y, f32::NEG_INFINITY);
    // 1e39 does not fit in f32: it reads as infinity.
    assert_eq!(corners[3][0].x, f32::INFINITY);
    let hittable: Vec<bool> = mesh.triangles().iter().map(|t| t.is_hittable()).collect();
    // Repeated corner and three collinear corners have zero area.
    assert_eq!(hittable, vec![true, false, false, false, false, false]);
}

#[test]
fn obj_empty_meshes_load_with_no_triangles() {
    for text in [
        "",
        "\n\n",
        "# only a comment",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\n",
        "v 0 0 0\nv 1 0 0\nf 1 2\np 1\nl 1 2\n",
        "o empty\ng nothing\ns 1\n",
    ] {
        let mesh = parse_obj(text.as_bytes(), "e.obj").unwrap();
        assert!(mesh.indices.is_empty(), "{text:?}");
    }
}

// ---------------------------------------------------------------- scene files

#[test]
fn scene_file_bad_numbers_name_line_and_column() {
    let head = "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n[film]\nwidth = 8\nheight = 4\n";
    for (rest, prefix, needle) in [
        ("[[object]]\ntype = \"sphere\"\ncenter = [nan, 0, 0]\nradius = 1\n", "line 9: column 10:", "must be finite"),
        ("[[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = inf\n", "line 10: column 10:", "must be greater than 0"),
        ("[[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = -1\n", "line 10: column 10:", "must be greater than 0"),
        ("[[object]]\ntype = \"quad\"\ncorner = [0, 0, 0]\nedge_u = [0, 0, 0]\nedge_v = [0, 0, 1]\n", "line 10: column 10:", "non-zero"),
        ("[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = [nan, 1, 1]\n", "line 10: column 13:", "must be finite"),
        ("[sampler]\nspp = -1\n", "line 8: column 7:", "at least 1"),
        ("[sampler]\nspp = 99999999999999999999999\n", "line 8:", ""),
    ] {
        let text = format!("{head}{rest}");
        assert_error(
            parse_scene(&text, "bad.toml", Path::new("/nonexistent")),
            &format!("bad.toml: {prefix}"),
            &[needle],
        );
    }
    let text = "[camera]\neye = [1, 2, 3]\ntarget = [1, 2, 3]\n[film]\nwidth = 8\nheight = 4\n";
    assert_error(
        parse_scene(text, "bad.toml", Path::new("/nonexistent")),
        "bad.toml: line 3: column 10:",
        &["eye and target are the same point"],
    );
    // An empty file has no position to name: the message says what is missing.
    assert_error(
        parse_scene("", "empty.toml", Path::new("/nonexistent")),
        "empty.toml: ",
        &["no [camera] table"],
    );
}

// ---------------------------------------------------------------- glTF files

/// A fresh folder for glTF files, removed on drop.
struct Folder(PathBuf);

impl Folder {
    fn new(tag: &str) -> Folder {
        let dir =
            std::env::temp_dir().join(format!("sahara-bad-input-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Folder(dir)
    }
}

impl Drop for Folder {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A GLB file of one mesh: `positions` (f32 xyz) and u32 `indices`, with the
/// accessors' counts given separately so they can lie.
fn glb(positions: &[f32], indices: &[u32], position_count: u64, index_count: u64) -> Vec<u8> {
    let mut bin: Vec<u8> = positions.iter().flat_map(|f| f.to_le_bytes()).collect();
    let index_at = bin.len();
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}},
"buffers": [{{"byteLength": {len}}}],
"bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": {index_at}}},
                {{"buffer": 0, "byteOffset": {index_at}, "byteLength": {ilen}}}],
"accessors": [{{"bufferView": 0, "componentType": 5126, "count": {position_count}, "type": "VEC3"}},
              {{"bufferView": 1, "componentType": 5125, "count": {index_count}, "type": "SCALAR"}}],
"meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}],
"nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}]}}"#,
        len = bin.len(),
        ilen = bin.len() - index_at,
    );
    let mut json = json.into_bytes();
    json.resize(json.len().div_ceil(4) * 4, b' ');
    bin.resize(bin.len().div_ceil(4) * 4, 0);
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

const TRIANGLE: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];

#[test]
fn gltf_bad_accessors_and_indices_name_the_file_and_object() {
    let dir = Folder::new("gltf");
    let load = |name: &str, bytes: Vec<u8>| {
        let path = dir.0.join(name);
        std::fs::write(&path, bytes).unwrap();
        let (result, largest) = largest_allocation(|| load_gltf(&path));
        (result, largest, path.display().to_string())
    };
    // The good file loads.
    let (result, _, _) = load("good.glb", glb(&TRIANGLE, &[0, 1, 2], 3, 3));
    assert_eq!(result.unwrap().meshes[0].mesh.indices, vec![[0, 1, 2]]);

    // An index past the vertices.
    let (result, _, path) = load("index.glb", glb(&TRIANGLE, &[0, 1, 7], 3, 3));
    assert_error(
        result,
        &format!("{path}: mesh 0 primitive 0:"),
        &["index 7 but only 3 vertices"],
    );
    // Accessors claiming 2^40 elements in a tiny buffer: an error, nothing large allocated.
    let (result, largest, path) = load("huge.glb", glb(&TRIANGLE, &[0, 1, 2], 1 << 40, 3));
    let m = assert_error(
        result,
        &format!("{path}: "),
        &[
            "mesh 0 primitive 0: accessor 0 (1099511627776 elements",
            "runs past the end of buffer view 0",
        ],
    );
    assert!(largest < 1 << 20, "{m}: allocated {largest} bytes at once");
    let (result, largest, path) = load("huge.glb", glb(&TRIANGLE, &[0, 1, 2], 3, 1 << 40));
    let m = assert_error(
        result,
        &format!("{path}: "),
        &["accessor 1 (1099511627776 elements"],
    );
    assert!(largest < 1 << 20, "{m}: allocated {largest} bytes at once");
    // NaN and infinite positions load; the triangle is never hit.
    let odd = [f32::NAN, 0.0, 0.0, 1.0, f32::INFINITY, 0.0, 0.0, 1.0, 0.0];
    let (result, _, _) = load("nan.glb", glb(&odd, &[0, 1, 2], 3, 3));
    let scene = result.unwrap();
    let triangles = scene.meshes[0].mesh.clone().triangles();
    assert_eq!(triangles.len(), 1);
    assert!(!triangles[0].is_hittable());
    // A zero-area triangle loads; never hit.
    let (result, _, _) = load("flat.glb", glb(&TRIANGLE, &[0, 1, 1], 3, 3));
    let mesh = result.unwrap().meshes.swap_remove(0).mesh;
    assert!(!mesh.triangles()[0].is_hittable());
    // Broken JSON: its line.
    let (result, _, path) = load(
        "broken.gltf",
        b"{\"asset\":\n{\"version\": 2.0,,}}".to_vec(),
    );
    assert_error(result, &format!("{path}: line 2:"), &["invalid glTF JSON"]);
}

// ---------------------------------------------------------------- fuzz regressions

/// Every input in `tests/fuzz_regressions/<target>/` (crashes the fuzz
/// targets of `fuzz/` found, kept as they were found) now gives a result or a
/// one-line error naming the file, as the fuzz targets assert.
#[test]
fn fuzz_crash_inputs_load_or_fail_cleanly() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_regressions");
    let dir = Folder::new("regressions");
    let mut seen = 0;
    for target in ["obj", "ply", "scene_file", "gltf", "image"] {
        let Ok(entries) = std::fs::read_dir(root.join(target)) else {
            continue;
        };
        for entry in entries {
            let path = entry.unwrap().path();
            let bytes = std::fs::read(&path).unwrap();
            let copy = dir.0.join("fuzz.in");
            let (error, name) = match target {
                "obj" => (parse_obj(&bytes, "fuzz.in").err(), "fuzz.in".to_owned()),
                "ply" => (parse_ply(&bytes, "fuzz.in").err(), "fuzz.in".to_owned()),
                "scene_file" => {
                    let text = String::from_utf8_lossy(&bytes);
                    let folder = Path::new("/nonexistent");
                    (
                        parse_scene(&text, "fuzz.in", folder).err(),
                        "fuzz.in".to_owned(),
                    )
                }
                "gltf" => {
                    std::fs::write(&copy, &bytes).unwrap();
                    (load_gltf(&copy).err(), copy.display().to_string())
                }
                _ => (
                    decode_rgb_f32(&bytes, "fuzz.in").err(),
                    "fuzz.in".to_owned(),
                ),
            };
            if let Some(e) = error {
                let m = e.to_string();
                assert!(
                    m.starts_with(&format!("{name}: ")) && !m.contains('\n'),
                    "{}: {m:?}",
                    path.display()
                );
            }
            seen += 1;
        }
    }
    assert!(
        seen >= 4,
        "regression inputs missing under {}",
        root.display()
    );
}

/// Fuzzing found (scene_file, crash-64711996...): a toml error quoting a
/// multi-line string value gave a message of several lines.
#[test]
fn scene_file_errors_quoting_line_breaks_stay_one_line() {
    let text = "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n[film]\nwidth = 8\nheight = 4\n\
                [integrator]\nname = \"\"\"path\nmax_depth = 3\n\"\"\"\n";
    let m = assert_error(
        parse_scene(text, "bad.toml", Path::new("/nonexistent")),
        "bad.toml: line 8: column 8:",
        &["unknown integrator", "path\\nmax_depth = 3\\n"],
    );
    assert!(!m.contains('\r'), "{m:?}");
    // Names of things are quoted the same way.
    let text = "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n[film]\nwidth = 8\nheight = 4\n\
                [[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"a\\nb\\r\\nc\"\n";
    assert_error(
        parse_scene(text, "bad.toml", Path::new("/nonexistent")),
        "bad.toml: line 11:",
        &[],
    );
}

/// Fuzzing found (image, crash-ae0a30e5...): the image crate ends some
/// messages with a newline, so a truncated JPEG's error was two lines.
#[test]
fn truncated_image_errors_are_one_line() {
    let jpeg = std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fuzz_regressions/image/crash-ae0a30e5c116cb274f4e63400738497f26c0042f"),
    )
    .unwrap();
    for len in [4, 20, 200, jpeg.len()] {
        assert_error(decode_rgb_f32(&jpeg[..len], "cut.jpg"), "cut.jpg: ", &[]);
    }
}

/// Fuzzing found (gltf, crash-f5cecd87...): the gltf crate unwraps an
/// image's `mimeType` when it has a `bufferView`, and its `uri` when it
/// has none; an image lacking them is an error naming the image.
#[test]
fn a_gltf_image_without_its_source_is_an_error() {
    let dir = Folder::new("gltf-image-source");
    for (image, says) in [
        (
            r#"{"bufferView": 0}"#,
            "images[0]: a bufferView without a mimeType",
        ),
        (
            r#"{"name": "x"}"#,
            "images[0]: neither a uri nor a bufferView",
        ),
        (
            r#"{"bufferView": 7, "mimeType": "image/png"}"#,
            "images[0]: buffer view 7 does not exist (1 buffer views)",
        ),
    ] {
        let text = format!(
            r#"{{"asset": {{"version": "2.0"}}, "buffers": [{{"byteLength": 4, "uri": "data:application/octet-stream;base64,AAAAAA=="}}],
               "bufferViews": [{{"buffer": 0, "byteLength": 4}}], "images": [{image}]}}"#
        );
        let path = dir.0.join("image.gltf");
        std::fs::write(&path, text).unwrap();
        let name = path.display().to_string();
        assert_error(load_gltf(&path), &format!("{name}: "), &[says]);
    }
}

/// Fuzzing found (gltf, crash-6349e2a3...): the gltf crate computes a GLB's
/// `length - 12` unchecked, so a header claiming fewer than 12 bytes
/// overflowed (a panic in debug builds).
#[test]
fn glb_header_shorter_than_itself_is_an_error_at_its_length() {
    let dir = Folder::new("glb-length");
    for length in [0u32, 2, 11] {
        let mut bytes = b"glTF".to_vec();
        bytes.extend(2u32.to_le_bytes());
        bytes.extend(length.to_le_bytes());
        bytes.extend(b"\x02\0\0\0JSON{}  ");
        let path = dir.0.join("short.glb");
        std::fs::write(&path, bytes).unwrap();
        assert_error(
            load_gltf(&path),
            &format!(
                "{}: byte 8: invalid GLB header: total length {length}",
                path.display()
            ),
            &[],
        );
    }
}

/// Fuzzing found (obj, crash-9091ee85...): tobj multiplies `vt`/`vn` indices
/// unchecked, so a relative index reaching more than one before the first
/// `vt`/`vn`, or a huge one, overflowed: a panic with overflow checks, and in
/// release builds an out-of-bounds panic or a silently wrong normal for
/// indices whose product wraps into range. They are now tobj's ordinary
/// out-of-bounds errors, with the line.
#[test]
fn obj_texture_and_normal_indices_that_overflowed_tobj_are_errors() {
    let head = "vn 0 0 1\nvt 0 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\n";
    // (2^64 + 2) / 3 + 1: as a 0-based index times 3, wraps to 2 in 64 bits.
    let wraps = "6148914691236517207";
    for (face, needles) in [
        ("f 1//-3 2//1 3//1", &["normal", "relative index -3"][..]),
        (&format!("f 1//{wraps} 2//1 3//1"), &["normal", wraps]),
        ("f 1//9223372036854775807 2//1 3//1", &["normal"]),
        ("f 1/-5/1 2/1/1 3/1/1", &["texture coordinate", "-5"]),
        (&format!("f 1/{wraps} 2/1 3/1"), &["texture coordinate"]),
        // Beyond isize: tobj's own parse error, as before.
        ("f 1//99999999999999999999 2//1 3//1", &["bad face"]),
    ] {
        let text = format!("{head}{face}\nf 1 2 3\n");
        assert_error(
            parse_obj(text.as_bytes(), "bad.obj"),
            "bad.obj: line 6:",
            needles,
        );
    }
    // tobj reads index 0, and a relative index landing just before the first
    // line, as "no index" (usize::MAX, never multiplied): loads, as before.
    for face in ["f 1//0 2//1 3//1", "f 1//-2 2//1 3//1", "f 1/0 2/1 3/1"] {
        let text = format!("{head}{face}\n");
        assert_eq!(
            parse_obj(text.as_bytes(), "ok.obj").unwrap().indices,
            vec![[0, 1, 2]]
        );
    }
    // A file without `vn` lines: tobj never looks normal indices up, so
    // positions-only loading goes on as before, whatever they are.
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//0 2//-7 3//99\n";
    assert_eq!(
        parse_obj(text.as_bytes(), "ok.obj").unwrap().indices,
        vec![[0, 1, 2]]
    );
    // Good relative indices still work, and earlier errors still come first.
    let text = format!("{head}f -3/-1/-1 -2/1/1 -1/1/1\n");
    assert_eq!(
        parse_obj(text.as_bytes(), "ok.obj").unwrap().indices,
        vec![[0, 1, 2]]
    );
    let text = format!("{head}v 1 zero 0\nf 1//0 2//1 3//1\n");
    assert_error(
        parse_obj(text.as_bytes(), "bad.obj"),
        "bad.obj: line 6:",
        &["bad vertex"],
    );
}

/// Fuzzing found (gltf, crash-32742ec2...): gltf-json's validation indexes
/// `accessors[POSITION]` without a bounds check, so a POSITION naming a
/// missing accessor panicked, in release builds too.
#[test]
fn gltf_position_naming_a_missing_accessor_is_an_error() {
    let dir = Folder::new("gltf-position");
    let json = r#"{"asset": {"version": "2.0"},
        "meshes": [{"primitives": [{"attributes": {"POSITION": 5}}]}],
        "accessors": [{"componentType": 5126, "count": 0, "type": "VEC3"}],
        "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]}"#;
    let path = dir.0.join("missing.gltf");
    std::fs::write(&path, json).unwrap();
    assert_error(
        load_gltf(&path),
        &format!(
            "{}: invalid glTF: meshes[0].primitives[0].attributes.POSITION:",
            path.display()
        ),
        &["accessor 5 does not exist (1 accessors)"],
    );
}
