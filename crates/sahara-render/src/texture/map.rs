//! How a material reads a texture: wrap modes, uv set, uv transform.

use std::sync::Arc;

use glam::{Affine2, Vec2, Vec4};

use super::footprint::UvFootprint;
use super::Texture;

/// What happens to texture coordinates outside `[0, 1]`, per axis
/// (OpenGL's and glTF's wrap modes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// The image tiles the plane.
    #[default]
    Repeat,
    /// The edge texels extend outwards.
    Clamp,
    /// The image tiles the plane, every other tile mirrored.
    MirroredRepeat,
}

impl Wrap {
    /// Texel index `i` of a row of `n` texels, wrapped into `0..n`.
    #[inline]
    pub fn apply(self, i: i64, n: u32) -> u32 {
        let n = n as i64;
        (match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::MirroredRepeat => {
                let m = i.rem_euclid(2 * n);
                if m >= n {
                    2 * n - 1 - m
                } else {
                    m
                }
            }
        }) as u32
    }
}

/// A texture as a material reads it.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureMap {
    /// The image.
    pub texture: Arc<Texture>,
    /// Wrap mode along `u` and along `v`.
    pub wrap: [Wrap; 2],
    /// Which of the mesh's uv sets is read (0 or 1).
    pub uv_set: u8,
    /// Applied to the uv set's coordinates before the lookup (glTF's
    /// `KHR_texture_transform`, pbrt's `uscale`/`vscale`/`udelta`/`vdelta`).
    pub transform: Affine2,
}

impl TextureMap {
    /// `texture` read with uv set 0, repeating, untransformed.
    pub fn new(texture: Arc<Texture>) -> Self {
        Self {
            texture,
            wrap: [Wrap::Repeat; 2],
            uv_set: 0,
            transform: Affine2::IDENTITY,
        }
    }

    /// This map with wrap modes along `u` and `v`.
    pub fn with_wrap(mut self, u: Wrap, v: Wrap) -> Self {
        self.wrap = [u, v];
        self
    }

    /// This map reading uv set `set` (0 or 1).
    pub fn with_uv_set(mut self, set: u8) -> Self {
        self.uv_set = set.min(1);
        self
    }

    /// This map with `transform` applied to the coordinates.
    pub fn with_transform(mut self, transform: Affine2) -> Self {
        self.transform = transform;
        self
    }

    /// Filtered linear RGBA at the hit whose uv sets are `uvs`, for a
    /// lookup of footprint `footprint` (see `super::footprint`).
    #[inline]
    pub fn lookup(&self, uvs: &[Vec2; 2], footprint: &UvFootprint) -> Vec4 {
        let set = self.uv_set as usize & 1;
        let uv = self.transform.transform_point2(uvs[set]);
        let width = footprint.texels(set, &self.transform, &self.texture);
        self.texture.filtered(uv, width, self.wrap)
    }

    /// Bilinear linear RGBA of the finest level at `uvs` (no footprint:
    /// alpha tests of shadow rays, whose footprint is unknown).
    #[inline]
    pub fn lookup_sharp(&self, uvs: &[Vec2; 2]) -> Vec4 {
        let uv = self
            .transform
            .transform_point2(uvs[self.uv_set as usize & 1]);
        self.texture.bilinear_level(0, uv, self.wrap)
    }
}

/// One channel of an RGBA texel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    /// Red.
    R,
    /// Green.
    G,
    /// Blue.
    B,
    /// Alpha.
    A,
}

impl Channel {
    /// The channel's value in `v`.
    #[inline]
    pub fn of(self, v: Vec4) -> f32 {
        match self {
            Channel::R => v.x,
            Channel::G => v.y,
            Channel::B => v.z,
            Channel::A => v.w,
        }
    }
}

/// A scalar parameter read from one channel of a texture.
#[derive(Clone, Debug, PartialEq)]
pub struct ScalarMap {
    /// The texture and how it is read.
    pub map: TextureMap,
    /// The channel holding the value.
    pub channel: Channel,
}

impl ScalarMap {
    /// Channel `channel` of `map`.
    pub fn new(map: TextureMap, channel: Channel) -> Self {
        Self { map, channel }
    }

    /// The value at the hit.
    #[inline]
    pub fn lookup(&self, uvs: &[Vec2; 2], footprint: &UvFootprint) -> f32 {
        self.channel.of(self.map.lookup(uvs, footprint))
    }
}
