//! A packet's lanes from its rays, eight lanes at a time: validity, the
//! reciprocal directions, the interval in the root cell, the watertight
//! test's permutation and shear constants, and the frustum.
//!
//! Why: set up ray by ray (six divisions, the root clip's branches and a
//! `RayShear` written per ray, then copied into the packet forms), the
//! set-up was a large part of the packet path on camera rays (see
//! `docs/performance.md`). Written over the lanes (plain loops, or AVX2
//! intrinsics), it is a few vector divisions and compares.
//!
//! Each lane computes exactly what `Ray::is_valid`, `Aabb::intersect_ray`
//! and `RayShear::new` compute for its ray, with the same operations in the
//! same order, so the lanes equal the scalar results bit for bit (the
//! packet tests compare both walks with brute force).

use glam::Vec3;

use super::{Lanes, Packet, MAILBOX, NO_HIT, OFF, PACKET};
use crate::isect::{permutation, RayShear};
use crate::leaf::Frustum;
use crate::leaf::PacketShear;
use crate::math::slack::FAR_GROW;
use crate::math::{Aabb, Ray};

/// `a` with the lanes not in `live` replaced by lane `f`'s value.
#[inline(always)]
fn borrow_off_lanes(a: &Lanes, live: u32, f: usize) -> Lanes {
    let mut a = *a;
    // Full packets (the common case) have nothing to borrow.
    if live == (1 << PACKET) - 1 {
        return a;
    }
    for l in 0..PACKET {
        a[l] = if live >> l & 1 != 0 { a[l] } else { a[f] };
    }
    a
}

impl Packet {
    /// A packet with every lane off, for [`Packet::setup`] to fill.
    pub(super) const EMPTY: Packet = Packet {
        neg: [false; 3],
        org: [[0.0; PACKET]; 3],
        inv: [[0.0; PACKET]; 3],
        t0: [OFF.0; PACKET],
        t1: [OFF.1; PACKET],
        tmin: [0.0; PACKET],
        dir: [[0.0; PACKET]; 3],
        k: None,
        s: [[0.0; PACKET]; 3],
        packet_shear: None,
        frustum: None,
        best_t: [0.0; PACKET],
        best: [NO_HIT; PACKET],
        closest: [f32::INFINITY; PACKET],
        mailbox: [(u32::MAX, 0); MAILBOX],
        mailbox_next: 0,
    };

    /// Make this the packet of `rays` (at most [`PACKET`]) in the root cell
    /// `bounds`; false when they must be traced one by one (no rays, or
    /// direction signs that differ). Written in place: returned by value,
    /// the ~1 KB packet was copied twice (`memmove` in the profile).
    #[inline(always)]
    pub(super) fn setup(&mut self, rays: &[Ray], bounds: &Aabb) -> bool {
        match self.gather(rays) {
            Some(neg) => self.setup_lanes(rays.len(), neg, bounds),
            None => false,
        }
    }

    /// [`Packet::setup`] at level `SIMD`: in AVX2 intrinsics from that
    /// level on. Whatever the packet held before (it may be reused): the
    /// set-up writes every field the walk reads, and the mailbox is reset.
    ///
    /// # Safety
    /// The CPU must have the level's instructions.
    #[inline(always)]
    pub(super) unsafe fn setup_at<const SIMD: u8>(&mut self, rays: &[Ray], bounds: &Aabb) -> bool {
        #[cfg(target_arch = "x86_64")]
        if SIMD >= crate::simd::level::AVX2 {
            // SAFETY: AVX2 (the caller's contract).
            return unsafe { self.setup_avx2(rays, bounds) };
        }
        (self.mailbox, self.mailbox_next) = (Packet::EMPTY.mailbox, 0);
        self.setup(rays, bounds)
    }

    /// Copy `rays` into the lanes (lanes past them repeat the first ray)
    /// and return the direction signs' bit masks by axis (bit `l`: lane
    /// `l`'s sign bit), or `None` for no rays.
    #[inline(always)]
    pub(super) fn gather(&mut self, rays: &[Ray]) -> Option<[u32; 3]> {
        let first = rays.first()?;
        let mut neg = [0u32; 3];
        for l in 0..PACKET {
            let r = rays.get(l).unwrap_or(first);
            for (k, m) in neg.iter_mut().enumerate() {
                self.org[k][l] = r.origin[k];
                self.dir[k][l] = r.dir[k];
                *m |= (r.dir[k].is_sign_negative() as u32) << l;
            }
            (self.tmin[l], self.best_t[l]) = (r.tmin, r.tmax);
        }
        Some(neg)
    }

