//! Throughput of a ray set: Mrays/s of wall clock, best of N runs after one
//! warm-up, on one thread and on all threads.

use std::time::Instant;

use sahara_kd::{Ray, TriangleAccel};

use super::pools::Pools;
use super::trace::{trace_into, BatchAnswers, Query};
use crate::record::{checksum, HitRecord};

/// The results and speed of one set.
#[derive(Clone, Debug)]
pub struct Measurement {
    /// One record per ray, in ray order (from the 1-thread runs).
    pub records: Vec<HitRecord>,
    /// Rays that hit (or are occluded).
    pub hits: u64,
    /// Sum of hit distances, f64, in ray order.
    pub t_sum: f64,
    /// Best Mrays/s on one thread.
    pub mrays_1t: f64,
    /// Best Mrays/s on one thread by the tracing thread's CPU time: less
    /// sensitive than wall clock to other load on a shared machine.
    pub mrays_1t_cpu: f64,
    /// Best Mrays/s on all threads.
    pub mrays_all: f64,
    /// True if the all-thread runs gave the same records as the 1-thread runs.
    pub threads_agree: bool,
    /// Best Mrays/s on one thread of the batch query (`closest_hits` or
    /// `any_hits` over the whole set).
    pub mrays_batch_1t: f64,
    /// The same by the tracing thread's CPU time.
    pub mrays_batch_1t_cpu: f64,
    /// True if the batch query gave the same records as single rays.
    pub batch_agrees: bool,
}

/// Million rays per second for `rays` rays in `secs` seconds (0 for no rays).
pub fn mrays_per_sec(rays: usize, secs: f64) -> f64 {
    if rays == 0 || secs <= 0.0 {
        0.0
    } else {
        rays as f64 / secs * 1e-6
    }
}

/// CPU time consumed by the calling thread, in seconds.
pub fn thread_cpu_seconds() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the clock id is a constant
    // every Linux kernel since 2.6.12 supports.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        return f64::NAN;
    }
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// Best Mrays/s of `runs` calls of `trace` on `pool`: by wall clock, and
/// by the CPU time of the thread that ran it (meaningful for a one-thread
/// pool, where that thread traced every ray).
fn best_of(
    mut trace: impl FnMut() + Send,
    rays: usize,
    pool: &rayon::ThreadPool,
    runs: usize,
) -> (f64, f64) {
    let mut best = f64::INFINITY;
    let mut best_cpu = f64::INFINITY;
    for _ in 0..runs.max(1) {
        let t0 = Instant::now();
        let cpu = pool.install(|| {
            let c0 = thread_cpu_seconds();
            trace();
            thread_cpu_seconds() - c0
        });
        best = best.min(t0.elapsed().as_secs_f64());
        best_cpu = best_cpu.min(cpu);
    }
    (mrays_per_sec(rays, best), mrays_per_sec(rays, best_cpu))
}

/// Trace `rays` once on one thread as a warm-up, then `runs` times on one
/// thread and `runs` times on all threads, timing each run.
pub fn measure(
    tree: &TriangleAccel,
    rays: &[Ray],
    query: Query,
    pools: &Pools,
    runs: usize,
) -> Measurement {
    let mut records = vec![HitRecord::MISS; rays.len()];
    pools
        .one
        .install(|| trace_into(tree, rays, query, &mut records));
    let (mrays_1t, mrays_1t_cpu) = best_of(
        || trace_into(tree, rays, query, &mut records),
        rays.len(),
        &pools.one,
        runs,
    );
    let mut records_all = vec![HitRecord::MISS; rays.len()];
    let (mrays_all, _) = best_of(
        || trace_into(tree, rays, query, &mut records_all),
        rays.len(),
        &pools.all,
        runs,
    );
    let same = |a: &HitRecord, b: &HitRecord| a.tri == b.tri && a.t.to_bits() == b.t.to_bits();
    let threads_agree = records.iter().zip(&records_all).all(|(a, b)| same(a, b));
    // The batch's output buffers are made by the warm-up call, outside the
    // timing, as a renderer keeps its buffers between calls.
    let mut answers = BatchAnswers::default();
    pools.one.install(|| answers.trace(tree, rays, query));
    let (mrays_batch_1t, mrays_batch_1t_cpu) = best_of(
        || answers.trace(tree, rays, query),
        rays.len(),
        &pools.one,
        runs,
    );
    let mut records_batch = vec![HitRecord::MISS; rays.len()];
    answers.records(query, &mut records_batch);
    let batch_agrees = records.iter().zip(&records_batch).all(|(a, b)| same(a, b));
    let (hits, t_sum) = checksum(&records);
    Measurement {
        mrays_batch_1t,
        mrays_batch_1t_cpu,
        batch_agrees,
        records,
        hits,
        t_sum,
        mrays_1t,
        mrays_1t_cpu,
        mrays_all,
        threads_agree,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use sahara_kd::{AccelParams, Triangle};

    #[test]
    fn measure_counts_hits_and_sums_t() {
        let tree = TriangleAccel::build(
            vec![Triangle::new(
                Vec3::new(-1.0, -1.0, 3.0),
                Vec3::new(1.0, -1.0, 3.0),
                Vec3::new(0.0, 1.0, 3.0),
            )],
            &AccelParams::default(),
        );
        let rays: Vec<Ray> = (0..10_000)
            .map(|i| {
                Ray::new(
                    Vec3::new(if i % 4 == 0 { 0.0 } else { 9.0 }, -0.5, 0.0),
                    Vec3::Z,
                )
            })
            .collect();
        let pools = Pools::new(2).unwrap();
        let m = measure(&tree, &rays, Query::ClosestHit, &pools, 2);
        assert_eq!(m.hits, 2500);
        assert_eq!(m.t_sum, 2500.0 * 3.0);
        assert!(m.threads_agree && m.batch_agrees);
        assert!(m.mrays_batch_1t > 0.0 && m.mrays_batch_1t_cpu > 0.0);
        assert!(m.mrays_1t > 0.0 && m.mrays_all > 0.0);
        let m = measure(&tree, &rays, Query::AnyHit, &pools, 1);
        assert_eq!((m.hits, m.t_sum), (2500, 0.0));
        assert_eq!(mrays_per_sec(0, 1.0), 0.0);
        assert_eq!(mrays_per_sec(2_000_000, 0.5), 4.0);
    }
}
