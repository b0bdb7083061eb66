//! The protocol's pinhole camera and its primary rays.

use glam::Vec3;
use sahara_kd::Ray;

use super::arith::{add, cross, mul, normalize, sub};
use super::frame::SceneFrame;

/// The image the primary rays sample, pixel `(x, y)` with `y = 0` the top row.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageSize {
    /// Width in pixels, `W`.
    pub width: u32,
    /// Height in pixels, `H`.
    pub height: u32,
}

impl ImageSize {
    /// The protocol's image, 1024 x 1024.
    pub const PROTOCOL: ImageSize = ImageSize {
        width: 1024,
        height: 1024,
    };

    /// Number of pixels.
    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }
}

impl Default for ImageSize {
    fn default() -> Self {
        Self::PROTOCOL
    }
}

/// A camera as the protocol (and a `<name>.camera.json` sidecar) gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProtocolCamera {
    /// Eye point.
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Up vector (need not be unit or orthogonal to the view direction).
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub vfov_deg: f32,
}

/// The orthonormal view frame derived from a [`ProtocolCamera`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraBasis {
    /// Forward, `f = normalize(target - eye)`.
    pub forward: Vec3,
    /// Right, `s = normalize(cross(f, up))`.
    pub right: Vec3,
    /// Up, `u = cross(s, f)`.
    pub up: Vec3,
    /// `h = tan(vfov / 2)`.
    pub tan_half_fov: f32,
}

/// `vfov_deg * pi / 180 * 0.5` in the reference's f32 order.
fn half_angle(vfov_deg: f32) -> f32 {
    vfov_deg * std::f32::consts::PI / 180.0 * 0.5
}

impl ProtocolCamera {
    /// The protocol's camera for a mesh without a sidecar: vfov 45, up
    /// `(0, 1, 0)`, looking at `c` from
    /// `c + normalize(0.3, 0.5, 1.0) * r / sin(vfov / 2)`.
    pub fn auto(frame: &SceneFrame) -> Self {
        let vfov_deg = 45.0;
        let distance = frame.radius / half_angle(vfov_deg).sin();
        Self {
            eye: add(
                frame.center,
                mul(normalize(Vec3::new(0.3, 0.5, 1.0)), distance),
            ),
            target: frame.center,
            up: Vec3::new(0.0, 1.0, 0.0),
            vfov_deg,
        }
    }

    /// The view frame.
    pub fn basis(&self) -> CameraBasis {
        let forward = normalize(sub(self.target, self.eye));
        let right = normalize(cross(forward, self.up));
        CameraBasis {
            forward,
            right,
            up: cross(right, forward),
            tan_half_fov: half_angle(self.vfov_deg).tan(),
        }
    }

    /// The primary ray through the centre of pixel `(x, y)`, over `[0, inf)`.
    pub fn primary_ray(&self, basis: &CameraBasis, image: ImageSize, x: u32, y: u32) -> Ray {
        let (w, h) = (image.width as f32, image.height as f32);
        let t = basis.tan_half_fov;
        // C: (2.0f * (x + 0.5f) / W - 1.0f) * h * ((float)W / H), all in float.
        let a = (2.0 * (x as f32 + 0.5) / w - 1.0) * t * (w / h);
        let b = (1.0 - 2.0 * (y as f32 + 0.5) / h) * t;
        let d = normalize(add(
            add(basis.forward, mul(basis.right, a)),
            mul(basis.up, b),
        ));
        Ray::with_interval(self.eye, d, 0.0, f32::INFINITY)
    }

