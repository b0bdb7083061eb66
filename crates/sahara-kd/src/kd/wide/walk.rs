//! The single-ray walk over wide nodes.
//!
//! At a wide node the ray's distances to the seven planes are computed at
//! once, and from them every slot's interval: a slot's entry is the
//! largest of the cell's entry and the distances of the planes it lies
//! beyond (seen from the ray), its exit the smallest of the cell's exit and
//! the distances of the planes it lies before; a NaN distance (a ray lying
//! in the plane, or a NaN plane of a shallow subtree) is passed over, so
//! the interval stays whole, as in the binary walk. A slot is visited if
//! its widened interval is not empty (the rule of `kd::interval`, which
//! visits every cell the binary walk visits) and its entry is not beyond
//! the closest hit. The visited slots are pushed onto the stack farthest
//! first, in the order the direction signs give (`FAR_FIRST`), and the
//! walk goes on with the top of the stack. There is no branch per plane:
//! the binary walk's near/far and one-side/both-sides decisions, which a
//! predictor cannot guess for incoherent rays, become lane operations.
//!
//! With AVX2 the planes, the intervals and the order are vector
//! operations; the visited slots are packed onto the stack with a
//! permutation from a table (AVX2) or `vpcompressd` (AVX-512). The
//! portable form computes the same values lane by lane.

use std::mem::MaybeUninit;

use glam::Vec3;

use super::node::{leaf_of, leaf_of_inline, WideNode, FAR_FIRST, LEAF_BIT, PLANES, WIDTH};
use crate::build::MAX_DEPTH;
use crate::kd::interval::{may_hold_closer, widened_t0, widened_t1};
use crate::kd::walk::{LeafResult, LeafVisit};
use crate::kd::{Counters, KdTree, LeafStorage};
use crate::leaf::layout::prefetch_lines;
use crate::math::slack::MARGIN;
use crate::math::Ray;
#[cfg(target_arch = "x86_64")]
use crate::simd::level;

/// Stack entries: each wide level pushes at most eight and pops one, and
/// the vector forms store eight lanes past the top.
const STACK: usize = (WIDTH - 1) * (MAX_DEPTH / 3 + 2) + 2 * WIDTH;

/// The far-child stack, one array per field (the vector forms store
/// eight entries of each field at once).
struct Stack {
    node: [MaybeUninit<u32>; STACK],
    t0: [MaybeUninit<f32>; STACK],
    t1: [MaybeUninit<f32>; STACK],
}

/// The ray as the node step reads it: origin and reciprocal direction in
/// lanes 0-2 (eight lanes, for the vector forms' loads).
struct WideRay {
    origin: [f32; WIDTH],
    inv: [f32; WIDTH],
    /// Bit `a`: the ray moves towards -axis `a` (the direction's sign bit).
    neg: u32,
}

/// One ray's walk in progress: its stack and closest hit distance. The
/// single-ray walk runs one to its end; the interleaved batch walk keeps
/// several and advances each in turn.
pub(crate) struct Walker {
    stack: Stack,
    sp: usize,
    closest: f32,
    ray: WideRay,
}

impl Walker {
    /// A walker with nothing to do.
    #[inline(always)]
    pub(crate) fn idle() -> Self {
        Self {
            stack: Stack {
                node: [const { MaybeUninit::uninit() }; STACK],
                t0: [const { MaybeUninit::uninit() }; STACK],
                t1: [const { MaybeUninit::uninit() }; STACK],
            },
            sp: 0,
            closest: f32::INFINITY,
            ray: WideRay {
                origin: [0.0; WIDTH],
                inv: [0.0; WIDTH],
                neg: 0,
            },
        }
    }

    /// Starts the walk of `ray` at the root of `tree` (with wide nodes);
    /// false if there is nothing to walk (an invalid ray, or one that
    /// misses the root cell).
    #[inline(always)]
    pub(crate) fn start<P: LeafStorage>(&mut self, tree: &KdTree<P>, ray: &Ray) -> bool {
        self.sp = 0;
        self.closest = f32::INFINITY;
        if tree.wide.is_empty() || !ray.is_valid() || ray.tmin > ray.tmax {
            return false;
        }
        let inv_dir = Vec3::ONE / ray.dir;
        let Some((t0, t1)) = tree
            .bounds
            .intersect_ray(ray.origin, inv_dir, ray.tmin, ray.tmax)
        else {
            return false;
        };
        let dir = ray.dir.to_array();
        let (o, i) = (ray.origin, inv_dir);
        self.ray = WideRay {
            origin: [o.x, o.y, o.z, 0.0, 0.0, 0.0, 0.0, 0.0],
            inv: [i.x, i.y, i.z, 1.0, 1.0, 1.0, 1.0, 1.0],
            neg: (0..3)
                .map(|a| (dir[a].is_sign_negative() as u32) << a)
                .sum(),
        };
        self.stack.node[0] = MaybeUninit::new(0);
        self.stack.t0[0] = MaybeUninit::new(t0);
        self.stack.t1[0] = MaybeUninit::new(t1);
        self.sp = 1;
        true
    }

