//! Helpers shared by the crate's unit tests.

use glam::Vec3;

use crate::math::Triangle;

/// A deterministic xorshift stream of floats in [-1, 1).
pub fn floats(seed: u64) -> impl FnMut() -> f32 {
    let mut s = seed;
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 40) as f32 / (1u64 << 23) as f32 - 1.0
    }
}

/// `n` random triangles with corners within `size` of centres in a cube of
/// half-width 4.
pub fn soup(f: &mut impl FnMut() -> f32, n: usize, size: f32) -> Vec<Triangle> {
    (0..n)
        .map(|_| {
            let c = Vec3::new(f(), f(), f()) * 4.0;
            Triangle::new(
                c,
                c + Vec3::new(f(), f(), f()) * size,
                c + Vec3::new(f(), f(), f()) * size,
            )
        })
        .collect()
}