    /// The `primary` set: one ray per pixel centre, in pixel order
    /// `y * W + x`.
    pub fn primary_rays(&self, image: ImageSize) -> Vec<Ray> {
        let basis = self.basis();
        let mut rays = Vec::with_capacity(image.pixels());
        for y in 0..image.height {
            for x in 0..image.width {
                rays.push(self.primary_ray(&basis, image, x, y));
            }
        }
        rays
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sahara_kd::Mesh;

    fn quad_mesh() -> Mesh {
        // A unit square in the plane z = 0, two triangles.
        Mesh {
            positions: vec![
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(1.0, -1.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(-1.0, 1.0, 0.0),
            ],
            indices: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
        (a - b).abs().max_element() <= tol
    }

    #[test]
    fn auto_camera_formula() {
        let frame = SceneFrame::from_bounds(Vec3::ZERO, Vec3::new(2.0, 4.0, 4.0));
        let cam = ProtocolCamera::auto(&frame);
        // Independently, in f64: c = (1, 2, 2), r = 3, distance r / sin(22.5 deg).
        let dist = 3.0 / (22.5f64.to_radians()).sin();
        let k = (0.3f64 * 0.3 + 0.5 * 0.5 + 1.0).sqrt();
        let want = [
            1.0 + 0.3 / k * dist,
            2.0 + 0.5 / k * dist,
            2.0 + 1.0 / k * dist,
        ];
        for a in 0..3 {
            assert!(
                (cam.eye[a] as f64 - want[a]).abs() < 1e-5 * dist,
                "eye {:?} want {:?}",
                cam.eye,
                want
            );
        }
        assert_eq!(cam.target, frame.center);
        assert_eq!(cam.up, Vec3::Y);
        assert_eq!(cam.vfov_deg, 45.0);
        // The bounding sphere (radius r about c) just fills the vertical fov.
        let d = (cam.eye - cam.target).length() as f64;
        assert!(((3.0 / d).asin().to_degrees() - 22.5).abs() < 1e-4);
    }

    #[test]
    fn basis_is_orthonormal_and_right_handed() {
        let cam = ProtocolCamera {
            eye: Vec3::new(1.0, 2.0, 3.0),
            target: Vec3::new(-2.0, 0.5, 0.0),
            up: Vec3::new(0.0, 2.0, 0.0),
            vfov_deg: 60.0,
        };
        let b = cam.basis();
        for v in [b.forward, b.right, b.up] {
            assert!((v.length() - 1.0).abs() < 1e-6);
        }
        assert!(b.forward.dot(b.right).abs() < 1e-6);
        assert!(b.forward.dot(b.up).abs() < 1e-6);
        assert!(b.up.dot(Vec3::Y) > 0.0);
        assert!(close(b.right.cross(b.up), -b.forward, 1e-6));
        assert!((b.tan_half_fov - (30f32).to_radians().tan()).abs() < 1e-6);
    }

    #[test]
    fn centre_pixel_of_an_odd_image_looks_at_the_target() {
        let mesh = quad_mesh();
        let frame = SceneFrame::from_mesh(&mesh).unwrap();
        let cam = ProtocolCamera::auto(&frame);
        let image = ImageSize {
            width: 5,
            height: 5,
        };
        let rays = cam.primary_rays(image);
        assert_eq!(rays.len(), 25);
        let centre = rays[2 * 5 + 2];
        // a = b = 0 exactly, so d = normalize(f) with f = normalize(target - eye).
        let f = normalize(sub(cam.target, cam.eye));
        assert_eq!(centre.dir, normalize(f));
        assert!(close(centre.dir, (cam.target - cam.eye).normalize(), 1e-7));
        // It reaches the target (the quad's centre) at distance |target - eye|.
        let t = (cam.target - cam.eye).length();
        assert!(close(centre.at(t), cam.target, 1e-5 * t));
        assert_eq!(centre.origin, cam.eye);
        assert_eq!((centre.tmin, centre.tmax), (0.0, f32::INFINITY));
    }

    #[test]
    fn centre_between_pixels_of_an_even_image_is_symmetric() {
        let cam = ProtocolCamera {
            eye: Vec3::new(0.0, 0.0, 5.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            vfov_deg: 90.0,
        };
        let image = ImageSize {
            width: 4,
            height: 4,
        };
        let rays = cam.primary_rays(image);
        let at = |x: usize, y: usize| rays[y * 4 + x].dir;
        // The four pixels around the centre average to the view direction.
        let mean = (at(1, 1) + at(2, 1) + at(1, 2) + at(2, 2)) * 0.25;
        assert!(close(mean.normalize(), Vec3::NEG_Z, 1e-6));
        // Mirror symmetry left/right and top/bottom.
        for y in 0..4 {
            for x in 0..4 {
                let d = at(x, y);
                let m = at(3 - x, y);
                assert_eq!((d.x, d.y, d.z), (-m.x, m.y, m.z));
                let v = at(x, 3 - y);
                assert_eq!((d.x, d.y, d.z), (v.x, -v.y, v.z));
            }
        }
        // y = 0 is the top row, x = 0 the left column; right is +x here.
        assert!(at(0, 0).y > 0.0 && at(0, 0).x < 0.0);
        // h = tan(45 deg) = 1: pixel (0, 0) has a = -0.75, b = 0.75.
        let d = at(0, 0);
        assert!(close(d, Vec3::new(-0.75, 0.75, -1.0).normalize(), 1e-6));
    }

    #[test]
    fn protocol_image_order_is_row_major() {
        let cam = ProtocolCamera {
            eye: Vec3::ZERO,
            target: Vec3::NEG_Z,
            up: Vec3::Y,
            vfov_deg: 45.0,
        };
        let basis = cam.basis();
        let rays = cam.primary_rays(ImageSize::PROTOCOL);
        assert_eq!(rays.len(), 1024 * 1024);
        for (x, y) in [(0, 0), (1023, 0), (5, 7), (1023, 1023)] {
            assert_eq!(
                rays[y as usize * 1024 + x as usize],
                cam.primary_ray(&basis, ImageSize::PROTOCOL, x, y)
            );
        }
        // The top row looks up by almost vfov / 2: atan(1023/1024 tan 22.5deg).
        let top = rays[511].dir;
        let want = ((1023.0f64 / 1024.0) * 22.5f64.to_radians().tan()).atan();
        let got = (top.y as f64).atan2(-top.z as f64);
        assert!((got - want).abs() < 1e-6, "{got} vs {want}");
    }
}
