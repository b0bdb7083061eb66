//! [`Accel`] against a brute-force oracle over every instance's triangles,
//! in scenes mixing merged meshes, shared meshes, moving instances and
//! ignorable instances; and its batch and packet forms against its
//! single-ray form.

use glam::{Affine3A, Quat, Vec3};
use sahara_kd::{brute, AccelParams, BuildParams, NoCounters, Ray, Triangle, PACKET16};

/// Both structures, the hierarchy (the default) and the kd-tree.
fn structures() -> [AccelParams; 2] {
    [
        AccelParams::default(),
        AccelParams::kd(BuildParams::default()),
    ]
}

use super::{Accel, BatchBuffers, RawHit};
use crate::scene::instance::{Instance, Placement, Srt};
use crate::scene::mesh::SceneMesh;
use crate::scene::shape::Shape;

/// A small deterministic generator (xorshift).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    fn vec(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.next(), self.next(), self.next()) * (hi - lo) + Vec3::splat(lo)
    }
}

/// A mixed scene, with `shared` instances of one shared sphere mesh:
/// merged static meshes (one placed by a rotation, scale and
/// translation), a mesh shared by several instances, one of them exactly
/// on top of a merged mesh's triangles (ties), a moving instance, and an
/// ignorable instance (index returned).
fn scene(shared: usize) -> (Vec<SceneMesh>, Vec<Instance>, Vec<u32>) {
    let sphere = |r: f32| {
        Shape::Sphere {
            center: Vec3::ZERO,
            radius: r,
        }
        .to_mesh()
    };
    let boxed = Shape::Box {
        min: Vec3::splat(-0.5),
        max: Vec3::splat(0.5),
    }
    .to_mesh();
    let floor = Shape::Quad {
        corner: Vec3::new(-4.0, -1.0, -4.0),
        edge_u: Vec3::new(0.0, 0.0, 8.0),
        edge_v: Vec3::new(8.0, 0.0, 0.0),
    }
    .to_mesh();
    let meshes = vec![
        floor,         // 0: merged
        sphere(0.6),   // 1: shared
        boxed.clone(), // 2: merged, turned and scaled
        sphere(0.4),   // 3: moving
        boxed,         // 4: merged, identity: the shared box below ties it
        sphere(0.3),   // 5: ignorable
        sphere(0.5),   // 6: shared by the box-tie instance and another
    ];
    let mut inst = vec![
        Instance::new(
            6,
            Affine3A::from_translation(Vec3::new(2.0, 0.0, 2.0)),
            None,
        ),
        Instance::new(0, Affine3A::IDENTITY, None),
        Instance::new(
            2,
            Affine3A::from_scale_rotation_translation(
                Vec3::new(1.5, 0.7, 1.1),
                Quat::from_euler(glam::EulerRot::XYZ, 0.3, 0.9, -0.4),
                Vec3::new(-1.5, 0.0, 0.5),
            ),
            None,
        ),
        Instance::moving(
            3,
            Srt::translation(Vec3::new(0.0, 1.0, -1.0)),
            Srt {
                scale: Vec3::splat(1.5),
                rotation: Quat::from_rotation_y(1.0),
                translation: Vec3::new(0.8, 1.2, -1.0),
            },
            None,
        ),
        Instance::new(4, Affine3A::IDENTITY, None),
        Instance::new(
            5,
            Affine3A::from_translation(Vec3::new(0.0, 2.5, 0.0)),
            None,
        ),
        Instance::new(
            6,
            Affine3A::from_translation(Vec3::new(-2.0, 0.5, -2.0)),
            None,
        ),
    ];
    // The merged box (instance 4) again, as a mesh shared with a later
    // instance, at the identity: exact ties with a merged instance of a
    // higher index.
    let mut meshes = meshes;
    meshes.push(meshes[4].clone());
    let tie = meshes.len() as u32 - 1;
    inst.insert(2, Instance::new(tie, Affine3A::IDENTITY, None));
    inst.push(Instance::new(
        tie,
        Affine3A::from_translation(Vec3::new(0.0, 0.0, 3.0)),
        None,
    ));
    for k in 0..shared {
        let a = k as f32 * 0.7;
        inst.push(Instance::new(
            1,
            Affine3A::from_translation(Vec3::new(3.0 * a.cos(), -0.4, 3.0 * a.sin())),
            None,
        ));
    }
    // The ignorable sphere is instance 6 after the insertion.
    (meshes, inst, vec![6])
}

