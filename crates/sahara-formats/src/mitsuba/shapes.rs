//! Mitsuba shapes as Sahara objects.
//!
//! | Mitsuba | Sahara |
//! |---|---|
//! | `rectangle` (`[-1, 1]^2` in `z = 0`, front `+z`) | the exact quad, placed by `to_world` |
//! | `cube` (`[-1, 1]^3`) | the exact box (tessellated by the assembly under a rotation) |
//! | `disk` (unit disc in `z = 0`, front `+z`) | the exact disc |
//! | `sphere` (`center`, `radius`, a similarity `to_world`) | the exact sphere in world space |
//! | `cylinder` (`p0`, `p1`, `radius`, open) | a mesh of 128 segments (warned) |
//! | `obj`, `ply`, `serialized` (`shape_index`) | the file's mesh, read once per file and options |
//! | `shapegroup`, `instance` | one mesh per group, an object per instance |
//!
//! - Fronts: Mitsuba's analytic shapes (rectangle, disk, sphere) face
//!   their normal transformed as a normal, so under a mirroring
//!   `to_world` Sahara's quad and disc are flipped to keep that side;
//!   meshes face their winding in both renderers. `flip_normals` flips the
//!   front (a sphere or cube then becomes a mesh facing in).
//! - Normals: a mesh without vertex normals gets smooth ones, as Mitsuba
//!   computes them; `face_normals` drops them.
//! - Texture coordinates are Mitsuba's (`v = 0` at an image's top row):
//!   an OBJ's `v` is flipped on load as Mitsuba flips it, PLY and
//!   serialized ones are kept, and every image texture reads them so.

use glam::{Affine3A, DMat3, DMat4, DVec3, Mat3, Vec2, Vec3};
use sahara_readers::FormatError;
use sahara_render::{Mesh, SceneMesh, Shape};

use super::builder::{key, Builder};
use super::properties::Object;
use super::serialized::parse_serialized;
use super::xml::Node;
use crate::common::gzip::read_maybe_gz;
use crate::common::mesh::smooth_normals;
use crate::description::{Geometry, Object as SceneObject, ObjectPlacement};

/// Rim segments of a tessellated cylinder.
const SEGMENTS: u32 = 128;

/// Shape types Mitsuba has that Sahara skips.
const SKIPPED: &[&str] = &[
    "bsplinecurve",
    "linearcurve",
    "sdfgrid",
    "ellipsoids",
    "ellipsoidsmesh",
    "blender",
    "merge",
];

/// A shape's geometry before it is placed.
pub(crate) enum Geom {
    /// An exact shape in object space, placed by the transform.
    Exact(Shape, DMat4),
    /// An exact shape already in world space.
    World(Shape),
    /// Mesh `i` of the description, placed by the transform.
    Shared(u32, DMat4),
    /// A mesh of its own, placed by the transform.
    Own(SceneMesh, DMat4),
}

/// The exact quad `[-1, 1]^2` facing `+z`, or `-z` when `flip`.
fn rectangle(flip: bool) -> Shape {
    let (a, b) = (Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 2.0, 0.0));
    let (edge_u, edge_v) = if flip { (b, a) } else { (a, b) };
    Shape::Quad {
        corner: Vec3::new(-1.0, -1.0, 0.0),
        edge_u,
        edge_v,
    }
}

/// True if `m` mirrors.
fn mirrors(m: &DMat4) -> bool {
    DMat3::from_mat4(*m).determinant() < 0.0
}

/// `mesh` with its fronts turned the other way.
fn flipped(mut mesh: SceneMesh) -> SceneMesh {
    for t in &mut mesh.mesh.indices {
        t.swap(1, 2);
    }
    if let Some(n) = &mut mesh.normals {
        n.iter_mut().for_each(|v| *v = -*v);
    }
    mesh
}

