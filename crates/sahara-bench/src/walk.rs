//! The binary tree walked front to back by plain scalar code, a node at a
//! time, for counting what a walk visits (the measurements of the
//! `examples/`): not the production walks, which step wide nodes with
//! SIMD, but the cells they visit.

use glam::Vec3;
use sahara_kd::{KdTree, Node, Ray};

/// Walks `tree` front to back along `ray` up to `tmax` (the closest hit's
/// distance, for the cells a closest-hit walk visits), calling `visit`
/// with every node it reaches (inner nodes and leaves, in the order the
/// walk meets them) and the ray's interval in the node's cell; a node for
/// which `visit` returns false is not descended into.
pub fn front_to_back(
    tree: &KdTree,
    ray: &Ray,
    tmax: f32,
    mut visit: impl FnMut(u32, &Node, f32, f32) -> bool,
) {
    let nodes = tree.nodes();
    let inv = Vec3::ONE / ray.dir;
    let Some((t0, t1)) = tree.bounds().intersect_ray(ray.origin, inv, ray.tmin, tmax) else {
        return;
    };
    let mut todo = vec![(0u32, t0, t1)];
    while let Some((i, a, b)) = todo.pop() {
        let n = &nodes[i as usize];
        if !visit(i, n, a, b) || n.is_leaf() {
            continue;
        }
        let axis = n.axis();
        let (o, d) = (ray.origin[axis], ray.dir[axis]);
        let t = (n.split() - o) * inv[axis];
        let below_first = o < n.split() || (o == n.split() && d <= 0.0);
        let (near, far) = if below_first {
            (i + 1, n.above_child())
        } else {
            (n.above_child(), i + 1)
        };
        if t.is_nan() {
            todo.push((far, a, b));
            todo.push((near, a, b));
        } else if t > b || t <= 0.0 {
            todo.push((near, a, b));
        } else if t < a {
            todo.push((far, a, b));
        } else {
            todo.push((far, t, b));
            todo.push((near, a, t));
        }
    }
}

/// The wide node of every inner node of `nodes` (leaves: `u32::MAX`) when
/// each wide node holds `levels` whole binary levels below its root, as
/// the tree's own wide nodes hold 3.
pub fn heap(nodes: &[Node], levels: u32) -> Vec<u32> {
    let mut of = vec![u32::MAX; nodes.len()];
    let (mut count, mut roots) = (0, vec![0u32]);
    while let Some(root) = roots.pop() {
        let mut todo = vec![(root, 0)];
        while let Some((i, depth)) = todo.pop() {
            let n = &nodes[i as usize];
            if n.is_leaf() {
                continue;
            }
            if depth == levels {
                roots.push(i);
                continue;
            }
            of[i as usize] = count;
            todo.push((i + 1, depth + 1));
            todo.push((n.above_child(), depth + 1));
        }
        count += 1;
    }
    of
}
