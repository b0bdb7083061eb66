//! What a benchmark reports, as plain structs whose serde form is the JSON
//! layout of `sahara bench --json` and `sahara stats --json`.

use sahara_kd::{AccelSummary, BvhStats, TreeStats};
use serde::Serialize;

use crate::protocol::{ProtocolCamera, SetKind};
use crate::runner::CountTotals;

/// The result of `sahara bench`: the tree, then one entry per traced set.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct BenchReport {
    /// The mesh (its path, or a name for a built-in mesh).
    pub mesh: String,
    /// Triangles in the mesh.
    pub triangles: usize,
    /// Builder name (`sah`, `binned`, ...).
    pub builder: String,
    /// Best build time of [`crate::runner::BUILD_RUNS`], milliseconds.
    pub build_ms: f64,
    /// Bytes of nodes, index array and triangles.
    pub memory_bytes: usize,
    /// The tree's SAH cost.
    pub sah_cost: f64,
    /// Threads of the all-thread runs.
    pub threads: usize,
    /// Timed runs per set and thread count (after one warm-up).
    pub runs: usize,
    /// Depth of the deepest leaf.
    pub tree_depth: u32,
    /// Leaves, empty ones included.
    pub leaves: usize,
    /// The camera of the generated sets (absent when tracing a ray file).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub camera: Option<CameraReport>,
    /// The sets traced.
    pub sets: SetReports,
}

/// The camera used and where it came from.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct CameraReport {
    /// `auto`, or the sidecar file it was read from.
    pub source: String,
    /// Eye point.
    pub eye: [f32; 3],
    /// Target point.
    pub target: [f32; 3],
    /// Up vector.
    pub up: [f32; 3],
    /// Vertical field of view, degrees.
    pub vfov_deg: f32,
}

impl CameraReport {
    /// The report of `camera` read from `source`.
    pub fn new(camera: &ProtocolCamera, source: impl Into<String>) -> Self {
        Self {
            source: source.into(),
            eye: camera.eye.to_array(),
            target: camera.target.to_array(),
            up: camera.up.to_array(),
            vfov_deg: camera.vfov_deg,
        }
    }
}

/// One optional entry per set, in the protocol's order; `file` is a ray file
/// traced instead of the generated sets.
#[derive(Clone, Debug, Default, Serialize, PartialEq)]
pub struct SetReports {
    /// The `primary` set.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub primary: Option<SetReport>,
    /// The `shadow` set (hits = occluded rays, t-sum 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shadow: Option<SetReport>,
    /// The `diffuse` set.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub diffuse: Option<SetReport>,
    /// The `random` set.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub random: Option<SetReport>,
    /// Rays read from a file (`sahara bench --rays FILE`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file: Option<SetReport>,
}

impl SetReports {
    /// The slot of a protocol set.
    pub fn slot(&mut self, kind: SetKind) -> &mut Option<SetReport> {
        match kind {
            SetKind::Primary => &mut self.primary,
            SetKind::Shadow => &mut self.shadow,
            SetKind::Diffuse => &mut self.diffuse,
            SetKind::Random => &mut self.random,
        }
    }

    /// The filled entries with their names, in order.
    pub fn entries(&self) -> Vec<(&'static str, &SetReport)> {
        [
            ("primary", &self.primary),
            ("shadow", &self.shadow),
            ("diffuse", &self.diffuse),
            ("random", &self.random),
            ("file", &self.file),
        ]
        .into_iter()
        .filter_map(|(n, s)| s.as_ref().map(|s| (n, s)))
        .collect()
    }
}

/// Results and speed of one set.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SetReport {
    /// Rays in the set.
    pub rays: usize,
    /// Rays that hit something (for `shadow`: occluded rays).
    pub hits: u64,
    /// Sum of the hit distances as f64, in ray order (0 for any-hit sets).
    pub t_sum: f64,
    /// Best Mrays/s on one thread.
    pub mrays_1t: f64,
    /// Best Mrays/s on one thread by the tracing thread's CPU time.
    pub mrays_1t_cpu: f64,
    /// Best Mrays/s on all threads.
    pub mrays_all: f64,
    /// Best Mrays/s on one thread of the batch query over the whole set
    /// (`KdTree::closest_hits` / `KdTree::any_hits`), checked hit for hit
    /// against single rays.
    pub mrays_batch_1t: f64,
    /// The same by the tracing thread's CPU time.
    pub mrays_batch_1t_cpu: f64,
    /// `primary` only: best Mrays/s on one thread of the packet path (8 rays
    /// per packet, 4x2 pixel tiles).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mrays_packet_1t: Option<f64>,
    /// The same by the tracing thread's CPU time.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mrays_packet_1t_cpu: Option<f64>,
    /// `primary` only: best Mrays/s on one thread of the 16-ray packet
    /// path (4x4 pixel tiles).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mrays_packet16_1t: Option<f64>,
    /// The same by the tracing thread's CPU time.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mrays_packet16_1t_cpu: Option<f64>,
    /// Traversal work, with `--counters`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub counters: Option<CounterReport>,
}

