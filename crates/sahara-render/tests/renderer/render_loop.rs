//! The render loop and whole scenes: determinism, the Cornell box, no NaN
//! anywhere, progressive passes and cancellation, instancing.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

use crate::common::{run, settings};
use glam::{Affine3A, Quat, Vec3};
use sahara_kd::TriangleAccel;
use sahara_render::internals::World;
use sahara_render::{
    builtin, render, Camera, Environment, Filter, FilterKind, Instance, Integrator, Light,
    Material, PathLoop, SamplerKind, Scene, Shape, Srt, Texture,
};

fn render_in_pool(threads: usize, scene: &Scene, s: &sahara_render::RenderSettings) -> Vec<u32> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let r = pool.install(|| render(scene, s, &|_| {}).unwrap());
    r.film
        .pixels
        .iter()
        .flat_map(|p| p.to_array().map(f32::to_bits))
        .collect()
}

#[test]
fn same_seed_same_bits_whatever_the_thread_count() {
    let scene = builtin::cornell_box();
    for (sampler, path_loop) in [
        (SamplerKind::Sobol, PathLoop::Scalar),
        (SamplerKind::Stratified, PathLoop::Scalar),
        (SamplerKind::Independent, PathLoop::Scalar),
        (SamplerKind::Sobol, PathLoop::Lanes),
        (SamplerKind::Stratified, PathLoop::Lanes),
        (SamplerKind::Independent, PathLoop::LanesNoRefill),
    ] {
        let mut s = settings(24, 24, 4, Integrator::default());
        s.sampler = sampler;
        s.path_loop = path_loop;
        // A filter wider than a pixel and small tiles: samples cross tiles.
        s.filter = Filter::from(FilterKind::Mitchell);
        s.tile_size = 5;
        s.spp *= 2;
        let one = render_in_pool(1, &scene, &s);
        let two = render_in_pool(2, &scene, &s);
        assert!(
            one == two,
            "{sampler:?}: images differ between 1 and 2 threads"
        );
        s.seed += 1;
        let other = render_in_pool(2, &scene, &s);
        assert!(one != other, "{sampler:?}: the seed changes nothing");
    }
}

#[test]
fn cornell_box_has_red_left_and_green_right() {
    let scene = builtin::cornell_box();
    let r = run(&scene, &settings(32, 32, 16, Integrator::default()));
    // Halves: more red on the left, more green on the right.
    let left = r.film.mean(0, 0, 16, 32);
    let right = r.film.mean(16, 0, 32, 32);
    assert!(left.x > 1.1 * right.x, "red: left {left} right {right}");
    assert!(right.y > 1.1 * left.y, "green: left {left} right {right}");
    // The outer strips at mid height are the side walls themselves.
    let red = r.film.mean(0, 10, 4, 22);
    let green = r.film.mean(28, 10, 32, 22);
    assert!(
        red.x > 2.0 * red.y && red.x > 2.0 * red.z,
        "left wall {red}"
    );
    assert!(
        green.y > 1.5 * green.x && green.y > 1.5 * green.z,
        "right wall {green}"
    );
    // The light, seen directly at the top centre, is the brightest thing.
    let top = r.film.mean(14, 4, 18, 5);
    assert!(top.x > 5.0, "ceiling light {top}");
}

