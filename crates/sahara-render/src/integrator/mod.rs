//! Light transport: the distribution ray tracer, the path tracer, and
//! debug views; what each integrator supports ([`Supports`]).

pub(crate) mod bdpt;
pub mod debug;
mod distribution;
pub mod guiding;
pub(crate) mod lanes;
pub(crate) mod laps;
mod path;
mod queries;
pub(crate) mod sppm;
mod state;
mod supports;
pub(crate) mod volpath;
pub(crate) mod wavefront;

use glam::{Vec2, Vec3};
use sahara_kd::{Ray, TraversalCounters};

use crate::light::LightSample;
use crate::material::maps::perturbed_normal;
use crate::material::NormalMap;
use crate::material::{BsdfSample, PointBsdf};
use crate::math::warp::Frame;
use crate::names::{name_table, Accepts, Named, Parameter};
use crate::sampler::dims;
use crate::sampler::PixelSampler;
use crate::texture::footprint::UvFootprint;
use crate::world::{ShadowQuery, SurfaceHit, World};
pub use lanes::LaneCounts;
use state::Deferred;
pub(crate) use state::{AuxSample, PathState};
pub use supports::{Feature, SettingsError, Support, Supports};

/// Which estimator computes a pixel sample's radiance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    /// Unidirectional path tracing with next-event estimation, MIS (power
    /// heuristic) and Russian roulette.
    Path {
        /// Largest number of scattering events (1: direct light only).
        max_depth: u32,
        /// Bounces before Russian roulette starts.
        rr_depth: u32,
    },
    /// Cook's distribution ray tracing: direct light from every light with
    /// `light_samples` samples each, recursion only through mirror, glossy
    /// and refractive lobes (no diffuse interreflection).
    Distribution {
        /// Largest number of specular/glossy bounces.
        max_depth: u32,
        /// Samples per area light (and environment) at every hit.
        light_samples: u32,
    },
    /// Bidirectional path tracing: a camera and a light subpath per
    /// sample, joined in every way, weighted by multiple importance
    /// sampling (power heuristic); finds caustics and light that arrives
    /// through small openings. Paths end at `max_depth` scattering events
    /// (no Russian roulette).
    Bdpt {
        /// Largest number of scattering events.
        max_depth: u32,
    },
    /// Light tracing: light subpaths joined to the camera, and the
    /// emitters the camera sees directly; surfaces seen through mirrors
    /// or glass stay black. Bidirectional path tracing's light strategy
    /// alone.
    LightPath {
        /// Largest number of scattering events.
        max_depth: u32,
    },
    /// Stochastic progressive photon mapping: per iteration (one per
    /// sample per pixel), camera paths through mirrors and glass to their
    /// first rough surface, photons from the lights gathered there within
    /// a radius that shrinks as iterations add up. Finds caustics seen in
    /// mirrors and through glass.
    Sppm {
        /// Largest number of scattering events of camera paths and of
        /// photons.
        max_depth: u32,
        /// Initial search radius in scene units (0: twice a pixel's width
        /// at the distance from the camera to the scene's centre).
        radius: f32,
        /// Photons per iteration (0: one per pixel).
        photons: u32,
    },
    /// The shading normal, mapped to `n / 2 + 1/2`.
    Normals,
    /// Distance to the first hit (0 where nothing is hit).
    Depth,
    /// Ambient occlusion: fraction of cosine-weighted rays unblocked within
    /// `distance` (0: a tenth of the scene's radius).
    Ao {
        /// Rays per pixel sample.
        samples: u32,
        /// Occlusion distance.
        distance: f32,
    },
    /// A heat map of kd-tree work per pixel (traversal steps plus triangle
    /// tests of the camera ray).
    Cost,
}

/// The default parameters of every integrator, used by the command line
/// and by scene files alike.
pub mod defaults {
    /// Largest number of scattering events of `path` and of specular/glossy
    /// bounces of `distribution`.
    pub const MAX_DEPTH: u32 = 8;
    /// Bounces before Russian roulette starts in `path`.
    pub const RR_DEPTH: u32 = 3;
    /// Samples per area light (and environment) at every hit of `distribution`.
    pub const LIGHT_SAMPLES: u32 = 4;
    /// Rays per pixel sample of `ao`.
    pub const AO_SAMPLES: u32 = 4;
    /// Occlusion distance of `ao` (0: a tenth of the scene's radius).
    pub const AO_DISTANCE: f32 = 0.0;
    /// Samples per pixel of a render that does not say.
    pub const SPP: u32 = 64;
    /// Samples per pixel of each progressive pass of a render that does
    /// not say.
    pub const PASS_SPP: u32 = 8;
}

