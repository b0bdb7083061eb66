//! The frustum of rays that share an origin, and the culling of a block of
//! triangles against it.
//!
//! Camera rays from a pinhole share their origin. In the watertight test's
//! permuted frame (which a packet's rays share, see `triangle_packet`), let
//! `(x, y, z)` be a point's coordinates relative to the origin along `kx`,
//! `ky`, `kz`, each multiplied by the sign of `d[kz]` so that points ahead
//! of the origin have `z >= 0`. Ray `l` is then the half-line `x = sx_l z`,
//! `y = sy_l z`, `z >= 0`, with `sx_l = d[kx] / d[kz]`, `sy_l = d[ky] /
//! d[kz]`: the test's own rounded shear constants. Every point of every ray
//! of the packet lies in the wedge
//!
//! `x - sx_lo z >= 0`, `x - sx_hi z <= 0`, `y - sy_lo z >= 0`,
//! `y - sy_hi z <= 0`, `z >= 0`
//!
//! (the smallest and largest constants over the rays). A triangle whose
//! three vertices lie outside one of these half-spaces lies outside it
//! entirely (the functions are linear), so no ray of the packet meets it.
//!
//! The culling never decides a hit, it only drops triangles, and it drops
//! one only when every vertex is outside by a margin of `MARGIN_REL` times
//! the vertex's distance from the origin (its 1-norm): far more than the
//! rounding of these few operations (a few units in 2^-24 of that distance)
//! or of the watertight test's own shear. The traversal makes the same kind
//! of decision for whole cells with the same relative slack
//! (`traverse::MARGIN`), so a triangle this test drops is one the tree
//! could as well have left out of the ray's cells.
//!
//! Why: a packet's rays miss 87-91% of the triangles of the leaves the
//! packet visits (primary rays of the bunny, sponza and teapot_stadium, 4x2
//! tiles); this test costs about a quarter of the 8-ray edge test and checks
//! eight triangles at once.

use super::IndexedBlock;
use super::{TriangleBlock, BLOCK_WIDTH};
use crate::isect::RayShear;

/// Relative slack of the culling planes (that of the traversal's
/// `MARGIN`: 2^-12).
const MARGIN_REL: f32 = 1.0 / 4096.0;

/// The wedge around rays that share an origin and a permutation.
#[derive(Clone, Copy, Debug)]
pub struct Frustum {
    /// The rays' shared permutation `kx`, `ky`, `kz`.
    k: [usize; 3],
    /// The origin along `kx`, `ky`, `kz`.
    o: [f32; 3],
    /// The sign of `d[kz]`: 1 or -1.
    sign: f32,
    /// The smallest `sx`, `sy` of the rays.
    lo: [f32; 2],
    /// The largest `sx`, `sy` of the rays.
    hi: [f32; 2],
}

impl Frustum {
    /// The frustum of the rays `shears[l]` with bit `l` set in `live`, or
    /// `None` if there are none or their origins or permutations differ.
    pub fn new(shears: &[RayShear], live: u32) -> Option<Self> {
        let mut rays = shears
            .iter()
            .enumerate()
            .filter(|&(l, _)| l < 32 && live >> l & 1 != 0)
            .map(|(_, s)| s);
        let first = rays.next()?;
        let [kx, ky, kz] = first.k;
        let mut f = Self {
            k: first.k,
            o: [first.origin[kx], first.origin[ky], first.origin[kz]],
            sign: if first.s.z < 0.0 { -1.0 } else { 1.0 },
            lo: [first.s.x, first.s.y],
            hi: [first.s.x, first.s.y],
        };
        let bits = |s: &RayShear| s.origin.to_array().map(f32::to_bits);
        for s in std::iter::once(first).chain(rays) {
            // Bitwise: -0 and +0 are the same point, but the planes are
            // built from one origin, so ask for that one exactly.
            if s.k != first.k || bits(s) != bits(first) || !(s.s.x.is_finite() && s.s.y.is_finite())
            {
                return None;
            }
            f.lo = [f.lo[0].min(s.s.x), f.lo[1].min(s.s.y)];
            f.hi = [f.hi[0].max(s.s.x), f.hi[1].max(s.s.y)];
        }
        // The permutation holds the sign of d[kz] (`RayShear::new` swaps
        // kx and ky for a negative one), so the rays agree on it.
        debug_assert!(f.o.iter().all(|o| !o.is_nan()));
        Some(f)
    }

