//! The light choice of next-event estimation: the light tree, power and
//! uniform sampling render the same image (each unbiased), block by block
//! within the noise each image's two halves measure.

use glam::{Affine3A, Vec3};
use sahara_render::{
    Camera, Environment, Integrator, Light, LightSampler, Material, Medium, RenderResult, Scene,
    Shape,
};

use crate::common::{path, run, settings};

/// A room-sized floor with a wall and a block, lit by many lights of
/// every kind the tree holds: small emitting spheres and quads (one- and
/// two-sided, facing every way) of differing power, an emitting box (a
/// mesh light, each triangle its own light in the tree), point and spot
/// lights, and a dim sky beside them.
fn many_lights() -> Scene {
    let cam = Camera::look_at(
        Vec3::new(0.0, 3.0, -7.0),
        Vec3::new(0.0, 0.5, 0.0),
        Vec3::Y,
        50.0,
        1.0,
    );
    let mut scene = Scene::new(cam);
    let white = scene.add_material(Material::diffuse(Vec3::splat(0.7)));
    scene.add_shape(
        Shape::Quad {
            corner: Vec3::new(-6.0, 0.0, -6.0),
            edge_u: Vec3::new(0.0, 0.0, 12.0),
            edge_v: Vec3::new(12.0, 0.0, 0.0),
        },
        white,
    );
    scene.add_shape(
        Shape::Quad {
            corner: Vec3::new(-6.0, 0.0, 4.0),
            edge_u: Vec3::new(12.0, 0.0, 0.0),
            edge_v: Vec3::new(0.0, 4.0, 0.0),
        },
        white,
    );
    scene.add_shape(
        Shape::Box {
            min: Vec3::new(-1.0, 0.0, -0.5),
            max: Vec3::new(0.5, 1.2, 1.0),
        },
        white,
    );
    let mut s = 0x9e37_79b9_u32;
    let mut r = move || {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        s as f32 / u32::MAX as f32
    };
    for i in 0..40 {
        let p = Vec3::new(8.0 * r() - 4.0, 0.3 + 3.0 * r(), 7.0 * r() - 3.0);
        let le = Vec3::new(1.0 + r(), 1.0, 1.0 + r()) * 10f32.powf(2.0 * r()) * 0.5;
        let mut m = Material::emitter(le);
        if i % 2 == 1 {
            let id = scene.add_material(m);
            let radius = 0.05 + 0.1 * r();
            scene.add_shape(Shape::Sphere { center: p, radius }, id);
        } else {
            m.two_sided_emission = i % 4 == 0;
            let id = scene.add_material(m);
            let n = Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize();
            let u = n.any_orthonormal_vector() * 0.3;
            scene.add_shape(
                Shape::Quad {
                    corner: p,
                    edge_u: u,
                    edge_v: n.cross(u),
                },
                id,
            );
        }
    }
    let glow = scene.add_material(Material::emitter(Vec3::new(2.0, 1.5, 1.0)));
    let cube = Shape::Box {
        min: Vec3::new(2.0, 0.0, 1.0),
        max: Vec3::new(2.4, 0.4, 1.4),
    };
    scene.add_object(cube.to_mesh(), Affine3A::IDENTITY, glow);
    scene.add_light(Light::point(Vec3::new(-3.0, 2.5, 2.0), Vec3::splat(3.0)));
    scene.add_light(Light::spot(
        Vec3::new(2.0, 3.5, -1.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::splat(20.0),
        15.0,
        25.0,
    ));
    scene.environment = Some(Environment::Constant(Vec3::splat(0.05)));
    scene
}

/// Mean of each 6 x 6 block of pixels, per channel.
fn blocks(r: &RenderResult) -> Vec<Vec3> {
    let (w, h) = (r.film.width, r.film.height);
    let mut out = Vec::new();
    for by in (0..h).step_by(6) {
        for bx in (0..w).step_by(6) {
            out.push(r.film.mean(bx, by, (bx + 6).min(w), (by + 6).min(h)));
        }
    }
    out
}

/// Seeds rendered per image: the spread of their blocks measures the
/// noise.
const SEEDS: u64 = 4;

/// Renders `scene` with `sampler` once per seed at `spp`: the blocks of
/// the average (grey, the mean of the channels), and the variance of that
/// average per block measured from the seeds' spread.
fn render_seeds(
    scene: &Scene,
    integrator: Integrator,
    spp: u32,
    sampler: LightSampler,
) -> Vec<(f64, f64)> {
    let runs: Vec<Vec<f64>> = (1..=SEEDS)
        .map(|seed| {
            let mut s = settings(48, 48, spp, integrator);
            s.seed = seed;
            s.light_sampler = sampler;
            blocks(&run(scene, &s))
                .iter()
                .map(|b| f64::from(b.element_sum()) / 3.0)
                .collect()
        })
        .collect();
    let n = SEEDS as f64;
    (0..runs[0].len())
        .map(|k| {
            let mean = runs.iter().map(|r| r[k]).sum::<f64>() / n;
            let var = runs.iter().map(|r| (r[k] - mean).powi(2)).sum::<f64>() / (n - 1.0);
            (mean, var / n)
        })
        .collect()
}

/// Asserts two estimators agree: the whole image's mean within 4.5
/// standard errors of the difference (from the blocks' measured noise,
/// summed over many blocks, so the error is well known), and block by
/// block z = difference over its standard error: pure noise gives a
/// median z^2 near 0.45 (for a t statistic of a few degrees of freedom a
/// little more) and few blocks far out; a bias of a few per cent gives
/// neither.
fn assert_same_image(what: &str, a: &[(f64, f64)], b: &[(f64, f64)]) {
    let diff: f64 = a.iter().zip(b).map(|(x, y)| x.0 - y.0).sum();
    let var: f64 = a.iter().zip(b).map(|(x, y)| x.1 + y.1).sum();
    let z = diff / var.sqrt();
    assert!(
        z.abs() < 4.5,
        "{what}: image means differ by {z} standard errors"
    );
    let mut z2: Vec<f64> = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x.0 - y.0).powi(2) / (x.1 + y.1).max(1e-20))
        .collect();
    z2.sort_by(f64::total_cmp);
    let median = z2[z2.len() / 2];
    let far = z2.iter().filter(|&&z| z > 36.0).count();
    assert!(median < 1.2, "{what}: median z^2 {median}");
    assert!(
        far * 20 <= z2.len(),
        "{what}: {far} blocks beyond 6 standard errors"
    );
}

