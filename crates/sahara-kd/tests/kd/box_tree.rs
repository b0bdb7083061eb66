//! Trees over boxes answer like a loop over all objects.

use glam::Vec3;
use sahara_kd::{Aabb, BoxTree, BuildParams, Builder, Ray};

/// Ray / sphere distance in `[tmin, tmax]` (the objects inside the boxes).
fn sphere_hit(c: Vec3, r: f32, ray: &Ray, tmax: f32) -> Option<f32> {
    let oc = ray.origin - c;
    let a = ray.dir.dot(ray.dir);
    let b = oc.dot(ray.dir);
    let disc = b * b - a * (oc.dot(oc) - r * r);
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    [(-b - s) / a, (-b + s) / a]
        .into_iter()
        .find(|&t| t >= ray.tmin && t <= tmax)
}

#[test]
fn box_tree_closest_and_any_match_a_loop() {
    let mut rng = crate::common::Rng(99);
    let spheres: Vec<(Vec3, f32)> = (0..300)
        .map(|_| {
            (
                Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 20.0,
                0.1 + rng.f32(),
            )
        })
        .collect();
    let boxes: Vec<Aabb> = spheres
        .iter()
        .map(|&(c, r)| Aabb::new(c - Vec3::splat(r), c + Vec3::splat(r)))
        .collect();
    for b in [Builder::Sah, Builder::Binned { bins: 16 }] {
        let tree = BoxTree::build(boxes.clone(), &BuildParams::new(b));
        let mut hits = 0;
        for _ in 0..3000 {
            let ray = Ray::new(
                Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 24.0 - Vec3::splat(2.0),
                rng.dir(),
            );
            let want = spheres
                .iter()
                .enumerate()
                .filter_map(|(i, &(c, r))| sphere_hit(c, r, &ray, ray.tmax).map(|t| (i as u32, t)))
                .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
            let got = tree.closest_with(&ray, |i, tmax| {
                let (c, r) = spheres[i as usize];
                sphere_hit(c, r, &ray, tmax)
            });
            assert_eq!(got, want, "{}: ray {ray:?}", b.name());
            let any = tree.any_with(&ray, |i| {
                let (c, r) = spheres[i as usize];
                sphere_hit(c, r, &ray, ray.tmax).is_some()
            });
            assert_eq!(any, want.is_some());
            hits += want.is_some() as u32;
        }
        assert!(hits > 300, "the test should exercise hits, got {hits}");
    }
}
