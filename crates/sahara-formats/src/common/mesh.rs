//! Smooth vertex normals, as the readers share them (pbrt's subdivided
//! meshes, Mitsuba's meshes without normals).

use glam::Vec3;
/// Per-vertex normals: the area-weighted mean of the faces' (winding) normals.
pub(crate) fn smooth_normals(positions: &[Vec3], tris: &[[u32; 3]]) -> Vec<Vec3> {
    let mut n = vec![Vec3::ZERO; positions.len()];
    for t in tris {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let f = (b - a).cross(c - a);
        for &i in t {
            n[i as usize] += f;
        }
    }
    n.into_iter()
        .map(|v| v.try_normalize().unwrap_or(Vec3::Z))
        .collect()
}