/// Mean traversal work per ray next to the SAH's prediction.
///
/// The means are over all rays of the set; a ray that misses the root cell
/// does no work, so the means per ray meeting the root (what the
/// `expected_*` figures predict, for a traversal without early exit) are
/// these divided by `root_fraction`.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct CounterReport {
    /// Fraction of the rays whose interval meets the root cell.
    pub root_fraction: f64,
    /// Inner nodes visited per ray.
    pub mean_inner: f64,
    /// Leaves visited per ray.
    pub mean_leaves: f64,
    /// Ray/triangle tests per ray.
    pub mean_triangles: f64,
    /// [`AccelSummary::expected_inner`].
    pub expected_inner: f64,
    /// [`AccelSummary::expected_leaves`].
    pub expected_leaves: f64,
    /// [`AccelSummary::expected_triangles`].
    pub expected_triangles: f64,
}

impl CounterReport {
    /// The report of `totals` on a tree with statistics `stats`.
    pub fn new(totals: &CountTotals, stats: &AccelSummary) -> Self {
        let n = totals.rays.max(1) as f64;
        Self {
            root_fraction: totals.rays_meeting_root as f64 / n,
            mean_inner: totals.work.inner as f64 / n,
            mean_leaves: totals.work.leaves as f64 / n,
            mean_triangles: totals.work.triangles as f64 / n,
            expected_inner: stats.expected_inner,
            expected_leaves: stats.expected_leaves,
            expected_triangles: stats.expected_triangles,
        }
    }

    /// `(inner, leaves, triangles)` per ray that meets the root.
    pub fn per_root_ray(&self) -> (f64, f64, f64) {
        let f = if self.root_fraction > 0.0 {
            self.root_fraction
        } else {
            1.0
        };
        (
            self.mean_inner / f,
            self.mean_leaves / f,
            self.mean_triangles / f,
        )
    }
}

/// A structure's own statistics.
#[derive(Clone, Debug, Serialize, PartialEq)]
#[serde(untagged)]
pub enum StructureStats {
    /// A kd-tree's.
    Kd(TreeStats),
    /// An eight-wide hierarchy's.
    Bvh(BvhStats),
}

/// The result of `sahara stats`: build time and every field of the
/// structure's statistics, and with `--all` every structure side by side.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct StatsReport {
    /// The mesh.
    pub mesh: String,
    /// `kd` or `bvh`.
    pub accel: String,
    /// Builder name.
    pub builder: String,
    /// Best build time, milliseconds.
    pub build_ms: f64,
    /// Builds timed.
    pub build_runs: usize,
    /// Of the triangles given to the build, those no ray can hit (a
    /// non-finite corner or zero area), which the structure leaves out.
    pub skipped_triangles: usize,
    /// The structure's statistics.
    #[serde(flatten)]
    pub tree: StructureStats,
    /// With `--all`: every structure and builder, built the same way.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub structures: Vec<StructureRow>,
}

/// One structure of `sahara stats --all`.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct StructureRow {
    /// As `kd-tree (sah)` or `bvh8 (spatial)`.
    pub structure: String,
    /// Best build time, milliseconds.
    pub build_ms: f64,
    /// The structure's summary: memory, references, the SAH's expected
    /// work per ray.
    #[serde(flatten)]
    pub summary: AccelSummaryReport,
}

/// [`AccelSummary`] as reported.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct AccelSummaryReport {
    /// Triangles given to the build.
    pub triangles: usize,
    /// Bytes of nodes, leaf data and indices.
    pub memory_bytes: usize,
    /// Triangle references in leaves.
    pub references: usize,
    /// The SAH cost in the structure's own units.
    pub sah_cost: f64,
    /// Inner nodes (wide nodes for the hierarchy) a ray meeting the root
    /// visits by the SAH.
    pub expected_inner: f64,
    /// Leaves it visits.
    pub expected_leaves: f64,
    /// Triangle tests it makes.
    pub expected_triangles: f64,
}

impl From<&AccelSummary> for AccelSummaryReport {
    fn from(s: &AccelSummary) -> Self {
        Self {
            triangles: s.triangles,
            memory_bytes: s.memory_bytes,
            references: s.references,
            sah_cost: s.sah_cost,
            expected_inner: s.expected_inner,
            expected_leaves: s.expected_leaves,
            expected_triangles: s.expected_triangles,
        }
    }
}