/// An open cylinder from `p0` to `p1` of radius `r`, facing out, with
/// Mitsuba's uv (`u` around, `v` along).
fn cylinder(p0: Vec3, p1: Vec3, r: f32) -> SceneMesh {
    let d = (p1 - p0).normalize_or_zero();
    let (s, t) = d.any_orthonormal_pair();
    let n = SEGMENTS;
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    for j in 0..=1u32 {
        for i in 0..=n {
            let phi = std::f32::consts::TAU * i as f32 / n as f32;
            let radial = s * phi.cos() + t * phi.sin();
            positions.push(p0 + (p1 - p0) * j as f32 + radial * r);
            normals.push(radial);
            uvs.push(Vec2::new(i as f32 / n as f32, j as f32));
        }
    }
    let mut indices = Vec::new();
    for i in 0..n {
        let (a, b) = (i, i + 1);
        let (c, e) = (b + n + 1, a + n + 1);
        indices.push([a, b, c]);
        indices.push([a, c, e]);
    }
    SceneMesh {
        mesh: Mesh { positions, indices },
        normals: Some(normals),
        uvs: Some(uvs),
        ..SceneMesh::default()
    }
}

/// A placement by `m`.
fn placement(m: &DMat4) -> ObjectPlacement {
    ObjectPlacement::Static(Affine3A::from_mat4(m.as_mat4()))
}

/// `mesh` under `m`, normals transformed as normals.
fn transformed(mut mesh: SceneMesh, m: &DMat4) -> SceneMesh {
    let mf = m.as_mat4();
    let nm = Mat3::from_mat4(mf).inverse().transpose();
    mesh.mesh
        .positions
        .iter_mut()
        .for_each(|p| *p = mf.transform_point3(*p));
    if let Some(n) = &mut mesh.normals {
        n.iter_mut()
            .for_each(|v| *v = (nm * *v).normalize_or_zero());
    }
    mesh
}

impl<'a> Builder<'a> {
    /// A `<shape>` directly in the scene.
    pub(crate) fn top_shape(&mut self, node: &'a Node) -> Result<(), FormatError> {
        let o = self.object(node)?;
        match o.ty {
            "shapegroup" => {
                if node.attr("id").is_none() {
                    self.w.add(
                        "a shapegroup without an id cannot be instanced; ignored",
                        &node.loc,
                    );
                }
                o.mark_all_used();
                return Ok(());
            }
            "instance" => return self.instance(&o),
            _ => {}
        }
        let (material, emitter) = self.shape_material(&o, true)?;
        let media = self.shape_media(&o)?;
        // A shape bounding media without a surface of its own: no material.
        let material = match (material, media) {
            (_, Some(mi)) if mi.index_matched && emitter.is_none() => None,
            (Some(m), _) => Some(m),
            (None, _) => {
                o.mark_all_used();
                return Ok(());
            }
        };
        let Some(geom) = self.geometry(&o)? else {
            return Ok(());
        };
        let material = match (emitter, material) {
            (Some(e), Some(m)) => Some(self.area_light(m, e)?),
            (_, m) => m,
        };
        o.warn_unused(&mut self.w);
        let (geometry, placement) = match geom {
            Geom::Exact(s, m) => (Geometry::Shape(s), placement(&m)),
            Geom::World(s) => (Geometry::Shape(s), ObjectPlacement::World),
            Geom::Shared(i, m) => (Geometry::Mesh(i), placement(&m)),
            Geom::Own(mesh, m) => (Geometry::Mesh(self.scene.add_mesh(mesh)), placement(&m)),
        };
        self.scene.objects.push(SceneObject {
            geometry,
            placement,
            material,
            name: o.node.attr("id").map(str::to_owned),
        });
        if let Some(mut mi) = media {
            mi.index_matched &= material.is_none();
            let k = self.scene.objects.len() as u32 - 1;
            self.scene.medium_interfaces.push((k, mi));
        }
        Ok(())
    }

