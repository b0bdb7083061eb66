//! What a render covers: the frame's pixels cut into tiles ([`Frame`]),
//! and the passes its sample range meets ([`PassPlan`]).

use super::adaptive;
use super::settings::RenderSettings;
use super::tile::Tile;
use crate::film::sums::filter_margin;
use crate::film::window::PixelWindow;

/// The pixels a render covers, cut into tiles.
pub(super) struct Frame {
    /// The image's size.
    pub(super) w: u32,
    pub(super) h: u32,
    /// The pixels whose sums the render produces.
    pub(super) window: PixelWindow,
    /// The pixels whose samples reach the window; with adaptive sampling,
    /// whole blocks of them, so that a piece of the frame judges its pixels
    /// as the whole frame does.
    pub(super) region: PixelWindow,
    /// The region's tiles, rows top to bottom.
    pub(super) tiles: Vec<Tile>,
}

impl Frame {
    /// The window `settings` asks for, the region its samples come from,
    /// and the region's tiles.
    pub(super) fn plan(settings: &RenderSettings) -> Self {
        let (w, h) = (settings.width.max(1), settings.height.max(1));
        let window = settings
            .window
            .unwrap_or(PixelWindow::full(w, h))
            .intersect(&PixelWindow::full(w, h));
        let region = window.grow(filter_margin(&settings.filter), w, h);
        let region = match settings.adaptive {
            Some(_) => region.align(adaptive::BLOCK, w, h),
            None => region,
        };
        let ts = settings.tile_size.max(1);
        let tiles: Vec<Tile> = (0..region.height().div_ceil(ts))
            .flat_map(|ty| {
                (0..region.width().div_ceil(ts)).map(move |tx| Tile {
                    x0: region.x0 + tx * ts,
                    y0: region.y0 + ty * ts,
                    x1: (region.x0 + (tx + 1) * ts).min(region.x1),
                    y1: (region.y0 + (ty + 1) * ts).min(region.y1),
                })
            })
            .collect();
        Self {
            w,
            h,
            window,
            region,
            tiles,
        }
    }
}

/// The passes a render's sample range meets, and the range within each.
///
/// A pixel's samples are numbered over all passes, so that a sample range
/// (a render farm's part by samples) draws the very samples the whole
/// render draws: sample `g` is index `g % spp` of pass `g / spp`, and each
/// pass draws the numbers of its indices in the range ([`Self::numbered`]).
pub(super) struct PassPlan {
    /// Samples per pixel of a whole pass.
    spp: u32,
    /// The first pass rendered.
    pub(super) first_pass: u32,
    /// Passes rendered, at most.
    pub(super) passes: u32,
    /// The sample range, counted over all passes.
    first: u64,
    last: u64,
}

impl PassPlan {
    /// The passes of `settings`' sample range.
    pub(super) fn new(settings: &RenderSettings) -> Self {
        let spp = settings.pass_size();
        let (first_pass, passes, first, last) = match &settings.samples {
            None => (0, settings.passes(), 0u64, u64::from(settings.spp.max(1))),
            Some(r) if r.start >= r.end => (0, 0, 0, 0),
            Some(r) => (
                r.start / spp,
                r.end.div_ceil(spp) - r.start / spp,
                u64::from(r.start),
                u64::from(r.end),
            ),
        };
        Self {
            spp,
            first_pass,
            passes,
            first,
            last,
        }
    }

    /// The sample indices of `pass` within the range.
    pub(super) fn indices(&self, pass: u32) -> std::ops::Range<u32> {
        let (spp, base) = (u64::from(self.spp), u64::from(pass) * u64::from(self.spp));
        let i0 = self.first.saturating_sub(base).min(spp) as u32;
        let i1 = self.last.saturating_sub(base).min(spp) as u32;
        i0..i1
    }

    /// The samples every pixel draws in `pass`, numbered over all passes:
    /// index `i` of the pass is sample `pass * spp + i`.
    pub(super) fn numbered(&self, pass: u32) -> std::ops::Range<u32> {
        let indices = self.indices(pass);
        pass * self.spp + indices.start..pass * self.spp + indices.end
    }
}
