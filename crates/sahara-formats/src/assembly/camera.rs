//! The automatic camera: the scene's subject seen from above, the front
//! and the right, or for models whose format says where their front is
//! (glTF: +Z), from the front and a little above.

use glam::Vec3;
use sahara_readers::FormatError;
use sahara_render::{Camera, Scene};

/// Vertical field of view of the automatic camera, degrees.
pub const AUTO_VFOV_DEG: f32 = 45.0;

/// True if some instance has a triangle whose corners are all finite.
pub(crate) fn has_finite_triangles(scene: &Scene) -> bool {
    scene
        .instances
        .iter()
        .any(|i| !scene.meshes[i.mesh as usize].mesh.bounds().is_empty())
}

/// How much larger than the subject a flat or emissive object must be for
/// the automatic camera to leave it out: a ground plane, a sea or a
/// glowing backdrop that dwarfs the subject would otherwise make it a speck
/// in the frame.
const GROUND_DWARFS: f32 = 4.0;

/// How much larger than the subject a flat or emissive object must be for
/// the automatic camera to leave it out of the framing (though not out of
/// the light, which [`GROUND_DWARFS`] decides): a floor twice the subject's
/// size would make the subject small in the frame.
const FRAME_DWARFS: f32 = 2.0;

/// Where the automatic camera stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum View {
    /// Above, in front (+Z) and to the right (+X): a three-quarter view
    /// that shows a mesh of unknown orientation in depth.
    ThreeQuarter,
    /// In front (+Z) and a little above ([`FRONT_ELEVATION_DEG`]), as glTF
    /// viewers show a model: glTF models face +Z with +Y up.
    Front,
}

/// How far above the horizontal the [`View::Front`] camera looks down.
const FRONT_ELEVATION_DEG: f32 = 15.0;

/// Thickness, relative to its largest extent, below which an object is flat:
/// a plane, or a sea or terrain whose waves or hills are low beside its size.
const FLAT: f32 = 0.05;

/// A camera that sees the scene (see [`auto_camera_framing`]).
#[cfg(test)]
fn auto_camera(scene: &Scene, name: &str) -> Result<Camera, FormatError> {
    auto_camera_framing(scene, name, View::ThreeQuarter).map(|(c, _)| c)
}

/// What the automatic camera frames and what it leaves out as context.
pub(crate) struct Grounds {
    /// Per instance: context, not subject (a flat or emissive object at
    /// least so many times the size of the subject: [`GROUND_DWARFS`] for
    /// the light, [`FRAME_DWARFS`] for the framing).
    pub(crate) context: Vec<bool>,
    /// Per instance: flat (its thickness at most [`FLAT`] of its size).
    pub(crate) flat: Vec<bool>,
    /// The bounds of what is not context (`None` if nothing has finite
    /// bounds).
    pub(crate) subject: Option<(Vec3, Vec3)>,
}

impl Grounds {
    /// True if instance `i` is a flat object left out as context: a ground
    /// plane, a sea, a backdrop.
    pub(crate) fn is_ground(&self, i: usize) -> bool {
        self.context[i] && self.flat[i]
    }
}

/// The scene's context and subject. Flat objects (grounds, seas,
/// backdrops) and emissive ones are candidates; a candidate whose size is
/// at least [`GROUND_DWARFS`] times the diagonal of the other objects'
/// bounds (those that are not candidates; if every object is one, all but
/// the largest) is context. The automatic camera frames what is not
/// context (with [`FRAME_DWARFS`] in place of [`GROUND_DWARFS`]), and
/// `auto` lighting does not count a ground's glow as the scene's light.
pub(crate) fn grounds(scene: &Scene) -> Grounds {
    grounds_at(scene, GROUND_DWARFS)
}

