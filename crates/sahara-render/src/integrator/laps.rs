//! Where a batch's time goes: to the batched ray queries (tracing), to the
//! work between them (shading), or to the film, a clock read a few times
//! per round of the whole batch (per strip, for the film) rather than per
//! ray or per sample.

use std::time::{Duration, Instant};

/// What a stretch of a round's time went to.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Lap {
    /// Finding hits and answering shadow rays.
    Tracing,
    /// Everything between the queries: the vertices' shading, sampling,
    /// the strategies' weights.
    Shading,
    /// Adding the samples into the film's sums.
    Film,
}

/// Time spent tracing, shading and on the film since the last
/// [`Laps::take`].
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Laps {
    /// Time in [`Lap::Tracing`].
    pub tracing: Duration,
    /// Time in [`Lap::Shading`].
    pub shading: Duration,
    /// Time in [`Lap::Film`].
    pub film: Duration,
}

impl Laps {
    /// Adds the time since `clock` to `what`; the clock for the next lap.
    pub fn lap(&mut self, clock: Instant, what: Lap) -> Instant {
        let now = Instant::now();
        let d = now - clock;
        match what {
            Lap::Tracing => self.tracing += d,
            Lap::Shading => self.shading += d,
            Lap::Film => self.film += d,
        }
        now
    }

    /// The times since the last call; resets them.
    pub fn take(&mut self) -> Laps {
        std::mem::take(self)
    }
}

impl std::ops::AddAssign for Laps {
    fn add_assign(&mut self, o: Self) {
        self.tracing += o.tracing;
        self.shading += o.shading;
        self.film += o.film;
    }
}
