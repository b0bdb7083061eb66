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

    /// Area of the image rectangle on the plane at unit distance in front
    /// of the eye.
    fn image_plane_area(&self) -> f32 {
        let th = self.tan_half_fov();
        4.0 * th * th * self.aspect
    }

    /// Area of the lens (1 for a pinhole, whose one point counts as a unit
    /// measure in importance and its densities, as in pbrt).
    fn lens_area(&self) -> f32 {
        if self.lens_radius > 0.0 {
            std::f32::consts::PI * self.lens_radius * self.lens_radius
        } else {
            1.0
        }
    }

    /// The normalised film position (`[0, 1]^2`, from the top-left corner)
    /// of the ray leaving lens point `lens` along unit `dir`, and the
    /// cosine of `dir` to the viewing direction; `None` if it misses the
    /// film. The inverse of [`Camera::generate_ray`].
    pub(crate) fn film_of(&self, lens: Vec3, dir: Vec3) -> Option<(Vec2, f32)> {
        let cos = dir.dot(self.forward);
        if cos <= 0.0 {
            return None;
        }
        // The pinhole direction through the same point of the plane in
        // focus (the ray itself for a pinhole).
        let d = if self.lens_radius > 0.0 {
            let focus = lens + dir * (self.focus_distance / cos);
            focus - self.eye
        } else {
            dir
        };
        let z = d.dot(self.forward);
        if z <= 0.0 {
            return None;
        }
        let th = self.tan_half_fov();
        let sx = d.dot(self.right) / z / (th * self.aspect);
        let sy = d.dot(self.up) / z / th;
        let film = Vec2::new(0.5 * (sx + 1.0), 0.5 * (1.0 - sy));
        ((0.0..1.0).contains(&film.x) && (0.0..1.0).contains(&film.y)).then_some((film, cos))
    }

    /// Importance of a ray leaving the lens at cosine `cos` to the
    /// viewing direction: `1 / (A lens_area cos^4)`, with `A` the image
    /// area at unit distance, so that it integrates to one over the film
    /// and the lens.
    fn importance(&self, cos: f32) -> f32 {
        let c2 = cos * cos;
        1.0 / (self.image_plane_area() * self.lens_area() * c2 * c2)
    }

    /// Solid-angle density with which [`Camera::generate_ray`] (uniform
    /// film positions) sends a ray along unit `dir` (from any lens point):
    /// `1 / (A cos^3)`, zero off the film.
    pub(crate) fn pdf_dir(&self, lens: Vec3, dir: Vec3) -> f32 {
        match self.film_of(lens, dir) {
            Some((_, cos)) => 1.0 / (self.image_plane_area() * cos * cos * cos),
            None => 0.0,
        }
    }

    /// The lens seen from `p`: a point on the lens (`u`; the eye for a
    /// pinhole), with the film position of the ray from it to `p` and the
    /// importance arriving along it, or `None` if that ray misses the film.
    pub(crate) fn sample_toward(&self, p: Vec3, u: Vec2) -> Option<LensSample> {
        let lens = if self.lens_radius > 0.0 {
            let l = concentric_disc(u) * self.lens_radius;
            self.eye + self.right * l.x + self.up * l.y
        } else {
            self.eye
        };
        let to_p = p - lens;
        let dist = to_p.length();
        if dist <= 0.0 || !dist.is_finite() {
            return None;
        }
        let dir = to_p / dist;
        let (film, cos) = self.film_of(lens, dir)?;
        Some(LensSample {
            film,
            lens,
            wi: -dir,
            dist,
            importance: self.importance(cos),
            pdf: dist * dist / (cos * self.lens_area()),
        })
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

/// The camera seen from a point (see [`Camera::sample_toward`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LensSample {
    /// Normalised film position of the ray.
    pub film: Vec2,
    /// The point on the lens.
    pub lens: Vec3,
    /// Unit direction from the point to the lens.
    pub wi: Vec3,
    /// Distance from the point to the lens.
    pub dist: f32,
    /// Importance `W_e` of the ray.
    pub importance: f32,
    /// Solid-angle density of `wi` at the point.
    pub pdf: f32,
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

    /// The lens seen from a point gives back the film position of the
    /// camera ray through that point, for a pinhole and a thin lens; and
    /// importance over the film integrates to one.
    #[test]
    fn sample_toward_inverts_generate_ray() {
        let pin = Camera::look_at(Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO, Vec3::Y, 50.0, 1.5);
        let lens = pin.with_thin_lens(0.2, 2.5);
        for c in [pin, lens] {
            for (film, u) in [
                (Vec2::new(0.3, 0.7), Vec2::new(0.1, 0.9)),
                (Vec2::new(0.95, 0.05), Vec2::new(0.5, 0.5)),
            ] {
                let (ray, _) = c.generate_ray(film, u, 0.0);
                let p = ray.origin + ray.dir * 1.7;
                let s = c.sample_toward(p, u).unwrap();
                assert!(
                    (s.film - film).abs().max_element() < 1e-4,
                    "{:?} {film}",
                    s.film
                );
                assert!((s.lens - ray.origin).length() < 1e-5);
                assert!((s.wi + ray.dir).length() < 1e-4);
            }
        }
        // Integral of W_e cos over directions through the film, by
        // uniform film positions: 1 = E[W_e cos / pdf_dir] = E[W_e / (pdf... )].
        let c = pin;
        let n = 200;
        let mut sum = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let film = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let (ray, _) = c.generate_ray(film, Vec2::ZERO, 0.0);
                let cos = ray.dir.dot(c.forward);
                sum += (c.importance(cos) * cos / c.pdf_dir(ray.origin, ray.dir)) as f64;
            }
        }
        let integral = sum / (n * n) as f64;
        assert!((integral - 1.0).abs() < 1e-3, "{integral}");
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
