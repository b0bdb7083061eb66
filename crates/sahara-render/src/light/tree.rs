//! A light tree: a bounding volume hierarchy over the lights in the scene
//! (each emitting triangle of a mesh its own light) for choosing the light
//! a shading point samples, after Conty Estevez & Kulla, "Importance
//! Sampling of Many Lights with Adaptive Tree Splitting" (2018), as in
//! pbrt-v4 (section 12.6.3).
//!
//! Every node bounds its lights: where they are (a box), how much they
//! emit (`phi`, the sum of their peak radiant intensities), and which ways
//! (a cone of the normals around `w` of half-angle θo, and θe, how far
//! beyond a normal light still leaves). From a shading point each node has
//! an importance, a cheap upper estimate of what its lights can send there:
//! `phi` over the squared distance, times the cosine of the smallest angle
//! the box allows between the node's cone and the direction to the point,
//! and (at a surface) the cosine the box allows at the point's normal. A
//! light is chosen by walking down from the root, at each node taking a
//! child with probability in proportion to its importance; the probability
//! of the whole walk is the product of those choices. The same product,
//! walked again along a light's stored left/right trail, is the
//! probability that a given light is chosen at a given point, which
//! multiple importance sampling needs when a scattered ray finds an
//! emitter.
//!
//! The importance is zero only where no light of the node can send any
//! light (behind all of them, or outside every spot's cone), so the choice
//! is unbiased: every light that can contribute has a positive
//! probability.

use glam::{Quat, Vec3};
use std::f32::consts::PI;

use crate::math::lanes::{F, M, U, V};

/// A bound on a set of lights: where they are, how much they emit and
/// which ways.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LightBounds {
    /// Lower corner of the box holding the lights.
    pub lo: Vec3,
    /// Upper corner.
    pub hi: Vec3,
    /// The sum of the lights' peak radiant intensities (luminance).
    pub phi: f32,
    /// Axis of the cone of the lights' normals (their main direction of
    /// emission).
    pub w: Vec3,
    /// Cosine of the cone's half-angle θo (-1: every direction).
    pub cos_o: f32,
    /// Cosine of θe, the angle beyond a normal at which light still
    /// leaves (0 for surfaces: up to their tangent plane).
    pub cos_e: f32,
    /// Whether some light emits both ways along its normal.
    pub two_sided: bool,
}

impl LightBounds {
    /// A light at `p` emitting equally in every direction.
    pub(crate) fn point(p: Vec3, phi: f32) -> Self {
        Self {
            lo: p,
            hi: p,
            phi,
            w: Vec3::Z,
            cos_o: -1.0,
            cos_e: 0.0,
            two_sided: false,
        }
    }

    /// A light at `p` whose emission is full within θo of `w` (cosine
    /// `cos_o`) and ends at θo + θe.
    pub(crate) fn cone(p: Vec3, phi: f32, w: Vec3, cos_o: f32, cos_e: f32) -> Self {
        Self {
            lo: p,
            hi: p,
            phi,
            w,
            cos_o,
            cos_e,
            two_sided: false,
        }
    }

    /// A flat emitter with corners `corners` and front normal `n`.
    pub(crate) fn surface(corners: &[Vec3], n: Vec3, phi: f32, two_sided: bool) -> Self {
        let (lo, hi) = corners
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &c| {
                (lo.min(c), hi.max(c))
            });
        Self {
            lo,
            hi,
            phi,
            w: n,
            cos_o: 1.0,
            cos_e: 0.0,
            two_sided,
        }
    }

    /// A sphere emitting outwards (its normals face every way).
    pub(crate) fn sphere(center: Vec3, radius: f32, phi: f32, two_sided: bool) -> Self {
        Self {
            lo: center - Vec3::splat(radius),
            hi: center + Vec3::splat(radius),
            phi,
            w: Vec3::Z,
            cos_o: -1.0,
            cos_e: 0.0,
            two_sided,
        }
    }

    /// The bound of both `self` and `b`.
    fn union(&self, b: &LightBounds) -> LightBounds {
        let (w, cos_o) = cone_union(self.w, self.cos_o, b.w, b.cos_o);
        LightBounds {
            lo: self.lo.min(b.lo),
            hi: self.hi.max(b.hi),
            phi: self.phi + b.phi,
            w,
            cos_o,
            cos_e: self.cos_e.min(b.cos_e),
            two_sided: self.two_sided || b.two_sided,
        }
    }

    fn centroid(&self) -> Vec3 {
        0.5 * (self.lo + self.hi)
    }

    /// An upper estimate of the light these lights send to `p`, whose
    /// surface normal is `n` (zero: a point in a medium, which takes light
    /// from every direction).
    #[cfg(test)]
    pub(crate) fn importance(&self, p: Vec3, n: Vec3) -> f32 {
        Packed::new(self).importance(p, n)
    }

    /// The orientation part of the build's cost: the solid angle the
    /// bound's emission covers, weighted by the cosine to the cone's axis
    /// (the measure M_Ω of Conty Estevez & Kulla).
    fn orientation_measure(&self) -> f32 {
        let theta_o = self.cos_o.clamp(-1.0, 1.0).acos();
        let theta_e = self.cos_e.clamp(-1.0, 1.0).acos();
        let theta_w = (theta_o + theta_e).min(PI);
        let (sin_o, cos_o) = theta_o.sin_cos();
        2.0 * PI * (1.0 - cos_o)
            + PI / 2.0
                * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o
                    + cos_o)
    }
}

