//! The sRGB transfer function (IEC 61966-2-1), both ways (the renderer's,
//! which its textures decode with).

pub use sahara_render::{linear_to_srgb8, srgb8_to_linear, srgb_to_linear};
