//! Timing the tree build.

use std::time::Instant;

use rayon::ThreadPool;
use sahara_kd::{BuildParams, KdTree, Triangle};

/// Builds timed by the protocol (the best of them is reported).
pub const BUILD_RUNS: usize = 3;

/// Build the tree `runs` times (at least once) on `pool`, each from a fresh
/// copy of `triangles` (the copy is not timed); returns the last tree and the
/// best build time in milliseconds.
pub fn build_timed(
    triangles: &[Triangle],
    params: &BuildParams,
    runs: usize,
    pool: &ThreadPool,
) -> (KdTree, f64) {
    let build = || {
        let tris = triangles.to_vec();
        let t0 = Instant::now();
        let tree = pool.install(|| KdTree::build(tris, params));
        (tree, t0.elapsed().as_secs_f64() * 1e3)
    };
    let (mut tree, mut best) = build();
    for _ in 1..runs {
        let (t, ms) = build();
        best = best.min(ms);
        tree = t;
    }
    (tree, best)
}
