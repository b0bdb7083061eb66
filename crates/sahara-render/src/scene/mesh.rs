//! Triangle meshes as plain arrays.

use glam::Vec3;
use sahara_kd::{Aabb, Triangle};

/// An indexed triangle mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles as three indices into `positions`, in file order.
    pub indices: Vec<[u32; 3]>,
}

impl Mesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }

    /// The triangles as a soup, in index order (what the kd-tree takes).
    pub fn triangles(&self) -> Vec<Triangle> {
        Triangle::from_indexed(&self.positions, &self.indices)
    }

    /// The triangles no ray can hit, which the kd-tree skips: those with a
    /// corner missing or not finite, and those of zero area.
    pub fn skipped_counts(&self) -> (usize, usize) {
        let (mut non_finite, mut flat) = (0, 0);
        for t in &self.indices {
            let v = t.map(|k| self.positions.get(k as usize).copied().unwrap_or(Vec3::NAN));
            if !v.iter().all(|p| p.is_finite()) {
                non_finite += 1;
            } else if !Triangle::new(v[0], v[1], v[2]).is_hittable() {
                flat += 1;
            }
        }
        (non_finite, flat)
    }

    /// Number of triangles no ray can hit (a corner missing, not finite, or
    /// zero area): the kd-tree skips them.
    pub fn unhittable_count(&self) -> usize {
        self.indices
            .iter()
            .filter(|t| {
                let v = t.map(|k| self.positions.get(k as usize).copied().unwrap_or(Vec3::NAN));
                !Triangle::new(v[0], v[1], v[2]).is_hittable()
            })
            .count()
    }

    /// Bounds of the vertices of the triangles whose three corners are
    /// finite (a triangle with a NaN or infinite corner is skipped by the
    /// kd-tree, and must not stretch the scene's bounds to infinity).
    pub fn bounds(&self) -> Aabb {
        self.indices
            .iter()
            .filter_map(|t| {
                let v = t.map(|k| self.positions.get(k as usize).copied().unwrap_or(Vec3::NAN));
                v.iter().all(|p| p.is_finite()).then_some(v)
            })
            .flatten()
            .fold(Aabb::EMPTY, |b, p| b.grow(p))
    }
}

/// A mesh with the optional attributes rendering uses beside positions.
///
/// Kept apart from [`Mesh`] so that the plain geometry type other crates
/// build stays two arrays.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneMesh {
    /// Positions and triangles.
    pub mesh: Mesh,
    /// Per-vertex shading normals (parallel to `mesh.positions`).
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates (parallel to `mesh.positions`).
    pub uvs: Option<Vec<glam::Vec2>>,
    /// A second set of per-vertex texture coordinates, which textures
    /// may read instead (glTF's `TEXCOORD_1`).
    pub uvs1: Option<Vec<glam::Vec2>>,
    /// Per-vertex tangents for normal maps (parallel to
    /// `mesh.positions`): `xyz` the direction of increasing `u` of the uv
    /// set the normal map reads, `w` (+1 or -1) the handedness, the
    /// bitangent being `w * normal x tangent` (glTF's `TANGENT`;
    /// [`SceneMesh::generate_tangents`] makes them).
    pub tangents: Option<Vec<glam::Vec4>>,
    /// Per-triangle material ids (parallel to `mesh.indices`); an
    /// instance's own material, when set, takes precedence.
    pub material_ids: Option<Vec<u32>>,
}

impl From<Mesh> for SceneMesh {
    fn from(mesh: Mesh) -> Self {
        Self {
            mesh,
            ..Self::default()
        }
    }
}

impl SceneMesh {
    /// Checks that the attribute arrays have the right lengths and indices
    /// are in range; returns a description of the first problem.
    pub fn validate(&self) -> Result<(), String> {
        let nv = self.mesh.positions.len();
        if let Some(i) = self
            .mesh
            .indices
            .iter()
            .flatten()
            .find(|&&i| i as usize >= nv)
        {
            return Err(format!("vertex index {i} out of range ({nv} vertices)"));
        }
        if self.normals.as_ref().is_some_and(|n| n.len() != nv) {
            return Err("normals: one per vertex expected".into());
        }
        if self.uvs.as_ref().is_some_and(|n| n.len() != nv) {
            return Err("uvs: one per vertex expected".into());
        }
        if self.uvs1.as_ref().is_some_and(|n| n.len() != nv) {
            return Err("uvs1: one per vertex expected".into());
        }
        if self.tangents.as_ref().is_some_and(|n| n.len() != nv) {
            return Err("tangents: one per vertex expected".into());
        }
        if self
            .material_ids
            .as_ref()
            .is_some_and(|m| m.len() != self.mesh.indices.len())
        {
            return Err("material_ids: one per triangle expected".into());
        }
        Ok(())
    }
}
