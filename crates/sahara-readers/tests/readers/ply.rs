//! PLY: encodings, scalar types, skipping, fan order, hostile headers and bodies.

use std::time::{Duration, Instant};

use glam::Vec3;
use sahara_readers::ply::parse_ply;
use sahara_readers::FormatError;

/// Body encoding of a test file.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Enc {
    Ascii,
    Le,
    Be,
}

/// Builds a PLY file value by value, independently of the parser.
struct Ply {
    enc: Enc,
    header: String,
    body: Vec<u8>,
}

impl Ply {
    fn new(enc: Enc) -> Ply {
        let format = match enc {
            Enc::Ascii => "ascii",
            Enc::Le => "binary_little_endian",
            Enc::Be => "binary_big_endian",
        };
        Ply {
            enc,
            header: format!("ply\nformat {format} 1.0\n"),
            body: Vec::new(),
        }
    }

    fn line(&mut self, line: &str) -> &mut Self {
        self.header.push_str(line);
        self.header.push('\n');
        self
    }

    /// Appends one value of PLY type `ty`.
    fn val(&mut self, ty: &str, v: f64) -> &mut Self {
        macro_rules! put {
            ($t:ty) => {{
                let x = v as $t;
                match self.enc {
                    Enc::Ascii => self.body.extend(format!("{x} ").bytes()),
                    Enc::Le => self.body.extend(x.to_le_bytes()),
                    Enc::Be => self.body.extend(x.to_be_bytes()),
                }
            }};
        }
        match ty {
            "char" | "int8" => put!(i8),
            "uchar" | "uint8" => put!(u8),
            "short" | "int16" => put!(i16),
            "ushort" | "uint16" => put!(u16),
            "int" | "int32" => put!(i32),
            "uint" | "uint32" => put!(u32),
            "float" | "float32" => put!(f32),
            "double" | "float64" => put!(f64),
            _ => panic!("test bug: unknown type {ty}"),
        }
        self
    }

    fn end_record(&mut self) -> &mut Self {
        if self.enc == Enc::Ascii {
            self.body.push(b'\n');
        }
        self
    }

    fn header_len(&self) -> usize {
        self.header.len() + "end_header\n".len()
    }

    fn bytes(&self) -> Vec<u8> {
        let mut out = self.header.clone().into_bytes();
        out.extend(b"end_header\n");
        out.extend(&self.body);
        out
    }
}

const POSITIONS: [[f64; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.1],
    [0.0, 1.0, -2.5],
    [-0.5, 0.5, 1e-3],
];
const FACES: [&[u32]; 3] = [&[4, 0, 1], &[0, 1, 2, 3], &[0, 1, 2, 3, 4]];
/// FACES fan-triangulated as (v0, vi, vi+1), written out by hand.
const TRIANGLES: [[u32; 3]; 6] = [
    [4, 0, 1],
    [0, 1, 2],
    [0, 2, 3],
    [0, 1, 2],
    [0, 2, 3],
    [0, 3, 4],
];

fn expected_positions() -> Vec<Vec3> {
    POSITIONS
        .iter()
        .map(|p| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32))
        .collect()
}

/// The test mesh with extra elements and properties around the ones that matter.
fn sample(enc: Enc, coord: &str, count_ty: &str, index_ty: &str) -> Ply {
    let mut p = Ply::new(enc);
    p.line("comment made by the sahara-formats tests")
        .line("obj_info extra header line")
        .line("element material 2")
        .line("property uchar red")
        .line("property list uchar float weights")
        .line("element vertex 5")
        .line("property uchar confidence")
        .line(&format!("property {coord} x"))
        .line(&format!("property {coord} y"))
        .line("property list ushort int neighbours")
        .line(&format!("property {coord} z"))
        .line("property float nx")
        .line("element face 3")
        .line("property list uchar float texcoord")
        .line(&format!(
            "property list {count_ty} {index_ty} vertex_indices"
        ))
        .line("property ushort flags")
        .line("element edge 1")
        .line("property int vertex1")
        .line("property list int int path");
    // material: 2 records, the second with a 3-entry list.
    p.val("uchar", 200.0).val("uchar", 0.0).end_record();
    p.val("uchar", 7.0).val("uchar", 3.0);
    p.val("float", 0.5).val("float", 0.25).val("float", 0.125);
    p.end_record();
    for (i, v) in POSITIONS.iter().enumerate() {
        p.val("uchar", 255.0 - i as f64);
        p.val(coord, v[0]).val(coord, v[1]);
        p.val("ushort", i as f64);
        for n in 0..i {
            p.val("int", n as f64 * 1000.0);
        }
        p.val(coord, v[2]).val("float", 9.0).end_record();
    }
    for (i, face) in FACES.iter().enumerate() {
        p.val("uchar", 2.0).val("float", 0.5).val("float", 0.5);
        p.val(count_ty, face.len() as f64);
        for &index in face.iter() {
            p.val(index_ty, index.into());
        }
        p.val("ushort", 60000.0 + i as f64).end_record();
    }
    p.val("int", 1.0)
        .val("int", 2.0)
        .val("int", 3.0)
        .val("int", 4.0);
    p.end_record();
    p
}

