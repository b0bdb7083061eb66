//! The brute-force oracle: every query answered by testing every triangle
//! (every hittable one: see [`Triangle::is_hittable`]).
//!
//! It uses the same watertight test and the same tie-breaking as the tree
//! (smallest `t`, then smallest triangle index), so a correct tree returns
//! bit-identical answers.

use crate::isect::{Hit, RayShear};
use crate::math::{Ray, Triangle};

/// The closest hit among all finite triangles.
pub fn closest_hit(triangles: &[Triangle], ray: &Ray) -> Option<Hit> {
    if !ray.is_valid() {
        return None;
    }
    let shear = RayShear::from_ray(ray);
    let mut best: Option<Hit> = None;
    let mut best_t = ray.tmax;
    for (i, tri) in triangles.iter().enumerate() {
        if !tri.is_hittable() {
            continue;
        }
        if let Some(h) = shear.intersect(tri, ray.tmin, best_t) {
            if best.is_none_or(|b| h.t < b.t) {
                best_t = h.t;
                best = Some(Hit {
                    t: h.t,
                    tri: i as u32,
                    u: h.u,
                    v: h.v,
                });
            }
        }
    }
    best
}

/// True if any finite triangle is hit.
pub fn any_hit(triangles: &[Triangle], ray: &Ray) -> bool {
    if !ray.is_valid() {
        return false;
    }
    let shear = RayShear::from_ray(ray);
    triangles
        .iter()
        .any(|tri| tri.is_hittable() && shear.intersect(tri, ray.tmin, ray.tmax).is_some())
}

/// Every hit with `t` in `(ray.tmin, ray.tmax]`, each triangle once,
/// ordered by `t`, then by triangle index.
pub fn all_hits(triangles: &[Triangle], ray: &Ray) -> Vec<Hit> {
    if !ray.is_valid() {
        return Vec::new();
    }
    let shear = RayShear::from_ray(ray);
    let mut hits: Vec<Hit> = triangles
        .iter()
        .enumerate()
        .filter(|(_, tri)| tri.is_hittable())
        .filter_map(|(i, tri)| {
            shear.intersect(tri, ray.tmin, ray.tmax).map(|h| Hit {
                t: h.t,
                tri: i as u32,
                u: h.u,
                v: h.v,
            })
        })
        .collect();
    hits.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.tri.cmp(&b.tri)));
    hits
}
