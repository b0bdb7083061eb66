//! URIs in glTF files: `data:` URIs (base64) and relative, percent-encoded file paths.
//!
//! Only local data is ever read: a URI with any other scheme (`http:` ...)
//! is refused, so loading never touches the network.

use std::path::{Path, PathBuf};

/// Where a glTF URI points.
#[derive(Debug, PartialEq)]
pub(crate) enum UriTarget {
    /// The decoded bytes of a `data:` URI.
    Data(Vec<u8>),
    /// A local file, resolved against the glTF file's folder.
    File(PathBuf),
}

/// Resolves `uri` relative to `folder`; the error text says what is wrong with it.
pub(crate) fn resolve(uri: &str, folder: &Path) -> Result<UriTarget, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (header, payload) = rest
            .split_once(',')
            .ok_or_else(|| "data URI without a ',' before its data".to_owned())?;
        if !header.ends_with(";base64") {
            return Err("data URI is not base64-encoded (';base64,' expected)".to_owned());
        }
        return decode_base64(payload).map(UriTarget::Data);
    }
    if let Some((scheme, _)) = uri.split_once(':') {
        let is_scheme = !scheme.is_empty()
            && scheme
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c));
        // A one-letter "scheme" is a Windows drive letter, not a URI scheme.
        if is_scheme && scheme.len() > 1 {
            return Err(format!(
                "URI scheme '{scheme}:' is not supported; only relative file paths and data: URIs are read"
            ));
        }
    }
    let path = percent_decode(uri)?;
    Ok(UriTarget::File(folder.join(path)))
}

/// Decodes `%XX` escapes; the result must be UTF-8.
fn percent_decode(text: &str) -> Result<String, String> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("bad percent escape in URI '{text}'"))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| format!("URI '{text}' does not decode to UTF-8"))
}

/// Decodes standard base64 (`+/`, optional `=` padding, whitespace ignored).
pub(crate) fn decode_base64(text: &str) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3 + 3);
    let mut acc: u32 = 0;
    let mut bits = 0;
    let mut padding = 0;
    for (i, c) in text.bytes().enumerate() {
        let value = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            b'=' => {
                padding += 1;
                continue;
            }
            c if c.is_ascii_whitespace() => continue,
            _ => {
                return Err(format!(
                    "invalid base64 character at offset {i} of the data URI"
                ))
            }
        };
        if padding > 0 {
            return Err("base64 data continues after '=' padding".to_owned());
        }
        acc = (acc << 6) | value as u32;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    if bits >= 6 {
        return Err("base64 data has a dangling character".to_owned());
    }
    Ok(out)
}
