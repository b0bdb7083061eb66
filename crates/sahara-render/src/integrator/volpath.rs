//! Volumetric path tracing: unidirectional path tracing through
//! participating media ([`crate::medium`]), which `path` becomes in a
//! scene with media.
//!
//! Along each ray the path samples where its medium scatters it
//! ([`Medium::free_flight`]): before the next surface, the path
//! scatters there by the medium's phase function, with next-event
//! estimation towards one light; beyond it, the surface is shaded as the
//! path tracer shades it. Light from a light sample and from a found
//! emitter are weighted against each other by the power heuristic, as in
//! `path`; shadow rays carry the transmittance of every medium they cross
//! and pass index-matched boundaries, which change the medium without
//! bending or scattering light. Every ray leaves its vertex in the medium
//! on the side it leaves to: the interface of the surface decides, by the
//! side of its geometric normal. An emitting medium adds its light along
//! every segment of the path that crosses it, estimated by the same
//! free-flight sample, at every bounce (the segment after the last
//! scattering included).
//!
//! Paths are traced one at a time (not in the render loop's batches): the
//! media's cost stays in the scenes that have them.

use glam::Vec3;
use sahara_kd::Ray;

use super::path::roulette;
use super::{escaped, light_contribution, through_hole, AuxSample, Context, Shading};
use crate::light::LightSample;
use crate::math::warp::power_heuristic;
use crate::medium::Medium;
use crate::sampler::{dims, PixelSampler};
use crate::world::{pass_through_draw, ShadowQuery, SurfaceHit, World, MAX_PASS_THROUGHS};

/// The `light` fields of [`dims::extra`] whose dimensions sample distances
/// in media along a path's rays, and estimate transmittance along its
/// shadow rays: a run of draws per bounce (two per segment in a
/// homogeneous medium, two per tentative collision in a grid).
const MEDIUM_DIMS: u32 = 0xffe;
const SHADOW_MEDIUM_DIMS: u32 = 0xffd;

/// The sampler's dimensions `field` of bounce `depth`, one after the
/// other.
fn draws(sampler: PixelSampler, depth: u32, field: u32) -> impl FnMut() -> f32 {
    let mut k = 0u32;
    move || {
        let u = sampler.get_1d(dims::extra(depth, field, k));
        k += 1;
        u
    }
}

/// Index-matched boundaries a path or a shadow ray passes at most (a
/// ray trapped between coincident boundaries ends there).
const MAX_CROSSINGS: u32 = 256;