    /// The rest of the set-up once the lanes hold the `n` rays (see
    /// [`Packet::setup`]); `neg` as [`Packet::gather`] returns it.
    ///
    /// One piece: the portable reference that `setup_full`'s
    /// intrinsics are held to lane for lane; its steps stand in the same
    /// order as those, so that the two read side by side.
    #[inline(always)]
    pub(super) fn setup_lanes(&mut self, n: usize, neg: [u32; 3], bounds: &Aabb) -> bool {
        debug_assert!((1..=PACKET).contains(&n));
        // One shared sign per axis among the rays given (the lanes past
        // them repeat the first ray).
        let rays_mask = (1u32 << n) - 1;
        let neg = neg.map(|m| m & rays_mask);
        if neg.iter().any(|&m| m != 0 && m != rays_mask) {
            return false;
        }
        let p = self;
        p.neg = neg.map(|m| m != 0);
        let (o, d, tmin, tmax) = (&p.org, &p.dir, &p.tmin, &p.best_t);
        let mut inv = [[0.0f32; PACKET]; 3];
        let (mut t0, mut t1) = ([0.0f32; PACKET], [0.0f32; PACKET]);
        let mut kz = [0u32; PACKET];
        let mut kneg = [false; PACKET];
        let mut live = 0u32;
        for l in 0..PACKET {
            // `Ray::is_valid`, and `tmin <= tmax`.
            let finite = o[0][l].is_finite()
                && o[1][l].is_finite()
                && o[2][l].is_finite()
                && d[0][l].is_finite()
                && d[1][l].is_finite()
                && d[2][l].is_finite();
            let nonzero = d[0][l] != 0.0 || d[1][l] != 0.0 || d[2][l] != 0.0;
            let valid = l < n
                && finite
                && nonzero
                && tmin[l] >= 0.0
                && !tmax[l].is_nan()
                && tmin[l] <= tmax[l];
            // `Aabb::intersect_ray` on `1 / d`, all three slabs at once; a
            // lane is out from the slab where the interval empties (the
            // scalar test returns there).
            let (mut a0, mut a1, mut out) = (tmin[l], tmax[l], false);
            for k in 0..3 {
                let iv = 1.0 / d[k][l];
                inv[k][l] = iv;
                let (lo, hi) = (bounds.min[k], bounds.max[k]);
                let near = (lo - o[k][l]) * iv;
                let far = (hi - o[k][l]) * iv;
                let swap = near > far;
                let (near, far) = if swap { (far, near) } else { (near, far) };
                let far = far * FAR_GROW;
                let b0 = if near > a0 { near } else { a0 };
                let b1 = if far < a1 { far } else { a1 };
                // Parallel to the slab: inside it for every t, or never.
                let parallel = iv.is_infinite();
                let outside = o[k][l] < lo || o[k][l] > hi;
                out |= if parallel { outside } else { b0 > b1 };
                (a0, a1) = if parallel { (a0, a1) } else { (b0, b1) };
            }
            let on = valid && !out;
            (t0[l], t1[l]) = if on { (a0, a1) } else { OFF };
            live |= (on as u32) << l;
            // `RayShear::new`'s dominant axis and the sign of d[kz].
            let (ax, ay, az) = (d[0][l].abs(), d[1][l].abs(), d[2][l].abs());
            let z = if ax >= ay && ax >= az {
                0
            } else if ay >= az {
                1
            } else {
                2
            };
            kz[l] = z;
            let dz = if z == 0 {
                d[0][l]
            } else if z == 1 {
                d[1][l]
            } else {
                d[2][l]
            };
            kneg[l] = dz < 0.0;
        }
        // Lanes that are off keep zero origins and reciprocals (the walks
        // mask them anyway).
        for (org, inv) in p.org.iter_mut().zip(&mut inv) {
            for l in 0..PACKET {
                let on = live >> l & 1 != 0;
                org[l] = if on { org[l] } else { 0.0 };
                inv[l] = if on { inv[l] } else { 0.0 };
            }
        }
        p.inv = inv;
        (p.t0, p.t1) = (t0, t1);
        (p.k, p.packet_shear, p.frustum) = (None, None, None);
        p.best = [NO_HIT; PACKET];
        p.closest = [f32::INFINITY; PACKET];
        // Lanes past the rays: `tmin` and `best_t` 0 (never read).
        for l in n..PACKET {
            (p.tmin[l], p.best_t[l]) = (0.0, 0.0);
        }
        // One permutation for the live rays: the packet forms of the
        // watertight test (and, with one origin, the frustum).
        if live == 0 {
            return true;
        }
        let f = live.trailing_zeros() as usize;
        let shared =
            (0..PACKET).all(|l| live >> l & 1 == 0 || (kz[l] == kz[f] && kneg[l] == kneg[f]));
        if shared {
            let k = permutation(kz[f] as usize, kneg[f]);
            let [kx, ky, kz] = k;
            // As `RayShear::new`: d[kx] / d[kz], d[ky] / d[kz], 1 / d[kz]
            // (the last is the reciprocal computed above).
            let [sx, sy, sz] = &mut p.s;
            for (l, s) in sx.iter_mut().enumerate() {
                *s = p.dir[kx][l] / p.dir[kz][l];
            }
            for (l, s) in sy.iter_mut().enumerate() {
                *s = p.dir[ky][l] / p.dir[kz][l];
            }
            *sz = p.inv[kz];
            p.k = Some(k);
            // Lanes that are off borrow the first live lane's constants, so
            // that their (masked) lanes compute finite values.
            let pick = |a: &Lanes| borrow_off_lanes(a, live, f);
            let (ox, oy, oz) = (pick(&p.org[kx]), pick(&p.org[ky]), pick(&p.org[kz]));
            let (sx, sy) = (pick(&p.s[0]), pick(&p.s[1]));
            p.packet_shear = Some(PacketShear::from_lanes(k, [ox, oy, oz], sx, sy));
            p.frustum = Frustum::from_lanes(k, [&ox, &oy, &oz], &sx, &sy);
        }
        true
    }

