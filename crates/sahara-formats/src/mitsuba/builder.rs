//! What the walk over a Mitsuba scene builds and shares with the modules
//! that map each kind of element: the table of `id`s, the description being
//! built, the materials and meshes made once each, the warnings.

use std::collections::HashMap;
use std::path::PathBuf;

use sahara_readers::FormatError;

use super::expand::Search;
use super::properties::{Child, Object};
use super::xml::Node;
use crate::common::tint::Tint;
use crate::common::warnings::Warnings;
use crate::description::SceneDescription;

/// What the walk over a scene builds, and what it has made so far.
pub(crate) struct Builder<'a> {
    /// Where files named in the scene are looked for.
    pub(crate) main: Search,
    /// Every object with an `id`, by id.
    pub(crate) ids: HashMap<&'a str, &'a Node>,
    /// The description being built.
    pub(crate) scene: SceneDescription,
    /// Warnings, one line per kind.
    pub(crate) w: Warnings,
    /// The material of each bsdf element (by address), once mapped;
    /// `None`: no surface (`null`).
    pub(crate) materials: HashMap<usize, Option<u32>>,
    /// The grey default of shapes without a bsdf.
    pub(crate) default_material: Option<u32>,
    /// The black surface of emitters without a bsdf.
    pub(crate) black_material: Option<u32>,
    /// Meshes loaded from files, by file, index within it and options.
    pub(crate) file_meshes: HashMap<(PathBuf, i64, bool, bool), Option<u32>>,
    /// The mesh of each shapegroup (by address), once made.
    pub(crate) groups: HashMap<usize, Option<u32>>,
    /// The normal maps made from bumpmaps' heights (their slopes are per
    /// unit of uv until [`scale_bumps`] sets their strength).
    pub(crate) bump_maps: Vec<std::sync::Arc<sahara_render::Texture>>,
    /// Textures read so far (by element address).
    pub(crate) textures: HashMap<usize, Tint>,
    /// The index of each medium element (by address), once made.
    pub(crate) media: HashMap<usize, u32>,
}

/// The address of an element: its identity for the caches.
pub(crate) fn key(node: &Node) -> usize {
    node as *const Node as usize
}

/// Collects the ids of `node`'s descendants into `ids`.
fn collect_ids<'a>(
    node: &'a Node,
    ids: &mut HashMap<&'a str, &'a Node>,
) -> Result<(), FormatError> {
    for c in &node.children {
        if c.tag != "ref" {
            if let Some(id) = c.attr("id") {
                if let Some(first) = ids.insert(id, c) {
                    return Err(c.error(format!(
                        "id \"{id}\" is given twice (first at line {})",
                        first.loc.line
                    )));
                }
            }
        }
        collect_ids(c, ids)?;
    }
    Ok(())
}

impl<'a> Builder<'a> {
    /// The builder of the scene `root` read from the file `name`, files
    /// looked for as `search` says, its ids collected.
    pub(crate) fn new(
        root: &'a Node,
        name: &str,
        search: Search,
        w: Warnings,
    ) -> Result<Self, FormatError> {
        let mut ids = HashMap::new();
        collect_ids(root, &mut ids)?;
        Ok(Builder {
            main: search,
            ids,
            scene: SceneDescription::new(name),
            w,
            materials: HashMap::new(),
            default_material: None,
            black_material: None,
            file_meshes: HashMap::new(),
            groups: HashMap::new(),
            textures: HashMap::new(),
            bump_maps: Vec::new(),
            media: HashMap::new(),
        })
    }

    /// The object `child` stands for (a `<ref>` looked up by its id),
    /// which must be one of `tags` (`what` names them in messages).
    pub(crate) fn resolve(
        &self,
        child: Child<'a>,
        tags: &[&str],
        what: &str,
    ) -> Result<&'a Node, FormatError> {
        let node = match child {
            Child::Node(n) => n,
            Child::Ref(r) => {
                let id = r.need("id")?;
                *self.ids.get(id).ok_or_else(|| {
                    r.error(format!("<ref id=\"{id}\">: no object has the id \"{id}\""))
                })?
            }
        };
        if !tags.contains(&node.tag.as_str()) {
            let at = child.node();
            return Err(at.error(format!(
                "expected {what} here, found a <{}>{}",
                node.tag,
                match child {
                    Child::Ref(_) => format!(" (id \"{}\")", at.attr("id").unwrap_or("")),
                    Child::Node(_) => String::new(),
                }
            )));
        }
        Ok(node)
    }

    /// The first nested object of `o` (written in place or referred to)
    /// whose element is `<tag>`, marked used.
    pub(crate) fn child_of(
        &self,
        o: &Object<'a>,
        tag: &str,
    ) -> Result<Option<&'a Node>, FormatError> {
        for e in o.entries() {
            let node = match e.child {
                Child::Node(n) => n,
                Child::Ref(_) => {
                    self.resolve(e.child, super::properties::OBJECT_TAGS, "an object")?
                }
            };
            if node.tag == tag {
                e.take();
                return Ok(Some(node));
            }
        }
        Ok(None)
    }

    /// The parsed object of `node`.
    pub(crate) fn object(&self, node: &'a Node) -> Result<Object<'a>, FormatError> {
        Object::parse(node, &self.main)
    }
}
