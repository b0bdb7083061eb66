//! RGB float images looked up with bilinear filtering and wrapping.

use glam::{Vec2, Vec3};

/// A linear RGB image supplied decoded by the caller.
///
/// Texture coordinates: `u` runs left to right, `v` bottom to top (OBJ and
/// OpenGL's convention); rows are stored from the top; both wrap.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Texels, row-major from the top-left corner.
    pub texels: Vec<Vec3>,
    /// Opacity per texel (same layout), if the image has an alpha channel.
    pub alpha: Option<Vec<f32>>,
}

impl Texture {
    /// A texture from its texels (`width * height` of them).
    pub fn new(width: u32, height: u32, texels: Vec<Vec3>) -> Self {
        assert_eq!(
            texels.len(),
            width as usize * height as usize,
            "texel count"
        );
        assert!(width > 0 && height > 0, "empty texture");
        Self {
            width,
            height,
            texels,
            alpha: None,
        }
    }

    /// This texture with an opacity channel (`width * height` values in
    /// `[0, 1]`).
    pub fn with_alpha(mut self, alpha: Vec<f32>) -> Self {
        assert_eq!(alpha.len(), self.texels.len(), "alpha count");
        self.alpha = Some(alpha);
        self
    }

    /// Bilinear lookup of the opacity at `uv` (1 without an alpha channel).
    pub fn alpha(&self, uv: Vec2) -> f32 {
        let Some(a) = &self.alpha else {
            return 1.0;
        };
        if !uv.is_finite() {
            return a[0];
        }
        let (w, h) = (self.width as i64, self.height as i64);
        let at = |x: i64, y: i64| a[(y.rem_euclid(h) * w + x.rem_euclid(w)) as usize];
        let x = uv.x.rem_euclid(1.0) * self.width as f32 - 0.5;
        let y = (1.0 - uv.y).rem_euclid(1.0) * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = at(x0, y0) + (at(x0 + 1, y0) - at(x0, y0)) * fx;
        let bottom = at(x0, y0 + 1) + (at(x0 + 1, y0 + 1) - at(x0, y0 + 1)) * fx;
        top + (bottom - top) * fy
    }

    /// The texel at integer coordinates, wrapped.
    #[inline]
    pub fn texel(&self, x: i64, y: i64) -> Vec3 {
        let x = x.rem_euclid(self.width as i64) as usize;
        let y = y.rem_euclid(self.height as i64) as usize;
        self.texels[y * self.width as usize + x]
    }

    /// Bilinear lookup at `uv` (texel centres at half-integer positions).
    pub fn bilinear(&self, uv: Vec2) -> Vec3 {
        if !uv.is_finite() {
            return self.texels[0];
        }
        let x = uv.x.rem_euclid(1.0) * self.width as f32 - 0.5;
        let y = (1.0 - uv.y).rem_euclid(1.0) * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = self.texel(x0, y0).lerp(self.texel(x0 + 1, y0), fx);
        let bottom = self.texel(x0, y0 + 1).lerp(self.texel(x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_interpolates_and_wraps() {
        let t = Texture::new(2, 1, vec![Vec3::ZERO, Vec3::ONE]);
        // Texel centres at u = 0.25 and 0.75.
        assert!((t.bilinear(Vec2::new(0.25, 0.5)) - Vec3::ZERO).length() < 1e-6);
        assert!((t.bilinear(Vec2::new(0.5, 0.5)) - Vec3::splat(0.5)).length() < 1e-6);
        // u = 0 lies halfway between the last texel and the first (wrap).
        assert!((t.bilinear(Vec2::new(0.0, 0.5)) - Vec3::splat(0.5)).length() < 1e-6);
        assert!((t.bilinear(Vec2::new(1.75, 0.5)) - Vec3::ONE).length() < 1e-6);
    }
}
