//! The watertight ray/triangle test: the reference every query and the
//! brute-force oracle share.

use glam::{DVec3, Vec3};

use super::TriangleHit;
use crate::math::{Ray, Triangle};

/// The watertight test's axis permutation `[kx, ky, kz]` for the dominant
/// axis `kz` of a direction whose `kz` component is negative (`neg`) or
/// not: `kx`, `ky` follow `kz` cyclically, swapped for a negative one to
/// keep the winding (and so the sign of the edge functions).
#[inline(always)]
pub(crate) fn permutation(kz: usize, neg: bool) -> [usize; 3] {
    let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
    // A swap without a branch when `neg`.
    let swap = (kx ^ ky) & (neg as usize).wrapping_neg();
    [kx ^ swap, ky ^ swap, kz]
}

/// Per-ray constants of the watertight test (Woop, Benthin, Wald 2013,
/// "Watertight Ray/Triangle Intersection", JCGT 2(1)): the dimension `kz`
/// where the direction is largest, and the shear that maps the ray onto +z.
#[derive(Clone, Copy, Debug)]
pub struct RayShear {
    /// Ray origin.
    pub origin: Vec3,
    /// Permuted axes: `kx`, `ky`, `kz`.
    pub k: [usize; 3],
    /// Shear constants `(dx/dz, dy/dz, 1/dz)` in the permuted frame.
    pub s: Vec3,
    /// Ray direction (for the hit distance).
    pub dir: Vec3,
}

impl RayShear {
    /// Precompute the shear for a ray direction.
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        // Without branches (the same choices as `x >= y && x >= z`, else
        // `y >= z`): rays in a batch have unrelated directions, which the
        // branch predictor cannot guess.
        let a = dir.abs();
        let x_wins = (a.x >= a.y) & (a.x >= a.z);
        let kz = (!x_wins as usize) * (2 - (a.y >= a.z) as usize);
        let d = dir.to_array();
        let [kx, ky, kz] = permutation(kz, d[kz] < 0.0);
        let s = Vec3::new(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
        Self {
            origin,
            k: [kx, ky, kz],
            s,
            dir,
        }
    }

    /// Shear precomputation for a [`Ray`].
    pub fn from_ray(ray: &Ray) -> Self {
        Self::new(ray.origin, ray.dir)
    }

    /// The watertight test: the hit with `t` in `(tmin, tmax]`, or `None`.
    ///
    /// This is the reference test: every query of the crate and the
    /// brute-force oracle call it, so a kd-tree and brute force compute the
    /// same bits for the same (ray, triangle) pair. Edges shared by two
    /// triangles are never missed: the edge functions are evaluated from the
    /// same sheared vertices, and an exact zero is re-evaluated in f64 as the
    /// paper prescribes. Back faces are not culled.
    #[inline(always)]
    pub fn intersect(&self, tri: &Triangle, tmin: f32, tmax: f32) -> Option<TriangleHit> {
        let [kx, ky, kz] = self.k;
        let a = tri.v[0] - self.origin;
        let b = tri.v[1] - self.origin;
        let c = tri.v[2] - self.origin;
        let ax = a[kx] - self.s.x * a[kz];
        let ay = a[ky] - self.s.y * a[kz];
        let bx = b[kx] - self.s.x * b[kz];
        let by = b[ky] - self.s.y * b[kz];
        let cx = c[kx] - self.s.x * c[kz];
        let cy = c[ky] - self.s.y * c[kz];

        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let det = u + v + w;
        let (bu, bv) = if u != 0.0 && v != 0.0 && w != 0.0 && det.is_finite() {
            if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
                return None;
            }
            let rcp = 1.0 / det;
            (v * rcp, w * rcp)
        } else {
            // An edge function exactly zero (a ray through an edge or a
            // vertex) is decided in double precision (paper, section 3); so is
            // one that overflowed f32 (vertices ~1e19 apart, whose products
            // pass f32::MAX). NaN or infinite sheared coordinates (vertices
            // ~1e38 away) fail the finiteness test.
            let (ax, ay, bx, by, cx, cy) = (
                ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64,
            );
            let u = cx * by - cy * bx;
            let v = ax * cy - ay * cx;
            let w = bx * ay - by * ax;
            if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
                return None;
            }
            let det = u + v + w;
            if det == 0.0 || !det.is_finite() {
                return None;
            }
            ((v / det) as f32, (w / det) as f32)
        };
        let t = TrianglePlane::new(tri).distance(self.origin, self.dir);
        // `tmin` is exclusive, as Embree's `tnear`: a hit at the origin itself
        // is not a hit. Besides sparing a ray leaving a surface its own
        // triangle, this settles hits that exist only by rounding: a ray
        // starting 1e-27 outside a 1e9-wide scene at a vertex, pointing
        // away, computes t = 0 there (the origin vanishes in `v0 - o`), and no
        // cell of a tree holds that point (fuzz regression in
        // `tests/kd/bad_input.rs`). Written so that NaN fails the test; `+ 0.0`
        // turns -0 into +0 for a negative `tmin`.
        if !(t > tmin && t <= tmax) {
            return None;
        }
        Some(TriangleHit {
            t: t + 0.0,
            u: bu,
            v: bv,
        })
    }
}