    /// One step of the walk: the top entry of the stack popped and
    /// visited (a wide node's visited slots pushed, or a leaf tested).
    /// Returns false once the walk is over. With `PREFETCH`, asks the
    /// cache for what the next step visits. `SIMD` is the level the caller
    /// is compiled for.
    #[inline(always)]
    pub(crate) fn advance<P: LeafStorage, C: Counters, const SIMD: u8, const PREFETCH: bool>(
        &mut self,
        tree: &KdTree<P>,
        counters: &mut C,
        leaf: &mut impl LeafVisit<C>,
    ) -> bool {
        if self.sp == 0 {
            return false;
        }
        self.sp -= 1;
        let sp = self.sp;
        // SAFETY: entries below `sp` were written by a push.
        let (node, t0, t1) = unsafe {
            (
                self.stack.node[sp].assume_init(),
                self.stack.t0[sp].assume_init(),
                self.stack.t1[sp].assume_init(),
            )
        };
        // Every stacked cell may hold a closer hit: the steps push only
        // such cells, and a closer hit drops the others at once (see
        // `drop_beyond_closest`), so no entry is popped only to be passed
        // over.
        debug_assert!(may_hold_closer(t0, self.closest));
        if node & LEAF_BIT != 0 {
            counters.leaf();
            let (offset, count) = leaf_of(node, tree.wide_shift, &tree.nodes);
            let before = self.closest;
            let r = leaf.visit(offset as usize, count as usize, counters, &mut self.closest);
            if let LeafResult::Stop = r {
                self.sp = 0;
                return false;
            }
            if self.closest < before {
                self.drop_beyond_closest();
            }
            return self.prefetch_top::<P, C, PREFETCH>(tree, leaf);
        }
        counters.inner();
        debug_assert!((node as usize) < tree.wide.len());
        // SAFETY: child words name wide nodes `derive` wrote.
        let n = unsafe { tree.wide.get_unchecked(node as usize) };
        debug_assert!(sp + 2 * WIDTH <= STACK, "tree deeper than the stack");
        #[cfg(target_arch = "x86_64")]
        if SIMD >= level::AVX2 {
            // SAFETY: the caller's level; `sp + 8` entries fit the stack.
            let (k, top) = unsafe {
                vector::step::<SIMD>(n, &self.ray, t0, t1, self.closest, &mut self.stack, sp)
            };
            self.sp += k;
            if PREFETCH {
                // The new top from the registers (loaded back from the
                // stack, it would wait for the vector stores just made), or
                // the one below when nothing was pushed; chosen without a
                // branch, which the predictor could not guess. Entry 0 is
                // written at the start, so the load is always of a pushed
                // word.
                // SAFETY: as above.
                let below = unsafe { self.stack.node[self.sp.max(1) - 1].assume_init() };
                prefetch_word(tree, leaf, if k != 0 { top } else { below });
            }
            return self.sp != 0;
        }
        self.sp += step(n, &self.ray, t0, t1, self.closest, &mut self.stack, sp);
        self.prefetch_top::<P, C, PREFETCH>(tree, leaf)
    }

    /// Removes the stacked cells entered beyond the closest hit (keeping
    /// the others in order): the walk then ends as soon as the last cell
    /// that may hold a closer hit is done, instead of popping the others
    /// one step at a time.
    #[inline(always)]
    fn drop_beyond_closest(&mut self) {
        let mut kept = 0;
        for i in 0..self.sp {
            // SAFETY: entries below `sp` were written by a push.
            let (node, t0, t1) = unsafe {
                (
                    self.stack.node[i].assume_init(),
                    self.stack.t0[i].assume_init(),
                    self.stack.t1[i].assume_init(),
                )
            };
            self.stack.node[kept] = MaybeUninit::new(node);
            self.stack.t0[kept] = MaybeUninit::new(t0);
            self.stack.t1[kept] = MaybeUninit::new(t1);
            kept += may_hold_closer(t0, self.closest) as usize;
        }
        self.sp = kept;
    }

