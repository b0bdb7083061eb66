//! The reference program's f32 vector arithmetic, one IEEE operation at a
//! time in its order: `dot` is `x*x' + y*y' + z*z'` left to right and
//! `normalize` divides each component by the length (no reciprocal).
//!
//! Written out rather than taken from `glam` so that the operation order is
//! fixed here, whatever `glam` does internally.

use glam::Vec3;

/// `a + b`.
#[inline]
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    Vec3::new(a.x + b.x, a.y + b.y, a.z + b.z)
}

/// `a - b`.
#[inline]
pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    Vec3::new(a.x - b.x, a.y - b.y, a.z - b.z)
}

/// `a * s`, component by component.
#[inline]
pub fn mul(a: Vec3, s: f32) -> Vec3 {
    Vec3::new(a.x * s, a.y * s, a.z * s)
}

/// `a.x*b.x + a.y*b.y + a.z*b.z`, summed left to right.
#[inline]
pub fn dot(a: Vec3, b: Vec3) -> f32 {
    a.x * b.x + a.y * b.y + a.z * b.z
}

/// The cross product, each component as `p*q - r*s` in the reference's order.
#[inline]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    Vec3::new(
        a.y * b.z - a.z * b.y,
        a.z * b.x - a.x * b.z,
        a.x * b.y - a.y * b.x,
    )
}

/// `sqrt(dot(a, a))`.
#[inline]
pub fn len(a: Vec3) -> f32 {
    dot(a, a).sqrt()
}

/// `a / len(a)`, dividing each component.
#[inline]
pub fn normalize(a: Vec3) -> Vec3 {
    let l = len(a);
    Vec3::new(a.x / l, a.y / l, a.z / l)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalize_divides_rather_than_multiplying_by_a_reciprocal() {
        // 1/3 is not exact, so x * (1/l) and x / l can differ; check that
        // normalize agrees with division on a case where they do differ.
        let v = Vec3::new(1.0, 1.0, 1.0);
        let l = len(v);
        let n = normalize(v);
        assert_eq!(n.x, 1.0 / l);
        let mut found = false;
        for i in 1..2000 {
            let x = i as f32 * 0.37;
            let w = Vec3::new(x, 1.0, 0.5);
            let l = len(w);
            if x / l != x * (1.0 / l) {
                assert_eq!(normalize(w).x, x / l);
                found = true;
                break;
            }
        }
        assert!(found, "some value must tell division from reciprocal");
    }

    #[test]
    fn cross_and_dot_of_axes() {
        assert_eq!(cross(Vec3::X, Vec3::Y), Vec3::Z);
        assert_eq!(cross(Vec3::Y, Vec3::Z), Vec3::X);
        assert_eq!(
            dot(Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, 5.0, 6.0)),
            32.0
        );
    }
}