impl RayShear {
    /// The watertight test of `tri` finished from its f32 edge functions
    /// `u, v, w` as [`RayShear::block_edges`] computed them (the same bits
    /// [`RayShear::intersect`] computes): a lane the block kept. Spares
    /// recomputing the edge functions; an exact zero or an overflow still
    /// goes through the whole scalar test (its f64 path).
    #[inline(always)]
    pub fn decide(
        &self,
        tri: &Triangle,
        uvw: [f32; 3],
        tmin: f32,
        tmax: f32,
    ) -> Option<TriangleHit> {
        self.decide_in_plane(tri, || TrianglePlane::new(tri), uvw, tmin, tmax)
    }

    /// [`RayShear::decide`] with the triangle's plane from `plane`, called
    /// only when the hit distance is needed: the packet test computes it
    /// once per triangle for all the rays it decides (the same bits as
    /// computing it per ray).
    #[inline(always)]
    pub fn decide_in_plane(
        &self,
        tri: &Triangle,
        plane: impl FnOnce() -> TrianglePlane,
        [u, v, w]: [f32; 3],
        tmin: f32,
        tmax: f32,
    ) -> Option<TriangleHit> {
        let det = u + v + w;
        if !(u != 0.0 && v != 0.0 && w != 0.0 && det.is_finite()) {
            return self.intersect(tri, tmin, tmax);
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let t = plane().distance(self.origin, self.dir);
        // As in `intersect`.
        if !(t > tmin && t <= tmax) {
            return None;
        }
        // Only now: most candidates lie outside the interval (the
        // triangle a ray leaves, those beyond the closest hit so far).
        let rcp = 1.0 / det;
        Some(TriangleHit {
            t: t + 0.0,
            u: v * rcp,
            v: w * rcp,
        })
    }
}

/// A triangle's plane in f64, for the hit distance along `o + t d` from the
/// plane equation `t = ((v0 - o) . n) / (d . n)`.
///
/// The paper's `t = (U Az + V Bz + W Cz) / det` sums vertex depths that
/// cancel when the vertices lie much farther from the origin than the hit
/// (a ground plane 5 km wide hit 0.3 m away loses three digits in f32). The
/// plane equation in f64 keeps about 1e-12 relative accuracy there; it is
/// evaluated only for rays that passed the edge test, so it costs little.
/// Its absolute error grows with the vertices' distance from the origin
/// (~1e-16 of it): a triangle 1e30 away cannot place a hit 3 units away.
#[derive(Clone, Copy, Debug)]
pub struct TrianglePlane {
    /// The first vertex.
    v0: DVec3,
    /// The (unnormalised) normal `(v1 - v0) x (v2 - v0)`.
    n: DVec3,
}

impl TrianglePlane {
    /// The plane of `tri`, in f64.
    #[inline(always)]
    pub fn new(tri: &Triangle) -> Self {
        let v0 = tri.v[0].as_dvec3();
        let n = (tri.v[1].as_dvec3() - v0).cross(tri.v[2].as_dvec3() - v0);
        Self { v0, n }
    }

