//! What a file is by its first bytes, for the kinds Sahara never reads as
//! a scene or a mesh (images, archives, programs): a renamed PNG would
//! otherwise be reported as broken glTF JSON or an OBJ that is not UTF-8.

use std::io::Read;
use std::path::Path;

/// Leading bytes of the kinds recognised, and their names in an error.
const KINDS: [(&[u8], &str); 9] = [
    (b"\x89PNG\r\n\x1a\n", "a PNG image"),
    (b"\xff\xd8\xff", "a JPEG image"),
    (b"\x76\x2f\x31\x01", "an OpenEXR image"),
    (b"#?RADIANCE", "a Radiance HDR image"),
    (b"#?RGBE", "a Radiance HDR image"),
    (b"GIF8", "a GIF image"),
    (b"%PDF", "a PDF document"),
    (b"PK\x03\x04", "a ZIP archive"),
    (b"\x7fELF", "a program (ELF)"),
];

/// The kind of the file at `path` (e.g. "a PNG image") when its first
/// bytes say it is one that is never a scene or a mesh; `None` otherwise,
/// and when it cannot be read (the reader then says why).
pub fn foreign_kind(path: &Path) -> Option<&'static str> {
    let mut head = [0u8; 16];
    let n = std::fs::File::open(path)
        .and_then(|mut f| f.read(&mut head))
        .ok()?;
    let head = &head[..n];
    KINDS
        .iter()
        .find(|(magic, _)| head.starts_with(magic))
        .map(|&(_, what)| what)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn images_are_known_by_their_first_bytes_and_meshes_are_not_taken_for_them() {
        let dir = std::env::temp_dir().join(format!("sahara-sniff-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let png = dir.join("model.glb");
        std::fs::write(&png, b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR").unwrap();
        assert_eq!(foreign_kind(&png), Some("a PNG image"));
        let obj = dir.join("model.obj");
        std::fs::write(&obj, b"v 0 0 0\n").unwrap();
        assert_eq!(foreign_kind(&obj), None);
        let glb = dir.join("real.glb");
        std::fs::write(&glb, b"glTF\x02\0\0\0").unwrap();
        assert_eq!(foreign_kind(&glb), None);
        assert_eq!(foreign_kind(&dir.join("missing.obj")), None);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
