//! Clipping a triangle to a box ("perfect splits", Havran 2000; Wald &
//! Havran 2006, section 4.3): the exact bounds of the part of a triangle that
//! lies inside a cell.

use glam::{BVec3A, DVec3, Vec3A};

use super::{Aabb, Triangle};

/// The bounds of `tri ∩ cell`, or `None` if they do not meet.
///
/// The polygon is clipped in f64 (Sutherland-Hodgman against the six
/// planes), its bounds are rounded outward to f32 and then intersected with
/// the cell, so the result always contains the true clipped triangle and
/// never leaves the cell.
pub fn clipped_bounds(tri: &Triangle, cell: &Aabb) -> Option<Aabb> {
    let tb = tri.bounds();
    // Fast path: a triangle inside the cell is its own clip.
    if tb.min.cmpge(cell.min).all() && tb.max.cmple(cell.max).all() {
        return Some(tb);
    }
    let inter = tb.intersection(*cell);
    if inter.is_empty() {
        return None;
    }
    // A polygon clipped by six planes has at most 3 + 6 vertices.
    let mut poly = [DVec3::ZERO; 9];
    let mut tmp = [DVec3::ZERO; 9];
    let mut n = 3;
    for (i, v) in tri.v.iter().enumerate() {
        poly[i] = v.as_dvec3();
    }
    for axis in 0..3 {
        // Only planes the triangle actually crosses need clipping.
        if tb.min[axis] < cell.min[axis] {
            n = clip_plane(&poly[..n], &mut tmp, axis, cell.min[axis] as f64, true);
            poly[..n].copy_from_slice(&tmp[..n]);
        }
        if tb.max[axis] > cell.max[axis] {
            n = clip_plane(&poly[..n], &mut tmp, axis, cell.max[axis] as f64, false);
            poly[..n].copy_from_slice(&tmp[..n]);
        }
        if n == 0 {
            return None;
        }
    }
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for p in &poly[..n] {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    // The clipped vertices carry f64 rounding relative to the largest
    // coordinate involved; pad by a bound on it so the bounds stay
    // conservative even for a 1e18-sized triangle cut by a 0.1-wide cell
    // (negligible, and below f32 resolution, at ordinary ratios).
    let scale = tri
        .v
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs().max_element() as f64));
    let scale = scale
        .max(cell.min.abs().max_element() as f64)
        .max(cell.max.abs().max_element() as f64);
    let pad = 16.0 * f64::EPSILON * scale;
    lo -= DVec3::splat(pad);
    hi += DVec3::splat(pad);
    let mut out = Aabb::EMPTY;
    for a in 0..3 {
        out.min[a] = round_down(lo[a]);
        out.max[a] = round_up(hi[a]);
    }
    let out = out.intersection(inter);
    if out.is_empty() {
        None
    } else {
        Some(out)
    }
}