/// Every feature at once, through every integrator: never NaN, never
/// negative.
#[test]
fn no_nan_or_negative_anywhere() {
    let cam = Camera::look_at(Vec3::new(0.0, 2.0, -6.0), Vec3::ZERO, Vec3::Y, 50.0, 1.5)
        .with_thin_lens(0.05, 6.0)
        .with_shutter(0.0, 1.0);
    let mut scene = Scene::new(cam);
    let checker: Vec<Vec3> = (0..64)
        .map(|i| {
            if (i % 8 + i / 8) % 2 == 0 {
                Vec3::splat(0.9)
            } else {
                Vec3::splat(0.1)
            }
        })
        .collect();
    let tex = Arc::new(Texture::new(8, 8, checker));
    let floor = scene.add_material(Material::diffuse(Vec3::ONE).with_texture(tex));
    let glass = scene.add_material(Material::glass(1.5));
    let rough_glass = scene.add_material(Material::rough_glass(1.33, 0.4));
    let metal = scene.add_material(Material::conductor(Vec3::new(0.9, 0.6, 0.2), 0.2));
    let mirror = scene.add_material(Material::mirror(Vec3::splat(0.9)));
    let lamp = scene.add_material(Material::emitter(Vec3::new(5.0, 4.0, 3.0)));
    let mut glow = Material::diffuse(Vec3::splat(0.5)).with_emission(Vec3::splat(2.0));
    glow.two_sided_emission = true;
    let glow = scene.add_material(glow);
    scene.add_shape(
        Shape::Quad {
            corner: Vec3::new(-5.0, -1.0, -5.0),
            edge_u: Vec3::new(0.0, 0.0, 10.0),
            edge_v: Vec3::new(10.0, 0.0, 0.0),
        },
        floor,
    );
    scene.add_shape(
        Shape::Sphere {
            center: Vec3::new(-1.5, 0.0, 0.0),
            radius: 1.0,
        },
        glass,
    );
    scene.add_shape(
        Shape::Sphere {
            center: Vec3::new(1.5, 0.0, 0.0),
            radius: 1.0,
        },
        rough_glass,
    );
    scene.add_shape(
        Shape::Box {
            min: Vec3::new(-0.5, -1.0, 1.5),
            max: Vec3::new(0.5, 0.5, 2.5),
        },
        metal,
    );
    scene.add_shape(
        Shape::Disc {
            center: Vec3::new(0.0, 3.0, 0.0),
            normal: -Vec3::Y,
            radius: 0.5,
        },
        lamp,
    );
    scene.add_shape(
        Shape::Sphere {
            center: Vec3::new(2.5, 2.0, 2.0),
            radius: 0.3,
        },
        lamp,
    );
    scene.add_shape(
        Shape::Box {
            min: Vec3::new(-3.0, -1.0, 2.0),
            max: Vec3::new(-2.5, 0.0, 2.5),
        },
        glow,
    );
    let ball = scene.add_mesh(
        Shape::Sphere {
            center: Vec3::ZERO,
            radius: 0.4,
        }
        .to_mesh(),
    );
    scene.add_instance(Instance::moving(
        ball,
        Srt::translation(Vec3::new(0.0, 1.0, -1.0)),
        Srt {
            scale: Vec3::splat(1.5),
            rotation: Quat::from_rotation_y(1.0),
            translation: Vec3::new(0.8, 1.2, -1.0),
        },
        Some(mirror),
    ));
    scene.add_instance(Instance::moving(
        ball,
        Srt::translation(Vec3::new(-2.0, 2.0, 1.0)),
        Srt::translation(Vec3::new(-1.0, 2.0, 1.0)),
        Some(glow),
    ));
    scene.add_light(Light::point(Vec3::new(2.0, 3.0, -2.0), Vec3::splat(10.0)));
    scene.add_light(Light::spot(
        Vec3::new(-2.0, 3.0, -2.0),
        Vec3::ZERO,
        Vec3::splat(20.0),
        15.0,
        25.0,
    ));
    scene.add_light(Light::directional(
        Vec3::new(-1.0, -2.0, 1.0),
        Vec3::splat(0.5),
    ));
    let env: Vec<Vec3> = (0..32 * 16)
        .map(|i| Vec3::splat(((i * 7919) % 13) as f32 / 4.0))
        .collect();
    scene.environment = Some(Environment::Map {
        texture: Arc::new(Texture::new(32, 16, env)),
        scale: 0.3,
    });
    scene.validate().unwrap();
    for integrator in ["path", "distribution", "normals", "depth", "ao", "cost"] {
        let integrator = Integrator::named(integrator).unwrap();
        let mut s = settings(30, 20, 8, integrator);
        s.filter = Filter::from(FilterKind::Mitchell);
        let r = run(&scene, &s);
        let mean = r.film.mean(0, 0, 30, 20);
        assert!(mean.max_element() > 0.0, "{integrator:?}: black image");
        if integrator == Integrator::Cost {
            let c = r.cost.as_ref().unwrap();
            assert!(c
                .steps
                .iter()
                .zip(&c.tests)
                .all(|(a, b)| a.is_finite() && b.is_finite()));
            assert!(c.tests.iter().any(|&t| t > 0.0));
            assert!(r.stats.trace.traversal.triangles > 0);
        }
    }
}

