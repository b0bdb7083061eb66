//! Sixteen-ray packets walked with AVX-512: one node fetch and one
//! decision for sixteen rays (a 4x4 pixel tile), each lane's interval in
//! one 512-bit register.
//!
//! The packet is two eight-ray packets (its halves, each set up as
//! [`Packet`]): the walk advances the sixteen lanes together, with exactly
//! the eight-lane walk's expressions lane for lane (`tp = (split - o) *
//! inv`, `t1 + |t1| MARGIN`, ...; no fused multiply-add), so every lane
//! visits the cells its single-ray walk visits; a leaf is tested by each
//! half that has a live ray in it, with the eight-ray leaf code (its
//! frustum cull, packet triangle test and mailbox).
//!
//! Why: the node walk is about half of the eight-ray packet path's time on
//! camera rays (`perf annotate`, the teapot in its stadium: node load,
//! the two "one side only" branches and the stack pops). Sharing it among
//! sixteen rays traced camera rays 1.06–1.11x as fast as 4x2 packets (1
//! thread, best of 3 interleaved rounds; Cornell box 1.06x, the four large
//! meshes 1.07–1.11x); Embree's 16-ray packets are 1.06–1.25x as fast as
//! its 8-ray ones on the same machine.

use std::arch::x86_64::*;

use super::{Packet, OFF, PACKET};
use crate::build::MAX_DEPTH;
use crate::kd::KdTree;
use crate::leaf::layout::Layout;
use crate::math::slack::MARGIN;
use crate::simd::level;

/// A far child and the sixteen rays' intervals in it.
#[derive(Clone, Copy)]
struct Entry {
    t0: __m512,
    t1: __m512,
    node: u32,
}

/// The two halves' lanes `a` and `b` as one register (`a` low).
///
/// # Safety
/// The CPU must have AVX-512 F.
#[inline(always)]
unsafe fn join(a: &[f32; PACKET], b: &[f32; PACKET]) -> __m512 {
    // SAFETY: AVX-512 F (the caller's contract); each array is 32 bytes.
    unsafe {
        let lo = _mm512_castps_pd(_mm512_castps256_ps512(_mm256_loadu_ps(a.as_ptr())));
        let hi = _mm256_castps_pd(_mm256_loadu_ps(b.as_ptr()));
        _mm512_castpd_ps(_mm512_insertf64x4::<1>(lo, hi))
    }
}

