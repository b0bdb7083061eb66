//! The settings of a render as a scene file or a caller gives them: one
//! layer ([`SettingsLayer`]), each setting optional. The defaults, the
//! scene file's layer and the caller's fold into one
//! (`defaults.apply(file).apply(caller)`, see `crate::request`), so a
//! setting is described once, here or in [`FrameSettings`]'s list, and
//! every reader and front end has it.

use std::ops::Range;
use std::path::PathBuf;
use std::time::Duration;

use sahara_kd::{AccelKind, Builder};
use sahara_render::{FrameLayer, FrameSettings, PathLoop, PixelWindow};

use crate::output::frame::OutputLayer;

/// The settings of a render as one layer gives them: the scene file's,
/// the caller's (the command line's options, Python's keyword arguments)
/// or the defaults'. `None` (or an empty piece) where the layer says
/// nothing: the layer below decides.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SettingsLayer {
    /// What the frame is: size, samples, seed, sampler, filter,
    /// integrator, adaptive sampling.
    pub frame: FrameLayer,
    /// How it is written: exposure, tone map, render passes, denoising.
    pub output: OutputLayer,
    /// The image file to write, `.png` or `.exr` (relative to the working
    /// folder unless absolute; a scene file in a shared folder does not
    /// write there).
    pub path: Option<PathBuf>,
    /// Stop starting passes after this long. A layer that gives a time
    /// limit without a sample count lifts the count of the layers below:
    /// the passes go on until the time is up.
    pub time_limit: Option<Duration>,
    /// The acceleration structure: a speed setting only, the image is the
    /// same with either.
    pub accel: Option<AccelKind>,
    /// The kd-tree builder (for [`AccelKind::Kd`]): a speed setting only,
    /// the image is the same with any.
    pub builder: Option<Builder>,
    /// How the path tracer traces its samples: in SIMD lanes or the
    /// scalar loop (the images equal to noise, not bit for bit).
    pub path_loop: Option<PathLoop>,
    /// The pixels a scene file keeps of its image (pbrt's `cropwindow`
    /// and `pixelbounds`, Mitsuba's crop): a render is an image of those
    /// pixels of the whole frame.
    pub crop_window: Option<FileCrop>,
    /// A piece of the frame to render on its own, as a part file for
    /// `sahara merge` (a render farm's).
    pub piece: PieceLayer,
}

/// Which piece of a frame to render: a part of a division, a crop window,
/// a range of every pixel's samples; any of them, or none (the whole
/// frame, as an image).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PieceLayer {
    /// Part `i` of `n` (`i` from 0), divided as [`PieceLayer::split`] says.
    pub part: Option<(u32, u32)>,
    /// How [`PieceLayer::part`] divides the frame.
    pub split: Option<Split>,
    /// The crop window `x0, x1, y0, y1`, fractions of the image (y from
    /// the top): its pixels alone; with a part by tiles, the tiles divide
    /// it.
    pub crop: Option<[f64; 4]>,
    /// The sample indices `start..end` of every pixel (counted over all
    /// passes); with a part by samples, the parts divide this range.
    pub samples: Option<Range<u32>>,
}

impl PieceLayer {
    /// True if any piece is asked for.
    pub fn is_piece(&self) -> bool {
        self.part.is_some() || self.crop.is_some() || self.samples.is_some()
    }
}

/// How a part divides a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Split {
    /// Pixel regions of nearly equal pixel counts.
    #[default]
    Tiles,
    /// Contiguous ranges of every pixel's sample indices.
    Samples,
}

impl Split {
    /// Every way, in the order messages list them.
    pub const ALL: [Split; 2] = [Split::Tiles, Split::Samples];

    /// Its name (`tiles`, `samples`).
    pub fn name(self) -> &'static str {
        match self {
            Split::Tiles => "tiles",
            Split::Samples => "samples",
        }
    }
}

impl SettingsLayer {
    /// This layer under `above`: every setting `above` gives replaces (or
    /// combines with) this one's. A time limit given above without a
    /// sample count lifts this layer's count (the render goes on until
    /// the time is up); the piece is the one above if it asks for one.
    pub fn apply(self, above: SettingsLayer) -> SettingsLayer {
        let uncapped = above.time_limit.is_some() && above.frame.spp.is_none();
        let mut frame = self.frame.apply(above.frame);
        if uncapped {
            frame.spp = Some(sahara_render::UNLIMITED_SPP);
        }
        let piece = &above.piece;
        SettingsLayer {
            frame,
            output: self.output.apply(above.output),
            path: above.path.or(self.path),
            time_limit: above.time_limit.or(self.time_limit),
            accel: above.accel.or(self.accel),
            builder: above.builder.or(self.builder),
            path_loop: above.path_loop.or(self.path_loop),
            crop_window: above.crop_window.or(self.crop_window),
            piece: PieceLayer {
                part: piece.part.or(self.piece.part),
                split: piece.split.or(self.piece.split),
                crop: piece.crop.or(self.piece.crop),
                samples: piece.samples.clone().or(self.piece.samples),
            },
        }
    }

    /// The frame these settings describe, the renderer's defaults where
    /// they say nothing (for tests and callers that render a file's
    /// settings as they are).
    pub fn frame_settings(&self) -> FrameSettings {
        self.frame.clone().decided()
    }
}

/// The pixels a scene file asks to render (pbrt's film `cropwindow` and
/// `pixelbounds`), resolved against the image size when that is known.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FileCrop {
    /// `x0, x1, y0, y1` as fractions of the image, y from the top: pixels
    /// `ceil(x0 W)..ceil(x1 W)`, `ceil(y0 H)..ceil(y1 H)` (pbrt-v4's rule).
    Fractions([f64; 4]),
    /// Pixels `x0..x1`, `y0..y1`, clipped to the image.
    Pixels([i64; 4]),
}

impl FileCrop {
    /// The pixels of a `width x height` image this crop keeps (may be empty).
    pub fn window(&self, width: u32, height: u32) -> PixelWindow {
        match *self {
            FileCrop::Fractions(f) => sahara_render::crop(width, height, f),
            FileCrop::Pixels([x0, x1, y0, y1]) => {
                let clip = |v: i64, size: u32| v.clamp(0, i64::from(size)) as u32;
                let (x0, y0) = (clip(x0, width), clip(y0, height));
                PixelWindow {
                    x0,
                    x1: clip(x1, width).max(x0),
                    y0,
                    y1: clip(y1, height).max(y0),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sahara_render::UNLIMITED_SPP;

    #[test]
    fn a_time_limit_above_without_a_count_lifts_the_count_below() {
        let file = SettingsLayer {
            frame: FrameLayer {
                spp: Some(16),
                ..Default::default()
            },
            ..Default::default()
        };
        let limit = SettingsLayer {
            time_limit: Some(Duration::from_secs(3)),
            ..Default::default()
        };
        let folded = file.clone().apply(limit.clone());
        assert_eq!(folded.frame.spp, Some(UNLIMITED_SPP));
        assert_eq!(folded.time_limit, Some(Duration::from_secs(3)));
        // A count given beside the limit caps it.
        let both = SettingsLayer {
            frame: FrameLayer {
                spp: Some(4),
                ..Default::default()
            },
            ..limit
        };
        assert_eq!(file.clone().apply(both).frame.spp, Some(4));
        // Without a time limit the file's count holds.
        let other = SettingsLayer {
            path: Some("x.png".into()),
            ..Default::default()
        };
        let folded = file.apply(other);
        assert_eq!(folded.frame.spp, Some(16));
        assert_eq!(folded.path, Some(PathBuf::from("x.png")));
    }
}
