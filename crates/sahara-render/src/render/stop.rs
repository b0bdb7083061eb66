//! When a render stops before its last pass.

use std::sync::atomic::Ordering;
use std::time::Instant;

use super::settings::RenderSettings;

/// When a render stops early: on cancel, and (after the first pass) at
/// the time limit.
pub(super) struct Stop<'a> {
    pub(super) settings: &'a RenderSettings,
    /// When the render began; the time limit counts from it.
    pub(super) start: Instant,
}

impl Stop<'_> {
    /// True once the caller has asked the render to stop.
    pub(super) fn cancelled(&self) -> bool {
        self.settings
            .cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    }

    /// True once the time limit has run out.
    pub(super) fn out_of_time(&self) -> bool {
        self.settings
            .time_limit
            .is_some_and(|t| self.start.elapsed() >= t)
    }
}