/// The sine and cosine of `max(0, a - b)` from those of `a` and `b` (both
/// in `[0, π]`).
#[inline]
fn less_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> (f32, f32) {
    if cos_a >= cos_b {
        (0.0, 1.0)
    } else {
        (sin_a * cos_b - cos_a * sin_b, cos_a * cos_b + sin_a * sin_b)
    }
}

/// A bound as the walk reads it: the quantities the importance needs,
/// computed once at the build (the box's centre, its bounding sphere's
/// radius and squared radius, the sine of the cone's half-angle).
#[derive(Clone, Copy, Debug)]
struct Packed {
    centre: Vec3,
    /// The squared radius of the box's bounding sphere.
    r2: f32,
    lo: Vec3,
    /// The radius of the box's bounding sphere.
    r: f32,
    hi: Vec3,
    phi: f32,
    w: Vec3,
    cos_o: f32,
    sin_o: f32,
    cos_e: f32,
    two_sided: bool,
    /// The cone holds every direction (cos θo = -1): the orientation
    /// term is one wherever the point is.
    omni: bool,
}

impl Packed {
    fn new(b: &LightBounds) -> Self {
        let r2 = 0.25 * (b.hi - b.lo).length_squared();
        Self {
            centre: b.centroid(),
            r2,
            lo: b.lo,
            r: r2.sqrt(),
            hi: b.hi,
            phi: b.phi,
            w: b.w,
            cos_o: b.cos_o,
            sin_o: (1.0 - b.cos_o * b.cos_o).max(0.0).sqrt(),
            cos_e: b.cos_e,
            two_sided: b.two_sided,
            omni: b.cos_o <= -1.0,
        }
    }

    /// An upper estimate of the light these lights send to `p`, whose
    /// surface normal is `n` (zero: a point in a medium, which takes light
    /// from every direction): `phi` over the squared distance, times the
    /// cosine of the smallest angle the box allows between the cone and
    /// the direction to `p`, times (at a surface) the cosine the box
    /// allows at the normal.
    ///
    /// Seen from a distance `D` the box's bounding sphere (radius `r`)
    /// spans an angle θb with sin θb = r / D and cos θb = √(D² − r²) / D.
    /// The normal term is one when the angle θi to the normal's line is
    /// within θb, which with a = |(p − c)·n| = D cos θi is a² ≥ D² − r²,
    /// and else cos(θi − θb) = (a √(D² − r²) + r √(D² − a²)) / D². So the
    /// usual case, a node of omnidirectional lights in front of the
    /// point, costs a dot product and one division, no square root.
    #[inline(always)]
    fn importance(&self, p: Vec3, n: Vec3) -> f32 {
        if self.phi <= 0.0 {
            return 0.0;
        }
        let to_p = p - self.centre;
        let dist2 = to_p.length_squared();
        // Within the box's sphere the distance is no guide, and the box
        // covers every direction: clamp the distance to the box's size, so
        // a point among the lights does not give them infinite weight.
        if dist2 <= self.r2 || (p.cmpge(self.lo).all() && p.cmple(self.hi).all()) {
            return if 1.0 > self.cos_e {
                (self.phi / self.r2.max(1e-20)).min(f32::MAX)
            } else {
                0.0
            };
        }
        // D² − r², the squared cosine of θb times D².
        let cos2_b_d2 = dist2 - self.r2;
        // The angle between the cone's axis and the direction to p, less
        // the cone's half-angle and the box's spread, at least zero.
        let cos_t = if self.omni {
            1.0
        } else {
            let d = dist2.sqrt();
            let mut cos_w = self.w.dot(to_p) / d;
            if self.two_sided {
                cos_w = cos_w.abs();
            }
            if cos_w >= self.cos_o {
                1.0
            } else {
                let sin_w = (1.0 - cos_w * cos_w).max(0.0).sqrt();
                let (sin_x, cos_x) = less_clamped(sin_w, cos_w, self.sin_o, self.cos_o);
                let (sin_b, cos_b) = (self.r / d, cos2_b_d2.sqrt() / d);
                less_clamped(sin_x, cos_x, sin_b, cos_b).1
            }
        };
        if cos_t <= self.cos_e {
            return 0.0;
        }
        let mut importance = self.phi * cos_t;
        if n != Vec3::ZERO {
            // Light may arrive from either side (transmission): the
            // smallest angle the box allows to the normal's line.
            let a = to_p.dot(n).abs();
            if a * a < cos2_b_d2 {
                let cos_ib =
                    (a * cos2_b_d2.sqrt() + self.r * (dist2 - a * a).max(0.0).sqrt()) / dist2;
                importance *= cos_ib.min(1.0);
            }
        }
        (importance / dist2.max(1e-20)).clamp(0.0, f32::MAX)
    }
}