impl Default for Integrator {
    fn default() -> Self {
        IntegratorKind::Path.into()
    }
}

/// The integrators by name, without their parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum IntegratorKind {
    /// [`Integrator::Path`].
    Path,
    /// [`Integrator::Distribution`].
    Distribution,
    /// [`Integrator::Bdpt`].
    Bdpt,
    /// [`Integrator::LightPath`].
    LightPath,
    /// [`Integrator::Sppm`].
    Sppm,
    /// [`Integrator::Normals`].
    Normals,
    /// [`Integrator::Depth`].
    Depth,
    /// [`Integrator::Ao`].
    Ao,
    /// [`Integrator::Cost`].
    Cost,
}

name_table!(IntegratorKind, "integrator", {
    IntegratorKind::Path => "path",
    IntegratorKind::Distribution => "distribution",
    IntegratorKind::Bdpt => "bdpt",
    IntegratorKind::LightPath => "lightpath",
    IntegratorKind::Sppm => "sppm",
    IntegratorKind::Normals => "normals",
    IntegratorKind::Depth => "depth",
    IntegratorKind::Ao => "ao",
    IntegratorKind::Cost => "cost",
});

impl IntegratorKind {
    /// The parameters of this kind, in the order
    /// [`Integrator::with_parameters`] takes them, with their defaults
    /// ([`defaults`]) and the values each takes. Scene files and the pbrt
    /// reader read an integrator's keys from this list: a new parameter is
    /// a change here, in `with_parameters` and in [`Integrator::parameters`].
    pub fn parameters(self) -> &'static [Parameter] {
        const MAX_DEPTH: Parameter = Parameter {
            name: "max_depth",
            default: defaults::MAX_DEPTH as f32,
            accepts: Accepts::WholeAtLeast(1),
        };
        const PATH: &[Parameter] = &[
            MAX_DEPTH,
            Parameter {
                name: "rr_depth",
                default: defaults::RR_DEPTH as f32,
                accepts: Accepts::WholeAtLeast(0),
            },
        ];
        const DISTRIBUTION: &[Parameter] = &[
            MAX_DEPTH,
            Parameter {
                name: "light_samples",
                default: defaults::LIGHT_SAMPLES as f32,
                accepts: Accepts::WholeAtLeast(1),
            },
        ];
        const SPPM: &[Parameter] = &[
            MAX_DEPTH,
            Parameter {
                name: "radius",
                default: 0.0,
                accepts: Accepts::AtLeast(0.0),
            },
            Parameter {
                name: "photons",
                default: 0.0,
                accepts: Accepts::WholeAtLeast(0),
            },
        ];
        const AO: &[Parameter] = &[
            Parameter {
                name: "samples",
                default: defaults::AO_SAMPLES as f32,
                accepts: Accepts::WholeAtLeast(1),
            },
            Parameter {
                name: "distance",
                default: defaults::AO_DISTANCE,
                accepts: Accepts::AtLeast(0.0),
            },
        ];
        match self {
            IntegratorKind::Path => PATH,
            IntegratorKind::Distribution => DISTRIBUTION,
            IntegratorKind::Bdpt | IntegratorKind::LightPath => &[MAX_DEPTH],
            IntegratorKind::Sppm => SPPM,
            IntegratorKind::Ao => AO,
            IntegratorKind::Normals | IntegratorKind::Depth | IntegratorKind::Cost => &[],
        }
    }
}

impl From<IntegratorKind> for Integrator {
    /// The integrator of that kind with the parameters of [`defaults`].
    fn from(kind: IntegratorKind) -> Self {
        let defaults: Vec<f32> = kind.parameters().iter().map(|p| p.default).collect();
        Integrator::with_parameters(kind, &defaults)
    }
}

