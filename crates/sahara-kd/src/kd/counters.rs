//! Counting the work of a walk: inner nodes, leaves and triangle tests.

/// Per-ray work counters for `sahara bench --counters`.
pub trait Counters {
    /// An inner node was visited.
    fn inner(&mut self);
    /// A leaf was visited.
    fn leaf(&mut self);
    /// A ray/triangle test was made.
    fn triangle(&mut self);
}

/// Counting nothing: the production traversal compiles to no counter code.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoCounters;

impl Counters for NoCounters {
    #[inline(always)]
    fn inner(&mut self) {}
    #[inline(always)]
    fn leaf(&mut self) {}
    #[inline(always)]
    fn triangle(&mut self) {}
}

/// Totals of traversal work over many rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalCounters {
    /// Inner nodes visited.
    pub inner: u64,
    /// Leaves visited (empty ones included).
    pub leaves: u64,
    /// Ray/triangle tests.
    pub triangles: u64,
}

impl Counters for TraversalCounters {
    fn inner(&mut self) {
        self.inner += 1;
    }
    fn leaf(&mut self) {
        self.leaves += 1;
    }
    fn triangle(&mut self) {
        self.triangles += 1;
    }
}

impl std::ops::AddAssign for TraversalCounters {
    fn add_assign(&mut self, o: Self) {
        self.inner += o.inner;
        self.leaves += o.leaves;
        self.triangles += o.triangles;
    }
}
