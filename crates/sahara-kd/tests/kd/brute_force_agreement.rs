//! Property tests: every builder's tree answers exactly as brute force.
//!
//! Closest hit: the same `t` to the bit, the same triangle (ties go to the
//! smallest index), the same barycentrics. Any hit: the same answer as brute
//! force and as "closest hit exists". Both for single rays (the binary
//! nodes) and for batches walked over the wide nodes, interleaved, and over
//! the binary ones. And every tree passes the structural validator.

use glam::Vec3;
use proptest::prelude::*;
use sahara_kd::internals::BatchWalk;
use sahara_kd::validate;
use sahara_kd::{brute, BuildParams, Builder, KdTree, Ray, Triangle};

/// A coordinate: mostly on a coarse grid (so that coplanar, axis-aligned and
/// shared vertices are common), sometimes arbitrary.
fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![
        3 => (-4i32..=4).prop_map(|i| i as f32 * 0.5),
        1 => -2.0f32..2.0,
    ]
}

fn point() -> impl Strategy<Value = Vec3> {
    (coord(), coord(), coord()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// A triangle: ordinary, axis-aligned (one coordinate shared), or degenerate
/// (a repeated vertex or three collinear points).
fn triangle() -> impl Strategy<Value = Triangle> {
    prop_oneof![
        6 => (point(), point(), point()).prop_map(|(a, b, c)| Triangle::new(a, b, c)),
        2 => (point(), point(), point(), 0usize..3).prop_map(|(a, mut b, mut c, axis)| {
            b[axis] = a[axis];
            c[axis] = a[axis];
            Triangle::new(a, b, c)
        }),
        1 => (point(), point()).prop_map(|(a, b)| Triangle::new(a, b, a)),
        1 => (point(), point()).prop_map(|(a, b)| Triangle::new(a, (a + b) * 0.5, b)),
    ]
}

/// How the soup is placed: plain, scaled (huge and tiny), flattened onto a
/// plane (zero-thickness bounds), or a small soup next to huge triangles
/// ("teapot in a stadium").
#[derive(Clone, Copy, Debug)]
enum Layout {
    Plain,
    Scaled(i32),
    Flat(usize),
    Stadium,
}

fn layout() -> impl Strategy<Value = Layout> {
    prop_oneof![
        4 => Just(Layout::Plain),
        2 => (-6i32..=6).prop_map(Layout::Scaled),
        1 => (0usize..3).prop_map(Layout::Flat),
        1 => Just(Layout::Stadium),
    ]
}

fn apply(layout: Layout, mut tris: Vec<Triangle>) -> Vec<Triangle> {
    match layout {
        Layout::Plain => {}
        Layout::Scaled(e) => {
            let s = 10f32.powi(e);
            tris.iter_mut()
                .for_each(|t| t.v.iter_mut().for_each(|v| *v *= s));
        }
        Layout::Flat(axis) => tris
            .iter_mut()
            .for_each(|t| t.v.iter_mut().for_each(|v| v[axis] = 0.25)),
        Layout::Stadium => {
            let s = 2000.0;
            tris.iter_mut()
                .for_each(|t| t.v.iter_mut().for_each(|v| *v *= 0.01));
            tris.push(Triangle::new(
                Vec3::new(-s, -1.0, -s),
                Vec3::new(s, -1.0, -s),
                Vec3::new(s, -1.0, s),
            ));
            tris.push(Triangle::new(
                Vec3::new(-s, -1.0, -s),
                Vec3::new(s, -1.0, s),
                Vec3::new(-s, -1.0, s),
            ));
            tris.push(Triangle::new(
                Vec3::new(-s, -1.0, s),
                Vec3::new(s, -1.0, s),
                Vec3::new(0.0, s, s),
            ));
        }
    }
    tris
}

/// How a ray is aimed.
#[derive(Clone, Copy, Debug)]
enum Aim {
    /// A random direction.
    Random(Vec3),
    /// Along an axis (zero components in the direction).
    Axis(usize, bool),
    /// At a vertex of triangle `i % n`.
    Vertex(usize, usize),
    /// At the midpoint of an edge of triangle `i % n`.
    Edge(usize, usize),
}

fn unit() -> impl Strategy<Value = Vec3> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
        .prop_filter("non-zero", |(x, y, z)| x * x + y * y + z * z > 1e-4)
        .prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn aim() -> impl Strategy<Value = Aim> {
    prop_oneof![
        3 => unit().prop_map(Aim::Random),
        2 => (0usize..3, any::<bool>()).prop_map(|(a, s)| Aim::Axis(a, s)),
        2 => (any::<usize>(), 0usize..3).prop_map(|(i, k)| Aim::Vertex(i, k)),
        2 => (any::<usize>(), 0usize..3).prop_map(|(i, k)| Aim::Edge(i, k)),
    ]
}

/// A ray description relative to the scene's bounds.
#[derive(Clone, Copy, Debug)]
struct RaySpec {
    /// Origin in the bounds' unit cube, stretched to 3x the bounds, or on
    /// the grid (then often exactly on split planes).
    origin: Vec3,
    on_grid: bool,
    aim: Aim,
    /// Interval: `tmin` as a fraction of the distance to the aim point,
    /// `tmax` finite or infinite.
    tmin_frac: f32,
    tmax_frac: Option<f32>,
}

fn ray_spec() -> impl Strategy<Value = RaySpec> {
    (
        (-1.0f32..2.0, -1.0f32..2.0, -1.0f32..2.0).prop_map(|(x, y, z)| Vec3::new(x, y, z)),
        any::<bool>(),
        aim(),
        prop_oneof![3 => Just(0.0f32), 1 => 0.0f32..1.2],
        prop_oneof![3 => Just(None), 1 => (0.0f32..2.0).prop_map(Some)],
    )
        .prop_map(|(origin, on_grid, aim, tmin_frac, tmax_frac)| RaySpec {
            origin,
            on_grid,
            aim,
            tmin_frac,
            tmax_frac,
        })
}

fn make_ray(spec: &RaySpec, tris: &[Triangle]) -> Ray {
    let b = tris
        .iter()
        .fold(sahara_kd::Aabb::EMPTY, |b, t| b.union(t.bounds()));
    let ext = b
        .extent()
        .max(Vec3::splat(1e-3 * b.extent().max_element().max(1e-30)));
    let mut o = b.min + spec.origin * ext;
    if spec.on_grid {
        // Snap to the scene's own grid: origins on planes the tree splits at.
        let v = tris[(spec.origin.x.to_bits() as usize) % tris.len()].v[0];
        o.x = v.x;
    }
    let pick = |i: usize| &tris[i % tris.len()];
    let (dir, dist) = match spec.aim {
        Aim::Random(d) => (d, ext.length()),
        Aim::Axis(a, s) => {
            let mut d = Vec3::ZERO;
            d[a] = if s { 1.0 } else { -1.0 };
            (d, ext[a])
        }
        Aim::Vertex(i, k) => {
            let d = pick(i).v[k] - o;
            (d, 1.0)
        }
        Aim::Edge(i, k) => {
            let t = pick(i);
            let d = (t.v[k] + t.v[(k + 1) % 3]) * 0.5 - o;
            (d, 1.0)
        }
    };
    let dir = if dir == Vec3::ZERO {
        Vec3::new(0.3, -1.0, 0.2)
    } else {
        dir
    };
    let tmin = spec.tmin_frac * dist / dir.length().max(1e-30) * 0.5;
    let tmax = spec
        .tmax_frac
        .map_or(f32::INFINITY, |f| tmin + f * dist / dir.length().max(1e-30));
    Ray::with_interval(o, dir, tmin, tmax)
}

fn builders() -> Vec<BuildParams> {
    let mut out: Vec<BuildParams> = Builder::ALL.iter().map(|&b| BuildParams::new(b)).collect();
    // Small scenes rarely make the SAH split; these settings force deep trees.
    let mut deep = BuildParams::new(Builder::Sah);
    deep.traversal_cost = 0.01;
    deep.empty_bonus = 0.9;
    out.push(deep);
    // Binned all the way down, and binned cells handed to the exact sweep
    // (the default hands over only cells larger than these scenes).
    let mut deep_binned = BuildParams::new(Builder::Binned { bins: 7 });
    deep_binned.traversal_cost = 0.01;
    deep_binned.exact_below = 0;
    out.push(deep_binned);
    let mut hybrid = deep_binned;
    hybrid.exact_below = 12;
    out.push(hybrid);
    let mut serial = BuildParams::new(Builder::Sah);
    serial.parallel = false;
    out.push(serial);
    // Without wide nodes: batches walk the binary nodes.
    out.push(BuildParams {
        wide_nodes: false,
        ..deep
    });
    // The compact leaf layout, with the default tree and a deep one.
    for base in [BuildParams::new(Builder::Sah), deep] {
        out.push(BuildParams {
            compact_leaves: true,
            ..base
        });
    }
    out
}

fn same_hit(a: Option<sahara_kd::Hit>, b: Option<sahara_kd::Hit>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => {
            a.t.to_bits() == b.t.to_bits() && a.tri == b.tri && a.u == b.u && a.v == b.v
        }
        _ => false,
    }
}

fn check(tris: Vec<Triangle>, rays: &[RaySpec]) -> Result<(), TestCaseError> {
    for params in builders() {
        let tree = KdTree::build(tris.clone(), &params);
        if let Err(e) = validate(&tree, &tris) {
            return Err(TestCaseError::fail(format!(
                "{}: invalid tree: {e}",
                params.builder.name()
            )));
        }
        let batch: Vec<Ray> = rays.iter().map(|s| make_ray(s, &tris)).collect();
        let mut walked = Vec::new();
        for walk in [BatchWalk::Wide, BatchWalk::Binary] {
            let mut hits = vec![None; batch.len()];
            tree.closest_hits_walked(&batch, &mut hits, walk);
            let mut occluded = vec![false; batch.len()];
            tree.any_hits_walked(&batch, &mut occluded, walk);
            walked.push((walk, hits, occluded));
        }
        for (i, spec) in rays.iter().enumerate() {
            let ray = make_ray(spec, &tris);
            let want = brute::closest_hit(&tris, &ray);
            let got = tree.closest_hit(&ray);
            prop_assert!(
                same_hit(want, got),
                "{}: ray {:?}: brute {:?} tree {:?}",
                params.builder.name(),
                ray,
                want,
                got
            );
            for (walk, hits, occluded) in &walked {
                prop_assert!(
                    same_hit(want, hits[i]),
                    "{}: batch walk {:?}, ray {:?}: brute {:?} tree {:?}",
                    params.builder.name(),
                    walk,
                    ray,
                    want,
                    hits[i]
                );
                prop_assert_eq!(
                    occluded[i],
                    want.is_some(),
                    "{}: batch walk {:?}, any-hit disagrees, ray {:?}",
                    params.builder.name(),
                    walk,
                    ray
                );
            }
            let any = tree.any_hit(&ray);
            prop_assert_eq!(
                any,
                want.is_some(),
                "{}: any-hit disagrees, ray {:?}",
                params.builder.name(),
                ray
            );
            prop_assert_eq!(any, brute::any_hit(&tris, &ray));
        }
    }
    Ok(())
}

proptest! {
    // 300 cases by default; PROPTEST_CASES=N runs more (e.g. for a soak).
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(300),
        ..ProptestConfig::default()
    })]

    #[test]
    fn random_soups_match_brute_force(
        tris in prop::collection::vec(triangle(), 1..48),
        layout in layout(),
        rays in prop::collection::vec(ray_spec(), 1..40),
    ) {
        check(apply(layout, tris), &rays)?;
    }
}

