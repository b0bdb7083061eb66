//! Clipping a triangle to a box ("perfect splits", Havran 2000; Wald &
//! Havran 2006, section 4.3): the exact bounds of the part of a triangle that
//! lies inside a cell.

use glam::DVec3;

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
        assert_eq!(b.min, Vec3::new(1.0, 0.0, 0.0));
        assert_eq!(b.max, Vec3::new(2.0, 1.0, 0.0));
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
