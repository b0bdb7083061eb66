//! The path tracer's lane loop held to the scalar loop: images equal to
//! noise, on scenes with every BSDF the lanes shade (with their own
//! formulas, or lane by lane by the scalar BSDF) and with a clear coat,
//! which they hand to the scalar code.

use glam::Vec3;
use sahara_render::{
    builtin, Environment, Integrator, Light, Material, PathLoop, RenderResult, SamplerKind, Scene,
    Shape,
};

use crate::common::{run, settings};

/// The Cornell box with a glass, a rough metal, a mirror, a rough glass,
/// a metallic-roughness sphere (shaded lane by lane by its scalar BSDF)
/// and a clear-coated one (scalar shading), a point light and a dim sky.
fn scene() -> Scene {
    let mut s = builtin::cornell_box();
    let spheres = [
        (Material::glass(1.5), (150.0, 90.0, 150.0), 90.0),
        (
            Material::conductor(Vec3::new(0.9, 0.6, 0.3), 0.3),
            (400.0, 80.0, 380.0),
            80.0,
        ),
        (
            Material::mirror(Vec3::splat(0.9)),
            (300.0, 330.0, 330.0),
            50.0,
        ),
        (Material::rough_glass(1.4, 0.4), (420.0, 60.0, 120.0), 60.0),
        (
            Material::new(sahara_render::Bsdf::MetallicRoughness {
                base_color: Vec3::new(0.2, 0.7, 0.3),
                metallic: 0.3,
                roughness: 0.4,
                ior: 1.5,
                specular: 1.0,
                specular_color: Vec3::ONE,
            }),
            (130.0, 40.0, 400.0),
            40.0,
        ),
        (
            {
                let mut m = Material::diffuse(Vec3::new(0.6, 0.2, 0.2));
                m.clearcoat = Some(Box::new(sahara_render::Clearcoat::uniform(1.0, 0.1, 1.5)));
                m
            },
            (230.0, 35.0, 250.0),
            35.0,
        ),
    ];
    for (m, c, r) in spheres {
        let m = s.add_material(m);
        s.add_shape(
            Shape::Sphere {
                center: Vec3::new(c.0, c.1, c.2),
                radius: r,
            },
            m,
        );
    }
    s.add_light(Light::point(
        Vec3::new(278.0, 400.0, 100.0),
        Vec3::splat(2.0e4),
    ));
    s.environment = Some(Environment::Constant(Vec3::splat(0.05)));
    s
}

/// The linear image of `r`, its channels in one list.
fn values(r: &RenderResult) -> Vec<f64> {
    r.film
        .pixels
        .iter()
        .flat_map(|p| p.to_array())
        .map(|v| v as f64)
        .collect()
}

/// Mean and variance of `a - b`, value by value.
fn diff_stats(a: &[f64], b: &[f64]) -> (f64, f64) {
    let n = a.len() as f64;
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    let mean = d.iter().sum::<f64>() / n;
    let var = d.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
    (mean, var)
}

/// The lane loop's image against the scalar loop's, two ways.
///
/// With the same seed every sample draws the same random numbers in both
/// loops and follows the same path, so the images agree to rounding (the
/// lanes' polynomial sines and cosines): measured, no value differs by
/// more than 1e-4; a path that rounding sends across an edge may differ
/// wholly, so up to one value in a thousand may differ by more than
/// 1e-3 (relative above 1).
///
/// With other seeds the difference is noise alone: its mean must lie
/// within 4 standard errors `sqrt(v / n)` of zero, per channel and over
/// the image, where `v` is the variance of the difference of two scalar
/// images of other seeds. (The variance of the difference itself is no
/// test here: the glass and the point light make the noise heavy-tailed,
/// and the variance of scalar-against-scalar differences measured over
/// seed pairs spreads by 1.5x; the same-seed test is the sharper check
/// that the lanes add no noise.)
#[test]
fn lanes_render_the_scalar_image_to_noise() {
    let scene = scene();
    for sampler in [SamplerKind::Independent, SamplerKind::Sobol] {
        let render = |path_loop, seed| {
            let mut s = settings(48, 48, 16, Integrator::default());
            s.sampler = sampler;
            s.path_loop = path_loop;
            s.seed = seed;
            run(&scene, &s)
        };
        let lanes = render(PathLoop::Lanes, 11);
        let same = render(PathLoop::Scalar, 11);
        let scalar = [12, 13].map(|seed| render(PathLoop::Scalar, seed));
        // The coated sphere was shaded by the scalar code, everything
        // else in the lanes.
        let counts = lanes.stats.trace.lanes;
        assert!(counts.scalar_material > 0 && counts.lane_bounces > 20 * counts.scalar_material);
        let (l, s0, s1) = (values(&lanes), values(&scalar[0]), values(&scalar[1]));
        let n = l.len() as f64;
        let off = l
            .iter()
            .zip(&values(&same))
            .filter(|(a, b)| (*a - *b).abs() > 1e-3 * b.abs().max(1.0))
            .count();
        assert!(
            off as f64 <= 1e-3 * n,
            "{sampler:?}: {off} of {n} values of the lanes differ from the scalar loop's of the same seed"
        );
        let (noise_mean, noise_var) = diff_stats(&s0, &s1);
        let (mean, _) = diff_stats(&l, &s0);
        let se = (noise_var / n).sqrt();
        assert!(
            noise_mean.abs() < 4.0 * se,
            "{sampler:?}: scalar seeds {noise_mean} vs {se}"
        );
        assert!(
            mean.abs() < 4.0 * se,
            "{sampler:?}: lanes - scalar {mean}, standard error {se}"
        );
        for c in 0..3 {
            let pick = |v: &[f64]| v.iter().skip(c).step_by(3).copied().collect::<Vec<_>>();
            let (m, _) = diff_stats(&pick(&l), &pick(&s0));
            let (_, nv) = diff_stats(&pick(&s0), &pick(&s1));
            let se = (nv / (n / 3.0)).sqrt();
            assert!(m.abs() < 4.0 * se, "{sampler:?} channel {c}: {m} vs {se}");
        }
    }
}
