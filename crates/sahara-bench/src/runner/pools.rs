//! The two thread pools a benchmark runs on: one thread, and all threads.

use rayon::{ThreadPool, ThreadPoolBuildError, ThreadPoolBuilder};

/// A dedicated 1-thread pool and a dedicated N-thread pool.
pub struct Pools {
    /// The 1-thread pool.
    pub one: ThreadPool,
    /// The N-thread pool.
    pub all: ThreadPool,
    /// N.
    pub threads: usize,
}

impl Pools {
    /// Pools of 1 and `threads` threads (at least 1).
    pub fn new(threads: usize) -> Result<Self, ThreadPoolBuildError> {
        let threads = threads.max(1);
        Ok(Self {
            one: ThreadPoolBuilder::new()
                .num_threads(1)
                .thread_name(|_| "bench-1t".into())
                .build()?,
            all: ThreadPoolBuilder::new()
                .num_threads(threads)
                .thread_name(|i| format!("bench-{i}"))
                .build()?,
            threads,
        })
    }

    /// The number of hardware threads, the default N.
    pub fn available_threads() -> usize {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    }
}