    /// With `PREFETCH`, asks the cache for the top entry's node or leaf;
    /// returns whether the walk goes on.
    #[inline(always)]
    fn prefetch_top<P: LeafStorage, C, const PREFETCH: bool>(
        &self,
        tree: &KdTree<P>,
        leaf: &impl LeafVisit<C>,
    ) -> bool {
        if self.sp == 0 {
            return false;
        }
        if PREFETCH {
            // SAFETY: entries below `sp` were written by a push.
            let word = unsafe { self.stack.node[self.sp - 1].assume_init() };
            prefetch_word(tree, leaf, word);
        }
        true
    }

    /// Asks the cache for the node or leaf the walk visits first.
    #[inline(always)]
    pub(crate) fn prefetch_first<P: LeafStorage, C>(
        &self,
        tree: &KdTree<P>,
        leaf: &impl LeafVisit<C>,
    ) {
        self.prefetch_top::<P, C, true>(tree, leaf);
    }
}

/// Asks the cache for the wide node or the leaf that child word `word`
/// names, without a branch on which it is (the predictor could not guess
/// it): the address is selected, and five lines are fetched from it (a
/// block of eight triangles, or a node and the nodes after it, its first
/// subtree), and one more line the leaf test reads. A leaf that does not
/// fit its word inline gets a useless hint.
#[inline(always)]
fn prefetch_word<P: LeafStorage, C>(tree: &KdTree<P>, leaf: &impl LeafVisit<C>, word: u32) {
    let (offset, _) = leaf_of_inline(word, tree.wide_shift);
    let (block, other) = leaf.leaf_address(offset as usize);
    let node = tree.wide.as_ptr().wrapping_add(word as usize).cast::<u8>();
    let is_leaf = word & LEAF_BIT != 0;
    let first = if is_leaf { block } else { node };
    let second = if is_leaf { other } else { node };
    prefetch_lines(first, 5);
    prefetch_lines(second, 1);
}

/// The planes of slot `c` at the three levels.
#[inline(always)]
fn slot_planes(c: usize) -> [usize; 3] {
    let (b0, b1) = (c >> 2, (c >> 1) & 1);
    [0, 1 + b0, 3 + 2 * b0 + b1]
}

/// The node step, lane by lane: pushes the slots to visit farthest first
/// and returns how many.
#[inline(always)]
fn step(
    n: &WideNode,
    r: &WideRay,
    t0: f32,
    t1: f32,
    closest: f32,
    stack: &mut Stack,
    sp: usize,
) -> usize {
    let mut tp = [0.0f32; PLANES];
    let mut neg = 0usize;
    for (p, tp) in tp.iter_mut().enumerate() {
        let a = n.axis(p);
        *tp = (n.planes[p] - r.origin[a]) * r.inv[a];
        neg |= ((r.neg >> a) as usize & 1) << p;
    }
    let used = n.used();
    let mut k = 0;
    for &c in &FAR_FIRST[neg] {
        let c = c as usize;
        if used >> c & 1 == 0 {
            continue;
        }
        let rank = super::node::rank(neg, c);
        let (mut lo, mut hi) = (t0, t1);
        for (level, p) in slot_planes(c).into_iter().enumerate() {
            // Written as `maxps` / `minps` compute them: a NaN distance
            // leaves the bound as it was.
            if rank >> (2 - level) & 1 == 1 {
                lo = if tp[p] > lo { tp[p] } else { lo };
            } else {
                hi = if tp[p] < hi { tp[p] } else { hi };
            }
        }
        if widened_t0(lo) <= widened_t1(hi) && may_hold_closer(lo, closest) {
            stack.node[sp + k] = MaybeUninit::new(n.children[c]);
            stack.t0[sp + k] = MaybeUninit::new(lo);
            stack.t1[sp + k] = MaybeUninit::new(hi);
            k += 1;
        }
    }
    k
}

/// `MARGIN` is a power of two, so `x (1 + MARGIN)` rounds as the walks'
/// other uses of it do.
const _: () = assert!(MARGIN == 1.0 / 4096.0);

#[cfg(target_arch = "x86_64")]
mod vector {
    use std::arch::x86_64::*;