#[test]
fn closed_meshes_match_brute_force() {
    let mut rng = crate::common::Rng(0x1234_5678_9abc_def1);
    let mut scenes = vec![
        crate::common::uv_sphere(Vec3::new(0.1, -0.2, 0.3), 1.5, 12, 16),
        crate::common::subdivided_cube(-1.0, 1.0, 4),
    ];
    let mut both = scenes[0].clone();
    both.extend(crate::common::subdivided_cube(1.0, 3.0, 3));
    scenes.push(both);
    for tris in scenes {
        let specs: Vec<RaySpec> = (0..400)
            .map(|i| RaySpec {
                origin: Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 3.0 - Vec3::ONE,
                on_grid: i % 3 == 0,
                aim: match i % 4 {
                    0 => Aim::Random(rng.dir()),
                    1 => Aim::Vertex(i * 7919, i % 3),
                    2 => Aim::Edge(i * 104729, i % 3),
                    _ => Aim::Axis(i % 3, i % 2 == 0),
                },
                tmin_frac: 0.0,
                tmax_frac: None,
            })
            .collect();
        check(tris, &specs).unwrap();
    }
}

#[test]
fn empty_and_non_finite_scenes() {
    let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    for params in builders() {
        let tree = KdTree::build(Vec::new(), &params);
        assert_eq!(tree.closest_hit(&ray), None);
        assert!(!tree.any_hit(&ray));
        // A NaN triangle is ignored; the finite one is found.
        let tris = vec![
            Triangle::new(
                Vec3::new(f32::NAN, 0.0, 1.0),
                Vec3::new(1.0, 0.0, 1.0),
                Vec3::new(0.0, 1.0, 1.0),
            ),
            Triangle::new(
                Vec3::new(-1.0, -1.0, 2.0),
                Vec3::new(1.0, -1.0, 2.0),
                Vec3::new(0.0, 1.0, 2.0),
            ),
        ];
        let tree = KdTree::build(tris.clone(), &params);
        validate(&tree, &tris).unwrap();
        let hit = tree.closest_hit(&ray).unwrap();
        assert_eq!((hit.t, hit.tri), (2.0, 1));
    }
}

