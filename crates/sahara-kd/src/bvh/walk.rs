//! The single-ray walk of the eight-wide hierarchy: all eight child boxes
//! of a node tested in one step (AVX2 or AVX-512, or a portable loop), the
//! children that the ray meets pushed on a short stack far to near in the
//! order the node keeps for the ray's octant (so the nearest is on top),
//! leaves tested eight triangles at a time with the kd-tree's watertight
//! block test.
//!
//! **Exactness.** The box test is a filter: it may keep a child the ray
//! misses, never drop one holding a hit the triangle test accepts. The
//! watertight test can accept a ray passing a few ulps outside a triangle
//! (its edge functions round), and the slab distances round too, both by
//! at most a small multiple of the ulp of the coordinates involved (those
//! of the box and of the origin). So every box is widened, for the walk,
//! by `pad = (|origin|_max + scale) 2^-19` on each side, where `scale` is
//! the largest coordinate magnitude of the hierarchy's bounds: ~30 ulps
//! of the larger of the two, far above those roundings and far below any
//! box. The widening costs nothing per node: the near planes are measured
//! from the origin moved by `pad` towards the ray's direction and the far
//! ones from the origin moved back, per axis, once per ray.
//!
//! A zero direction component gives an infinite reciprocal; a slab
//! distance `0 * inf` (the origin on a widened plane) is NaN and is left
//! out by the order of the `min`/`max` operands (they return the second
//! operand, the running interval, for a NaN first one), which treats the
//! ray as inside that slab: conservative. Children are pruned only when
//! their entry distance exceeds the closest hit so far (`>`, not `>=`),
//! so a triangle at the same distance with a smaller index is still found
//! (the tie rule of every query).

use super::node::{is_leaf, leaf_parts, ChildRef, WideNode, ARITY};
use super::Bvh;
use crate::isect::{keep_closer, Hit, RayShear};
use crate::kd::Counters;
use crate::leaf::layout::{Layout, LeafBlock, Whole};
use crate::leaf::BLOCK_WIDTH;
use crate::math::Ray;
use crate::simd::level;

/// Entries of the walk's stack: a node pushes at most eight and pops one,
/// over at most `MAX_BINARY_DEPTH` levels, plus eight of slack for the
/// AVX2 form's full-width stores.
pub(crate) const STACK: usize = 7 * super::build::MAX_BINARY_DEPTH + 16;

/// The relative widening of the boxes (see the module's documentation).
const PAD: f32 = 1.0 / (1 << 19) as f32;

/// A ray prepared for the box tests.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BoxRay {
    /// `1 / d` per axis.
    pub(crate) inv: [f32; 3],
    /// The origin the near planes are measured from, per axis.
    pub(crate) near_origin: [f32; 3],
    /// The origin the far planes are measured from, per axis.
    pub(crate) far_origin: [f32; 3],
    /// Offsets, in floats within a node's `bounds`, of each axis' near
    /// planes (`16 axis + 8 side`) and far planes.
    pub(crate) near: [usize; 3],
    pub(crate) far: [usize; 3],
    /// The octant: bit `a` set when the direction is negative along `a`.
    pub(crate) octant: u32,
    /// The start of the ray's interval.
    pub(crate) tmin: f32,
}

impl BoxRay {
    /// The box-test form of `ray` for a hierarchy whose coordinates are at
    /// most `scale` in magnitude.
    #[inline(always)]
    pub(crate) fn new(ray: &Ray, scale: f32) -> Self {
        let o = ray.origin.to_array();
        let d = ray.dir.to_array();
        let pad = (ray.origin.abs().max_element() + scale) * PAD;
        let mut s = Self {
            inv: [0.0; 3],
            near_origin: [0.0; 3],
            far_origin: [0.0; 3],
            near: [0; 3],
            far: [0; 3],
            octant: 0,
            tmin: ray.tmin,
        };
        for a in 0..3 {
            let neg = d[a].is_sign_negative();
            s.inv[a] = 1.0 / d[a];
            // Towards the direction for the near planes, back for the far.
            let toward = if neg { -pad } else { pad };
            s.near_origin[a] = o[a] + toward;
            s.far_origin[a] = o[a] - toward;
            s.near[a] = 16 * a + 8 * neg as usize;
            s.far[a] = 16 * a + 8 * (!neg) as usize;
            s.octant |= (neg as u32) << a;
        }
        s
    }
}

