//! The scene model: what is rendered, as plain values the caller fills
//! in: the camera, meshes and built-in shapes placed as instances,
//! materials, lights and the environment.

pub mod builtin;
pub mod camera;
pub mod instance;
pub mod mesh;
pub mod shape;
pub(crate) mod tangents;

use glam::{Affine3A, Vec3};
use sahara_kd::Aabb;

use crate::light::{Environment, Light};
use crate::material::Material;
use crate::medium::{Medium, MediumInterface};
use crate::scene::camera::Camera;
use crate::scene::instance::{Instance, Placement};
use crate::scene::mesh::SceneMesh;
use crate::scene::shape::Shape;

/// A built-in shape placed in the scene, remembered so that an emissive one
/// is sampled analytically rather than as triangles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeInstance {
    /// The instance holding the shape's tessellation.
    pub instance: u32,
    /// The exact shape (world coordinates).
    pub shape: Shape,
}

/// Everything to render: camera, geometry, materials, lights.
///
/// Area lights are not listed: every triangle whose material emits is one
/// (sampled analytically for quad, disc and sphere shapes added with
/// [`Scene::add_shape`], by area for meshes). Emissive geometry on moving
/// instances is seen but not sampled by next-event estimation.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The camera.
    pub camera: Camera,
    /// Distinct meshes (each gets one kd-tree, shared by its instances).
    pub meshes: Vec<SceneMesh>,
    /// Placed meshes.
    pub instances: Vec<Instance>,
    /// Materials, indexed by instances and per-triangle ids.
    pub materials: Vec<Material>,
    /// Point, spot and directional lights.
    pub lights: Vec<Light>,
    /// Light from infinitely far (none: black).
    pub environment: Option<Environment>,
    /// Instances that are built-in shapes.
    pub shapes: Vec<ShapeInstance>,
    /// Participating media, indexed by [`MediumInterface`]s and
    /// `camera_medium`.
    pub media: Vec<Medium>,
    /// The medium the camera sits in (none: vacuum).
    pub camera_medium: Option<u32>,
    /// The media on the two sides of instances' surfaces, by instance
    /// (an instance named twice takes the last).
    pub medium_interfaces: Vec<(u32, MediumInterface)>,
    /// The mesh of a unit sphere that every emitting sphere added with
    /// [`Scene::add_shape`] places by its own transform (none yet).
    pub unit_sphere: Option<u32>,
}

impl Scene {
    /// An empty scene seen by `camera`.
    pub fn new(camera: Camera) -> Self {
        Self {
            camera,
            meshes: Vec::new(),
            instances: Vec::new(),
            materials: Vec::new(),
            lights: Vec::new(),
            environment: None,
            shapes: Vec::new(),
            media: Vec::new(),
            camera_medium: None,
            medium_interfaces: Vec::new(),
            unit_sphere: None,
        }
    }

    /// Adds a medium; returns its index.
    pub fn add_medium(&mut self, m: Medium) -> u32 {
        self.media.push(m);
        self.media.len() as u32 - 1
    }

    /// Puts the media of `interface` on the two sides of `instance`'s
    /// surface.
    pub fn set_medium_interface(&mut self, instance: u32, interface: MediumInterface) {
        self.medium_interfaces.push((instance, interface));
    }

    /// True if any light travels through a medium: the camera sits in
    /// one, or a surface bounds one.
    pub fn has_media(&self) -> bool {
        !self.media.is_empty()
            && (self.camera_medium.is_some()
                || self
                    .medium_interfaces
                    .iter()
                    .any(|(_, m)| m.inside.is_some() || m.outside.is_some() || m.index_matched))
    }

    /// Adds a material; returns its id.
    pub fn add_material(&mut self, m: Material) -> u32 {
        self.materials.push(m);
        self.materials.len() as u32 - 1
    }

    /// Adds a mesh; returns its index.
    pub fn add_mesh(&mut self, m: impl Into<SceneMesh>) -> u32 {
        self.meshes.push(m.into());
        self.meshes.len() as u32 - 1
    }

    /// Adds an instance; returns its index.
    pub fn add_instance(&mut self, i: Instance) -> u32 {
        self.instances.push(i);
        self.instances.len() as u32 - 1
    }

    /// Adds a mesh with one static instance of it; returns the instance.
    pub fn add_object(
        &mut self,
        m: impl Into<SceneMesh>,
        transform: Affine3A,
        material: u32,
    ) -> u32 {
        let mesh = self.add_mesh(m);
        self.add_instance(Instance::new(mesh, transform, Some(material)))
    }

