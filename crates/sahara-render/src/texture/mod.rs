//! Images that materials and environments look up.
//!
//! - [`Texture`]: an image (8-bit sRGB, 8-bit linear or float texels, with
//!   an optional alpha channel) and its MIP pyramid, built on the first
//!   filtered lookup that needs it;
//! - [`TextureMap`]: how a material reads a texture: wrap modes, which
//!   uv set, a uv transform; bilinear filtering between MIP levels chosen
//!   by the footprint of the lookup ([`footprint`], docs/textures.md);
//! - [`ScalarMap`]: one channel of a texture (roughness, metallic, ...).
//!
//! Texture coordinates: `u` runs left to right, `v` bottom to top (OBJ and
//! OpenGL's convention); rows are stored from the top.

pub mod footprint;
mod map;
mod pyramid;

use std::sync::OnceLock;

use glam::{Vec2, Vec3, Vec4};

pub use map::{Channel, ScalarMap, TextureMap, Wrap};
use pyramid::Level;

/// How an 8-bit texture's colour channels encode values (alpha is always
/// linear).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Encoding {
    /// The sRGB transfer function (colours: base colour, emission).
    Srgb,
    /// Values as they are, `code / 255` (data: normals, roughness,
    /// metallic, occlusion).
    Linear,
}

/// An image with its MIP pyramid.
///
/// Texels are decoded to linear values on lookup: 8-bit images stay 8-bit
/// in memory (a quarter of a float image), which real assets with dozens
/// of 2k and 4k maps need.
#[derive(Clone)]
pub struct Texture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    base: Level,
    /// Levels 1 and up, each half the size of the one before (rounded
    /// down, at least 1), built on first use.
    pyramid: OnceLock<Vec<Level>>,
    /// The mean of the level-0 texels, computed on first use: callers ask
    /// for it once per triangle or per material, and each asking must not
    /// cost a pass over the texels.
    mean: OnceLock<Vec3>,
}

impl PartialEq for Texture {
    fn eq(&self, other: &Self) -> bool {
        self.base == other.base
    }
}

impl std::fmt::Debug for Texture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Texture({}x{} {})",
            self.width,
            self.height,
            self.base.format()
        )
    }
}

impl Texture {
    /// A float texture from linear RGB texels (`width * height` of them,
    /// row-major from the top-left corner), opaque.
    pub fn new(width: u32, height: u32, texels: Vec<Vec3>) -> Self {
        Self::from_level(Level::rgb_f32(width, height, texels))
    }

    /// An 8-bit RGBA texture (`width * height` texels, row-major from the
    /// top-left corner); `encoding` says how R, G and B encode values,
    /// `has_alpha` whether A is meaningful (else it reads as 1).
    pub fn from_rgba8(
        width: u32,
        height: u32,
        texels: Vec<[u8; 4]>,
        encoding: Encoding,
        has_alpha: bool,
    ) -> Self {
        Self::from_level(Level::rgba8(width, height, texels, encoding, has_alpha))
    }

    fn from_level(base: Level) -> Self {
        assert!(base.width > 0 && base.height > 0, "empty texture");
        Self {
            width: base.width,
            height: base.height,
            base,
            pyramid: OnceLock::new(),
            mean: OnceLock::new(),
        }
    }

    /// This texture with an opacity channel (`width * height` values in
    /// `[0, 1]`).
    pub fn with_alpha(mut self, alpha: Vec<f32>) -> Self {
        self.base.set_alpha(alpha);
        self.pyramid = OnceLock::new();
        self
    }

    /// True if the texture has an alpha channel.
    pub fn has_alpha(&self) -> bool {
        self.base.has_alpha()
    }

