//! Hit records and the tie rule every query and the oracle share.

/// Where a ray meets a triangle: distance and barycentrics, with the hit
/// point `(1 - u - v) v0 + u v1 + v v2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Barycentric weight of `v1`.
    pub u: f32,
    /// Barycentric weight of `v2`.
    pub v: f32,
}

/// The closest hit of a ray: distance, triangle and barycentrics (hit point
/// `(1 - u - v) v0 + u v1 + v v2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Index of the triangle, as given to the build.
    pub tri: u32,
    /// Barycentric weight of `v1`.
    pub u: f32,
    /// Barycentric weight of `v2`.
    pub v: f32,
}

/// Make `h`, a hit on triangle `i` with `h.t <= *best_t`, the best hit if
/// it is closer, or as close with a smaller index (the tie rule every query
/// and the brute-force oracle share).
#[inline(always)]
pub(crate) fn keep_closer(best_t: &mut f32, best: &mut Hit, h: TriangleHit, i: u32) {
    if h.t < *best_t || i < best.tri {
        *best_t = h.t;
        *best = Hit {
            t: h.t,
            tri: i,
            u: h.u,
            v: h.v,
        };
    }
}
