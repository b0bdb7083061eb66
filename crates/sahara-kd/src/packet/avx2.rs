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

use std::arch::x86_64::*;

use super::{Packet, OFF, PACKET};
use crate::geometry::{Aabb, Ray, Triangle};
use crate::traverse::{MARGIN, MAX_DEPTH};
use crate::tree::KdTree;

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
        self.setup_lanes(PACKET, neg, bounds)
    }
}

impl KdTree<Triangle> {
    /// The packet walk (see the module doc).
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn walk_packet_avx2(&self, p: &mut Packet) {
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
        let mut live = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1)) as u32;
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
                let hi = _mm256_add_ps(t1, _mm256_mul_ps(_mm256_and_ps(t1, abs), margin));
                let lo = _mm256_sub_ps(t0, _mm256_mul_ps(_mm256_and_ps(t0, abs), margin));
                // Ordered comparisons: false for a NaN `tp` (ray in the
                // plane), as Rust's `>` and `<` are.
                let near_only = _mm256_cmp_ps::<_CMP_GT_OQ>(tp, hi);
                let far_only = _mm256_andnot_ps(near_only, _mm256_cmp_ps::<_CMP_LT_OQ>(tp, lo));
                let active = _mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1);
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
                continue;
            }
            let live_rays = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1)) as u32;
            let count = nd.leaf_count() as usize;
            if count != 0 {
                // SAFETY: `nd` is a leaf of this tree.
                unsafe { self.packet_leaf(p, nd.leaf_offset() as usize, count, live_rays) };
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
                    node = e.node;
                    break;
                }
            }
        }
    }
}