/// The instance's triangles as the oracle tests them: in world space for
/// a merged instance (transformed as the build does), else in object
/// space, with the ray moved there as the accelerator moves it.
fn oracle_hit(
    accel: &Accel,
    meshes: &[SceneMesh],
    instances: &[Instance],
    i: u32,
    ray: &Ray,
    s: f32,
) -> (Vec<Triangle>, Ray) {
    let inst = &instances[i as usize];
    let tris = meshes[inst.mesh as usize].mesh.triangles();
    if accel.is_merged(i) {
        let Placement::Static(xf) = inst.placement else {
            panic!("a merged instance moves")
        };
        let world = tris
            .iter()
            .map(|t| {
                Triangle::new(
                    xf.transform_point3(t.v[0]),
                    xf.transform_point3(t.v[1]),
                    xf.transform_point3(t.v[2]),
                )
            })
            .collect();
        (world, *ray)
    } else {
        let inv = match inst.placement {
            Placement::Static(a) => a.inverse(),
            Placement::Moving { .. } => inst.placement.at(s).inverse(),
        };
        let r = Ray::with_interval(
            inv.transform_point3(ray.origin),
            inv.transform_vector3(ray.dir),
            ray.tmin,
            ray.tmax,
        );
        (tris, r)
    }
}

/// The closest hit by brute force: smallest `t`, then smallest instance,
/// then smallest triangle.
fn oracle_closest(
    accel: &Accel,
    meshes: &[SceneMesh],
    instances: &[Instance],
    ray: &Ray,
    s: f32,
) -> Option<RawHit> {
    let mut best: Option<RawHit> = None;
    for i in 0..instances.len() as u32 {
        let (tris, r) = oracle_hit(accel, meshes, instances, i, ray, s);
        if let Some(h) = brute::closest_hit(&tris, &r) {
            if best.is_none_or(|b| h.t < b.t) {
                best = Some(RawHit::of(&h, i));
            }
        }
    }
    best
}

/// Occlusion by brute force.
fn oracle_occluded(
    accel: &Accel,
    meshes: &[SceneMesh],
    instances: &[Instance],
    ray: &Ray,
    s: f32,
    ignore: Option<u32>,
) -> bool {
    (0..instances.len() as u32).any(|i| {
        Some(i) != ignore && {
            let (tris, r) = oracle_hit(accel, meshes, instances, i, ray, s);
            brute::any_hit(&tris, &r)
        }
    })
}

/// Rays through the scene: random, aimed at triangle corners and centres
/// (edges and ties), some with short intervals, with their shutter
/// fractions.
fn rays(meshes: &[SceneMesh], instances: &[Instance], n: usize) -> (Vec<Ray>, Vec<f32>) {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut rays = Vec::with_capacity(n);
    let mut s = Vec::with_capacity(n);
    for k in 0..n {
        let origin = rng.vec(-5.0, 5.0);
        let target = if k % 3 == 0 {
            let inst = &instances[k / 3 % instances.len()];
            let m = &meshes[inst.mesh as usize].mesh;
            let t = m.indices[k / 7 % m.indices.len()];
            let [a, b, c] = t.map(|j| m.positions[j as usize]);
            let p = if k % 2 == 0 { a } else { (a + b + c) / 3.0 };
            inst.placement.at(0.5).transform_point3(p)
        } else {
            rng.vec(-2.0, 2.0)
        };
        let tmax = if k % 5 == 0 {
            rng.next() * 4.0
        } else {
            f32::INFINITY
        };
        rays.push(Ray::with_interval(origin, target - origin, 0.0, tmax));
        s.push(rng.next());
    }
    (rays, s)
}

#[test]
fn the_layout_merges_what_is_static_unshared_and_not_ignorable() {
    let (meshes, instances, ignorable) = scene(3);
    let accel = Accel::build(&meshes, &instances, &AccelParams::default(), &ignorable);
    let merged: Vec<u32> = (0..instances.len() as u32)
        .filter(|&i| accel.is_merged(i))
        .collect();
    // Floor, turned box, identity box.
    assert_eq!(merged, [1, 3, 5]);
    assert_eq!(accel.merged_count(), 3);
    assert_eq!(accel.instance_count(), instances.len());
    assert_eq!(accel.two_level_count(), instances.len() - 3);
    // The world tree, and one tree each for the sphere shared three
    // times, the moving sphere, the ignorable sphere, the shared sphere
    // and the shared box.
    assert_eq!(accel.tree_count(), 1 + 5);
}