/// [`grounds`], with context `dwarfs` times the subject's size or more.
fn grounds_at(scene: &Scene, dwarfs: f32) -> Grounds {
    let n = scene.instances.len();
    let bounds: Vec<Option<(Vec3, Vec3)>> = scene
        .instances
        .iter()
        .map(|inst| {
            let m = &scene.meshes[inst.mesh as usize].mesh;
            let b = inst.placement.world_bounds(m.bounds());
            (!b.is_empty() && b.min.is_finite() && b.max.is_finite()).then_some((b.min, b.max))
        })
        .collect();
    let size = |b: &(Vec3, Vec3)| (b.1 - b.0).max_element();
    let flat: Vec<bool> = bounds
        .iter()
        .map(|b| {
            b.is_some_and(|b| {
                let e = b.1 - b.0;
                e.min_element() <= FLAT * e.max_element()
            })
        })
        .collect();
    let candidate: Vec<bool> = (0..n)
        .map(|i| bounds[i].is_some() && (flat[i] || emissive(scene, i)))
        .collect();
    let union = |keep: &dyn Fn(usize) -> bool| {
        let (lo, hi) = (0..n)
            .filter(|&i| keep(i))
            .filter_map(|i| bounds[i])
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), b| {
                (lo.min(b.0), hi.max(b.1))
            });
        (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
    };
    // The measure of the subject: what is neither flat nor emissive, else
    // (paper cut-outs on a sheet) everything but the largest object.
    let largest = (0..n)
        .filter_map(|i| bounds[i].map(|b| (i, size(&b))))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i);
    let measure = union(&|i| !candidate[i]).or_else(|| union(&|i| Some(i) != largest));
    let diagonal = measure.map(|(lo, hi)| (hi - lo).length());
    let context: Vec<bool> = (0..n)
        .map(|i| match (bounds[i], diagonal) {
            (Some(b), Some(d)) if candidate[i] && d.is_finite() => size(&b) >= dwarfs * d,
            _ => false,
        })
        .collect();
    let subject = union(&|i| !context[i]);
    Grounds {
        context,
        flat,
        subject,
    }
}

/// True if some triangle of instance `i` emits light.
fn emissive(scene: &Scene, i: usize) -> bool {
    let inst = &scene.instances[i];
    if let Some(m) = inst.material {
        return scene
            .materials
            .get(m as usize)
            .is_some_and(|m| m.is_emissive());
    }
    let mesh = &scene.meshes[inst.mesh as usize];
    match &mesh.material_ids {
        None => scene.materials.first().is_some_and(|m| m.is_emissive()),
        Some(ids) => ids.iter().any(|&m| {
            scene
                .materials
                .get(m as usize)
                .is_some_and(|m| m.is_emissive())
        }),
    }
}

/// Cells per side of the grid on which [`open_room`] measures how much of
/// each side of the bounds is walled.
const ROOM_GRID: usize = 24;

/// If the framed objects enclose a room open on one side (five sides of
/// their bounds walled, one open, as a Cornell box), that side: its axis
/// (0, 1, 2 for x, y, z) and whether it is the high end of that axis. A
/// side is walled where triangles facing along its axis lie within 3 % of
/// the bounds' size from it; walled means 90 % of it, open less than half.
fn open_room(scene: &Scene, framed: &[bool], lo: Vec3, hi: Vec3) -> Option<(usize, bool)> {
    let extent = hi - lo;
    if extent.min_element() <= 0.0 {
        return None;
    }
    let tol = 0.03 * extent.max_element();
    // covered[2 * axis + high][row * ROOM_GRID + column]
    let mut covered = vec![vec![false; ROOM_GRID * ROOM_GRID]; 6];
    for (i, inst) in scene.instances.iter().enumerate() {
        if !framed[i] {
            continue;
        }
        let mesh = &scene.meshes[inst.mesh as usize].mesh;
        let xf = inst.placement.at(0.0);
        for idx in &mesh.indices {
            let [a, b, c] = idx.map(|k| xf.transform_point3(mesh.positions[k as usize]));
            let normal = (b - a).cross(c - a).normalize_or_zero();
            for axis in 0..3 {
                if normal[axis].abs() < 0.9 {
                    continue;
                }
                for (high, plane) in [(false, lo[axis]), (true, hi[axis])] {
                    if [a, b, c].iter().any(|p| (p[axis] - plane).abs() > tol) {
                        continue;
                    }
                    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                    let to_grid = |p: Vec3| {
                        glam::Vec2::new(
                            (p[u] - lo[u]) / extent[u] * ROOM_GRID as f32,
                            (p[v] - lo[v]) / extent[v] * ROOM_GRID as f32,
                        )
                    };
                    mark_triangle(
                        &mut covered[2 * axis + high as usize],
                        [to_grid(a), to_grid(b), to_grid(c)],
                    );
                }
            }
        }
    }
    let share: Vec<f32> = covered
        .iter()
        .map(|g| g.iter().filter(|&&c| c).count() as f32 / g.len() as f32)
        .collect();
    let open: Vec<usize> = (0..6).filter(|&f| share[f] < 0.5).collect();
    let walled = (0..6).filter(|&f| share[f] >= 0.9).count();
    match (open.as_slice(), walled) {
        (&[f], 5) => Some((f / 2, f % 2 == 1)),
        _ => None,
    }
}