/// `N` bounds side by side, one per lane, for [`LightTree::sample_lanes`].
struct PackedLanes<const N: usize> {
    centre: V<N>,
    r2: F<N>,
    lo: V<N>,
    r: F<N>,
    hi: V<N>,
    phi: F<N>,
    w: V<N>,
    cos_o: F<N>,
    sin_o: F<N>,
    cos_e: F<N>,
    two_sided: M<N>,
    omni: M<N>,
}

impl<const N: usize> PackedLanes<N> {
    /// Lane `i` holds the bound `of(i)`.
    #[inline(always)]
    fn gather<'a>(of: impl Fn(usize) -> &'a Packed) -> Self {
        let b: [&Packed; N] = std::array::from_fn(of);
        Self {
            centre: V::from_fn(|i| b[i].centre),
            r2: F::from_fn(|i| b[i].r2),
            lo: V::from_fn(|i| b[i].lo),
            r: F::from_fn(|i| b[i].r),
            hi: V::from_fn(|i| b[i].hi),
            phi: F::from_fn(|i| b[i].phi),
            w: V::from_fn(|i| b[i].w),
            cos_o: F::from_fn(|i| b[i].cos_o),
            sin_o: F::from_fn(|i| b[i].sin_o),
            cos_e: F::from_fn(|i| b[i].cos_e),
            two_sided: M(std::array::from_fn(|i| b[i].two_sided)),
            omni: M(std::array::from_fn(|i| b[i].omni)),
        }
    }

    /// [`Packed::importance`] lane by lane: every branch computed and the
    /// lanes' results selected, in the same operations and order, so each
    /// lane's value is the scalar one bit for bit.
    #[inline(always)]
    fn importance(&self, p: V<N>, n: V<N>) -> F<N> {
        let zero = F::splat(0.0);
        let one = F::splat(1.0);
        let to_p = p - self.centre;
        let dist2 = to_p.length_squared();
        let in_box = p.x.ge(self.lo.x)
            & p.y.ge(self.lo.y)
            & p.z.ge(self.lo.z)
            & p.x.le(self.hi.x)
            & p.y.le(self.hi.y)
            & p.z.le(self.hi.z);
        let inside = dist2.le(self.r2) | in_box;
        let inside_value = one.gt(self.cos_e).select(
            (self.phi / self.r2.zip(F::splat(1e-20), f32::max)).zip(F::splat(f32::MAX), f32::min),
            zero,
        );
        let cos2_b_d2 = dist2 - self.r2;
        // The cone's angle, skipped where every lane's lights shine every
        // way (points, spheres).
        let cos_t = if self.omni.all() {
            one
        } else {
            let d = dist2.sqrt();
            let cos_w = self.w.dot(to_p) / d;
            let cos_w = self.two_sided.select(cos_w.abs(), cos_w);
            let within = cos_w.ge(self.cos_o);
            let sin_w = (one - cos_w * cos_w).zip(zero, f32::max).sqrt();
            let (sin_x, cos_x) = less_clamped_lanes(sin_w, cos_w, self.sin_o, self.cos_o);
            let (sin_b, cos_b) = (self.r / d, cos2_b_d2.sqrt() / d);
            let spread = less_clamped_lanes(sin_x, cos_x, sin_b, cos_b).1;
            (self.omni | within).select(one, spread)
        };
        let dark = cos_t.le(self.cos_e);
        let at_surface = !(n.x.eq(zero) & n.y.eq(zero) & n.z.eq(zero));
        let a = to_p.dot(n).abs();
        let narrow = at_surface & (a * a).lt(cos2_b_d2);
        let mut importance = self.phi * cos_t;
        if narrow.any() {
            let cos_ib = (a * cos2_b_d2.sqrt()
                + self.r * (dist2 - a * a).zip(zero, f32::max).sqrt())
                / dist2;
            importance = narrow.select(importance * cos_ib.zip(one, f32::min), importance);
        }
        let value =
            (importance / dist2.zip(F::splat(1e-20), f32::max)).map(|x| x.clamp(0.0, f32::MAX));
        let value = dark.select(zero, value);
        let value = inside.select(inside_value, value);
        self.phi.le(zero).select(zero, value)
    }
}