    /// The frustum of eight rays that share the permutation `k`, from their
    /// origins along `kx`, `ky`, `kz` and their constants `sx`, `sy` by
    /// lane, or `None` if their origins differ. Every lane counts: give
    /// lanes that are off a live lane's values.
    #[inline(always)]
    pub fn from_lanes(
        k: [usize; 3],
        o: [&[f32; BLOCK_WIDTH]; 3],
        sx: &[f32; BLOCK_WIDTH],
        sy: &[f32; BLOCK_WIDTH],
    ) -> Option<Self> {
        let mut same = true;
        let (mut lo, mut hi) = ([sx[0], sy[0]], [sx[0], sy[0]]);
        for l in 0..BLOCK_WIDTH {
            for a in o {
                same &= a[l].to_bits() == a[0].to_bits();
            }
            same &= sx[l].is_finite() && sy[l].is_finite();
            lo = [lo[0].min(sx[l]), lo[1].min(sy[l])];
            hi = [hi[0].max(sx[l]), hi[1].max(sy[l])];
        }
        // The permutation holds the sign of d[kz] (`RayShear::new` swaps
        // kx and ky for a negative one), so `kx` alone tells. (Comparing
        // whole arrays stored the permutation with two scalar writes and
        // read it back as one vector: a failed store forwarding.)
        let positive = k[0] == (k[2] + 1) % 3;
        same.then_some(Self {
            k,
            o: [o[0][0], o[1][0], o[2][0]],
            sign: if positive { 1.0 } else { -1.0 },
            lo,
            hi,
        })
    }

    /// The lanes among the first `lanes` of `block` that some ray of the
    /// frustum may hit, as a bit mask (bit `i` = lane `i`).
    #[inline(always)]
    pub fn survivors(&self, block: &TriangleBlock, lanes: usize) -> u32 {
        let [kx, ky, kz] = self.k;
        let [ox, oy, oz] = self.o;
        let (sg, [lx, ly], [hx, hy]) = (self.sign, self.lo, self.hi);
        // Plain eight-lane loops, innermost, so that they are vectorised
        // (see `triangle_block`). `out[plane][l]`: every vertex of lane
        // `l` so far lies outside the plane.
        let mut out = [[true; BLOCK_WIDTH]; 5];
        for p in &block.v {
            for l in 0..BLOCK_WIDTH {
                let x = (p[kx][l] - ox) * sg;
                let y = (p[ky][l] - oy) * sg;
                let z = (p[kz][l] - oz) * sg;
                let m = (x.abs() + y.abs() + z.abs()) * MARGIN_REL;
                // Ordered comparisons: a NaN coordinate culls nothing.
                out[0][l] &= x - lx * z < -m;
                out[1][l] &= x - hx * z > m;
                out[2][l] &= y - ly * z < -m;
                out[3][l] &= y - hy * z > m;
                out[4][l] &= z < -m;
            }
        }
        let [o0, o1, o2, o3, o4] = &out;
        let mut mask = 0u32;
        for (l, ((((&a, &b), &c), &d), &e)) in o0.iter().zip(o1).zip(o2).zip(o3).zip(o4).enumerate()
        {
            mask |= (!(a | b | c | d | e) as u32) << l;
        }
        mask & ((1u32 << lanes) - 1)
    }

    /// [`Frustum::survivors`] in AVX2 intrinsics: the same operations lane
    /// for lane (no fused multiply-add, `-m` by a sign flip), so the same
    /// mask (tested against it).
    ///
    /// Why: compiled from the lane loops, the five planes' results went
    /// through byte arrays and were packed into the mask bit by bit; the
    /// cull was about a fifth of the bunny's packet path (`perf`).
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    pub unsafe fn survivors_avx2(&self, block: &TriangleBlock, lanes: usize) -> u32 {
        use std::arch::x86_64::*;
        // SAFETY: each row is eight f32.
        let load = |k: usize, a: usize| unsafe { _mm256_loadu_ps(block.v[k][a].as_ptr()) };
        let v = [
            [load(0, 0), load(0, 1), load(0, 2)],
            [load(1, 0), load(1, 1), load(1, 2)],
            [load(2, 0), load(2, 1), load(2, 2)],
        ];
        // SAFETY: AVX2 (the caller's contract).
        unsafe { self.survivors_lanes_avx2(v, lanes) }
    }

    /// [`Frustum::survivors_avx2`] of a block as a tree stores it (its lanes
    /// gathered from the vertex table).
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    pub unsafe fn survivors_indexed_avx2(&self, block: IndexedBlock, lanes: usize) -> u32 {
        // SAFETY: AVX2 (the caller's contract).
        unsafe { self.survivors_lanes_avx2(block.lanes_avx2(), lanes) }
    }

