//! Perspective cameras: pinhole and thin lens, with a shutter interval.

use glam::{Vec2, Vec3};
use sahara_kd::Ray;

use crate::math::warp::concentric_disc;

/// A perspective camera.
///
/// Right-handed: `right = forward x up`, so with forward +Z and up +Y the
/// image's right is world -X. Raster coordinates run from the top-left
/// corner, x right and y down.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Centre of projection (centre of the lens).
    pub eye: Vec3,
    /// Unit viewing direction.
    pub forward: Vec3,
    /// Unit image-right direction.
    pub right: Vec3,
    /// Unit image-up direction.
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub vfov_deg: f32,
    /// Width over height of the image.
    pub aspect: f32,
    /// Radius of the lens aperture (0: pinhole, everything sharp).
    pub lens_radius: f32,
    /// Distance of the plane in focus, along `forward`.
    pub focus_distance: f32,
    /// Shutter opening time.
    pub shutter_open: f32,
    /// Shutter closing time.
    pub shutter_close: f32,
}

impl Camera {
    /// A pinhole camera at `eye` looking at `target`, focused on the target.
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, vfov_deg: f32, aspect: f32) -> Self {
        let forward = (target - eye).normalize();
        let right = forward.cross(up).normalize();
        let up = right.cross(forward);
        Self {
            eye,
            forward,
            right,
            up,
            vfov_deg,
            aspect,
            lens_radius: 0.0,
            focus_distance: (target - eye).dot(forward),
            shutter_open: 0.0,
            shutter_close: 1.0,
        }
    }

    /// This camera with a thin lens of `aperture_radius` focused at
    /// `focus_distance` (depth of field).
    pub fn with_thin_lens(mut self, aperture_radius: f32, focus_distance: f32) -> Self {
        self.lens_radius = aperture_radius.max(0.0);
        self.focus_distance = focus_distance;
        self
    }

    /// This camera with the shutter open over `[open, close]`.
    pub fn with_shutter(mut self, open: f32, close: f32) -> Self {
        self.shutter_open = open;
        self.shutter_close = close.max(open);
        self
    }

    /// Half the height of the image plane at unit distance.
    pub fn tan_half_fov(&self) -> f32 {
        (self.vfov_deg.to_radians() * 0.5).tan()
    }

    /// The ray through normalised film position `film` (`[0, 1]^2`, from the
    /// top-left corner), lens sample `lens` and time sample `u_time`, with
    /// its time. The direction is unit length.
    pub fn generate_ray(&self, film: Vec2, lens: Vec2, u_time: f32) -> (Ray, f32) {
        let th = self.tan_half_fov();
        let sx = (2.0 * film.x - 1.0) * th * self.aspect;
        let sy = (1.0 - 2.0 * film.y) * th;
        // Pinhole direction scaled so that its forward component is 1.
        let d = self.forward + self.right * sx + self.up * sy;
        let time = self.shutter_open + (self.shutter_close - self.shutter_open) * u_time;
        if self.lens_radius <= 0.0 {
            return (Ray::new(self.eye, d.normalize()), time);
        }
        // Thin lens: every ray through the lens meets the pinhole ray on the
        // plane at focus_distance.
        let focus = self.eye + d * self.focus_distance;
        let l = concentric_disc(lens) * self.lens_radius;
        let origin = self.eye + self.right * l.x + self.up * l.y;
        (Ray::new(origin, (focus - origin).normalize()), time)
    }

    /// Fraction of the shutter interval at `time`, in `[0, 1]` (0 for an
    /// instantaneous shutter).
    pub fn shutter_fraction(&self, time: f32) -> f32 {
        let len = self.shutter_close - self.shutter_open;
        if len > 0.0 {
            ((time - self.shutter_open) / len).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positive_x_is_on_the_left_when_looking_down_z() {
        let c = Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, 60.0, 1.0);
        let (left, _) = c.generate_ray(Vec2::new(0.1, 0.5), Vec2::ZERO, 0.0);
        let (top, _) = c.generate_ray(Vec2::new(0.5, 0.1), Vec2::ZERO, 0.0);
        assert!(left.dir.x > 0.0);
        assert!(top.dir.y > 0.0);
    }

    #[test]
    fn vertical_fov_spans_the_image_height() {
        let c = Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, 90.0, 2.0);
        let (top, _) = c.generate_ray(Vec2::new(0.5, 0.0), Vec2::ZERO, 0.0);
        assert!((top.dir.angle_between(Vec3::Z).to_degrees() - 45.0).abs() < 1e-3);
        let (side, _) = c.generate_ray(Vec2::new(0.0, 0.5), Vec2::ZERO, 0.0);
        assert!((side.dir.x / side.dir.z - 2.0).abs() < 1e-5);
    }
}