#[test]
fn every_encoding_and_scalar_type_gives_the_same_mesh() {
    let encodings = [Enc::Ascii, Enc::Le, Enc::Be];
    let coords = ["float", "double", "float32", "float64"];
    let counts = ["uchar", "ushort", "int", "uint", "uint8", "char"];
    let indices = ["int", "uint", "ushort", "uchar", "int32", "short"];
    for enc in encodings {
        for coord in coords {
            for count_ty in counts {
                for index_ty in indices {
                    let bytes = sample(enc, coord, count_ty, index_ty).bytes();
                    let what = format!("{enc:?} {coord} list {count_ty} {index_ty}");
                    let mesh = parse_ply(&bytes, &what).unwrap_or_else(|e| panic!("{what}: {e}"));
                    assert_eq!(mesh.positions, expected_positions(), "{what}");
                    assert_eq!(mesh.indices, TRIANGLES, "{what}");
                }
            }
        }
    }
}

#[test]
fn ascii_with_comments_and_reordered_axes() {
    let text = "ply\r\n\
        format ascii 1.0\r\n\
        comment axes are listed z, x, y\r\n\
        element vertex 4\r\n\
        property double z\r\n\
        property double x\r\n\
        property double y\r\n\
        element face 1\r\n\
        property list uchar uint vertex_indices\r\n\
        end_header\r\n\
        3 1 2\r\n\
        6 4 5\r\n\
        9 7 8\r\n\
        -1.5e2 0.1 .5\r\n\
        4 3 2 1 0\r\n";
    let mesh = parse_ply(text.as_bytes(), "axes.ply").unwrap();
    assert_eq!(
        mesh.positions,
        vec![
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(4.0, 5.0, 6.0),
            Vec3::new(7.0, 8.0, 9.0),
            Vec3::new(0.1, 0.5, -150.0),
        ]
    );
    assert_eq!(mesh.indices, vec![[3, 2, 1], [3, 1, 0]]);
}

#[test]
fn vertex_index_alias_and_first_list_fallback() {
    for list_name in ["vertex_index", "corners"] {
        let text = format!(
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
             element face 1\nproperty int material\nproperty list uchar int {list_name}\nend_header\n\
             0 0 0\n1 0 0\n0 1 0\n5 3 2 1 0\n"
        );
        let mesh = parse_ply(text.as_bytes(), "alias.ply").unwrap();
        assert_eq!(mesh.indices, vec![[2, 1, 0]], "{list_name}");
    }
    // vertex_indices wins over an earlier list.
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                element face 1\nproperty list uchar int other\nproperty list uchar int vertex_indices\nend_header\n\
                0 0 0\n1 0 0\n0 1 0\n3 0 0 0 3 0 2 1\n";
    let mesh = parse_ply(text.as_bytes(), "alias.ply").unwrap();
    assert_eq!(mesh.indices, vec![[0, 2, 1]]);
}

/// Asserts `result` failed quickly with a message containing every `needle`.
fn assert_fails(result: Result<impl std::fmt::Debug, FormatError>, needles: &[&str]) -> String {
    let message = result.expect_err("expected an error").to_string();
    for needle in needles {
        assert!(
            message.contains(needle),
            "message {message:?} lacks {needle:?}"
        );
    }
    assert!(
        !message.contains('\n'),
        "message is not one line: {message:?}"
    );
    message
}

#[test]
fn two_pow_40_vertices_in_a_tiny_file_errors_before_allocating() {
    for enc in [Enc::Ascii, Enc::Le, Enc::Be] {
        let mut p = Ply::new(enc);
        p.line("element vertex 1099511627776")
            .line("property float x")
            .line("property float y")
            .line("property float z")
            .line("element face 1099511627776")
            .line("property list uchar int vertex_indices");
        p.val("float", 1.0)
            .val("float", 2.0)
            .val("float", 3.0)
            .end_record();
        let bytes = p.bytes();
        assert!(bytes.len() < 1024);
        // Binary: the byte where vertex data starts; ascii: the first body line.
        let position = match enc {
            Enc::Ascii => "huge.ply: line 10:".to_owned(),
            _ => format!("huge.ply: byte {}:", p.header_len()),
        };
        let start = Instant::now();
        let message = assert_fails(
            parse_ply(&bytes, "huge.ply"),
            &[
                &position,
                "element 'vertex'",
                "header line 3",
                "1099511627776",
            ],
        );
        assert!(start.elapsed() < Duration::from_secs(1), "{message}");
    }
}