/// Where a walk stands: the stack of children still to visit with their
/// entry distances.
pub(crate) struct Stack {
    pub(crate) refs: [std::mem::MaybeUninit<ChildRef>; STACK],
    pub(crate) dist: [std::mem::MaybeUninit<f32>; STACK],
    pub(crate) len: usize,
}

impl Stack {
    #[inline(always)]
    pub(crate) fn new() -> Self {
        Self {
            refs: [const { std::mem::MaybeUninit::uninit() }; STACK],
            dist: [const { std::mem::MaybeUninit::uninit() }; STACK],
            len: 0,
        }
    }

    #[inline(always)]
    fn push(&mut self, r: ChildRef, t: f32) {
        debug_assert!(self.len < STACK);
        // SAFETY: in bounds (the depth bound of the build).
        unsafe {
            self.refs.get_unchecked_mut(self.len).write(r);
            self.dist.get_unchecked_mut(self.len).write(t);
        }
        self.len += 1;
    }

    #[inline(always)]
    pub(crate) fn pop(&mut self) -> Option<(ChildRef, f32)> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: entries below `len` were written by a push.
        unsafe {
            Some((
                self.refs.get_unchecked(self.len).assume_init(),
                self.dist.get_unchecked(self.len).assume_init(),
            ))
        }
    }
}

/// The eight slab intervals of a node for one ray: the entry distances
/// and the mask of children entered at or before `tfar` (the closest hit so
/// far, or the ray's end), at level `SIMD`.
///
/// # Safety
/// The CPU must have the level's instructions and the caller must be
/// compiled for them.
#[inline(always)]
pub(crate) unsafe fn node_step<const SIMD: u8, const ORDERED: bool>(
    node: &WideNode,
    r: &BoxRay,
    tfar: f32,
    stack: &mut Stack,
) {
    let _ = SIMD;
    portable_step::<ORDERED>(node, r, tfar, stack)
}

/// [`node_step`] in plain code: the same operations, one lane at a time.
#[inline(always)]
fn portable_step<const ORDERED: bool>(node: &WideNode, r: &BoxRay, tfar: f32, stack: &mut Stack) {
    let b: &[f32; 48] = bytemuck_bounds(node);
    let mut tn = [0.0f32; ARITY];
    let mut hit = 0u32;
    for (slot, t) in tn.iter_mut().enumerate() {
        let mut near = r.tmin;
        let mut far = tfar;
        for a in 0..3 {
            let n = (b[r.near[a] + slot] - r.near_origin[a]) * r.inv[a];
            let f = (b[r.far[a] + slot] - r.far_origin[a]) * r.inv[a];
            // `maxps`/`minps` operand order: a NaN slab keeps the interval.
            near = if n > near { n } else { near };
            far = if f < far { f } else { far };
        }
        *t = near;
        hit |= ((near <= far) as u32) << slot;
    }
    for i in 0..ARITY {
        let slot = if ORDERED {
            node.slot_in_order(i, r.octant)
        } else {
            i
        };
        if hit >> slot & 1 == 1 {
            stack.push(node.child[slot], tn[slot]);
        }
    }
}