    /// The shape's material and its area emitter, if any; `None` for the
    /// material: the shape is not rendered (a `null` bsdf, no emitter).
    fn shape_material(
        &mut self,
        o: &Object<'a>,
        may_emit: bool,
    ) -> Result<(Option<u32>, Option<&'a Node>), FormatError> {
        let mut bsdf = None;
        let mut emitter = None;
        for e in o.entries() {
            let tag = e.child.node().tag.as_str();
            if !["ref", "bsdf", "emitter", "medium"].contains(&tag) {
                continue;
            }
            let node = self.resolve(
                e.child,
                &["bsdf", "emitter", "medium"],
                "a <bsdf> or <emitter>",
            )?;
            match node.tag.as_str() {
                "bsdf" if bsdf.is_some() => {
                    return Err(e
                        .child
                        .node()
                        .error(format!("{} has more than one bsdf", o.what())))
                }
                "bsdf" => bsdf = Some(node),
                "emitter" if emitter.is_some() => {
                    return Err(e
                        .child
                        .node()
                        .error(format!("{} has more than one emitter", o.what())))
                }
                "emitter" => emitter = Some(node),
                // Read by `shape_media` (a shape directly in the scene).
                "medium" if may_emit => {}
                "medium" => self.w.add(
                    "media on shapes inside a shapegroup are not supported; ignored",
                    &e.child.node().loc,
                ),
                _ => continue,
            }
            e.take();
        }
        if emitter.is_some() && !may_emit {
            self.w.add(
                "emitters inside a shapegroup are not supported (as in Mitsuba); they do not emit",
                &o.node.loc,
            );
            emitter = None;
        }
        let material = match (bsdf, emitter) {
            (Some(b), _) => self.material(b)?,
            // Mitsuba's emitters without a bsdf reflect nothing.
            (None, Some(_)) => Some(self.black_material()),
            (None, None) => Some(self.default_material()),
        };
        match (material, emitter) {
            (Some(m), e) => Ok((Some(m), e)),
            (None, None) => Ok((None, None)),
            (None, Some(e)) => {
                self.w.add(
                    "a 'null' bsdf with an area emitter: the emitter's surface blocks light (black)",
                    &o.node.loc,
                );
                Ok((Some(self.black_material()), Some(e)))
            }
        }
    }

    /// The geometry of shape `o`, or `None` if Sahara skips it.
    pub(crate) fn geometry(&mut self, o: &Object<'a>) -> Result<Option<Geom>, FormatError> {
        let m = o.transform("to_world")?;
        let flip = o.bool("flip_normals", false)?;
        Ok(Some(match o.ty {
            "rectangle" => Geom::Exact(rectangle(flip != mirrors(&m)), m),
            "disk" => Geom::Exact(
                Shape::Disc {
                    center: Vec3::ZERO,
                    normal: if flip != mirrors(&m) {
                        -Vec3::Z
                    } else {
                        Vec3::Z
                    },
                    radius: 1.0,
                },
                m,
            ),
            "cube" => {
                let b = Shape::Box {
                    min: Vec3::splat(-1.0),
                    max: Vec3::ONE,
                };
                if flip {
                    self.w.add(
                        "a cube with flip_normals becomes a mesh facing in",
                        &o.node.loc,
                    );
                    Geom::Own(flipped(b.to_mesh()), m)
                } else {
                    Geom::Exact(b, m)
                }
            }
            "sphere" => {
                let c = o.vector("center")?.unwrap_or(DVec3::ZERO);
                let r = o.float("radius", 1.0)?;
                if r <= 0.0 {
                    return Err(o.error("sphere: 'radius' must be > 0"));
                }
                let lin = DMat3::from_mat4(m);
                let lens = [lin.x_axis, lin.y_axis, lin.z_axis].map(DVec3::length);
                let similar = lens.iter().all(|&l| (l - lens[0]).abs() <= 1e-5 * lens[0])
                    && lin.x_axis.dot(lin.y_axis).abs() <= 1e-5 * lens[0] * lens[0]
                    && lin.y_axis.dot(lin.z_axis).abs() <= 1e-5 * lens[0] * lens[0]
                    && lin.x_axis.dot(lin.z_axis).abs() <= 1e-5 * lens[0] * lens[0];
                if !similar {
                    self.w.add(
                        "sphere: a 'to_world' that is not a rotation, uniform scale and translation (Mitsuba refuses it too) scales by its x axis",
                        &o.node.loc,
                    );
                }
                let shape = Shape::Sphere {
                    center: m.transform_point3(c).as_vec3(),
                    radius: (r * lens[0]) as f32,
                };
                if flip {
                    self.w.add(
                        "a sphere with flip_normals becomes a mesh facing in",
                        &o.node.loc,
                    );
                    Geom::Own(flipped(shape.to_mesh()), DMat4::IDENTITY)
                } else {
                    Geom::World(shape)
                }
            }
            "cylinder" => {
                let p0 = o.vector("p0")?.unwrap_or(DVec3::ZERO).as_vec3();
                let p1 = o.vector("p1")?.unwrap_or(DVec3::Z).as_vec3();
                let r = o.float("radius", 1.0)? as f32;
                if r <= 0.0 || p0 == p1 {
                    return Err(o.error("cylinder: needs 'radius' > 0 and p0 != p1"));
                }
                self.w.add(
                    format!(
                        "cylinder: tessellated ({SEGMENTS} segments; Sahara has no exact cylinder)"
                    ),
                    &o.node.loc,
                );
                let mesh = cylinder(p0, p1, r);
                Geom::Own(if flip { flipped(mesh) } else { mesh }, m)
            }
            "obj" | "ply" | "serialized" => match self.file_mesh(o, flip)? {
                Some(i) => Geom::Shared(i, m),
                None => return Ok(None),
            },
            t if SKIPPED.contains(&t) => {
                self.w.add(
                    format!("shape '{t}' is not supported; skipped"),
                    &o.node.loc,
                );
                o.mark_all_used();
                return Ok(None);
            }
            "shapegroup" | "instance" => {
                return Err(o.error(format!("a '{}' cannot be nested here", o.ty)))
            }
            other => return Err(o.error(format!("unknown shape type '{other}'"))),
        }))
    }