#[test]
fn counts_below_u32_but_beyond_the_file_size_error() {
    let mut p = Ply::new(Enc::Le);
    p.line("element vertex 2")
        .line("property float x")
        .line("property float y")
        .line("property float z")
        .line("element face 1000000000")
        .line("property list uchar int vertex_indices");
    for _ in 0..6 {
        p.val("float", 0.0);
    }
    p.val("uchar", 3.0);
    for i in [0.0, 1.0, 1.0] {
        p.val("int", i);
    }
    let position = format!("faces.ply: byte {}:", p.header_len() + 24);
    assert_fails(
        parse_ply(&p.bytes(), "faces.ply"),
        &[&position, "element 'face'", "1000000000", "truncated"],
    );
}

#[test]
fn element_without_properties_and_a_huge_count_is_skipped_quickly() {
    let mut p = Ply::new(Enc::Le);
    p.line("element nothing 1099511627776")
        .line("element vertex 1")
        .line("property double x")
        .line("property double y")
        .line("property double z");
    p.val("double", 1.0).val("double", 2.0).val("double", 3.0);
    let start = Instant::now();
    let mesh = parse_ply(&p.bytes(), "nothing.ply").unwrap();
    assert!(start.elapsed() < Duration::from_secs(1));
    assert_eq!(mesh.positions, vec![Vec3::new(1.0, 2.0, 3.0)]);
    assert!(mesh.indices.is_empty());
}

fn triangle_ply(enc: Enc, index: f64, index_ty: &str) -> Ply {
    let mut p = Ply::new(enc);
    p.line("element vertex 3")
        .line("property float x")
        .line("property float y")
        .line("property float z")
        .line("element face 2")
        .line(&format!("property list uchar {index_ty} vertex_indices"));
    for v in 0..9 {
        p.val("float", v as f64);
        if v % 3 == 2 {
            p.end_record();
        }
    }
    p.val("uchar", 3.0);
    for i in [0.0, 1.0, 2.0] {
        p.val(index_ty, i);
    }
    p.end_record();
    p.val("uchar", 3.0);
    for i in [0.0, index, 2.0] {
        p.val(index_ty, i);
    }
    p.end_record();
    p
}

#[test]
fn truncated_fixed_size_element_is_reported_where_its_data_starts() {
    let p = triangle_ply(Enc::Le, 1.0, "int");
    let h = p.header_len();
    // Three 12-byte vertices need 36 bytes; only 30 are left.
    let bytes = &p.bytes()[..h + 30];
    match parse_ply(bytes, "cut.ply") {
        Err(FormatError::AtByte {
            offset, message, ..
        }) => {
            assert_eq!(offset, h as u64, "{message}");
            assert!(message.contains("element 'vertex'"), "{message}");
            assert!(
                message.contains("3 records of at least 12 bytes"),
                "{message}"
            );
            assert!(message.contains("only 30 bytes"), "{message}");
        }
        other => panic!("expected a byte-offset error, got {other:?}"),
    }
}

#[test]
fn truncated_binary_records_report_the_byte_where_data_runs_out() {
    for enc in [Enc::Le, Enc::Be] {
        let full = sample(enc, "double", "uchar", "int").bytes();
        let n = full.len();
        // The file ends with face 2's ushort flags (2 bytes), then the edge
        // record: int vertex1, int list length 2, two ints (16 bytes).
        match parse_ply(&full[..n - 17], "cut.ply") {
            Err(FormatError::AtByte {
                offset, message, ..
            }) => {
                assert_eq!(offset, (n - 18) as u64, "{message}");
                assert!(message.contains("face 2, property 'flags'"), "{message}");
                assert!(message.contains("ushort"), "{message}");
            }
            other => panic!("expected a byte-offset error, got {other:?}"),
        }
        match parse_ply(&full[..n - 1], "cut.ply") {
            Err(FormatError::AtByte {
                offset, message, ..
            }) => {
                assert_eq!(offset, (n - 12) as u64, "{message}");
                assert!(
                    message.contains("edge 0: list 'path' claims 2 int values"),
                    "{message}"
                );
            }
            other => panic!("expected a byte-offset error, got {other:?}"),
        }
    }
}

