//! The list of names beside the `object` and `material` render passes.

use sahara_render::Aov;
use serde_json::{Map, Value};

use crate::assembly::SceneNames;

/// The list of names of the `object` and `material` passes among `aovs`
/// (None: neither asked for): a JSON file next to the image
/// (`frame.exr` -> `frame.names.json`) that says what each id is,
///
/// ```json
/// { "object": { "1": "bunny.ply", "2": "sphere 3" }, "material": { "1": "gold" } }
/// ```
///
/// Ids are the scene's instance and material index + 1 (0, nothing hit,
/// is not listed). Pure ASCII: other characters are written as JSON
/// escapes, so the text also fits an EXR header (a part file carries it,
/// and `merge` writes it beside the merged frame).
pub fn names_json(names: &SceneNames, aovs: &[Aov]) -> Option<String> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::frame::names_path;
    use std::path::Path;

    #[test]
    fn ids_count_from_one_and_the_text_is_ascii() {
        let names = SceneNames {
            objects: vec!["bunny.ply".into(), "tête".into()],
            materials: vec!["gold".into()],
        };
        let text = names_json(&names, &[Aov::Object]).unwrap();
        assert!(text.is_ascii(), "{text}");
        let v: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["object"]["1"], "bunny.ply");
        assert_eq!(v["object"]["2"], "tête");
        assert!(v.get("material").is_none());
        assert_eq!(names_json(&names, &[Aov::Depth]), None);
        assert_eq!(
            names_path(Path::new("out/frame.exr")),
            Path::new("out/frame.names.json")
        );
    }
}
