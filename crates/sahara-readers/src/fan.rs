//! Fan triangulation, the one polygon split the mesh formats use (OBJ and
//! PLY here, pbrt shapes in `sahara-formats`).
//!
//! A polygon `v0 v1 ... vn-1` becomes `(v0, v1, v2), (v0, v2, v3), ...,
//! (v0, vn-2, vn-1)`, in that order; the benchmark protocol numbers triangles
//! by this order.

/// Appends the fan `(v0, vi, vi+1)` of `polygon`; fewer than three corners give nothing.
pub fn fan_triangulate(polygon: &[u32], out: &mut Vec<[u32; 3]>) {
    if let Some((&first, rest)) = polygon.split_first() {
        out.extend(rest.windows(2).map(|w| [first, w[0], w[1]]));
    }
}
