//! The lights of a scene, gathered once when its world is built: the
//! explicit lights, emissive shapes sampled analytically, other static
//! emissive instances as triangle lights, and the environment.

use glam::Vec2;

use super::area::{EmissionTextures, Emitter};
use super::{AreaLight, EnvLight, LightSource};
use crate::material::Material;
use crate::math::warp::Frame;
use crate::scene::shape::Shape;
use crate::scene::Scene;

/// Every light of a scene, in the order the light choice sees them: the
/// scene's explicit lights, emissive shapes sampled analytically, other
/// static emissive instances as triangle lights, the environment.
pub(crate) struct SceneLights {
    /// The lights.
    pub(crate) lights: Vec<LightSource>,
    /// The light of each instance, if it emits.
    pub(crate) instance_light: Vec<Option<u32>>,
    /// The environment's light.
    pub(crate) env: Option<u32>,
    /// Per light, the triangles of its instance's mesh a mesh light was
    /// made of, in order (empty for other lights).
    pub(crate) mesh_triangles: Vec<Vec<u32>>,
}

impl SceneLights {
    /// The lights of `scene`.
    pub(crate) fn gather(scene: &Scene) -> Self {
        let mut lights: Vec<LightSource> = scene
            .lights
            .iter()
            .map(|l| LightSource::Explicit(*l))
            .collect();
        let mut instance_light = vec![None; scene.instances.len()];
        let mut mesh_triangles = vec![Vec::new(); lights.len()];
        let material = |id: u32| scene.materials.get(id as usize);
        // Analytic shapes first.
        for s in &scene.shapes {
            let inst = &scene.instances[s.instance as usize];
            let Some(m) = material(scene.material_of(s.instance, 0)) else {
                continue;
            };
            if !m.is_emissive()
                || m.textures.emission.is_some()
                || !s.shape.has_analytic_sampling()
                || inst.placement.is_moving()
            {
                continue;
            }
            instance_light[s.instance as usize] = Some(lights.len() as u32);
            mesh_triangles.push(Vec::new());
            lights.push(LightSource::Area(AreaLight::analytic(
                emitter_of(&s.shape),
                m.emission,
                m.two_sided_emission,
                s.instance,
            )));
        }
        // Then every other static instance with emissive triangles. Whether
        // a mesh's own materials emit at all is found once per mesh, not
        // once per instance: a scene of 10^4 instances of a 10^6-triangle
        // mesh would otherwise look at 10^10 triangles here.
        let emissive = |id: u32| material(id).is_some_and(Material::is_emissive);
        let mesh_emits: Vec<bool> = scene
            .meshes
            .iter()
            .map(|m| match &m.material_ids {
                Some(ids) => ids.iter().any(|&id| emissive(id)),
                None => emissive(0),
            })
            .collect();
        for (i, inst) in scene.instances.iter().enumerate() {
            if instance_light[i].is_some() || inst.placement.is_moving() {
                continue;
            }
            let emits = match inst.material {
                Some(id) => emissive(id),
                None => mesh_emits[inst.mesh as usize],
            };
            if let Some((light, source)) = emits.then(|| triangle_light(scene, i as u32)).flatten()
            {
                instance_light[i] = Some(lights.len() as u32);
                mesh_triangles.push(source);
                lights.push(LightSource::Area(light));
            }
        }
        let env = scene.environment.as_ref().map(|e| {
            mesh_triangles.push(Vec::new());
            lights.push(LightSource::Environment(EnvLight::new(e)));
            lights.len() as u32 - 1
        });
        Self {
            lights,
            instance_light,
            env,
            mesh_triangles,
        }
    }
}

/// The analytic emitter of a quad, disc or sphere (boxes are never
/// sampled analytically).
fn emitter_of(shape: &Shape) -> Emitter {
    match *shape {
        Shape::Quad {
            corner,
            edge_u,
            edge_v,
        } => Emitter::Quad {
            corner,
            u: edge_u,
            v: edge_v,
            n: edge_u.cross(edge_v).normalize(),
        },
        Shape::Disc {
            center,
            normal,
            radius,
        } => Emitter::Disc {
            center,
            frame: Frame::from_normal(normal.normalize()),
            radius,
        },
        Shape::Sphere { center, radius } => Emitter::Sphere { center, radius },
        Shape::Box { .. } => unreachable!("a box has no analytic sampling"),
    }
}

/// The emissive triangles of static instance `i` in world space as one
/// area light, with their radiance and emission textures, and the mesh's
/// triangles they are (None: none of its triangles emits, or none is
/// finite).
fn triangle_light(scene: &Scene, i: u32) -> Option<(AreaLight, Vec<u32>)> {
    let inst = &scene.instances[i as usize];
    let mesh = &scene.meshes[inst.mesh as usize];
    let xf = inst.placement.at(0.0);
    let (mut tris, mut radiance, mut two) = (Vec::new(), Vec::new(), Vec::new());
    let mut textures = EmissionTextures::default();
    let mut map_of: Vec<(u32, u32)> = Vec::new();
    let mut source = Vec::new();
    for (t, idx) in mesh.mesh.indices.iter().enumerate() {
        let id = scene.material_of(i, t as u32);
        let Some(m) = scene.materials.get(id as usize) else {
            continue;
        };
        if !m.is_emissive() {
            continue;
        }
        let corners = idx.map(|k| xf.transform_point3(mesh.mesh.positions[k as usize]));
        if !corners.iter().all(|p| p.is_finite()) {
            continue;
        }
        tris.push(corners);
        source.push(t as u32);
        radiance.push(m.emission);
        two.push(m.two_sided_emission);
        textures
            .triangles
            .push(m.textures.emission.as_ref().map(|map| {
                let slot = match map_of.iter().find(|(mid, _)| *mid == id) {
                    Some(&(_, s)) => s,
                    None => {
                        textures.maps.push(map.clone());
                        let s = textures.maps.len() as u32 - 1;
                        map_of.push((id, s));
                        s
                    }
                };
                let set = |uvs: Option<&Vec<Vec2>>| {
                    uvs.map_or([Vec2::ZERO, Vec2::X, Vec2::Y], |t| {
                        idx.map(|k| t[k as usize])
                    })
                };
                let uv0 = set(mesh.uvs.as_ref());
                let uv1 = mesh.uvs1.as_ref().map_or(uv0, |_| set(mesh.uvs1.as_ref()));
                (slot, [uv0, uv1])
            }));
    }
    (!tris.is_empty()).then(|| (AreaLight::mesh(tris, radiance, two, textures), source))
}