/// Marks the cells of `grid` (`ROOM_GRID` square) whose centres lie in the
/// triangle `t` (in cell units), and the cell of its centroid.
fn mark_triangle(grid: &mut [bool], t: [glam::Vec2; 3]) {
    let g = ROOM_GRID as f32;
    let cell = |x: f32| (x.max(0.0) as usize).min(ROOM_GRID - 1);
    let centroid = (t[0] + t[1] + t[2]) / 3.0;
    grid[cell(centroid.y) * ROOM_GRID + cell(centroid.x)] = true;
    let lo = t[0].min(t[1]).min(t[2]).max(glam::Vec2::ZERO);
    let hi = t[0].max(t[1]).max(t[2]).min(glam::Vec2::splat(g));
    let edge = |p: glam::Vec2, a: glam::Vec2, b: glam::Vec2| (b - a).perp_dot(p - a);
    let area = edge(t[2], t[0], t[1]);
    if area == 0.0 {
        return;
    }
    for y in (lo.y.floor() as usize)..(hi.y.ceil() as usize).min(ROOM_GRID) {
        for x in (lo.x.floor() as usize)..(hi.x.ceil() as usize).min(ROOM_GRID) {
            let p = glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let w = [
                edge(p, t[0], t[1]) * area.signum(),
                edge(p, t[1], t[2]) * area.signum(),
                edge(p, t[2], t[0]) * area.signum(),
            ];
            if w.iter().all(|&w| w >= 0.0) {
                grid[y * ROOM_GRID + x] = true;
            }
        }
    }
}

/// How far from the centre of the box `lo..hi`, looking at it from the
/// direction `from` (with +Y up), every corner of the box is within the
/// field of view (`half_fov` either side, across and up: any image at
/// least as wide as it is tall shows it all), with a 5 % margin. Tighter
/// than the bounding sphere, which leaves a model long along the line of
/// sight (a fox seen from the front) small in the frame.
fn front_distance(lo: Vec3, hi: Vec3, from: Vec3, half_fov: f32) -> f32 {
    let right = Vec3::Y.cross(from).normalize();
    let up = from.cross(right);
    let (c, tan) = (0.5 * (lo + hi), half_fov.tan());
    let (mut d, mut nearest) = (0.0f32, 0.0f32);
    for k in 0..8 {
        let corner = Vec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        ) - c;
        // The corner's offset towards the eye shortens its depth.
        let nearer = corner.dot(from);
        let across = corner.dot(right).abs().max(corner.dot(up).abs());
        d = d.max(across / tan + nearer);
        nearest = nearest.max(nearer);
    }
    let r = (0.5 * (hi - lo).length()).max(1e-6);
    // Never so close that the box reaches the eye.
    1.05 * d.max(nearest + 0.1 * r)
}

