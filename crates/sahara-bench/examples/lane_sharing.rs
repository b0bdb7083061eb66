//! How many wide nodes the 16 rays of a packet would share, for two ways of
//! filling a packet: 16 samples of one pixel (the lanes of a vectorised
//! path loop, as Mitsuba's `llvm` variants fill them) against one sample of
//! each of 16 pixels (the render loop's camera packets, and its bounce and
//! shadow batches taken 16 rays at a time in direction-octant order).
//!
//! ```sh
//! cargo run --release -p sahara-bench --example lane_sharing -- MESH [CAMERA.json]
//! ```
//!
//! The camera looks at the mesh (its sidecar, else the protocol's automatic
//! camera) over a 256 x 256 image; a pixel's samples are jittered within
//! it. From each camera ray's hit, a shadow ray goes to the protocol's
//! light and a bounce ray in a cosine-weighted direction. Each ray walks
//! the binary tree to its closest hit, and its inner nodes are charged to
//! the tree's wide nodes (three binary levels each). Per group of 16 rays:
//! the wide nodes its rays fetch one by one (`alone`), and the distinct
//! ones among them (`shared`), which a packet walk that kept all its lanes
//! together would fetch; their ratio is the most a packet could save.

use std::collections::HashSet;
use std::path::Path;

use glam::Vec3;
use sahara_bench::protocol::{secondary::cosine_direction, SceneFrame};
use sahara_bench::walk::{front_to_back, heap};
use sahara_bench::{ProtocolCamera, SplitMix64};
use sahara_kd::{BuildParams, KdTree, Ray, Triangle};

const SIZE: u32 = 256;
const LANES: usize = 16;

/// The wide nodes `ray` fetches walking to its closest hit.
fn fetched(tree: &KdTree, wide: &[u32], ray: &Ray) -> HashSet<u32> {
    let tmax = tree.closest_hit(ray).map_or(ray.tmax, |h| h.t);
    let mut out = HashSet::new();
    front_to_back(tree, ray, tmax, |i, n, _, _| {
        if !n.is_leaf() {
            out.insert(wide[i as usize]);
        }
        true
    });
    out
}

/// (fetched alone, distinct) summed over groups of rays.
fn sharing(tree: &KdTree, wide: &[u32], groups: &[Vec<Ray>]) -> (f64, f64, usize) {
    let (mut alone, mut shared, mut rays) = (0usize, 0usize, 0usize);
    for g in groups {
        let mut union = HashSet::new();
        for r in g {
            let f = fetched(tree, wide, r);
            alone += f.len();
            union.extend(f);
        }
        shared += union.len();
        rays += g.len();
    }
    (alone as f64, shared as f64, rays)
}