/// Either structure held to each instruction limit answers as brute force
/// does, single rays, batches and packets alike.
#[test]
fn every_instruction_limit_matches_brute_force() {
    use sahara_kd::{AccelKind, AccelParams, Isa, TriangleAccel};
    let mut rng = crate::common::Rng(0x5eed_0f15_0a11_u64);
    let mut tris = crate::common::uv_sphere(Vec3::new(0.1, -0.2, 0.3), 1.5, 12, 16);
    tris.extend(crate::common::subdivided_cube(1.0, 3.0, 3));
    let rays: Vec<Ray> = (0..512)
        .map(|_| {
            let o = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 6.0 - Vec3::splat(2.0);
            Ray::new(o, rng.dir())
        })
        .collect();
    let want: Vec<_> = rays.iter().map(|r| brute::closest_hit(&tris, r)).collect();
    for kind in [AccelKind::Kd, AccelKind::Bvh] {
        for isa in [Isa::Portable, Isa::Avx2, Isa::Avx512] {
            let params = AccelParams {
                kind,
                isa,
                ..AccelParams::default()
            };
            let accel = TriangleAccel::build(tris.clone(), &params);
            assert_eq!(accel.isa(), isa);
            let what = format!("{} at {}", kind.name(), isa.name());
            for (r, w) in rays.iter().zip(&want) {
                assert!(same_hit(*w, accel.closest_hit(r)), "{what}: {r:?}");
                assert_eq!(accel.any_hit(r), w.is_some(), "{what}: {r:?}");
            }
            let mut batch = vec![None; rays.len()];
            accel.closest_hits_serial(&rays, &mut batch);
            for (k, chunk) in rays.chunks(16).enumerate() {
                let mut packet = vec![None; chunk.len()];
                accel.closest_hit_packet16(chunk, &mut packet);
                for (i, h) in packet.iter().enumerate() {
                    assert!(same_hit(want[16 * k + i], *h), "{what}: packet");
                }
            }
            for (w, h) in want.iter().zip(&batch) {
                assert!(same_hit(*w, *h), "{what}: batch");
            }
        }
    }
}
