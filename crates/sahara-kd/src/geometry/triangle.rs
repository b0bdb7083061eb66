//! Triangles and the watertight ray/triangle test.

use glam::Vec3;

use super::{Aabb, Ray};

/// A triangle given by its three vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// The vertices, in winding order.
    pub v: [Vec3; 3],
}

/// Where a ray meets a triangle: distance and barycentrics, with the hit
/// point `(1 - u - v) v0 + u v1 + v v2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Barycentric weight of `v1`.
    pub u: f32,
    /// Barycentric weight of `v2`.
    pub v: f32,
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
        (b - a).cross(c - a) != glam::DVec3::ZERO
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

/// Per-ray constants of the watertight test (Woop, Benthin, Wald 2013,
/// "Watertight Ray/Triangle Intersection", JCGT 2(1)): the dimension `kz`
/// where the direction is largest, and the shear that maps the ray onto +z.
#[derive(Clone, Copy, Debug)]
pub struct RayShear {
    /// Ray origin.
    pub origin: Vec3,
    /// Permuted axes: `kx`, `ky`, `kz`.
    pub k: [usize; 3],
    /// Shear constants `(dx/dz, dy/dz, 1/dz)` in the permuted frame.
    pub s: Vec3,
}

impl RayShear {
    /// Precompute the shear for a ray direction.
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        let a = dir.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        // Swap to preserve the winding (and so the sign of the edge functions).
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let s = Vec3::new(dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
        Self {
            origin,
            k: [kx, ky, kz],
            s,
        }
    }

    /// Shear precomputation for a [`Ray`].
    pub fn from_ray(ray: &Ray) -> Self {
        Self::new(ray.origin, ray.dir)
    }

    /// The watertight test: the hit with `t` in `[tmin, tmax]`, or `None`.
    ///
    /// This is the reference test: every query of the crate and the
    /// brute-force oracle call it, so a kd-tree and brute force compute the
    /// same bits for the same (ray, triangle) pair. Edges shared by two
    /// triangles are never missed: the edge functions are evaluated from the
    /// same sheared vertices, and an exact zero is re-evaluated in f64 as the
    /// paper prescribes. Back faces are not culled.
    #[inline(always)]
    pub fn intersect(&self, tri: &Triangle, tmin: f32, tmax: f32) -> Option<TriangleHit> {
        let [kx, ky, kz] = self.k;
        let a = tri.v[0] - self.origin;
        let b = tri.v[1] - self.origin;
        let c = tri.v[2] - self.origin;
        let ax = a[kx] - self.s.x * a[kz];
        let ay = a[ky] - self.s.y * a[kz];
        let bx = b[kx] - self.s.x * b[kz];
        let by = b[ky] - self.s.y * b[kz];
        let cx = c[kx] - self.s.x * c[kz];
        let cy = c[ky] - self.s.y * c[kz];

        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            // Edge hit: decide it in double precision (paper, section 3).
            let (ax, ay, bx, by, cx, cy) = (
                ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64,
            );
            u = (cx * by - cy * bx) as f32;
            v = (ax * cy - ay * cx) as f32;
            w = (bx * ay - by * ax) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let az = self.s.z * a[kz];
        let bz = self.s.z * b[kz];
        let cz = self.s.z * c[kz];
        let t_scaled = u * az + v * bz + w * cz;
        let rcp = 1.0 / det;
        let t = t_scaled * rcp;
        // Written so that NaN fails the test.
        if !(t >= tmin && t <= tmax) {
            return None;
        }
        Some(TriangleHit {
            t,
            u: v * rcp,
            v: w * rcp,
        })
    }
}

/// Convenience: the watertight test of one ray against one triangle.
pub fn intersect_ray_triangle(ray: &Ray, tri: &Triangle) -> Option<TriangleHit> {
    RayShear::from_ray(ray).intersect(tri, ray.tmin, ray.tmax)
}
