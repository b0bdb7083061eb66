//! The built-in scene `sahara bench` traces when given no mesh: a sphere
//! and a torus on a ground plane, made in code (no files needed).

use std::f32::consts::{PI, TAU};

use glam::Vec3;
use sahara_render::Mesh;

/// Appends a quad `a b c d` (counter-clockwise) as two triangles.
fn quad(mesh: &mut Mesh, a: u32, b: u32, c: u32, d: u32) {
    mesh.indices.push([a, b, c]);
    mesh.indices.push([a, c, d]);
}

/// Appends a surface given by `point(i, j)` on an `nu x nv` grid, closed in
/// `u` (wrapping) and in `v` if `wrap_v`.
fn grid(mesh: &mut Mesh, nu: u32, nv: u32, wrap_v: bool, point: impl Fn(u32, u32) -> Vec3) {
    let base = mesh.positions.len() as u32;
    let rows = if wrap_v { nv } else { nv + 1 };
    for j in 0..rows {
        for i in 0..nu {
            mesh.positions.push(point(i, j));
        }
    }
    let at = |i: u32, j: u32| base + (j % rows) * nu + (i % nu);
    for j in 0..nv {
        for i in 0..nu {
            quad(mesh, at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
        }
    }
}

/// The built-in scene: a UV sphere (64 x 32), a torus (64 x 32) and a
/// ground quad; 8,194 triangles (the sphere's pole rows are degenerate
/// slivers, as in any UV sphere).
pub fn demo_scene() -> Mesh {
    let mut mesh = Mesh::default();
    // Ground quad, y = 0, facing up.
    let g = mesh.positions.len() as u32;
    for (x, z) in [(-4.0, 4.0), (4.0, 4.0), (4.0, -4.0), (-4.0, -4.0)] {
        mesh.positions.push(Vec3::new(x, 0.0, z));
    }
    quad(&mut mesh, g, g + 1, g + 2, g + 3);
    // Sphere of radius 1 at (-1.3, 1, 0).
    let (nu, nv) = (64, 32);
    grid(&mut mesh, nu, nv, false, |i, j| {
        let phi = TAU * i as f32 / nu as f32;
        let theta = PI * j as f32 / nv as f32;
        Vec3::new(-1.3, 1.0, 0.0)
            + Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            )
    });
    // Torus (R = 0.8, r = 0.3) standing at (1.4, 1.1, 0.3).
    grid(&mut mesh, nu, nv, true, |i, j| {
        let a = TAU * i as f32 / nu as f32;
        let b = TAU * j as f32 / nv as f32;
        let ring = 0.8 + 0.3 * b.cos();
        Vec3::new(1.4, 1.1, 0.3) + Vec3::new(ring * a.cos(), ring * a.sin(), 0.3 * b.sin())
    });
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn demo_scene_is_a_valid_mesh() {
        let m = demo_scene();
        assert_eq!(m.triangle_count(), 2 + 2 * 64 * 32 * 2);
        let n = m.positions.len() as u32;
        assert!(m.indices.iter().flatten().all(|&i| i < n));
        let b = m.bounds();
        assert_eq!(b.min.y, 0.0);
        assert!(b.max.y > 2.0);
    }
}