#[test]
fn passes_stop_on_cancel_and_time_limit() {
    let scene = builtin::cornell_box();
    let mut s = settings(16, 16, 1, Integrator::default());
    s.spp *= 1_000_000;
    s.time_limit = Some(Duration::from_millis(150));
    let r = render(&scene, &s, &|_| {}).unwrap();
    assert!(r.stats.stopped_early && r.stats.passes >= 1 && r.stats.passes < 1_000_000);
    assert_eq!(r.stats.spp, r.stats.passes);
    assert!(r.film.mean(0, 0, 16, 16).x > 0.0);

    let cancel = Arc::new(AtomicBool::new(true));
    s.time_limit = None;
    s.cancel = Some(cancel);
    let r = render(&scene, &s, &|_| {}).unwrap();
    assert_eq!(r.stats.passes, 0);
    assert!(r.film.pixels.iter().all(|p| *p == Vec3::ZERO));

    // Progress reports every tile of every pass.
    let count = std::sync::atomic::AtomicU32::new(0);
    let mut s = settings(16, 16, 1, Integrator::default());
    s.spp *= 3;
    s.tile_size = 8;
    render(&scene, &s, &|p| {
        assert!(p.tiles_done <= p.tiles && p.pass < 3);
        count.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    })
    .unwrap();
    assert_eq!(count.into_inner(), 12);
}

#[test]
fn instances_share_one_tree() {
    let mut scene = Scene::new(Camera::look_at(
        Vec3::new(0.0, 0.0, -30.0),
        Vec3::ZERO,
        Vec3::Y,
        60.0,
        1.0,
    ));
    let m = scene.add_material(Material::diffuse(Vec3::ONE));
    let mesh = scene.add_mesh(
        Shape::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        }
        .to_mesh(),
    );
    for i in 0..100 {
        let t = Vec3::new(
            (i % 10) as f32 * 3.0 - 13.5,
            (i / 10) as f32 * 3.0 - 13.5,
            0.0,
        );
        scene.add_instance(Instance::new(mesh, Affine3A::from_translation(t), Some(m)));
    }
    let world = World::new(&scene, &Default::default());
    // A shared mesh is never merged into the world tree: one object-space
    // tree serves all hundred instances.
    assert_eq!(world.accel.tree_count(), 1);
    assert_eq!(world.accel.merged_count(), 0);
    assert_eq!(world.accel.two_level_count(), 100);
    let one = TriangleAccel::build(
        scene.meshes[mesh as usize].mesh.triangles(),
        &Default::default(),
    )
    .memory_bytes();
    assert_eq!(world.accel.tree_bytes(), one);
    // And all hundred are there: a lit render sees spheres everywhere.
    scene.environment = Some(Environment::Constant(Vec3::ONE));
    let r = run(&scene, &settings(40, 40, 1, Integrator::Normals));
    let hit = r.film.pixels.iter().filter(|p| p.length() > 0.0).count();
    assert!(hit > 300, "{hit} pixels see a sphere");
}

