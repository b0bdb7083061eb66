//! The hierarchy's leaves: up to four triangles as structure-of-arrays
//! floats with their indices, and the watertight test of one ray against
//! the four at once.
//!
//! Four, not the kd-tree's eight: a leaf's box is what a wide node tests,
//! so small leaves make tight boxes, and a leaf of four is 160 bytes where
//! the kd-tree's block of eight is 288 (Embree and tinybvh's eight-wide
//! hierarchy use leaves of four too). The test is the kd-tree's block test
//! on four lanes: the same operations in the same order as
//! [`RayShear::intersect`], a filter that drops only lanes the scalar test
//! rejects early; the lanes it keeps are decided by the scalar test's own
//! last step ([`RayShear::decide`]), so hits are bit-identical to brute
//! force.

use glam::Vec3;

use crate::isect::RayShear;
use crate::math::Triangle;

/// Triangles per leaf.
pub(crate) const QUAD: usize = 4;

/// Up to four triangles and their indices (160 bytes; unused lanes are
/// zero and masked out by the leaf's count).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub(crate) struct Quad {
    /// `v[vertex][axis][lane]`.
    pub(crate) v: [[[f32; QUAD]; 3]; 3],
    /// The triangle index of each lane (`u32::MAX`: unused).
    pub(crate) tri: [u32; QUAD],
}

impl Quad {
    /// A leaf of `tris` (one to four) with indices `ids`.
    pub(crate) fn pack(tris: &[Triangle], ids: &[u32]) -> Self {
        assert!(!tris.is_empty() && tris.len() <= QUAD && tris.len() == ids.len());
        let mut q = Quad {
            v: [[[0.0; QUAD]; 3]; 3],
            tri: [u32::MAX; QUAD],
        };
        for (lane, (t, &i)) in tris.iter().zip(ids).enumerate() {
            for (k, p) in t.v.iter().enumerate() {
                for axis in 0..3 {
                    q.v[k][axis][lane] = p[axis];
                }
            }
            q.tri[lane] = i;
        }
        q
    }

    /// The triangle in `lane`.
    #[inline(always)]
    pub(crate) fn triangle(&self, lane: usize) -> Triangle {
        let p = |k: usize| Vec3::new(self.v[k][0][lane], self.v[k][1][lane], self.v[k][2][lane]);
        Triangle::new(p(0), p(1), p(2))
    }
}

