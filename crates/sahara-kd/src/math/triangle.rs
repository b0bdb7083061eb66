//! Triangles: three vertices, their bounds and whether a ray can hit them.

use glam::{DVec3, Vec3};

use super::Aabb;

/// A triangle given by its three vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// The vertices, in winding order.
    pub v: [Vec3; 3],
}
impl Triangle {
    /// A triangle from three vertices.
    pub fn new(a: Vec3, b: Vec3, c: Vec3) -> Self {
        Self { v: [a, b, c] }
    }

    /// Triangles from an indexed mesh; indices must be in range.
    pub fn from_indexed(positions: &[Vec3], indices: &[[u32; 3]]) -> Vec<Triangle> {
        indices
            .iter()
            .map(|t| {
                Triangle::new(
                    positions[t[0] as usize],
                    positions[t[1] as usize],
                    positions[t[2] as usize],
                )
            })
            .collect()
    }

    /// The triangle's bounding box.
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(self.v)
    }

    /// True if every coordinate is finite. Triangles that are not are never
    /// hit and never stored in a tree.
    pub fn is_finite(&self) -> bool {
        self.v.iter().all(|p| p.is_finite())
    }

    /// True if the triangle can be hit: finite coordinates and a non-zero
    /// area. Only such triangles are stored in trees or hit by the oracle.
    ///
    /// A zero-area triangle (repeated or collinear vertices) has edge
    /// functions that are pure rounding noise, so the watertight test can
    /// report a "hit" with an arbitrary `t` on it; leaving such triangles out
    /// everywhere keeps every query well defined. The cross product is taken
    /// in f64, where it is exactly zero for exactly collinear f32 vertices
    /// (the two products of each component are equal and round alike).
    pub fn is_hittable(&self) -> bool {
        if !self.is_finite() {
            return false;
        }
        let [a, b, c] = self.v.map(|p| p.as_dvec3());
        (b - a).cross(c - a) != DVec3::ZERO
    }

    /// Twice the area (length of the edge cross product).
    pub fn double_area(&self) -> f32 {
        (self.v[1] - self.v[0])
            .cross(self.v[2] - self.v[0])
            .length()
    }

    /// The unnormalised geometric normal `(v1 - v0) x (v2 - v0)`.
    pub fn normal(&self) -> Vec3 {
        (self.v[1] - self.v[0]).cross(self.v[2] - self.v[0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_area_triangles_are_not_hittable() {
        let a = Vec3::new(-1.0, 1.447554, -2.0);
        let c = Vec3::new(-1.0, 0.0, 2.0);
        assert!(!Triangle::new(a, (a + c) * 0.5, c).is_hittable());
        assert!(!Triangle::new(a, a, c).is_hittable());
        assert!(!Triangle::new(a, c, Vec3::new(f32::NAN, 0.0, 0.0)).is_hittable());
        assert!(Triangle::new(a, c, Vec3::ZERO).is_hittable());
    }
}
