//! The list of names beside the `object` and `material` render passes: a
//! JSON file next to the image (`frame.exr` -> `frame.names.json`) that
//! says what each id of those passes is, written atomically.
//!
//! ```json
//! { "object": { "1": "bunny.ply", "2": "sphere 3" }, "material": { "1": "gold" } }
//! ```
//!
//! Ids are the scene's instance and material index + 1 (0, nothing hit, is
//! not listed). A part file carries the same text in its header, so that
//! `merge` writes the list beside the merged frame.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, Context, Result};
use sahara_formats::write_atomically;
use sahara_formats::FormatError;
use sahara_formats::SceneNames;
use sahara_render::Aov;
use serde_json::{Map, Value};

/// The list's text for the passes among `aovs` (None: neither `object`
/// nor `material` asked for). Pure ASCII: other characters are written
/// as JSON escapes, so the text also fits an EXR header.
pub(crate) fn json(names: &SceneNames, aovs: &[Aov]) -> Option<String> {
    let table = |list: &[String]| {
        let map: Map<String, Value> = list
            .iter()
            .enumerate()
            .map(|(k, n)| ((k + 1).to_string(), Value::String(n.clone())))
            .collect();
        Value::Object(map)
    };
    let mut out = Map::new();
    if aovs.contains(&Aov::Object) {
        out.insert("object".into(), table(&names.objects));
    }
    if aovs.contains(&Aov::Material) {
        out.insert("material".into(), table(&names.materials));
    }
    if out.is_empty() {
        return None;
    }
    let text = serde_json::to_string_pretty(&Value::Object(out)).expect("JSON of strings");
    let mut ascii = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_ascii() {
            ascii.push(c);
        } else {
            let mut units = [0u16; 2];
            for u in c.encode_utf16(&mut units) {
                ascii += &format!("\\u{u:04x}");
            }
        }
    }
    Some(ascii + "\n")
}

/// Where the list of names of the image `image` goes.
pub(crate) fn path_beside(image: &Path) -> PathBuf {
    let stem = image
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    image.with_file_name(format!("{stem}.names.json"))
}

/// Writes `text` beside `image`, atomically.
pub(crate) fn write_beside(image: &Path, text: &str) -> Result<()> {
    let path = path_beside(image);
    write_atomically(&path, |out| {
        out.write_all(text.as_bytes())
            .map_err(|e| FormatError::write(&path, e))
    })
    .map_err(|e| anyhow!("{e}"))
    .context("cannot write the list of object and material names")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_count_from_one_and_the_text_is_ascii() {
        let names = SceneNames {
            objects: vec!["bunny.ply".into(), "tête".into()],
            materials: vec!["gold".into()],
        };
        let text = json(&names, &[Aov::Object]).unwrap();
        assert!(text.is_ascii(), "{text}");
        let v: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["object"]["1"], "bunny.ply");
        assert_eq!(v["object"]["2"], "tête");
        assert!(v.get("material").is_none());
        assert_eq!(json(&names, &[Aov::Depth]), None);
        assert_eq!(
            path_beside(Path::new("out/frame.exr")),
            Path::new("out/frame.names.json")
        );
    }
}