#[test]
fn truncated_face_list_reports_the_byte_offset() {
    let p = triangle_ply(Enc::Be, 1.0, "int");
    let h = p.header_len();
    // Face 1 starts at h + 36 + 13 = h + 49: a count of 3, then 12 index bytes.
    let full = p.bytes();
    assert_eq!(full.len(), h + 36 + 13 + 13);
    let bytes = &full[..h + 49 + 5];
    match parse_ply(bytes, "cut.ply") {
        Err(FormatError::AtByte {
            offset, message, ..
        }) => {
            assert_eq!(offset, (h + 49) as u64, "{message}");
            assert!(message.contains("face 1"), "{message}");
            assert!(message.contains("claims 3"), "{message}");
        }
        other => panic!("expected a byte-offset error, got {other:?}"),
    }
}

#[test]
fn out_of_range_index_reports_offset_or_line() {
    let p = triangle_ply(Enc::Le, 7.0, "uint");
    let h = p.header_len();
    match parse_ply(&p.bytes(), "range.ply") {
        Err(e @ FormatError::AtByte { .. }) => {
            let FormatError::AtByte { offset, .. } = &e else {
                unreachable!()
            };
            // Face 1 at h + 49: count (1 byte), index 0 (4 bytes), then the 7.
            assert_eq!(*offset, (h + 54) as u64);
            assert_eq!(
                e.to_string(),
                format!(
                    "range.ply: byte {}: face 1 has index 7 but the file has 3 vertices",
                    h + 54
                )
            );
        }
        other => panic!("expected a byte-offset error, got {other:?}"),
    }
    let p = triangle_ply(Enc::Ascii, 3.0, "int");
    // Header: 9 lines with end_header; vertices on lines 10-12; faces 13-14.
    assert_fails(
        parse_ply(&p.bytes(), "range.ply"),
        &["range.ply: line 14: face 1 has index 3 but the file has 3 vertices"],
    );
}

#[test]
fn negative_index_errors() {
    for enc in [Enc::Ascii, Enc::Le, Enc::Be] {
        let p = triangle_ply(enc, -1.0, "int");
        assert_fails(
            parse_ply(&p.bytes(), "neg.ply"),
            &["neg.ply:", "face 1 has negative vertex index -1"],
        );
    }
}

#[test]
fn bad_headers_name_the_line() {
    let vertex = "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n";
    let cases: &[(String, &[&str])] = &[
        ("PLY\nformat ascii 1.0\nend_header\n".into(), &["line 1:", "not a PLY file"]),
        (String::new(), &["line 1:", "empty"]),
        ("ply\nformat binary_middle_endian 1.0\nend_header\n".into(), &["line 2:", "binary_middle_endian"]),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n".into(), &["line 4:", "end_header"]),
        ("ply\nformat ascii 1.0\nproperty float x\nend_header\n".into(), &["line 3:", "before any 'element'"]),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\nend_header\n".into(), &["line 4:", "half"]),
        ("ply\nformat ascii 1.0\nelement vertex -1\nend_header\n".into(), &["line 3:", "-1"]),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n".into(), &["line 3:", "no property 'z'"]),
        (format!("ply\nformat ascii 1.0\n{vertex}element face 0\nproperty list float int vertex_indices\nend_header\n"), &["line 8:", "length type float"]),
        (format!("ply\nformat ascii 1.0\n{vertex}element face 0\nproperty list uchar float vertex_indices\nend_header\n"), &["line 7:", "must be integers"]),
        (format!("ply\nformat ascii 1.0\n{vertex}element face 0\nproperty int vertex_indices\nend_header\n"), &["line 7:", "no list property"]),
        (format!("ply\n{vertex}end_header\n"), &["line 6:", "no 'format' line"]),
        (format!("ply\nformat ascii 1.0\n{vertex}banana\nend_header\n"), &["line 7:", "banana"]),
    ];
    for (text, needles) in cases {
        let message = assert_fails(parse_ply(text.as_bytes(), "bad.ply"), needles);
        assert!(message.starts_with("bad.ply: line "), "{message}");
    }
}