#[test]
fn an_interrupted_first_pass_keeps_the_pixels_it_finished() {
    let scene = builtin::cornell_box();
    let mut s = settings(16, 16, 8, Integrator::default());
    // A box filter: each pixel only gets its own samples, so a finished
    // pixel is the same whether its neighbours were rendered or not.
    s.filter = Filter::from(FilterKind::Box);
    s.tile_size = 4;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let full = pool.install(|| render(&scene, &s, &|_| {}).unwrap());
    assert_eq!(full.stats.first_pass_pixels, 0);

    // Cancel as the second tile finishes: on one thread tiles run in order,
    // so exactly the first two tiles (the top-left 8x4 pixels) are done.
    let cancel = Arc::new(AtomicBool::new(false));
    s.cancel = Some(cancel.clone());
    s.spp *= 3;
    let r = pool.install(|| {
        render(&scene, &s, &|p| {
            if p.tiles_done == 2 {
                cancel.store(true, std::sync::atomic::Ordering::SeqCst);
            }
        })
        .unwrap()
    });
    assert!(r.stats.stopped_early);
    assert_eq!(r.stats.passes, 0);
    assert_eq!(r.stats.first_pass_pixels, 32);
    assert_eq!(
        r.stats.spp, 8,
        "the finished pixels have the pass's samples"
    );
    for y in 0..16 {
        for x in 0..16 {
            let k = y * 16 + x;
            let (got, want) = (r.film.pixels[k], full.film.pixels[k]);
            if x < 8 && y < 4 {
                assert_eq!(
                    got.to_array().map(f32::to_bits),
                    want.to_array().map(f32::to_bits)
                );
                assert!(got != Vec3::ZERO);
            } else {
                assert_eq!(got, Vec3::ZERO, "pixel ({x}, {y}) was not rendered");
            }
        }
    }
}

#[test]
fn previews_come_between_passes_and_leave_the_image_unchanged() {
    let scene = builtin::cornell_box();
    let mut s = settings(12, 12, 1, Integrator::default());
    s.spp *= 4;
    let plain = render(&scene, &s, &|_| {}).unwrap();
    let mut seen = Vec::new();
    let watched = sahara_render::render_watched(
        &scene,
        &s,
        &|_| {},
        Some(sahara_render::Preview {
            every: Duration::ZERO,
            show: &mut |r| seen.push((r.stats.spp, r.film.mean(0, 0, 12, 12))),
        }),
    )
    .unwrap();
    // Passes 1 to 3; the image of pass 4 is the result itself.
    assert_eq!(
        seen.iter().map(|(spp, _)| *spp).collect::<Vec<_>>(),
        [1, 2, 3]
    );
    assert!(seen.iter().all(|(_, mean)| mean.x > 0.0));
    assert_eq!(watched.film.pixels, plain.film.pixels);
    assert_eq!(watched.stats.spp, 4);
}

#[test]
fn the_built_in_cornell_light_is_a_white_diffuser_that_emits() {
    // As in Mitsuba's Cornell box: the light panel reflects (diffuse 0.78)
    // besides emitting (17, 12, 4).
    let scene = builtin::cornell_box();
    let lights: Vec<_> = scene.materials.iter().filter(|m| m.is_emissive()).collect();
    assert_eq!(lights.len(), 1);
    assert_eq!(lights[0].emission, Vec3::new(17.0, 12.0, 4.0));
    assert_eq!(
        lights[0].bsdf,
        sahara_render::Bsdf::Diffuse {
            albedo: Vec3::splat(0.78)
        }
    );
}

/// The path tracer says where its threads' time went (tracing, shading,
/// the film, the rest), in shares that add up to one; integrators that do not trace in batches say nothing.
#[test]
fn the_time_split_covers_the_path_tracer_only() {
    let scene = builtin::cornell_box();
    let r = render(&scene, &settings(16, 16, 4, Integrator::default()), &|_| {}).unwrap();
    let split = r.stats.time_split;
    let shares = split.shares().expect("the path tracer measures its split");
    let (t, s, f, rest) = (shares.tracing, shares.shading, shares.film, shares.rest);
    assert!(t > 0.0 && s > 0.0 && f > 0.0 && rest >= 0.0, "{shares:?}");
    assert!((t + s + f + rest - 1.0).abs() < 1e-9, "{shares:?}");
    assert!(split.tracing + split.shading + split.film <= split.total);
    let ao = Integrator::Ao {
        samples: 1,
        distance: 0.0,
    };
    let r = render(&scene, &settings(16, 16, 4, ao), &|_| {}).unwrap();
    assert_eq!(r.stats.time_split.shares(), None);
}

