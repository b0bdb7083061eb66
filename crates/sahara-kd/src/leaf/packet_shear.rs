//! One triangle against eight rays at once: the edge test of a packet.
//!
//! The block test (`triangle_block`) puts eight triangles in the lanes and
//! one ray in the scalars; a packet's leaf test turns that around and puts
//! eight rays in the lanes. It needs the rays to share the watertight test's
//! axis permutation `k` (then only the origin and shear constants differ
//! from lane to lane), which coherent camera rays almost always do. As with
//! the block test, each lane repeats exactly the f32 operations of
//! [`RayShear::intersect`], so a lane it drops is one the scalar test
//! rejects, and [`RayShear::decide`] finishes the lanes it keeps: results
//! stay bit-identical to the single-ray test.
//!
//! Why: a leaf of `c` triangles costs a packet of `a` live rays
//! `a * ceil(c / 8)` block tests but only `c` packet tests; camera rays meet
//! leaves of two to four triangles on the shared meshes (`sahara bench
//! --counters`), where the packet test does a half to a quarter of the work.

use super::edges::edge_lanes;
#[cfg(target_arch = "x86_64")]
use super::edges::{edge_lanes_avx2, sheared_avx2};
use super::BLOCK_WIDTH;
use crate::isect::RayShear;
use crate::math::Triangle;

const _: () = assert!(
    RAYS == BLOCK_WIDTH,
    "the packet test reuses the block's 8-lane edge step"
);

/// Rays per packet test.
pub const RAYS: usize = 8;

use crate::simd::lanes::Lanes;

/// The shear constants of up to eight rays that share one permutation.
#[derive(Clone, Copy, Debug)]
pub struct PacketShear {
    /// The shared permutation `kx`, `ky`, `kz`.
    pub k: [usize; 3],
    /// Origins in the permuted frame: `o[kx]`, `o[ky]`, `o[kz]` per lane.
    o: [Lanes; 3],
    /// `dx/dz` per lane.
    sx: Lanes,
    /// `dy/dz` per lane.
    sy: Lanes,
}

impl PacketShear {
    /// The packet form of `shears` (at most eight; missing lanes are
    /// copies of the first), or `None` if their permutations differ.
    pub fn new(shears: &[RayShear]) -> Option<Self> {
        let first = shears.first()?;
        if shears.len() > RAYS || shears.iter().any(|s| s.k != first.k) {
            return None;
        }
        let [kx, ky, kz] = first.k;
        let mut p = Self {
            k: first.k,
            o: [[0.0; RAYS]; 3],
            sx: [0.0; RAYS],
            sy: [0.0; RAYS],
        };
        for l in 0..RAYS {
            let s = shears.get(l).unwrap_or(first);
            p.o[0][l] = s.origin[kx];
            p.o[1][l] = s.origin[ky];
            p.o[2][l] = s.origin[kz];
            p.sx[l] = s.s.x;
            p.sy[l] = s.s.y;
        }
        Some(p)
    }

    /// The packet form of rays that share the permutation `k`, from their
    /// origins along `kx`, `ky`, `kz` and their constants `sx`, `sy` by
    /// lane (what [`PacketShear::new`] gathers from `RayShear`s).
    #[inline(always)]
    pub fn from_lanes(k: [usize; 3], o: [Lanes; 3], sx: Lanes, sy: Lanes) -> Self {
        Self { k, o, sx, sy }
    }

    /// One vertex (coordinates `p`) moved to each ray's origin and sheared,
    /// as `RayShear::sheared` does for one ray.
    #[inline(always)]
    fn sheared(&self, p: [f32; 3]) -> (Lanes, Lanes) {
        let [kx, ky, kz] = self.k;
        let (px, py, pz) = (p[kx], p[ky], p[kz]);
        let mut x = [0.0f32; RAYS];
        let mut y = [0.0f32; RAYS];
        for l in 0..RAYS {
            let z = pz - self.o[2][l];
            x[l] = (px - self.o[0][l]) - self.sx[l] * z;
            y[l] = (py - self.o[1][l]) - self.sy[l] * z;
        }
        (x, y)
    }

    /// Triangle `tri` against the eight rays: the rays the
    /// watertight test may accept, as a bit mask (bit `l` = ray `l`), and
    /// their edge functions `[u, v, w]` for [`RayShear::decide`].
    #[inline(always)]
    pub fn triangle_edges(&self, tri: &Triangle) -> (u32, [Lanes; 3]) {
        let vertex = |k: usize| tri.v[k].to_array();
        // Lanes are rays here; the step is the block test's, lane for lane.
        edge_lanes(
            self.sheared(vertex(0)),
            self.sheared(vertex(1)),
            self.sheared(vertex(2)),
        )
    }
}

#[cfg(target_arch = "x86_64")]
impl PacketShear {
    /// [`PacketShear::triangle_edges`] in AVX2 intrinsics (the same
    /// results).
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn triangle_edges_avx2(&self, tri: &Triangle) -> (u32, [Lanes; 3]) {
        // SAFETY: AVX2 (this function's target feature).
        unsafe { self.triangle_edges_intrinsics(|k, axis| tri.v[k][axis]) }
    }

