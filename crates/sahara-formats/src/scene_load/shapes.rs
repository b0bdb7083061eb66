//! Built-in shapes placed in a scene.
//!
//! A static shape whose transform maps it onto a shape of the same kind (any
//! affine map for a quad; uniform scale for a disc or sphere; no rotation
//! for a box) is transformed exactly and added with [`Scene::add_shape`],
//! so an emissive quad, disc or sphere is sampled analytically as an area
//! light. Other shapes (moving, or non-uniformly scaled, or a rotated box)
//! become a tessellated mesh with an instance transform.

use glam::{Affine3A, Vec3};
use sahara_render::{Instance, Placement, Scene, Shape};

use crate::scene_file::ShapeSpec;

/// The renderer shape of a built-in shape spec (`None` for a mesh file).
pub fn shape_of(spec: &ShapeSpec) -> Option<Shape> {
    match *spec {
        ShapeSpec::Mesh { .. } => None,
        ShapeSpec::Builtin(shape) => Some(shape),
    }
}

/// `shape` under the affine map `m`, if it is again a shape of its kind.
pub fn transformed(shape: Shape, m: &Affine3A) -> Option<Shape> {
    let lin = m.matrix3;
    let cols = [lin.x_axis, lin.y_axis, lin.z_axis].map(Vec3::from);
    let lens = cols.map(Vec3::length);
    let uniform = lens.iter().all(|&l| (l - lens[0]).abs() <= 1e-5 * lens[0])
        && cols[0].dot(cols[1]).abs() <= 1e-5 * lens[0] * lens[0]
        && cols[1].dot(cols[2]).abs() <= 1e-5 * lens[0] * lens[0]
        && cols[0].dot(cols[2]).abs() <= 1e-5 * lens[0] * lens[0];
    let s = lens[0];
    Some(match shape {
        Shape::Quad {
            corner,
            edge_u,
            edge_v,
        } => Shape::Quad {
            corner: m.transform_point3(corner),
            edge_u: m.transform_vector3(edge_u),
            edge_v: m.transform_vector3(edge_v),
        },
        Shape::Disc {
            center,
            normal,
            radius,
        } if uniform => Shape::Disc {
            center: m.transform_point3(center),
            normal: (m.transform_vector3(normal) * m.matrix3.determinant().signum()).normalize(),
            radius: radius * s,
        },
        Shape::Sphere { center, radius } if uniform => Shape::Sphere {
            center: m.transform_point3(center),
            radius: radius * s,
        },
        Shape::Box { min, max } => {
            let off_diagonal = [lin.x_axis.y, lin.x_axis.z, lin.y_axis.x]
                .into_iter()
                .chain([lin.y_axis.z, lin.z_axis.x, lin.z_axis.y])
                .any(|v| v.abs() > 1e-6 * s);
            if off_diagonal {
                return None;
            }
            let (a, b) = (m.transform_point3(min), m.transform_point3(max));
            Shape::Box {
                min: a.min(b),
                max: a.max(b),
            }
        }
        _ => return None,
    })
}

/// Adds `shape` placed by `placement` with `material`; returns its instance.
pub fn add_placed_shape(
    scene: &mut Scene,
    shape: Shape,
    placement: Placement,
    material: u32,
) -> u32 {
    if let Placement::Static(m) = placement {
        if let Some(exact) = transformed(shape, &m) {
            return scene.add_shape(exact, material);
        }
    }
    let mesh = scene.add_mesh(shape.to_mesh());
    scene.add_instance(Instance {
        mesh,
        placement,
        material: Some(material),
    })
}
