//! What the caller sees while a render runs: a [`Progress`] report after
//! each tile, and a [`Preview`] of the passes completed so far between
//! passes.

use std::time::{Duration, Instant};

use super::result::RenderResult;

/// Progress report, sent after each tile and each pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    /// Current pass (0-based).
    pub pass: u32,
    /// Most passes (when only a time limit bounds the render, those of
    /// [`UNLIMITED_SPP`](super::UNLIMITED_SPP)).
    pub passes: u32,
    /// Tiles finished in this pass.
    pub tiles_done: u32,
    /// Tiles per pass.
    pub tiles: u32,
    /// Time since the render began.
    pub elapsed: Duration,
    /// Rays traced so far (camera, bounce and shadow rays), for a live
    /// Mrays/s figure.
    pub rays: u64,
}

/// What [`render_watched`](super::render_watched) calls between passes, at most once per `every`.
pub struct Preview<'a> {
    /// Shortest time between two calls.
    pub every: Duration,
    /// Called with the image of the passes completed so far (not after the
    /// last pass: that image is the render's result).
    pub show: &'a mut (dyn FnMut(&RenderResult) + Send),
}

/// Hands images to the caller's [`Preview`] at most once per its `every`.
pub(super) struct Previews<'a> {
    preview: Option<Preview<'a>>,
    last: Instant,
}

impl<'a> Previews<'a> {
    /// Previews for the caller's `preview`, the first due one `every` from now.
    pub(super) fn new(preview: Option<Preview<'a>>) -> Self {
        Self {
            preview,
            last: Instant::now(),
        }
    }

    /// Shows the image `image` makes, if a preview is due.
    pub(super) fn offer(&mut self, image: impl FnOnce() -> RenderResult) {
        if let Some(p) = self.preview.as_mut() {
            if self.last.elapsed() >= p.every {
                (p.show)(&image());
                self.last = Instant::now();
            }
        }
    }
}