    /// The mesh of an `obj`, `ply` or `serialized` shape, read once per
    /// file and options; `None` if it has no triangles.
    fn file_mesh(&mut self, o: &Object<'a>, flip: bool) -> Result<Option<u32>, FormatError> {
        let Some(path) = o.file("filename", &self.main)? else {
            return Err(o.error(format!("shape '{}' needs a 'filename' string", o.ty)));
        };
        let face = o.bool("face_normals", false)?;
        let index = if o.ty == "serialized" {
            o.int("shape_index", 0)?
        } else {
            0
        };
        if index < 0 {
            return Err(o.error("serialized: 'shape_index' must be >= 0"));
        }
        let k = (path.clone(), index, face, flip);
        if let Some(m) = self.file_meshes.get(&k) {
            return Ok(*m);
        }
        let name = path.display().to_string();
        let at = |e: FormatError| o.error(e);
        let (mut mesh, face) = match o.ty {
            "obj" => {
                let obj = sahara_readers::obj::load_obj_geometry(&path).map_err(at)?;
                // Mitsuba flips an OBJ's v on load.
                let uvs = obj
                    .uvs
                    .map(|u| u.into_iter().map(|v| Vec2::new(v.x, 1.0 - v.y)).collect());
                (
                    SceneMesh {
                        mesh: obj.mesh,
                        normals: obj.normals,
                        uvs,
                        ..SceneMesh::default()
                    },
                    face,
                )
            }
            "ply" => {
                let bytes = read_maybe_gz(&path).map_err(at)?;
                let ply =
                    sahara_readers::ply::parse_ply_with_attributes(&bytes, &name).map_err(at)?;
                (
                    SceneMesh {
                        mesh: ply.mesh,
                        normals: ply.normals,
                        uvs: ply.uvs,
                        ..SceneMesh::default()
                    },
                    face,
                )
            }
            _ => {
                let bytes = std::fs::read(&path).map_err(|e| at(FormatError::io(&path, e)))?;
                let s = parse_serialized(&bytes, &name, index as usize).map_err(at)?;
                (s.mesh, face || s.face_normals)
            }
        };
        let out = if mesh.mesh.indices.is_empty() {
            self.w.add(
                format!("{name}: the mesh has no triangles; skipped"),
                &o.node.loc,
            );
            None
        } else {
            if face {
                mesh.normals = None;
            } else if mesh.normals.is_none() {
                mesh.normals = Some(smooth_normals(&mesh.mesh.positions, &mesh.mesh.indices));
            }
            if flip {
                mesh = flipped(mesh);
            }
            Some(self.scene.add_mesh(mesh))
        };
        self.file_meshes.insert(k, out);
        Ok(out)
    }

