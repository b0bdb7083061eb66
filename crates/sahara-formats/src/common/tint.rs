//! Tints, as the pbrt and Mitsuba readers both map them: a
//! colour times at most one image ([`Tint`]), an opacity image folded into
//! a colour texture's alpha ([`with_opacity`]).

use std::sync::Arc;

use glam::{Affine2, Vec3};
use sahara_render::{Texture, TextureMap, Wrap};

/// A colour, optionally times an image.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Tint {
    /// The constant factor.
    pub(crate) color: Vec3,
    /// The image (linear RGB), if any.
    pub(crate) image: Option<Arc<Texture>>,
    /// How the image is read.
    pub(crate) sampling: Sampling,
}

/// How an image texture is read: pbrt's `wrap` and its `uv` mapping's
/// scale and offset.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Sampling {
    /// The wrap mode along both axes.
    pub(crate) wrap: Wrap,
    /// `(u, v)` to `(uscale u + udelta, vscale v + vdelta)`.
    pub(crate) transform: Affine2,
}

impl Sampling {
    /// The texture map reading `texture` this way.
    pub(crate) fn map(self, texture: Arc<Texture>) -> TextureMap {
        TextureMap::new(texture)
            .with_wrap(self.wrap, self.wrap)
            .with_transform(self.transform)
    }
}

impl Tint {
    /// A constant.
    pub(crate) fn constant(c: Vec3) -> Self {
        Self {
            color: c,
            image: None,
            sampling: Sampling::default(),
        }
    }

    /// The texture map a Sahara material holds for this tint (see
    /// [`Tint::baked`]), read as the image says.
    pub(crate) fn map(&self) -> Option<TextureMap> {
        self.baked().map(|t| self.sampling.map(t))
    }

    /// The map of the image alone, without the colour, if there is one.
    pub(crate) fn image_map(&self) -> Option<TextureMap> {
        self.image.clone().map(|t| self.sampling.map(t))
    }

    /// The texture a Sahara material holds for this tint: the image with
    /// the colour multiplied in, a 1 x 1 image of a colour other than
    /// white, or none for white.
    pub(crate) fn baked(&self) -> Option<Arc<Texture>> {
        match &self.image {
            Some(t) if self.color == Vec3::ONE => Some(t.clone()),
            Some(t) => {
                let texels = t.texels().map(|v| v * self.color).collect();
                Some(Arc::new(with_alpha_of(
                    t,
                    Texture::new(t.width, t.height, texels),
                )))
            }
            None if self.color == Vec3::ONE => None,
            None => Some(Arc::new(Texture::new(1, 1, vec![self.color]))),
        }
    }

    /// The mean value (the image's mean texel times the colour).
    pub(crate) fn mean(&self) -> Vec3 {
        match &self.image {
            Some(t) => self.color * t.mean(),
            None => self.color,
        }
    }
}

/// `base` (a material's colour texture, or white) with the opacity of
/// `alpha`'s image (its red channel) as its alpha channel, on the grid of
/// the larger of the two; the other is looked up bilinearly at its texel
/// centres.
pub(crate) fn with_opacity(base: Option<&Arc<Texture>>, alpha: &Texture) -> Arc<Texture> {
    let white;
    let base = match base {
        Some(b) => b.as_ref(),
        None => {
            white = Texture::new(1, 1, vec![Vec3::ONE]);
            &white
        }
    };
    let grid = if texel_count(base) >= texel_count(alpha) {
        base
    } else {
        alpha
    };
    let (w, h) = (grid.width, grid.height);
    let mut texels = Vec::with_capacity(texel_count(grid));
    let mut opacity = Vec::with_capacity(texel_count(grid));
    for y in 0..h {
        for x in 0..w {
            let uv = glam::Vec2::new(
                (x as f32 + 0.5) / w as f32,
                1.0 - (y as f32 + 0.5) / h as f32,
            );
            let at = |t: &Texture| {
                if t.width == w && t.height == h {
                    t.texel(x.into(), y.into())
                } else {
                    t.bilinear(uv)
                }
            };
            texels.push(at(base));
            opacity.push(at(alpha).x.clamp(0.0, 1.0));
        }
    }
    Arc::new(Texture::new(w, h, texels).with_alpha(opacity))
}

/// Texels in level 0 of `t`.
pub(crate) fn texel_count(t: &Texture) -> usize {
    t.width as usize * t.height as usize
}

/// The alpha channel of `t`'s level 0, if it has one.
pub(crate) fn alpha_of(t: &Texture) -> Option<Vec<f32>> {
    t.has_alpha()
        .then(|| t.texels_rgba().map(|v| v.w).collect())
}

/// `out` (a texture on `src`'s grid) with `src`'s alpha channel, if it has
/// one.
pub(crate) fn with_alpha_of(src: &Texture, out: Texture) -> Texture {
    match alpha_of(src) {
        Some(a) => out.with_alpha(a),
        None => out,
    }
}