impl KdTree<crate::math::Triangle> {
    /// The sixteen-ray walk over the halves `h` (set up, with the same
    /// direction signs), which collect the closest hits.
    ///
    /// # Safety
    /// The CPU must have AVX2 and AVX-512 F; `layout` must hold this tree's
    /// leaf blocks.
    #[target_feature(enable = "avx2,avx512f")]
    pub(super) unsafe fn walk_packet16_avx512<L: Layout>(&self, layout: L, h: &mut [Packet; 2]) {
        debug_assert_eq!(h[0].neg, h[1].neg);
        // SAFETY (all `join`s): AVX-512 F (the caller's contract).
        let org = [0, 1, 2].map(|k| unsafe { join(&h[0].org[k], &h[1].org[k]) });
        let inv = [0, 1, 2].map(|k| unsafe { join(&h[0].inv[k], &h[1].inv[k]) });
        let (mut t0, mut t1) = unsafe { (join(&h[0].t0, &h[1].t0), join(&h[0].t1, &h[1].t1)) };
        let mut closest = unsafe { join(&h[0].closest, &h[1].closest) };
        let neg = h[0].neg;
        let off0 = _mm512_set1_ps(OFF.0);
        let off1 = _mm512_set1_ps(OFF.1);
        let margin = _mm512_set1_ps(MARGIN);
        let margin1 = _mm512_set1_ps(1.0 + MARGIN);

        let mut stack = [const { std::mem::MaybeUninit::<Entry>::uninit() }; MAX_DEPTH];
        let mut sp = 0usize;
        let mut node = 0u32;
        // As in the eight-lane walk: the widened intervals and the lanes
        // still on change only at a cut or a pop.
        let derive = |t0: __m512, t1: __m512| {
            (
                _mm512_sub_ps(t0, _mm512_mul_ps(_mm512_abs_ps(t0), margin)),
                _mm512_add_ps(t1, _mm512_mul_ps(_mm512_abs_ps(t1), margin)),
                _mm512_cmp_ps_mask::<_CMP_LE_OQ>(t0, t1),
            )
        };
        let (mut lo, mut hi, mut active) = derive(t0, t1);
        let mut live = active;
        while live != 0 {
            debug_assert!((node as usize) < self.nodes.len());
            // SAFETY: node indices come from the builder (see `walk`).
            let nd = unsafe { *self.nodes.get_unchecked(node as usize) };
            if !nd.is_leaf() {
                let axis = nd.axis();
                let (near, far) = nd.near_far(node, &neg);
                // SAFETY: `axis` < 3 for an inner node.
                let (o, iv) = unsafe { (*org.get_unchecked(axis), *inv.get_unchecked(axis)) };
                // The eight-lane walk's decisions, sixteen lanes at once
                // (ordered comparisons: false for a NaN `tp`).
                let tp = _mm512_mul_ps(_mm512_sub_ps(_mm512_set1_ps(nd.split()), o), iv);
                let near_only = _mm512_cmp_ps_mask::<_CMP_GT_OQ>(tp, hi);
                let far_only = !near_only & _mm512_cmp_ps_mask::<_CMP_LT_OQ>(tp, lo);
                let to_near = !far_only & active;
                let to_far = !near_only & active;
                // Every live ray on one side: intervals unchanged.
                if to_far == 0 {
                    node = near;
                    continue;
                }
                if to_near == 0 {
                    node = far;
                    continue;
                }
                // Both sides: cut the intervals at the plane (`minps` and
                // `maxps` return their second operand for a NaN `tp`, as
                // in the eight-lane walk).
                let cut_near = _mm512_max_ps(_mm512_min_ps(tp, t1), t0);
                let cut_far = _mm512_min_ps(_mm512_max_ps(tp, t0), t1);
                let n1 = _mm512_mask_blend_ps(near_only, cut_near, t1);
                let f0 = _mm512_mask_blend_ps(far_only, cut_far, t0);
                let (n0, n1) = (
                    _mm512_mask_blend_ps(to_near, off0, t0),
                    _mm512_mask_blend_ps(to_near, off1, n1),
                );
                let (f0, f1) = (
                    _mm512_mask_blend_ps(to_far, off0, f0),
                    _mm512_mask_blend_ps(to_far, off1, t1),
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
            let count = nd.leaf_count() as usize;
            if count != 0 {
                let live_rays = u32::from(active);
                for (half, p) in h.iter_mut().enumerate() {
                    let m = (live_rays >> (half * PACKET)) & 0xff;
                    // SAFETY: `nd` is a leaf of this tree; AVX2.
                    unsafe {
                        self.packet_leaf::<{ level::AVX2 }, _>(
                            layout,
                            p,
                            nd.leaf_offset() as usize,
                            count,
                            m,
                        )
                    };
                }
                // SAFETY: AVX-512 F.
                closest = unsafe { join(&h[0].closest, &h[1].closest) };
            }
            // Pop the next cell some ray may still find a closer hit in.
            live = 0;
            while sp > 0 {
                sp -= 1;
                // SAFETY: entries below `sp` were written by the push above.
                let e = unsafe { stack.get_unchecked(sp).assume_init() };
                let keep = _mm512_cmp_ps_mask::<_CMP_LE_OQ>(e.t0, e.t1)
                    & _mm512_cmp_ps_mask::<_CMP_LE_OQ>(e.t0, _mm512_mul_ps(closest, margin1));
                if keep != 0 {
                    live = keep;
                    t0 = _mm512_mask_blend_ps(keep, off0, e.t0);
                    t1 = _mm512_mask_blend_ps(keep, off1, e.t1);
                    (lo, hi, active) = derive(t0, t1);
                    node = e.node;
                    break;
                }
            }
        }
    }
}