/// The bounds of the parts of `tri` in the consecutive slabs
/// `planes[i] <= x[axis] <= planes[i + 1]` (`planes` ascending), each
/// intersected with the box `within` (`[lo, hi]`): `emit(i, lo, hi)` for
/// every slab whose part is not empty. For the bins of a spatial split, in
/// O(1) per slab: a part's corners are the triangle's vertices inside its
/// slab and the points where the triangle's edges cross its two planes, and
/// the crossings of a plane are computed once for the two slabs that share
/// it.
///
/// The crossings are computed in f32 and padded by `16 u S` (`u = 2^-24`,
/// `S` the largest coordinate magnitude of the triangle), which bounds
/// their rounding: `t = (c - p_a) * (1 / (q_a - p_a))` carries four
/// roundings (a relative error below `4.01 u`), so the point
/// `p + (q - p) t` is off by at most `|q - p| 6.01 u + |x| u <= 13.1 u S`
/// per coordinate (`|t| <= 1`, `|q - p| <= 2S`, `|x| <= S`). The vertices
/// are exact, so every part contains the
/// true clip of the triangle to its slab and is at most that pad larger.
pub fn slab_parts(
    tri: &Triangle,
    axis: usize,
    planes: &[f32],
    within: (Vec3A, Vec3A),
    mut emit: impl FnMut(usize, Vec3A, Vec3A),
) {
    let Some(last) = planes.len().checked_sub(1) else {
        return;
    };
    let v = tri.v.map(Vec3A::from);
    let s = v.iter().fold(0.0f32, |m, p| m.max(p.abs().max_element()));
    // The floor covers gradual underflow (absolute errors of 2^-149).
    let pad = Vec3A::splat((16.0 * (f32::EPSILON / 2.0) * s).max(f32::MIN_POSITIVE));
    let on_axis = BVec3A::new(axis == 0, axis == 1, axis == 2);
    let pa = [v[0][axis], v[1][axis], v[2][axis]];
    let d = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    let inv = [0, 1, 2].map(|i| 1.0 / (pa[(i + 1) % 3] - pa[i]));
    // The bounds of the triangle's section by the plane `axis = c`: the
    // edges' crossings (padded) and the vertices on it.
    let section = |c: f32| -> (Vec3A, Vec3A) {
        let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        for i in 0..3 {
            let (p, q) = (pa[i], pa[(i + 1) % 3]);
            let crosses = BVec3A::splat((p < c && q > c) || (p > c && q < c));
            let x = Vec3A::select(on_axis, Vec3A::splat(c), v[i] + d[i] * ((c - p) * inv[i]));
            lo = lo.min(Vec3A::select(crosses, x, Vec3A::INFINITY));
            hi = hi.max(Vec3A::select(crosses, x, Vec3A::NEG_INFINITY));
        }
        let (mut lo, mut hi) = (lo - pad, hi + pad);
        for (i, p) in v.iter().enumerate() {
            let on = BVec3A::splat(pa[i] == c);
            lo = lo.min(Vec3A::select(on, *p, Vec3A::INFINITY));
            hi = hi.max(Vec3A::select(on, *p, Vec3A::NEG_INFINITY));
        }
        (lo, hi)
    };
    let mut below = section(planes[0]);
    for i in 0..last {
        let (c0, c1) = (planes[i], planes[i + 1]);
        let above = section(c1);
        let (mut lo, mut hi) = (below.0.min(above.0), below.1.max(above.1));
        for (k, p) in v.iter().enumerate() {
            let inside = BVec3A::splat(pa[k] > c0 && pa[k] < c1);
            lo = lo.min(Vec3A::select(inside, *p, Vec3A::INFINITY));
            hi = hi.max(Vec3A::select(inside, *p, Vec3A::NEG_INFINITY));
        }
        let lo = lo.max(Vec3A::select(
            on_axis,
            within.0.max(Vec3A::splat(c0)),
            within.0,
        ));
        let hi = hi.min(Vec3A::select(
            on_axis,
            within.1.min(Vec3A::splat(c1)),
            within.1,
        ));
        if lo.cmple(hi).all() {
            emit(i, lo, hi);
        }
        below = above;
    }
}

/// One Sutherland-Hodgman step: keep the part of `poly` on the inner side of
/// the plane `axis = pos` (`keep_above` selects the side `>= pos`).
fn clip_plane(
    poly: &[DVec3],
    out: &mut [DVec3; 9],
    axis: usize,
    pos: f64,
    keep_above: bool,
) -> usize {
    let inside = |p: &DVec3| {
        if keep_above {
            p[axis] >= pos
        } else {
            p[axis] <= pos
        }
    };
    let mut n = 0;
    for i in 0..poly.len() {
        let a = poly[i];
        let b = poly[(i + 1) % poly.len()];
        let (ia, ib) = (inside(&a), inside(&b));
        if ia {
            out[n] = a;
            n += 1;
        }
        if ia != ib {
            let t = (pos - a[axis]) / (b[axis] - a[axis]);
            let mut p = a + (b - a) * t;
            p[axis] = pos; // exactly on the plane
            out[n] = p;
            n += 1;
        }
    }
    n
}

