//! Timing the structure's build.

use std::time::Instant;

use rayon::ThreadPool;
use sahara_kd::Triangle;

/// Builds timed by the protocol (the best of them is reported).
pub const BUILD_RUNS: usize = 3;

/// Build with `build` `runs` times (at least once) on `pool`, each from a
/// fresh copy of `triangles` (the copy is not timed); returns the last
/// structure and the best build time in milliseconds.
pub fn build_timed<T: Send>(
    triangles: &[Triangle],
    runs: usize,
    pool: &ThreadPool,
    build: impl Fn(Vec<Triangle>) -> T + Sync,
) -> (T, f64) {
    let once = || {
        let tris = triangles.to_vec();
        let t0 = Instant::now();
        let tree = pool.install(|| build(tris));
        (tree, t0.elapsed().as_secs_f64() * 1e3)
    };
    let (mut tree, mut best) = once();
    for _ in 1..runs {
        let (t, ms) = once();
        best = best.min(ms);
        tree = t;
    }
    (tree, best)
}
