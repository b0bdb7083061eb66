//! Where a batch's time goes: to the batched ray queries (tracing) or to
//! the work between them (shading), a clock read a few times per round of
//! the whole batch rather than per ray.

use std::time::{Duration, Instant};

/// What a stretch of a round's time went to.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Lap {
    /// Finding hits and answering shadow rays.
    Tracing,
    /// Everything between the queries: the vertices' shading, sampling,
    /// the strategies' weights.
    Shading,
}

/// Time spent tracing and shading since the last [`Laps::take`].
#[derive(Debug, Default)]
pub(crate) struct Laps {
    tracing: Duration,
    shading: Duration,
}

impl Laps {
    /// Adds the time since `clock` to `what`; the clock for the next lap.
    pub fn lap(&mut self, clock: Instant, what: Lap) -> Instant {
        let now = Instant::now();
        match what {
            Lap::Tracing => self.tracing += now - clock,
            Lap::Shading => self.shading += now - clock,
        }
        now
    }

    /// The time spent tracing and shading since the last call, and resets
    /// both.
    pub fn take(&mut self) -> (Duration, Duration) {
        (
            std::mem::take(&mut self.tracing),
            std::mem::take(&mut self.shading),
        )
    }
}
