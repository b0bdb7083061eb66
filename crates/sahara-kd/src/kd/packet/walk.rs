//! The packet walk, written once for eight lanes (portable or AVX2) and
//! sixteen (AVX-512): one node fetch and one decision for all the rays.
//!
//! Each lane computes exactly the single-ray walk's expressions (the rules
//! of `kd::interval`; no fused multiply-add), so every lane visits the
//! cells its single-ray walk visits and the leaf tests give bit-identical
//! hits. The widened intervals and the mask of lanes still on are kept
//! beside the intervals: they change only where the intervals do (a cut or
//! a pop), not at the one-sided steps.

use super::{Lanes, Packet, OFF, PACKET};
use crate::build::MAX_DEPTH;
use crate::kd::interval::{cut, may_hold_closer, widened_t0, widened_t1};
use crate::kd::KdTree;
use crate::leaf::layout::Layout;
use crate::math::Triangle;
use crate::simd::lanes::FloatLanes;

/// A far child and the rays' intervals in it (`t0 > t1`: ray masked off).
#[derive(Clone, Copy)]
struct Entry<L> {
    t0: L,
    t1: L,
    node: u32,
}

/// Where a walk starts: the rays' direction signs, origins, reciprocal
/// directions and intervals in the root cell, lane by lane.
pub(super) struct Start<L> {
    neg: [bool; 3],
    org: [L; 3],
    inv: [L; 3],
    t0: L,
    t1: L,
    closest: L,
}

/// The rays a walk carries and what it does at a non-empty leaf.
pub(super) trait PacketLeaves<L> {
    /// The lanes at the root.
    fn start(&self) -> Start<L>;

    /// Test the leaf at `offset` with `count` triangles for the rays in
    /// `live` (bit `l` = lane `l`); return every lane's closest hit
    /// distance so far (infinity where there is none).
    ///
    /// # Safety
    /// `offset` and `count` are those of a non-empty leaf of the walked
    /// tree.
    unsafe fn visit(&mut self, offset: usize, count: usize, live: u32) -> L;
}

impl KdTree<Triangle> {
    /// The packet walk over the lanes of `leaves` (see the module doc).
    ///
    /// # Safety
    /// The CPU must have the instructions of the lane form `L`, and the
    /// caller must be compiled for them.
    #[inline(always)]
    pub(super) unsafe fn walk_packet<L: FloatLanes, V: PacketLeaves<L>>(&self, mut leaves: V) {
        let Start {
            neg,
            org,
            inv,
            mut t0,
            mut t1,
            mut closest,
        } = leaves.start();
        let (off0, off1) = (L::splat(OFF.0), L::splat(OFF.1));
        let mut stack = [const { std::mem::MaybeUninit::<Entry<L>>::uninit() }; MAX_DEPTH];
        let mut sp = 0usize;
        let mut node = 0u32;
        let (mut lo, mut hi, mut active) = derive(t0, t1);
        let mut live = L::bits(active);
        while live != 0 {
            debug_assert!((node as usize) < self.nodes.len());
            // SAFETY: node indices come from the builder (see `walk`).
            let nd = unsafe { *self.nodes.get_unchecked(node as usize) };
            if !nd.is_leaf() {
                let axis = nd.axis();
                let (near, far) = nd.near_far(node, &neg);
                // SAFETY: `axis` < 3 for an inner node.
                let (o, iv) = unsafe { (*org.get_unchecked(axis), *inv.get_unchecked(axis)) };
                let tp = L::splat(nd.split()).sub(o).mul(iv);
                let near_only = tp.gt(hi);
                let far_only = L::and_not(near_only, tp.lt(lo));
                let to_near = L::and_not(far_only, active);
                let to_far = L::and_not(near_only, active);
                // Every live ray on one side: its interval is unchanged
                // (and lanes that are off stay off).
                if L::bits(to_far) == 0 {
                    node = near;
                    continue;
                }
                if L::bits(to_near) == 0 {
                    node = far;
                    continue;
                }
                // Both sides: cut the intervals at the plane.
                let (cut_near, cut_far) = cut(tp, t0, t1);
                let n1 = L::select(near_only, t1, cut_near);
                let f0 = L::select(far_only, t0, cut_far);
                let (n0, n1) = (L::select(to_near, t0, off0), L::select(to_near, n1, off1));
                let (f0, f1) = (L::select(to_far, f0, off0), L::select(to_far, t1, off1));
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
                // SAFETY: `nd` is a non-empty leaf of this tree.
                closest =
                    unsafe { leaves.visit(nd.leaf_offset() as usize, count, L::bits(active)) };
            }
            // Pop the next cell some ray may still find a closer hit in.
            live = 0;
            while sp > 0 {
                sp -= 1;
                // SAFETY: entries below `sp` were written by the push above.
                let e = unsafe { stack.get_unchecked(sp).assume_init() };
                let keep = L::and(e.t0.le(e.t1), may_hold_closer(e.t0, closest));
                live = L::bits(keep);
                if live != 0 {
                    t0 = L::select(keep, e.t0, off0);
                    t1 = L::select(keep, e.t1, off1);
                    (lo, hi, active) = derive(t0, t1);
                    node = e.node;
                    break;
                }
            }
        }
    }
}

/// The widened interval and the lanes still on. (A function, not a
/// closure: a closure is compiled without its caller's target features.)
#[inline(always)]
fn derive<L: FloatLanes>(t0: L, t1: L) -> (L, L, L::Mask) {
    (widened_t0(t0), widened_t1(t1), t0.le(t1))
}

/// An eight-lane form that loads from a packet's lane arrays.
pub(super) trait Load8: FloatLanes {
    /// The lanes of `a`.
    ///
    /// # Safety
    /// As [`FloatLanes`]: the CPU has the form's instructions.
    unsafe fn load(a: &Lanes) -> Self;
}