impl Integrator {
    /// The integrator of `kind` with `values`, one for each of
    /// [`IntegratorKind::parameters`] in its order, each accepted by its
    /// [`Parameter::check`].
    ///
    /// # Panics
    /// If the number of values is not that of the kind's parameters.
    pub fn with_parameters(kind: IntegratorKind, values: &[f32]) -> Self {
        match (kind, values) {
            (IntegratorKind::Path, &[max_depth, rr_depth]) => Integrator::Path {
                max_depth: max_depth as u32,
                rr_depth: rr_depth as u32,
            },
            (IntegratorKind::Distribution, &[max_depth, light_samples]) => {
                Integrator::Distribution {
                    max_depth: max_depth as u32,
                    light_samples: light_samples as u32,
                }
            }
            (IntegratorKind::Bdpt, &[max_depth]) => Integrator::Bdpt {
                max_depth: max_depth as u32,
            },
            (IntegratorKind::LightPath, &[max_depth]) => Integrator::LightPath {
                max_depth: max_depth as u32,
            },
            (IntegratorKind::Sppm, &[max_depth, radius, photons]) => Integrator::Sppm {
                max_depth: max_depth as u32,
                radius,
                photons: photons as u32,
            },
            (IntegratorKind::Ao, &[samples, distance]) => Integrator::Ao {
                samples: samples as u32,
                distance,
            },
            (IntegratorKind::Normals, &[]) => Integrator::Normals,
            (IntegratorKind::Depth, &[]) => Integrator::Depth,
            (IntegratorKind::Cost, &[]) => Integrator::Cost,
            _ => panic!(
                "the {kind} integrator takes {} values, not {}",
                kind.parameters().len(),
                values.len()
            ),
        }
    }

    /// The values of its kind's [`IntegratorKind::parameters`], in order.
    pub fn parameters(&self) -> Vec<f32> {
        match *self {
            Integrator::Path {
                max_depth,
                rr_depth,
            } => vec![max_depth as f32, rr_depth as f32],
            Integrator::Distribution {
                max_depth,
                light_samples,
            } => vec![max_depth as f32, light_samples as f32],
            Integrator::Ao { samples, distance } => vec![samples as f32, distance],
            Integrator::Bdpt { max_depth } | Integrator::LightPath { max_depth } => {
                vec![max_depth as f32]
            }
            Integrator::Sppm {
                max_depth,
                radius,
                photons,
            } => vec![max_depth as f32, radius, photons as f32],
            Integrator::Normals | Integrator::Depth | Integrator::Cost => Vec::new(),
        }
    }
}

impl Integrator {
    /// Which integrator this is, without its parameters.
    pub fn kind(&self) -> IntegratorKind {
        match self {
            Integrator::Path { .. } => IntegratorKind::Path,
            Integrator::Distribution { .. } => IntegratorKind::Distribution,
            Integrator::Bdpt { .. } => IntegratorKind::Bdpt,
            Integrator::LightPath { .. } => IntegratorKind::LightPath,
            Integrator::Sppm { .. } => IntegratorKind::Sppm,
            Integrator::Normals => IntegratorKind::Normals,
            Integrator::Depth => IntegratorKind::Depth,
            Integrator::Ao { .. } => IntegratorKind::Ao,
            Integrator::Cost => IntegratorKind::Cost,
        }
    }

    /// The integrator called `name`, with the parameters of [`defaults`].
    pub fn named(name: &str) -> Result<Self, crate::names::UnknownName> {
        IntegratorKind::from_name(name).map(Self::from)
    }

    /// The integrator's name (its kind's, from the one name table).
    pub fn name(&self) -> &'static str {
        self.kind().name()
    }

    /// The largest number of scattering events of a light transport
    /// integrator whose paths are counted the same way (`path`, `bdpt`,
    /// `lightpath`, `sppm`: 1 is direct light); `None` for the others
    /// (`distribution` counts specular bounces only).
    pub fn path_length(&self) -> Option<u32> {
        match *self {
            Integrator::Path { max_depth, .. }
            | Integrator::Bdpt { max_depth }
            | Integrator::LightPath { max_depth }
            | Integrator::Sppm { max_depth, .. } => Some(max_depth),
            _ => None,
        }
    }

    /// This integrator with [`Self::path_length`] `n`, if it has one.
    pub fn with_path_length(mut self, n: u32) -> Self {
        match &mut self {
            Integrator::Path { max_depth, .. }
            | Integrator::Bdpt { max_depth }
            | Integrator::LightPath { max_depth }
            | Integrator::Sppm { max_depth, .. } => *max_depth = n,
            _ => {}
        }
        self
    }
}

/// Work counted while tracing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraceStats {
    /// Rays from the camera.
    pub camera_rays: u64,
    /// Rays after scattering.
    pub bounce_rays: u64,
    /// Occlusion rays.
    pub shadow_rays: u64,
    /// Kd-tree work of camera rays in the `cost` view.
    pub traversal: TraversalCounters,
    /// How the lane loop shaded its path vertices.
    pub lanes: LaneCounts,
}

impl std::ops::AddAssign for TraceStats {
    fn add_assign(&mut self, o: Self) {
        self.camera_rays += o.camera_rays;
        self.bounce_rays += o.bounce_rays;
        self.shadow_rays += o.shadow_rays;
        self.traversal += o.traversal;
        self.lanes += o.lanes;
    }
}