    /// The distance along `o + t d` to the plane, rounded to f32.
    #[inline(always)]
    pub fn distance(&self, o: Vec3, d: Vec3) -> f32 {
        let den = d.as_dvec3().dot(self.n);
        ((self.v0 - o.as_dvec3()).dot(self.n) / den) as f32
    }

    /// [`TrianglePlane::distance`] for eight rays (origins `o`, directions
    /// `d` by axis and lane) in AVX2 intrinsics, four lanes of f64 at a
    /// time: the same operations in the same order, so the same bits.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn distances_avx2(&self, o: [&[f32; 8]; 3], d: [&[f32; 8]; 3]) -> [f32; 8] {
        use std::arch::x86_64::*;
        let mut t = [0.0f32; 8];
        let (v0, n) = (self.v0.to_array(), self.n.to_array());
        for half in 0..2 {
            // SAFETY: four f32 at `4 * half` of eight.
            let wide =
                |a: &[f32; 8]| unsafe { _mm256_cvtps_pd(_mm_loadu_ps(a.as_ptr().add(4 * half))) };
            // `a . n` as glam's `dot`: (x nx + y ny) + z nz.
            let dot = |a: [__m256d; 3]| {
                let xy = _mm256_add_pd(
                    _mm256_mul_pd(a[0], _mm256_set1_pd(n[0])),
                    _mm256_mul_pd(a[1], _mm256_set1_pd(n[1])),
                );
                _mm256_add_pd(xy, _mm256_mul_pd(a[2], _mm256_set1_pd(n[2])))
            };
            let den = dot([wide(d[0]), wide(d[1]), wide(d[2])]);
            let to_v0 = |k: usize| _mm256_sub_pd(_mm256_set1_pd(v0[k]), wide(o[k]));
            let num = dot([to_v0(0), to_v0(1), to_v0(2)]);
            let q = _mm256_cvtpd_ps(_mm256_div_pd(num, den));
            // SAFETY: four f32 at `4 * half` of eight.
            unsafe { _mm_storeu_ps(t.as_mut_ptr().add(4 * half), q) };
        }
        t
    }
}