/// [`less_clamped`]'s cosine and sine, lane by lane.
#[inline(always)]
fn less_clamped_lanes<const N: usize>(
    sin_a: F<N>,
    cos_a: F<N>,
    sin_b: F<N>,
    cos_b: F<N>,
) -> (F<N>, F<N>) {
    let none = cos_a.ge(cos_b);
    (
        none.select(F::splat(0.0), sin_a * cos_b - cos_a * sin_b),
        none.select(F::splat(1.0), cos_a * cos_b + sin_a * sin_b),
    )
}

/// The smallest cone (axis, cosine of the half-angle) holding both cones.
fn cone_union(wa: Vec3, cos_a: f32, wb: Vec3, cos_b: f32) -> (Vec3, f32) {
    if cos_a <= -1.0 || cos_b <= -1.0 {
        return (wa, -1.0);
    }
    let theta_a = cos_a.clamp(-1.0, 1.0).acos();
    let theta_b = cos_b.clamp(-1.0, 1.0).acos();
    let cross = wa.cross(wb);
    let theta_d = cross.length().atan2(wa.dot(wb));
    if (theta_d + theta_b).min(PI) <= theta_a {
        return (wa, cos_a);
    }
    if (theta_d + theta_a).min(PI) <= theta_b {
        return (wb, cos_b);
    }
    let theta_o = 0.5 * (theta_a + theta_d + theta_b);
    if theta_o >= PI || cross.length_squared() < 1e-12 {
        return (wa, -1.0);
    }
    // Turn a's axis towards b's until the cone reaches both.
    let w = (Quat::from_axis_angle(cross.normalize(), theta_o - theta_a) * wa).normalize();
    (w, theta_o.cos())
}

/// A node: its bound, and its children or light.
#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: Packed,
    /// A leaf's light; an inner node's second child (its first is the
    /// next node).
    index: u32,
    leaf: bool,
}

/// Left/right choices from the root to a light: bit `k` is the choice at
/// depth `k` (1: the second child), `depth` of them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Trail {
    bits: u64,
    depth: u8,
}

/// Depth beyond which the build splits a node's lights in two halves by
/// count, so that no trail is longer than its 64 bits.
const MAX_SAH_DEPTH: u32 = 40;

/// Buckets along each axis in which the build weighs splits.
const BUCKETS: usize = 12;

/// A light tree over lights `0..n` given by their bounds.
#[derive(Clone, Debug)]
pub(crate) struct LightTree {
    nodes: Vec<Node>,
    /// Per light, its trail (None: it emits nothing and is left out).
    trails: Vec<Option<Trail>>,
}

impl LightTree {
    /// The tree over the lights with bounds `bounds` (lights of no power
    /// are left out: they are never chosen).
    pub(crate) fn new(bounds: &[LightBounds]) -> Self {
        let mut items: Vec<(LightBounds, u32)> = bounds
            .iter()
            .enumerate()
            .filter(|(_, b)| b.phi > 0.0 && b.phi.is_finite() && b.lo.is_finite())
            .map(|(i, b)| (*b, i as u32))
            .collect();
        let mut tree = Self {
            nodes: Vec::with_capacity(2 * items.len()),
            trails: vec![None; bounds.len()],
        };
        if !items.is_empty() {
            tree.build(&mut items, Trail::default());
        }
        tree
    }

    /// True if no light is in the tree.
    pub(crate) fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Builds the subtree of `items` at `trail`; returns its node's index.
    fn build(&mut self, items: &mut [(LightBounds, u32)], trail: Trail) -> usize {
        let at = self.nodes.len();
        if let [(b, light)] = items {
            self.nodes.push(Node {
                bounds: Packed::new(b),
                index: *light,
                leaf: true,
            });
            self.trails[*light as usize] = Some(trail);
            return at;
        }
        let all = items[1..]
            .iter()
            .fold(items[0].0, |acc, (b, _)| acc.union(b));
        self.nodes.push(Node {
            bounds: Packed::new(&all),
            index: 0,
            leaf: true,
        });
        let mid = split(items, &all, u32::from(trail.depth) < MAX_SAH_DEPTH);
        let (left, right) = items.split_at_mut(mid);
        let depth = trail.depth + 1;
        self.build(
            left,
            Trail {
                bits: trail.bits,
                depth,
            },
        );
        let second = self.build(
            right,
            Trail {
                bits: trail.bits | 1 << trail.depth,
                depth,
            },
        );
        self.nodes[at].index = second as u32;
        self.nodes[at].leaf = false;
        at
    }

