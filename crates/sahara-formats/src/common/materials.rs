//! What the material mappings of mesh files (MTL, glTF) and scene files
//! share: textures decoded once per image and encoding ([`TextureCache`];
//! a texture that cannot be read is a warning and the material goes
//! without it), colours clamped to [0, 1], emission kept finite.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::Vec3;
use sahara_readers::FormatError;
use sahara_render::{Encoding, Texture};

use crate::common::image::load_texture;

/// Where a texture's image came from, as the cache knows it.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Source {
    /// A file.
    File(PathBuf),
    /// Image `index` embedded in the glTF file `file`.
    Embedded(String, usize),
}

/// Decoded textures by image and encoding, so that an image used by many
/// materials is read once.
#[derive(Debug, Default)]
pub struct TextureCache {
    images: HashMap<(Source, Encoding), Option<Arc<Texture>>>,
}

impl TextureCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// The texture in `path` read as `encoding`, decoded on first use;
    /// `None` (and a warning) if it cannot be read.
    pub fn file(
        &mut self,
        path: &Path,
        encoding: Encoding,
        warnings: &mut Vec<String>,
    ) -> Option<Arc<Texture>> {
        self.get(Source::File(path.to_path_buf()), encoding, warnings, || {
            load_texture(path, encoding)
        })
    }

    /// The texture `source` read as `encoding`, decoded by `decode` on
    /// first use; `None` (and a warning) if it cannot be read.
    pub(crate) fn get(
        &mut self,
        source: Source,
        encoding: Encoding,
        warnings: &mut Vec<String>,
        decode: impl FnOnce() -> Result<Texture, FormatError>,
    ) -> Option<Arc<Texture>> {
        self.images
            .entry((source, encoding))
            .or_insert_with(|| match decode() {
                Ok(t) => Some(Arc::new(t)),
                Err(e) => {
                    warnings.push(format!("{e}; the material goes without this texture"));
                    None
                }
            })
            .clone()
    }

    /// Number of distinct images decoded (or tried), per encoding.
    pub fn len(&self) -> usize {
        self.images.len()
    }

    /// True if no texture was asked for.
    pub fn is_empty(&self) -> bool {
        self.images.is_empty()
    }
}

/// Clamps every component to [0, 1] (NaN becomes 0).
pub(crate) fn unit(c: [f32; 3]) -> Vec3 {
    Vec3::from_array(c.map(|x| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) }))
}

/// Non-negative finite emission.
pub(crate) fn emission(c: [f32; 3]) -> Vec3 {
    Vec3::from_array(c.map(|x| if x.is_finite() { x.max(0.0) } else { 0.0 }))
}
