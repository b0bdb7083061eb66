//! What two changes to the walk could save at most, counted on a ray set
//! without building them: the measurement behind two entries of
//! `docs/performance.md` ("Measured and did not pay").
//!
//! ```sh
//! sahara bench MESH --sets primary,diffuse --dump-rays diffuse rays.bin
//! cargo run --release -p sahara-bench --example walk_ceilings -- MESH rays.bin
//! ```
//!
//! Each ray walks the binary tree front to back up to its closest hit.
//! - **Descent**: the inner nodes visited before the first leaf. A ray that
//!   starts on a surface spends them going down to its own origin's leaf;
//!   a walk that started there (ropes, or a restart from the origin's
//!   leaf) would skip them, and no more.
//! - **Tight bounds**: the walk again, skipping every node whose geometry
//!   (its triangles clipped to its cell, boxed) the ray's interval in the
//!   cell misses: the most that child bounds stored in the nodes, as a
//!   bounding volume hierarchy has them, could cull (with a box test at
//!   every binary node; wide nodes would test fewer).
//! - **Descent, timed**: the one-thread CPU time of the batch walk the
//!   renderer uses (the rays in direction-octant order), against the same
//!   walk of the same rays cut to `[tmin, tmin + 1e-5 * diagonal]`, which
//!   goes down to the origin's leaf and tests it. Their ratio bounds what a
//!   walk starting at the origin's leaf could save in time, not only in
//!   nodes (an upper bound: such a walk still tests that leaf).

use std::path::Path;

use glam::Vec3;
use sahara_bench::runner::throughput::thread_cpu_seconds;
use sahara_kd::{Aabb, BuildParams, Hit, KdTree, Primitive, Ray, Triangle};

/// Inner nodes visited, inner nodes before the first leaf, non-empty leaves
/// visited; with `tight`, nodes whose bounds the ray misses are skipped.
fn walk(tree: &KdTree, tight: Option<&[Aabb]>, ray: &Ray, tmax: f32) -> (u32, u32, u32) {
    let inv = Vec3::ONE / ray.dir;
    let (mut inner, mut descent, mut leaves, mut seen_leaf) = (0, 0, 0, false);
    sahara_bench::walk::front_to_back(tree, ray, tmax, |i, n, a, b| {
        if let Some(tight) = tight {
            let tb = &tight[i as usize];
            if tb.is_empty() || tb.intersect_ray(ray.origin, inv, a, b).is_none() {
                return false;
            }
        }
        if n.is_leaf() {
            seen_leaf = true;
            leaves += (n.leaf_count() > 0) as u32;
        } else {
            inner += 1;
            descent += (!seen_leaf) as u32;
        }
        true
    });
    (inner, descent, leaves)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, mesh, rays] = &args[..] else {
        eprintln!("usage: walk_ceilings MESH RAYS");
        std::process::exit(2);
    };
    let mesh = sahara_readers::load_mesh(Path::new(mesh)).expect("mesh");
    let p = |i: u32| mesh.positions[i as usize];
    let tris: Vec<Triangle> = mesh
        .indices
        .iter()
        .map(|i| Triangle::new(p(i[0]), p(i[1]), p(i[2])))
        .collect();
    let tree = KdTree::build(tris.clone(), &BuildParams::default());
    let rays = sahara_bench::files::read_rays(Path::new(rays)).expect("rays");
    let nodes = tree.nodes();
    // Each node's geometry bounds: a leaf's triangles clipped to its cell,
    // an inner node's the union of its children's.
    let mut cells = vec![tree.bounds(); nodes.len()];
    let mut order = Vec::new();
    tree.visit(|i, _, cell, _| {
        cells[i as usize] = *cell;
        order.push(i);
    });
    let empty = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };
    let mut tight = vec![empty; nodes.len()];
    for &i in order.iter().rev() {
        let n = &nodes[i as usize];
        tight[i as usize] = if n.is_leaf() {
            tree.leaf_triangles(n)
                .iter()
                .filter_map(|&t| tris[t as usize].clipped_bounds(&cells[i as usize]))
                .fold(empty, Aabb::union)
        } else {
            tight[i as usize + 1].union(tight[n.above_child() as usize])
        };
    }
    let (mut n, mut plain, mut culled) = (0u64, [0u64; 3], [0u64; 3]);
    for ray in &rays {
        let tmax = tree.closest_hit(ray).map_or(ray.tmax, |h| h.t);
        let inv = Vec3::ONE / ray.dir;
        if tree
            .bounds()
            .intersect_ray(ray.origin, inv, ray.tmin, tmax)
            .is_none()
        {
            continue;
        }
        let (a, b) = (
            walk(&tree, None, ray, tmax),
            walk(&tree, Some(&tight), ray, tmax),
        );
        n += 1;
        for (s, v) in plain.iter_mut().zip([a.0, a.1, a.2]) {
            *s += v as u64;
        }
        for (s, v) in culled.iter_mut().zip([b.0, b.1, b.2]) {
            *s += v as u64;
        }
    }
    let per = |x: u64| x as f64 / n.max(1) as f64;
    println!(
        "{n} rays meeting the tree: {:.2} inner nodes each, {:.2} of them ({:.0} %) before the first leaf; {:.2} non-empty leaves",
        per(plain[0]),
        per(plain[1]),
        100.0 * plain[1] as f64 / plain[0].max(1) as f64,
        per(plain[2])
    );
    println!(
        "with tight bounds at every node: {:.2} inner nodes ({:.3}x), {:.2} non-empty leaves ({:.3}x)",
        per(culled[0]),
        culled[0] as f64 / plain[0].max(1) as f64,
        per(culled[2]),
        culled[2] as f64 / plain[2].max(1) as f64
    );
    descent_timed(&tree, &rays);
}

/// The "descent, timed" line: best of five interleaved runs of each.
fn descent_timed(tree: &KdTree, rays: &[Ray]) {
    let mut full = rays.to_vec();
    full.sort_by_key(|r| {
        (r.dir.x < 0.0) as u8 | ((r.dir.y < 0.0) as u8) << 1 | ((r.dir.z < 0.0) as u8) << 2
    });
    let eps = 1e-5 * tree.bounds().extent().length();
    let cut: Vec<Ray> = full
        .iter()
        .map(|r| Ray {
            tmax: r.tmin + eps,
            ..*r
        })
        .collect();
    let mut out: Vec<Option<Hit>> = vec![None; full.len()];
    let mut time = |rays: &[Ray]| {
        let t = thread_cpu_seconds();
        tree.closest_hits_serial(rays, &mut out);
        thread_cpu_seconds() - t
    };
    let (mut t_full, mut t_cut) = (f64::MAX, f64::MAX);
    for _ in 0..5 {
        t_full = t_full.min(time(&full));
        t_cut = t_cut.min(time(&cut));
    }
    println!(
        "batch walk, one thread: {:.1} ms; cut to the origin's leaf: {:.1} ms ({:.0} %); a walk without the descent: at most {:.2}x",
        t_full * 1e3,
        t_cut * 1e3,
        100.0 * t_cut / t_full,
        t_full / (t_full - t_cut)
    );
}