/// What an integrator needs for one pixel sample.
pub struct Context<'w, 'a> {
    /// The scene.
    pub world: &'w World<'a>,
    /// Sample dimensions.
    pub sampler: PixelSampler,
    /// Counters.
    pub stats: &'w mut TraceStats,
}

impl Integrator {
    /// Radiance along a camera ray at `time`, the ray queries answered one
    /// at a time (the render loop answers them in batches, with the same
    /// result bit for bit: see `wavefront`). The bidirectional integrators'
    /// light tracing contributions land elsewhere on the film: they are
    /// left out here (see [`Integrator::li_splats`]); so is the photons'
    /// part of SPPM's.
    pub fn li(&self, ctx: &mut Context, ray: &Ray, time: f32) -> Vec3 {
        self.li_splats(
            ctx,
            ray,
            time,
            Vec2::ONE,
            &mut Vec::new(),
            &mut AuxSample::default(),
        )
    }

    /// True for the integrators whose samples also add light elsewhere on
    /// the film ([`bdpt::Splat`]): the whole frame must be rendered for
    /// any pixel to be complete.
    pub fn splats(&self) -> bool {
        matches!(self, Integrator::Bdpt { .. } | Integrator::LightPath { .. })
    }

    /// [`Integrator::li`], with the light tracing contributions of the
    /// bidirectional integrators pushed to `splats` (`film`: the image's
    /// size in pixels), and what the denoiser is told recorded in `aux` by
    /// the volumetric path tracer (the other integrators that come here
    /// record none; the stepped ones record theirs in the render loop).
    pub(crate) fn li_splats(
        &self,
        ctx: &mut Context,
        ray: &Ray,
        time: f32,
        film: Vec2,
        splats: &mut Vec<bdpt::Splat>,
        aux: &mut AuxSample,
    ) -> Vec3 {
        ctx.stats.camera_rays += 1;
        match *self {
            Integrator::Bdpt { max_depth } => bdpt::sample(
                ctx,
                ray,
                time,
                max_depth,
                bdpt::Strategies::All,
                film,
                splats,
            ),
            Integrator::LightPath { max_depth } => bdpt::sample(
                ctx,
                ray,
                time,
                max_depth,
                bdpt::Strategies::LightTracing,
                film,
                splats,
            ),
            // The photons' part of the estimate needs a whole iteration
            // (the render loop's): one ray alone gets the light its
            // camera path finds directly.
            Integrator::Sppm { max_depth, .. } => {
                ctx.stats.camera_rays -= 1;
                sppm::camera_path(ctx, *ray, time, max_depth).0
            }
            Integrator::Path {
                max_depth,
                rr_depth,
            } if ctx.world.has_media() => volpath::li(ctx, ray, time, max_depth, rr_depth, aux),
            Integrator::Path { .. } | Integrator::Distribution { .. } => {
                let world = ctx.world;
                let mut st = PathState::new(*ray, time, ctx.sampler);
                let mut deferred = Vec::new();
                loop {
                    let hit = world.intersect(&st.ray, time);
                    let more = self.step(ctx, &mut st, hit, &mut deferred);
                    for d in deferred.drain(..) {
                        st.apply(&d.op, d.shadow.is_none_or(|q| world.visible(&q)));
                    }
                    if !more {
                        break;
                    }
                }
                st.l
            }
            Integrator::Normals => debug::normals(ctx, ray, time),
            Integrator::Depth => debug::depth(ctx, ray, time),
            Integrator::Ao { samples, distance } => {
                debug::ao(ctx, ray, time, samples.max(1), distance)
            }
            Integrator::Cost => debug::cost(ctx, ray, time),
        }
    }

    /// The bidirectional integrators' depth and strategies (the render
    /// loop traces their samples in batches, [`bdpt::batch`]); `None` for
    /// the others.
    pub(crate) fn bidirectional(&self) -> Option<(u32, bdpt::Strategies)> {
        match *self {
            Integrator::Bdpt { max_depth } => Some((max_depth, bdpt::Strategies::All)),
            Integrator::LightPath { max_depth } => {
                Some((max_depth, bdpt::Strategies::LightTracing))
            }
            _ => None,
        }
    }

    /// True for the integrators written as steps over path states (path
    /// and distribution), which the render loop traces in batches.
    pub(crate) fn is_stepped(&self) -> bool {
        matches!(
            self,
            Integrator::Path { .. } | Integrator::Distribution { .. }
        )
    }

