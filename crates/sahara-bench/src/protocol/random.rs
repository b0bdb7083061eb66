//! The `random` set: origins uniform in the bounding box, directions uniform
//! on the sphere.

use glam::Vec3;
use sahara_kd::Ray;

use super::arith::sub;
use super::frame::SceneFrame;
use super::splitmix::SplitMix64;
use super::RANDOM_SEED_OFFSET;

/// The `i`-th random ray: generator seeded by `i + 0x9E3779B9`; draws
/// `u1, u2` give the direction (`z = 1 - 2 u1`, `phi = 2 pi u2`), draws
/// `u3, u4, u5` the origin `min + (u3, u4, u5) * extent`.
pub fn random_ray(frame: &SceneFrame, i: u64) -> Ray {
    let mut g = SplitMix64::new(i + RANDOM_SEED_OFFSET);
    let u1 = g.next_f32();
    let u2 = g.next_f32();
    let u3 = g.next_f32();
    let u4 = g.next_f32();
    let u5 = g.next_f32();
    let z = 1.0 - 2.0 * u1;
    let phi = 2.0 * std::f32::consts::PI * u2;
    let sr = 0.0f32.max(1.0 - z * z).sqrt();
    let ext = sub(frame.max, frame.min);
    let origin = Vec3::new(
        frame.min.x + u3 * ext.x,
        frame.min.y + u4 * ext.y,
        frame.min.z + u5 * ext.z,
    );
    let dir = Vec3::new(sr * phi.cos(), sr * phi.sin(), z);
    Ray::with_interval(origin, dir, 0.0, f32::INFINITY)
}

/// The first `count` random rays (the protocol uses
/// [`super::RANDOM_RAYS`]), by ray index.
pub fn random_rays(frame: &SceneFrame, count: usize) -> Vec<Ray> {
    (0..count as u64).map(|i| random_ray(frame, i)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ray_zero_from_hand_computed_draws() {
        // Ray 0's draws (Python, see splitmix.rs): top-24-bit integers
        // 4575833, 4574272, 6174549, 7426833, 15216930 over 2^24.
        let frame = SceneFrame::from_bounds(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 2.0, 4.0));
        let r = random_ray(&frame, 0);
        let u: Vec<f64> = [4575833u32, 4574272, 6174549, 7426833, 15216930]
            .iter()
            .map(|&k| k as f64 / 16_777_216.0)
            .collect();
        let z = 1.0 - 2.0 * u[0];
        let phi = 2.0 * std::f64::consts::PI * u[1];
        let sr = (1.0 - z * z).sqrt();
        let want_dir = [sr * phi.cos(), sr * phi.sin(), z];
        let want_org = [-1.0 + u[2] * 4.0, u[3] * 2.0, 2.0 + u[4] * 2.0];
        for a in 0..3 {
            assert!((r.dir[a] as f64 - want_dir[a]).abs() < 1e-6, "{:?}", r.dir);
            assert!(
                (r.origin[a] as f64 - want_org[a]).abs() < 1e-6,
                "{:?}",
                r.origin
            );
        }
        assert_eq!((r.tmin, r.tmax), (0.0, f32::INFINITY));
    }

    #[test]
    fn rays_are_unit_inside_the_box_and_indexed() {
        let frame = SceneFrame::from_bounds(Vec3::splat(-2.0), Vec3::splat(5.0));
        let rays = random_rays(&frame, 1000);
        assert_eq!(rays.len(), 1000);
        let mut mean = Vec3::ZERO;
        for (i, r) in rays.iter().enumerate() {
            assert_eq!(*r, random_ray(&frame, i as u64));
            assert!((r.dir.length() - 1.0).abs() < 1e-5);
            assert!(r.origin.cmpge(frame.min).all() && r.origin.cmple(frame.max).all());
            mean += r.dir;
        }
        // Uniform on the sphere: the mean direction is near zero.
        assert!((mean / 1000.0).length() < 0.1);
    }
}
