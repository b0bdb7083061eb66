//! Built-in shapes: quad, disc, sphere, box. Tessellated into meshes for
//! intersection; quads, discs and spheres keep their exact form for
//! analytic area-light sampling.

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

use crate::math::warp::Frame;
use crate::names::name_table;
use crate::scene::mesh::{Mesh, SceneMesh};

/// Segments of a tessellated disc's rim.
pub const DISC_SEGMENTS: u32 = 128;
/// Latitude bands of a tessellated sphere (longitudes: twice as many).
pub const SPHERE_BANDS: u32 = 64;

/// A built-in shape in world coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// The parallelogram `corner + s edge_u + t edge_v`, `s, t` in `[0, 1]`;
    /// front face towards `edge_u x edge_v`.
    Quad {
        /// One corner.
        corner: Vec3,
        /// First edge from the corner.
        edge_u: Vec3,
        /// Second edge from the corner.
        edge_v: Vec3,
    },
    /// A disc facing `normal`.
    Disc {
        /// Centre.
        center: Vec3,
        /// Unit front normal.
        normal: Vec3,
        /// Radius.
        radius: f32,
    },
    /// A sphere, front face outwards.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
    },
    /// An axis-aligned box, faces outwards.
    Box {
        /// Lower corner.
        min: Vec3,
        /// Upper corner.
        max: Vec3,
    },
}

/// The built-in shapes by name, without their parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShapeKind {
    /// [`Shape::Quad`].
    Quad,
    /// [`Shape::Disc`].
    Disc,
    /// [`Shape::Sphere`].
    Sphere,
    /// [`Shape::Box`].
    Box,
}

name_table!(ShapeKind, "shape", {
    ShapeKind::Quad => "quad",
    ShapeKind::Disc => "disc",
    ShapeKind::Sphere => "sphere",
    ShapeKind::Box => "box",
});

impl Shape {
    /// Which shape this is, without its parameters.
    pub fn kind(&self) -> ShapeKind {
        match self {
            Shape::Quad { .. } => ShapeKind::Quad,
            Shape::Disc { .. } => ShapeKind::Disc,
            Shape::Sphere { .. } => ShapeKind::Sphere,
            Shape::Box { .. } => ShapeKind::Box,
        }
    }

    /// Surface area of the exact shape.
    pub fn area(&self) -> f32 {
        match *self {
            Shape::Quad { edge_u, edge_v, .. } => edge_u.cross(edge_v).length(),
            Shape::Disc { radius, .. } => PI * radius * radius,
            Shape::Sphere { radius, .. } => 4.0 * PI * radius * radius,
            Shape::Box { min, max } => {
                let e = max - min;
                2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
            }
        }
    }

    /// True for the shapes whose emission is sampled analytically.
    pub fn has_analytic_sampling(&self) -> bool {
        !matches!(self, Shape::Box { .. })
    }

