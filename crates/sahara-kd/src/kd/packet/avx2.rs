//! The packet walk with AVX2 intrinsics: each inner node costs a handful of
//! 256-bit operations for all eight rays.
//!
//! Why intrinsics: the portable walk's per-lane loops (with their
//! three-way choices) were left scalar by the compiler; the profile of the
//! packet path showed scalar `vsubss`/`vmulss` sequences and mask bytes
//! throughout, and with leaf tests switched off it still ran at the speed
//! of the single-ray path (sponza 7.5 Mrays/s), so the inner step was the
//! bottleneck. Each lane computes exactly the portable walk's expressions
//! (`tp = (split - o) * inv`, `t1 + |t1| MARGIN`, ...; no fused
//! multiply-add), so both walks visit the same cells and the leaf tests
//! give bit-identical hits.

use crate::leaf::layout::Layout;
use crate::simd::level;
use std::arch::x86_64::*;

use super::{Packet, NO_HIT, OFF, PACKET};
use crate::build::MAX_DEPTH;
use crate::isect::permutation;
use crate::kd::KdTree;
use crate::leaf::Frustum;
use crate::leaf::PacketShear;
use crate::math::slack::FAR_GROW;
use crate::math::slack::MARGIN;
use crate::math::{Aabb, Ray, Triangle};

/// A far child and the rays' intervals in it.
#[derive(Clone, Copy)]
struct Entry {
    t0: __m256,
    t1: __m256,
    node: u32,
}

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
    /// it).
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

impl KdTree<Triangle> {
    /// The packet walk (see the module doc).
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn walk_packet_avx2<L: Layout>(&self, layout: L, p: &mut Packet) {
        let load = |a: &[f32; PACKET]| unsafe { _mm256_loadu_ps(a.as_ptr()) };
        let org = [load(&p.org[0]), load(&p.org[1]), load(&p.org[2])];
        let inv = [load(&p.inv[0]), load(&p.inv[1]), load(&p.inv[2])];
        let (mut t0, mut t1) = (load(&p.t0), load(&p.t1));
        let off0 = _mm256_set1_ps(OFF.0);
        let off1 = _mm256_set1_ps(OFF.1);
        let abs = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff));
        let margin = _mm256_set1_ps(MARGIN);
        let margin1 = _mm256_set1_ps(1.0 + MARGIN);
        let mut closest = load(&p.closest);

        let mut stack = [const { std::mem::MaybeUninit::<Entry>::uninit() }; MAX_DEPTH];
        let mut sp = 0usize;
        let mut node = 0u32;
        // The intervals widened by the margin and the lanes still on, kept
        // beside the intervals: they change only where the intervals do (a
        // cut or a pop), not at the one-sided steps.
        let derive = |t0: __m256, t1: __m256| {
            (
                _mm256_sub_ps(t0, _mm256_mul_ps(_mm256_and_ps(t0, abs), margin)),
                _mm256_add_ps(t1, _mm256_mul_ps(_mm256_and_ps(t1, abs), margin)),
                _mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1),
            )
        };
        let (mut lo, mut hi, mut active) = derive(t0, t1);
        let mut live = _mm256_movemask_ps(active) as u32;
        while live != 0 {
            debug_assert!((node as usize) < self.nodes.len());
            // SAFETY: node indices come from the builder (see `walk`).
            let nd = unsafe { *self.nodes.get_unchecked(node as usize) };
            if !nd.is_leaf() {
                let axis = nd.axis();
                let (near, far) = nd.near_far(node, &p.neg);
                // SAFETY: `axis` < 3 for an inner node.
                let (o, iv) = unsafe { (*org.get_unchecked(axis), *inv.get_unchecked(axis)) };
                let tp = _mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(nd.split()), o), iv);
                // Ordered comparisons: false for a NaN `tp` (ray in the
                // plane), as Rust's `>` and `<` are.
                let near_only = _mm256_cmp_ps::<_CMP_GT_OQ>(tp, hi);
                let far_only = _mm256_andnot_ps(near_only, _mm256_cmp_ps::<_CMP_LT_OQ>(tp, lo));
                let to_near = _mm256_andnot_ps(far_only, active);
                let to_far = _mm256_andnot_ps(near_only, active);
                let (nm, fm) = (_mm256_movemask_ps(to_near), _mm256_movemask_ps(to_far));
                // Every live ray on one side: its interval is unchanged
                // (and lanes that are off stay off).
                if fm == 0 {
                    node = near;
                    continue;
                }
                if nm == 0 {
                    node = far;
                    continue;
                }
                // Both sides: cut the intervals at the plane, as the
                // portable walk does (`tp.min(t1).max(t0)`; `minps`
                // returns its second operand for a NaN `tp`, as `f32::min`
                // returns the non-NaN one).
                let cut_near = _mm256_max_ps(_mm256_min_ps(tp, t1), t0);
                let cut_far = _mm256_min_ps(_mm256_max_ps(tp, t0), t1);
                let n1 = _mm256_blendv_ps(cut_near, t1, near_only);
                let f0 = _mm256_blendv_ps(cut_far, t0, far_only);
                let (n0, n1) = (
                    _mm256_blendv_ps(off0, t0, to_near),
                    _mm256_blendv_ps(off1, n1, to_near),
                );
                let (f0, f1) = (
                    _mm256_blendv_ps(off0, f0, to_far),
                    _mm256_blendv_ps(off1, t1, to_far),
                );
                debug_assert!(sp < MAX_DEPTH, "tree deeper than the traversal stack");
                // SAFETY: builders never exceed MAX_DEPTH levels.
                unsafe {
                    stack.get_unchecked_mut(sp).write(Entry {
                        t0: f0,
                        t1: f1,
                        node: far,
                    })
                };
                sp += 1;
                (node, t0, t1) = (near, n0, n1);
                (lo, hi, active) = derive(t0, t1);
                continue;
            }
            let live_rays = _mm256_movemask_ps(active) as u32;
            let count = nd.leaf_count() as usize;
            if count != 0 {
                // SAFETY: `nd` is a leaf of this tree.
                unsafe {
                    self.packet_leaf::<{ level::AVX2 }, _>(
                        layout,
                        p,
                        nd.leaf_offset() as usize,
                        count,
                        live_rays,
                    )
                };
                closest = load(&p.closest);
            }
            // Pop the next cell some ray may still find a closer hit in.
            live = 0;
            while sp > 0 {
                sp -= 1;
                // SAFETY: entries below `sp` were written by the push above.
                let e = unsafe { stack.get_unchecked(sp).assume_init() };
                let keep = _mm256_and_ps(
                    _mm256_cmp_ps::<_CMP_LE_OQ>(e.t0, e.t1),
                    _mm256_cmp_ps::<_CMP_LE_OQ>(e.t0, _mm256_mul_ps(closest, margin1)),
                );
                live = _mm256_movemask_ps(keep) as u32;
                if live != 0 {
                    t0 = _mm256_blendv_ps(off0, e.t0, keep);
                    t1 = _mm256_blendv_ps(off1, e.t1, keep);
                    (lo, hi, active) = derive(t0, t1);
                    node = e.node;
                    break;
                }
            }
        }
    }
}