    /// Adds a built-in shape with a material; returns its instance. An
    /// emissive quad, disc or sphere becomes an analytically sampled light.
    ///
    /// Emitting spheres share one tessellation, a unit sphere placed by
    /// each one's transform: a hall of a hundred small lamps then builds
    /// one small tree for all of them, not a hundred (shadow rays towards
    /// a lamp ignore its own instance, so a lamp is never merged into the
    /// world tree).
    pub fn add_shape(&mut self, shape: Shape, material: u32) -> u32 {
        let emits = self
            .materials
            .get(material as usize)
            .is_some_and(|m| m.is_emissive() && m.textures.emission.is_none());
        let instance = match shape {
            Shape::Sphere { center, radius } if emits => {
                let mesh = match self.unit_sphere {
                    Some(m) => m,
                    None => {
                        let unit = Shape::Sphere {
                            center: Vec3::ZERO,
                            radius: 1.0,
                        };
                        let m = self.add_mesh(unit.to_mesh());
                        self.unit_sphere = Some(m);
                        m
                    }
                };
                let xf = Affine3A::from_scale_rotation_translation(
                    Vec3::splat(radius),
                    glam::Quat::IDENTITY,
                    center,
                );
                self.add_instance(Instance::new(mesh, xf, Some(material)))
            }
            _ => self.add_object(shape.to_mesh(), Affine3A::IDENTITY, material),
        };
        self.shapes.push(ShapeInstance { instance, shape });
        instance
    }

    /// Adds an explicit light.
    pub fn add_light(&mut self, l: Light) {
        self.lights.push(l);
    }

    /// The material id of triangle `tri` of instance `instance`.
    #[inline]
    pub fn material_of(&self, instance: u32, tri: u32) -> u32 {
        let inst = &self.instances[instance as usize];
        inst.material.unwrap_or_else(|| {
            self.meshes[inst.mesh as usize]
                .material_ids
                .as_ref()
                .map_or(0, |ids| ids[tri as usize])
        })
    }

    /// Gives every mesh that a normal-mapped material is used on, and that
    /// has no tangents, MikkTSpace tangents for the uv set of the normal
    /// map ([`SceneMesh::generate_tangents`]); loaders call it once the
    /// scene is complete. Returns the number of meshes given tangents.
    /// (Without tangents a normal map is read in a frame made per
    /// triangle from its uv gradient: right for flat, unmirrored meshes,
    /// but with visible seams on smooth ones.)
    pub fn generate_tangents(&mut self) -> usize {
        let mut wanted: Vec<Option<u8>> = vec![None; self.meshes.len()];
        let normal_set = |id: u32| {
            self.materials
                .get(id as usize)
                .and_then(|m| m.textures.normal.as_ref())
                .map(|n| n.map.uv_set)
        };
        for inst in &self.instances {
            let Some(w) = wanted.get_mut(inst.mesh as usize) else {
                continue;
            };
            if w.is_some() {
                continue;
            }
            *w = match (inst.material, &self.meshes[inst.mesh as usize].material_ids) {
                (Some(m), _) => normal_set(m),
                (None, Some(ids)) => {
                    let mut seen = std::collections::HashSet::new();
                    ids.iter()
                        .filter(|&&id| seen.insert(id))
                        .find_map(|&id| normal_set(id))
                }
                (None, None) => normal_set(0),
            };
        }
        let mut n = 0;
        for (mesh, set) in self.meshes.iter_mut().zip(wanted) {
            if let Some(set) = set {
                if mesh.tangents.is_none() && mesh.generate_tangents(set) {
                    n += 1;
                }
            }
        }
        n
    }