    /// The shape as a triangle mesh with normals and texture coordinates;
    /// triangle winding puts each front face towards its normal.
    pub fn to_mesh(&self) -> SceneMesh {
        let mut b = Builder::default();
        match *self {
            Shape::Quad {
                corner,
                edge_u,
                edge_v,
            } => b.quad(corner, edge_u, edge_v),
            Shape::Disc {
                center,
                normal,
                radius,
            } => {
                let f = Frame::from_normal(normal.normalize());
                let c = b.vertex(center, f.n, Vec2::splat(0.5));
                for i in 0..DISC_SEGMENTS {
                    let phi = 2.0 * PI * i as f32 / DISC_SEGMENTS as f32;
                    let (s, co) = phi.sin_cos();
                    let p = center + radius * (f.s * co + f.t * s);
                    b.vertex(p, f.n, Vec2::new(0.5 + 0.5 * co, 0.5 + 0.5 * s));
                }
                for i in 0..DISC_SEGMENTS {
                    let j = (i + 1) % DISC_SEGMENTS;
                    // s x t = n: counter-clockwise about n faces n.
                    b.tri(c, c + 1 + i, c + 1 + j);
                }
            }
            Shape::Sphere { center, radius } => {
                let (nt, np) = (SPHERE_BANDS, 2 * SPHERE_BANDS);
                for i in 0..=nt {
                    let theta = PI * i as f32 / nt as f32;
                    for j in 0..=np {
                        let phi = 2.0 * PI * j as f32 / np as f32;
                        let n = Vec3::new(
                            theta.sin() * phi.cos(),
                            theta.cos(),
                            theta.sin() * phi.sin(),
                        );
                        let uv = Vec2::new(j as f32 / np as f32, 1.0 - i as f32 / nt as f32);
                        b.vertex(center + radius * n, n, uv);
                    }
                }
                let row = np + 1;
                for i in 0..nt {
                    for j in 0..np {
                        let a = i * row + j;
                        let (c, d) = (a + row, a + 1);
                        // Skip the degenerate triangles at the poles.
                        if i != 0 {
                            b.tri(a, d, c);
                        }
                        if i != nt - 1 {
                            b.tri(d, c + 1, c);
                        }
                    }
                }
            }
            Shape::Box { min, max } => {
                let e = max - min;
                let (x, y, z) = (Vec3::X * e.x, Vec3::Y * e.y, Vec3::Z * e.z);
                b.quad(min, y, x); // -z
                b.quad(min + z, x, y); // +z
                b.quad(min, z, y); // -x
                b.quad(min + x, y, z); // +x
                b.quad(min, x, z); // -y
                b.quad(min + y, z, x); // +y
            }
        }
        b.finish()
    }
}

#[derive(Default)]
struct Builder {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    indices: Vec<[u32; 3]>,
}

impl Builder {
    fn vertex(&mut self, p: Vec3, n: Vec3, uv: Vec2) -> u32 {
        self.positions.push(p);
        self.normals.push(n);
        self.uvs.push(uv);
        self.positions.len() as u32 - 1
    }

    fn tri(&mut self, a: u32, b: u32, c: u32) {
        self.indices.push([a, b, c]);
    }

    fn quad(&mut self, corner: Vec3, eu: Vec3, ev: Vec3) {
        let n = eu.cross(ev).normalize_or_zero();
        let a = self.vertex(corner, n, Vec2::new(0.0, 0.0));
        self.vertex(corner + eu, n, Vec2::new(1.0, 0.0));
        self.vertex(corner + eu + ev, n, Vec2::new(1.0, 1.0));
        self.vertex(corner + ev, n, Vec2::new(0.0, 1.0));
        self.tri(a, a + 1, a + 2);
        self.tri(a, a + 2, a + 3);
    }

    fn finish(self) -> SceneMesh {
        SceneMesh {
            mesh: Mesh {
                positions: self.positions,
                indices: self.indices,
            },
            normals: Some(self.normals),
            uvs: Some(self.uvs),
            uvs1: None,
            tangents: None,
            material_ids: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn winding_normals_agree(m: &SceneMesh) {
        let n = m.normals.as_ref().unwrap();
        for t in &m.mesh.indices {
            let p = t.map(|i| m.mesh.positions[i as usize]);
            let g = (p[1] - p[0]).cross(p[2] - p[0]);
            assert!(g.length() > 0.0, "degenerate triangle");
            assert!(
                g.dot(n[t[0] as usize]) > 0.0,
                "winding disagrees with normal"
            );
        }
    }

    #[test]
    fn tessellations_face_their_normals_and_approximate_the_area() {
        let shapes = [
            Shape::Quad {
                corner: Vec3::ZERO,
                edge_u: Vec3::X,
                edge_v: Vec3::Z * 2.0,
            },
            Shape::Disc {
                center: Vec3::ONE,
                normal: -Vec3::Y,
                radius: 2.0,
            },
            Shape::Sphere {
                center: Vec3::ONE,
                radius: 3.0,
            },
            Shape::Box {
                min: Vec3::ZERO,
                max: Vec3::new(1.0, 2.0, 3.0),
            },
        ];
        for s in shapes {
            let m = s.to_mesh();
            winding_normals_agree(&m);
            let area: f32 = m
                .mesh
                .triangles()
                .iter()
                .map(|t| 0.5 * t.double_area())
                .sum();
            assert!(
                (area / s.area() - 1.0).abs() < 2e-3,
                "{s:?}: {area} vs {}",
                s.area()
            );
        }
    }
}
