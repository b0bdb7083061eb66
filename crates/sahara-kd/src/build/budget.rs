//! A cap on triangle references, shared by all subtrees of a build.
//!
//! Split clipping duplicates the references of straddling triangles. On
//! ordinary meshes the SAH keeps that near 1.5-5x, but pathological inputs
//! (many long triangles crossing each other) could double the references at
//! every level until the depth cap. Each split reserves the references it
//! adds; a split that would pass the cap becomes a leaf instead.

use std::sync::atomic::{AtomicUsize, Ordering};

/// References in use and the most allowed.
pub struct RefBudget {
    used: AtomicUsize,
    limit: usize,
}

impl RefBudget {
    /// A budget of `limit` references, `used` of them taken by the root.
    pub fn new(used: usize, limit: usize) -> Self {
        Self {
            used: AtomicUsize::new(used),
            limit,
        }
    }

    /// Take `extra` more references; false, taking nothing, if that would
    /// pass the limit.
    pub fn try_take(&self, extra: usize) -> bool {
        self.used
            .fetch_update(Ordering::Relaxed, Ordering::Relaxed, |u| {
                u.checked_add(extra).filter(|&t| t <= self.limit)
            })
            .is_ok()
    }

    /// Give back `n` references taken before.
    pub fn give_back(&self, n: usize) {
        self.used.fetch_sub(n, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn budget_refuses_past_its_limit() {
        let b = RefBudget::new(10, 15);
        assert!(b.try_take(5));
        assert!(!b.try_take(1));
        b.give_back(2);
        assert!(b.try_take(2));
        assert!(!b.try_take(1));
    }
}