/// A sphere before a wall, the auxiliary images asked for.
fn aux_scene() -> (Scene, sahara_render::RenderSettings) {
    let cam = Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, 40.0, 1.0);
    let mut scene = Scene::new(cam);
    let wall = scene.add_material(Material::diffuse(Vec3::new(0.3, 0.5, 0.7)));
    let ball = scene.add_material(Material::conductor(Vec3::new(0.9, 0.6, 0.2), 0.4));
    scene.add_shape(
        Shape::Quad {
            corner: Vec3::new(-20.0, -20.0, 8.0),
            edge_u: Vec3::new(0.0, 40.0, 0.0),
            edge_v: Vec3::new(40.0, 0.0, 0.0),
        },
        wall,
    );
    scene.add_shape(
        Shape::Sphere {
            center: Vec3::new(0.0, 0.0, 4.0),
            radius: 1.0,
        },
        ball,
    );
    scene.lights.push(Light::Point {
        position: Vec3::new(0.0, 3.0, 0.0),
        intensity: Vec3::splat(10.0),
    });
    let mut s = settings(16, 16, 8, Integrator::default());
    s.aovs = <sahara_render::Aov as sahara_render::Named>::ALL.to_vec();
    (scene, s)
}

/// The albedo, normal and depth images hold what each pixel sees: the
/// wall's colour, normal and distance at the corners, the sphere's at the
/// centre, within what averaging over the pixel's samples allows.
#[test]
fn aux_images_are_the_albedo_normal_and_depth_of_what_pixels_see() {
    let (scene, s) = aux_scene();
    let r = run(&scene, &s);
    let aux = r.aux.expect("asked for");
    let img = &aux.images;
    let at = |x: u32, y: u32| (y * 16 + x) as usize;
    // The ray through a pixel's centre.
    let centre_ray = |x: u32, y: u32| {
        let film = glam::Vec2::new((x as f32 + 0.5) / 16.0, (y as f32 + 0.5) / 16.0);
        scene
            .camera
            .generate_ray(film, glam::Vec2::splat(0.5), 0.5)
            .0
    };
    for (x, y) in [(0, 0), (15, 0), (0, 15), (15, 15)] {
        let k = at(x, y);
        assert!(
            (img.albedo[k] - Vec3::new(0.3, 0.5, 0.7))
                .abs()
                .max_element()
                < 1e-6
        );
        assert!(
            (img.normal[k] - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-5,
            "{}",
            img.normal[k]
        );
        let want = 8.0 / centre_ray(x, y).dir.z;
        assert!(
            (img.depth[k] / want - 1.0).abs() < 0.01,
            "{} vs {want}",
            img.depth[k]
        );
        // The wall's plane; the uv of a quad runs over [0, 1].
        assert!(
            (img.position[k].z - 8.0).abs() < 1e-4,
            "{}",
            img.position[k]
        );
        let p = centre_ray(x, y).at(want);
        assert!(
            (img.position[k] - p).length() < 0.05 * want,
            "{} vs {p}",
            img.position[k]
        );
        assert!(img.uv[k].min_element() >= 0.0 && img.uv[k].max_element() <= 1.0);
    }
    for (x, y) in [(7, 7), (8, 8), (7, 8)] {
        let k = at(x, y);
        assert!(
            (img.albedo[k] - Vec3::new(0.9, 0.6, 0.2))
                .abs()
                .max_element()
                < 1e-6
        );
        let ray = centre_ray(x, y);
        // The near intersection with the unit sphere at (0, 0, 4).
        let oc = ray.origin - Vec3::new(0.0, 0.0, 4.0);
        let b = oc.dot(ray.dir);
        let t = -b - (b * b - (oc.length_squared() - 1.0)).sqrt();
        let n = (ray.origin + t * ray.dir - Vec3::new(0.0, 0.0, 4.0)).normalize();
        assert!(
            (img.depth[k] / t - 1.0).abs() < 0.01,
            "{} vs {t}",
            img.depth[k]
        );
        assert!(
            (img.normal[k] - n).length() < 0.05,
            "{} vs {n}",
            img.normal[k]
        );
        let on_sphere = (img.position[k] - Vec3::new(0.0, 0.0, 4.0)).length();
        assert!((on_sphere - 1.0).abs() < 0.01, "{on_sphere}");
    }
    assert!(img.variance.iter().all(|v| v.min_element() >= 0.0));
    // Without the request, nothing is made.
    let mut plain = s.clone();
    plain.aovs.clear();
    assert!(run(&scene, &plain).aux.is_none());
}

/// The auxiliary sums are the same bits whatever the thread count, and
/// asking for them leaves the beauty image as it was.
#[test]
fn aux_sums_do_not_depend_on_threads_and_leave_the_image_alone() {
    let (scene, s) = aux_scene();
    let in_pool = |threads: usize, s: &sahara_render::RenderSettings| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render(&scene, s, &|_| {}).unwrap())
    };
    let (one, two) = (in_pool(1, &s), in_pool(2, &s));
    assert_eq!(
        one.aux.as_ref().unwrap().sums,
        two.aux.as_ref().unwrap().sums
    );
    let mut plain = s.clone();
    plain.aovs.clear();
    assert_eq!(in_pool(2, &plain).sums, two.sums);
}

