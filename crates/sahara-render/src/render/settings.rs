//! How to render: [`RenderSettings`], and their check against what the
//! integrator supports and the scene holds.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

use sahara_kd::AccelParams;

use super::aux::Aov;
use crate::film::window::PixelWindow;
use crate::integrator::guiding::Guiding;
#[cfg(doc)]
use crate::integrator::Supports;
use crate::integrator::{Feature, Integrator, SettingsError};
use crate::scene::Scene;
use crate::settings::FrameSettings;

/// How to render: what the frame is ([`FrameSettings`], read as these
/// settings' own fields) and how this render goes about it.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    /// What the frame is: size, samples per pixel and per pass, seed,
    /// sampler, filter, integrator, adaptive sampling. With a time limit,
    /// `spp` can be [`UNLIMITED_SPP`].
    pub frame: FrameSettings,
    /// Stop starting passes after this long, even before `spp` samples; a
    /// pass under way when it runs out is abandoned (the first pass always
    /// completes). With a time limit, `spp` can be [`UNLIMITED_SPP`].
    pub time_limit: Option<Duration>,
    /// Set to true (e.g. on Ctrl-C) to stop; the passes completed are kept,
    /// and if the first pass is under way, the pixels it has finished.
    pub cancel: Option<Arc<AtomicBool>>,
    /// Tile edge in pixels.
    pub tile_size: u32,
    /// The meshes' acceleration structure: which (the eight-wide
    /// hierarchy by default, or the kd-tree) and its build parameters. A
    /// speed setting only: every structure finds the same hits.
    pub build: AccelParams,
    /// Full scale of the `cost` heat map in work units per camera ray
    /// (None: the image's maximum).
    pub cost_scale: Option<f32>,
    /// The pixels whose sums the render produces (None: the whole image).
    /// Every sample whose filter footprint reaches them is rendered, so a
    /// window's sums are those of the whole frame's render over it, where
    /// the integrator splits by pixels ([`Supports::pixel_parts`]); the
    /// light-tracing integrators render a window as a crop, whose own
    /// pixels' light subpaths stand for the whole frame's.
    pub window: Option<PixelWindow>,
    /// The sample indices of every pixel to render, counted over all
    /// passes: sample `k` is index `k % pass_spp` of pass `k / pass_spp`
    /// (None: `0..spp`). The passes rendered are those the range meets.
    /// A range other than `0..spp` needs an integrator that splits by
    /// samples ([`Supports::sample_ranges`]).
    pub samples: Option<std::ops::Range<u32>>,
    /// True when the render is a part of a frame whose parts' sums are
    /// added up afterwards (a render farm's): its `window` must then be a
    /// part by pixels the integrator supports ([`Supports::pixel_parts`]).
    /// False: the window is a crop, an image of those pixels.
    pub part: bool,
    /// The render passes to make beside the beauty, the images a denoiser
    /// and compositing use ([`AuxImages`](super::AuxImages); the integrators whose
    /// [`Supports::aovs`] says so); empty: none. Adaptive sampling
    /// ([`FrameSettings::adaptive`]) needs an integrator that supports it
    /// ([`Supports::adaptive`]), and not with `samples` other than
    /// `0..spp` (a pixel's decisions need all its samples).
    pub aovs: Vec<Aov>,
    /// How the path tracer's samples are traced: in SIMD lanes or one
    /// path step at a time (the other integrators ignore it).
    pub path_loop: PathLoop,
}

/// The loop that traces the path tracer's samples (`path`, in a scene
/// without media). Both run the same estimator; their images are equal
/// to noise, not bit for bit (the lanes' arithmetic differs in rounding).
/// Each gives the same bytes for a seed at any thread count, and under a
/// render farm's split and merge (the frame digest tells the loops apart).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PathLoop {
    /// The lanes, refilled, where every material of the scene has a lane
    /// BSDF, else the scalar loop.
    Auto,
    /// Paths in SIMD lanes (packets of 16 under AVX-512, 8 under AVX2),
    /// lanes refilled from the next samples as their paths end.
    Lanes,
    /// Paths in SIMD lanes, a packet refilled only once all its paths
    /// have ended.
    LanesNoRefill,
    /// The scalar path tracer, a step of every path of a strip at a time
    /// (the wavefront): the reference the lanes are held to, and the
    /// default, because the lanes are not yet faster on every scene
    /// (measured faster on a box of quads, slower on a large mesh whose
    /// paths escape often; docs/performance.md, "Paths in SIMD lanes").
    #[default]
    Scalar,
}

crate::names::name_table!(PathLoop, "path loop", {
    PathLoop::Auto => "auto",
    PathLoop::Lanes => "lanes",
    PathLoop::LanesNoRefill => "lanes-no-refill",
    PathLoop::Scalar => "scalar",
});

impl PathLoop {
    /// Whether `integrator`'s samples in `scene` go to the lanes, and if
    /// so whether lanes are refilled.
    pub(crate) fn lanes(self, integrator: &Integrator, scene: &Scene) -> Option<bool> {
        if !matches!(integrator, Integrator::Path { .. }) || scene.has_media() {
            return None;
        }
        match self {
            PathLoop::Auto => {
                crate::material::lanes::all_in_lanes(&scene.materials).then_some(true)
            }
            PathLoop::Lanes => Some(true),
            PathLoop::LanesNoRefill => Some(false),
            PathLoop::Scalar => None,
        }
    }
}

/// The renderer reads the frame's settings as its own (`settings.spp`):
/// they are the settings of every render, kept in one struct so that a
/// scene file, a part file and a caller describe them once.
impl std::ops::Deref for RenderSettings {
    type Target = FrameSettings;

    fn deref(&self) -> &FrameSettings {
        &self.frame
    }
}