/// Convenience: the watertight test of one ray against one triangle.
pub fn intersect_ray_triangle(ray: &Ray, tri: &Triangle) -> Option<TriangleHit> {
    RayShear::from_ray(ray).intersect(tri, ray.tmin, ray.tmax)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The eight-lane plane distances equal the scalar ones bit for bit
    /// (near and far planes, grazing and parallel rays).
    #[test]
    fn avx2_plane_distances_equal_the_scalar_ones() {
        #[cfg(target_arch = "x86_64")]
        if crate::simd::has_avx2() {
            let mut f = crate::test_support::floats(5150);
            for round in 0..2000 {
                let s = if round % 3 == 0 { 1000.0 } else { 1.0 };
                let tri = Triangle::new(
                    Vec3::new(f(), f(), f()) * s,
                    Vec3::new(f(), f(), f()) * s,
                    Vec3::new(f(), f(), f()) * s,
                );
                let plane = TrianglePlane::new(&tri);
                let mut o = [[0.0f32; 8]; 3];
                let mut d = [[0.0f32; 8]; 3];
                for l in 0..8 {
                    for k in 0..3 {
                        o[k][l] = f() * 3.0;
                        d[k][l] = if round % 7 == 0 && k == 2 { 0.0 } else { f() };
                    }
                }
                // SAFETY: the CPU has AVX2.
                let t =
                    unsafe { plane.distances_avx2([&o[0], &o[1], &o[2]], [&d[0], &d[1], &d[2]]) };
                for l in 0..8 {
                    let want = plane.distance(
                        Vec3::new(o[0][l], o[1][l], o[2][l]),
                        Vec3::new(d[0][l], d[1][l], d[2][l]),
                    );
                    assert_eq!(t[l].to_bits(), want.to_bits(), "round {round} lane {l}");
                }
            }
        }
    }

    #[test]
    fn hit_reports_distance_and_barycentrics() {
        let tri = Triangle::new(
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::new(4.0, 0.0, 2.0),
            Vec3::new(0.0, 4.0, 2.0),
        );
        let ray = Ray::new(Vec3::new(1.0, 2.0, 0.0), Vec3::new(0.0, 0.0, 0.5));
        let h = intersect_ray_triangle(&ray, &tri).unwrap();
        assert_eq!(h.t, 4.0);
        // p = (1, 2) = (1-u-v) v0 + u (4,0) + v (0,4)  =>  u = 1/4, v = 1/2.
        assert_eq!((h.u, h.v), (0.25, 0.5));
        // Both windings hit (no culling); outside and behind miss.
        let flipped = Triangle::new(tri.v[0], tri.v[2], tri.v[1]);
        assert!(intersect_ray_triangle(&ray, &flipped).is_some());
        assert!(
            intersect_ray_triangle(&Ray::new(Vec3::new(3.0, 3.0, 0.0), Vec3::Z), &tri).is_none()
        );
        assert!(
            intersect_ray_triangle(&Ray::new(Vec3::new(1.0, 1.0, 3.0), Vec3::Z), &tri).is_none()
        );
        // The interval is closed.
        let r = Ray::with_interval(ray.origin, ray.dir, 0.0, 4.0);
        assert!(intersect_ray_triangle(&r, &tri).is_some());
        let r = Ray::with_interval(ray.origin, ray.dir, 0.0, 3.999);
        assert!(intersect_ray_triangle(&r, &tri).is_none());
    }

    #[test]
    fn tmin_is_exclusive_and_tmax_inclusive() {
        let tri = Triangle::new(
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::new(4.0, 0.0, 2.0),
            Vec3::new(0.0, 4.0, 2.0),
        );
        let o = Vec3::new(1.0, 1.0, 0.0);
        let d = Vec3::new(0.0, 0.0, 1.0); // hits at t = 2 exactly
        let hit = |tmin, tmax| intersect_ray_triangle(&Ray::with_interval(o, d, tmin, tmax), &tri);
        assert!(hit(2.0, 3.0).is_none(), "t == tmin is not a hit");
        assert_eq!(hit(1.999_999_9, 3.0).unwrap().t, 2.0);
        assert_eq!(hit(0.0, 2.0).unwrap().t, 2.0, "t == tmax is a hit");
        assert!(hit(0.0, 1.999_999_9).is_none());
        // A ray starting on the triangle (t = 0) does not hit it.
        let on = Ray::new(Vec3::new(1.0, 1.0, 2.0), Vec3::new(0.0, 0.0, 1.0));
        assert!(intersect_ray_triangle(&on, &tri).is_none());
        let on_back = Ray::new(Vec3::new(1.0, 1.0, 2.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(intersect_ray_triangle(&on_back, &tri).is_none());
    }

    #[test]
    fn distance_is_accurate_on_huge_triangles_hit_up_close() {
        // The teapot-in-a-stadium case: a 10 km ground triangle hit 0.3 m
        // from the origin. Reference distance computed in f64.
        let s = 5000.0;
        let tri = Triangle::new(
            Vec3::new(-s, 0.0, -s),
            Vec3::new(s, 0.0, -s),
            Vec3::new(0.0, 0.0, s),
        );
        for (o, d) in [
            (Vec3::new(0.1, 0.3, 0.2), Vec3::new(0.3, -1.0, 0.7)),
            (Vec3::new(-7.3, 0.05, 3.1), Vec3::new(-0.9, -0.2, 0.1)),
        ] {
            let h = intersect_ray_triangle(&Ray::new(o, d), &tri).unwrap();
            let exact = -(o.y as f64) / d.y as f64;
            let rel = ((h.t as f64 - exact) / exact).abs();
            assert!(rel < 2e-7, "t = {} exact {exact} rel {rel}", h.t);
        }
    }
}
