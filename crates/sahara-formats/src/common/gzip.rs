//! Scene and mesh files that may be gzip-compressed.

use std::io::Read;
use std::path::Path;

use sahara_readers::FormatError;

/// Largest file (after decompression) read, in bytes: a guard against a
/// gzip bomb, far above any real scene file.
pub(crate) const MAX_FILE_BYTES: u64 = 1 << 32;

/// Reads a file, decompressing it if it is gzip (recognised by its first
/// two bytes, whatever its name).
pub(crate) fn read_maybe_gz(path: &Path) -> Result<Vec<u8>, FormatError> {
    let bytes = std::fs::read(path).map_err(|e| FormatError::io(path, e))?;
    if !bytes.starts_with(&[0x1f, 0x8b]) {
        return Ok(bytes);
    }
    let mut out = Vec::new();
    flate2::read::MultiGzDecoder::new(&bytes[..])
        .take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut out)
        .map_err(|e| {
            FormatError::in_file(
                &path.display().to_string(),
                format!("cannot decompress: {e}"),
            )
        })?;
    if out.len() as u64 > MAX_FILE_BYTES {
        return Err(FormatError::in_file(
            &path.display().to_string(),
            format!("decompresses to more than {MAX_FILE_BYTES} bytes"),
        ));
    }
    Ok(out)
}