/// A node's bounds as one flat array of 48 floats.
#[inline(always)]
fn bytemuck_bounds(node: &WideNode) -> &[f32; 48] {
    // SAFETY: `[[[f32; 8]; 2]; 3]` is 48 contiguous floats.
    unsafe { &*(node.bounds.as_ptr() as *const [f32; 48]) }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    use super::{leaf_any, leaf_closest, BoxRay, Stack};
    use crate::bvh::node::is_leaf;
    use crate::bvh::Bvh;
    use crate::isect::{Hit, RayShear};
    use crate::kd::Counters;
    use crate::math::Ray;
    use crate::simd::level;

    /// For each 8-bit mask, the indices of its set bits in order, four bits
    /// each (for the AVX2 compress: `vpsrlvd` spreads them over the lanes
    /// and `vpermd` reads the low three bits).
    static COMPRESS: [u32; 256] = {
        let mut t = [0u32; 256];
        let mut m = 0;
        while m < 256 {
            let (mut w, mut k, mut b) = (0u32, 0, 0);
            while b < 8 {
                if m >> b & 1 == 1 {
                    w |= (b as u32) << (4 * k);
                    k += 1;
                }
                b += 1;
            }
            t[m] = w;
            m += 1;
        }
        t
    };

    /// A ray's box-test constants in registers, set up once per walk:
    /// the slab distance of a plane `b` is `b * inv - origin * inv`, one
    /// fused multiply-add. Its rounding (of `origin * inv`, then of the
    /// sum) stays below the walk's widening of the boxes (see the module
    /// documentation); a zero direction component makes it `inf - inf`
    /// (NaN) only where the plane and the origin lie on the same side of
    /// zero, and a NaN slab keeps the interval: conservative.
    #[derive(Clone, Copy)]
    struct Lanes {
        inv: [__m256; 3],
        near_oinv: [__m256; 3],
        far_oinv: [__m256; 3],
        near: [usize; 3],
        far: [usize; 3],
        tmin: __m256,
        octant_shift: __m256i,
    }

    impl Lanes {
        #[inline(always)]
        unsafe fn new(r: &BoxRay) -> Self {
            // SAFETY: AVX (the caller's contract).
            unsafe {
                let v = |f: [f32; 3]| f.map(|x| _mm256_set1_ps(x));
                let inv = r.inv;
                Self {
                    inv: v(inv),
                    near_oinv: v([0, 1, 2].map(|a| r.near_origin[a] * inv[a])),
                    far_oinv: v([0, 1, 2].map(|a| r.far_origin[a] * inv[a])),
                    near: r.near,
                    far: r.far,
                    tmin: _mm256_set1_ps(r.tmin),
                    octant_shift: _mm256_set1_epi32(3 * r.octant as i32),
                }
            }
        }

        /// The entry distances of the eight children and the mask of
        /// those entered at or before `tfar`.
        #[inline(always)]
        unsafe fn test(&self, b: *const f32, tfar: __m256) -> (__m256, __m256) {
            // SAFETY: `b` points at a node's 48 bounds (64-byte aligned);
            // every offset is 16 axis + 8 side; FMA (the caller's contract).
            unsafe {
                let n = |a: usize| {
                    _mm256_fmsub_ps(_mm256_load_ps(b.add(self.near[a])), self.inv[a], self.near_oinv[a])
                };
                let f = |a: usize| {
                    _mm256_fmsub_ps(_mm256_load_ps(b.add(self.far[a])), self.inv[a], self.far_oinv[a])
                };
                // The running interval is the second operand: a NaN slab
                // distance leaves it as it is.
                let tn = _mm256_max_ps(n(0), _mm256_max_ps(n(1), _mm256_max_ps(n(2), self.tmin)));
                let tf = _mm256_min_ps(f(0), _mm256_min_ps(f(1), _mm256_min_ps(f(2), tfar)));
                (tn, _mm256_cmp_ps::<_CMP_LE_OQ>(tn, tf))
            }
        }
    }

    /// Push the children of `node` in `hit` on the stack: far to near in
    /// the node's order for the ray's octant (`ORDERED`) or in slot order.
    #[inline(always)]
    unsafe fn push<const SIMD: u8, const ORDERED: bool>(
        node: *const crate::bvh::WideNode,
        l: &Lanes,
        tn: __m256,
        hit: __m256,
        stack: &mut Stack,
    ) {
        // SAFETY: the stack has room for eight entries past `len` (its
        // slack); the node's `child` and `order` are 32-byte aligned; the
        // CPU has the level's instructions (the caller's contract).
        unsafe {
            let child = _mm256_load_si256((*node).child.as_ptr() as *const __m256i);
            let (tn, child, hit) = if ORDERED {
                let order = _mm256_load_si256((*node).order.as_ptr() as *const __m256i);
                let perm = _mm256_srlv_epi32(order, l.octant_shift);
                (
                    _mm256_permutevar8x32_ps(tn, perm),
                    _mm256_permutevar8x32_epi32(child, perm),
                    _mm256_permutevar8x32_ps(hit, perm),
                )
            } else {
                (tn, child, hit)
            };
            let mask = _mm256_movemask_ps(hit) as u32;
            let at = stack.len;
            let refs = stack.refs.as_mut_ptr().add(at) as *mut __m256i;
            let dist = stack.dist.as_mut_ptr().add(at) as *mut f32;
            if SIMD >= level::AVX512 {
                // Compressed in registers, stored whole: the store form of
                // `vpcompressd` is microcoded and slow on AMD's Zen 4.
                let k = mask as __mmask8;
                _mm256_storeu_si256(refs, _mm256_maskz_compress_epi32(k, child));
                _mm256_storeu_ps(dist, _mm256_maskz_compress_ps(k, tn));
            } else {
                let idx = _mm256_srlv_epi32(
                    _mm256_set1_epi32(COMPRESS[mask as usize] as i32),
                    _mm256_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28),
                );
                _mm256_storeu_si256(refs, _mm256_permutevar8x32_epi32(child, idx));
                _mm256_storeu_ps(dist, _mm256_permutevar8x32_ps(tn, idx));
            }
            stack.len = at + mask.count_ones() as usize;
        }
    }

    /// [`Bvh::walk_closest`] in intrinsics.
    ///
    /// # Safety
    /// AVX2 and FMA (and AVX-512 F, VL at that level); the caller is
    /// compiled for them.
    #[inline(always)]
    pub(super) unsafe fn closest<C: Counters, const SIMD: u8>(
        bvh: &Bvh,
        ray: &Ray,
        counters: &mut C,
    ) -> Option<Hit> {
        let r = BoxRay::new(ray, bvh.scale);
        let shear = RayShear::from_ray(ray);
        let mut best_t = ray.tmax;
        let mut best = Hit {
            t: f32::INFINITY,
            tri: u32::MAX,
            u: 0.0,
            v: 0.0,
        };
        let mut stack = Stack::new();
        let mut node = 0u32;
        // SAFETY: the level's instructions (the caller's contract); inner
        // references name nodes the build wrote.
        unsafe {
            let l = Lanes::new(&r);
            let mut tfar = _mm256_set1_ps(best_t);
            loop {
                counters.inner();
                let n = bvh.nodes.as_ptr().add(node as usize);
                let (tn, hit) = l.test((*n).bounds.as_ptr() as *const f32, tfar);
                if _mm256_testz_ps(hit, hit) == 0 {
                    push::<SIMD, true>(n, &l, tn, hit, &mut stack);
                }
                loop {
                    let Some((c, t)) = stack.pop() else {
                        return (best.tri != u32::MAX).then_some(best);
                    };
                    if t > best_t {
                        continue;
                    }
                    if is_leaf(c) {
                        leaf_closest::<C, SIMD>(
                            bvh, c, &shear, ray.tmin, &mut best_t, &mut best, counters,
                        );
                        tfar = _mm256_set1_ps(best_t);
                        continue;
                    }
                    node = c;
                    break;
                }
            }
        }
    }

    /// [`Bvh::walk_any`] in intrinsics.
    ///
    /// # Safety
    /// As [`closest`].
    #[inline(always)]
    pub(super) unsafe fn any<C: Counters, const SIMD: u8>(
        bvh: &Bvh,
        ray: &Ray,
        counters: &mut C,
    ) -> bool {
        let r = BoxRay::new(ray, bvh.scale);
        let shear = RayShear::from_ray(ray);
        let mut stack = Stack::new();
        let mut node = 0u32;
        // SAFETY: as in `closest`.
        unsafe {
            let l = Lanes::new(&r);
            let tfar = _mm256_set1_ps(ray.tmax);
            loop {
                counters.inner();
                let n = bvh.nodes.as_ptr().add(node as usize);
                let (tn, hit) = l.test((*n).bounds.as_ptr() as *const f32, tfar);
                if _mm256_testz_ps(hit, hit) == 0 {
                    push::<SIMD, false>(n, &l, tn, hit, &mut stack);
                }
                loop {
                    let Some((c, _)) = stack.pop() else {
                        return false;
                    };
                    if is_leaf(c) {
                        if leaf_any::<C, SIMD>(bvh, c, &shear, ray.tmin, ray.tmax, counters) {
                            return true;
                        }
                        continue;
                    }
                    node = c;
                    break;
                }
            }
        }
    }
}