/// A camera that sees the scene's objects: looking at the centre of their
/// bounds from where `view` says (above, the front (+Z) and the right
/// (+X); or the front and a little above), at the distance where their
/// bounding sphere fills the vertical field of view; with the log's words
/// for how it chose. Context ([`grounds`]: flat or emissive objects at
/// least [`FRAME_DWARFS`] times the size of everything else, such as a
/// ground plane or a sea) is left out of the framing (it still renders),
/// so that the subject fills the frame rather than the plane it stands on. Objects that enclose a room open on one side (a Cornell box)
/// are looked into through that side, the opening filling the frame, not
/// at from outside its walls.
pub(crate) fn auto_camera_framing(
    scene: &Scene,
    name: &str,
    view: View,
) -> Result<(Camera, String), FormatError> {
    let g = grounds_at(scene, FRAME_DWARFS);
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    let (mut framed, mut left_out) = (0, 0);
    let mut in_frame = vec![false; scene.instances.len()];
    for (i, inst) in scene.instances.iter().enumerate() {
        let m = &scene.meshes[inst.mesh as usize].mesh;
        let b = inst.placement.world_bounds(m.bounds());
        if b.is_empty() {
            continue;
        }
        if g.context[i] {
            left_out += 1;
            continue;
        }
        framed += 1;
        in_frame[i] = true;
        lo = lo.min(b.min);
        hi = hi.max(b.max);
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(FormatError::in_file(
            name,
            "the mesh has no triangles with finite corners; nothing to frame",
        ));
    }
    let c = 0.5 * lo + 0.5 * hi;
    let r = (0.5 * (hi - lo).length()).max(1e-6);
    let half_fov = 0.5 * AUTO_VFOV_DEG.to_radians();
    let room = open_room(scene, &in_frame, lo, hi);
    let (eye, up) = match room {
        Some((axis, high)) => {
            // Outside the open side, on its centre, at the distance where
            // the opening (a little margin around it) fills the frame.
            let out = Vec3::AXES[axis] * if high { 1.0 } else { -1.0 };
            let half = 0.5 * (hi - lo);
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let face = c + out * half[axis];
            let d = 1.05 * half[u].max(half[v]) / half_fov.tan();
            let up = if axis == 1 { Vec3::NEG_Z } else { Vec3::Y };
            (face + out * d, up)
        }
        None => match view {
            View::ThreeQuarter => {
                let from = Vec3::new(0.3, 0.5, 1.0).normalize();
                (c + from * (r / half_fov.sin()), Vec3::Y)
            }
            View::Front => {
                let (sin, cos) = FRONT_ELEVATION_DEG.to_radians().sin_cos();
                let from = Vec3::new(0.0, sin, cos);
                (c + from * front_distance(lo, hi, from, half_fov), Vec3::Y)
            }
        },
    };
    // Coordinates near the float range put the eye at infinity, and
    // coordinates far from the origin beside a tiny mesh leave no room
    // between eye and target.
    if !(eye.is_finite() && c.is_finite() && r.is_finite()) || eye == c {
        return Err(FormatError::in_file(
            name,
            format!(
                "the mesh's bounds ({lo} to {hi}) are too large to frame automatically; \
                 give a camera sidecar (--camera FILE or {{stem}}.camera.json)"
            ),
        ));
    }
    let objects = |n: usize| if n == 1 { "" } else { "s" };
    let mut how = match left_out {
        0 if framed == 1 => "auto (framing the one object".to_owned(),
        0 => format!("auto (framing all {framed} objects"),
        n => format!(
            "auto (framing {framed} object{}; {n} flat or emissive object{} at least \
             {FRAME_DWARFS} times their size, a ground, sea or backdrop, left out of the framing",
            objects(framed),
            objects(n)
        ),
    };
    if let Some((axis, high)) = room {
        how += &format!(
            "; a room open on its {}{} side, looked into through it",
            if high { '+' } else { '-' },
            ['x', 'y', 'z'][axis]
        );
    }
    how.push(')');
    Ok((Camera::look_at(eye, c, up, AUTO_VFOV_DEG, 1.0), how))
}