    /// The level-0 texels' linear RGB, row by row from the top left.
    pub fn texels(&self) -> impl Iterator<Item = Vec3> + '_ {
        (0..self.base.len()).map(|i| self.base.get(i).truncate())
    }

    /// The level-0 texels' linear RGBA (alpha 1 without an alpha
    /// channel), row by row from the top left.
    pub fn texels_rgba(&self) -> impl Iterator<Item = Vec4> + '_ {
        (0..self.base.len()).map(|i| self.base.get(i))
    }

    /// The mean linear RGB of the texels, computed the first time it is
    /// asked for and kept.
    pub fn mean(&self) -> Vec3 {
        *self.mean.get_or_init(|| {
            let sum = self
                .texels()
                .fold(glam::DVec3::ZERO, |s, t| s + t.as_dvec3());
            (sum / self.base.len() as f64).as_vec3()
        })
    }

    /// Bytes the texels take (the pyramid included once built).
    pub fn memory_bytes(&self) -> usize {
        self.base.memory_bytes()
            + self
                .pyramid
                .get()
                .map_or(0, |p| p.iter().map(Level::memory_bytes).sum())
    }

    /// Number of MIP levels (1 + however often the size halves to 1x1).
    pub fn levels(&self) -> usize {
        let side = self.width.max(self.height);
        (u32::BITS - side.leading_zeros()) as usize
    }

    /// Level `k` (clamped to the last), building the pyramid if needed.
    fn level(&self, k: usize) -> &Level {
        if k == 0 {
            return &self.base;
        }
        let p = self.pyramid.get_or_init(|| pyramid::build(&self.base));
        &p[(k - 1).min(p.len() - 1)]
    }

    /// Size of level `k` in texels.
    pub fn level_size(&self, k: usize) -> (u32, u32) {
        let k = k.min(self.levels() - 1) as u32;
        ((self.width >> k).max(1), (self.height >> k).max(1))
    }

    /// The level-0 texel at integer coordinates, wrapped around (repeat).
    #[inline]
    pub fn texel(&self, x: i64, y: i64) -> Vec3 {
        self.texel_rgba(0, x, y, [Wrap::Repeat; 2]).truncate()
    }

    /// Linear RGBA of texel `(x, y)` of level `k`, wrapped by `wrap`.
    #[inline]
    pub fn texel_rgba(&self, k: usize, x: i64, y: i64, wrap: [Wrap; 2]) -> Vec4 {
        let l = self.level(k);
        let x = wrap[0].apply(x, l.width);
        let y = wrap[1].apply(y, l.height);
        l.get(y as usize * l.width as usize + x as usize)
    }

    /// Bilinear lookup of level `k` at `uv` (texel centres at
    /// half-integer texel positions), in linear RGBA.
    pub fn bilinear_level(&self, k: usize, uv: Vec2, wrap: [Wrap; 2]) -> Vec4 {
        if !uv.is_finite() {
            return self.base.get(0);
        }
        let (w, h) = self.level_size(k);
        let x = uv.x * w as f32 - 0.5;
        let y = (1.0 - uv.y) * h as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        // Coordinates far outside the image (huge uvs) stay integers.
        let (x0, y0) = (x0.clamp(-1e15, 1e15) as i64, y0.clamp(-1e15, 1e15) as i64);
        let t = |dx, dy| self.texel_rgba(k, x0 + dx, y0 + dy, wrap);
        let top = t(0, 0).lerp(t(1, 0), fx);
        let bottom = t(0, 1).lerp(t(1, 1), fx);
        top.lerp(bottom, fy)
    }

    /// Filtered lookup at `uv` of a footprint `width` level-0 texels wide:
    /// bilinear in the two levels whose texels are nearest that width,
    /// blended (trilinear MIP-mapping); plain bilinear at level 0 for
    /// footprints of a texel or less.
    pub fn filtered(&self, uv: Vec2, width: f32, wrap: [Wrap; 2]) -> Vec4 {
        let last = self.levels() - 1;
        let level = if width > 1.0 { width.log2() } else { 0.0 };
        if level <= 0.0 || last == 0 || level.is_nan() {
            return self.bilinear_level(0, uv, wrap);
        }
        if level >= last as f32 {
            return self.bilinear_level(last, uv, wrap);
        }
        let k = level.floor();
        let f = level - k;
        let k = k as usize;
        let a = self.bilinear_level(k, uv, wrap);
        if f == 0.0 {
            return a;
        }
        a.lerp(self.bilinear_level(k + 1, uv, wrap), f)
    }

    /// Bilinear lookup of level 0 at `uv`, wrapping around (repeat).
    pub fn bilinear(&self, uv: Vec2) -> Vec3 {
        self.bilinear_level(0, uv, [Wrap::Repeat; 2]).truncate()
    }

    /// Bilinear lookup of the opacity at `uv` (1 without an alpha channel).
    pub fn alpha(&self, uv: Vec2) -> f32 {
        if !self.has_alpha() {
            return 1.0;
        }
        self.bilinear_level(0, uv, [Wrap::Repeat; 2]).w
    }
}

/// The linear value of an 8-bit sRGB code (IEC 61966-2-1), from a table.
#[inline]
pub fn srgb8_to_linear(code: u8) -> f32 {
    static TABLE: OnceLock<[f32; 256]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0)))[code as usize]
}

/// The linear value of an sRGB-encoded value in `[0, 1]`.
pub fn srgb_to_linear(s: f32) -> f32 {
    if s <= 0.040_45 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

/// The 8-bit sRGB code nearest a linear value in `[0, 1]`.
pub fn linear_to_srgb8(v: f32) -> u8 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    let s = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5).clamp(0.0, 255.0) as u8
}

#[cfg(test)]
mod tests;