    /// The watertight-test constants of ray `l` (a live lane), as
    /// `RayShear::new` computes them.
    #[inline(always)]
    pub(super) fn shear(&self, l: usize) -> RayShear {
        let origin = Vec3::new(self.org[0][l], self.org[1][l], self.org[2][l]);
        let dir = Vec3::new(self.dir[0][l], self.dir[1][l], self.dir[2][l]);
        match self.k {
            Some(k) => RayShear {
                origin,
                k,
                s: Vec3::new(self.s[0][l], self.s[1][l], self.s[2][l]),
                dir,
            },
            None => RayShear::new(origin, dir),
        }
    }
}

/// The set-up in AVX2 intrinsics.
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    use super::super::{Packet, NO_HIT, OFF, PACKET};
    use crate::isect::permutation;
    use crate::leaf::{Frustum, PacketShear};
    use crate::math::slack::FAR_GROW;
    use crate::math::{Aabb, Ray};

    impl Packet {
        /// [`Packet::setup`] with a full packet's rays loaded as an 8x8 matrix
        /// (one ray per row: origin, direction, `tmin`, `tmax`) and transposed
        /// into the lanes, the signs read with `movemask`.
        ///
        /// Why: copied float by float, the 64 loads and stores of the gather and
        /// the per-ray sign comparisons were the largest part of the set-up
        /// (itself about a third of the bunny's packet path by `perf`).
        ///
        /// # Safety
        /// The CPU must have AVX2.
        #[target_feature(enable = "avx2")]
        pub(super) unsafe fn setup_avx2(&mut self, rays: &[Ray], bounds: &Aabb) -> bool {
            // Whatever the packet held before (it may be reused): both set-ups
            // write every field the walk reads (all lanes) but the mailbox.
            (self.mailbox, self.mailbox_next) = (Packet::EMPTY.mailbox, 0);
            let Ok(rays) = <&[Ray; PACKET]>::try_from(rays) else {
                return self.setup(rays, bounds);
            };
            const { assert!(std::mem::size_of::<Ray>() == 32 && PACKET == 8) };
            // SAFETY: `Ray` is `repr(C)`, eight `f32` (32 bytes, asserted).
            let row = |i: usize| unsafe { _mm256_loadu_ps(rays[i].origin.as_ref().as_ptr()) };
            let (r0, r1, r2, r3) = (row(0), row(1), row(2), row(3));
            let (r4, r5, r6, r7) = (row(4), row(5), row(6), row(7));
            // The usual three-stage 8x8 transpose: interleave pairs of rows,
            // then pairs of pairs, then swap 128-bit halves.
            let (t0, t1) = (_mm256_unpacklo_ps(r0, r1), _mm256_unpackhi_ps(r0, r1));
            let (t2, t3) = (_mm256_unpacklo_ps(r2, r3), _mm256_unpackhi_ps(r2, r3));
            let (t4, t5) = (_mm256_unpacklo_ps(r4, r5), _mm256_unpackhi_ps(r4, r5));
            let (t6, t7) = (_mm256_unpacklo_ps(r6, r7), _mm256_unpackhi_ps(r6, r7));
            let u0 = _mm256_shuffle_ps::<0x44>(t0, t2);
            let u1 = _mm256_shuffle_ps::<0xEE>(t0, t2);
            let u2 = _mm256_shuffle_ps::<0x44>(t1, t3);
            let u3 = _mm256_shuffle_ps::<0xEE>(t1, t3);
            let u4 = _mm256_shuffle_ps::<0x44>(t4, t6);
            let u5 = _mm256_shuffle_ps::<0xEE>(t4, t6);
            let u6 = _mm256_shuffle_ps::<0x44>(t5, t7);
            let u7 = _mm256_shuffle_ps::<0xEE>(t5, t7);
            let col = [
                _mm256_permute2f128_ps::<0x20>(u0, u4),
                _mm256_permute2f128_ps::<0x20>(u1, u5),
                _mm256_permute2f128_ps::<0x20>(u2, u6),
                _mm256_permute2f128_ps::<0x20>(u3, u7),
                _mm256_permute2f128_ps::<0x31>(u0, u4),
                _mm256_permute2f128_ps::<0x31>(u1, u5),
                _mm256_permute2f128_ps::<0x31>(u2, u6),
                _mm256_permute2f128_ps::<0x31>(u3, u7),
            ];
            let store =
                |a: &mut [f32; PACKET], v: __m256| unsafe { _mm256_storeu_ps(a.as_mut_ptr(), v) };
            for k in 0..3 {
                store(&mut self.org[k], col[k]);
                store(&mut self.dir[k], col[3 + k]);
            }
            store(&mut self.tmin, col[6]);
            store(&mut self.best_t, col[7]);
            let neg = [3, 4, 5].map(|c| _mm256_movemask_ps(col[c]) as u32);
            if neg.iter().any(|&m| m != 0 && m != 0xff) {
                return false;
            }
            self.neg = neg.map(|m| m != 0);
            let [ox, oy, oz, dx, dy, dz, tmin, tmax] = col;
            self.setup_full([ox, oy, oz], [dx, dy, dz], tmin, tmax, bounds);
            true
        }

        /// [`Packet::setup_lanes`] for a full packet whose rays share their
        /// direction signs, in AVX2 intrinsics.
        ///
        /// Why: compiled from the portable lane loops, this part of the set-up
        /// was about a thousand instructions with a flat profile (`perf
        /// annotate`), a quarter of the bunny's packet path. Each step below is
        /// the portable one's, lane for lane, with the same rounding and the
        /// same NaN rules (ordered comparisons as Rust's `<`, `>`, `<=`, `>=`;
        /// `blendv` for `if`), so the lanes are bit-identical (tested against
        /// it). One piece for the same reason: split, its steps would pass
        /// their vectors through memory at each call boundary, and they
        /// read step for step against the portable set-up.
        #[target_feature(enable = "avx2")]
        fn setup_full(
            &mut self,
            o: [__m256; 3],
            d: [__m256; 3],
            tmin: __m256,
            tmax: __m256,
            bounds: &Aabb,
        ) {
            let abs = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff));
            let inf = _mm256_set1_ps(f32::INFINITY);
            let zero = _mm256_setzero_ps();
            let store =
                |a: &mut [f32; PACKET], v: __m256| unsafe { _mm256_storeu_ps(a.as_mut_ptr(), v) };
            // `Ray::is_valid` and `tmin <= tmax`.
            let finite = |x: __m256| _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_and_ps(x, abs), inf);
            let mut valid = _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_GE_OQ>(tmin, zero),
                _mm256_cmp_ps::<_CMP_LE_OQ>(tmin, tmax),
            );
            valid = _mm256_and_ps(valid, _mm256_cmp_ps::<_CMP_ORD_Q>(tmax, tmax));
            let mut nonzero = zero;
            for k in 0..3 {
                valid = _mm256_and_ps(valid, _mm256_and_ps(finite(o[k]), finite(d[k])));
                nonzero = _mm256_or_ps(nonzero, _mm256_cmp_ps::<_CMP_NEQ_UQ>(d[k], zero));
            }
            valid = _mm256_and_ps(valid, nonzero);
            // `Aabb::intersect_ray` on `1 / d`, slab by slab.
            let (mut a0, mut a1, mut out) = (tmin, tmax, zero);
            let one = _mm256_set1_ps(1.0);
            let grow = _mm256_set1_ps(FAR_GROW);
            let mut inv = [zero; 3];
            for k in 0..3 {
                let iv = _mm256_div_ps(one, d[k]);
                inv[k] = iv;
                let (lo, hi) = (_mm256_set1_ps(bounds.min[k]), _mm256_set1_ps(bounds.max[k]));
                let near = _mm256_mul_ps(_mm256_sub_ps(lo, o[k]), iv);
                let far = _mm256_mul_ps(_mm256_sub_ps(hi, o[k]), iv);
                let swap = _mm256_cmp_ps::<_CMP_GT_OQ>(near, far);
                let (near, far) = (
                    _mm256_blendv_ps(near, far, swap),
                    _mm256_blendv_ps(far, near, swap),
                );
                let far = _mm256_mul_ps(far, grow);
                let b0 = _mm256_blendv_ps(a0, near, _mm256_cmp_ps::<_CMP_GT_OQ>(near, a0));
                let b1 = _mm256_blendv_ps(a1, far, _mm256_cmp_ps::<_CMP_LT_OQ>(far, a1));
                let parallel = _mm256_cmp_ps::<_CMP_EQ_OQ>(_mm256_and_ps(iv, abs), inf);
                let outside = _mm256_or_ps(
                    _mm256_cmp_ps::<_CMP_LT_OQ>(o[k], lo),
                    _mm256_cmp_ps::<_CMP_GT_OQ>(o[k], hi),
                );
                let empty = _mm256_cmp_ps::<_CMP_GT_OQ>(b0, b1);
                out = _mm256_or_ps(out, _mm256_blendv_ps(empty, outside, parallel));
                a0 = _mm256_blendv_ps(b0, a0, parallel);
                a1 = _mm256_blendv_ps(b1, a1, parallel);
            }
            let on = _mm256_andnot_ps(out, valid);
            let live = _mm256_movemask_ps(on) as u32;
            store(
                &mut self.t0,
                _mm256_blendv_ps(_mm256_set1_ps(OFF.0), a0, on),
            );
            store(
                &mut self.t1,
                _mm256_blendv_ps(_mm256_set1_ps(OFF.1), a1, on),
            );
            // Lanes that are off keep zero origins and reciprocals.
            for k in 0..3 {
                inv[k] = _mm256_and_ps(inv[k], on);
                store(&mut self.org[k], _mm256_and_ps(o[k], on));
                store(&mut self.inv[k], inv[k]);
            }
            (self.k, self.packet_shear, self.frustum) = (None, None, None);
            self.best = [NO_HIT; PACKET];
            self.closest = [f32::INFINITY; PACKET];
            if live == 0 {
                return;
            }
            // `RayShear::new`'s dominant axis (x if |dx| is largest, else y if
            // |dy| >= |dz|, else z) and the sign of d[kz]: one for all live rays?
            let [ax, ay, az] = d.map(|x| _mm256_and_ps(x, abs));
            let is_x = _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_GE_OQ>(ax, ay),
                _mm256_cmp_ps::<_CMP_GE_OQ>(ax, az),
            );
            let is_y = _mm256_andnot_ps(is_x, _mm256_cmp_ps::<_CMP_GE_OQ>(ay, az));
            let (mx, my) = (
                _mm256_movemask_ps(is_x) as u32 & live,
                _mm256_movemask_ps(is_y) as u32 & live,
            );
            let kz = if mx == live {
                0
            } else if my == live {
                1
            } else if mx | my == 0 {
                2
            } else {
                return;
            };
            let kneg = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(d[kz], zero)) as u32 & live;
            if kneg != 0 && kneg != live {
                return;
            }
            let k = permutation(kz, kneg != 0);
            let [kx, ky, kz] = k;
            // As `RayShear::new`: d[kx] / d[kz], d[ky] / d[kz], 1 / d[kz].
            let sx = _mm256_div_ps(d[kx], d[kz]);
            let sy = _mm256_div_ps(d[ky], d[kz]);
            store(&mut self.s[0], sx);
            store(&mut self.s[1], sy);
            store(&mut self.s[2], inv[kz]);
            self.k = Some(k);
            // Lanes that are off borrow the first live lane's constants.
            let first = _mm256_set1_epi32(live.trailing_zeros() as i32);
            let pick = |a: __m256| _mm256_blendv_ps(_mm256_permutevar8x32_ps(a, first), a, on);
            let lanes = |a: __m256| {
                let mut l = [0.0f32; PACKET];
                store(&mut l, pick(a));
                l
            };
            let (ox, oy, oz) = (
                lanes(_mm256_and_ps(o[kx], on)),
                lanes(_mm256_and_ps(o[ky], on)),
                lanes(_mm256_and_ps(o[kz], on)),
            );
            let (sx, sy) = (lanes(sx), lanes(sy));
            self.packet_shear = Some(PacketShear::from_lanes(k, [ox, oy, oz], sx, sy));
            self.frustum = Frustum::from_lanes(k, [&ox, &oy, &oz], &sx, &sy);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::floats;

    /// Every lane equals the scalar computations of its ray, bit for bit:
    /// the root interval (or off), the reciprocals and the shear; rays of
    /// every kind (axis-parallel, zero, invalid, outside the box).
    #[test]
    fn lanes_equal_the_scalar_set_up() {
        let mut f = floats(99);
        let bounds = Aabb::new(Vec3::new(-1.0, -2.0, -0.5), Vec3::new(1.5, 1.0, 2.0));
        let mut shared = 0;
        for round in 0..4000 {
            let n = 1 + round % PACKET;
            let eye = Vec3::new(f(), f(), f()) * 3.0;
            let aim = Vec3::new(f(), f(), f());
            let rays: Vec<Ray> = (0..n)
                .map(|i| {
                    let mut dir = aim + Vec3::new(f(), f(), f()) * 0.1;
                    let mut r = Ray::new(eye, dir);
                    match (round + i) % 23 {
                        0 => dir.x = 0.0,
                        1 => dir = Vec3::new(0.0, 0.0, aim.z),
                        2 => dir = Vec3::ZERO,
                        3 => r.tmin = -1.0,
                        4 => r.tmax = f32::NAN,
                        5 => r.tmax = r.tmin * 0.5,
                        6 => r.origin.x = f32::INFINITY,
                        7 => r.origin = Vec3::new(2.0, 0.0, 0.0),
                        _ => {}
                    }
                    // Keep the signs shared (else there is no packet).
                    r.dir = Vec3::select(aim.cmplt(Vec3::ZERO), -dir.abs(), dir.abs());
                    r
                })
                .collect();
            let mut p = Packet::EMPTY;
            assert!(p.setup(&rays, &bounds), "round {round}: the signs agree");
            assert_same_as_avx2(&p, &rays, &bounds);
            shared += p.k.is_some() as usize;
            for (l, r) in rays.iter().enumerate() {
                let inv = Vec3::ONE / r.dir;
                let want = if r.is_valid() && r.tmin <= r.tmax {
                    bounds.intersect_ray(r.origin, inv, r.tmin, r.tmax)
                } else {
                    None
                };
                let got = (p.t0[l] <= p.t1[l]).then_some((p.t0[l], p.t1[l]));
                let bits = |x: Option<(f32, f32)>| x.map(|(a, b)| (a.to_bits(), b.to_bits()));
                assert_eq!(bits(got), bits(want), "round {round} ray {l}");
                assert_eq!(p.best_t[l].to_bits(), r.tmax.to_bits());
                if got.is_none() {
                    continue;
                }
                for k in 0..3 {
                    assert_eq!(p.inv[k][l].to_bits(), inv[k].to_bits());
                }
                let (a, b) = (p.shear(l), RayShear::from_ray(r));
                assert_eq!(a.k, b.k);
                assert_eq!(
                    a.s.to_array().map(f32::to_bits),
                    b.s.to_array().map(f32::to_bits)
                );
                assert_eq!(a.origin, b.origin);
                assert_eq!(a.dir, b.dir);
            }
            for l in rays.len()..PACKET {
                assert!(p.t0[l] > p.t1[l], "lanes past the rays are off");
            }
        }
        assert!(shared > 400, "{shared} packets with a shared permutation");
    }

    /// The AVX2 set-up (the transposed gather) gives packet `p` exactly.
    fn assert_same_as_avx2(p: &Packet, rays: &[Ray], bounds: &Aabb) {
        #[cfg(target_arch = "x86_64")]
        if crate::simd::has_avx2() {
            let mut q = Packet::EMPTY;
            // SAFETY: the CPU has AVX2.
            assert!(unsafe { q.setup_avx2(rays, bounds) });
            let bits =
                |a: &[Lanes]| -> Vec<u32> { a.iter().flatten().map(|x| x.to_bits()).collect() };
            assert_eq!(p.neg, q.neg);
            assert_eq!(bits(&p.org), bits(&q.org));
            assert_eq!(bits(&p.dir), bits(&q.dir));
            assert_eq!(bits(&p.inv), bits(&q.inv));
            assert_eq!(bits(&p.s), bits(&q.s));
            let scalars = |p: &Packet| bits(&[p.t0, p.t1, p.tmin, p.best_t, p.closest]);
            assert_eq!(scalars(p), scalars(&q));
            assert_eq!(p.k, q.k);
            // Debug prints floats exactly (shortest round-trip form).
            assert_eq!(format!("{:?}", p.frustum), format!("{:?}", q.frustum));
            assert_eq!(
                format!("{:?}", p.packet_shear),
                format!("{:?}", q.packet_shear)
            );
            let hits = |p: &Packet| p.best.map(|h| (h.t.to_bits(), h.tri));
            assert_eq!(hits(p), hits(&q));
        }
    }

    #[test]
    fn mixed_signs_are_refused() {
        let bounds = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        let a = Ray::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 1.0));
        let b = Ray::new(Vec3::ZERO, Vec3::new(1.0, -1.0, 1.0));
        let c = Ray::new(Vec3::ZERO, Vec3::new(1.0, -0.0, 1.0));
        let mut p = Packet::EMPTY;
        assert!(p.setup(&[a, a], &bounds));
        assert!(!p.setup(&[a, b], &bounds));
        assert!(!p.setup(&[a, c], &bounds));
        assert!(!p.setup(&[], &bounds));
        // Full packets (the AVX2 set-up's transposed path), a differing
        // sign in each lane and axis, -0 included.
        for l in 0..PACKET {
            for bad in [b, c, Ray::new(Vec3::ZERO, Vec3::new(-1.0, 1.0, 1.0))] {
                let mut rays = [a; PACKET];
                rays[l] = bad;
                assert!(!p.setup(&rays, &bounds));
                #[cfg(target_arch = "x86_64")]
                if crate::simd::has_avx2() {
                    // SAFETY: the CPU has AVX2.
                    assert!(!unsafe { p.setup_avx2(&rays, &bounds) });
                }
            }
        }
        assert!(p.setup(&[a; PACKET], &bounds));
    }
}