    use super::{Stack, WideRay};
    use crate::kd::wide::node::{rank, WideNode, FAR_FIRST, PLANES, WIDTH};
    use crate::math::slack::MARGIN;
    use crate::simd::level;

    /// Slot `c`'s rank in front-to-back order (see `node::rank`), per
    /// combination of plane signs: bit 2 - level set where the slot lies
    /// beyond its plane at that level.
    static RANK: [[u8; WIDTH]; 1 << PLANES] = {
        let mut t = [[0u8; WIDTH]; 1 << PLANES];
        let mut neg = 0;
        while neg < 1 << PLANES {
            let mut c = 0;
            while c < WIDTH {
                t[neg][c] = rank(neg, c) as u8;
                c += 1;
            }
            neg += 1;
        }
        t
    };

    /// Per combination of plane signs, per level: the slots that lie
    /// beyond their plane at that level (bit `c` for slot `c`).
    static BEYOND: [[u8; 3]; 1 << PLANES] = {
        let mut t = [[0u8; 3]; 1 << PLANES];
        let mut neg = 0;
        while neg < 1 << PLANES {
            let mut c = 0;
            while c < WIDTH {
                let r = rank(neg, c);
                let mut level = 0;
                while level < 3 {
                    t[neg][level] |= (((r >> (2 - level)) & 1) << c) as u8;
                    level += 1;
                }
                c += 1;
            }
            neg += 1;
        }
        t
    };

    /// For each mask of lanes, the lanes set, packed to the front
    /// (`vpcompressd` as a permutation, for AVX2).
    static PACK: [[u8; WIDTH]; 256] = {
        let mut t = [[0u8; WIDTH]; 256];
        let mut m = 0;
        while m < 256 {
            let (mut k, mut l) = (0, 0);
            while l < WIDTH {
                if m >> l & 1 == 1 {
                    t[m][k] = l as u8;
                    k += 1;
                }
                l += 1;
            }
            m += 1;
        }
        t
    };

    /// Eight bytes as eight 32-bit lanes.
    #[inline(always)]
    unsafe fn lanes_of(bytes: &[u8; WIDTH]) -> __m256i {
        unsafe { _mm256_cvtepu8_epi32(_mm_loadl_epi64(bytes.as_ptr().cast())) }
    }

