//! The scene quantities the protocol derives from the mesh's bounding box:
//! centre `c`, half diagonal `r`, offset `eps` and the point light `L`.

use glam::Vec3;
use sahara_kd::Mesh;

use super::arith::{add, len, mul, sub};
use super::ProtocolError;

/// Bounding box of the vertices that triangles use, and what the protocol
/// derives from it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneFrame {
    /// Lower corner of the box.
    pub min: Vec3,
    /// Upper corner of the box.
    pub max: Vec3,
    /// Centre `c = (min + max) * 0.5`.
    pub center: Vec3,
    /// Length of the diagonal.
    pub diag: f32,
    /// Half the diagonal, `r = 0.5 * diag`.
    pub radius: f32,
    /// Offset of secondary ray origins along the normal, `1e-5 * diag`.
    pub eps: f32,
}

impl SceneFrame {
    /// The frame of a mesh. The box is grown as the reference does it
    /// (strict comparisons, vertices in index order), so even the sign of a
    /// zero corner agrees.
    pub fn from_mesh(mesh: &Mesh) -> Result<Self, ProtocolError> {
        check_mesh(mesh)?;
        let mut min = Vec3::splat(f32::INFINITY);
        let mut max = Vec3::splat(f32::NEG_INFINITY);
        for &i in mesh.indices.iter().flatten() {
            let p = mesh.positions[i as usize];
            for a in 0..3 {
                if p[a] < min[a] {
                    min[a] = p[a];
                }
                if p[a] > max[a] {
                    max[a] = p[a];
                }
            }
        }
        Ok(Self::from_bounds(min, max))
    }

    /// The frame of a given box.
    pub fn from_bounds(min: Vec3, max: Vec3) -> Self {
        let center = mul(add(min, max), 0.5);
        let diag = len(sub(max, min));
        Self {
            min,
            max,
            center,
            diag,
            radius: 0.5 * diag,
            eps: 1e-5 * diag,
        }
    }

    /// The point light of the `shadow` set:
    /// `L = c + (0, 1.5 r, 0) + 0.5 r (1, 0, 0.5)`.
    pub fn light(&self) -> Vec3 {
        let r = self.radius;
        add(
            add(self.center, Vec3::new(0.0, 1.5 * r, 0.0)),
            mul(Vec3::new(1.0, 0.0, 0.5), 0.5 * r),
        )
    }
}

/// Check that the mesh has triangles and that every index is in range.
pub fn check_mesh(mesh: &Mesh) -> Result<(), ProtocolError> {
    if mesh.indices.is_empty() {
        return Err(ProtocolError::EmptyMesh);
    }
    let n = mesh.positions.len();
    for (t, tri) in mesh.indices.iter().enumerate() {
        if let Some(&v) = tri.iter().find(|&&v| v as usize >= n) {
            return Err(ProtocolError::BadIndex {
                triangle: t,
                vertex: v,
                vertices: n,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_covers_only_used_vertices() {
        let mesh = Mesh {
            positions: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(0.0, 4.0, 4.0),
                Vec3::new(100.0, -100.0, 100.0), // unused
            ],
            indices: vec![[0, 1, 2]],
        };
        let f = SceneFrame::from_mesh(&mesh).unwrap();
        assert_eq!(f.min, Vec3::ZERO);
        assert_eq!(f.max, Vec3::new(2.0, 4.0, 4.0));
        assert_eq!(f.center, Vec3::new(1.0, 2.0, 2.0));
        assert_eq!(f.diag, 6.0);
        assert_eq!(f.radius, 3.0);
        assert_eq!(f.eps, 1e-5_f32 * 6.0);
        // L = c + (0, 4.5, 0) + (1.5, 0, 0.75)
        assert_eq!(f.light(), Vec3::new(2.5, 6.5, 2.75));
    }

    #[test]
    fn bad_meshes_are_errors() {
        let empty = Mesh::default();
        assert!(matches!(
            SceneFrame::from_mesh(&empty),
            Err(ProtocolError::EmptyMesh)
        ));
        let bad = Mesh {
            positions: vec![Vec3::ZERO; 3],
            indices: vec![[0, 1, 2], [0, 1, 3]],
        };
        assert!(matches!(
            SceneFrame::from_mesh(&bad),
            Err(ProtocolError::BadIndex {
                triangle: 1,
                vertex: 3,
                vertices: 3
            })
        ));
    }
}
