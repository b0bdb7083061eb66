//! What the scene readers share: positions in files ([`position`]),
//! warnings counted by kind ([`warnings`]), gzip-compressed files
//! ([`gzip`]), spectra as RGB ([`spectrum`]), tints and blends ([`tint`])
//! and smooth normals ([`normals`]). Nothing here knows a format's
//! vocabulary; the pbrt and Mitsuba readers map theirs onto these.

pub(crate) mod gzip;
pub(crate) mod normals;
pub(crate) mod position;
pub(crate) mod spectrum;
pub(crate) mod tint;
pub(crate) mod warnings;
