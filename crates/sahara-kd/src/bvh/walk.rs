//! The single-ray walk of the eight-wide hierarchy: all eight child boxes
//! of a node tested in one step (AVX2, or a portable loop), the children
//! the ray meets visited near to far in the order the node keeps for the
//! ray's octant (a lone child directly, several through a short stack whose
//! top is the nearest), leaves of four triangles tested at once with the
//! watertight test.
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
//! distance that is NaN (`0 * inf`, or `inf - inf` in the fused form) is
//! left out by the order of the `min`/`max` operands (they return the
//! second operand, the running interval, for a NaN first one), which
//! treats the ray as inside that slab: conservative. A child is skipped
//! only when its entry distance exceeds the closest hit so far (`>`, not
//! `>=`), so a triangle at the same distance with a smaller index is still
//! found (the tie rule of every query).

use super::node::{is_leaf, leaf_parts, ChildRef, WideNode, ARITY};
use super::quad::{quad_edges, QUAD};
use super::Bvh;
use crate::isect::{keep_closer, Hit, RayShear};
use crate::kd::Counters;
use crate::math::Ray;
#[cfg(target_arch = "x86_64")]
use crate::simd::level;

/// Entries of the walk's stack: a node pushes at most eight and takes one,
/// over at most `MAX_BINARY_DEPTH` levels, plus eight of slack for the
/// full-width stores.
pub(crate) const STACK: usize = 7 * super::build::MAX_BINARY_DEPTH + 16;

/// The relative widening of the boxes (see the module's documentation).
pub(crate) const PAD: f32 = 1.0 / (1 << 19) as f32;

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

/// The walk's stack: children still to visit and their entry distances.
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

/// One node step in plain code: the children of `node` whose boxes the
/// ray enters at or before `tfar` pushed on `stack`, far to near in the
/// node's order for the ray's octant (`ORDERED`) or in slot order.
#[inline(always)]
pub(crate) fn portable_step<const ORDERED: bool>(
    node: &WideNode,
    r: &BoxRay,
    tfar: f32,
    stack: &mut Stack,
) {
    // SAFETY: `[[[f32; 8]; 2]; 3]` is 48 contiguous floats.
    let b: &[f32; 48] = unsafe { &*(node.bounds.as_ptr() as *const [f32; 48]) };
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

/// The closest-hit test of leaf `r`: lowers `best_t` and updates `best`;
/// true if it found a hit.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn leaf_closest<C: Counters>(
    bvh: &Bvh,
    r: ChildRef,
    edges: impl Fn(&super::quad::Quad, usize) -> (u32, [[f32; QUAD]; 3]),
    shear: &RayShear,
    tmin: f32,
    best_t: &mut f32,
    best: &mut Hit,
    counters: &mut C,
) -> bool {
    let (line, count) = leaf_parts(r);
    counters.leaf();
    (0..count).for_each(|_| counters.triangle());
    // SAFETY: leaf references name leaves the build wrote.
    let q = unsafe { bvh.quad(line) };
    let (mut m, e) = edges(q, count);
    let mut found = false;
    while m != 0 {
        let l = m.trailing_zeros() as usize;
        m &= m - 1;
        let uvw = [e[0][l], e[1][l], e[2][l]];
        if let Some(h) = shear.decide(&q.triangle(l), uvw, tmin, *best_t) {
            keep_closer(best_t, best, h, q.tri[l]);
            found = true;
        }
    }
    found
}