    /// A light chosen for the point `p` with normal `n` (zero in a medium)
    /// by `u`, and the probability of the choice; None where no light can
    /// reach the point.
    pub(crate) fn sample(&self, p: Vec3, n: Vec3, mut u: f32) -> Option<(u32, f32)> {
        let mut i = 0usize;
        let mut pmf = 1.0f32;
        let root = self.nodes.first()?;
        if root.leaf {
            return (root.bounds.importance(p, n) > 0.0).then_some((root.index, 1.0));
        }
        loop {
            let node = &self.nodes[i];
            if node.leaf {
                return Some((node.index, pmf));
            }
            let (a, b) = (i + 1, node.index as usize);
            let ia = self.nodes[a].bounds.importance(p, n);
            let ib = self.nodes[b].bounds.importance(p, n);
            let sum = ia + ib;
            if sum.is_nan() || sum <= 0.0 {
                return None;
            }
            let pa = ia / sum;
            if u < pa {
                u = (u / pa).min(ONE_BELOW);
                pmf *= pa;
                i = a;
            } else {
                u = ((u - pa) / (1.0 - pa)).clamp(0.0, ONE_BELOW);
                pmf *= 1.0 - pa;
                i = b;
            }
        }
    }

    /// [`LightTree::sample`] for the `N` points of the lanes `on` at once:
    /// per lane the light chosen, the probability of the choice and
    /// whether a light was chosen. The lanes walk down together, each
    /// level's two importances computed in the lanes; each lane's answer
    /// is the scalar walk's, bit for bit.
    #[inline(always)]
    pub(crate) fn sample_lanes<const N: usize>(
        &self,
        on: M<N>,
        p: V<N>,
        n: V<N>,
        mut u: F<N>,
    ) -> (U<N>, F<N>, M<N>) {
        let mut light = U([0; N]);
        let mut pmf = F::splat(1.0);
        let mut found = M::splat(false);
        let Some(root) = self.nodes.first() else {
            return (light, pmf, found);
        };
        let zero = F::splat(0.0);
        if root.leaf {
            let lit = PackedLanes::<N>::gather(|_| &root.bounds)
                .importance(p, n)
                .gt(zero);
            return (U([root.index; N]), pmf, on & lit);
        }
        let one_below = F::splat(ONE_BELOW);
        let mut node = U([0u32; N]);
        let mut walking = on;
        while walking.any() {
            // Lanes that are not walking look at the root's children, whose
            // answers are not used.
            let at = walking.select_u(node, U([0; N]));
            let first = at.map(|i| i + 1);
            let second = U(std::array::from_fn(|i| self.nodes[at.0[i] as usize].index));
            let ia = PackedLanes::<N>::gather(|i| &self.nodes[first.0[i] as usize].bounds)
                .importance(p, n);
            let ib = PackedLanes::<N>::gather(|i| &self.nodes[second.0[i] as usize].bounds)
                .importance(p, n);
            let sum = ia + ib;
            let dead = sum.test(sum, |s, _| s.is_nan() || s <= 0.0);
            walking = walking & !dead;
            let pa = ia / sum;
            let left = u.lt(pa);
            let u_left = (u / pa).zip(one_below, f32::min);
            let u_right = ((u - pa) / (F::splat(1.0) - pa)).map(|x| x.clamp(0.0, ONE_BELOW));
            u = walking.select(left.select(u_left, u_right), u);
            pmf = walking.select(left.select(pmf * pa, pmf * (F::splat(1.0) - pa)), pmf);
            node = walking.select_u(left.select_u(first, second), node);
            for i in 0..N {
                if walking.0[i] {
                    let at = &self.nodes[node.0[i] as usize];
                    if at.leaf {
                        light.0[i] = at.index;
                        found.0[i] = true;
                        walking.0[i] = false;
                    }
                }
            }
        }
        (light, pmf, found)
    }