    /// One step of a stepped integrator's path `st`, whose ray found `hit`;
    /// contributions waiting on shadow rays go to `out`. Returns whether
    /// the path goes on (with `st.ray`).
    #[inline]
    pub(crate) fn step(
        &self,
        ctx: &mut Context,
        st: &mut PathState,
        hit: Option<SurfaceHit>,
        out: &mut Vec<Deferred>,
    ) -> bool {
        ctx.sampler = st.sampler;
        match *self {
            Integrator::Path {
                max_depth,
                rr_depth,
            } => path::step(ctx, st, hit, max_depth, rr_depth, out),
            Integrator::Distribution {
                max_depth,
                light_samples,
            } => distribution::step(ctx, st, hit, max_depth, light_samples.max(1), out),
            _ => false,
        }
    }
}

/// The local shading setup at a hit: frame (normal-mapped), outgoing
/// direction, the BSDF with its textures looked up, emission.
pub(crate) struct Shading {
    pub frame: Frame,
    pub wo_world: Vec3,
    pub wo: Vec3,
    /// The BSDF at the hit.
    pub bsdf: PointBsdf,
    /// The factor on light arriving by indirect paths (painted occlusion).
    pub occlusion: f32,
    /// Radiance the surface emits towards `wo`.
    pub emitted: Vec3,
    /// The back of a one-sided material: it scatters nothing.
    pub blind: bool,
}

impl Shading {
    /// Shading at `hit` for a ray travelling along `dir`.
    #[inline]
    pub fn new(world: &World, hit: &SurfaceHit, dir: Vec3) -> Self {
        let material = world.material(hit.material);
        let uvs = hit.uvs();
        let fp = if material.has_textures() {
            world.uv_footprint(hit)
        } else {
            UvFootprint::POINT
        };
        let mut point = material.at(&uvs, &fp);
        let mapped = |m: Option<Vec3>, map: Option<&NormalMap>| match (m, map) {
            (Some(m), Some(map)) => {
                let (t, sign) = world.tangent(hit, map.map.uv_set);
                perturbed_normal(hit.ns, t, sign, m)
            }
            _ => hit.ns,
        };
        let ns = mapped(point.normal, material.textures.normal.as_ref());
        let frame = Frame::from_normal(ns);
        if let (Some(coat), Some(c)) = (&mut point.bsdf.coat, &material.clearcoat) {
            let n = mapped(point.coat_normal, c.normal_map.as_ref());
            *coat = coat.with_normal(frame.to_local(n));
        }
        let wo_world = -dir;
        let emitted = if material.is_emissive() {
            material.emitted(hit.ng.dot(wo_world), &uvs, &fp)
        } else {
            Vec3::ZERO
        };
        Self {
            frame,
            wo_world,
            wo: frame.to_local(wo_world),
            bsdf: point.bsdf,
            occlusion: point.occlusion,
            emitted,
            blind: material.is_blind_side(wo_world.dot(hit.ng)),
        }
    }

    /// True when `wi` leaves on a side the BSDF may scatter to: a reflector
    /// must not send light through its geometric surface (shading normals
    /// can suggest it; that would leak light).
    #[inline]
    pub fn side_ok(&self, hit: &SurfaceHit, wi: Vec3) -> bool {
        !self.bsdf.is_reflective_only() || wi.dot(hit.ng) * self.wo_world.dot(hit.ng) > 0.0
    }
}

impl Shading {
    /// The world direction of a sampled `wi`, or `None` if the path must
    /// end. A reflection that the shading normal sends below the geometric
    /// surface (at silhouettes of smooth-shaded meshes) is, for a delta
    /// lobe, folded back across the geometric plane, which keeps its energy
    /// (mirror spheres would otherwise show dark rims); other lobes end the
    /// path there, as their density for the folded direction is unknown.
    #[inline]
    pub fn scattered(&self, hit: &SurfaceHit, wi_local: Vec3, delta: bool) -> Option<Vec3> {
        let wi = self.frame.to_world(wi_local);
        if self.side_ok(hit, wi) {
            return Some(wi);
        }
        if !delta {
            return None;
        }
        let folded = (wi - 2.0 * wi.dot(hit.ng) * hit.ng).normalize();
        self.side_ok(hit, folded).then_some(folded)
    }

