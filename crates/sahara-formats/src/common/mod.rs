//! What the scene readers share: positions in files ([`position`]),
//! warnings counted by kind ([`warnings`]), gzip-compressed files
//! ([`gzip`]), spectra as RGB ([`spectrum`]), tints and blends ([`tint`]),
//! smooth vertex normals ([`mesh`]), images in as linear colour ([`image`])
//! and textures decoded once ([`materials`]). Nothing here knows a
//! format's vocabulary; each reader maps its own onto these.

pub(crate) mod gzip;
pub(crate) mod image;
pub(crate) mod materials;
pub(crate) mod mesh;
pub(crate) mod position;
pub(crate) mod spectrum;
pub(crate) mod tint;
pub(crate) mod warnings;

#[cfg(test)]
pub(crate) mod test_scenes;