#[test]
fn the_light_tree_renders_the_image_power_and_uniform_sampling_render() {
    let scene = many_lights();
    let power = render_seeds(&scene, path(3), 256, LightSampler::Power);
    let tree = render_seeds(&scene, path(3), 256, LightSampler::Tree);
    assert_same_image("tree vs power", &tree, &power);
    let uniform = render_seeds(&scene, path(3), 256, LightSampler::Uniform);
    assert_same_image("uniform vs power", &uniform, &power);
    // The tree's image is the cleaner one: less variance over the blocks.
    let var = |v: &[(f64, f64)]| v.iter().map(|x| x.1).sum::<f64>();
    assert!(
        var(&tree) < var(&power),
        "{} vs {}",
        var(&tree),
        var(&power)
    );
}

#[test]
fn in_fog_the_light_tree_renders_the_image_power_sampling_renders() {
    let mut scene = many_lights();
    let fog = scene.add_medium(Medium::homogeneous(
        Vec3::splat(0.02),
        Vec3::splat(0.08),
        0.3,
    ));
    scene.camera_medium = Some(fog);
    // With media the path tracer takes its volumetric steps (points in
    // the fog have no normal for the tree to weigh).
    let volpath = path(3);
    let power = render_seeds(&scene, volpath, 128, LightSampler::Power);
    let tree = render_seeds(&scene, volpath, 128, LightSampler::Tree);
    assert_same_image("volpath: tree vs power", &tree, &power);
}