    /// The next bounce of a path at `hit`: the BSDF sampled with the
    /// sampler's dimensions of bounce `depth`, and the ray leaving along
    /// the sampled direction (counted as a bounce ray); `None` if the path
    /// ends there.
    pub fn sample_bounce(
        &self,
        ctx: &mut Context,
        hit: &SurfaceHit,
        depth: u32,
    ) -> Option<(BsdfSample, Ray)> {
        if self.blind {
            return None;
        }
        let u_lobe = ctx.sampler.get_1d(dims::bounce(depth, dims::BSDF_LOBE));
        let u = ctx.sampler.get_2d(dims::bounce(depth, dims::BSDF_DIR));
        let s = self.bsdf.sample(self.wo, u_lobe, u)?;
        let wi = self.scattered(hit, s.wi, s.delta)?;
        ctx.stats.bounce_rays += 1;
        Some((s, Ray::new(hit.spawn_origin(wi), wi)))
    }
}

/// The `light` field of [`dims::extra`] whose dimensions decide stochastic
/// transparency.
const PASS_THROUGH_DIMS: u32 = 0xfff;

/// If the surface of `hit` has a hole where `st`'s ray meets it, moves the
/// ray past it (same direction, same path vertex) and returns true.
pub(crate) fn pass_through(ctx: &Context, st: &mut PathState, hit: &SurfaceHit) -> bool {
    let m = ctx.world.material(hit.material);
    if !m.has_holes() || st.pass_throughs >= crate::world::MAX_PASS_THROUGHS {
        return false;
    }
    let u = ctx
        .sampler
        .get_1d(dims::extra(st.depth, PASS_THROUGH_DIMS, st.pass_throughs));
    if !m.passes(&hit.uvs(), u) {
        return false;
    }
    st.pass_throughs += 1;
    let dir = st.ray.dir;
    st.ray = Ray::new(hit.spawn_origin(dir), dir);
    true
}

/// If the surface of `hit` has a hole where `ray` meets it (the `holes`-th
/// the ray has passed), moves `ray` past it and counts it: the
/// bidirectional and photon integrators' [`pass_through`], whose draws are
/// a hash of the ray and the hit rather than sample dimensions.
pub(crate) fn through_hole(
    world: &World,
    ray: &mut Ray,
    hit: &SurfaceHit,
    holes: &mut u32,
) -> bool {
    let m = world.material(hit.material);
    if !m.has_holes()
        || *holes >= crate::world::MAX_PASS_THROUGHS
        || !m.passes(
            &hit.uvs(),
            crate::world::pass_through_draw(ray, hit, *holes),
        )
    {
        return false;
    }
    *holes += 1;
    *ray = Ray::new(hit.spawn_origin(ray.dir), ray.dir);
    true
}

/// Light leaving a light chosen by power: the light's index, the
/// emission, the throughput its ray carries (`Le cos / (pmf pdf_pos
/// pdf_dir)`), and the ray, off the emitting surface by a little more than
/// rounding (analytic spheres are tessellated inside the exact surface
/// sampled here). `dim(k)` is the sample dimension of decision `k`.
pub(crate) fn leave_light(
    ctx: &Context,
    dim: impl Fn(u32) -> u32,
) -> Option<(usize, f32, crate::light::emission::Emission, Vec3, Ray)> {
    let world = ctx.world;
    let (i, pmf) = world.pick_light(ctx.sampler.get_1d(dim(0)))?;
    let e = world.lights[i].sample_emission(
        ctx.sampler.get_2d(dim(1)),
        ctx.sampler.get_2d(dim(2)),
        world.center,
        world.radius,
    )?;
    let (cos, origin) = if e.n == Vec3::ZERO {
        (1.0, e.p)
    } else {
        (
            e.n.dot(e.dir).abs(),
            e.p + e.n * (1e-5 * e.p.abs().max_element().max(1.0)),
        )
    };
    let beta = e.le * (cos / (pmf * e.pdf_pos * e.pdf_dir));
    Some((i, pmf, e, beta, Ray::new(origin, e.dir)))
}

/// The environment's light reaching a path that leaves the scene along
/// `dir` with throughput `beta` (recorded in `aux` too), weighted against
/// light sampling by the power heuristic unless the last bounce was a
/// delta; `None` without an environment.
pub(crate) fn escaped(
    world: &World,
    aux: &mut AuxSample,
    dir: Vec3,
    beta: Vec3,
    prev_delta: bool,
    prev_pdf: f32,
) -> Option<Vec3> {
    if !world.has_environment() {
        return None;
    }
    let le = world.env_radiance(dir);
    aux.escape(le);
    let w = if prev_delta {
        1.0
    } else {
        crate::math::warp::power_heuristic(prev_pdf, world.env_pdf_mis(dir))
    };
    Some(beta * le * w)
}