impl Load8 for Lanes {
    #[inline(always)]
    unsafe fn load(a: &Lanes) -> Self {
        *a
    }
}

#[cfg(target_arch = "x86_64")]
impl Load8 for std::arch::x86_64::__m256 {
    #[inline(always)]
    unsafe fn load(a: &Lanes) -> Self {
        // SAFETY: eight f32; AVX (the caller's contract).
        unsafe { std::arch::x86_64::_mm256_loadu_ps(a.as_ptr()) }
    }
}

/// An eight-ray packet's leaves, tested at level `SIMD`.
pub(super) struct Leaf8<'a, const SIMD: u8, Y> {
    tree: &'a KdTree<Triangle>,
    layout: Y,
    p: &'a mut Packet,
}

impl<'a, const SIMD: u8, Y: Layout> Leaf8<'a, SIMD, Y> {
    /// The leaves of `tree` (blocks `layout`) for the packet `p`, set up.
    #[inline(always)]
    pub(super) fn new(tree: &'a KdTree<Triangle>, layout: Y, p: &'a mut Packet) -> Self {
        Self { tree, layout, p }
    }
}

impl<const SIMD: u8, Y: Layout, L: Load8> PacketLeaves<L> for Leaf8<'_, SIMD, Y> {
    #[inline(always)]
    fn start(&self) -> Start<L> {
        let p = &self.p;
        // SAFETY: the walk runs where the form's instructions are (the
        // walk's contract). No closure here (see `derive`).
        unsafe {
            Start {
                neg: p.neg,
                org: [L::load(&p.org[0]), L::load(&p.org[1]), L::load(&p.org[2])],
                inv: [L::load(&p.inv[0]), L::load(&p.inv[1]), L::load(&p.inv[2])],
                t0: L::load(&p.t0),
                t1: L::load(&p.t1),
                closest: L::load(&p.closest),
            }
        }
    }

    #[inline(always)]
    unsafe fn visit(&mut self, offset: usize, count: usize, live: u32) -> L {
        // SAFETY: a leaf of this tree (the caller's contract); the level's
        // instructions (the walk's).
        unsafe {
            self.tree
                .packet_leaf::<SIMD, _>(self.layout, self.p, offset, count, live);
            L::load(&self.p.closest)
        }
    }
}

/// The halves' lanes `a` and `b` as one sixteen-lane register (`a` low).
///
/// # Safety
/// The CPU must have AVX-512 F, and the caller must be compiled for it.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn join(a: &Lanes, b: &Lanes) -> std::arch::x86_64::__m512 {
    use std::arch::x86_64::*;
    // SAFETY: AVX-512 F (the caller's contract); each array is 32 bytes.
    unsafe {
        let lo = _mm512_castps_pd(_mm512_castps256_ps512(_mm256_loadu_ps(a.as_ptr())));
        let hi = _mm256_castps_pd(_mm256_loadu_ps(b.as_ptr()));
        _mm512_castpd_ps(_mm512_insertf64x4::<1>(lo, hi))
    }
}

/// A sixteen-ray packet's leaves: each half that has a live ray in a leaf
/// tests it with the eight-ray leaf test (its frustum cull, packet
/// triangle test and mailbox), at level `SIMD`.
pub(super) struct Leaf16<'a, const SIMD: u8, Y> {
    tree: &'a KdTree<Triangle>,
    layout: Y,
    h: &'a mut [Packet; 2],
}

impl<'a, const SIMD: u8, Y: Layout> Leaf16<'a, SIMD, Y> {
    /// The leaves of `tree` (blocks `layout`) for the halves `h`, set up
    /// with the same direction signs.
    #[inline(always)]
    pub(super) fn new(tree: &'a KdTree<Triangle>, layout: Y, h: &'a mut [Packet; 2]) -> Self {
        debug_assert_eq!(h[0].neg, h[1].neg);
        Self { tree, layout, h }
    }
}

#[cfg(target_arch = "x86_64")]
impl<const SIMD: u8, Y: Layout> PacketLeaves<std::arch::x86_64::__m512> for Leaf16<'_, SIMD, Y> {
    #[inline(always)]
    fn start(&self) -> Start<std::arch::x86_64::__m512> {
        let [a, b] = &*self.h;
        // SAFETY: AVX-512 F (the walk's contract).
        let j = |x: &Lanes, y: &Lanes| unsafe { join(x, y) };
        Start {
            neg: a.neg,
            org: [
                j(&a.org[0], &b.org[0]),
                j(&a.org[1], &b.org[1]),
                j(&a.org[2], &b.org[2]),
            ],
            inv: [
                j(&a.inv[0], &b.inv[0]),
                j(&a.inv[1], &b.inv[1]),
                j(&a.inv[2], &b.inv[2]),
            ],
            t0: j(&a.t0, &b.t0),
            t1: j(&a.t1, &b.t1),
            closest: j(&a.closest, &b.closest),
        }
    }

    #[inline(always)]
    unsafe fn visit(
        &mut self,
        offset: usize,
        count: usize,
        live: u32,
    ) -> std::arch::x86_64::__m512 {
        for (half, p) in self.h.iter_mut().enumerate() {
            let m = (live >> (half * PACKET)) & 0xff;
            // SAFETY: a leaf of this tree (the caller's contract); the
            // level's instructions (the walk's).
            unsafe {
                self.tree
                    .packet_leaf::<SIMD, _>(self.layout, p, offset, count, m)
            };
        }
        // SAFETY: AVX-512 F (the walk's contract).
        unsafe { join(&self.h[0].closest, &self.h[1].closest) }
    }
}
