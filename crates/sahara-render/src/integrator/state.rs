//! A pixel sample's path in flight, between one ray query and the next.
//!
//! The path tracer and the distribution ray tracer are written as steps: a
//! step takes the closest hit of the path's current ray, adds what it can
//! to the sample's radiance, and leaves behind the path's next ray (if the
//! path goes on) and the light contributions that wait on a shadow ray
//! ([`Deferred`]). Whoever drives the steps answers the ray queries: one
//! at a time ([`super::Integrator::li`]) or a whole tile's paths per step
//! in batches ([`super::wavefront`]). Both apply every sample's deferred
//! contributions in the order its step made them, before its next step, so
//! the radiance is summed in the same order and comes out bit for bit the
//! same either way.

use glam::Vec3;
use sahara_kd::Ray;

use crate::sampler::PixelSampler;
use crate::world::ShadowQuery;

/// One pixel sample's path between two steps.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PathState {
    /// The ray the next step needs the closest hit of.
    pub ray: Ray,
    /// The sample's time.
    pub time: f32,
    /// The sample's random numbers.
    pub sampler: PixelSampler,
    /// Radiance gathered so far.
    pub l: Vec3,
    /// Throughput of the path so far.
    pub beta: Vec3,
    /// Scattering events so far.
    pub depth: u32,
    /// Whether the last scattering was a delta lobe (true for camera
    /// rays): emission found by the next ray counts in full.
    pub prev_delta: bool,
    /// Density of the last scattering's direction.
    pub prev_pdf: f32,
    /// Point of the last scattering.
    pub prev_p: Vec3,
    /// Shading normal there (light choice depends on it).
    pub prev_n: Vec3,
    /// Running sum of one light's samples (the distribution tracer).
    pub light_sum: Vec3,
    /// Surfaces with holes the path has passed through.
    pub pass_throughs: u32,
    /// The last vertex's painted occlusion, which light reaching it by
    /// more than one scattering passes (applied to `beta` once the
    /// emission at the next vertex is counted).
    pub occlusion: f32,
    /// What a denoiser is told about this sample.
    pub aux: AuxSample,
    /// The path's number among the batch whose vertices train the guide
    /// ([`super::guiding::NO_RECORD`]: it records none).
    pub guide: u32,
}

/// What a denoiser is told about one sample (Intel Open Image Denoise's
/// conventions): the albedo and the shading normal of the first surface
/// the path meets that is not a perfect mirror or smooth glass (through
/// those, the surface seen in them), and the camera distance, position and
/// texture coordinates of the first hit. A path that escapes first gets the environment's colour (clamped
/// to `[0, 1]`) as albedo and a zero normal; its distance is 0.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct AuxSample {
    /// Albedo in `[0, 1]`.
    pub albedo: Vec3,
    /// World-space shading normal, facing the arriving ray.
    pub normal: Vec3,
    /// Distance from the camera to the first hit, along the ray.
    pub depth: f32,
    /// World position of the first hit.
    pub position: Vec3,
    /// Texture coordinates (the first uv set) of the first hit.
    pub uv: glam::Vec2,
    /// Still looking for the surface (false from the start when nobody
    /// asked for the values).
    pub open: bool,
}

impl AuxSample {
    /// Records the surface `sh` of `hit`, met after `depth` scatterings by a
    /// ray of direction `dir`.
    #[inline]
    pub fn surface(
        &mut self,
        sh: &super::Shading,
        hit: &crate::world::SurfaceHit,
        dir: Vec3,
        depth: u32,
    ) {
        if !self.open {
            return;
        }
        if depth == 0 {
            self.depth = hit.t * dir.length();
            self.position = hit.p;
            self.uv = hit.uv;
        }
        if !sh.bsdf.is_delta() {
            self.albedo = sh.bsdf.albedo();
            let n = sh.frame.n;
            self.normal = if n.dot(sh.wo_world) < 0.0 { -n } else { n };
            self.open = false;
        }
    }

    /// Records a scattering in a participating medium of single-scattering
    /// albedo `albedo` at `p`, at `distance` from the camera if it is the
    /// path's first event: a medium has no surface, so its normal is zero
    /// (the denoiser's sign for "no surface here").
    #[inline]
    pub fn medium(&mut self, albedo: Vec3, p: Vec3, distance: Option<f32>) {
        if !self.open {
            return;
        }
        if let Some(d) = distance {
            self.depth = d;
            self.position = p;
        }
        self.albedo = albedo.clamp(Vec3::ZERO, Vec3::ONE);
        self.normal = Vec3::ZERO;
        self.open = false;
    }

    /// Records an escape into the environment of radiance `le`.
    #[inline]
    pub fn escape(&mut self, le: Vec3) {
        if self.open {
            self.albedo = le.clamp(Vec3::ZERO, Vec3::ONE);
            self.open = false;
        }
    }
}

impl PathState {
    /// A path starting with camera ray `ray` at `time`.
    #[inline]
    pub fn new(ray: Ray, time: f32, sampler: PixelSampler) -> Self {
        Self {
            ray,
            time,
            sampler,
            l: Vec3::ZERO,
            beta: Vec3::ONE,
            depth: 0,
            prev_delta: true,
            prev_pdf: 0.0,
            prev_p: ray.origin,
            prev_n: Vec3::ZERO,
            light_sum: Vec3::ZERO,
            pass_throughs: 0,
            occlusion: 1.0,
            aux: AuxSample::default(),
            guide: super::guiding::NO_RECORD,
        }
    }

    /// This path with its auxiliary values recorded as it goes, if `on`
    /// (otherwise [`AuxSample`]'s checks end at once).
    #[inline]
    pub fn with_aux(mut self, on: bool) -> Self {
        self.aux.open = on;
        self
    }

    /// Applies a deferred contribution, `visible` telling whether its
    /// shadow ray (if it has one) reached the light.
    #[inline]
    pub fn apply(&mut self, op: &Op, visible: bool) {
        match *op {
            Op::Add(v) => {
                if visible {
                    self.l += v;
                }
            }
            Op::Sum(v) => {
                if visible {
                    self.light_sum += v;
                }
            }
            Op::Flush { beta, n } => {
                self.l += beta * self.light_sum / n as f32;
                self.light_sum = Vec3::ZERO;
            }
        }
    }
}

/// What a deferred contribution does to its sample.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Op {
    /// `l += v` if the shadow ray is unblocked.
    Add(Vec3),
    /// `light_sum += v` if the shadow ray is unblocked.
    Sum(Vec3),
    /// `l += beta * light_sum / n`, then `light_sum = 0` (no shadow ray).
    Flush {
        /// The throughput at the vertex.
        beta: Vec3,
        /// The light's sample count.
        n: u32,
    },
}

/// A light contribution waiting on its shadow ray.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Deferred {
    /// The shadow ray, if the contribution has one.
    pub shadow: Option<ShadowQuery>,
    /// What to do with the sample's radiance.
    pub op: Op,
}