/// Triangle tests of one leaf (the blocks of `r`) for the closest hit:
/// lowers `best_t` and updates `best`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn leaf_closest<C: Counters, const SIMD: u8>(
    bvh: &Bvh,
    r: ChildRef,
    shear: &RayShear,
    tmin: f32,
    best_t: &mut f32,
    best: &mut Hit,
    counters: &mut C,
) {
    let (first, count) = leaf_parts(r);
    counters.leaf();
    let layout = Whole(&bvh.blocks);
    // SAFETY: the build points every leaf reference at `ceil(count / 8)`
    // blocks of `blocks` and at the eight indices per block.
    let blocks = unsafe { layout.blocks(first * BLOCK_WIDTH, count) };
    for (b, block) in blocks.enumerate() {
        let lanes = (count - b * BLOCK_WIDTH).min(BLOCK_WIDTH);
        (0..lanes).for_each(|_| counters.triangle());
        // SAFETY: `SIMD` is the level the walk is compiled for.
        let (mut m, e) = unsafe { block.edges::<SIMD>(shear, lanes) };
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            let uvw = [e[0][l], e[1][l], e[2][l]];
            if let Some(h) = shear.decide(&block.triangle(l), uvw, tmin, *best_t) {
                // SAFETY: eight indices per block.
                let i = unsafe { *bvh.indices.get_unchecked(block.run() + l) };
                keep_closer(best_t, best, h, i);
            }
        }
    }
}

