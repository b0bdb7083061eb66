//! Build parameters shared by every builder.

/// Which algorithm builds the tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Builder {
    /// Exact SAH by sorted event sweep, O(N log N), with split clipping
    /// (Wald & Havran 2006).
    Sah,
    /// SAH evaluated at the boundaries of `bins` equal bins per axis.
    Binned {
        /// Bins per axis (16 is the lecture's "often enough").
        bins: u32,
    },
    /// The "intuitive" baselines: a fixed axis rule and position rule,
    /// stopping at `max_leaf_size` or `max_depth`.
    Naive {
        /// How the split axis is chosen.
        axis: AxisRule,
        /// Where the split plane goes.
        position: PositionRule,
    },
}

/// Split-axis rule of the naive builders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AxisRule {
    /// x, y, z, x, ... by depth.
    RoundRobin,
    /// The cell's longest axis.
    LargestExtent,
}

/// Split-position rule of the naive builders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PositionRule {
    /// The middle of the cell.
    Middle,
    /// The median of the triangles' (clipped) bounding-box centres.
    Median,
}

impl Builder {
    /// Every builder, for comparisons and tests.
    pub const ALL: [Builder; 6] = [
        Builder::Sah,
        Builder::Binned { bins: 16 },
        Builder::Naive {
            axis: AxisRule::RoundRobin,
            position: PositionRule::Middle,
        },
        Builder::Naive {
            axis: AxisRule::RoundRobin,
            position: PositionRule::Median,
        },
        Builder::Naive {
            axis: AxisRule::LargestExtent,
            position: PositionRule::Middle,
        },
        Builder::Naive {
            axis: AxisRule::LargestExtent,
            position: PositionRule::Median,
        },
    ];

    /// A short name (`sah`, `binned`, `rr-middle`, ...).
    pub fn name(&self) -> String {
        match self {
            Builder::Sah => "sah".into(),
            Builder::Binned { bins: 16 } => "binned".into(),
            Builder::Binned { bins } => format!("binned{bins}"),
            Builder::Naive { axis, position } => {
                let a = match axis {
                    AxisRule::RoundRobin => "rr",
                    AxisRule::LargestExtent => "largest",
                };
                let p = match position {
                    PositionRule::Middle => "middle",
                    PositionRule::Median => "median",
                };
                format!("{a}-{p}")
            }
        }
    }

    /// Parse a name given by [`Builder::name`]; `median` and `middle` alone
    /// mean the largest-extent variants, `binnedN` sets the bin count.
    pub fn parse(s: &str) -> Option<Builder> {
        let naive = |axis, position| Some(Builder::Naive { axis, position });
        match s {
            "sah" => Some(Builder::Sah),
            "binned" => Some(Builder::Binned { bins: 16 }),
            "rr-middle" => naive(AxisRule::RoundRobin, PositionRule::Middle),
            "rr-median" => naive(AxisRule::RoundRobin, PositionRule::Median),
            "largest-middle" | "middle" => naive(AxisRule::LargestExtent, PositionRule::Middle),
            "largest-median" | "median" => naive(AxisRule::LargestExtent, PositionRule::Median),
            _ => {
                let bins: u32 = s.strip_prefix("binned")?.parse().ok()?;
                (2..=1024)
                    .contains(&bins)
                    .then_some(Builder::Binned { bins })
            }
        }
    }
}

