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

    /// Bounds of the vertices that triangles use.
    pub fn bounds(&self) -> Aabb {
        self.indices
            .iter()
            .flatten()
            .fold(Aabb::EMPTY, |b, &i| b.grow(self.positions[i as usize]))
    }
}
