//! Scene generators shared by the integration tests (meshes made in code).

#![allow(dead_code)]

use glam::Vec3;
use sahara_kd::Triangle;

/// A closed UV sphere: `rings` x `segments` quads split into triangles, the
/// poles as fans; vertices are shared exactly between neighbours.
pub fn uv_sphere(center: Vec3, radius: f32, rings: usize, segments: usize) -> Vec<Triangle> {
    let mut pts = vec![center + Vec3::Y * radius];
    for r in 1..rings {
        let th = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..segments {
            let ph = 2.0 * std::f32::consts::PI * s as f32 / segments as f32;
            pts.push(
                center + radius * Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()),
            );
        }
    }
    pts.push(center - Vec3::Y * radius);
    let idx = |r: usize, s: usize| 1 + (r - 1) * segments + s % segments;
    let south = pts.len() - 1;
    let mut tris = Vec::new();
    for s in 0..segments {
        tris.push(Triangle::new(pts[0], pts[idx(1, s + 1)], pts[idx(1, s)]));
        tris.push(Triangle::new(
            pts[south],
            pts[idx(rings - 1, s)],
            pts[idx(rings - 1, s + 1)],
        ));
    }
    for r in 1..rings - 1 {
        for s in 0..segments {
            let (a, b, c, d) = (idx(r, s), idx(r, s + 1), idx(r + 1, s + 1), idx(r + 1, s));
            tris.push(Triangle::new(pts[a], pts[b], pts[c]));
            tris.push(Triangle::new(pts[a], pts[c], pts[d]));
        }
    }
    tris
}

/// A closed cube `[lo, hi]^3` whose faces are `n x n` grids of quads, each
/// split into two triangles: many vertices and edges lie exactly on the
/// planes a kd-tree splits at.
pub fn subdivided_cube(lo: f32, hi: f32, n: usize) -> Vec<Triangle> {
    let mut tris = Vec::new();
    let coord = |i: usize| lo + (hi - lo) * i as f32 / n as f32;
    for axis in 0..3 {
        for &side in &[lo, hi] {
            for i in 0..n {
                for j in 0..n {
                    let p = |a: usize, b: usize| {
                        let mut v = Vec3::ZERO;
                        v[axis] = side;
                        v[(axis + 1) % 3] = coord(a);
                        v[(axis + 2) % 3] = coord(b);
                        v
                    };
                    let (a, b, c, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
                    tris.push(Triangle::new(a, b, c));
                    tris.push(Triangle::new(a, c, d));
                }
            }
        }
    }
    tris
}

/// A deterministic xorshift generator for tests that need many rays.
pub struct Rng(pub u64);

impl Rng {
    /// The next value in [0, 1).
    pub fn f32(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A uniformly distributed unit vector.
    pub fn dir(&mut self) -> Vec3 {
        let z = 1.0 - 2.0 * self.f32();
        let phi = 2.0 * std::f32::consts::PI * self.f32();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}
