//! Triangle meshes as plain arrays: [`Mesh`] is `sahara-kd`'s (the one mesh
//! type readers, renderer and benchmarks share), [`SceneMesh`] adds what
//! rendering uses beside positions.

use glam::Vec3;
pub use sahara_kd::Mesh;

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