impl std::ops::DerefMut for RenderSettings {
    fn deref_mut(&mut self) -> &mut FrameSettings {
        &mut self.frame
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            frame: FrameSettings::default(),
            time_limit: None,
            cancel: None,
            tile_size: 32,
            build: AccelParams::default(),
            cost_scale: None,
            window: None,
            samples: None,
            part: false,
            aovs: Vec::new(),
            path_loop: PathLoop::default(),
        }
    }
}

impl From<FrameSettings> for RenderSettings {
    /// A render of the whole frame `frame` with the defaults for the rest.
    fn from(frame: FrameSettings) -> Self {
        Self {
            frame,
            ..Default::default()
        }
    }
}

/// The `spp` of a render bounded by its time limit only.
pub const UNLIMITED_SPP: u32 = u32::MAX;

impl RenderSettings {
    /// Samples per pixel of each pass: `pass_spp`, at least 1, at most `spp`.
    pub fn pass_size(&self) -> u32 {
        self.pass_spp.clamp(1, self.spp.max(1))
    }

    /// The most passes the render takes: `spp` in passes of [`Self::pass_size`].
    pub fn passes(&self) -> u32 {
        self.spp.max(1).div_ceil(self.pass_size())
    }

    /// Refuses what the integrator cannot honour, as its kind declares
    /// ([`IntegratorKind::supports`]): a sample range, a part by pixels,
    /// adaptive sampling (and adaptive sampling with a sample range, which
    /// no integrator takes), render passes. Every render runs this first.
    ///
    /// [`IntegratorKind::supports`]: crate::IntegratorKind::supports
    pub fn check(&self) -> Result<(), SettingsError> {
        let kind = self.integrator.kind();
        let sample_range = self.samples.as_ref().filter(|r| **r != (0..self.spp));
        if sample_range.is_some() {
            kind.require(Feature::SampleRanges)?;
        }
        let (w, h) = (self.width.max(1), self.height.max(1));
        let full = PixelWindow::full(w, h);
        if self.part && self.window.is_some_and(|win| win.intersect(&full) != full) {
            kind.require(Feature::PixelParts)?;
        }
        if self.adaptive.is_some() {
            kind.require(Feature::Adaptive)?;
            if let Some(r) = sample_range {
                return Err(SettingsError::AdaptiveSampleRange {
                    samples: r.clone(),
                    spp: self.spp,
                });
            }
        }
        if !self.aovs.is_empty() {
            kind.require(Feature::Aovs)?;
        }
        if self.guiding == Guiding::On {
            if let Some(why) = self.unguided(false) {
                return Err(SettingsError::Guiding(why));
            }
        }
        Ok(())
    }

    /// Why this render cannot be guided (None: it can), in a scene with
    /// media if `media`.
    fn unguided(&self, media: bool) -> Option<&'static str> {
        let whole = self.samples.as_ref().is_none_or(|r| *r == (0..self.spp));
        if !matches!(self.integrator, Integrator::Path { .. }) {
            Some("it guides the path integrator only")
        } else if self.part || !whole {
            Some(
                "a farm's part cannot learn from the other parts' paths (render parts with \
                 guiding off)",
            )
        } else if self.adaptive.is_some() {
            Some("it does not combine with adaptive sampling")
        } else if media {
            Some("it does not guide through participating media")
        } else {
            None
        }
    }

    /// True if this render is guided ([`Guiding`]): asked for (`on`), or
    /// `auto` where guiding applies, in a scene with media if `media`.
    pub fn guided(&self, media: bool) -> bool {
        match self.guiding {
            Guiding::Off => false,
            Guiding::On | Guiding::Auto => self.unguided(media).is_none(),
        }
    }

    /// [`RenderSettings::check`], and refuses what the integrator cannot
    /// honour in this scene: participating media.
    pub fn check_for(&self, scene: &Scene) -> Result<(), SettingsError> {
        self.check()?;
        if scene.has_media() {
            self.integrator.kind().require(Feature::Media)?;
            if self.guiding == Guiding::On {
                if let Some(why) = self.unguided(true) {
                    return Err(SettingsError::Guiding(why));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod path_loop_tests {
    use super::*;
    use crate::material::{Bsdf, Material};
    use glam::Vec3;

    /// `auto` takes the lanes (refilled) where every material is shaded
    /// in the lanes (a layered BSDF is, lane by lane), the scalar loop
    /// where one is under a clear coat, and never for other integrators.
    #[test]
    fn auto_takes_the_lanes_where_every_material_is_shaded_in_lanes() {
        let path = Integrator::default();
        let mut scene = crate::builtin::cornell_box();
        assert!(matches!(path, Integrator::Path { .. }));
        assert_eq!(PathLoop::Auto.lanes(&path, &scene), Some(true));
        assert_eq!(PathLoop::Scalar.lanes(&path, &scene), None);
        let distribution = Integrator::named("distribution").unwrap();
        assert_eq!(PathLoop::Auto.lanes(&distribution, &scene), None);
        let mut metal = Material::new(Bsdf::MetallicRoughness {
            base_color: Vec3::ONE,
            metallic: 0.5,
            roughness: 0.5,
            ior: 1.5,
            specular: 1.0,
            specular_color: Vec3::ONE,
        });
        scene.add_material(metal.clone());
        assert_eq!(PathLoop::Auto.lanes(&path, &scene), Some(true));
        metal.clearcoat = Some(Box::new(crate::material::Clearcoat::uniform(1.0, 0.1, 1.5)));
        scene.add_material(metal);
        assert_eq!(PathLoop::Auto.lanes(&path, &scene), None);
        assert_eq!(PathLoop::Lanes.lanes(&path, &scene), Some(true));
    }
}
