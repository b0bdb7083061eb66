//! Watertightness: rays never slip between the triangles of closed meshes,
//! through the kd-tree of every builder and through brute force.

use glam::Vec3;
use sahara_kd::validate;
use sahara_kd::{brute, BuildParams, Builder, KdTree, Ray, Triangle};

fn trees(tris: &[Triangle]) -> Vec<(String, KdTree)> {
    Builder::ALL
        .iter()
        .map(|&b| {
            let tree = KdTree::build(tris.to_vec(), &BuildParams::new(b));
            validate(&tree, tris).unwrap_or_else(|e| panic!("{}: {e}", b.name()));
            (b.name(), tree)
        })
        .collect()
}

/// Rays from inside a closed mesh, in every direction, must hit it.
fn assert_no_escape(tris: &[Triangle], inside: &[Vec3], rays_per_point: usize) {
    let mut rng = crate::common::Rng(0x9e37_79b9_7f4a_7c15);
    let trees = trees(tris);
    let mut escaped = 0;
    for &o in inside {
        for _ in 0..rays_per_point {
            let ray = Ray::new(o, rng.dir());
            assert!(
                brute::any_hit(tris, &ray),
                "brute force: ray {ray:?} escaped"
            );
            for (name, tree) in &trees {
                if tree.closest_hit(&ray).is_none() || !tree.any_hit(&ray) {
                    escaped += 1;
                    eprintln!("{name}: ray {ray:?} escaped");
                }
            }
        }
    }
    assert_eq!(escaped, 0);
}

#[test]
fn no_ray_escapes_a_tessellated_sphere() {
    let c = Vec3::new(0.25, -0.5, 1.0);
    let tris = crate::common::uv_sphere(c, 2.0, 24, 48);
    let inside = [
        c,
        c + Vec3::new(0.5, 0.3, -0.2),
        c + Vec3::new(0.0, 1.2, 0.0),
        c - Vec3::new(1.1, 0.0, 0.9),
    ];
    assert_no_escape(&tris, &inside, 4000);
}

#[test]
fn no_ray_escapes_a_subdivided_cube() {
    let tris = crate::common::subdivided_cube(-1.0, 1.0, 8);
    // The centre lies on the middle split planes of every naive tree.
    let inside = [
        Vec3::ZERO,
        Vec3::new(0.5, 0.25, -0.75),
        Vec3::new(-0.99, 0.0, 0.5),
    ];
    assert_no_escape(&tris, &inside, 4000);
}

#[test]
fn rays_at_shared_vertices_and_edges_always_hit() {
    // Grid points of the cube's faces are exactly representable, so these
    // rays pass exactly through shared vertices and along shared edges.
    let n = 8;
    let tris = crate::common::subdivided_cube(-1.0, 1.0, n);
    let trees = trees(&tris);
    let coord = |i: usize| -1.0 + 2.0 * i as f32 / n as f32;
    let mut targets = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            targets.push(Vec3::new(1.0, coord(i), coord(j))); // vertices on the +x face
            if j < n {
                // Midpoints of edges, exactly representable too.
                targets.push(Vec3::new(-1.0, coord(i), (coord(j) + coord(j + 1)) * 0.5));
            }
        }
    }
    let origins = [
        Vec3::ZERO,
        Vec3::new(0.3, -0.1, 0.2),
        Vec3::new(5.0, 0.25, 0.5),
        Vec3::new(-4.0, 3.0, 2.0),
    ];
    let mut misses = 0;
    for o in origins {
        for &p in &targets {
            let ray = Ray::new(o, p - o);
            // From outside, the target can be on the far side; any hit will do
            // as long as the ray meets the cube at its target.
            let want = brute::closest_hit(&tris, &ray);
            assert!(want.is_some(), "brute force: ray {ray:?} slipped through");
            for (name, tree) in &trees {
                let got = tree.closest_hit(&ray);
                if got.map(|h| (h.t.to_bits(), h.tri)) != want.map(|h| (h.t.to_bits(), h.tri)) {
                    misses += 1;
                    eprintln!("{name}: ray {ray:?}: tree {got:?} brute {want:?}");
                }
            }
        }
    }
    assert_eq!(misses, 0);
}

#[test]
fn a_ray_through_a_shared_edge_hits_one_of_its_triangles() {
    // Two triangles sharing the diagonal of the unit square, hit exactly on
    // the diagonal from many origins: never a gap.
    let a = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0));
    let b = Triangle::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::Y);
    let tris = [a, b];
    let mut rng = crate::common::Rng(7);
    for i in 0..10_000 {
        let s = (i as f32 + 0.5) / 10_000.0;
        let target = Vec3::new(s, s, 0.0);
        let origin = target + Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, 0.5 + rng.f32());
        let ray = Ray::new(origin, target - origin);
        assert!(
            brute::any_hit(&tris, &ray),
            "ray {ray:?} slipped through the shared edge"
        );
    }
}
