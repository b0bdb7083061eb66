//! What each integrator supports beyond rendering a whole frame: parts of
//! a frame by pixels or by samples, adaptive sampling, render passes and
//! so denoising. Declared once per kind in one table
//! ([`IntegratorKind::supports`]), as its parameters are
//! ([`IntegratorKind::parameters`]), and enforced by
//! [`RenderSettings::check`](crate::RenderSettings::check), which every
//! render runs before it starts: settings an integrator cannot honour are
//! refused with a [`SettingsError`], never dropped. The command line and the
//! Python package print these errors as they are.

use std::fmt;
use std::ops::Range;

use super::IntegratorKind;
use crate::names::Named;

/// Whether an integrator supports a feature, and if not, why.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Support {
    /// Supported.
    Yes,
    /// Not supported, for the reason given (a clause that completes "the
    /// sppm integrator cannot ...: ").
    No(&'static str),
}

impl Support {
    /// True if supported.
    pub fn is_yes(self) -> bool {
        self == Support::Yes
    }
}

/// What an integrator supports beyond rendering a whole frame with a fixed
/// number of samples per pixel ([`IntegratorKind::supports`]). Every
/// integrator supports crop windows, time limits, cancelling and previews.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Supports {
    /// A part of a frame by pixels ([`RenderSettings::part`] with a
    /// window): its sums are the whole frame's over the window, so parts by
    /// pixels add up to the whole frame bit for bit.
    ///
    /// [`RenderSettings::part`]: crate::RenderSettings::part
    pub pixel_parts: Support,
    /// A range of every pixel's samples ([`RenderSettings::samples`]):
    /// ranges rendered apart add up to the whole frame bit for bit.
    ///
    /// [`RenderSettings::samples`]: crate::RenderSettings::samples
    pub sample_ranges: Support,
    /// Adaptive sampling ([`RenderSettings::adaptive`]): pixels stop taking
    /// samples once their noise is low enough.
    ///
    /// [`RenderSettings::adaptive`]: crate::RenderSettings::adaptive
    pub adaptive: Support,
    /// Render passes beside the beauty ([`RenderSettings::aovs`]); the
    /// denoiser's guides, albedo and normal, are two of them.
    ///
    /// [`RenderSettings::aovs`]: crate::RenderSettings::aovs
    pub aovs: Support,
    /// Participating media ([`crate::Scene::media`]): light attenuated
    /// and scattered between surfaces.
    pub media: Support,
}

/// A feature an integrator may or may not support ([`Supports`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Feature {
    /// [`Supports::pixel_parts`].
    PixelParts,
    /// [`Supports::sample_ranges`].
    SampleRanges,
    /// [`Supports::adaptive`].
    Adaptive,
    /// [`Supports::aovs`].
    Aovs,
    /// Denoising, which needs the albedo and normal passes: supported where
    /// [`Supports::aovs`] is.
    Denoise,
    /// [`Supports::media`].
    Media,
}

impl Feature {
    /// What the feature asks of an integrator, completing "the bdpt
    /// integrator cannot ...".
    fn asks(self) -> &'static str {
        match self {
            Feature::PixelParts => "render a part of the frame by pixels",
            Feature::SampleRanges => "render a range of each pixel's samples",
            Feature::Adaptive => "sample adaptively (a noise threshold)",
            Feature::Aovs => "make render passes (AOVs)",
            Feature::Denoise => "be denoised",
            Feature::Media => "render participating media",
        }
    }
}

impl Supports {
    /// Whether `feature` is supported.
    pub fn get(&self, feature: Feature) -> Support {
        match feature {
            Feature::PixelParts => self.pixel_parts,
            Feature::SampleRanges => self.sample_ranges,
            Feature::Adaptive => self.adaptive,
            Feature::Aovs | Feature::Denoise => self.aovs,
            Feature::Media => self.media,
        }
    }
}

/// Why media are the path tracer's only.
const NO_MEDIA: &str = "only the path integrator traces light through media (as the volumetric \
                        path tracer); use --integrator path";

/// Why the render passes are the path and distribution integrators' only.
const NO_AOVS: &str = "only the path and distribution integrators record what each sample first \
                       sees (its albedo, normal, depth)";

