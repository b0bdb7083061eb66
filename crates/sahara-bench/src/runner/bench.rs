//! A benchmark: one built tree, its pools, and set measurements.

use rayon::ThreadPoolBuildError;
use sahara_kd::Mesh;
use sahara_kd::{AccelParams, AccelSummary, Ray, TriangleAccel};

use super::build::{build_timed, BUILD_RUNS};
use super::counters::count_set;
use super::pools::Pools;
use super::throughput::{measure, Measurement};
use super::trace::{trace_into, Query};
use crate::record::HitRecord;
use crate::report::{BenchReport, CameraReport, CounterReport, SetReport, SetReports};

/// A tree built for benchmarking, with the pools that trace on it.
pub struct Bench {
    tree: TriangleAccel,
    stats: AccelSummary,
    build_ms: f64,
    pools: Pools,
    runs: usize,
}

impl Bench {
    /// Build the tree over `mesh` [`BUILD_RUNS`] times on `threads` threads
    /// (keeping the best time); sets will be timed `runs` times each.
    ///
    /// The mesh's indices must be in range (see
    /// [`crate::protocol::frame::check_mesh`]).
    pub fn new(
        mesh: &Mesh,
        params: &AccelParams,
        threads: usize,
        runs: usize,
    ) -> Result<Self, ThreadPoolBuildError> {
        let pools = Pools::new(threads)?;
        let (tree, build_ms) = build_timed(&mesh.triangles(), BUILD_RUNS, &pools.all, |t| {
            TriangleAccel::build(t, params)
        });
        let stats = tree.summary();
        Ok(Self {
            tree,
            stats,
            build_ms,
            pools,
            runs: runs.max(1),
        })
    }

    /// The tree.
    pub fn tree(&self) -> &TriangleAccel {
        &self.tree
    }

    /// The tree's statistics.
    pub fn stats(&self) -> &AccelSummary {
        &self.stats
    }

    /// Best build time, milliseconds.
    pub fn build_ms(&self) -> f64 {
        self.build_ms
    }

    /// Threads of the all-thread runs.
    pub fn threads(&self) -> usize {
        self.pools.threads
    }

    /// Timed runs per set and thread count.
    pub fn runs(&self) -> usize {
        self.runs
    }

    /// Trace `rays` once, untimed, on all threads.
    pub fn trace(&self, rays: &[Ray], query: Query) -> Vec<HitRecord> {
        let mut out = vec![HitRecord::MISS; rays.len()];
        self.pools
            .all
            .install(|| trace_into(&self.tree, rays, query, &mut out));
        out
    }

    /// Measure a set (warm-up, then timed runs on 1 and all threads), with
    /// traversal counters if asked.
    pub fn measure(&self, rays: &[Ray], query: Query, counters: bool) -> (SetReport, Measurement) {
        let m = measure(&self.tree, rays, query, &self.pools, self.runs);
        let counters = counters.then(|| {
            let totals = self
                .pools
                .all
                .install(|| count_set(&self.tree, rays, query));
            CounterReport::new(&totals, &self.stats)
        });
        let report = SetReport {
            rays: rays.len(),
            hits: m.hits,
            t_sum: m.t_sum,
            mrays_1t: m.mrays_1t,
            mrays_1t_cpu: m.mrays_1t_cpu,
            mrays_all: m.mrays_all,
            mrays_batch_1t: m.mrays_batch_1t,
            mrays_batch_1t_cpu: m.mrays_batch_1t_cpu,
            mrays_packet_1t: None,
            mrays_packet_1t_cpu: None,
            mrays_packet16_1t: None,
            mrays_packet16_1t_cpu: None,
            counters,
        };
        (report, m)
    }

    /// Time the packet path of `size` on one thread over the row-major
    /// rays of `image` (checked against `reference`, the single-ray
    /// records).
    pub fn measure_packets(
        &self,
        rays: &[Ray],
        image: crate::protocol::camera::ImageSize,
        reference: &[HitRecord],
        size: super::PacketSize,
    ) -> super::PacketMeasurement {
        self.pools
            .one
            .install(|| super::measure_packets(&self.tree, rays, image, self.runs, reference, size))
    }

    /// The full report, from the mesh's name, the camera and the sets.
    pub fn report(
        &self,
        mesh: &str,
        camera: Option<CameraReport>,
        sets: SetReports,
    ) -> BenchReport {
        BenchReport {
            mesh: mesh.to_owned(),
            triangles: self.stats.triangles,
            builder: self.stats.structure.clone(),
            build_ms: self.build_ms,
            memory_bytes: self.stats.memory_bytes,
            sah_cost: self.stats.sah_cost,
            threads: self.pools.threads,
            runs: self.runs,
            tree_depth: self.stats.depth,
            leaves: self.stats.leaves,
            camera,
            sets,
        }
    }
}
