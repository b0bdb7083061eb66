//! The plain triangle mesh every mesh reader returns.

use glam::Vec3;

/// An indexed triangle mesh as read from a file: plain data, no renderer
/// types (the scene assembly moves both vectors into its own mesh type).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles as three indices into `positions`, in file order.
    pub indices: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }
}