/// Radiance along a camera ray at `time` through the scene's media;
/// `max_depth` counts scattering events at surfaces and in media alike.
/// What the denoiser is told goes to `aux` (if open): the first surface
/// that is not a perfect mirror or smooth glass, or the first scattering
/// in a medium before it, whichever comes first; index-matched boundaries
/// are not surfaces to it.
///
/// One loop on purpose: the path's state (ray, medium, throughput, the
/// last scattering for MIS, boundaries crossed) passes from event to
/// event (a scattering in a medium, a boundary, a hole, a surface), and
/// each event's work is in the functions below.
pub(crate) fn li(
    ctx: &mut Context,
    ray: &Ray,
    time: f32,
    max_depth: u32,
    rr_depth: u32,
    aux: &mut AuxSample,
) -> Vec3 {
    let world = ctx.world;
    let camera = ray.origin;
    let mut l = Vec3::ZERO;
    let mut beta = Vec3::ONE;
    let mut ray = *ray;
    let mut medium = world.scene.camera_medium;
    let mut depth = 0u32;
    // Index-matched boundaries and holes passed.
    let (mut crossings, mut holes) = (0u32, 0u32);
    // The distances in media of the current bounce's rays.
    let mut flights = draws(ctx.sampler, 0, MEDIUM_DIMS);
    // The last scattering event: whether it was a delta lobe (the camera
    // counts as one: emitters it sees count fully), its density for the
    // direction taken, and where it was.
    // The last scattering: whether by a delta lobe, its density, its point
    // and the shading normal there (zero in a medium).
    let (mut prev_delta, mut prev_pdf, mut prev_p, mut prev_n) =
        (true, 0.0f32, ray.origin, Vec3::ZERO);
    let mut occlusion = 1.0f32;
    loop {
        let hit = world.intersect(&ray, time);
        if let Some(m) = medium {
            let m = world.medium(m);
            let t_max = hit.map_or(f32::INFINITY, |h| h.t);
            let flight = m.free_flight(ray.origin, ray.dir, t_max, &mut flights);
            // What the medium emits along the segment arrives with the
            // throughput so far. Light sampling never picks a medium, so
            // this is the only estimate of it: no MIS weight.
            if flight.emitted != Vec3::ZERO {
                l += beta * flight.emitted;
            }
            beta *= flight.weight;
            if beta == Vec3::ZERO {
                break;
            }
            if flight.scattered {
                if depth >= max_depth {
                    break;
                }
                let p = ray.origin + ray.dir * flight.t;
                aux.medium(m.albedo(p), p, (depth == 0).then(|| (p - camera).length()));
                l += beta * medium_light(ctx, m, p, ray.dir, medium, time, depth);
                let (wi, pdf) = m.phase().sample(
                    ray.dir,
                    ctx.sampler.get_2d(dims::bounce(depth, dims::BSDF_DIR)),
                );
                ctx.stats.bounce_rays += 1;
                (prev_delta, prev_pdf, prev_p, prev_n) = (false, pdf, p, Vec3::ZERO);
                ray = Ray::new(p, wi);
                depth += 1;
                flights = draws(ctx.sampler, depth, MEDIUM_DIMS);
                if !roulette(ctx, &mut beta, depth, rr_depth) {
                    break;
                }
                continue;
            }
        }
        let Some(hit) = hit else {
            if let Some(le) = escaped(world, aux, ray.dir, beta, prev_delta, prev_pdf) {
                l += le;
            }
            break;
        };
        let interface = world.medium_interface(hit.instance).copied();
        if let Some(mi) = interface.filter(|mi| mi.index_matched) {
            // A boundary of media only: the ray goes on into the medium
            // beyond, at the same vertex of the path.
            if crossings >= MAX_CROSSINGS {
                break;
            }
            crossings += 1;
            medium = mi.medium_along(hit.ng, ray.dir);
            ray = Ray::new(hit.spawn_origin(ray.dir), ray.dir);
            continue;
        }
        if through_hole(world, &mut ray, &hit, &mut holes) {
            continue;
        }
        let sh = Shading::new(world, &hit, ray.dir);
        if depth == 0 && aux.open && crossings + holes > 0 {
            // The camera ray went on past boundaries and holes: its first
            // hit's distance is from the camera, not from the last of them.
            aux.surface(&sh, &hit, ray.dir, 0);
            aux.depth = (hit.p - camera).length();
        } else {
            aux.surface(&sh, &hit, ray.dir, depth);
        }
        if sh.emitted != Vec3::ZERO {
            let w = if prev_delta {
                1.0
            } else {
                emitter_weight(world, prev_pdf, (prev_p, prev_n), &hit, ray.dir)
            };
            l += beta * sh.emitted * w;
        }
        // What reaches the last vertex by more than one scattering passes
        // its painted occlusion.
        beta *= std::mem::replace(&mut occlusion, 1.0);
        if depth >= max_depth {
            break;
        }
        let leaving = |dir: Vec3| interface.map_or(medium, |mi| mi.medium_along(hit.ng, dir));
        if !sh.bsdf.is_delta() {
            l += surface_light(ctx, &hit, &sh, beta, time, depth, &leaving);
        }
        let Some((s, next)) = sh.sample_bounce(ctx, &hit, depth) else {
            break;
        };
        beta *= s.weight;
        occlusion = sh.occlusion;
        medium = leaving(next.dir);
        (prev_delta, prev_pdf, prev_p, prev_n) = (s.delta, s.pdf, hit.p, hit.ns);
        ray = next;
        depth += 1;
        flights = draws(ctx.sampler, depth, MEDIUM_DIMS);
        if !roulette(ctx, &mut beta, depth, rr_depth) {
            break;
        }
    }
    l
}

