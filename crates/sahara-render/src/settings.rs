//! The settings that decide a frame's pixels, described once.
//!
//! [`FrameSettings`] is what a frame is: its size, its samples, its seed,
//! and how the samples are drawn, weighed and added up. The renderer's
//! [`RenderSettings`](crate::RenderSettings) hold one, a farm's part file
//! records one, and a scene file or a caller gives a [`FrameLayer`]: the
//! same fields, each optional. Layers fold, the one above over the one
//! below (`defaults.apply(file).apply(caller)`), and the result decides
//! the settings: a setting is added to this one list and every layer, the
//! decided settings and the defaults have it.
//!
//! Most settings given above simply replace those below. A few
//! [`Choice`]s combine: a filter or an integrator named by its kind alone
//! ([`Pick::Kind`], the command line's `--integrator path`) keeps the
//! parameters a scene file gave the same kind; adaptive sampling's
//! threshold and minimum are given apart ([`AdaptiveChoice`]).

use std::fmt::Debug;

use crate::film::filter::{Filter, FilterKind};
use crate::integrator::guiding::Guiding;
use crate::integrator::{defaults, Integrator, IntegratorKind};
use crate::light::LightSampler;
use crate::sampler::SamplerKind;

/// Declares a struct of settings with its defaults, and its layer: the
/// same fields, each an `Option` (`None`: the layer says nothing of it),
/// with [`apply`](FrameLayer::apply) (a layer over another) and
/// [`decided`](FrameLayer::decided) (the settings, defaults where no
/// layer gave one).
///
/// ```ignore
/// layered! {
///     /// What a frame is.
///     pub struct FrameSettings;
///     /// Some of a frame's settings.
///     pub struct FrameLayer;
///     {
///         /// Image width in pixels.
///         width: u32 = 512;
///         /// Reconstruction filter: a kind alone keeps the parameters below.
///         filter: Filter = Filter::default(), by Pick<Filter>;
///     }
/// }
/// ```
///
/// A field `by` a [`Choice`] is held in the layer as that choice, which
/// says how it combines with the one below and what it decides; any
/// other field given above replaces the one below.
#[macro_export]
macro_rules! layered {
    (
        $(#[$sm:meta])* $svis:vis struct $settings:ident;
        $(#[$lm:meta])* $lvis:vis struct $layer:ident;
        {
            $( $(#[$fm:meta])* $field:ident : $ty:ty = $default:expr $(, by $choice:ty)? ; )*
        }
    ) => {
        $(#[$sm])*
        #[derive(Clone, Debug, PartialEq)]
        $svis struct $settings {
            $( $(#[$fm])* pub $field: $ty, )*
        }

        impl Default for $settings {
            fn default() -> Self {
                Self { $( $field: $default, )* }
            }
        }

        $(#[$lm])*
        #[derive(Clone, Debug, Default, PartialEq)]
        $lvis struct $layer {
            $( $(#[$fm])* pub $field: Option<$crate::layered!(@held $ty $(, $choice)?)>, )*
        }

        impl $layer {
            /// This layer under `above`: every setting `above` gives
            /// replaces this one's (or, for a setting held as a `Choice`,
            /// combines with it).
            pub fn apply(self, above: Self) -> Self {
                Self {
                    $( $field: $crate::layered!(@over self.$field, above.$field $(, $choice)?), )*
                }
            }

            /// The settings this layer decides: the defaults where it gives none.
            pub fn decided(self) -> $settings {
                $settings {
                    $( $field: $crate::layered!(@decide self.$field, $default $(, $choice)?), )*
                }
            }
        }
    };
    (@held $ty:ty) => { $ty };
    (@held $ty:ty, $choice:ty) => { $choice };
    (@over $below:expr, $above:expr) => { $above.or($below) };
    (@over $below:expr, $above:expr, $choice:ty) => {
        <$choice as $crate::Choice>::over($below, $above)
    };
    (@decide $value:expr, $default:expr) => { $value.unwrap_or_else(|| $default) };
    (@decide $value:expr, $default:expr, $choice:ty) => {
        $value.map(<$choice as $crate::Choice>::decide).unwrap_or_else(|| $default)
    };
}

/// A setting whose value given above combines with the one below, rather
/// than replacing it.
pub trait Choice: Sized {
    /// The setting's value once decided.
    type Decided;

    /// This value (given below) under `above`.
    fn under(self, above: Self) -> Self;

    /// The value decided.
    fn decide(self) -> Self::Decided;

    /// `below` under `above`, either of them perhaps not given.
    fn over(below: Option<Self>, above: Option<Self>) -> Option<Self> {
        match (below, above) {
            (Some(b), Some(a)) => Some(b.under(a)),
            (b, a) => a.or(b),
        }
    }
}

/// A setting of a kind with parameters (a filter, an integrator), as a
/// layer gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pick<T: Pickable> {
    /// The kind alone (the command line's `--filter`, Python's
    /// `filter=`): the parameters a layer below gave the same kind hold,
    /// else the kind's defaults.
    Kind(T::Kind),
    /// The kind with its parameters (a scene file's).
    Value(T),
}

/// A setting [`Pick`]ed by its kind or given with its parameters.
pub trait Pickable: Sized + Clone {
    /// Its kind.
    type Kind: Copy + PartialEq + Debug;

    /// The kind with its default parameters.
    fn of_kind(kind: Self::Kind) -> Self;

    /// This value (given below) under the kind `kind` named above.
    fn kind_over(self, kind: Self::Kind) -> Self;
}

impl<T: Pickable> Choice for Pick<T> {
    type Decided = T;

    fn under(self, above: Self) -> Self {
        match (self, above) {
            (Pick::Value(below), Pick::Kind(kind)) => Pick::Value(below.kind_over(kind)),
            (_, above) => above,
        }
    }

    fn decide(self) -> T {
        match self {
            Pick::Kind(kind) => T::of_kind(kind),
            Pick::Value(v) => v,
        }
    }
}

impl Pickable for Filter {
    type Kind = FilterKind;

    fn of_kind(kind: FilterKind) -> Self {
        Filter::from(kind)
    }

    /// The same kind keeps its parameters; another takes its defaults.
    fn kind_over(self, kind: FilterKind) -> Self {
        if self.kind() == kind {
            self
        } else {
            Filter::from(kind)
        }
    }
}

impl Pickable for Integrator {
    type Kind = IntegratorKind;

    fn of_kind(kind: IntegratorKind) -> Self {
        Integrator::from(kind)
    }

    /// The same kind keeps its parameters; another takes its defaults,
    /// but between `path`, `bdpt`, `lightpath` and `sppm`, which count a
    /// path's length alike, the length below holds too, so that switching
    /// the estimator renders the same image.
    fn kind_over(self, kind: IntegratorKind) -> Self {
        if self.kind() == kind {
            return self;
        }
        let new = Integrator::from(kind);
        match (self.path_length(), new.path_length()) {
            (Some(n), Some(_)) => new.with_path_length(n),
            _ => new,
        }
    }
}

/// Adaptive sampling: stop a pixel once its estimated noise is below
/// `threshold` (the render's `spp` is then a cap).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive {
    /// The noise at which a pixel stops (see `render::adaptive`'s formula; Cycles'
    /// default is 0.01, lower is cleaner and slower).
    pub threshold: f32,
    /// Samples every pixel takes before it is first tested.
    pub min_spp: u32,
}

impl Adaptive {
    /// The minimum samples of [`Adaptive::min_spp`] when none is given.
    pub const DEFAULT_MIN_SPP: u32 = 16;
}

/// Adaptive sampling as a layer gives it: the threshold that asks for it
/// and the minimum, each perhaps not given (the command line's
/// `--min-spp` with the scene file's threshold, say).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AdaptiveChoice {
    /// The noise threshold ([`Adaptive::threshold`]).
    pub threshold: Option<f32>,
    /// The samples before a pixel is first tested ([`Adaptive::min_spp`]).
    pub min_spp: Option<u32>,
}

impl From<Adaptive> for AdaptiveChoice {
    fn from(a: Adaptive) -> Self {
        Self {
            threshold: Some(a.threshold),
            min_spp: Some(a.min_spp),
        }
    }
}

impl Choice for AdaptiveChoice {
    type Decided = Option<Adaptive>;

    fn under(self, above: Self) -> Self {
        Self {
            threshold: above.threshold.or(self.threshold),
            min_spp: above.min_spp.or(self.min_spp),
        }
    }

    /// Adaptive sampling if a threshold was given (a minimum alone asks
    /// for nothing).
    fn decide(self) -> Option<Adaptive> {
        self.threshold.map(|threshold| Adaptive {
            threshold,
            min_spp: self.min_spp.unwrap_or(Adaptive::DEFAULT_MIN_SPP),
        })
    }
}

layered! {
    /// What a frame is: the settings that decide its pixels (and so its
    /// digest, [`frame_digest`](crate::frame_digest)). The tree builder,
    /// the tile size, the threads, the time limit, the window and the
    /// sample range rendered are not among them: they change no pixel of
    /// the frame.
    pub struct FrameSettings;
    /// Some of a frame's settings, as a scene file or a caller gives them
    /// (`None`: not given); see the [module](self).
    pub struct FrameLayer;
    {
        /// Image width in pixels.
        width: u32 = 512;
        /// Image height in pixels (the camera's aspect should be
        /// width/height).
        height: u32 = 512;
        /// Samples per pixel of the image (the cap, with adaptive
        /// sampling).
        spp: u32 = defaults::SPP;
        /// Samples per pixel of each progressive pass (at most `spp`); the
        /// last pass takes what is left of `spp`.
        pass_spp: u32 = defaults::PASS_SPP;
        /// Seed of every random decision.
        seed: u64 = 0;
        /// Sample generator.
        sampler: SamplerKind = SamplerKind::Sobol;
        /// Reconstruction filter.
        filter: Filter = Filter::default(), by Pick<Filter>;
        /// Light transport.
        integrator: Integrator = Integrator::default(), by Pick<Integrator>;
        /// Adaptive sampling: pixels stop once their noise is low enough,
        /// and `spp` is a cap (None: every pixel takes `spp`).
        adaptive: Option<Adaptive> = None, by AdaptiveChoice;
        /// How next-event estimation chooses the light it samples.
        light_sampler: LightSampler = LightSampler::Tree;
        /// Whether `path` guides its bounces by what the render learns of
        /// where light comes from ([`Guiding`]).
        guiding: Guiding = Guiding::Off;
    }
}

impl From<FrameSettings> for FrameLayer {
    /// Every setting given, as `settings` has it.
    fn from(s: FrameSettings) -> Self {
        Self {
            width: Some(s.width),
            height: Some(s.height),
            spp: Some(s.spp),
            pass_spp: Some(s.pass_spp),
            seed: Some(s.seed),
            sampler: Some(s.sampler),
            filter: Some(Pick::Value(s.filter)),
            integrator: Some(Pick::Value(s.integrator)),
            adaptive: s.adaptive.map(AdaptiveChoice::from),
            light_sampler: Some(s.light_sampler),
            guiding: Some(s.guiding),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file() -> FrameLayer {
        FrameLayer {
            width: Some(40),
            height: Some(30),
            spp: Some(5),
            seed: Some(11),
            filter: Some(Pick::Value(Filter::Box { radius: 0.7 })),
            integrator: Some(Pick::Value(Integrator::Bdpt { max_depth: 20 })),
            adaptive: Some(AdaptiveChoice {
                threshold: Some(0.1),
                min_spp: Some(4),
            }),
            ..Default::default()
        }
    }

    #[test]
    fn a_layer_above_replaces_what_it_gives_and_keeps_the_rest() {
        let caller = FrameLayer {
            width: Some(8),
            spp: Some(2),
            ..Default::default()
        };
        let s = FrameLayer::default().apply(file()).apply(caller).decided();
        assert_eq!((s.width, s.height, s.spp, s.seed), (8, 30, 2, 11));
        assert_eq!(s.pass_spp, defaults::PASS_SPP);
        assert_eq!(s.sampler, SamplerKind::Sobol);
        assert_eq!(FrameLayer::default().decided(), FrameSettings::default());
        // Every setting given decides itself.
        let all = FrameLayer::from(s.clone()).decided();
        assert_eq!(all, s);
    }

    #[test]
    fn a_kind_named_above_keeps_the_parameters_below_of_that_kind() {
        let with = |filter, integrator| {
            let caller = FrameLayer {
                filter: Some(Pick::Kind(filter)),
                integrator: Some(Pick::Kind(integrator)),
                ..Default::default()
            };
            file().apply(caller).decided()
        };
        let s = with(FilterKind::Box, IntegratorKind::Bdpt);
        assert_eq!(s.filter, Filter::Box { radius: 0.7 });
        assert_eq!(s.integrator, Integrator::Bdpt { max_depth: 20 });
        // Another kind: its defaults, but the path length of the
        // estimators that count it alike.
        let s = with(FilterKind::Tent, IntegratorKind::Path);
        assert_eq!(s.filter, Filter::from(FilterKind::Tent));
        assert_eq!(
            s.integrator,
            Integrator::Path {
                max_depth: 20,
                rr_depth: defaults::RR_DEPTH
            }
        );
        assert_eq!(
            with(FilterKind::Box, IntegratorKind::Distribution).integrator,
            Integrator::from(IntegratorKind::Distribution)
        );
        // A kind over nothing is that kind's defaults.
        let caller = FrameLayer {
            integrator: Some(Pick::Kind(IntegratorKind::Sppm)),
            ..Default::default()
        };
        assert_eq!(
            caller.decided().integrator,
            Integrator::from(IntegratorKind::Sppm)
        );
    }

    #[test]
    fn adaptive_samplings_threshold_and_minimum_are_given_apart() {
        let decided = |caller: AdaptiveChoice| {
            let caller = FrameLayer {
                adaptive: Some(caller),
                ..Default::default()
            };
            file().apply(caller).decided().adaptive
        };
        let a = |threshold, min_spp| Some(Adaptive { threshold, min_spp });
        assert_eq!(decided(AdaptiveChoice::default()), a(0.1, 4));
        let threshold = AdaptiveChoice {
            threshold: Some(0.02),
            min_spp: None,
        };
        assert_eq!(decided(threshold), a(0.02, 4));
        let min = AdaptiveChoice {
            threshold: None,
            min_spp: Some(32),
        };
        assert_eq!(decided(min), a(0.1, 32));
        // A minimum alone asks for nothing; a threshold alone takes the
        // default minimum.
        let alone = |c: AdaptiveChoice| {
            FrameLayer {
                adaptive: Some(c),
                ..Default::default()
            }
            .decided()
            .adaptive
        };
        assert_eq!(alone(min), None);
        assert_eq!(alone(threshold), a(0.02, Adaptive::DEFAULT_MIN_SPP));
    }
}