    /// An `instance` of a shapegroup.
    fn instance(&mut self, o: &Object<'a>) -> Result<(), FormatError> {
        let m = o.transform("to_world")?;
        let mut group = None;
        for e in o.entries() {
            let node = self.resolve(e.child, &["shape"], "a shapegroup")?;
            e.take();
            if group.is_some() {
                return Err(e.child.node().error("an instance refers to one shapegroup"));
            }
            group = Some(node);
        }
        let Some(group) = group else {
            return Err(o.error("an instance needs a <ref id=...> to a shapegroup"));
        };
        if group.attr("type") != Some("shapegroup") {
            return Err(o.error(format!(
                "an instance refers to a shapegroup, not a shape of type '{}'",
                group.attr("type").unwrap_or("")
            )));
        }
        o.warn_unused(&mut self.w);
        let Some(mesh) = self.group_mesh(group)? else {
            return Ok(());
        };
        self.scene.objects.push(SceneObject {
            geometry: Geometry::Mesh(mesh),
            placement: placement(&m),
            material: None,
            name: o.node.attr("id").or(group.attr("id")).map(str::to_owned),
        });
        Ok(())
    }

    /// The one mesh of a shapegroup: its shapes with their transforms
    /// applied, a material per triangle; `None` if nothing in it is
    /// rendered.
    fn group_mesh(&mut self, group: &'a Node) -> Result<Option<u32>, FormatError> {
        if let Some(m) = self.groups.get(&key(group)) {
            return Ok(*m);
        }
        let g = self.object(group)?;
        let mut out = SceneMesh::default();
        let (mut normals, mut uvs, mut ids) = (Vec::new(), Vec::new(), Vec::new());
        let (mut any_normals, mut any_uvs) = (false, false);
        for node in g.nested("shape") {
            let o = self.object(node)?;
            if matches!(o.ty, "shapegroup" | "instance") {
                return Err(o.error(format!("a shapegroup cannot hold a '{}'", o.ty)));
            }
            let (Some(material), _) = self.shape_material(&o, false)? else {
                o.mark_all_used();
                continue;
            };
            let Some(geom) = self.geometry(&o)? else {
                continue;
            };
            o.warn_unused(&mut self.w);
            let mesh = match geom {
                Geom::Exact(s, m) => transformed(s.to_mesh(), &m),
                Geom::World(s) => s.to_mesh(),
                Geom::Shared(i, m) => transformed(self.scene.meshes[i as usize].clone(), &m),
                Geom::Own(mesh, m) => transformed(mesh, &m),
            };
            let base = out.mesh.positions.len();
            let Ok(base32) = u32::try_from(base) else {
                return Err(g.error("the shapegroup has more than 2^32 vertices"));
            };
            normals.resize(base, Vec3::ZERO);
            uvs.resize(base, Vec2::ZERO);
            let n = mesh.mesh.positions.len();
            match mesh.normals {
                Some(v) => {
                    any_normals = true;
                    normals.extend(v);
                }
                None => normals.extend(smooth_normals(&mesh.mesh.positions, &mesh.mesh.indices)),
            }
            match mesh.uvs {
                Some(v) => {
                    any_uvs = true;
                    uvs.extend(v);
                }
                None => uvs.extend(std::iter::repeat_n(Vec2::ZERO, n)),
            }
            ids.extend(std::iter::repeat_n(material, mesh.mesh.indices.len()));
            out.mesh
                .indices
                .extend(mesh.mesh.indices.iter().map(|t| t.map(|i| i + base32)));
            out.mesh.positions.extend(mesh.mesh.positions);
        }
        g.warn_unused(&mut self.w);
        let m = if out.mesh.indices.is_empty() {
            None
        } else {
            out.normals = any_normals.then_some(normals);
            out.uvs = any_uvs.then_some(uvs);
            out.material_ids = Some(ids);
            Some(self.scene.add_mesh(out))
        };
        self.groups.insert(key(group), m);
        Ok(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cylinder_faces_out_and_spans_its_axis() {
        let c = cylinder(Vec3::ZERO, Vec3::new(0.0, 0.0, 2.0), 0.5);
        for t in &c.mesh.indices {
            let [a, b, d] = t.map(|i| c.mesh.positions[i as usize]);
            let n = (b - a).cross(d - a);
            let mid = (a + b + d) / 3.0;
            assert!(n.dot(Vec3::new(mid.x, mid.y, 0.0)) > 0.0);
        }
        let zmax = c.mesh.positions.iter().map(|p| p.z).fold(0.0, f32::max);
        assert_eq!(zmax, 2.0);
    }

    #[test]
    fn a_flipped_rectangle_faces_minus_z() {
        let Shape::Quad { edge_u, edge_v, .. } = rectangle(true) else {
            unreachable!()
        };
        assert_eq!(edge_u.cross(edge_v).normalize(), -Vec3::Z);
    }
}