/// True when a triangle of leaf `r` is hit within `(tmin, tmax]`.
#[inline(always)]
pub(crate) fn leaf_any<C: Counters>(
    bvh: &Bvh,
    r: ChildRef,
    edges: impl Fn(&super::quad::Quad, usize) -> (u32, [[f32; QUAD]; 3]),
    shear: &RayShear,
    tmin: f32,
    tmax: f32,
    counters: &mut C,
) -> bool {
    let (line, count) = leaf_parts(r);
    counters.leaf();
    (0..count).for_each(|_| counters.triangle());
    // SAFETY: leaf references name leaves the build wrote.
    let q = unsafe { bvh.quad(line) };
    let (mut m, e) = edges(q, count);
    while m != 0 {
        let l = m.trailing_zeros() as usize;
        m &= m - 1;
        let uvw = [e[0][l], e[1][l], e[2][l]];
        if shear.decide(&q.triangle(l), uvw, tmin, tmax).is_some() {
            return true;
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
        let edges = |q: &super::quad::Quad, n| quad_edges(&shear, q, n);
        let mut best_t = ray.tmax;
        let mut best = Hit {
            t: f32::INFINITY,
            tri: u32::MAX,
            u: 0.0,
            v: 0.0,
        };
        let mut stack = Stack::new();
        stack.push(0, r.tmin);
        while let Some((c, t)) = stack.pop() {
            if t > best_t {
                continue;
            }
            if is_leaf(c) {
                leaf_closest(
                    self,
                    c,
                    edges,
                    &shear,
                    ray.tmin,
                    &mut best_t,
                    &mut best,
                    counters,
                );
                continue;
            }
            counters.inner();
            // SAFETY: inner references name nodes the build wrote.
            portable_step::<true>(unsafe { self.node(c) }, &r, best_t, &mut stack);
        }
        (best.tri != u32::MAX).then_some(best)
    }

    /// The any-hit walk at level `SIMD`.
    #[inline(always)]
    pub(crate) fn walk_any<C: Counters, const SIMD: u8>(
        &self,
        ray: &Ray,
        counters: &mut C,
    ) -> bool {
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
        let edges = |q: &super::quad::Quad, n| quad_edges(&shear, q, n);
        let mut stack = Stack::new();
        stack.push(0, r.tmin);
        while let Some((c, _)) = stack.pop() {
            if is_leaf(c) {
                if leaf_any(self, c, edges, &shear, ray.tmin, ray.tmax, counters) {
                    return true;
                }
                continue;
            }
            counters.inner();
            // SAFETY: inner references name nodes the build wrote.
            portable_step::<false>(unsafe { self.node(c) }, &r, ray.tmax, &mut stack);
        }
        false
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) mod x86 {
    use std::arch::x86_64::*;

    use super::{leaf_any, leaf_closest, BoxRay, Stack};
    use crate::bvh::node::{is_leaf, WideNode};
    use crate::bvh::quad::sse::{quad_edges, QuadRay};
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
    /// documentation).
    #[derive(Clone, Copy)]
    pub(crate) struct Lanes {
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
        pub(crate) unsafe fn new(r: &BoxRay) -> Self {
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
        unsafe fn test(&self, n: &WideNode, tfar: __m256) -> (__m256, __m256) {
            // SAFETY: the node's bounds are 48 floats, 64-byte aligned;
            // every offset is 16 axis + 8 side; FMA (the caller's
            // contract).
            unsafe {
                let b = n.bounds.as_ptr() as *const f32;
                let near = |a: usize| {
                    _mm256_fmsub_ps(
                        _mm256_load_ps(b.add(self.near[a])),
                        self.inv[a],
                        self.near_oinv[a],
                    )
                };
                let far = |a: usize| {
                    _mm256_fmsub_ps(
                        _mm256_load_ps(b.add(self.far[a])),
                        self.inv[a],
                        self.far_oinv[a],
                    )
                };
                // The running interval is the second operand: a NaN slab
                // distance leaves it as it is.
                let tn = _mm256_max_ps(
                    near(0),
                    _mm256_max_ps(near(1), _mm256_max_ps(near(2), self.tmin)),
                );
                let tf = _mm256_min_ps(far(0), _mm256_min_ps(far(1), _mm256_min_ps(far(2), tfar)));
                (tn, _mm256_cmp_ps::<_CMP_LE_OQ>(tn, tf))
            }
        }
    }

    /// Compress the lanes of `mask` of `refs` and `dist` to the front and
    /// store all eight at `at` on the stack (the ones past the count are
    /// garbage, overwritten by later pushes).
    #[inline(always)]
    unsafe fn store<const SIMD: u8>(
        stack: &mut Stack,
        at: usize,
        mask: u32,
        refs: __m256i,
        dist: __m256,
    ) {
        // SAFETY: the stack has room for eight entries past `at` (its
        // slack); the level's instructions (the caller's contract).
        unsafe {
            let r = stack.refs.as_mut_ptr().add(at) as *mut __m256i;
            let d = stack.dist.as_mut_ptr().add(at) as *mut f32;
            if SIMD >= level::AVX512 {
                // Compressed in registers, stored whole: the store form of
                // `vpcompressd` is microcoded and slow on AMD's Zen 4.
                let k = mask as __mmask8;
                _mm256_storeu_si256(r, _mm256_maskz_compress_epi32(k, refs));
                _mm256_storeu_ps(d, _mm256_maskz_compress_ps(k, dist));
            } else {
                let idx = _mm256_srlv_epi32(
                    _mm256_set1_epi32(COMPRESS[mask as usize] as i32),
                    _mm256_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28),
                );
                _mm256_storeu_si256(r, _mm256_permutevar8x32_epi32(refs, idx));
                _mm256_storeu_ps(d, _mm256_permutevar8x32_ps(dist, idx));
            }
        }
    }

    /// The next child to visit after a node step: the lone child the ray
    /// enters, or, of several, the nearest (the others pushed, far to near
    /// in the node's order for the ray's octant when `ORDERED`); `None`
    /// when the ray enters none.
    #[inline(always)]
    pub(crate) unsafe fn step<const SIMD: u8, const ORDERED: bool>(
        n: &WideNode,
        l: &Lanes,
        tfar: __m256,
        stack: &mut Stack,
    ) -> Option<u32> {
        // SAFETY: the node's `child` and `order` are 32-byte aligned; the
        // level's instructions (the caller's contract).
        unsafe {
            let (tn, hit) = l.test(n, tfar);
            let mask = _mm256_movemask_ps(hit) as u32;
            if mask == 0 {
                return None;
            }
            if mask.is_power_of_two() {
                return Some(*n.child.get_unchecked(mask.trailing_zeros() as usize));
            }
            let child = _mm256_load_si256(n.child.as_ptr() as *const __m256i);
            let at = stack.len;
            if !ORDERED {
                store::<SIMD>(stack, at, mask, child, tn);
                let top = at + mask.count_ones() as usize - 1;
                stack.len = top;
                return Some(stack.refs.get_unchecked(top).assume_init());
            }
            // The child entered first is visited next; the others are
            // pushed far to near in the node's order for the ray's octant.
            // (The octant order alone, by box centres, chose badly where
            // one box is huge: on the teapot in a stadium the ground's
            // leaf, whose hit would prune the rest, came last, and camera
            // rays visited 6.5 leaves each.)
            let entered = _mm256_blendv_ps(_mm256_set1_ps(f32::INFINITY), tn, hit);
            let m = _mm256_min_ps(entered, _mm256_permute_ps::<0b10_11_00_01>(entered));
            let m = _mm256_min_ps(m, _mm256_permute_ps::<0b01_00_11_10>(m));
            let m = _mm256_min_ps(m, _mm256_permute2f128_ps::<1>(m, m));
            let first = (_mm256_movemask_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(entered, m)) as u32 & mask)
                .trailing_zeros();
            let next = *n.child.get_unchecked(first as usize);
            let rest = _mm256_andnot_ps(
                _mm256_castsi256_ps(_mm256_cmpeq_epi32(
                    _mm256_set1_epi32(first as i32),
                    _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
                )),
                hit,
            );
            let order = _mm256_load_si256(n.order.as_ptr() as *const __m256i);
            let perm = _mm256_srlv_epi32(order, l.octant_shift);
            let pushed = _mm256_movemask_ps(_mm256_permutevar8x32_ps(rest, perm)) as u32;
            store::<SIMD>(
                stack,
                at,
                pushed,
                _mm256_permutevar8x32_epi32(child, perm),
                _mm256_permutevar8x32_ps(tn, perm),
            );
            stack.len = at + pushed.count_ones() as usize;
            Some(next)
        }
    }

    /// Drop the stacked children entered beyond `best_t` (after a hit),
    /// keeping the order of the rest: with them gone, every child popped
    /// may hold a closer hit, so pops need no distance test.
    #[inline(always)]
    pub(crate) unsafe fn compact<const SIMD: u8>(stack: &mut Stack, best_t: f32) {
        // SAFETY: entries below `len` were written; the level's
        // instructions (the caller's contract). Reading past `len` up to
        // the next multiple of eight reads slack entries (the stack's
        // eight spare entries), masked out.
        unsafe {
            let t = _mm256_set1_ps(best_t);
            let mut out = 0;
            let mut i = 0;
            while i < stack.len {
                let refs = _mm256_loadu_si256(stack.refs.as_ptr().add(i) as *const __m256i);
                let dist = _mm256_loadu_ps(stack.dist.as_ptr().add(i) as *const f32);
                let live = (1u32 << (stack.len - i).min(8)) - 1;
                let keep = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(dist, t)) as u32 & live;
                store::<SIMD>(stack, out, keep, refs, dist);
                out += keep.count_ones() as usize;
                i += 8;
            }
            stack.len = out;
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
        let qr = QuadRay::new(&shear);
        // SAFETY: SSE2.
        let edges = |q: &crate::bvh::quad::Quad, n| unsafe { quad_edges(&qr, q, n) };
        let mut best_t = ray.tmax;
        let mut best = Hit {
            t: f32::INFINITY,
            tri: u32::MAX,
            u: 0.0,
            v: 0.0,
        };
        let mut stack = Stack::new();
        let mut c = 0u32;
        // SAFETY: the level's instructions (the caller's contract); child
        // references name nodes and leaves the build wrote.
        unsafe {
            let l = Lanes::new(&r);
            let mut tfar = _mm256_set1_ps(best_t);
            'walk: loop {
                while !is_leaf(c) {
                    counters.inner();
                    match step::<SIMD, true>(bvh.node(c), &l, tfar, &mut stack) {
                        Some(next) => c = next,
                        None => match stack.pop() {
                            Some((next, _)) => c = next,
                            None => break 'walk,
                        },
                    }
                }
                if leaf_closest(
                    bvh,
                    c,
                    edges,
                    &shear,
                    ray.tmin,
                    &mut best_t,
                    &mut best,
                    counters,
                ) {
                    tfar = _mm256_set1_ps(best_t);
                    compact::<SIMD>(&mut stack, best_t);
                }
                match stack.pop() {
                    Some((next, _)) => c = next,
                    None => break,
                }
            }
        }
        (best.tri != u32::MAX).then_some(best)
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
        let qr = QuadRay::new(&shear);
        // SAFETY: SSE2.
        let edges = |q: &crate::bvh::quad::Quad, n| unsafe { quad_edges(&qr, q, n) };
        let mut stack = Stack::new();
        let mut c = 0u32;
        // SAFETY: as in `closest`.
        unsafe {
            let l = Lanes::new(&r);
            let tfar = _mm256_set1_ps(ray.tmax);
            loop {
                while !is_leaf(c) {
                    counters.inner();
                    match step::<SIMD, false>(bvh.node(c), &l, tfar, &mut stack) {
                        Some(next) => c = next,
                        None => match stack.pop() {
                            Some((next, _)) => c = next,
                            None => return false,
                        },
                    }
                }
                if leaf_any(bvh, c, edges, &shear, ray.tmin, ray.tmax, counters) {
                    return true;
                }
                match stack.pop() {
                    Some((next, _)) => c = next,
                    None => return false,
                }
            }
        }
    }
}