impl IntegratorKind {
    /// What this kind supports: the one table the render's checks and the
    /// documents read.
    pub fn supports(self) -> Supports {
        use Support::{No, Yes};
        // Light tracing adds each sample's light to whichever pixel it
        // reaches, anywhere in the frame.
        const LIGHT_TRACING: Supports = Supports {
            pixel_parts: No(
                "its light tracing lands anywhere in the frame, from every pixel's \
                             samples; split the frame by samples instead",
            ),
            sample_ranges: Yes,
            adaptive: No("its light tracing adds light to pixels that have stopped"),
            aovs: No(NO_AOVS),
            media: No(NO_MEDIA),
        };
        // A pixel's value depends on its own samples only.
        const VIEW: Supports = Supports {
            pixel_parts: Yes,
            sample_ranges: Yes,
            adaptive: Yes,
            aovs: No(NO_AOVS),
            media: No(NO_MEDIA),
        };
        match self {
            IntegratorKind::Path => Supports {
                pixel_parts: Yes,
                sample_ranges: Yes,
                adaptive: Yes,
                aovs: Yes,
                media: Yes,
            },
            IntegratorKind::Distribution => Supports {
                pixel_parts: Yes,
                sample_ranges: Yes,
                adaptive: Yes,
                aovs: Yes,
                media: No(NO_MEDIA),
            },
            IntegratorKind::Bdpt | IntegratorKind::LightPath => LIGHT_TRACING,
            IntegratorKind::Sppm => Supports {
                pixel_parts: Yes,
                sample_ranges: No("its iterations each shrink the search radius the next one \
                                   uses; split the frame by pixels instead"),
                adaptive: No(
                    "its iterations gather photons for every pixel at once, and a \
                              pixel cannot stop taking them",
                ),
                aovs: No(NO_AOVS),
                media: No(NO_MEDIA),
            },
            IntegratorKind::Normals
            | IntegratorKind::Depth
            | IntegratorKind::Ao
            | IntegratorKind::Cost => VIEW,
        }
    }

    /// `Ok` if this kind supports `feature`, else the error that says why.
    pub fn require(self, feature: Feature) -> Result<(), SettingsError> {
        match self.supports().get(feature) {
            Support::Yes => Ok(()),
            Support::No(why) => Err(SettingsError::Unsupported {
                integrator: self,
                feature,
                why,
            }),
        }
    }
}

/// Render settings that cannot be honoured: the render is refused rather
/// than done without them. One line each.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SettingsError {
    /// The integrator does not support `feature` ([`IntegratorKind::supports`]).
    Unsupported {
        /// The integrator asked for.
        integrator: IntegratorKind,
        /// What it was asked to do.
        feature: Feature,
        /// Why it cannot.
        why: &'static str,
    },
    /// Adaptive sampling with a range of the samples: a pixel's decision to
    /// stop needs all of its samples.
    AdaptiveSampleRange {
        /// The range asked for.
        samples: Range<u32>,
        /// The frame's samples per pixel.
        spp: u32,
    },
    /// Path guiding asked for (`guiding = on`) where it cannot apply, for
    /// the reason given.
    Guiding(&'static str),
}

impl fmt::Display for SettingsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SettingsError::Unsupported {
                integrator,
                feature,
                why,
            } => write!(
                f,
                "the {} integrator cannot {}: {why}",
                integrator.name(),
                feature.asks()
            ),
            SettingsError::AdaptiveSampleRange { samples, spp } => write!(
                f,
                "adaptive sampling cannot be used with sample ranges (samples {}..{} of {spp}): \
                 a pixel's decision to stop needs all its samples; split the frame by pixels \
                 instead",
                samples.start, samples.end
            ),
            SettingsError::Guiding(why) => write!(f, "path guiding cannot be used here: {why}"),
        }
    }
}

impl std::error::Error for SettingsError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unsupported_feature_says_which_integrator_and_why_in_one_line() {
        let e = IntegratorKind::Sppm.require(Feature::Adaptive).unwrap_err();
        let text = e.to_string();
        assert!(
            text.starts_with("the sppm integrator cannot sample adaptively"),
            "{text}"
        );
        assert!(!text.contains('\n'));
        assert!(IntegratorKind::Path.require(Feature::Denoise).is_ok());
    }
}