#[test]
fn non_numeric_ascii_tokens_report_the_line() {
    let text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n\
                element face 1\nproperty list uchar int vertex_indices\nend_header\n\
                0 0 0\n\n1 zero 0\n3 0 1 1\n";
    assert_fails(
        parse_ply(text.as_bytes(), "word.ply"),
        &[
            "word.ply: line 12:",
            "vertex 1",
            "'zero' is not a valid float",
        ],
    );
    let text = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n\
                element face 1\nproperty list uchar int vertex_indices\nend_header\n\
                0 0 0\n3 0 0.5 0\n";
    assert_fails(
        parse_ply(text.as_bytes(), "word.ply"),
        &["word.ply: line 11:", "'0.5' is not a valid int"],
    );
    let text = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n\
                element face 1\nproperty list uchar int vertex_indices\nend_header\n\
                0 0 0\n300 0 0 0\n";
    assert_fails(
        parse_ply(text.as_bytes(), "word.ply"),
        &["line 11:", "300", "uchar"],
    );
}

#[test]
fn an_ascii_line_with_too_few_or_too_many_values_is_an_error_at_that_line() {
    let head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    // Line 11 holds two values: without the line check the next line's
    // first value would be taken as its z.
    let short = format!("{head}0 0 0\n1 0\n0 1 0\n3 0 1 2\n");
    assert_fails(
        parse_ply(short.as_bytes(), "short.ply"),
        &["short.ply: line 11:", "expected 3 values, found 2"],
    );
    let long = format!("{head}0 0 0\n1 0 0 7\n0 1 0\n3 0 1 2\n");
    assert_fails(
        parse_ply(long.as_bytes(), "long.ply"),
        &["long.ply: line 11:", "expected 3 values, found more"],
    );
    // A face line shorter than its list length says.
    let face = format!("{head}0 0 0\n1 0 0\n0 1 0\n3 0 1\n");
    assert_fails(
        parse_ply(face.as_bytes(), "face.ply"),
        &["face.ply: line 13:", "expected 4 values, found 3"],
    );
    // Blank lines between records and trailing spaces are fine.
    let ok = format!("{head}0 0 0  \n\n1 0 0\r\n0 1 0\n3 0 1 2");
    assert_eq!(parse_ply(ok.as_bytes(), "ok.ply").unwrap().indices.len(), 1);
}

#[test]
fn nan_and_inf_coordinates_load() {
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                element face 1\nproperty list uchar int vertex_indices\nend_header\n\
                nan 0 0\ninf -inf 0\n0 1 0\n3 0 1 2\n";
    let mesh = parse_ply(text.as_bytes(), "nan.ply").unwrap();
    assert!(mesh.positions[0].x.is_nan());
    assert_eq!(mesh.positions[1].x, f32::INFINITY);
    assert_eq!(mesh.positions[1].y, f32::NEG_INFINITY);
    assert_eq!(mesh.indices, vec![[0, 1, 2]]);
    let mut p = Ply::new(Enc::Le);
    p.line("element vertex 1")
        .line("property float x")
        .line("property float y")
        .line("property float z");
    p.val("float", f64::NAN).val("float", 0.0).val("float", 0.0);
    assert!(parse_ply(&p.bytes(), "nan.ply").unwrap().positions[0]
        .x
        .is_nan());
}

#[test]
fn empty_meshes_load_as_empty() {
    let text = "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\n\
                element face 0\nproperty list uchar int vertex_indices\nend_header\n";
    let mesh = parse_ply(text.as_bytes(), "empty.ply").unwrap();
    assert!(mesh.positions.is_empty() && mesh.indices.is_empty());
    let mesh = parse_ply(b"ply\nformat ascii 1.0\nend_header", "bare.ply").unwrap();
    assert!(mesh.positions.is_empty() && mesh.indices.is_empty());
}

#[test]
fn faces_with_fewer_than_three_corners_give_no_triangles() {
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                element face 4\nproperty list uchar int vertex_indices\nend_header\n\
                0 0 0\n1 0 0\n0 1 0\n0\n1 2\n2 0 1\n3 2 1 0\n";
    let mesh = parse_ply(text.as_bytes(), "few.ply").unwrap();
    assert_eq!(mesh.indices, vec![[2, 1, 0]]);
}

#[test]
fn never_panics_on_truncated_or_corrupted_files() {
    for enc in [Enc::Ascii, Enc::Le, Enc::Be] {
        let good = sample(enc, "float", "uchar", "int").bytes();
        for len in 0..good.len() {
            let _ = parse_ply(&good[..len], "prefix.ply");
        }
        // Deterministic pseudo-random byte corruption.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..2000 {
            let mut bytes = good.clone();
            for _ in 0..3 {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let at = (state % bytes.len() as u64) as usize;
                bytes[at] = (state >> 32) as u8;
            }
            let _ = parse_ply(&bytes, "corrupt.ply");
        }
    }
}