    /// The body of [`Frustum::survivors_avx2`], on the lanes `[vertex][axis]`:
    /// always inlined into the two callers (the lanes stay in registers),
    /// hence no target feature of its own and no closures.
    ///
    /// # Safety
    /// The CPU must have AVX2, and the caller must be compiled for it.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn survivors_lanes_avx2(
        &self,
        v: [[std::arch::x86_64::__m256; 3]; 3],
        lanes: usize,
    ) -> u32 {
        use std::arch::x86_64::*;
        const { assert!(BLOCK_WIDTH == 8) };
        let [kx, ky, kz] = self.k;
        // SAFETY: AVX2 (the caller's contract).
        unsafe {
            let (ox, oy, oz) = (
                _mm256_set1_ps(self.o[0]),
                _mm256_set1_ps(self.o[1]),
                _mm256_set1_ps(self.o[2]),
            );
            let (sg, rel) = (_mm256_set1_ps(self.sign), _mm256_set1_ps(MARGIN_REL));
            let (lx, ly) = (_mm256_set1_ps(self.lo[0]), _mm256_set1_ps(self.lo[1]));
            let (hx, hy) = (_mm256_set1_ps(self.hi[0]), _mm256_set1_ps(self.hi[1]));
            let abs = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff));
            let sign = _mm256_castsi256_ps(_mm256_set1_epi32(i32::MIN));
            let all = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
            let (mut o0, mut o1, mut o2, mut o3, mut o4) = (all, all, all, all, all);
            for p in &v {
                let x = _mm256_mul_ps(_mm256_sub_ps(p[kx], ox), sg);
                let y = _mm256_mul_ps(_mm256_sub_ps(p[ky], oy), sg);
                let z = _mm256_mul_ps(_mm256_sub_ps(p[kz], oz), sg);
                let sum = _mm256_add_ps(
                    _mm256_add_ps(_mm256_and_ps(x, abs), _mm256_and_ps(y, abs)),
                    _mm256_and_ps(z, abs),
                );
                let m = _mm256_mul_ps(sum, rel);
                let neg_m = _mm256_xor_ps(m, sign);
                // Outside each plane: x - lx z < -m, x - hx z > m, the same
                // with y, and z < -m.
                let px_lo = _mm256_sub_ps(x, _mm256_mul_ps(lx, z));
                let px_hi = _mm256_sub_ps(x, _mm256_mul_ps(hx, z));
                let py_lo = _mm256_sub_ps(y, _mm256_mul_ps(ly, z));
                let py_hi = _mm256_sub_ps(y, _mm256_mul_ps(hy, z));
                o0 = _mm256_and_ps(o0, _mm256_cmp_ps::<_CMP_LT_OQ>(px_lo, neg_m));
                o1 = _mm256_and_ps(o1, _mm256_cmp_ps::<_CMP_GT_OQ>(px_hi, m));
                o2 = _mm256_and_ps(o2, _mm256_cmp_ps::<_CMP_LT_OQ>(py_lo, neg_m));
                o3 = _mm256_and_ps(o3, _mm256_cmp_ps::<_CMP_GT_OQ>(py_hi, m));
                o4 = _mm256_and_ps(o4, _mm256_cmp_ps::<_CMP_LT_OQ>(z, neg_m));
            }
            let culled = _mm256_or_ps(_mm256_or_ps(_mm256_or_ps(o0, o1), _mm256_or_ps(o2, o3)), o4);
            !(_mm256_movemask_ps(culled) as u32) & ((1u32 << lanes) - 1)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Ray, Triangle};
    use crate::test_support::floats;
    use glam::Vec3;

    /// Every triangle a ray of the frustum hits survives, whatever the
    /// direction the rays share; and a narrow frustum culls most of a
    /// random scene.
    #[test]
    fn keeps_every_hit_and_culls_the_rest() {
        let mut f = floats(77);
        let (mut hits, mut culled, mut tested) = (0, 0, 0);
        for round in 0..3000 {
            let eye = Vec3::new(f(), f(), f());
            // Rays around one of the six axis directions (both signs of
            // d[kz], every kz), some wide, most narrow.
            let axis = round % 6;
            let mut aim = Vec3::ZERO;
            aim[axis % 3] = if axis < 3 { 1.0 } else { -1.0 };
            let spread = if round % 5 == 0 { 0.6 } else { 0.05 };
            let rays: Vec<Ray> = (0..8)
                .map(|_| Ray::new(eye, aim + Vec3::new(f(), f(), f()) * spread))
                .collect();
            let shears: Vec<RayShear> = rays.iter().map(RayShear::from_ray).collect();
            let live = if round % 7 == 0 { 0b1010_0110 } else { 0xff };
            let Some(fr) = Frustum::new(&shears, live) else {
                // Mixed permutations: the wide packets may have them.
                assert!(spread > 0.5 || shears.iter().any(|s| s.k != shears[0].k));
                continue;
            };
            // Triangles around the rays: near ones, far ones, large ones
            // and ones straddling the origin.
            let tris: Vec<Triangle> = (0..BLOCK_WIDTH)
                .map(|i| {
                    let c = eye + aim * (f() * 4.0) + Vec3::new(f(), f(), f()) * 0.4;
                    let size = if i % 3 == 0 { 2.0 } else { 0.1 };
                    Triangle::new(
                        c + Vec3::new(f(), f(), f()) * size,
                        c + Vec3::new(f(), f(), f()) * size,
                        c + Vec3::new(f(), f(), f()) * size,
                    )
                })
                .collect();
            let block = TriangleBlock::pack(&tris);
            let lanes = if round % 4 == 0 { 5 } else { BLOCK_WIDTH };
            let m = fr.survivors(&block, lanes);
            assert_eq!(m >> lanes, 0, "lanes past the count are masked");
            #[cfg(target_arch = "x86_64")]
            if crate::simd::has_avx2() {
                // SAFETY: the CPU has AVX2.
                assert_eq!(
                    unsafe { fr.survivors_avx2(&block, lanes) },
                    m,
                    "round {round}"
                );
            }
            for (i, t) in tris.iter().enumerate().take(lanes) {
                tested += 1;
                let hit = (0..8)
                    .filter(|&l| live >> l & 1 != 0)
                    .any(|l| shears[l].intersect(t, 0.0, f32::INFINITY).is_some());
                if hit {
                    hits += 1;
                    assert!(
                        m >> i & 1 != 0,
                        "round {round}: triangle {i} is hit but culled"
                    );
                } else if m >> i & 1 == 0 {
                    culled += 1;
                }
            }
        }
        assert!(hits > 1000, "{hits} hits");
        assert!(
            culled * 2 > tested - hits,
            "{culled} of {} misses culled",
            tested - hits
        );
    }

    /// Triangles outside the wedge but for one vertex placed on an
    /// extreme ray (up to rounding): whenever the watertight test says that
    /// ray hits one, the cull keeps it.
    #[test]
    fn keeps_triangles_touching_the_wedge_at_a_vertex() {
        let mut f = floats(404);
        let mut hits = 0;
        for round in 0..4000 {
            let eye = Vec3::new(f(), f(), f()) * 10.0;
            let axis = round % 6;
            let mut aim = Vec3::ZERO;
            aim[axis % 3] = if axis < 3 { 1.0 } else { -1.0 };
            let rays: Vec<Ray> = (0..8)
                .map(|_| Ray::new(eye, aim + Vec3::new(f(), f(), f()) * 0.05))
                .collect();
            let shears: Vec<RayShear> = rays.iter().map(RayShear::from_ray).collect();
            let Some(fr) = Frustum::new(&shears, 0xff) else {
                continue;
            };
            // The ray with the smallest or largest sx or sy.
            let key = |s: &RayShear| if round % 4 < 2 { s.s.x } else { s.s.y };
            let by = |a: &usize, b: &usize| key(&shears[*a]).total_cmp(&key(&shears[*b]));
            let l = if round % 2 == 0 {
                (0..8).min_by(by)
            } else {
                (0..8).max_by(by)
            }
            .unwrap();
            let t = 0.5 + f().abs() * 4.0;
            let v0 = rays[l].origin + rays[l].dir * t;
            // Away from the packet's middle ray, across the ray's path.
            let mid = rays.iter().map(|r| r.dir).sum::<Vec3>() / 8.0;
            let out = (v0 - (eye + mid * t)).normalize();
            let across = out.cross(rays[l].dir).normalize() * 0.2;
            let tri = Triangle::new(v0, v0 + out * 0.3 + across, v0 + out * 0.3 - across);
            let block = TriangleBlock::pack(&[tri]);
            if shears[l].intersect(&tri, 0.0, f32::INFINITY).is_some() {
                hits += 1;
                assert_eq!(fr.survivors(&block, 1), 1, "round {round}: hit but culled");
                #[cfg(target_arch = "x86_64")]
                if crate::simd::has_avx2() {
                    // SAFETY: the CPU has AVX2.
                    assert_eq!(unsafe { fr.survivors_avx2(&block, 1) }, 1, "round {round}");
                }
            }
        }
        assert!(hits > 200, "{hits} hits at a vertex");
    }

    #[test]
    fn refuses_rays_that_do_not_share_an_origin_or_permutation() {
        let a = RayShear::new(Vec3::ZERO, Vec3::new(0.1, 0.0, 1.0));
        let b = RayShear::new(Vec3::ZERO, Vec3::new(-0.1, 0.0, -1.0));
        let c = RayShear::new(Vec3::X, Vec3::new(0.1, 0.0, 1.0));
        assert!(Frustum::new(&[a, a], 0b11).is_some());
        assert!(Frustum::new(&[a, b], 0b11).is_none());
        assert!(Frustum::new(&[a, c], 0b11).is_none());
        // Lanes that are off do not count.
        assert!(Frustum::new(&[a, b], 0b01).is_some());
        assert!(Frustum::new(&[a, a], 0).is_none());
    }
}
