//! The scene file as one tree: `<include>`d files spliced in, `<default>`
//! parameters applied, and the names of Mitsuba 0.x files (camelCase:
//! `maxDepth`, `intIOR`, `toWorld`) converted to Mitsuba 3's
//! (`max_depth`, `int_ior`, `to_world`), each file by its own `version`.

use std::path::{Path, PathBuf};

use sahara_readers::FormatError;

use super::defaults::Defaults;
use super::xml::{read_file, Node};
use crate::common::warnings::Warnings;

/// Deepest chain of files including files.
const MAX_INCLUDE_DEPTH: usize = 16;

/// Tags whose `name` attribute names a parameter (converted for 0.x files).
const NAMED_TAGS: &[&str] = &[
    "integer",
    "float",
    "boolean",
    "string",
    "rgb",
    "srgb",
    "spectrum",
    "blackbody",
    "point",
    "vector",
    "transform",
    "texture",
    "ref",
    "bsdf",
    "emitter",
    "sampler",
    "rfilter",
    "film",
    "medium",
    "phase",
    "volume",
];

/// The `<scene>` of `root` (a file's root element) with everything
/// expanded, given the parameters `defaults`; `main` is the folder of
/// the file the render started from.
pub(crate) fn expand_scene(
    root: Node,
    defaults: &mut Defaults,
    search: &mut Search,
    w: &mut Warnings,
) -> Result<Node, FormatError> {
    let mut out = Vec::new();
    let legacy = check_scene(&root, defaults, w)?;
    let Node {
        tag,
        attrs,
        children,
        loc,
        folder,
    } = root;
    expand_children(children, legacy, defaults, search, 0, w, &mut out)?;
    Ok(Node {
        tag,
        attrs,
        children: out,
        loc,
        folder,
    })
}

/// Checks that `root` is a `<scene>` of a version Sahara reads; true for
/// a Mitsuba 0.x file.
fn check_scene(root: &Node, defaults: &Defaults, w: &mut Warnings) -> Result<bool, FormatError> {
    if root.tag != "scene" {
        return Err(root.error(format!(
            "expected <scene version=\"3.0.0\"> as the file's root, found <{}>",
            root.tag
        )));
    }
    let Some(v) = root.attr("version") else {
        w.add(
            "<scene> has no version; read as Mitsuba 3 (version=\"3.0.0\")",
            &root.loc,
        );
        return Ok(false);
    };
    let v = defaults.substitute(root, v)?;
    let major = v
        .split('.')
        .next()
        .and_then(|m| m.trim().parse::<u32>().ok())
        .ok_or_else(|| root.error(format!("<scene> version '{v}' is not a version number")))?;
    match major {
        0 => Ok(true),
        2 | 3 => Ok(false),
        _ => Err(root.error(format!(
            "<scene> version '{v}': Sahara reads Mitsuba 0.x, 2.x and 3.x files"
        ))),
    }
}

/// Mitsuba 0.x's camelCase parameter name in Mitsuba 3's spelling: an
/// `_` before each capital that follows a lower-case letter or digit, all
/// in lower case (`intIOR` is `int_ior`).
pub(crate) fn snake_case(name: &str) -> String {
    let mut out = String::with_capacity(name.len() + 4);
    let mut prev_lower = false;
    for c in name.chars() {
        if c.is_ascii_uppercase() && prev_lower {
            out.push('_');
        }
        prev_lower = c.is_ascii_lowercase() || c.is_ascii_digit();
        out.push(c.to_ascii_lowercase());
    }
    out
}

/// Expands `children` in order into `out`.
fn expand_children(
    children: Vec<Node>,
    legacy: bool,
    defaults: &mut Defaults,
    search: &mut Search,
    depth: usize,
    w: &mut Warnings,
    out: &mut Vec<Node>,
) -> Result<(), FormatError> {
    for node in children {
        match node.tag.as_str() {
            "default" => defaults.declare(&node)?,
            "path" => {
                let dir = defaults.substitute(&node, node.need("value")?)?;
                let dir = node.folder.join(dir);
                search.extra.push(dir);
            }
            "include" => {
                let file = defaults.substitute(&node, node.need("filename")?)?;
                if depth >= MAX_INCLUDE_DEPTH {
                    return Err(node.error(format!(
                        "<include> nests more than {MAX_INCLUDE_DEPTH} deep (a file including itself?)"
                    )));
                }
                let path = search.resolve(&node.folder, &file);
                let name = path.display().to_string();
                let root = read_file(&path, &name, w)
                    .map_err(|e| node.error(format!("<include filename=\"{file}\">: {e}")))?;
                let inner_legacy = check_scene(&root, defaults, w)?;
                expand_children(
                    root.children,
                    inner_legacy,
                    defaults,
                    search,
                    depth + 1,
                    w,
                    out,
                )?;
            }
            _ => out.push(expand_node(node, legacy, defaults, search, depth, w)?),
        }
    }
    Ok(())
}

/// One element (not `<default>` or `<include>`) with its attributes
/// substituted and its children expanded.
fn expand_node(
    mut node: Node,
    legacy: bool,
    defaults: &mut Defaults,
    search: &mut Search,
    depth: usize,
    w: &mut Warnings,
) -> Result<Node, FormatError> {
    defaults.substitute_attrs(&mut node)?;
    if legacy && NAMED_TAGS.contains(&node.tag.as_str()) {
        for (k, v) in &mut node.attrs {
            if k == "name" {
                *v = snake_case(v);
            }
        }
    }
    let children = std::mem::take(&mut node.children);
    let mut out = Vec::with_capacity(children.len());
    expand_children(children, legacy, defaults, search, depth, w, &mut out)?;
    node.children = out;
    Ok(node)
}

/// Where files named in the scene are looked for.
#[derive(Clone, Debug, Default)]
pub(crate) struct Search {
    /// The folder of the file the render started from.
    pub(crate) main: PathBuf,
    /// Folders added by `<path value="..."/>`, in file order.
    pub(crate) extra: Vec<PathBuf>,
}

impl Search {
    /// Files looked up from `main` (and the naming file's folder).
    pub(crate) fn new(main: &Path) -> Self {
        Self {
            main: main.to_path_buf(),
            extra: Vec::new(),
        }
    }

    /// A file named in the scene: absolute as given, else the first that
    /// exists of: the folder of the file naming it, the `<path>` folders
    /// (the last added first, as Mitsuba's resolver), the main file's
    /// folder; if none has it, the first.
    pub(crate) fn resolve(&self, folder: &Path, file: &str) -> PathBuf {
        let p = Path::new(file);
        if p.is_absolute() {
            return p.to_path_buf();
        }
        let near = folder.join(p);
        std::iter::once(near.clone())
            .chain(self.extra.iter().rev().map(|d| d.join(p)))
            .chain(std::iter::once(self.main.join(p)))
            .find(|c| c.exists())
            .unwrap_or(near)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camel_case_names_become_snake_case() {
        for (a, b) in [
            ("maxDepth", "max_depth"),
            ("intIOR", "int_ior"),
            ("toWorld", "to_world"),
            ("specularReflectance", "specular_reflectance"),
            ("sampleCount", "sample_count"),
            ("fov", "fov"),
            ("uvscale", "uvscale"),
        ] {
            assert_eq!(snake_case(a), b);
        }
    }
}