/// Parameters of a build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildParams {
    /// The algorithm.
    pub builder: Builder,
    /// Cost of one traversal step, K_T, relative to `intersection_cost`.
    pub traversal_cost: f32,
    /// Cost of one ray/triangle test, K_I.
    pub intersection_cost: f32,
    /// Fraction of the split cost forgiven when one side is empty
    /// (cutting off empty space; Wald & Havran's lambda = 1 - bonus).
    pub empty_bonus: f32,
    /// Depth cap; `None` means `8 + 1.3 log2 N` (pbrt-v3's rule).
    pub max_depth: Option<u32>,
    /// Naive builders make a leaf at this many triangles; the SAH builders
    /// make one at or below it without evaluating splits.
    pub max_leaf_size: u32,
    /// Build subtrees in parallel on rayon's pool.
    pub parallel: bool,
    /// Most triangle references the tree may hold, as a multiple of the
    /// triangle count (split clipping duplicates straddlers). A split that
    /// would pass it becomes a leaf, so no input can make the build's memory
    /// explode. When the cap is reached in a parallel build, which subtree
    /// meets it first may vary from run to run.
    pub max_duplication: f32,
    /// Primitives a leaf tests at once: the SAH prices a leaf of `n` at
    /// `K_I ceil(n / leaf_width)` (triangle trees test eight, the leaf block width
    /// = 8 at a time, so a leaf of 8 costs one test); 1 is the classic model.
    pub leaf_width: u32,
    /// Extra cost of each triangle in a leaf, in leaf tests: the SAH prices
    /// a leaf of `n` at `K_I (ceil(n / leaf_width) + lane_cost n)`. It stands
    /// for the work a block test does per triangle that the block does not
    /// amortise (reading 36 bytes, and the exact scalar test of each
    /// triangle the ray's line passes through). Default 0: larger values
    /// made smaller leaves, padded to blocks of eight, that cost memory and
    /// speed on the shared meshes (figures in `docs/performance.md`).
    pub lane_cost: f32,
    /// The binned builder hands a cell of at most this many references to
    /// the exact sweep (0: bins all the way down). Binning the few large
    /// cells near the root and sweeping the many small ones below
    /// (Wald & Havran 2006 section 6 suggest the same split of work) keeps
    /// most of the binned build's speed at the exact build's quality.
    pub exact_below: u32,
    /// Store each leaf block's distinct vertices once instead of every
    /// lane's vertices: about two thirds of a triangle tree's memory,
    /// tracing some 3-13% slower (figures in `docs/performance.md`).
    /// Default false.
    pub compact_leaves: bool,
    /// Derive wide nodes (three binary levels in one 64-byte node, walked
    /// with SIMD) for the batches of incoherent rays; single rays, packets
    /// and coherent batches walk the binary nodes, which stay the
    /// reference form. The wide nodes make a tree some 8-10% larger
    /// (figures in `docs/accelerator.md`). Default true.
    pub wide_nodes: bool,
}

impl Default for BuildParams {
    fn default() -> Self {
        Self::new(Builder::Sah)
    }
}

/// Depth bound of every built tree (and of the walks' stacks).
pub const MAX_DEPTH: usize = 64;

/// The binned builder's default [`BuildParams::exact_below`]: 2^16, the
/// smallest threshold that kept the dragon's tree at the exact build's
/// SAH cost and tracing speed while building faster (the measurements are
/// in `docs/performance.md`).
pub const EXACT_BELOW: u32 = 1 << 16;

impl BuildParams {
    /// Default parameters for a builder.
    ///
    /// K_T = 15 and an empty bonus of 0.2 are Wald & Havran's (2006,
    /// section 5) values. Their K_I = 20 prices one scalar triangle test;
    /// here K_I prices one eight-wide block test (`leaf_width`) and is 40,
    /// the fastest of 20, 30 and 40 on the shared meshes but the dragon
    /// (figures in `docs/performance.md`).
    pub fn new(builder: Builder) -> Self {
        let max_leaf_size = match builder {
            Builder::Naive { .. } => 4,
            _ => 1,
        };
        Self {
            builder,
            traversal_cost: 15.0,
            intersection_cost: 40.0,
            empty_bonus: 0.2,
            max_depth: None,
            max_leaf_size,
            parallel: true,
            max_duplication: 64.0,
            leaf_width: crate::simd::lanes::WIDTH as u32,
            lane_cost: 0.0,
            exact_below: match builder {
                Builder::Binned { .. } => EXACT_BELOW,
                _ => 0,
            },
            compact_leaves: false,
            wide_nodes: true,
        }
    }

    /// Tests the SAH charges for a leaf of `n` primitives:
    /// `ceil(n / leaf_width)`.
    #[inline(always)]
    pub fn leaf_tests(&self, n: usize) -> f64 {
        leaf_tests(n, self.leaf_width, self.lane_cost)
    }

    /// The reference budget for `n` triangles.
    pub fn reference_budget(&self, n: usize) -> super::budget::RefBudget {
        let limit = (n as f64 * self.max_duplication.max(1.0) as f64) as usize;
        super::budget::RefBudget::new(n, limit.max(n))
    }

    /// The depth cap for `n` triangles, clamped to the traversal stack.
    pub fn depth_limit(&self, n: usize) -> u32 {
        let d = self
            .max_depth
            .unwrap_or_else(|| (8.0 + 1.3 * (n.max(1) as f64).log2()).round() as u32);
        d.min(MAX_DEPTH as u32 - 1)
    }
}

/// `ceil(n / width) + lane_cost n` as f64 (a width of 0 counts as 1).
#[inline(always)]
pub fn leaf_tests(n: usize, width: u32, lane_cost: f32) -> f64 {
    n.div_ceil(width.max(1) as usize) as f64 + lane_cost as f64 * n as f64
}
