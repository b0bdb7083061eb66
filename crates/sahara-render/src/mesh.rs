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

    /// Bounds of the vertices that triangles use.
    pub fn bounds(&self) -> Aabb {
        self.indices
            .iter()
            .flatten()
            .fold(Aabb::EMPTY, |b, &i| b.grow(self.positions[i as usize]))
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