/// The depth view and the depth pass average the distances of the samples
/// that hit: at a sphere's silhouette no pixel comes nearer than the
/// sphere's nearest point (misses are not averaged in as 0), and a pixel no
/// sample hit is 0.
#[test]
fn depth_never_mixes_misses_into_hits() {
    let cam = Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, 30.0, 1.0);
    let mut scene = Scene::new(cam);
    let m = scene.add_material(Material::diffuse(Vec3::splat(0.5)));
    scene.add_shape(
        Shape::Sphere {
            center: Vec3::new(0.0, 0.0, 5.0),
            radius: 1.0,
        },
        m,
    );
    scene.lights.push(Light::Point {
        position: Vec3::new(0.0, 3.0, 0.0),
        intensity: Vec3::splat(10.0),
    });
    let nearest = 4.0 - 1e-3;
    let farthest = (5.0f32 * 5.0 - 1.0).sqrt() + 1e-3;
    let check = |d: &[f32]| {
        let hit = d.iter().filter(|&&v| v > 0.0).count();
        assert!(hit > 0 && hit < d.len(), "{hit} of {}", d.len());
        for &v in d {
            assert!(v == 0.0 || (nearest..=farthest).contains(&v), "{v}");
        }
    };
    let r = run(&scene, &settings(24, 24, 8, Integrator::Depth));
    check(&r.film.pixels.iter().map(|p| p.x).collect::<Vec<_>>());
    let mut s = settings(24, 24, 8, Integrator::default());
    s.aovs = vec![sahara_render::Aov::Depth];
    let r = run(&scene, &s);
    let aux = r.aux.unwrap();
    check(&aux.images.depth);
    assert!(
        aux.images.albedo.is_empty() && aux.sums.albedo.is_none(),
        "not asked for"
    );
}

/// A pixel whose samples each see either an emitter of radiance `E` or
/// nothing has the variance of a coin: with mean `m` over `n` samples,
/// the sample variance is `(m E - m^2) n / (n - 1)`, that of the mean
/// `(m E - m^2) / (n - 1)`.
#[test]
fn the_variance_pass_is_that_of_the_pixels_mean() {
    let cam = Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, 30.0, 1.0);
    let mut scene = Scene::new(cam);
    let e = Vec3::new(2.0, 1.0, 0.5);
    let m = scene.add_material(Material::emitter(e));
    scene.add_shape(
        Shape::Sphere {
            center: Vec3::new(0.0, 0.0, 5.0),
            radius: 1.0,
        },
        m,
    );
    let n = 16;
    let mut s = settings(24, 24, n, Integrator::default());
    s.aovs = vec![sahara_render::Aov::Variance];
    let r = run(&scene, &s);
    let variance = &r.aux.as_ref().unwrap().images.variance;
    let mut edge = 0;
    for (k, v) in variance.iter().enumerate() {
        let mean = r.film.pixels[k];
        let want = (mean * e - mean * mean) / (n - 1) as f32;
        assert!(
            (*v - want).abs().max_element() <= 1e-5 * e.max_element().powi(2),
            "{v} vs {want}"
        );
        edge += (v.x > 0.0) as usize;
    }
    assert!(edge > 10, "{edge} pixels on the silhouette");
}