    /// The probability that [`LightTree::sample`] chooses `light` at `p`
    /// with normal `n`.
    pub(crate) fn pmf(&self, p: Vec3, n: Vec3, light: u32) -> f32 {
        let Some(Some(trail)) = self.trails.get(light as usize) else {
            return 0.0;
        };
        let root = &self.nodes[0];
        if root.leaf {
            return if root.bounds.importance(p, n) > 0.0 {
                1.0
            } else {
                0.0
            };
        }
        let mut i = 0usize;
        let mut pmf = 1.0f32;
        for k in 0..trail.depth {
            let node = &self.nodes[i];
            let (a, b) = (i + 1, node.index as usize);
            let ia = self.nodes[a].bounds.importance(p, n);
            let ib = self.nodes[b].bounds.importance(p, n);
            let sum = ia + ib;
            if sum.is_nan() || sum <= 0.0 {
                return 0.0;
            }
            // The same arithmetic as the sampling walk, so that both give
            // the same number.
            let pa = ia / sum;
            if trail.bits >> k & 1 == 0 {
                pmf *= pa;
                i = a;
            } else {
                pmf *= 1.0 - pa;
                i = b;
            }
        }
        pmf
    }
}

/// The largest f32 below one.
const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

/// Reorders `items` and returns where to split them: the best split of
/// the buckets along any axis by the cost of Conty Estevez & Kulla (power
/// times orientation measure times surface area, the box's elongation
/// weighed in), or (with `sah` false, or when no split separates them) in
/// two halves by count along the longest axis.
fn split(items: &mut [(LightBounds, u32)], all: &LightBounds, sah: bool) -> usize {
    let (clo, chi) = items
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), (b, _)| {
            (lo.min(b.centroid()), hi.max(b.centroid()))
        });
    let extent = all.hi - all.lo;
    let max_extent = extent.max_element();
    let mut best: Option<(f32, usize, usize)> = None;
    if sah {
        for axis in 0..3 {
            let (lo, hi) = (clo[axis], chi[axis]);
            if hi <= lo {
                continue;
            }
            let bucket = |b: &LightBounds| {
                let t = (b.centroid()[axis] - lo) / (hi - lo);
                ((t * BUCKETS as f32) as usize).min(BUCKETS - 1)
            };
            let mut buckets: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
            for (b, _) in items.iter() {
                let k = bucket(b);
                buckets[k] = Some(buckets[k].map_or(*b, |x| x.union(b)));
            }
            let kr = if extent[axis] > 0.0 {
                max_extent / extent[axis]
            } else {
                1.0
            };
            let cost = |b: &Option<LightBounds>| {
                b.map_or(0.0, |b| {
                    let e = b.hi - b.lo;
                    let area = 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
                    b.phi * b.orientation_measure() * area * kr
                })
            };
            let fold = |acc: Option<LightBounds>, b: &Option<LightBounds>| match (acc, b) {
                (Some(a), Some(b)) => Some(a.union(b)),
                (a, b) => a.or(*b),
            };
            for cut in 1..BUCKETS {
                let below = buckets[..cut].iter().fold(None, fold);
                let above = buckets[cut..].iter().fold(None, fold);
                if below.is_none() || above.is_none() {
                    continue;
                }
                let c = cost(&below) + cost(&above);
                if c.is_finite() && best.is_none_or(|(bc, _, _)| c < bc) {
                    best = Some((c, axis, cut));
                }
            }
        }
    }
    if let Some((_, axis, cut)) = best {
        let (lo, hi) = (clo[axis], chi[axis]);
        let mut k = 0;
        for j in 0..items.len() {
            let t = (items[j].0.centroid()[axis] - lo) / (hi - lo);
            if (((t * BUCKETS as f32) as usize).min(BUCKETS - 1)) < cut {
                items.swap(j, k);
                k += 1;
            }
        }
        if k > 0 && k < items.len() {
            return k;
        }
    }
    // Halves by count along the axis where the centroids spread most.
    let axis = (chi - clo).max_position();
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| {
        a.0.centroid()[axis].total_cmp(&b.0.centroid()[axis])
    });
    mid
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A few hundred lights of every kind of bound, spread over a box.
    fn lights() -> Vec<LightBounds> {
        let mut s = 0x2545_f491_u64;
        let mut r = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut v = Vec::new();
        for i in 0..300 {
            let p = Vec3::new(r(), r(), r()) * 10.0;
            let phi = 0.1 + 10.0 * r();
            let n = Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize();
            v.push(match i % 5 {
                0 => LightBounds::point(p, phi),
                1 => LightBounds::cone(p, phi, n, 0.8, 0.9),
                2 => LightBounds::sphere(p, 0.1, phi, false),
                3 => {
                    let (a, b) = (
                        n.any_orthonormal_vector(),
                        n.cross(n.any_orthonormal_vector()),
                    );
                    LightBounds::surface(&[p, p + a * 0.3, p + b * 0.3], n, phi, i % 2 == 0)
                }
                _ => LightBounds::surface(&[p, p + Vec3::X, p + Vec3::Y], Vec3::Z, phi, false),
            });
        }
        v
    }

    /// Checks at points around the lights that the pmf of every light
    /// and the failures of sampling add up to one, that sampling chooses
    /// each light as often as its pmf says and returns that pmf, that a
    /// light that can send light to a point can be chosen there, and
    /// returns the sum of the pmf at each point.
    fn check(b: &[LightBounds]) -> Vec<f64> {
        let tree = LightTree::new(b);
        let points = [
            (Vec3::new(5.0, 5.0, 5.0), Vec3::ZERO),
            (Vec3::new(-3.0, 2.0, 7.0), Vec3::new(0.0, 1.0, 0.0)),
            (Vec3::new(1.0, 9.0, 0.5), Vec3::new(0.6, 0.0, 0.8)),
            (Vec3::new(30.0, -4.0, 2.0), Vec3::X),
        ];
        let mut sums = Vec::new();
        for (p, n) in points {
            let pmf: Vec<f32> = (0..b.len() as u32).map(|i| tree.pmf(p, n, i)).collect();
            for (i, &q) in pmf.iter().enumerate() {
                if b[i].importance(p, n) > 0.0 {
                    assert!(q > 0.0, "light {i} can light {p} but is never chosen");
                }
            }
            let sum: f64 = pmf.iter().map(|&x| f64::from(x)).sum();
            // Stratified draws: each light's share of [0, 1) is one
            // interval of its pmf's length.
            let m = 200_000;
            let mut count = vec![0u32; b.len()];
            let mut failed = 0u32;
            for k in 0..m {
                let u = (k as f32 + 0.5) / m as f32;
                let Some((i, q)) = tree.sample(p, n, u) else {
                    failed += 1;
                    continue;
                };
                assert!((q - pmf[i as usize]).abs() <= 1e-5 * pmf[i as usize].max(1e-3));
                count[i as usize] += 1;
            }
            for (i, &c) in count.iter().enumerate() {
                let expect = pmf[i] as f64 * m as f64;
                assert!(
                    (c as f64 - expect).abs() <= 2.0 + 1e-3 * expect,
                    "{i}: {c} vs {expect}"
                );
            }
            let total = sum + f64::from(failed) / f64::from(m);
            assert!((total - 1.0).abs() < 1e-3, "pmf {sum} + failures at {p}");
            sums.push(sum);
        }
        sums
    }

    #[test]
    fn the_pmf_sums_to_one_and_matches_sampling() {
        // Lights that send light everywhere: the pmf sums to one.
        let omni: Vec<LightBounds> = lights()
            .into_iter()
            .map(|b| LightBounds { cos_o: -1.0, ..b })
            .collect();
        for sum in check(&omni) {
            assert!((sum - 1.0).abs() < 1e-4, "sum {sum}");
        }
        // Lights facing their own ways: some walks find no light there
        // (a node's bound reaches the point, none of its lights does).
        for sum in check(&lights()) {
            assert!(sum > 0.5 && sum <= 1.0 + 1e-4, "sum {sum}");
        }
    }

    /// The walk in lanes answers each lane as the scalar walk does, bit
    /// for bit: at points among, beside and far from the lights, at a
    /// surface and in a medium, with lanes switched off; for many lights,
    /// one light and none.
    #[test]
    fn the_lanes_walk_is_the_scalar_walk() {
        const N: usize = 16;
        let mut r = crate::math::hash::test_numbers(2);
        let many = lights();
        for b in [many.clone(), many[3..4].to_vec(), Vec::new()] {
            let tree = LightTree::new(&b);
            for _ in 0..400 {
                let p = V::<N>::from_fn(|_| Vec3::new(r(), r(), r()) * 14.0 - 2.0);
                let n = V::<N>::from_fn(|i| {
                    if i % 4 == 0 {
                        Vec3::ZERO
                    } else {
                        Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize()
                    }
                });
                let u = F::<N>::from_fn(|_| r());
                let on = M(std::array::from_fn(|_| r() < 0.8));
                let (light, pmf, found) = tree.sample_lanes(on, p, n, u);
                for i in 0..N {
                    let scalar = if on.0[i] {
                        tree.sample(p.get(i), n.get(i), u.0[i])
                    } else {
                        None
                    };
                    let lanes = found.0[i].then(|| (light.0[i], pmf.0[i]));
                    assert_eq!(
                        scalar.map(|(l, q)| (l, q.to_bits())),
                        lanes.map(|(l, q)| (l, q.to_bits())),
                        "lane {i} at {}",
                        p.get(i)
                    );
                }
            }
        }
    }

    /// The importance by its definition, in angles (f64): phi over the
    /// squared distance times cos max(0, θw − θo − θb) (zero from θe on)
    /// times, at a surface, cos max(0, θi − θb); inside the box's sphere
    /// phi over its squared radius.
    fn importance_by_angles(b: &LightBounds, p: Vec3, n: Vec3) -> f64 {
        let (lo, hi) = (b.lo.as_dvec3(), b.hi.as_dvec3());
        let c = 0.5 * (lo + hi);
        let r2 = 0.25 * (hi - lo).length_squared();
        let to_p = p.as_dvec3() - c;
        let d2 = to_p.length_squared();
        let phi = f64::from(b.phi);
        if d2 <= r2 {
            return phi / r2.max(1e-20);
        }
        let wi = to_p / d2.sqrt();
        let theta_b = (r2 / d2).sqrt().asin();
        let mut cos_w = b.w.as_dvec3().dot(wi);
        if b.two_sided {
            cos_w = cos_w.abs();
        }
        let theta_w = cos_w.clamp(-1.0, 1.0).acos();
        let theta_o = f64::from(b.cos_o).clamp(-1.0, 1.0).acos();
        let theta_e = f64::from(b.cos_e).clamp(-1.0, 1.0).acos();
        let theta = (theta_w - theta_o - theta_b).max(0.0);
        if theta >= theta_e {
            return 0.0;
        }
        let mut v = phi * theta.cos() / d2;
        if n != Vec3::ZERO {
            let theta_i = wi.dot(n.as_dvec3()).abs().min(1.0).acos();
            v *= (theta_i - theta_b).max(0.0).cos();
        }
        v
    }

    #[test]
    fn the_importance_is_its_definition_in_angles() {
        let mut s = 0x9e37_79b9_u64;
        let mut r = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        let bounds = lights();
        // Unions too: boxes with wide cones.
        let mut all: Vec<LightBounds> = bounds.clone();
        for k in 0..bounds.len() / 3 {
            all.push(
                bounds[3 * k]
                    .union(&bounds[3 * k + 1])
                    .union(&bounds[3 * k + 2]),
            );
        }
        let mut checked = 0;
        for b in &all {
            for _ in 0..40 {
                let p = Vec3::new(r(), r(), r()) * 14.0 - Vec3::splat(2.0);
                let n = match (r() * 3.0) as u32 {
                    0 => Vec3::ZERO,
                    _ => Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize(),
                };
                let want = importance_by_angles(b, p, n);
                let got = f64::from(b.importance(p, n));
                // Near θe the cut-off may fall either side.
                let scale = f64::from(b.phi) / (p - b.centroid()).length_squared().max(1e-6) as f64;
                if (want - got).abs() > 1e-3 * want + 2e-3 * scale {
                    let theta_edge = want == 0.0 || got == 0.0;
                    assert!(
                        theta_edge && want.min(got) == 0.0 && want.max(got) < 0.02 * scale,
                        "{b:?} at {p} {n}: {got} vs {want}"
                    );
                }
                checked += 1;
            }
        }
        assert!(checked > 10_000);
    }

    #[test]
    fn lights_behind_a_point_or_outside_a_spot_have_no_weight() {
        // A quad facing +z and a spot aimed down its -z axis.
        let quad = LightBounds::surface(
            &[Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)],
            Vec3::Z,
            1.0,
            false,
        );
        assert!(quad.importance(Vec3::new(0.5, 0.5, 2.0), Vec3::Z) > 0.0);
        assert_eq!(quad.importance(Vec3::new(0.5, 0.5, -2.0), Vec3::Z), 0.0);
        let two = LightBounds {
            two_sided: true,
            ..quad
        };
        assert!(two.importance(Vec3::new(0.5, 0.5, -2.0), Vec3::Z) > 0.0);
        let cos = |deg: f32| deg.to_radians().cos();
        let spot = LightBounds::cone(Vec3::ZERO, 1.0, Vec3::NEG_Z, cos(20.0), cos(10.0));
        assert!(spot.importance(Vec3::new(0.0, 0.0, -5.0), Vec3::ZERO) > 0.0);
        assert!(spot.importance(Vec3::new(5.0 * 0.5, 0.0, -5.0), Vec3::ZERO) > 0.0);
        assert_eq!(spot.importance(Vec3::new(5.0, 0.0, -5.0), Vec3::ZERO), 0.0);
        // A union holds both cones.
        let (w, c) = cone_union(Vec3::Z, cos(10.0), Vec3::X, cos(10.0));
        assert!((c - cos(55.0)).abs() < 1e-4);
        assert!((w - Vec3::new(1.0, 0.0, 1.0).normalize()).length() < 1e-4);
    }
}
