//! Tangents for normal maps, by the MikkTSpace rules (Mikkelsen 2008),
//! which is how Blender, Substance and xNormal bake normal maps and what
//! glTF asks for when a file has no `TANGENT`.
//!
//! The algorithm gives a tangent per triangle corner; corners of one
//! vertex that get different tangents (across a uv seam, or a mirrored
//! half of a model) make the vertex split in two, so that the mesh keeps
//! one tangent per vertex.

use std::collections::HashMap;

use bevy_mikktspace::{generate_tangents, Geometry, TangentSpace};
use glam::{Vec2, Vec3, Vec4};

use crate::scene::mesh::SceneMesh;

/// The mesh as the algorithm reads it, and its answers per corner.
struct Corners<'a> {
    mesh: &'a SceneMesh,
    uvs: &'a [Vec2],
    out: Vec<Option<Vec4>>,
}

impl Corners<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.mesh.mesh.indices[face][vert] as usize
    }

    fn corner(&self, face: usize) -> [Vec3; 3] {
        self.mesh.mesh.indices[face].map(|i| {
            let p = self.mesh.mesh.positions[i as usize];
            if p.is_finite() {
                p
            } else {
                Vec3::ZERO
            }
        })
    }
}

impl Geometry for Corners<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.mesh.indices.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.corner(face)[vert].to_array()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        let n = match &self.mesh.normals {
            Some(n) => n[self.vertex(face, vert)],
            None => {
                let [a, b, c] = self.corner(face);
                (b - a).cross(c - a)
            }
        };
        let n = n.normalize_or_zero();
        if n.is_finite() { n } else { Vec3::ZERO }.to_array()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let t = self.uvs[self.vertex(face, vert)];
        if t.is_finite() { t } else { Vec2::ZERO }.to_array()
    }

    fn set_tangent(&mut self, t: Option<TangentSpace>, face: usize, vert: usize) {
        self.out[face * 3 + vert] = t.map(|t| Vec4::from_array(t.tangent_encoded()));
    }
}

impl SceneMesh {
    /// Gives the mesh MikkTSpace tangents for uv set `uv_set` (0 or 1),
    /// splitting the vertices whose corners disagree. Returns false (and
    /// changes nothing) if the mesh has no such uv set. Per-triangle data
    /// is unchanged; vertices are only appended.
    pub fn generate_tangents(&mut self, uv_set: u8) -> bool {
        let uvs = match uv_set {
            0 => self.uvs.as_deref(),
            _ => self.uvs1.as_deref(),
        };
        let Some(uvs) = uvs else {
            return false;
        };
        let mut c = Corners {
            mesh: self,
            uvs,
            out: vec![None; self.mesh.indices.len() * 3],
        };
        // The error type has no values: generation always succeeds.
        if generate_tangents(&mut c).is_err() {
            return false;
        }
        let corners = c.out;
        let nv = self.mesh.positions.len();
        let mut tangents: Vec<Option<Vec4>> = vec![None; nv];
        let mut split: HashMap<(u32, [u32; 4]), u32> = HashMap::new();
        for (k, t) in corners.into_iter().enumerate() {
            // A corner the algorithm gave up on (a degenerate triangle
            // without neighbours) takes any tangent: no ray hits it.
            let t = t.unwrap_or(Vec4::new(1.0, 0.0, 0.0, 1.0));
            let (tri, corner) = (k / 3, k % 3);
            let v = self.mesh.indices[tri][corner];
            match tangents[v as usize] {
                None => tangents[v as usize] = Some(t),
                Some(old) if old == t => {}
                Some(_) => {
                    let key = (v, t.to_array().map(f32::to_bits));
                    let copy = *split.entry(key).or_insert_with(|| {
                        let copy = self.mesh.positions.len() as u32;
                        self.duplicate_vertex(v as usize);
                        tangents.push(Some(t));
                        copy
                    });
                    self.mesh.indices[tri][corner] = copy;
                }
            }
        }
        self.tangents = Some(
            tangents
                .into_iter()
                .map(|t| t.unwrap_or(Vec4::new(1.0, 0.0, 0.0, 1.0)))
                .collect(),
        );
        true
    }

    /// Appends a copy of vertex `v` with all its attributes.
    fn duplicate_vertex(&mut self, v: usize) {
        self.mesh.positions.push(self.mesh.positions[v]);
        for a in [&mut self.uvs, &mut self.uvs1].into_iter().flatten() {
            a.push(a[v]);
        }
        if let Some(n) = &mut self.normals {
            n.push(n[v]);
        }
    }
}
