//! Loop subdivision of triangle meshes (C. Loop, *Smooth Subdivision
//! Surfaces Based on Triangles*, MS thesis, University of Utah, 1987).
//!
//! Each level splits every triangle in four. New edge vertices are
//! `3/8 (a + b) + 1/8 (c + d)` inside the mesh and the edge midpoint on
//! its boundary; an old vertex of valence `n` moves to
//! `(1 - n beta) v + beta * sum(neighbours)` with Loop's
//! `beta = (5/8 - (3/8 + cos(2 pi / n) / 4)^2) / n`, and on the boundary
//! to `3/4 v + 1/8 (b0 + b1)` of its two boundary neighbours. Vertices on
//! edges shared by more than two triangles stay where they are. The result
//! is the mesh after `levels` steps (not projected to the limit surface),
//! with smooth normals averaged from the faces.

use std::collections::HashMap;

use glam::Vec3;

/// The mesh after `levels` Loop subdivision steps.
pub(crate) fn loop_subdivide(
    mut positions: Vec<Vec3>,
    mut tris: Vec<[u32; 3]>,
    levels: u32,
) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    for _ in 0..levels {
        // Edge (lo, hi) -> (new vertex, opposite vertices, triangle count).
        let mut edges: HashMap<(u32, u32), (u32, [u32; 2], u32)> = HashMap::new();
        for t in &tris {
            for k in 0..3 {
                let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                let e = edges.entry((a.min(b), a.max(b))).or_insert((0, [c, c], 0));
                if e.2 < 2 {
                    e.1[e.2 as usize] = c;
                }
                e.2 += 1;
            }
        }
        let n = positions.len();
        let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); n];
        let mut boundary: Vec<Vec<u32>> = vec![Vec::new(); n];
        let mut crease = vec![false; n];
        // Sorted keys: new vertex numbers do not depend on hash order.
        let mut keys: Vec<(u32, u32)> = edges.keys().copied().collect();
        keys.sort_unstable();
        let mut odd = Vec::with_capacity(keys.len());
        for (next, key) in (n as u32..).zip(&keys) {
            let (a, b) = *key;
            let e = edges.get_mut(key).expect("key from the map");
            e.0 = next;
            let (pa, pb) = (positions[a as usize], positions[b as usize]);
            odd.push(match e.2 {
                2 => {
                    let (c, d) = (positions[e.1[0] as usize], positions[e.1[1] as usize]);
                    (pa + pb) * 0.375 + (c + d) * 0.125
                }
                _ => (pa + pb) * 0.5,
            });
            neighbours[a as usize].push(b);
            neighbours[b as usize].push(a);
            match e.2 {
                1 => {
                    boundary[a as usize].push(b);
                    boundary[b as usize].push(a);
                }
                2 => {}
                _ => {
                    crease[a as usize] = true;
                    crease[b as usize] = true;
                }
            }
        }
        let mut out: Vec<Vec3> = (0..n)
            .map(|v| {
                let p = positions[v];
                if crease[v] || neighbours[v].is_empty() {
                    return p;
                }
                if !boundary[v].is_empty() {
                    return match boundary[v][..] {
                        [b0, b1] => {
                            p * 0.75 + (positions[b0 as usize] + positions[b1 as usize]) * 0.125
                        }
                        _ => p,
                    };
                }
                let k = neighbours[v].len() as f32;
                let c = 0.375 + 0.25 * (2.0 * std::f32::consts::PI / k).cos();
                let beta = (0.625 - c * c) / k;
                let sum: Vec3 = neighbours[v].iter().map(|&q| positions[q as usize]).sum();
                p * (1.0 - k * beta) + sum * beta
            })
            .collect();
        out.extend(odd);
        let mid = |a: u32, b: u32| edges[&(a.min(b), a.max(b))].0;
        let mut new_tris = Vec::with_capacity(tris.len() * 4);
        for &[a, b, c] in &tris {
            let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
            new_tris.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        positions = out;
        tris = new_tris;
    }
    (positions, tris)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A regular octahedron (every vertex of valence 4).
    fn octahedron() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let p = vec![Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
        let t = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        (p, t)
    }

    #[test]
    fn subdivision_counts_and_loops_weights() {
        let (p, t) = octahedron();
        let (p1, t1) = loop_subdivide(p.clone(), t.clone(), 1);
        // V' = V + E, F' = 4F.
        assert_eq!(p1.len(), 6 + 12);
        assert_eq!(t1.len(), 32);
        // Valence 4: beta = (5/8 - (3/8 + cos(pi/2)/4)^2)/4 = (5/8 - 9/64)/4 = 31/256.
        // The vertex +X with neighbours +-Y, +-Z (sum 0) moves to (1 - 4 beta) X.
        let beta = 31.0 / 256.0;
        assert!(
            (p1[0] - Vec3::X * (1.0 - 4.0 * beta)).length() < 1e-6,
            "{}",
            p1[0]
        );
        // Edge +X..+Y with opposite +Z and -Z: 3/8 (X + Y) + 1/8 (Z - Z).
        let e = p1[6..]
            .iter()
            .find(|q| (**q - (Vec3::X + Vec3::Y) * 0.375).length() < 1e-6);
        assert!(e.is_some());
        let (p3, t3) = loop_subdivide(p, t, 3);
        assert_eq!(t3.len(), 8 * 64);
        // The surface shrinks towards a smooth blob: every vertex strictly
        // inside the octahedron's circumsphere, none collapsed to the centre.
        let r: Vec<f32> = p3.iter().map(|q| q.length()).collect();
        assert!(
            r.iter().all(|&l| l < 1.0 && l > 0.3),
            "{:?}",
            r.iter()
                .copied()
                .fold((f32::MAX, 0.0f32), |(a, b), l| (a.min(l), b.max(l)))
        );
        // Faces keep their orientation: outward normals.
        for tri in &t3 {
            let [a, b, c] = tri.map(|i| p3[i as usize]);
            assert!((b - a).cross(c - a).dot(a + b + c) > 0.0);
        }
    }

    #[test]
    fn boundary_vertices_follow_the_boundary_rule() {
        // One triangle: all edges are boundary edges.
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let (p1, t1) = loop_subdivide(p, vec![[0, 1, 2]], 1);
        assert_eq!(t1.len(), 4);
        assert!((p1[0] - (Vec3::X + Vec3::Y) * 0.125).length() < 1e-6);
        assert!(p1[3..].contains(&(Vec3::X * 0.5)));
    }
}