/// The largest f32 not above `x`.
fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) > x {
        f.next_down()
    } else {
        f
    }
}

/// The smallest f32 not below `x`.
fn round_up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x {
        f.next_up()
    } else {
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn triangle_inside_is_unchanged() {
        let t = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        let cell = Aabb::new(Vec3::splat(-1.0), Vec3::splat(2.0));
        assert_eq!(clipped_bounds(&t, &cell), Some(t.bounds()));
    }

    #[test]
    fn clipping_tightens_the_other_axes() {
        // The right triangle (0,0)-(2,0)-(0,2) cut at x >= 1 spans y in [0, 1].
        let t = Triangle::new(
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        );
        let cell = Aabb::new(Vec3::new(1.0, -5.0, -5.0), Vec3::splat(5.0));
        let b = clipped_bounds(&t, &cell).unwrap();
        // Exact up to the conservative outward rounding (at most 1 ulp).
        let exact = Aabb::new(Vec3::new(1.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 0.0));
        assert!(
            b.min.cmple(exact.min).all() && b.max.cmpge(exact.max).all(),
            "{b:?} must contain {exact:?}"
        );
        assert!(
            (b.max - exact.max).abs().max_element() <= 2.0 * f32::EPSILON,
            "{b:?}"
        );
        assert!(
            (b.min - exact.min).abs().max_element() <= 2.0 * f32::EPSILON,
            "{b:?}"
        );
    }

    #[test]
    fn clipping_a_huge_triangle_to_a_thin_cell_stays_conservative() {
        // A 1e18 triangle cut by a slab 0.37 thick: f64 rounding of the
        // clipped vertices (~256 units) dwarfs the cell, so without padding
        // the bounds could miss part of the true clip.
        let t = Triangle::new(
            Vec3::new(-1e18, -1e18, 3.0),
            Vec3::new(1e18, 0.0, -5.0),
            Vec3::new(0.0, 1e18, 7.0),
        );
        let cell = Aabb::new(Vec3::new(-10.0, 0.1, -10.0), Vec3::new(10.0, 0.47, 10.0));
        let b = clipped_bounds(&t, &cell).expect("the triangle crosses the slab");
        // The true clip spans the whole x and z range of the cell inside the
        // triangle; check a point of the triangle inside the cell is covered.
        let p = glam::DVec3::new(0.0, 0.3, 0.0);
        let v = t.v.map(|q| q.as_dvec3());
        // Barycentric point of the triangle near p (solve in x, y): the
        // plane's z at (0, 0.3).
        let n = (v[1] - v[0]).cross(v[2] - v[0]);
        let z = v[0].z - (n.x * (p.x - v[0].x) + n.y * (p.y - v[0].y)) / n.z;
        assert!(
            (b.min.z as f64) <= z && z <= b.max.z as f64,
            "{b:?} misses z = {z}"
        );
        assert!(b.min.y >= 0.1 && b.max.y <= 0.47);
    }

    /// The slab parts contain the exact clip of the triangle to each slab
    /// and are at most a few ulps larger.
    #[test]
    fn slab_parts_agree_with_clipped_bounds() {
        let mut f = crate::test_support::floats(77);
        for _ in 0..2000 {
            let t = Triangle::new(
                Vec3::new(f(), f(), f()) * 4.0,
                Vec3::new(f(), f(), f()) * 4.0,
                Vec3::new(f(), f(), f()) * 4.0,
            );
            let axis = (f().abs() * 3.0) as usize % 3;
            let mut planes: Vec<f32> = (0..5).map(|_| f() * 4.0).collect();
            if f() > 0.5 {
                // A plane through a vertex.
                planes[0] = t.v[1][axis];
            }
            planes.sort_by(f32::total_cmp);
            let within = t.bounds();
            let mut parts = [None; 4];
            let w = (within.min.into(), within.max.into());
            slab_parts(&t, axis, &planes, w, |i, lo, hi| {
                parts[i] = Some(Aabb::new(lo.into(), hi.into()))
            });
            for (i, part) in parts.iter().enumerate() {
                let (lo, hi) = (planes[i], planes[i + 1]);
                let mut cell = within;
                cell.min[axis] = cell.min[axis].max(lo);
                cell.max[axis] = cell.max[axis].min(hi);
                let exact = if cell.is_empty() {
                    None
                } else {
                    clipped_bounds(&t, &cell)
                };
                match (exact, *part) {
                    (Some(e), Some(s)) => {
                        assert!(s.min.cmple(e.min + 1e-5).all() && s.max.cmpge(e.max - 1e-5).all());
                        assert!((s.min - e.min).abs().max_element() < 1e-4, "{s:?} {e:?}");
                        assert!((s.max - e.max).abs().max_element() < 1e-4, "{s:?} {e:?}");
                    }
                    (None, None) => {}
                    (e, s) => {
                        // Only a touch at a plane may differ.
                        let b = e.or(s).unwrap();
                        assert!(b.extent()[axis] < 1e-5, "{e:?} {s:?}");
                    }
                }
            }
        }
    }

    /// The corners of the exact clip of the triangle to each slab (its
    /// vertices inside and its edges' crossings of the planes, in f64) lie
    /// in the slab's part, with no tolerance beyond the f64 rounding of the
    /// corners themselves: the parts are conservative.
    #[test]
    fn slab_parts_contain_the_clip() {
        let mut f = crate::test_support::floats(78);
        for _ in 0..2000 {
            let big = if f() > 0.0 { 1e3 } else { 1.0 };
            let t = Triangle::new(
                Vec3::new(f(), f(), f()) * big,
                Vec3::new(f(), f(), f()) * big,
                Vec3::new(f(), f(), f()) + Vec3::splat(f() * big),
            );
            let axis = (f().abs() * 3.0) as usize % 3;
            let within = t.bounds();
            let (lo, hi) = (within.min[axis], within.max[axis]);
            let planes: Vec<f32> = (0..=8).map(|i| lo + (hi - lo) * (i as f32 / 8.0)).collect();
            let mut parts = [Aabb::EMPTY; 8];
            let w = (within.min.into(), within.max.into());
            slab_parts(&t, axis, &planes, w, |i, lo, hi| {
                parts[i] = Aabb::new(lo.into(), hi.into())
            });
            let v = t.v.map(|p| p.as_dvec3());
            for (i, part) in parts.iter().enumerate() {
                let (c0, c1) = (planes[i] as f64, planes[i + 1] as f64);
                let mut corners: Vec<DVec3> = v
                    .iter()
                    .filter(|p| p[axis] >= c0 && p[axis] <= c1)
                    .copied()
                    .collect();
                for k in 0..3 {
                    let (p, q) = (v[k], v[(k + 1) % 3]);
                    for c in [c0, c1] {
                        if (p[axis] - c) * (q[axis] - c) < 0.0 {
                            corners.push(p + (q - p) * ((c - p[axis]) / (q[axis] - p[axis])));
                        }
                    }
                }
                let (pl, ph) = (part.min.as_dvec3(), part.max.as_dvec3());
                for x in corners {
                    let tol = 1e-13 * x.abs().max_element().max(1.0);
                    assert!(
                        x.cmpge(pl - tol).all() && x.cmple(ph + tol).all(),
                        "{x:?} outside slab {i}: {part:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn disjoint_cell_gives_none() {
        // Bounding boxes overlap but the triangle misses the corner cell.
        let t = Triangle::new(
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        );
        let cell = Aabb::new(Vec3::new(1.5, 1.5, -1.0), Vec3::splat(2.0));
        assert_eq!(clipped_bounds(&t, &cell), None);
    }
}
