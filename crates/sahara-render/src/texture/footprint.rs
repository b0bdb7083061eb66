//! How large a texture lookup's footprint is: the MIP level it needs.
//!
//! Sahara estimates footprints the way pbrt-v4 does for rays without
//! differentials: at every hit, camera ray or not, the surface is taken to
//! be seen from the camera, and the footprint is where two rays one pixel
//! apart (in angle, at the image centre) from the eye towards the hit meet
//! the hit's tangent plane. For camera rays of a pinhole camera that is
//! the exact ray-differential footprint (but for the small change of the
//! pixel angle away from the image centre); after a bounce it stands for
//! the blur the bounce adds, which ray differentials would track only
//! through specular bounces anyway. It needs nothing carried along the
//! path (the batched render loop keeps paths small), and it is the same
//! for every sample of a pixel, so a pixel's samples are filtered alike.
//!
//! The pixel angle is scaled by `max(1/8, 1/sqrt(spp))`: the pixel's
//! samples already average the texture over the pixel, so each lookup
//! only needs to cover the distance between samples. The footprint in
//! texels is the longer axis of the projected pixel, but at most 8 times
//! the shorter one (pbrt's largest anisotropy): at grazing angles the
//! samples across the pixel do the rest of the averaging, rather than an
//! isotropic filter blurring the texture along both axes.

use glam::{Affine2, Vec2, Vec3};

use super::Texture;

/// Longest footprint axis over the shortest that a lookup filters.
pub const MAX_ANISOTROPY: f32 = 8.0;

/// The camera as texture lookups see it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSpread {
    /// Centre of projection.
    pub eye: Vec3,
    /// Angle between neighbouring lookups, radians: the pixel angle at
    /// the image centre times the samples-per-pixel scale.
    pub angle: f32,
}

impl CameraSpread {
    /// The spread of a pinhole camera at `eye` with vertical field of view
    /// `vfov_deg` over `height` pixels, `spp` samples per pixel.
    pub fn new(eye: Vec3, vfov_deg: f32, height: u32, spp: u64) -> Self {
        let pixel = 2.0 * (0.5 * vfov_deg.to_radians()).tan() / height.max(1) as f32;
        let scale = (1.0 / (spp.max(1) as f32).sqrt()).max(0.125);
        Self {
            eye,
            angle: pixel * scale,
        }
    }

    /// The offsets to the neighbouring lookups' points from `p` on the
    /// plane through `p` with normal `n` (`None` where a neighbouring ray
    /// misses that plane: the surface is seen edge-on).
    pub fn surface_offsets(&self, p: Vec3, n: Vec3) -> Option<[Vec3; 2]> {
        let v = p - self.eye;
        let dist = v.length();
        if !(dist > 0.0 && dist.is_finite() && self.angle > 0.0) {
            return None;
        }
        let w = v / dist;
        // The footprint's axes: along the surface's slope as seen from
        // the eye (the stretched one) and across it.
        let slope = n - w * n.dot(w);
        let (a, b) = if slope.length_squared() > 1e-12 {
            let a = slope.normalize();
            (a, w.cross(a))
        } else {
            w.any_orthonormal_pair()
        };
        let vn = v.dot(n);
        let mut out = [Vec3::ZERO; 2];
        for (o, side) in out.iter_mut().zip([a, b]) {
            let d = w + side * self.angle;
            let denom = d.dot(n);
            let t = vn / denom;
            if !(t.is_finite() && t > 0.0) {
                return None;
            }
            *o = self.eye + d * t - p;
        }
        Some(out)
    }
}

/// The derivatives of each uv set along the two footprint axes at a hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvFootprint {
    /// `[set][axis]`: the change of uv set `set` between the hit and its
    /// neighbouring lookup along `axis`.
    pub d: [[Vec2; 2]; 2],
}

impl UvFootprint {
    /// A point-sized footprint: lookups read the finest level.
    pub const POINT: UvFootprint = UvFootprint {
        d: [[Vec2::ZERO; 2]; 2],
    };

    /// The footprint of the triangle with corners `p` (world space) and uv
    /// sets `uv[set]` for surface offsets `offsets` (from
    /// `CameraSpread::surface_offsets`): uv is an affine function on the
    /// triangle's plane, whose gradient takes each offset to its change
    /// of uv.
    pub fn on_triangle(p: [Vec3; 3], uv: [[Vec2; 3]; 2], offsets: [Vec3; 2]) -> Self {
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let n = e1.cross(e2);
        let n2 = n.length_squared();
        if !(n2 > 0.0 && n2.is_finite()) {
            return Self::POINT;
        }
        // The dual basis of (e1, e2) in the plane: b1.e1 = 1, b1.e2 = 0,
        // b2.e1 = 0, b2.e2 = 1.
        let b1 = e2.cross(n) / n2;
        let b2 = n.cross(e1) / n2;
        let mut d = [[Vec2::ZERO; 2]; 2];
        for (set, t) in uv.iter().enumerate() {
            let (du1, du2) = (t[1] - t[0], t[2] - t[0]);
            for (axis, o) in offsets.iter().enumerate() {
                let g = du1 * b1.dot(*o) + du2 * b2.dot(*o);
                d[set][axis] = if g.is_finite() { g } else { Vec2::ZERO };
            }
        }
        Self { d }
    }

    /// The footprint's width in level-0 texels of `texture` read through
    /// `transform` from uv set `set`: the longer axis, but at most
    /// `MAX_ANISOTROPY` times the shorter.
    #[inline]
    pub fn texels(&self, set: usize, transform: &Affine2, texture: &Texture) -> f32 {
        let size = Vec2::new(texture.width as f32, texture.height as f32);
        let [a, b] = self.d[set].map(|d| (transform.matrix2 * d * size).length());
        let (major, minor) = if a > b { (a, b) } else { (b, a) };
        minor.max(major / MAX_ANISOTROPY)
    }
}