/// The power heuristic's weight of an emitter that a path found at `hit`
/// along `dir` by scattering at `prev` (point and shading normal, zero in
/// a medium) with density `prev_pdf`, against light sampling from there.
fn emitter_weight(
    world: &World,
    prev_pdf: f32,
    prev: (Vec3, Vec3),
    hit: &SurfaceHit,
    dir: Vec3,
) -> f32 {
    let lp = world.light_pdf(prev.0, prev.1, hit, dir);
    // Emitters that light sampling never picks are found by scattering
    // alone: weight 1.
    if lp > 0.0 {
        power_heuristic(prev_pdf, lp)
    } else {
        1.0
    }
}

/// Next-event estimation at a surface: light from one light reflected
/// by the surface `sh` of `hit` at bounce `depth`, through the media
/// (`leaving(wi)`: the medium a ray towards `wi` starts in), weighted
/// against BSDF sampling by the power heuristic, times the path's
/// throughput `beta`.
fn surface_light(
    ctx: &mut Context,
    hit: &SurfaceHit,
    sh: &Shading,
    beta: Vec3,
    time: f32,
    depth: u32,
    leaving: &dyn Fn(Vec3) -> Option<u32>,
) -> Vec3 {
    let world = ctx.world;
    let u_pick = ctx.sampler.get_1d(dims::bounce(depth, dims::LIGHT_PICK));
    let u = ctx.sampler.get_2d(dims::bounce(depth, dims::LIGHT_POINT));
    let Some((ls, pmf)) = world.sample_light_mis(hit.p, hit.ns, u_pick, u) else {
        return Vec3::ZERO;
    };
    let Some((c, bsdf_pdf, shadow)) = light_contribution(ctx, hit, sh, &ls, time) else {
        return Vec3::ZERO;
    };
    let mut draw = draws(ctx.sampler, depth, SHADOW_MEDIUM_DIMS);
    let tr = transmittance(world, &shadow, leaving(ls.wi), &mut draw);
    if tr == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let (w, light_pdf) = light_weight(&ls, pmf, bsdf_pdf);
    beta * c * tr * (w / light_pdf)
}

/// The power heuristic's weight of light sample `ls` (chosen with
/// probability `pmf`) against scattering's density `other_pdf` for its
/// direction (1 for a delta light), and the sample's whole density.
fn light_weight(ls: &LightSample, pmf: f32, other_pdf: f32) -> (f32, f32) {
    let light_pdf = pmf * ls.pdf;
    let w = if ls.delta {
        1.0
    } else {
        power_heuristic(light_pdf, other_pdf)
    };
    (w, light_pdf)
}

/// Light arriving at `p` in medium `m` (index `medium`) from one light
/// chosen as the world chooses, scattered by the phase function towards `-w_in`
/// (light travelling along `w_in` scatters at `p`), weighted against
/// phase sampling by the power heuristic; not yet times the path's
/// throughput.
fn medium_light(
    ctx: &mut Context,
    m: &Medium,
    p: Vec3,
    w_in: Vec3,
    medium: Option<u32>,
    time: f32,
    depth: u32,
) -> Vec3 {
    let world = ctx.world;
    let u_pick = ctx.sampler.get_1d(dims::bounce(depth, dims::LIGHT_PICK));
    let u = ctx.sampler.get_2d(dims::bounce(depth, dims::LIGHT_POINT));
    let Some((ls, pmf)) = world.sample_light_mis(p, Vec3::ZERO, u_pick, u) else {
        return Vec3::ZERO;
    };
    let f = m.phase().eval(w_in, ls.wi);
    if f <= 0.0 || ls.pdf <= 0.0 || ls.li.max_element() <= 0.0 {
        return Vec3::ZERO;
    }
    ctx.stats.shadow_rays += 1;
    let shadow = world.shadow_query(p, ls.wi, ls.dist, time, ls.ignore);
    let tr = transmittance(
        world,
        &shadow,
        medium,
        &mut draws(ctx.sampler, depth, SHADOW_MEDIUM_DIMS),
    );
    if tr == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let (w, light_pdf) = light_weight(&ls, pmf, f);
    ls.li * tr * (f * w / light_pdf)
}

