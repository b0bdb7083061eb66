//! An indexed triangle mesh: vertex positions and triangles as indices,
//! the form meshes are read and kept in before they become the triangle
//! soup a tree is built over ([`Mesh::triangles`]).

use glam::Vec3;

use super::{Aabb, Triangle};

/// An indexed triangle mesh as two plain arrays; a tree is built over
/// [`Mesh::triangles`].
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
