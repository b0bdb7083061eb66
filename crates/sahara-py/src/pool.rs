//! Sahara's thread pools: the machine's (rayon's global pool) or one of a
//! given size, made once per size and kept.

use std::sync::{Arc, Mutex};

use pyo3::exceptions::PyRuntimeError;
use pyo3::PyResult;
use rayon::ThreadPool;

/// Pools made so far, by thread count.
static POOLS: Mutex<Vec<(usize, Arc<ThreadPool>)>> = Mutex::new(Vec::new());

/// The pool of `threads` threads (made now if it is the first call with
/// that count).
pub(crate) fn pool(threads: usize) -> PyResult<Arc<ThreadPool>> {
    let mut pools = POOLS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, p)) = pools.iter().find(|(n, _)| *n == threads) {
        return Ok(p.clone());
    }
    let p = Arc::new(
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("sahara-{i}"))
            .build()
            .map_err(|e| PyRuntimeError::new_err(format!("cannot start {threads} threads: {e}")))?,
    );
    pools.push((threads, p.clone()));
    Ok(p)
}

/// Runs `f` on `threads` threads (None or 0: all of the machine's): its
/// rayon work goes to that pool.
pub(crate) fn run_on<R: Send>(threads: Option<usize>, f: impl FnOnce() -> R + Send) -> PyResult<R> {
    match threads.filter(|&t| t > 0) {
        None => Ok(f()),
        Some(t) => Ok(pool(t)?.install(f)),
    }
}
