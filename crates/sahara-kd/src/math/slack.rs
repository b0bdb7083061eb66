//! The float slack of the traversal's and the cull's distance comparisons,
//! and the rounding bounds they rest on (see `docs/accelerator.md`).

/// Relative slack on the traversal's distance comparisons.
///
/// Cell distances and triangle distances are rounded separately, so a
/// triangle in the next cell may report a `t` a few ulps below the boundary
/// it lies behind. Skipping a cell or a child only when it is farther than
/// this margin keeps the result bit-identical to testing every triangle
/// (what the brute-force oracle does); the price is an occasional extra leaf
/// visit at a boundary. 2^-12 is ~500 ulps: far above the rounding of the
/// watertight test on the test suite's scales, far below any cell size.
pub const MARGIN: f32 = 1.0 / 4096.0;

/// The factor `1 + 2 gamma(3)` by which [`Aabb::intersect_ray`] enlarges
/// the far distance.
pub const FAR_GROW: f32 = 1.0 + 2.0 * gamma(3);

/// pbrt's `gamma(n) = n u / (1 - n u)` bound on the relative error of `n`
/// rounded f32 operations (u = machine epsilon / 2).
pub const fn gamma(n: u32) -> f32 {
    let u = f32::EPSILON * 0.5;
    (n as f32 * u) / (1.0 - n as f32 * u)
}