/// A small box on a ground plane forty times its size, and a wall (flat,
/// but not dwarfing the box): the plane stays out of the world tree, the
/// box and the wall go in, and the hits are still the oracle's.
#[test]
fn a_ground_that_dwarfs_the_rest_keeps_its_own_tree() {
    let quad = |corner: Vec3, edge_u: Vec3, edge_v: Vec3| {
        Shape::Quad {
            corner,
            edge_u,
            edge_v,
        }
        .to_mesh()
    };
    let meshes = vec![
        quad(
            Vec3::new(-20.0, 0.0, -20.0),
            Vec3::new(0.0, 0.0, 40.0),
            Vec3::new(40.0, 0.0, 0.0),
        ),
        Shape::Box {
            min: Vec3::new(-0.5, 0.0, -0.5),
            max: Vec3::new(0.5, 1.0, 0.5),
        }
        .to_mesh(),
        quad(
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ),
    ];
    let instances: Vec<Instance> = (0..3)
        .map(|m| Instance::new(m, Affine3A::IDENTITY, None))
        .collect();
    let accel = Accel::build(&meshes, &instances, &AccelParams::default(), &[]);
    let merged: Vec<bool> = (0..3).map(|i| accel.is_merged(i)).collect();
    assert_eq!(merged, [false, true, true]);
    let (rays, s) = rays(&meshes, &instances, 2000);
    let mut hits = 0;
    for (r, &s) in rays.iter().zip(&s) {
        let got = accel.closest(r, s, &mut NoCounters);
        assert_eq!(
            got,
            oracle_closest(&accel, &meshes, &instances, r, s),
            "ray {r:?}"
        );
        hits += usize::from(got.is_some());
        assert_eq!(
            accel.occluded(r, s, None),
            oracle_occluded(&accel, &meshes, &instances, r, s, None),
            "ray {r:?}"
        );
    }
    assert!(hits > 600, "{hits} hits");
}

#[test]
fn hits_equal_the_brute_force_oracle() {
    for (shared, params) in [0, 3, 12]
        .into_iter()
        .flat_map(|s| structures().map(|p| (s, p)))
    {
        let (meshes, instances, ignorable) = scene(shared);
        let accel = Accel::build(&meshes, &instances, &params, &ignorable);
        let (rays, s) = rays(&meshes, &instances, 1200);
        let mut hits = 0;
        let mut ties = 0;
        for (r, &s) in rays.iter().zip(&s) {
            let got = accel.closest(r, s, &mut NoCounters);
            let want = oracle_closest(&accel, &meshes, &instances, r, s);
            assert_eq!(got, want, "ray {r:?} at {s}");
            hits += usize::from(got.is_some());
            ties += usize::from(got.is_some_and(|h| h.instance == 2));
            for ignore in [None, Some(ignorable[0])] {
                assert_eq!(
                    accel.occluded(r, s, ignore),
                    oracle_occluded(&accel, &meshes, &instances, r, s, ignore),
                    "ray {r:?} at {s} ignoring {ignore:?}"
                );
            }
        }
        assert!(hits > 400, "{hits} hits");
        // The shared box (instance 2) wins every tie with the merged one
        // (instance 5) it lies on: it is hit, the merged one never where
        // they coincide.
        assert!(ties > 10, "{ties} tied hits");
    }
}

#[test]
fn batches_and_packets_equal_single_rays() {
    for (shared, params) in [0, 12]
        .into_iter()
        .flat_map(|s| structures().map(|p| (s, p)))
    {
        let (meshes, instances, ignorable) = scene(shared);
        let accel = Accel::build(&meshes, &instances, &params, &ignorable);
        assert_eq!(
            accel.two_level_count() > super::PACKET_INSTANCES,
            shared > 0
        );
        let (rays, s) = rays(&meshes, &instances, 1000);
        let single: Vec<Option<RawHit>> = rays
            .iter()
            .zip(&s)
            .map(|(r, &s)| accel.closest(r, s, &mut NoCounters))
            .collect();
        let mut buf = BatchBuffers::default();
        let mut batch = vec![None; rays.len()];
        accel.closest_batch(&rays, &s, &mut batch, &mut buf);
        assert_eq!(batch, single);
        let mut packets = vec![None; rays.len()];
        for ((r, s), o) in rays
            .chunks(PACKET16)
            .zip(s.chunks(PACKET16))
            .zip(packets.chunks_mut(PACKET16))
        {
            accel.closest_packet(r, s, o);
        }
        assert_eq!(packets, single);
        let ignore: Vec<Option<u32>> = (0..rays.len())
            .map(|k| (k % 2 == 0).then_some(ignorable[0]))
            .collect();
        let one: Vec<bool> = (0..rays.len())
            .map(|k| accel.occluded(&rays[k], s[k], ignore[k]))
            .collect();
        let mut blocked = vec![false; rays.len()];
        accel.occluded_batch(&rays, &s, &ignore, &mut blocked, &mut buf);
        assert_eq!(blocked, one);
        assert!(one.iter().any(|&b| b) && one.iter().any(|&b| !b));
    }
}
