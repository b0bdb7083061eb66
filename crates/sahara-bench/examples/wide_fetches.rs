//! How many wide nodes a ray fetches under other ways of grouping the
//! binary tree's inner nodes into wide nodes, without building them: the
//! measurement behind the "did not pay" list of `docs/performance.md`.
//!
//! ```sh
//! sahara bench MESH --sets primary,diffuse --dump-rays diffuse rays.bin
//! cargo run --release -p sahara-bench --example wide_fetches -- MESH rays.bin
//! ```
//!
//! Each ray walks the binary tree front to back up to its closest hit (the
//! cells the real walks visit); every inner node it visits is charged to
//! the wide node that holds it under each grouping, and the distinct wide
//! nodes are counted. Groupings: the heap of `levels` binary levels (3 is
//! today's 64-byte node, 4 a 16-wide node of two cache lines), and
//! treelets of `7` or `15` inner nodes grown greedily from each wide
//! node's root by the largest cell surface area (the SAH's probability of
//! a ray meeting the cell).

use std::collections::HashSet;
use std::path::Path;

use sahara_bench::walk::heap;
use sahara_kd::{Aabb, BuildParams, KdTree, Node, Triangle};

fn area(b: &Aabb) -> f32 {
    let d = b.max - b.min;
    2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
}

/// The wide node of every inner node, each wide node a treelet of up to
/// `size` inner nodes grown by the largest cell area.
fn treelets(nodes: &[Node], cells: &[Aabb], size: usize) -> Vec<u32> {
    let mut of = vec![u32::MAX; nodes.len()];
    let (mut count, mut roots) = (0, vec![0u32]);
    while let Some(root) = roots.pop() {
        let mut frontier = vec![root];
        for _ in 0..size {
            let Some(best) = (0..frontier.len()).max_by(|&a, &b| {
                area(&cells[frontier[a] as usize]).total_cmp(&area(&cells[frontier[b] as usize]))
            }) else {
                break;
            };
            let i = frontier.swap_remove(best);
            of[i as usize] = count;
            for c in [i + 1, nodes[i as usize].above_child()] {
                if !nodes[c as usize].is_leaf() {
                    frontier.push(c);
                }
            }
        }
        roots.extend(frontier);
        count += 1;
    }
    of
}

/// The inner nodes `ray` visits up to its closest hit, front to back.
fn visited(tree: &KdTree, ray: &sahara_kd::Ray) -> Vec<u32> {
    let tmax = tree.closest_hit(ray).map_or(ray.tmax, |h| h.t);
    let mut out = Vec::new();
    sahara_bench::walk::front_to_back(tree, ray, tmax, |i, n, _, _| {
        if !n.is_leaf() {
            out.push(i);
        }
        true
    });
    out
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, mesh, rays] = &args[..] else {
        eprintln!("usage: wide_fetches MESH RAYS");
        std::process::exit(2);
    };
    let mesh = sahara_readers::load_mesh(Path::new(mesh)).expect("mesh");
    let p = |i: u32| mesh.positions[i as usize];
    let tris = mesh
        .indices
        .iter()
        .map(|i| Triangle::new(p(i[0]), p(i[1]), p(i[2])))
        .collect();
    let tree = KdTree::build(tris, &BuildParams::default());
    let rays = sahara_bench::files::read_rays(Path::new(rays)).expect("rays");
    let nodes = tree.nodes();
    let mut cells = vec![tree.bounds(); nodes.len()];
    tree.visit(|i, _, cell, _| cells[i as usize] = *cell);
    let groupings = [
        ("heap of 3 levels (today)", heap(nodes, 3)),
        ("heap of 4 levels", heap(nodes, 4)),
        ("treelets of 7", treelets(nodes, &cells, 7)),
        ("treelets of 15", treelets(nodes, &cells, 15)),
    ];
    let inner = nodes.iter().filter(|n| !n.is_leaf()).count();
    let mut fetches = vec![0u64; groupings.len()];
    let (mut walked, mut binary) = (0u64, 0u64);
    for ray in &rays {
        let v = visited(&tree, ray);
        if v.is_empty() {
            continue;
        }
        walked += 1;
        binary += v.len() as u64;
        for (f, (_, of)) in fetches.iter_mut().zip(&groupings) {
            *f += v
                .iter()
                .map(|&i| of[i as usize])
                .collect::<HashSet<_>>()
                .len() as u64;
        }
    }
    let per = |x: u64| x as f64 / walked.max(1) as f64;
    println!(
        "{walked} rays meeting the tree, {:.2} binary inner nodes each",
        per(binary)
    );
    for ((name, of), f) in groupings.iter().zip(&fetches) {
        let wide = of
            .iter()
            .filter(|&&w| w != u32::MAX)
            .collect::<HashSet<_>>()
            .len();
        println!(
            "{name:26} {:6.2} wide nodes a ray ({:.3}x today), {:.2} inner nodes a wide node",
            per(*f),
            per(*f) / per(fetches[0]),
            inner as f64 / wide as f64
        );
    }
}