/// The watertight test's edge functions `[u, v, w]` of four lanes and the
/// mask of the lanes (among the first `lanes`) the test may accept, as
/// `RayShear::block_edges` computes them for eight.
#[inline(always)]
pub(crate) fn quad_edges(shear: &RayShear, q: &Quad, lanes: usize) -> (u32, [[f32; QUAD]; 3]) {
    #[cfg(target_arch = "x86_64")]
    {
        // SAFETY: SSE2 is part of x86-64.
        unsafe { sse::quad_edges(&sse::QuadRay::new(shear), q, lanes) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    portable_edges(shear, q, lanes)
}

/// [`quad_edges`] as plain loops (the reference the SSE form is held to).
#[inline(always)]
#[cfg_attr(target_arch = "x86_64", allow(dead_code))]
pub(crate) fn portable_edges(shear: &RayShear, q: &Quad, lanes: usize) -> (u32, [[f32; QUAD]; 3]) {
    let [kx, ky, kz] = shear.k;
    let (ox, oy, oz) = (shear.origin[kx], shear.origin[ky], shear.origin[kz]);
    let (sx, sy) = (shear.s.x, shear.s.y);
    let sheared = |k: usize| {
        let mut x = [0.0f32; QUAD];
        let mut y = [0.0f32; QUAD];
        for l in 0..QUAD {
            let z = q.v[k][kz][l] - oz;
            x[l] = (q.v[k][kx][l] - ox) - sx * z;
            y[l] = (q.v[k][ky][l] - oy) - sy * z;
        }
        (x, y)
    };
    let ((ax, ay), (bx, by), (cx, cy)) = (sheared(0), sheared(1), sheared(2));
    let mut e = [[0.0f32; QUAD]; 3];
    let mut mask = 0u32;
    for l in 0..QUAD {
        let u = cx[l] * by[l] - cy[l] * bx[l];
        let v = ax[l] * cy[l] - ay[l] * cx[l];
        let w = bx[l] * ay[l] - by[l] * ax[l];
        (e[0][l], e[1][l], e[2][l]) = (u, v, w);
        let det = u + v + w;
        let nonzero = u != 0.0 && v != 0.0 && w != 0.0;
        let mixed = (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0);
        mask |= ((!(nonzero && det.is_finite() && mixed)) as u32) << l;
    }
    (mask & ((1u32 << lanes) - 1), e)
}

#[cfg(target_arch = "x86_64")]
pub(crate) mod sse {
    //! The four-lane test in SSE2 intrinsics (part of every x86-64 CPU):
    //! the same operations lane for lane as the portable loops (no fused
    //! multiply-add; ordered comparisons as Rust's `<`, `>`, unordered
    //! `!=`), so the same edge functions and mask.

    use std::arch::x86_64::*;

    use super::{Quad, QUAD};
    use crate::isect::RayShear;

    /// A ray's shear constants broadcast to four lanes, set up once per
    /// walk.
    #[derive(Clone, Copy)]
    pub(crate) struct QuadRay {
        k: [usize; 3],
        o: [__m128; 3],
        sx: __m128,
        sy: __m128,
    }

    impl QuadRay {
        #[inline(always)]
        pub(crate) fn new(shear: &RayShear) -> Self {
            let [kx, ky, kz] = shear.k;
            // SAFETY: SSE2 is part of x86-64.
            unsafe {
                Self {
                    k: shear.k,
                    o: [
                        _mm_set1_ps(shear.origin[kx]),
                        _mm_set1_ps(shear.origin[ky]),
                        _mm_set1_ps(shear.origin[kz]),
                    ],
                    sx: _mm_set1_ps(shear.s.x),
                    sy: _mm_set1_ps(shear.s.y),
                }
            }
        }
    }

    /// [`super::quad_edges`] for a ray set up as `r`.
    ///
    /// # Safety
    /// None beyond x86-64 (SSE2); `unsafe` for the intrinsics.
    #[inline(always)]
    pub(crate) unsafe fn quad_edges(
        r: &QuadRay,
        q: &Quad,
        lanes: usize,
    ) -> (u32, [[f32; QUAD]; 3]) {
        // SAFETY: each row is four f32; SSE2.
        unsafe {
            let [kx, ky, kz] = r.k;
            let sheared = |k: usize| {
                let row = |a: usize| _mm_loadu_ps(q.v[k][a].as_ptr());
                let z = _mm_sub_ps(row(kz), r.o[2]);
                (
                    _mm_sub_ps(_mm_sub_ps(row(kx), r.o[0]), _mm_mul_ps(r.sx, z)),
                    _mm_sub_ps(_mm_sub_ps(row(ky), r.o[1]), _mm_mul_ps(r.sy, z)),
                )
            };
            let (ax, ay) = sheared(0);
            let (bx, by) = sheared(1);
            let (cx, cy) = sheared(2);
            let cross = |p: __m128, q: __m128, r: __m128, s: __m128| {
                _mm_sub_ps(_mm_mul_ps(p, q), _mm_mul_ps(r, s))
            };
            let u = cross(cx, by, cy, bx);
            let v = cross(ax, cy, ay, cx);
            let w = cross(bx, ay, by, ax);
            let mut e = [[0.0f32; QUAD]; 3];
            _mm_storeu_ps(e[0].as_mut_ptr(), u);
            _mm_storeu_ps(e[1].as_mut_ptr(), v);
            _mm_storeu_ps(e[2].as_mut_ptr(), w);
            let det = _mm_add_ps(_mm_add_ps(u, v), w);
            let zero = _mm_setzero_ps();
            let nonzero = _mm_and_ps(
                _mm_and_ps(_mm_cmpneq_ps(u, zero), _mm_cmpneq_ps(v, zero)),
                _mm_cmpneq_ps(w, zero),
            );
            // A finite sum means u, v, w are finite (an infinite or NaN term
            // makes it infinite or NaN); finite and non-zero, their signs
            // are mixed exactly when their sign bits differ.
            let abs = _mm_castsi128_ps(_mm_set1_epi32(0x7fff_ffff));
            let finite = _mm_cmplt_ps(_mm_and_ps(det, abs), _mm_set1_ps(f32::INFINITY));
            let mixed = _mm_or_ps(_mm_xor_ps(u, v), _mm_xor_ps(u, w));
            let reject = _mm_and_ps(_mm_and_ps(nonzero, finite), mixed);
            let keep = !(_mm_movemask_ps(reject) as u32) & 0xf;
            (keep & ((1u32 << lanes) - 1), e)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Ray;
    use crate::test_support::floats;

    /// The SSE test gives the portable one's mask and edge functions bit
    /// for bit, and keeps every lane the scalar test accepts.
    #[test]
    fn sse_edges_equal_the_portable_ones_and_keep_every_hit() {
        let mut f = floats(4242);
        let (mut kept, mut hits) = (0, 0);
        for round in 0..4000 {
            let pick = |f: &mut dyn FnMut() -> f32| match round % 5 {
                0 => f().round(),
                1 => 0.0,
                _ => f(),
            };
            let mut tris: Vec<Triangle> = (0..QUAD)
                .map(|_| {
                    let mut p = || Vec3::new(pick(&mut f), f(), pick(&mut f) + 2.0);
                    Triangle::new(p(), p(), p())
                })
                .collect();
            tris[3].v[2] = tris[3].v[0]; // degenerate
            let q = Quad::pack(&tris, &[0, 1, 2, 3]);
            let mut dir = Vec3::new(f(), f(), f());
            dir[round % 3] = if round % 2 == 0 { 2.0 } else { -2.0 };
            let origin = match round % 4 {
                0 => tris[1].v[0] - dir,
                1 => (tris[1].v[0] + tris[1].v[1]) * 0.5 - dir * 0.5,
                _ => Vec3::new(f(), f(), f()) * 2.0,
            };
            let ray = Ray::new(origin, dir);
            let shear = RayShear::from_ray(&ray);
            for lanes in [1, 3, QUAD] {
                let (m, e) = portable_edges(&shear, &q, lanes);
                let (m2, e2) = quad_edges(&shear, &q, lanes);
                assert_eq!(m, m2, "round {round}");
                let bits = |e: [[f32; QUAD]; 3]| e.map(|r| r.map(f32::to_bits));
                assert_eq!(bits(e), bits(e2), "round {round}");
                kept += m.count_ones();
                for (l, t) in tris.iter().enumerate().take(lanes) {
                    let hit = shear.intersect(t, ray.tmin, ray.tmax);
                    if hit.is_some() {
                        hits += 1;
                        assert!(m & (1 << l) != 0, "lane {l} hit but was dropped");
                        let uvw = [e[0][l], e[1][l], e[2][l]];
                        assert_eq!(shear.decide(t, uvw, ray.tmin, ray.tmax), hit);
                    }
                }
            }
        }
        assert!(kept > 2000 && hits > 200, "{kept} kept, {hits} hits");
    }
}