#[cfg(test)]
mod tests {
    use super::*;
    use sahara_render::Material;

    #[test]
    fn auto_camera_sees_the_bounds_centre() {
        let mut scene = Scene::new(Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 1.0));
        let m = scene.add_material(Material::default());
        scene.add_shape(
            sahara_render::Shape::Box {
                min: Vec3::splat(1.0),
                max: Vec3::splat(3.0),
            },
            m,
        );
        let c = auto_camera(&scene, "t").unwrap();
        let to_centre = (Vec3::splat(2.0) - c.eye).normalize();
        assert!(to_centre.dot(c.forward) > 0.9999);
        assert!(c.eye.distance(Vec3::splat(2.0)) > 3.0f32.sqrt());
    }

    /// A unit sphere on a square ground plane of side `side`.
    fn sphere_on_ground(side: f32) -> Scene {
        let mut scene = Scene::new(Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 1.0));
        let m = scene.add_material(Material::default());
        scene.add_shape(
            sahara_render::Shape::Sphere {
                center: Vec3::ZERO,
                radius: 1.0,
            },
            m,
        );
        scene.add_shape(
            sahara_render::Shape::Quad {
                corner: Vec3::new(-side / 2.0, -1.0, -side / 2.0),
                edge_u: Vec3::new(side, 0.0, 0.0),
                edge_v: Vec3::new(0.0, 0.0, side),
            },
            m,
        );
        scene
    }

    #[test]
    fn a_ground_plane_that_dwarfs_the_subject_is_left_out_of_the_framing() {
        let (c, how) =
            auto_camera_framing(&sphere_on_ground(1000.0), "t", View::ThreeQuarter).unwrap();
        // Framed on the sphere (radius 1): the eye is a few radii away,
        // not hundreds.
        assert!(c.eye.length() < 5.0, "{}", c.eye);
        assert!((c.forward.dot(-c.eye.normalize()) - 1.0).abs() < 1e-4);
        assert!(
            how.contains("1 flat or emissive object") && how.contains("left out"),
            "{how}"
        );
    }

    /// A sea of side 392 made of a grid whose waves rise and fall by
    /// `wave`, emitting `glow`.
    fn wavy_sea(scene: &mut Scene, wave: f32, glow: f32) {
        let n = 16;
        let side = 392.0;
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let (x, z) = (i as f32 / n as f32 - 0.5, j as f32 / n as f32 - 0.5);
                let y = wave * ((7.0 * x).sin() + (5.0 * z).cos()) / 2.0;
                positions.push(Vec3::new(side * x, y, side * z));
            }
        }
        let mut indices = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let k = j * (n + 1) + i;
                indices.push([k, k + n + 1, k + 1]);
                indices.push([k + 1, k + n + 1, k + n + 2]);
            }
        }
        let water = scene.add_material(
            sahara_render::Material::diffuse(Vec3::new(0.1, 0.3, 0.4))
                .with_emission(Vec3::splat(glow)),
        );
        scene.add_object(
            sahara_render::Mesh { positions, indices },
            glam::Affine3A::IDENTITY,
            water,
        );
    }

    /// A palm of sorts, about 6 units tall: a trunk and a crown of flat
    /// leaves, on an island of sand 20 units across.
    fn palm_island(scene: &mut Scene) {
        let m = scene.add_material(Material::default());
        let boxed = |min: Vec3, max: Vec3| sahara_render::Shape::Box { min, max };
        scene.add_shape(
            boxed(Vec3::new(-10.0, -1.0, -10.0), Vec3::new(10.0, 0.5, 10.0)),
            m,
        );
        scene.add_shape(
            boxed(Vec3::new(-0.3, 0.5, -0.3), Vec3::new(0.3, 6.0, 0.3)),
            m,
        );
        for k in 0..4 {
            let dir = Vec3::AXES[2 * (k % 2)] * if k < 2 { 1.0 } else { -1.0 };
            scene.add_shape(
                sahara_render::Shape::Quad {
                    corner: Vec3::new(0.0, 6.0, 0.0) - dir.cross(Vec3::Y) * 0.5,
                    edge_u: dir * 3.0 - Vec3::Y,
                    edge_v: dir.cross(Vec3::Y),
                },
                m,
            );
        }
    }

    #[test]
    fn a_wavy_glowing_sea_is_left_out_and_the_island_framed() {
        let mut scene = Scene::new(Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 1.0));
        palm_island(&mut scene);
        // Waves of 2 units over 392: five times the old flatness bound.
        wavy_sea(&mut scene, 2.0, 1.0);
        let (c, how) = auto_camera_framing(&scene, "t", View::ThreeQuarter).unwrap();
        assert!(
            how.contains("framing 6 objects; 1 flat or emissive object"),
            "{how}"
        );
        // The island's bounding sphere (radius about 14.6) fills the frame:
        // the eye is tens of units away, not hundreds.
        assert!(c.eye.length() < 60.0, "{}", c.eye);
        let g = grounds(&scene);
        assert_eq!(g.context, [false, false, false, false, false, false, true]);
        assert!(g.is_ground(6));
    }

    /// The Cornell box as five one-sided walls (open at +z), with a block.
    fn cornell_room(scene: &mut Scene, closed: bool) {
        let m = scene.add_material(Material::default());
        let (s, h, d) = (556.0, 548.0, 559.0);
        let quad = |corner: Vec3, edge_u: Vec3, edge_v: Vec3| sahara_render::Shape::Quad {
            corner,
            edge_u,
            edge_v,
        };
        let (x, y, z) = (Vec3::X * s, Vec3::Y * h, Vec3::Z * d);
        let o = Vec3::new(-s, 0.0, 0.0);
        for q in [
            quad(o, x, z),     // floor
            quad(o + y, z, x), // ceiling
            quad(o, y, x),     // back
            quad(o, z, y),     // left
            quad(o + x, y, z), // right
        ] {
            scene.add_shape(q, m);
        }
        if closed {
            scene.add_shape(quad(o + z, x, y), m);
        }
        scene.add_shape(
            sahara_render::Shape::Box {
                min: Vec3::new(-400.0, 0.0, 100.0),
                max: Vec3::new(-250.0, 330.0, 250.0),
            },
            m,
        );
    }

    #[test]
    fn a_room_open_on_one_side_is_looked_into_through_it() {
        let mut scene = Scene::new(Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 1.0));
        cornell_room(&mut scene, false);
        let (c, how) = auto_camera_framing(&scene, "t", View::ThreeQuarter).unwrap();
        assert!(how.contains("a room open on its +z side"), "{how}");
        // On the opening's axis, outside it, looking straight in, level.
        let centre = Vec3::new(-278.0, 274.0, 279.5);
        assert!((c.eye.x - centre.x).abs() < 1e-3 && (c.eye.y - centre.y).abs() < 1e-3);
        assert!(c.eye.z > 559.0, "{}", c.eye);
        assert!(c.forward.dot(Vec3::NEG_Z) > 0.9999, "{}", c.forward);
        // Close enough for the opening to fill the frame: its half height
        // (274) at 45 degrees, with a margin.
        let d = c.eye.z - 559.0;
        assert!(d > 661.0 && d < 720.0, "{d}");
        // Closed on all six sides, it is no room with an opening.
        let mut scene = Scene::new(Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 1.0));
        cornell_room(&mut scene, true);
        let (_, how) = auto_camera_framing(&scene, "t", View::ThreeQuarter).unwrap();
        assert_eq!(how, "auto (framing all 7 objects)");
        // Nor is a sphere on a floor.
        let (_, how) =
            auto_camera_framing(&sphere_on_ground(3.0), "t", View::ThreeQuarter).unwrap();
        assert!(!how.contains("room"), "{how}");
    }

    #[test]
    fn a_gltf_model_is_seen_from_its_front_a_little_above() {
        let mut scene = Scene::new(Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 1.0));
        let m = scene.add_material(Material::default());
        scene.add_shape(
            sahara_render::Shape::Box {
                min: Vec3::new(1.0, 0.0, -1.0),
                max: Vec3::new(3.0, 4.0, 1.0),
            },
            m,
        );
        let (c, _) = auto_camera_framing(&scene, "t", View::Front).unwrap();
        let from = (c.eye - Vec3::new(2.0, 2.0, 0.0)).normalize();
        // Straight in front (+Z), 15 degrees above, looking at the centre.
        assert!(from.x.abs() < 1e-6, "{from}");
        assert!((from.y - 15f32.to_radians().sin()).abs() < 1e-5, "{from}");
        assert!((c.forward + from).length() < 1e-5, "{}", c.forward);
        // The three-quarter view of other meshes: from the right and
        // higher.
        let (c, _) = auto_camera_framing(&scene, "t", View::ThreeQuarter).unwrap();
        let from = (c.eye - Vec3::new(2.0, 2.0, 0.0)).normalize();
        assert!(from.x > 0.2 && from.y > 0.4, "{from}");
    }

    #[test]
    fn a_model_long_along_the_line_of_sight_still_fills_the_front_view() {
        // A box 1 wide, 1 tall and 6 deep (a fox seen from the front): every
        // corner in the frame, the outermost near its edge (the bounding
        // sphere would leave it a third of the frame).
        let mut scene = Scene::new(Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 1.0));
        let m = scene.add_material(Material::default());
        let (lo, hi) = (Vec3::new(-0.5, 0.0, -3.0), Vec3::new(0.5, 1.0, 3.0));
        scene.add_shape(sahara_render::Shape::Box { min: lo, max: hi }, m);
        let (c, _) = auto_camera_framing(&scene, "t", View::Front).unwrap();
        let tan = (0.5 * AUTO_VFOV_DEG.to_radians()).tan();
        let right = c.forward.cross(Vec3::Y).normalize();
        let up = right.cross(c.forward);
        let mut widest = 0.0f32;
        for k in 0..8 {
            let p = Vec3::new(
                [lo.x, hi.x][k & 1],
                [lo.y, hi.y][(k >> 1) & 1],
                [lo.z, hi.z][(k >> 2) & 1],
            ) - c.eye;
            let depth = p.dot(c.forward);
            assert!(depth > 0.0, "corner {k} behind the eye");
            let fill = p.dot(right).abs().max(p.dot(up).abs()) / (depth * tan);
            assert!(fill <= 1.0, "corner {k} out of the frame: {fill}");
            widest = widest.max(fill);
        }
        assert!(widest > 0.9, "{widest}");
    }

    #[test]
    fn a_floor_a_few_times_the_subjects_size_does_not_decide_the_framing() {
        // A chair on a floor 3.8 times its size (Bevy's
        // MixedLightingExample): the chair is framed, the floor left out;
        // the light's ground rule (four times) still counts the floor.
        let (c, how) = auto_camera_framing(&sphere_on_ground(13.2), "t", View::Front).unwrap();
        assert!(
            how.contains("1 flat or emissive object at least 2 times"),
            "{how}"
        );
        assert!(c.eye.length() < 5.0, "{}", c.eye);
        assert!(!grounds(&sphere_on_ground(13.2)).context.contains(&true));
    }

    #[test]
    fn a_floor_of_the_subjects_size_is_framed_with_it() {
        let (c, how) =
            auto_camera_framing(&sphere_on_ground(3.0), "t", View::ThreeQuarter).unwrap();
        assert_eq!(how, "auto (framing all 2 objects)");
        // Farther than the sphere alone needs (sqrt(3) / sin(22.5 deg) =
        // 4.5): the floor's corners are in the frame too (6.1).
        assert!(c.eye.length() > 6.0, "{}", c.eye);
    }
}