/// Light from a light sample if nothing blocks it: `f |cos| Li` (not
/// divided by the pdf), the BSDF's density for the direction, and the
/// shadow ray that decides whether it arrives (counted); `None` if zero.
pub(crate) fn light_contribution(
    ctx: &mut Context,
    hit: &SurfaceHit,
    sh: &Shading,
    ls: &LightSample,
    time: f32,
) -> Option<(Vec3, f32, ShadowQuery)> {
    if sh.blind || !sh.side_ok(hit, ls.wi) {
        return None;
    }
    let wi = sh.frame.to_local(ls.wi);
    let e = sh.bsdf.eval(sh.wo, wi);
    let c = e.f * wi.z.abs() * ls.li;
    if c.max_element() <= 0.0 {
        return None;
    }
    ctx.stats.shadow_rays += 1;
    let shadow = ctx
        .world
        .shadow_query(hit.spawn_origin(ls.wi), ls.wi, ls.dist, time, ls.ignore);
    Some((c, e.pdf, shadow))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::Light;
    use crate::material::Material;
    use crate::sampler::{SampleId, SamplerKind};
    use crate::scene::camera::Camera;
    use crate::scene::shape::Shape;
    use crate::scene::Scene;
    use sahara_kd::AccelParams;

    /// Radiance seen at the centre of a quad whose back faces the camera
    /// and a point light beside the camera.
    fn back_radiance(material: Material) -> Vec3 {
        let cam = Camera::look_at(Vec3::new(0.0, 0.0, -3.0), Vec3::ZERO, Vec3::Y, 40.0, 1.0);
        let mut scene = Scene::new(cam);
        let m = scene.add_material(material);
        scene.add_shape(
            Shape::Quad {
                corner: Vec3::new(-1.0, -1.0, 0.0),
                edge_u: Vec3::new(2.0, 0.0, 0.0),
                edge_v: Vec3::new(0.0, 2.0, 0.0),
            },
            m,
        );
        scene.add_light(Light::point(Vec3::new(0.3, 0.0, -2.0), Vec3::splat(4.0)));
        let world = World::new(&scene, &AccelParams::default());
        let mut stats = TraceStats::default();
        let mut sum = Vec3::ZERO;
        for index in 0..16 {
            let sampler = PixelSampler::new(
                SamplerKind::Sobol,
                SampleId {
                    stream: 0,
                    pass: 0,
                    index,
                    count: 16,
                },
            );
            let mut ctx = Context {
                world: &world,
                sampler,
                stats: &mut stats,
            };
            let ray = Ray::new(Vec3::new(0.0, 0.0, -3.0), Vec3::Z);
            sum += Integrator::default().li(&mut ctx, &ray, 0.0);
        }
        sum / 16.0
    }

    #[test]
    fn one_sided_materials_are_black_from_behind() {
        let two = back_radiance(Material::diffuse(Vec3::splat(0.8)));
        assert!(two.min_element() > 0.1, "{two}");
        let one = back_radiance(Material::diffuse(Vec3::splat(0.8)).with_two_sided(false));
        assert_eq!(one, Vec3::ZERO);
        // Glass has two sides whatever the flag says.
        let glass = back_radiance(Material::glass(1.5).with_two_sided(false));
        let glass_two = back_radiance(Material::glass(1.5));
        assert_eq!(glass, glass_two);
    }

    /// A floor under a square whose left half is opaque and right half a
    /// hole (alpha 0 in its texture), lit from straight above; the world
    /// and radiance seen looking down at `x` on the floor.
    fn cut_out_scene(mode: crate::material::AlphaMode) -> Scene {
        use crate::texture::Texture;
        let cam = Camera::look_at(Vec3::new(0.0, 3.0, 0.0), Vec3::ZERO, Vec3::Z, 40.0, 1.0);
        let mut scene = Scene::new(cam);
        let floor = scene.add_material(Material::diffuse(Vec3::ONE));
        let texture = Texture::new(2, 1, vec![Vec3::ONE; 2]).with_alpha(vec![1.0, 0.0]);
        let leaf = scene.add_material(
            Material::diffuse(Vec3::ZERO)
                .with_texture(std::sync::Arc::new(texture))
                .with_alpha(mode, 1.0),
        );
        scene.add_shape(
            Shape::Quad {
                corner: Vec3::new(-2.0, 0.0, -2.0),
                edge_u: Vec3::new(0.0, 0.0, 4.0),
                edge_v: Vec3::new(4.0, 0.0, 0.0),
            },
            floor,
        );
        scene.add_shape(
            Shape::Quad {
                corner: Vec3::new(-1.0, 1.0, -1.0),
                edge_u: Vec3::new(2.0, 0.0, 0.0),
                edge_v: Vec3::new(0.0, 0.0, 2.0),
            },
            leaf,
        );
        scene.add_light(Light::directional(Vec3::new(0.0, -1.0, 0.0), Vec3::ONE));
        scene
    }

    fn radiance_down(world: &World, x: f32) -> Vec3 {
        let mut stats = TraceStats::default();
        let sampler = PixelSampler::new(
            SamplerKind::Sobol,
            SampleId {
                stream: 0,
                pass: 0,
                index: 0,
                count: 1,
            },
        );
        let mut ctx = Context {
            world,
            sampler,
            stats: &mut stats,
        };
        let ray = Ray::new(Vec3::new(x, 3.0, 0.0), -Vec3::Y);
        Integrator::named("path").unwrap().li(&mut ctx, &ray, 0.0)
    }

    #[test]
    fn a_cut_out_casts_the_cut_outs_shadow() {
        use crate::material::AlphaMode;
        let up = Vec3::Y;
        let on_floor = |x: f32| Vec3::new(x, 1e-3, 0.0);
        let opaque = cut_out_scene(AlphaMode::Opaque);
        let world = World::new(&opaque, &AccelParams::default());
        assert!(!world.unoccluded(on_floor(-0.5), up, f32::INFINITY, 0.0, None));
        assert!(!world.unoccluded(on_floor(0.5), up, f32::INFINITY, 0.0, None));
        assert_eq!(radiance_down(&world, 0.5), Vec3::ZERO);

        let mask = cut_out_scene(AlphaMode::Mask { cutoff: 0.5 });
        let world = World::new(&mask, &AccelParams::default());
        // The opaque half shadows the floor, the hole lets the light by.
        assert!(!world.unoccluded(on_floor(-0.5), up, f32::INFINITY, 0.0, None));
        assert!(world.unoccluded(on_floor(0.5), up, f32::INFINITY, 0.0, None));
        // Outside the square the floor is lit either way.
        assert!(world.unoccluded(on_floor(1.5), up, f32::INFINITY, 0.0, None));
        // Looking down: the black opaque half, the lit floor through the
        // hole (white Lambertian under unit irradiance: 1 / pi).
        assert_eq!(radiance_down(&world, -0.5), Vec3::ZERO);
        let through = radiance_down(&world, 0.5);
        assert!(
            (through - Vec3::splat(std::f32::consts::FRAC_1_PI))
                .abs()
                .max_element()
                < 1e-3,
            "{through}"
        );

        // Blend at opacity 1 on the left, 0 on the right: the same answers.
        let blend = cut_out_scene(AlphaMode::Blend);
        let world = World::new(&blend, &AccelParams::default());
        assert!(!world.unoccluded(on_floor(-0.5), up, f32::INFINITY, 0.0, None));
        assert!(world.unoccluded(on_floor(0.5), up, f32::INFINITY, 0.0, None));

        // Blend at a uniform opacity of 0.3: about 70 % of shadow rays
        // pass.
        let mut half = cut_out_scene(AlphaMode::Blend);
        half.materials[1].textures.base_color = None;
        half.materials[1].alpha = 0.3;
        let world = World::new(&half, &AccelParams::default());
        let n = 4000;
        let open = (0..n)
            .filter(|&i| {
                let x = -0.9 + 1.8 * (i as f32 + 0.5) / n as f32;
                world.unoccluded(on_floor(x), up, f32::INFINITY, 0.0, None)
            })
            .count();
        let f = open as f32 / n as f32;
        assert!((f - 0.7).abs() < 0.03, "{f}");
    }
}

#[cfg(test)]
mod parameter_tests {
    use super::*;

    /// Every kind's defaults make its integrator, and its values read back
    /// in the order of its parameter list.
    #[test]
    fn parameters_round_trip_through_the_list() {
        for &kind in IntegratorKind::ALL {
            let i = Integrator::from(kind);
            assert_eq!(i.kind(), kind);
            let values = i.parameters();
            assert_eq!(values.len(), kind.parameters().len());
            assert_eq!(Integrator::with_parameters(kind, &values), i);
            for (p, v) in kind.parameters().iter().zip(&values) {
                assert_eq!(p.check(*v), Ok(*v), "{kind} {}", p.name);
            }
        }
        assert_eq!(
            Integrator::from(IntegratorKind::Path),
            Integrator::Path {
                max_depth: defaults::MAX_DEPTH,
                rr_depth: defaults::RR_DEPTH
            }
        );
        let depth = IntegratorKind::Path.parameters()[0];
        assert!(depth.check(0.0).is_err() && depth.check(2.5).is_err());
        assert_eq!(depth.check(3.0), Ok(3.0));
    }
}
