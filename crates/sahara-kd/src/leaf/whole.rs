//! The whole leaf layout: a leaf's triangles copied, in leaf order, into
//! blocks of [`BLOCK_WIDTH`] (structure of arrays), so that one leaf visit
//! reads contiguous memory instead of an index and then a triangle per
//! reference, and so that the block test (`ray_block`) computes the edge
//! functions of eight triangles at once.

use glam::Vec3;

use crate::math::Triangle;

/// Triangles per block.
pub const BLOCK_WIDTH: usize = crate::simd::lanes::WIDTH;

/// Up to eight triangles, coordinates by vertex, axis and lane.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct TriangleBlock {
    /// `v[vertex][axis][lane]`.
    pub v: [[[f32; BLOCK_WIDTH]; 3]; 3],
}

/// The triangles a run of a padded index array names (`u32::MAX` marks
/// padding), in order: what one leaf block holds, in either layout.
pub(crate) fn run_triangles(prims: &[Triangle], run: &[u32]) -> Vec<Triangle> {
    run.iter()
        .filter(|&&i| i != u32::MAX)
        .map(|&i| prims[i as usize])
        .collect()
}

impl TriangleBlock {
    /// A block of `tris` (at most eight); unused lanes are zero (and masked
    /// out by the lane count at test time).
    pub fn pack(tris: &[Triangle]) -> Self {
        assert!(tris.len() <= BLOCK_WIDTH, "{} triangles", tris.len());
        let mut v = [[[0.0; BLOCK_WIDTH]; 3]; 3];
        for (lane, t) in tris.iter().enumerate() {
            for (k, p) in t.v.iter().enumerate() {
                for axis in 0..3 {
                    v[k][axis][lane] = p[axis];
                }
            }
        }
        Self { v }
    }

    /// The triangle in `lane`, as it was packed.
    #[inline(always)]
    pub fn triangle(&self, lane: usize) -> Triangle {
        let p = |k: usize| Vec3::new(self.v[k][0][lane], self.v[k][1][lane], self.v[k][2][lane]);
        Triangle::new(p(0), p(1), p(2))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::floats;

    #[test]
    fn pack_round_trips() {
        let mut f = floats(7);
        let tris: Vec<Triangle> = (0..5)
            .map(|_| {
                Triangle::new(
                    Vec3::new(f(), f(), f()),
                    Vec3::new(f(), f(), f()),
                    Vec3::new(f(), f(), f()),
                )
            })
            .collect();
        let b = TriangleBlock::pack(&tris);
        for (i, t) in tris.iter().enumerate() {
            assert_eq!(b.triangle(i), *t);
        }
    }
}
