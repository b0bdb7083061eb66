//! The expanded `<scene>` as a [`SceneDescription`]: the walk over the
//! scene's elements (the state it shares with the other modules is
//! [`super::builder::Builder`]).
//!
//! - Each `<shape>` is an object ([`super::shapes`]); a `shapegroup` is
//!   one mesh made once, and each `instance` of it an object showing it.
//! - Each bsdf becomes a material on first use ([`super::bsdfs`]), a
//!   shape's `area` emitter its material emitting.
//! - The `<sensor>` is the camera and, with the `<integrator>`, the
//!   render settings ([`super::sensor`], [`super::integrator`]); a scene
//!   without one is seen by Sahara's automatic camera.
//! - Other emitters are lights or the environment ([`super::emitters`]).

use std::collections::HashMap;

use sahara_readers::FormatError;

use super::builder::Builder;
use super::expand::Search;
use super::xml::Node;
use crate::common::warnings::Warnings;
use crate::description::{CameraRequest, SceneDescription};

/// The description of the expanded `<scene>` `root`, read from the file
/// `name`, files looked for as `search` says.
pub(crate) fn build(
    root: &Node,
    name: &str,
    search: Search,
    w: Warnings,
) -> Result<SceneDescription, FormatError> {
    let mut b = Builder::new(root, name, search, w)?;
    let mut sensor = None;
    let mut integrator = None;
    for node in &root.children {
        match node.tag.as_str() {
            "sensor" if sensor.is_some() => b.w.add(
                "more than one <sensor>: the first one is used",
                &node.loc,
            ),
            "sensor" => sensor = Some(node),
            "integrator" if integrator.is_some() => b.w.add(
                "more than one <integrator>: the first one is used",
                &node.loc,
            ),
            "integrator" => integrator = Some(node),
            "shape" => b.top_shape(node)?,
            // An area emitter with an id is defined for shapes to refer to.
            "emitter" if node.attr("type") == Some("area") && node.attr("id").is_some() => {}
            "emitter" => b.emitter(node)?,
            // Made when used (a shape or an instance refers to them).
            "bsdf" | "texture" => {
                node.need("type")?;
            }
            // Made when used (a shape or the sensor refers to them).
            "medium" | "phase" | "volume" => {
                node.need("type")?;
            }
            // Defined for a sensor to refer to.
            "film" | "sampler" | "rfilter" if node.attr("id").is_some() => {}
            "film" | "sampler" | "rfilter" => b.w.add(
                format!("<{}> outside a <sensor> has no effect; ignored", node.tag),
                &node.loc,
            ),
            "ref" => b.w.add("<ref> directly in <scene> has no effect; ignored", &node.loc),
            other if super::properties::OBJECT_TAGS.contains(&other) => unreachable!(),
            other => {
                return Err(node.error(format!(
                    "unknown element <{other}> in <scene> (expected shape, bsdf, texture, emitter, sensor, integrator, default or include)"
                )))
            }
        }
    }
    scale_bumps(&mut b.scene, &b.bump_maps);
    let integrator = super::integrator::integrator(&mut b, integrator)?;
    let (camera, settings) = super::sensor::sensor(&mut b, sensor, integrator)?;
    b.scene.camera = match camera {
        Some(camera) => CameraRequest::Given {
            camera,
            source: String::new(),
        },
        None => CameraRequest::Automatic,
    };
    b.scene.settings = Some(settings);
    let mut scene = b.scene;
    scene.warnings = b.w.into_lines();
    Ok(scene)
}

/// Sets the strength of each normal map made from a `bumpmap`'s heights
/// (slopes per unit of uv) to the inverse of the mean length a unit of uv
/// spans on the meshes and quads wearing it, so that the slopes are per
/// unit of length, as Mitsuba's bumps are.
fn scale_bumps(scene: &mut SceneDescription, bumps: &[std::sync::Arc<sahara_render::Texture>]) {
    use crate::description::{Geometry, ObjectPlacement};
    use glam::{Affine3A, Vec3};
    let mut sums: HashMap<u32, (f64, f64)> = HashMap::new();
    for o in &scene.objects {
        let Some(m) = o.material else { continue };
        let bumped = scene.materials[m as usize]
            .textures
            .normal
            .as_ref()
            .is_some_and(|n| {
                bumps
                    .iter()
                    .any(|b| std::sync::Arc::ptr_eq(b, &n.map.texture))
            });
        if !bumped {
            continue;
        }
        let xf = match o.placement {
            ObjectPlacement::Static(a) => a,
            _ => Affine3A::IDENTITY,
        };
        let mut add = |p: [Vec3; 3], uv: [glam::Vec2; 3]| {
            let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
            let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
            let det = d1.x * d2.y - d1.y * d2.x;
            let area = 0.5 * e1.cross(e2).length();
            if det.abs() < 1e-12 || area <= 0.0 {
                return;
            }
            let du = (e1 * d2.y - e2 * d1.y) / det;
            let dv = (e2 * d1.x - e1 * d2.x) / det;
            let s = sums.entry(m).or_default();
            s.0 += f64::from(area * (du.length() * dv.length()).sqrt());
            s.1 += f64::from(area);
        };
        match &o.geometry {
            Geometry::Mesh(i) => {
                let mesh = &scene.meshes[*i as usize];
                let Some(uvs) = &mesh.uvs else { continue };
                for t in &mesh.mesh.indices {
                    let p = t.map(|k| xf.transform_point3(mesh.mesh.positions[k as usize]));
                    add(p, t.map(|k| uvs[k as usize]));
                }
            }
            Geometry::Shape(sahara_render::Shape::Quad {
                corner,
                edge_u,
                edge_v,
            }) => {
                let p =
                    [*corner, *corner + *edge_u, *corner + *edge_v].map(|v| xf.transform_point3(v));
                add(p, [glam::Vec2::ZERO, glam::Vec2::X, glam::Vec2::Y]);
            }
            _ => {}
        }
    }
    for (m, (l, a)) in sums {
        let len = l / a;
        if let Some(n) = &mut scene.materials[m as usize].textures.normal {
            if len > 0.0 && len.is_finite() {
                n.scale = (1.0 / len) as f32;
            }
        }
    }
}