    /// Checks every index and array length; returns the first problem.
    pub fn validate(&self) -> Result<(), String> {
        for (i, m) in self.meshes.iter().enumerate() {
            m.validate().map_err(|e| format!("mesh {i}: {e}"))?;
            if let Some(ids) = &m.material_ids {
                if let Some(id) = ids.iter().find(|&&id| id as usize >= self.materials.len()) {
                    return Err(format!("mesh {i}: material id {id} out of range"));
                }
            }
        }
        for (i, inst) in self.instances.iter().enumerate() {
            if inst.mesh as usize >= self.meshes.len() {
                return Err(format!("instance {i}: mesh {} out of range", inst.mesh));
            }
            let m = &self.meshes[inst.mesh as usize];
            let mat = inst.material.unwrap_or(0);
            if (inst.material.is_some() || m.material_ids.is_none())
                && mat as usize >= self.materials.len()
            {
                return Err(format!("instance {i}: material {mat} out of range"));
            }
        }
        for s in &self.shapes {
            if s.instance as usize >= self.instances.len() {
                return Err(format!("shape instance {} out of range", s.instance));
            }
        }
        let c = &self.camera;
        if !(c.vfov_deg > 0.0 && c.vfov_deg < 180.0 && c.aspect > 0.0 && c.eye.is_finite()) {
            return Err("camera: field of view, aspect or position invalid".into());
        }
        Ok(())
    }

    /// Radiance emitted by the scene's brightest emitter (a quick check for
    /// a scene with no light at all).
    pub fn has_light(&self) -> bool {
        !self.lights.is_empty()
            || self.environment.is_some()
            || self.materials.iter().any(|m| m.is_emissive())
    }

    /// Problems that do not stop a render, one line each: triangles no ray
    /// can hit, over all meshes (non-finite coordinates or zero area; the
    /// kd-trees leave them out, and bounds and framing ignore them) and a
    /// scene without any light (it renders black but for what emits).
    pub fn diagnostics(&self) -> Vec<String> {
        let mut out = Vec::new();
        let (mut non_finite, mut flat, mut total) = (0, 0, 0);
        for m in &self.meshes {
            let (a, b) = m.mesh.skipped_counts();
            non_finite += a;
            flat += b;
            total += m.mesh.indices.len();
        }
        if non_finite + flat > 0 {
            let why: Vec<String> = [
                (non_finite, "with a NaN or infinite corner"),
                (flat, "of zero area"),
            ]
            .into_iter()
            .filter(|(n, _)| *n > 0)
            .map(|(n, what)| format!("{n} {what}"))
            .collect();
            out.push(format!(
                "{} of {total} triangles skipped ({})",
                non_finite + flat,
                why.join(", ")
            ));
        }
        if !self.has_light() {
            out.push(
                "the scene has no light (no light source, emissive material or environment): \
                 the image will be black"
                    .to_string(),
            );
        } else if self.emitters_face_away() {
            out.push(
                "no light reaches the scene: every emitting surface emits from its front face \
                 only, and each faces away from the rest of the scene (flip its winding, or \
                 make its emission two-sided)"
                    .to_string(),
            );
        }
        out
    }

    /// True if the scene's only light is emitting surfaces, each static,
    /// one-sided triangle of which has the box around all the other
    /// geometry behind its plane: then no light reaches anything but the
    /// emitters themselves. Moving or two-sided emitters count as
    /// reaching, as do lights of any other kind.
    fn emitters_face_away(&self) -> bool {
        if !self.lights.is_empty() || self.environment.is_some() {
            return false;
        }
        // One pass over the triangles: the box around those that do not
        // emit (in each instance's own space, placed once per instance),
        // and the emitting ones (instance, triangle, material).
        let mut others = Aabb::EMPTY;
        let mut emitters = Vec::new();
        for (i, inst) in self.instances.iter().enumerate() {
            let mesh = &self.meshes[inst.mesh as usize].mesh;
            let mut local = Aabb::EMPTY;
            for (t, tri) in mesh.indices.iter().enumerate() {
                let m = &self.materials[self.material_of(i as u32, t as u32) as usize];
                if m.is_emissive() {
                    emitters.push((inst, tri, m));
                } else {
                    local = tri
                        .iter()
                        .fold(local, |b, &v| b.grow(mesh.positions[v as usize]));
                }
            }
            others = others.union(inst.placement.world_bounds(local));
        }
        if others.is_empty() {
            return false;
        }
        for (inst, tri, m) in emitters {
            let Placement::Static(xf) = inst.placement else {
                return false;
            };
            if m.two_sided_emission {
                return false;
            }
            let mesh = &self.meshes[inst.mesh as usize].mesh;
            let [a, b, c] = tri.map(|v| xf.transform_point3(mesh.positions[v as usize]));
            let n = (b - a).cross(c - a);
            // The corner of the box farthest along the front normal.
            let far = Vec3::select(n.cmpgt(Vec3::ZERO), others.max, others.min);
            if n.dot(far - a) > 0.0 {
                return false;
            }
        }
        true
    }
}
