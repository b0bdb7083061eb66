//! Pathological inputs cannot blow up a build's memory: the reference cap.

use glam::Vec3;
use sahara_kd::{brute, BuildParams, Builder, KdTree, Ray, Triangle};

/// Long thin triangles through the whole scene, crossing each other: every
/// split plane cuts nearly all of them, so each level would double the
/// references without a cap.
fn crossing_slivers(n: usize) -> Vec<Triangle> {
    let mut rng = crate::common::Rng(0xdead_beef);
    (0..n)
        .map(|_| {
            let a = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - Vec3::ONE;
            let d = rng.dir();
            Triangle::new(a - d * 10.0, a + d * 10.0, a + d * 10.0 + Vec3::splat(1e-3))
        })
        .collect()
}

#[test]
fn reference_cap_bounds_every_builder() {
    let tris = crossing_slivers(3000);
    let mut rng = crate::common::Rng(5);
    let rays: Vec<Ray> = (0..300)
        .map(|_| {
            Ray::new(
                Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 4.0 - Vec3::splat(2.0),
                rng.dir(),
            )
        })
        .collect();
    for b in Builder::ALL {
        let mut p = BuildParams::new(b);
        p.max_duplication = 8.0;
        let tree = KdTree::build(tris.clone(), &p);
        let s = tree.stats();
        assert!(
            s.references <= 8 * tris.len(),
            "{}: {} references for {} triangles",
            b.name(),
            s.references,
            tris.len()
        );
        // Capped trees are still exact.
        for r in &rays {
            let (want, got) = (brute::closest_hit(&tris, r), tree.closest_hit(r));
            assert_eq!(
                want.map(|h| (h.t.to_bits(), h.tri)),
                got.map(|h| (h.t.to_bits(), h.tri)),
                "{}",
                b.name()
            );
        }
    }
}