/// The fraction of light that crosses the segment of `q`, starting in
/// `medium`: the product of the media's transmittances over the pieces
/// between the index-matched boundaries it passes, zero if any other
/// surface (but `q`'s ignored one, and holes it passes through) blocks it.
pub(crate) fn transmittance(
    world: &World,
    q: &ShadowQuery,
    medium: Option<u32>,
    draw: &mut dyn FnMut() -> f32,
) -> Vec3 {
    let mut piece = |m: Option<u32>, ray: &Ray, d: f32| {
        m.map_or(Vec3::ONE, |m| {
            world.medium(m).transmittance(ray.origin, ray.dir, d, draw)
        })
    };
    let mut tr = Vec3::ONE;
    let mut ray = q.ray;
    let mut medium = medium;
    let mut passed = 0u32;
    for k in 0..MAX_CROSSINGS + MAX_PASS_THROUGHS {
        let Some(h) = world.intersect(&ray, q.time) else {
            return tr * piece(medium, &ray, ray.tmax);
        };
        tr *= piece(medium, &ray, h.t);
        if Some(h.instance) != q.ignore {
            match world.medium_interface(h.instance) {
                Some(mi) if mi.index_matched => medium = mi.medium_along(h.ng, ray.dir),
                _ => {
                    let m = world.material(h.material);
                    if !m.has_holes()
                        || passed >= MAX_PASS_THROUGHS
                        || !m.passes(&h.uvs(), pass_through_draw(&ray, &h, k))
                    {
                        return Vec3::ZERO;
                    }
                    passed += 1;
                }
            }
        }
        if tr == Vec3::ZERO {
            return tr;
        }
        let origin = h.spawn_origin(ray.dir);
        let travelled = (origin - ray.origin).dot(ray.dir) / ray.dir.length_squared();
        ray = Ray::with_interval(origin, ray.dir, 0.0, ray.tmax - travelled);
        if ray.tmax.is_nan() || ray.tmax <= 0.0 {
            return tr;
        }
    }
    Vec3::ZERO
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::filter::Filter;
    use crate::integrator::Integrator;
    use crate::light::environment::Environment;
    use crate::material::Material;
    use crate::medium::{DensityGrid, GridMedium, MediumInterface};
    use crate::render::{render, RenderSettings};
    use crate::scene::camera::Camera;
    use crate::scene::shape::Shape;
    use crate::scene::Scene;
    use crate::settings::FrameSettings;

    /// Fills the inside of `instance`'s closed surface with `medium`, the
    /// surface only bounding it.
    fn fill(scene: &mut Scene, instance: u32, medium: Medium) {
        let m = scene.add_medium(medium);
        scene.set_medium_interface(
            instance,
            MediumInterface {
                inside: Some(m),
                outside: None,
                index_matched: true,
            },
        );
    }

    /// The mean pixel of a `size`² render of `scene` at `spp`, path traced
    /// to `max_depth` without Russian roulette, box filtered.
    fn mean(scene: &Scene, size: u32, spp: u32, max_depth: u32) -> Vec3 {
        mean_seeded(scene, size, spp, max_depth, 7)
    }

    /// [`mean`] with the sampler's `seed`.
    fn mean_seeded(scene: &Scene, size: u32, spp: u32, max_depth: u32, seed: u64) -> Vec3 {
        let settings = RenderSettings::from(FrameSettings {
            width: size,
            height: size,
            spp,
            seed,
            filter: Filter::Box { radius: 0.5 },
            integrator: Integrator::Path {
                max_depth,
                rr_depth: max_depth,
            },
            ..Default::default()
        });
        let r = render(scene, &settings, &|_| {}).unwrap();
        assert_eq!(r.stats.nan_samples, 0);
        r.film.pixels.iter().copied().sum::<Vec3>() / r.film.pixels.len() as f32
    }

    /// The render passes of a scene with media: a diffuse wall seen
    /// through a box of medium (an index-matched boundary, 1 to 6 in
    /// front of the camera). Through an empty medium, the passes are the
    /// wall's, as without the box (the distance from the camera, not from
    /// the boundary); through a dense one, every first event is a
    /// scattering in it: the medium's albedo σs / σt, a zero normal, a
    /// distance within the box.
    #[test]
    fn render_passes_record_the_first_surface_or_the_first_scattering() {
        use crate::render::{Aov, AuxImages};
        let passes = |medium: Option<Medium>| -> AuxImages {
            let cam = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 20.0, 1.0);
            let mut scene = Scene::new(cam);
            scene.add_light(crate::light::Light::Directional {
                direction: -Vec3::Z,
                irradiance: Vec3::ONE,
            });
            let wall = scene.add_material(Material::diffuse(Vec3::new(0.2, 0.4, 0.6)));
            scene.add_shape(
                Shape::Quad {
                    corner: Vec3::new(-20.0, -20.0, -2.0),
                    edge_u: Vec3::new(40.0, 0.0, 0.0),
                    edge_v: Vec3::new(0.0, 40.0, 0.0),
                },
                wall,
            );
            if let Some(medium) = medium {
                let bound = scene.add_material(Material::diffuse(Vec3::ONE));
                let b = scene.add_shape(
                    Shape::Box {
                        min: Vec3::new(-20.0, -20.0, -1.0),
                        max: Vec3::new(20.0, 20.0, 4.0),
                    },
                    bound,
                );
                fill(&mut scene, b, medium);
            }
            let settings = RenderSettings {
                frame: FrameSettings {
                    width: 8,
                    height: 8,
                    spp: 4,
                    ..Default::default()
                },
                aovs: vec![Aov::Albedo, Aov::Normal, Aov::Depth],
                ..RenderSettings::default()
            };
            render(&scene, &settings, &|_| {})
                .unwrap()
                .aux
                .unwrap()
                .images
        };
        let bare = passes(None);
        let clear = passes(Some(Medium::homogeneous(Vec3::ZERO, Vec3::ZERO, 0.0)));
        assert_eq!(clear.albedo, bare.albedo);
        assert_eq!(clear.normal, bare.normal);
        for (a, b) in clear.depth.iter().zip(&bare.depth) {
            assert!(
                (a - b).abs() < 1e-5 * b,
                "depth {a} through the box, {b} without"
            );
        }
        let sigma_s = Vec3::new(25.0, 50.0, 50.0);
        let sigma_a = Vec3::new(25.0, 0.0, 0.0);
        let dense = passes(Some(Medium::homogeneous(sigma_a, sigma_s, 0.0)));
        for k in 0..dense.albedo.len() {
            let a = dense.albedo[k];
            assert!(
                (a - Vec3::new(0.5, 1.0, 1.0)).abs().max_element() < 1e-6,
                "{a}"
            );
            assert_eq!(dense.normal[k], Vec3::ZERO);
            assert!(
                dense.depth[k] > 1.0 && dense.depth[k] < 1.5,
                "{}",
                dense.depth[k]
            );
        }
    }

    /// An absorbing slab of thickness 2 between the camera and an emitter
    /// that fills the view: what arrives is the emitter's radiance times
    /// exp(-σa 2) per channel. Each sample passes (weight Tr / mean(Tr))
    /// or not, so the mean of N samples has a relative standard deviation
    /// of sqrt((1 - p) / (p N)) with p = mean(Tr) = 0.174: 0.85 % at
    /// 32² x 64 samples; the tolerance is four of those.
    #[test]
    fn a_slab_transmits_exp_minus_sigma_t_d_per_channel() {
        // A narrow view: every ray crosses the slab within 1e-4 of
        // straight through.
        let cam = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0);
        let mut scene = Scene::new(cam);
        let light = scene.add_material(Material::emitter(Vec3::ONE));
        scene.add_shape(
            Shape::Quad {
                corner: Vec3::new(-20.0, -20.0, -5.0),
                edge_u: Vec3::new(40.0, 0.0, 0.0),
                edge_v: Vec3::new(0.0, 40.0, 0.0),
            },
            light,
        );
        let glass = scene.add_material(Material::diffuse(Vec3::ONE));
        let slab = scene.add_shape(
            Shape::Box {
                min: Vec3::new(-20.0, -20.0, -1.0),
                max: Vec3::new(20.0, 20.0, 1.0),
            },
            glass,
        );
        let sigma_a = Vec3::new(0.5, 1.0, 2.0);
        fill(
            &mut scene,
            slab,
            Medium::homogeneous(sigma_a, Vec3::ZERO, 0.0),
        );
        let got = mean(&scene, 32, 64, 4);
        let want = Vec3::new((-1.0f32).exp(), (-2.0f32).exp(), (-4.0f32).exp());
        let rel = ((got - want) / want).abs().max_element();
        assert!(rel < 0.034, "got {got}, want {want}");
    }

    /// A white furnace: a sphere of non-absorbing medium (isotropic and
    /// strongly forward scattering; homogeneous, a grid's blob, and
    /// pbrt's noise cloud) under
    /// a uniform environment of radiance 1, bounded by an index-matched
    /// sphere. Every path ends in the
    /// environment, so every pixel's expected value is 1, with and
    /// without next-event estimation's share. The image mean's standard
    /// deviation over six seeds is 0.13 %; the tolerance is 0.6 %.
    #[test]
    fn a_white_furnace_stays_white() {
        let blob = |g: f32| {
            // A smooth blob of density over the sphere's bounding cube.
            let n = 16;
            let mut v = Vec::new();
            for z in 0..n {
                for y in 0..n {
                    for x in 0..n {
                        let p = (Vec3::new(x as f32, y as f32, z as f32) + 0.5) / n as f32 - 0.5;
                        v.push((1.0 - 4.0 * p.length_squared()).max(0.0) * 3.0);
                    }
                }
            }
            Medium::Grid(Box::new(GridMedium::new(
                DensityGrid::new([n; 3], v).unwrap(),
                Vec3::ZERO,
                Vec3::ONE,
                crate::medium::HenyeyGreenstein::new(g),
                glam::Affine3A::from_scale_rotation_translation(
                    Vec3::splat(2.0),
                    glam::Quat::IDENTITY,
                    Vec3::splat(-1.0),
                ),
            )))
        };
        let media = [
            Medium::homogeneous(Vec3::ZERO, Vec3::splat(2.0), 0.0),
            Medium::homogeneous(Vec3::ZERO, Vec3::splat(2.0), 0.7),
            blob(0.0),
            blob(0.7),
            // pbrt-v4's noise cloud over the sphere's bounding cube.
            Medium::Cloud(Box::new(crate::medium::CloudMedium::new(
                Vec3::ZERO,
                Vec3::splat(4.0),
                crate::medium::HenyeyGreenstein::new(0.7),
                1.0,
                1.0,
                5.0,
                (Vec3::ZERO, Vec3::ONE),
                glam::Affine3A::from_scale_rotation_translation(
                    Vec3::splat(2.0),
                    glam::Quat::IDENTITY,
                    Vec3::splat(-1.0),
                ),
            ))),
        ];
        for (k, medium) in media.into_iter().enumerate() {
            let cam = Camera::look_at(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 40.0, 1.0);
            let mut scene = Scene::new(cam);
            scene.environment = Some(Environment::Constant(Vec3::ONE));
            let mat = scene.add_material(Material::diffuse(Vec3::splat(0.5)));
            let ball = scene.add_shape(
                Shape::Sphere {
                    center: Vec3::ZERO,
                    radius: 1.0,
                },
                mat,
            );
            fill(&mut scene, ball, medium);
            let got = mean(&scene, 24, 32, 256);
            assert!(
                (got - Vec3::ONE).abs().max_element() < 0.006,
                "medium {k}: {got}"
            );
        }
    }

    /// Single scattering in a slab of thickness h lit from straight above
    /// by a directional light of irradiance E and seen from straight
    /// above: light scattered once at depth s has crossed s on the way
    /// down and s on the way up, so
    /// `L = σs E p ∫ exp(-2 σt s) ds = σs E (1 - exp(-2 σt h)) / (8 π σt)`
    /// with the isotropic p = 1 / (4π), per channel (a coloured medium:
    /// the channels' extinctions differ, which the spectral sampling must
    /// weigh). One scattering event only (`max_depth` 1). The image
    /// mean's relative deviation over six seeds is at most 0.4 %; the
    /// tolerance is 1.5 %.
    #[test]
    fn single_scattering_in_a_slab_matches_the_closed_form() {
        let cam = Camera::look_at(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, Vec3::Z, 1.0, 1.0);
        let mut scene = Scene::new(cam);
        let e = Vec3::splat(10.0);
        scene.add_light(crate::light::Light::Directional {
            direction: -Vec3::Y,
            irradiance: e,
        });
        let mat = scene.add_material(Material::diffuse(Vec3::ONE));
        let h = 1.0;
        let slab = scene.add_shape(
            Shape::Box {
                min: Vec3::new(-50.0, 0.0, -50.0),
                max: Vec3::new(50.0, h, 50.0),
            },
            mat,
        );
        let (sigma_a, sigma_s) = (Vec3::new(0.5, 0.2, 0.0), Vec3::new(0.3, 1.0, 2.5));
        fill(&mut scene, slab, Medium::homogeneous(sigma_a, sigma_s, 0.0));
        let got = mean(&scene, 24, 64, 1);
        let sigma_t = sigma_a + sigma_s;
        let want = sigma_s * e * (Vec3::ONE - (-2.0 * sigma_t * h).exp())
            / (8.0 * std::f32::consts::PI * sigma_t);
        let rel = ((got - want) / want).abs().max_element();
        assert!(rel < 0.015, "got {got}, want {want}");
    }

    /// An absorbing slab of thickness 2 that emits, seen head-on against
    /// black: each channel's radiance is `Le (1 - exp(-σa d))` (the
    /// emission `σa Le` per unit length, attenuated by `exp(-σa t)` from
    /// depth t). Over six seeds the image mean's largest relative
    /// deviation from it is 0.49 %; the tolerance is 1.5 %.
    #[test]
    fn an_emitting_slab_glows_by_its_absorption() {
        let cam = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0);
        let mut scene = Scene::new(cam);
        let mat = scene.add_material(Material::diffuse(Vec3::ONE));
        let slab = scene.add_shape(
            Shape::Box {
                min: Vec3::new(-20.0, -20.0, -1.0),
                max: Vec3::new(20.0, 20.0, 1.0),
            },
            mat,
        );
        let sigma_a = Vec3::new(0.2, 1.0, 2.0);
        let le = Vec3::new(1.0, 2.0, 0.5);
        fill(
            &mut scene,
            slab,
            Medium::homogeneous(sigma_a, Vec3::ZERO, 0.0).with_emission(le),
        );
        let want = le * (Vec3::ONE - (-2.0 * sigma_a).exp());
        let got = mean(&scene, 32, 64, 4);
        let rel = ((got - want) / want).abs().max_element();
        assert!(rel < 0.015, "got {got}, want {want}");
    }

    /// Inside an unbounded medium that absorbs, scatters and emits `Le`
    /// (and nothing else in the scene), the radiance is `Le` everywhere
    /// and in every direction: what a stretch absorbs, it emits again,
    /// whatever the scattering coefficient or the phase function. A
    /// coloured medium (the channels' extinctions and albedos differ) and
    /// a forward-scattering one; homogeneous, and a grid whose density
    /// varies (its emission follows its absorption, so the balance holds
    /// point by point) over a box too deep for paths to leave. Paths end
    /// after n = 40 (and 2) scatterings, so what arrives is
    /// `Le (1 - α^(n+1))` per channel (α = σs / σt, the same at every density): the emission of
    /// the 41 segments of each path, the last one included. Over six
    /// seeds the largest relative deviation of the image mean from it is
    /// 0.62 %; the tolerance is 2 %.
    #[test]
    fn an_emitting_medium_is_in_equilibrium_at_its_emission() {
        let sigma_a = Vec3::new(0.5, 1.0, 0.2);
        let sigma_s = Vec3::new(1.0, 0.5, 2.0);
        let le = Vec3::new(1.0, 0.5, 2.0);
        // The grid's blue scatters less: spectral tracking's weights vary
        // with how far a channel's albedo is from the others', and at 0.91
        // against 0.67 and 0.33 blue's spread over seeds is 5 %.
        let grid_sigma_s = Vec3::new(1.0, 0.5, 0.8);
        let grid = |g: f32| {
            let n = 12;
            let mut v = Vec::new();
            for z in 0..n {
                for y in 0..n {
                    for x in 0..n {
                        let p = (Vec3::new(x as f32, y as f32, z as f32) + 0.5) / n as f32 - 0.5;
                        v.push(1.0 + (p.x * 20.0).sin() * (p.y * 13.0).cos() * 0.7);
                    }
                }
            }
            Medium::Grid(Box::new(GridMedium::new(
                DensityGrid::new([n; 3], v).unwrap(),
                sigma_a,
                grid_sigma_s,
                crate::medium::HenyeyGreenstein::new(g),
                glam::Affine3A::from_scale_rotation_translation(
                    Vec3::splat(100.0),
                    glam::Quat::IDENTITY,
                    Vec3::splat(-50.0),
                ),
            )))
            .with_emission(le)
        };
        let media = [
            Medium::homogeneous(sigma_a, sigma_s, 0.0).with_emission(le),
            Medium::homogeneous(sigma_a, sigma_s, 0.8).with_emission(le),
            grid(0.0),
            grid(0.8),
        ];
        for (k, medium) in media.into_iter().enumerate() {
            let sigma_s = if k < 2 { sigma_s } else { grid_sigma_s };
            let cam = Camera::look_at(Vec3::ZERO, -Vec3::Z, Vec3::Y, 60.0, 1.0);
            let mut scene = Scene::new(cam);
            scene.camera_medium = Some(scene.add_medium(medium));
            let albedo = sigma_s / (sigma_a + sigma_s);
            // Up to 40 scatterings, and (where the last segment's share
            // is large) up to 2.
            for depth in [40, 2] {
                let want = le * (Vec3::ONE - albedo.powf(depth as f32 + 1.0));
                let got = mean(&scene, 16, 32, depth);
                let rel = ((got - want) / want).abs().max_element();
                assert!(
                    rel < 0.02,
                    "medium {k}, depth {depth}: got {got}, want {want}"
                );
            }
        }
    }
}