/// True when a triangle of leaf `r` is hit within `(tmin, tmax]`.
#[inline(always)]
pub(crate) fn leaf_any<C: Counters, const SIMD: u8>(
    bvh: &Bvh,
    r: ChildRef,
    shear: &RayShear,
    tmin: f32,
    tmax: f32,
    counters: &mut C,
) -> bool {
    let (first, count) = leaf_parts(r);
    counters.leaf();
    let layout = Whole(&bvh.blocks);
    // SAFETY: as in `leaf_closest`.
    let blocks = unsafe { layout.blocks(first * BLOCK_WIDTH, count) };
    for (b, block) in blocks.enumerate() {
        let lanes = (count - b * BLOCK_WIDTH).min(BLOCK_WIDTH);
        (0..lanes).for_each(|_| counters.triangle());
        // SAFETY: `SIMD` is the level the walk is compiled for.
        let (mut m, e) = unsafe { block.edges::<SIMD>(shear, lanes) };
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            let uvw = [e[0][l], e[1][l], e[2][l]];
            if shear.decide(&block.triangle(l), uvw, tmin, tmax).is_some() {
                return true;
            }
        }
    }
    false
}

impl Bvh {
    /// The closest-hit walk at level `SIMD`.
    #[inline(always)]
    pub(crate) fn walk_closest<C: Counters, const SIMD: u8>(
        &self,
        ray: &Ray,
        counters: &mut C,
    ) -> Option<Hit> {
        if self.nodes.is_empty() || !ray.is_valid() || ray.tmin > ray.tmax {
            return None;
        }
        #[cfg(target_arch = "x86_64")]
        if SIMD >= level::AVX2 {
            // SAFETY: the caller's contract.
            return unsafe { x86::closest::<C, SIMD>(self, ray, counters) };
        }
        let r = BoxRay::new(ray, self.scale);
        let shear = RayShear::from_ray(ray);
        let mut best_t = ray.tmax;
        let mut best = Hit {
            t: f32::INFINITY,
            tri: u32::MAX,
            u: 0.0,
            v: 0.0,
        };
        let mut stack = Stack::new();
        let mut node = 0u32;
        loop {
            counters.inner();
            // SAFETY: inner references name nodes the build wrote.
            let n = unsafe { self.nodes.get_unchecked(node as usize) };
            // SAFETY: `SIMD` is the level this walk is compiled for.
            unsafe { node_step::<SIMD, true>(n, &r, best_t, &mut stack) };
            loop {
                let Some((c, t)) = stack.pop() else {
                    return (best.tri != u32::MAX).then_some(best);
                };
                if t > best_t {
                    continue;
                }
                if is_leaf(c) {
                    leaf_closest::<C, SIMD>(
                        self, c, &shear, ray.tmin, &mut best_t, &mut best, counters,
                    );
                    continue;
                }
                node = c;
                break;
            }
        }
    }

    /// The any-hit walk at level `SIMD`.
    #[inline(always)]
    pub(crate) fn walk_any<C: Counters, const SIMD: u8>(&self, ray: &Ray, counters: &mut C) -> bool {
        if self.nodes.is_empty() || !ray.is_valid() || ray.tmin > ray.tmax {
            return false;
        }
        #[cfg(target_arch = "x86_64")]
        if SIMD >= level::AVX2 {
            // SAFETY: the caller's contract.
            return unsafe { x86::any::<C, SIMD>(self, ray, counters) };
        }
        let r = BoxRay::new(ray, self.scale);
        let shear = RayShear::from_ray(ray);
        let mut stack = Stack::new();
        let mut node = 0u32;
        loop {
            counters.inner();
            // SAFETY: inner references name nodes the build wrote.
            let n = unsafe { self.nodes.get_unchecked(node as usize) };
            // SAFETY: `SIMD` is the level this walk is compiled for.
            unsafe { node_step::<SIMD, false>(n, &r, ray.tmax, &mut stack) };
            loop {
                let Some((c, _)) = stack.pop() else {
                    return false;
                };
                if is_leaf(c) {
                    if leaf_any::<C, SIMD>(self, c, &shear, ray.tmin, ray.tmax, counters) {
                        return true;
                    }
                    continue;
                }
                node = c;
                break;
            }
        }
    }
}
