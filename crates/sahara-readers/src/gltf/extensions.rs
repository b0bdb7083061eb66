//! Which glTF extensions a file uses, before the file is parsed for real.
//!
//! A file is read as plain JSON first, so that what Sahara cannot render
//! is said in words rather than as a parser's complaint about a field:
//! glTF 1.0 files, required extensions Sahara lacks (Draco and meshopt
//! compression each by name), and optional extensions it ignores (one
//! warning each, with the number of places the file uses it). Textures
//! given only as KTX2 (`KHR_texture_basisu`) are given that image as their
//! `source` here, before the `gltf` crate, which requires one, reads them.

use serde_json::Value;

use crate::error::FormatError;

/// Extensions Sahara reads (`KHR_materials_volume` in part: its
/// thickness decides between a thin wall and a solid, and its attenuation
/// fills a solid with an absorbing medium).
pub const SUPPORTED: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_clearcoat",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_mesh_quantization",
    "KHR_texture_basisu",
    "KHR_texture_transform",
];

/// The plain JSON of a `.gltf` or `.glb` file, with the warnings about
/// extensions it uses but Sahara ignores.
pub(crate) struct Prescan {
    /// The file's JSON.
    pub json: Value,
    /// One line per ignored optional extension.
    pub warnings: Vec<String>,
}

/// The JSON chunk of a GLB container, or the bytes themselves for a
/// `.gltf`; `Err` for a GLB of container version 1 (glTF 1.0's binary
/// form).
fn json_bytes<'a>(bytes: &'a [u8], name: &str) -> Result<Option<&'a [u8]>, FormatError> {
    let Some(rest) = bytes.strip_prefix(b"glTF") else {
        return Ok(Some(bytes));
    };
    let word = |at: usize| {
        rest.get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    if word(0) == Some(1) {
        return Err(glTF_1(name));
    }
    // Header (magic, version, length), then the first chunk: length, type.
    let (Some(len), Some(kind)) = (word(8), word(12)) else {
        return Ok(None);
    };
    if kind != 0x4E4F_534A {
        return Ok(None);
    }
    Ok(rest.get(16..16usize.saturating_add(len as usize)))
}

#[allow(non_snake_case)]
fn glTF_1(name: &str) -> FormatError {
    FormatError::in_file(name, "glTF 1.0 is not supported; convert it to glTF 2.0")
}

/// Reads the file's JSON and checks its version and extensions. A file
/// that is not JSON at all is left to the real parser (which says where
/// the JSON breaks).
pub(crate) fn prescan(bytes: &[u8], name: &str) -> Result<Option<Prescan>, FormatError> {
    let Some(text) = json_bytes(bytes, name)? else {
        return Ok(None);
    };
    let Ok(json) = serde_json::from_slice::<Value>(text) else {
        return Ok(None);
    };
    let version = json
        .get("asset")
        .and_then(|a| a.get("version"))
        .and_then(Value::as_str);
    // glTF 1.0 files name their objects by id in maps (`"meshes": {..}`)
    // and may lack a version.
    let maps = ["meshes", "accessors", "nodes", "materials"]
        .iter()
        .any(|k| json.get(k).is_some_and(Value::is_object));
    if version.is_some_and(|v| v.starts_with("1.") || v == "1") || (version.is_none() && maps) {
        return Err(glTF_1(name));
    }
    let names = |key: &str| -> Vec<String> {
        json.get(key)
            .and_then(Value::as_array)
            .map(|a| {
                a.iter()
                    .filter_map(Value::as_str)
                    .map(str::to_owned)
                    .collect()
            })
            .unwrap_or_default()
    };
    for ext in names("extensionsRequired") {
        if SUPPORTED.contains(&ext.as_str()) {
            continue;
        }
        let what = match ext.as_str() {
            "KHR_draco_mesh_compression" => {
                "Draco-compressed meshes (KHR_draco_mesh_compression) are not supported; \
                 save the file without mesh compression"
                    .to_owned()
            }
            "EXT_meshopt_compression" | "KHR_meshopt_compression" => format!(
                "meshopt-compressed buffers ({ext}) are not supported; \
                 save the file without buffer compression"
            ),
            _ => format!("requires the glTF extension {ext}, which Sahara does not support"),
        };
        return Err(FormatError::in_file(name, what));
    }
    let mut warnings = Vec::new();
    for ext in names("extensionsUsed") {
        if SUPPORTED.contains(&ext.as_str()) {
            continue;
        }
        let uses = count_uses(&json, &ext);
        warnings.push(format!(
            "{name}: extension {ext} is not supported and is ignored ({uses} use{})",
            if uses == 1 { "" } else { "s" }
        ));
    }
    Ok(Some(Prescan { json, warnings }))
}

/// Number of objects in `v` whose `extensions` name `ext`.
pub(crate) fn count_uses(v: &Value, ext: &str) -> usize {
    match v {
        Value::Object(map) => map
            .iter()
            .map(|(k, child)| {
                let here = usize::from(
                    k == "extensions" && child.as_object().is_some_and(|e| e.contains_key(ext)),
                );
                here + count_uses(child, ext)
            })
            .sum(),
        Value::Array(items) => items.iter().map(|c| count_uses(c, ext)).sum(),
        _ => 0,
    }
}

/// The file's bytes with each texture that has a `KHR_texture_basisu`
/// source but no `source` of its own given that image as its `source`, so
/// that the `gltf` crate (which requires one) reads the KTX2 image; `None`
/// when no texture needs it. A texture with both keeps its own (a PNG or
/// JPEG fallback). A `.glb` keeps its binary chunk as it was.
pub(crate) fn with_basisu_sources(bytes: &[u8], json: &Value) -> Option<Vec<u8>> {
    let textures = json.get("textures")?.as_array()?;
    let needs = |t: &Value| {
        t.get("source").is_none()
            && t.pointer("/extensions/KHR_texture_basisu/source")
                .is_some_and(Value::is_u64)
    };
    if !textures.iter().any(needs) {
        return None;
    }
    let mut json = json.clone();
    for t in json.get_mut("textures")?.as_array_mut()? {
        if needs(t) {
            let source = t.pointer("/extensions/KHR_texture_basisu/source")?.clone();
            t.as_object_mut()?.insert("source".to_owned(), source);
        }
    }
    let mut text = serde_json::to_vec(&json).ok()?;
    if !bytes.starts_with(b"glTF") {
        return Some(text);
    }
    // GLB: a 12-byte header, then the JSON chunk (length, type, data) and
    // the rest (the binary chunk) as it was.
    let word = |at: usize| -> Option<usize> {
        Some(u32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?) as usize)
    };
    let json_end = 20usize.checked_add(word(12)?)?;
    let rest = bytes.get(json_end..)?;
    text.resize(text.len().div_ceil(4) * 4, b' ');
    let total = 20 + text.len() + rest.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(&bytes[..8]);
    out.extend_from_slice(&u32::try_from(total).ok()?.to_le_bytes());
    out.extend_from_slice(&u32::try_from(text.len()).ok()?.to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&text);
    out.extend_from_slice(rest);
    Some(out)
}