    /// The body of [`PacketShear::triangle_edges_avx2`], always inlined
    /// into the packet traversal (compiled as a function, it was left out
    /// of line once the leaf test existed for two leaf layouts).
    ///
    /// # Safety
    /// The CPU must have AVX2, and the caller must be compiled for it.
    #[inline(always)]
    /// `vertex(k, axis)` is coordinate `axis` of the triangle's vertex `k`
    /// (read straight from a leaf block: building a `Triangle` first cost
    /// the packets a few percent).
    pub(crate) unsafe fn triangle_edges_intrinsics(
        &self,
        vertex: impl Fn(usize, usize) -> f32,
    ) -> (u32, [Lanes; 3]) {
        use std::arch::x86_64::*;
        let [kx, ky, kz] = self.k;
        // SAFETY: eight f32 per row; AVX2 (the caller's contract).
        unsafe {
            let o = [
                _mm256_loadu_ps(self.o[0].as_ptr()),
                _mm256_loadu_ps(self.o[1].as_ptr()),
                _mm256_loadu_ps(self.o[2].as_ptr()),
            ];
            let (sx, sy) = (
                _mm256_loadu_ps(self.sx.as_ptr()),
                _mm256_loadu_ps(self.sy.as_ptr()),
            );
            // Written out: `array::map` with intrinsics stayed a call.
            let v = &vertex;
            let a = [
                _mm256_set1_ps(v(0, kx)),
                _mm256_set1_ps(v(0, ky)),
                _mm256_set1_ps(v(0, kz)),
            ];
            let b = [
                _mm256_set1_ps(v(1, kx)),
                _mm256_set1_ps(v(1, ky)),
                _mm256_set1_ps(v(1, kz)),
            ];
            let c = [
                _mm256_set1_ps(v(2, kx)),
                _mm256_set1_ps(v(2, ky)),
                _mm256_set1_ps(v(2, kz)),
            ];
            edge_lanes_avx2(
                sheared_avx2(a, o, sx, sy),
                sheared_avx2(b, o, sx, sy),
                sheared_avx2(c, o, sx, sy),
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::leaf::TriangleBlock;
    use crate::math::Ray;
    use crate::test_support::floats;
    use glam::Vec3;

    /// Every lane gives what the block test gives for that ray: the same
    /// keep bit and the same edge functions, bit for bit.
    #[test]
    fn packet_lanes_equal_block_lanes() {
        let mut f = floats(31);
        let mut compared = 0;
        for _ in 0..500 {
            let tris: Vec<Triangle> = (0..BLOCK_WIDTH)
                .map(|_| {
                    let c = Vec3::new(f(), f(), f() + 3.0);
                    Triangle::new(
                        c + Vec3::new(f(), f(), f()) * 0.5,
                        c + Vec3::new(f(), f(), f()) * 0.5,
                        c + Vec3::new(f(), f(), f()) * 0.5,
                    )
                })
                .collect();
            let block = TriangleBlock::pack(&tris);
            let eye = Vec3::new(f(), f(), -1.0);
            let shears: Vec<RayShear> = (0..RAYS)
                .map(|_| {
                    let r = Ray::new(
                        eye + Vec3::new(f(), f(), 0.0) * 0.1,
                        Vec3::new(f() * 0.3, f() * 0.3, 1.0),
                    );
                    RayShear::from_ray(&r)
                })
                .collect();
            let p = PacketShear::new(&shears).expect("all rays have kz = z");
            for lane in 0..BLOCK_WIDTH {
                let (m, e) = p.triangle_edges(&tris[lane]);
                #[cfg(target_arch = "x86_64")]
                if crate::simd::has_avx2() {
                    // SAFETY: the CPU has AVX2.
                    let (m2, e2) = unsafe { p.triangle_edges_avx2(&tris[lane]) };
                    assert_eq!(m, m2);
                    assert_eq!(
                        e.map(|r| r.map(f32::to_bits)),
                        e2.map(|r| r.map(f32::to_bits))
                    );
                }
                for (l, s) in shears.iter().enumerate() {
                    let (bm, be) = s.block_edges(&block, BLOCK_WIDTH);
                    assert_eq!(m >> l & 1, bm >> lane & 1, "ray {l} triangle {lane}");
                    for k in 0..3 {
                        assert_eq!(e[k][l].to_bits(), be[k][lane].to_bits());
                    }
                    compared += (bm >> lane & 1) as usize;
                }
            }
        }
        assert!(compared > 200, "{compared} kept lanes compared");
    }

    #[test]
    fn mixed_permutations_are_refused() {
        let a = RayShear::new(Vec3::ZERO, Vec3::Z);
        let b = RayShear::new(Vec3::ZERO, Vec3::X);
        assert!(PacketShear::new(&[a, a]).is_some());
        assert!(PacketShear::new(&[a, b]).is_none());
        assert!(PacketShear::new(&[]).is_none());
    }
}