/// 16 rays at a time, each octant's rays in their order (the render loop's
/// batches).
fn by_octant(rays: &[Ray]) -> Vec<Vec<Ray>> {
    let octant =
        |d: Vec3| (d.x < 0.0) as usize | ((d.y < 0.0) as usize) << 1 | ((d.z < 0.0) as usize) << 2;
    let mut out = Vec::new();
    for o in 0..8 {
        let of: Vec<Ray> = rays
            .iter()
            .copied()
            .filter(|r| octant(r.dir) == o)
            .collect();
        out.extend(of.chunks(LANES).map(<[Ray]>::to_vec));
    }
    out
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mesh = sahara_readers::load_mesh(Path::new(&args[1])).expect("mesh");
    let frame = SceneFrame::from_bounds(
        mesh.positions
            .iter()
            .copied()
            .fold(Vec3::INFINITY, Vec3::min),
        mesh.positions
            .iter()
            .copied()
            .fold(Vec3::NEG_INFINITY, Vec3::max),
    );
    let camera = match args.get(2) {
        Some(path) => {
            let c = sahara_readers::camera::read_sidecar(Path::new(path)).expect("camera");
            ProtocolCamera {
                eye: c.eye,
                target: c.target,
                up: c.up,
                vfov_deg: c.vfov_deg,
            }
        }
        None => ProtocolCamera::auto(&frame),
    };
    let p = |i: u32| mesh.positions[i as usize];
    let tris: Vec<Triangle> = mesh
        .indices
        .iter()
        .map(|i| Triangle::new(p(i[0]), p(i[1]), p(i[2])))
        .collect();
    let tree = KdTree::build(tris.clone(), &BuildParams::default());
    let wide = heap(tree.nodes(), 3);
    let basis = camera.basis();
    let light = frame.light();
    let mut rng = SplitMix64::new(7);
    // The camera ray of pixel (x, y) at film offset (jx, jy) in [0, 1)^2.
    let camera_ray = |x: u32, y: u32, jx: f32, jy: f32| {
        let t = basis.tan_half_fov;
        let a = (2.0 * (x as f32 + jx) / SIZE as f32 - 1.0) * t;
        let b = (1.0 - 2.0 * (y as f32 + jy) / SIZE as f32) * t;
        Ray::new(
            camera.eye,
            (basis.forward + basis.right * a + basis.up * b).normalize(),
        )
    };
    // The shadow and bounce rays from a camera ray's hit (none on a miss).
    let secondary = |ray: &Ray, rng: &mut SplitMix64| -> Option<(Ray, Ray)> {
        let h = tree.closest_hit(ray)?;
        let [a, b, c] = mesh.indices[h.tri as usize].map(p);
        let mut n = (b - a).cross(c - a).normalize();
        if n.dot(ray.dir) > 0.0 {
            n = -n;
        }
        let o = ray.origin + ray.dir * h.t + n * frame.eps;
        let to = light - o;
        let shadow = Ray::with_interval(o, to.normalize(), 0.0, 0.999 * to.length());
        Some((shadow, Ray::new(o, cosine_direction(n, rng))))
    };
    // Pixel lanes: each pixel's 16 jittered samples form a group.
    let (mut cam_l, mut sh_l, mut bo_l) = (Vec::new(), Vec::new(), Vec::new());
    // Pixel blocks: one sample per pixel; camera rays in 4x4 blocks, the
    // secondary rays of a strip of four rows in octant order.
    let (mut cam_b, mut sh_b, mut bo_b) = (Vec::new(), Vec::new(), Vec::new());
    for by in (0..SIZE).step_by(4) {
        let (mut strip_sh, mut strip_bo) = (Vec::new(), Vec::new());
        for bx in (0..SIZE).step_by(4) {
            let mut block = Vec::new();
            for y in by..by + 4 {
                for x in bx..bx + 4 {
                    let j = (rng.next_f32(), rng.next_f32());
                    let r = camera_ray(x, y, j.0, j.1);
                    block.push(r);
                    if let Some((s, b)) = secondary(&r, &mut rng) {
                        strip_sh.push(s);
                        strip_bo.push(b);
                    }
                }
            }
            cam_b.push(block);
        }
        sh_b.extend(by_octant(&strip_sh));
        bo_b.extend(by_octant(&strip_bo));
    }
    // The lanes of every 16th pixel (a sparse sample of the image: the same
    // pixels' statistics as the blocks').
    for y in (0..SIZE).step_by(4) {
        for x in (0..SIZE).step_by(4) {
            let (mut c, mut s, mut b) = (Vec::new(), Vec::new(), Vec::new());
            for _ in 0..LANES {
                let r = camera_ray(x, y, rng.next_f32(), rng.next_f32());
                c.push(r);
                if let Some((sr, br)) = secondary(&r, &mut rng) {
                    s.push(sr);
                    b.push(br);
                }
            }
            cam_l.push(c);
            if !s.is_empty() {
                sh_l.push(s);
                bo_l.push(b);
            }
        }
    }
    println!("| rays | packet of 16 | wide nodes a ray fetches alone | distinct in its packet, a ray | shared |");
    println!("|---|---|---:|---:|---:|");
    for (what, groups) in [
        (
            "camera",
            [("4x4 pixels", &cam_b), ("one pixel's samples", &cam_l)],
        ),
        (
            "shadow",
            [
                ("16 of a strip, by octant", &sh_b),
                ("one pixel's samples", &sh_l),
            ],
        ),
        (
            "bounce",
            [
                ("16 of a strip, by octant", &bo_b),
                ("one pixel's samples", &bo_l),
            ],
        ),
    ] {
        for (how, g) in groups {
            let (alone, shared, n) = sharing(&tree, &wide, g);
            println!(
                "| {what} | {how} | {:.2} | {:.2} | {:.2}x |",
                alone / n as f64,
                shared / n as f64,
                alone / shared
            );
        }
    }
}
