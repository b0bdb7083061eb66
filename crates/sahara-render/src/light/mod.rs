//! Lights: point, spot and directional lights given explicitly; area
//! lights made from emissive geometry; the environment; and the lights of
//! a scene gathered once for its world ([`gather`]).

pub mod area;
pub(crate) mod choice;
pub mod directional;
pub(crate) mod emission;
pub mod environment;
pub(crate) mod gather;
mod kinds;
pub mod point;
pub mod spot;
pub(crate) mod tree;

use glam::Vec3;

pub use area::AreaLight;
pub use choice::LightSampler;
pub use environment::{EnvLight, Environment};
pub use kinds::{LightKind, LightOf, AREA_SHAPES};

/// A light given explicitly (area lights come from emissive materials).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// An isotropic point light.
    Point {
        /// Position.
        position: Vec3,
        /// Radiant intensity (W/sr per channel).
        intensity: Vec3,
    },
    /// A spot light: a point light limited to a cone with a smooth edge.
    Spot {
        /// Position.
        position: Vec3,
        /// Unit axis of the cone.
        direction: Vec3,
        /// Radiant intensity on the axis.
        intensity: Vec3,
        /// Cosine of the angle where the falloff starts.
        cos_inner: f32,
        /// Cosine of the angle where the light ends.
        cos_outer: f32,
    },
    /// A distant light such as the sun.
    Directional {
        /// Unit direction the light travels in.
        direction: Vec3,
        /// Irradiance on a surface facing the light.
        irradiance: Vec3,
    },
}

impl Light {
    /// A point light.
    pub fn point(position: Vec3, intensity: Vec3) -> Self {
        Light::Point {
            position,
            intensity,
        }
    }

    /// A spot light at `position` aimed at `target`, full inside
    /// `inner_deg`, dark beyond `outer_deg` (half-angles in degrees).
    pub fn spot(
        position: Vec3,
        target: Vec3,
        intensity: Vec3,
        inner_deg: f32,
        outer_deg: f32,
    ) -> Self {
        let outer = outer_deg.max(inner_deg);
        Light::Spot {
            position,
            direction: (target - position).normalize(),
            intensity,
            cos_inner: inner_deg.to_radians().cos(),
            cos_outer: outer.to_radians().cos(),
        }
    }

    /// A directional light travelling along `direction`.
    pub fn directional(direction: Vec3, irradiance: Vec3) -> Self {
        Light::Directional {
            direction: direction.normalize(),
            irradiance,
        }
    }

    /// Light arriving at `p` from this light.
    #[inline]
    pub fn sample(&self, p: Vec3) -> Option<LightSample> {
        match *self {
            Light::Point {
                position,
                intensity,
            } => point::sample(position, intensity, p),
            Light::Spot {
                position,
                direction,
                intensity,
                cos_inner,
                cos_outer,
            } => spot::sample(position, direction, intensity, cos_inner, cos_outer, p),
            Light::Directional {
                direction,
                irradiance,
            } => directional::sample(direction, irradiance),
        }
    }

    /// Emitted power (luminance), by which lights are chosen and a
    /// scene's own lights measured; a directional light's is what falls
    /// on a disc of `scene_radius`.
    pub fn power(&self, scene_radius: f32) -> f32 {
        match *self {
            Light::Point { intensity, .. } => point::power(intensity),
            Light::Spot {
                intensity,
                cos_inner,
                cos_outer,
                ..
            } => spot::power(intensity, cos_inner, cos_outer),
            Light::Directional { irradiance, .. } => directional::power(irradiance, scene_radius),
        }
    }

    /// True for the light at infinity (directional).
    pub(crate) fn is_infinite(&self) -> bool {
        match self {
            Light::Directional { .. } => true,
            Light::Point { .. } | Light::Spot { .. } => false,
        }
    }

    /// Light leaving this light, its direction from `u_dir`; `disc` gives
    /// a light at infinity's origin on the disc of the scene's `radius`
    /// facing its direction.
    pub(crate) fn emission(
        &self,
        u_dir: glam::Vec2,
        disc: impl Fn(Vec3) -> Vec3,
        radius: f32,
    ) -> emission::Emission {
        match *self {
            Light::Point {
                position,
                intensity,
            } => point::emission(position, intensity, u_dir),
            Light::Spot {
                position,
                direction,
                intensity,
                cos_inner,
                cos_outer,
            } => spot::emission(position, direction, intensity, cos_inner, cos_outer, u_dir),
            Light::Directional {
                direction,
                irradiance,
            } => directional::emission(direction, irradiance, disc(direction), radius),
        }
    }

    /// Density of direction `dir` leaving this light (zero for a light at
    /// infinity: see `emission::pdf_disc`).
    pub(crate) fn pdf_dir(&self, dir: Vec3) -> f32 {
        match *self {
            Light::Point { .. } => point::PDF_DIR,
            Light::Spot {
                direction,
                cos_outer,
                ..
            } => spot::pdf_dir(direction, cos_outer, dir),
            Light::Directional { .. } => 0.0,
        }
    }
}

/// Light arriving at a point from a sampled direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Unit direction towards the light.
    pub wi: Vec3,
    /// Distance to the light's point (infinite for distant lights).
    pub dist: f32,
    /// Incident radiance (for delta lights: irradiance-like `I / d^2`).
    pub li: Vec3,
    /// Solid-angle density (1 for delta lights).
    pub pdf: f32,
    /// True for point, spot and directional lights.
    pub delta: bool,
    /// An instance that cannot block this sample: the convex emitter itself
    /// (its tessellation may lie across the exact surface sampled).
    pub ignore: Option<u32>,
    /// Unit front normal of the light's surface at the sampled point (zero
    /// for point, spot and directional lights and the environment).
    pub n: Vec3,
    /// Whether the light's surface emits from both faces there.
    pub two_sided: bool,
}

/// Any light the integrators sample.
#[derive(Clone, Debug)]
pub enum LightSource {
    /// An explicit light.
    Explicit(Light),
    /// Emissive geometry.
    Area(AreaLight),
    /// The environment.
    Environment(EnvLight),
}

impl LightSource {
    /// Light arriving at `p` (sample `u` places it on area lights).
    pub fn sample(&self, p: Vec3, u: glam::Vec2) -> Option<LightSample> {
        match self {
            LightSource::Explicit(l) => l.sample(p),
            LightSource::Area(a) => a.sample(p, u),
            LightSource::Environment(e) => e.sample(u),
        }
    }

    /// [`LightSource::sample`] for estimators that pair light sampling
    /// with BSDF sampling by MIS: the environment samples its compensated
    /// distribution ([`EnvLight::sample_mis`]).
    pub fn sample_mis(&self, p: Vec3, u: glam::Vec2) -> Option<LightSample> {
        match self {
            LightSource::Environment(e) => e.sample_mis(u),
            _ => self.sample(p, u),
        }
    }

    /// True for lights a ray can never hit.
    pub fn is_delta(&self) -> bool {
        match self {
            LightSource::Explicit(_) => true,
            LightSource::Area(_) | LightSource::Environment(_) => false,
        }
    }

    /// Emitted power (luminance) used to choose lights.
    pub fn power(&self, scene_radius: f32) -> f32 {
        match self {
            LightSource::Explicit(l) => l.power(scene_radius),
            LightSource::Area(a) => a.power(),
            LightSource::Environment(e) => e.power(scene_radius),
        }
    }
}