    /// The node step of `super::step` in vector form (the same values):
    /// pushes the slots to visit farthest first at `sp`; returns how many,
    /// and the child word now on top (if any).
    ///
    /// # Safety
    /// AVX2 (AVX-512 F + VL at that level) and the caller compiled for it;
    /// `sp + 8` entries fit the stack.
    #[inline(always)]
    pub(super) unsafe fn step<const SIMD: u8>(
        n: &WideNode,
        r: &WideRay,
        t0: f32,
        t1: f32,
        closest: f32,
        stack: &mut Stack,
        sp: usize,
    ) -> (usize, u32) {
        if SIMD >= level::AVX512 {
            // SAFETY: the caller's contract.
            return unsafe { step512(n, r, t0, t1, closest, stack, sp) };
        }
        unsafe {
            let planes = _mm256_load_ps(n.planes.as_ptr());
            let meta = _mm256_set1_epi32(n.meta() as i32);
            let axes = _mm256_and_si256(
                _mm256_srlv_epi32(meta, _mm256_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14)),
                _mm256_set1_epi32(3),
            );
            let inv = _mm256_permutevar8x32_ps(_mm256_loadu_ps(r.inv.as_ptr()), axes);
            let org = _mm256_permutevar8x32_ps(_mm256_loadu_ps(r.origin.as_ptr()), axes);
            let tp = _mm256_mul_ps(_mm256_sub_ps(planes, org), inv);
            let neg = (_mm256_movemask_ps(inv) & 0x7f) as usize;
            // Each level's plane distance in every slot's lane, and the
            // slots beyond it (the rank's bit for that level, moved to
            // the sign bit that `blendv` reads).
            let rank = lanes_of(&RANK[neg]);
            let d0 = _mm256_permutevar8x32_ps(tp, _mm256_setzero_si256());
            let d1 = _mm256_permutevar8x32_ps(tp, _mm256_setr_epi32(1, 1, 1, 1, 2, 2, 2, 2));
            let d2 = _mm256_permutevar8x32_ps(tp, _mm256_setr_epi32(3, 3, 4, 4, 5, 5, 6, 6));
            let far0 = _mm256_castsi256_ps(_mm256_slli_epi32(rank, 29));
            let far1 = _mm256_castsi256_ps(_mm256_slli_epi32(rank, 30));
            let far2 = _mm256_castsi256_ps(_mm256_slli_epi32(rank, 31));
            let lo_inf = _mm256_set1_ps(f32::NEG_INFINITY);
            let hi_inf = _mm256_set1_ps(f32::INFINITY);
            // `max(x, bound)` returns `bound` when `x` is NaN.
            let mut lo = _mm256_set1_ps(t0);
            lo = _mm256_max_ps(_mm256_blendv_ps(lo_inf, d0, far0), lo);
            lo = _mm256_max_ps(_mm256_blendv_ps(lo_inf, d1, far1), lo);
            lo = _mm256_max_ps(_mm256_blendv_ps(lo_inf, d2, far2), lo);
            let mut hi = _mm256_set1_ps(t1);
            hi = _mm256_min_ps(_mm256_blendv_ps(d0, hi_inf, far0), hi);
            hi = _mm256_min_ps(_mm256_blendv_ps(d1, hi_inf, far1), hi);
            hi = _mm256_min_ps(_mm256_blendv_ps(d2, hi_inf, far2), hi);
            let abs = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff));
            let margin = _mm256_set1_ps(MARGIN);
            let wlo = _mm256_sub_ps(lo, _mm256_mul_ps(_mm256_and_ps(lo, abs), margin));
            let whi = _mm256_add_ps(hi, _mm256_mul_ps(_mm256_and_ps(hi, abs), margin));
            let limit = _mm256_set1_ps(closest * (1.0 + MARGIN));
            let slot_bits = _mm256_setr_epi32(
                1 << 16,
                1 << 17,
                1 << 18,
                1 << 19,
                1 << 20,
                1 << 21,
                1 << 22,
                1 << 23,
            );
            let used = _mm256_castsi256_ps(_mm256_cmpeq_epi32(
                _mm256_and_si256(meta, slot_bits),
                slot_bits,
            ));
            let visit = _mm256_and_ps(
                _mm256_and_ps(
                    _mm256_cmp_ps::<_CMP_LE_OQ>(wlo, whi),
                    _mm256_cmp_ps::<_CMP_LE_OQ>(lo, limit),
                ),
                used,
            );
            // Into front-to-back order, farthest first.
            let order = lanes_of(&FAR_FIRST[neg]);
            let visit = _mm256_permutevar8x32_ps(visit, order);
            let m = _mm256_movemask_ps(visit) as u32;
            let children = _mm256_load_si256(n.children.as_ptr().cast());
            let node_p = stack.node.as_mut_ptr().add(sp).cast::<__m256i>();
            let t0_p = stack.t0.as_mut_ptr().add(sp).cast::<f32>();
            let t1_p = stack.t1.as_mut_ptr().add(sp).cast::<f32>();
            let k = m.count_ones() as usize;
            let packed = if SIMD >= level::AVX512 {
                let children = _mm256_permutevar8x32_epi32(children, order);
                let lo = _mm256_permutevar8x32_ps(lo, order);
                let hi = _mm256_permutevar8x32_ps(hi, order);
                let m = m as u8;
                let packed = _mm256_maskz_compress_epi32(m, children);
                _mm256_storeu_ps(t0_p, _mm256_maskz_compress_ps(m, lo));
                _mm256_storeu_ps(t1_p, _mm256_maskz_compress_ps(m, hi));
                packed
            } else {
                let pick = _mm256_permutevar8x32_epi32(order, lanes_of(&PACK[m as usize]));
                _mm256_storeu_ps(t0_p, _mm256_permutevar8x32_ps(lo, pick));
                _mm256_storeu_ps(t1_p, _mm256_permutevar8x32_ps(hi, pick));
                _mm256_permutevar8x32_epi32(children, pick)
            };
            _mm256_storeu_si256(node_p, packed);
            let top = _mm256_permutevar8x32_epi32(packed, _mm256_set1_epi32(k as i32 - 1));
            (k, _mm256_cvtsi256_si32(top) as u32)
        }
    }

    /// [`step`] with AVX-512's masked minimum and maximum, mask registers
    /// and `vpcompressd` (the same values).
    ///
    /// # Safety
    /// AVX-512 F + VL and the caller compiled for them; `sp + 8` entries
    /// fit the stack.
    #[inline(always)]
    unsafe fn step512(
        n: &WideNode,
        r: &WideRay,
        t0: f32,
        t1: f32,
        closest: f32,
        stack: &mut Stack,
        sp: usize,
    ) -> (usize, u32) {
        unsafe {
            let planes = _mm256_load_ps(n.planes.as_ptr());
            let meta = n.meta();
            let axes = _mm256_and_si256(
                _mm256_srlv_epi32(
                    _mm256_set1_epi32(meta as i32),
                    _mm256_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14),
                ),
                _mm256_set1_epi32(3),
            );
            let inv = _mm256_permutevar8x32_ps(_mm256_loadu_ps(r.inv.as_ptr()), axes);
            let org = _mm256_permutevar8x32_ps(_mm256_loadu_ps(r.origin.as_ptr()), axes);
            let tp = _mm256_mul_ps(_mm256_sub_ps(planes, org), inv);
            let neg = (_mm256_movemask_ps(inv) & 0x7f) as usize;
            let [b0, b1, b2] = BEYOND[neg];
            let d0 = _mm256_permutevar8x32_ps(tp, _mm256_setzero_si256());
            let d1 = _mm256_permutevar8x32_ps(tp, _mm256_setr_epi32(1, 1, 1, 1, 2, 2, 2, 2));
            let d2 = _mm256_permutevar8x32_ps(tp, _mm256_setr_epi32(3, 3, 4, 4, 5, 5, 6, 6));
            // Where the slot lies beyond the plane its entry may grow,
            // elsewhere its exit may shrink; `max(d, bound)` and
            // `min(d, bound)` return `bound` when `d` is NaN.
            let mut lo = _mm256_set1_ps(t0);
            let mut hi = _mm256_set1_ps(t1);
            lo = _mm256_mask_max_ps(lo, b0, d0, lo);
            hi = _mm256_mask_min_ps(hi, !b0, d0, hi);
            lo = _mm256_mask_max_ps(lo, b1, d1, lo);
            hi = _mm256_mask_min_ps(hi, !b1, d1, hi);
            lo = _mm256_mask_max_ps(lo, b2, d2, lo);
            hi = _mm256_mask_min_ps(hi, !b2, d2, hi);
            // The widened interval of `kd::interval`: `lo >= 0` (it is at
            // least the ray's `tmin`), so `lo - |lo| M` is `lo (1 - M)`,
            // and `hi + |hi| M` compares as `hi (1 + M)` (for `hi < 0` both
            // say the slot is behind the ray).
            let wlo = _mm256_mul_ps(lo, _mm256_set1_ps(1.0 - MARGIN));
            let whi = _mm256_mul_ps(hi, _mm256_set1_ps(1.0 + MARGIN));
            let limit = _mm256_set1_ps(closest * (1.0 + MARGIN));
            let visit = _mm256_cmp_ps_mask::<_CMP_LE_OQ>(wlo, whi)
                & _mm256_cmp_ps_mask::<_CMP_LE_OQ>(lo, limit)
                & (meta >> 16) as u8;
            // Into front-to-back order, farthest first.
            let order = lanes_of(&FAR_FIRST[neg]);
            let flags = _mm256_maskz_mov_epi32(visit, _mm256_set1_epi32(-1));
            let flags = _mm256_permutevar8x32_epi32(flags, order);
            let m = _mm256_test_epi32_mask(flags, flags);
            let children = _mm256_load_si256(n.children.as_ptr().cast());
            let children = _mm256_permutevar8x32_epi32(children, order);
            let lo = _mm256_permutevar8x32_ps(lo, order);
            let hi = _mm256_permutevar8x32_ps(hi, order);
            let packed = _mm256_maskz_compress_epi32(m, children);
            _mm256_storeu_si256(stack.node.as_mut_ptr().add(sp).cast(), packed);
            _mm256_storeu_ps(
                stack.t0.as_mut_ptr().add(sp).cast(),
                _mm256_maskz_compress_ps(m, lo),
            );
            _mm256_storeu_ps(
                stack.t1.as_mut_ptr().add(sp).cast(),
                _mm256_maskz_compress_ps(m, hi),
            );
            let k = m.count_ones() as usize;
            let top = _mm256_permutevar8x32_epi32(packed, _mm256_set1_epi32(k as i32 - 1));
            (k, _mm256_cvtsi256_si32(top) as u32)
        }
    }
}
