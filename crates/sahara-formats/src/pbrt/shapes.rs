//! pbrt shapes as meshes in object space (or, for full spheres and discs,
//! Sahara's exact shapes so that emitters are sampled analytically).
//!
//! - `trianglemesh`, `plymesh` (`.ply` or `.ply.gz`; quads and polygons
//!   fan-triangulated), `bilinearmesh` (each patch as two triangles),
//!   `loopsubdiv` (subdivided to `levels`), pbrt-v3 `heightfield`.
//! - `sphere`, `disk`, `cylinder` with their partial forms (`zmin`, `zmax`,
//!   `phimax`, `innerradius`), tessellated; a full sphere or disc is also
//!   kept exact.
//! - `curve`, `nurbs`, `cone`, `paraboloid`, `hyperboloid` and
//!   displacement are not supported: a warning with their count.
//!
//! Faces are wound so that their front (Sahara's `(v1 - v0) x (v2 - v0)`)
//! is pbrt's surface normal `dp/du x dp/dv`; the caller flips them for
//! `ReverseOrientation` and for transforms that swap handedness.

use glam::{Vec2, Vec3};
use sahara_render::Shape;
use sahara_render::{Mesh, SceneMesh};

use super::declarations::Entity;
use super::subdivision::loop_subdivide;
use crate::common::gzip::read_maybe_gz;
use crate::common::mesh::smooth_normals;
use crate::common::warnings::Warnings;
use sahara_readers::fan::fan_triangulate;
use sahara_readers::ply::parse_ply_with_attributes;
use sahara_readers::FormatError;

/// Largest number of triangles a shape may make (subdivision).
#[cfg(not(fuzzing))]
const MAX_TRIANGLES: u64 = 1 << 24;
/// The fuzz targets' budget (cargo-fuzz sets `cfg(fuzzing)`): their
/// instrumented build subdivides 262,144 triangles in 0.4 s, so the full
/// budget would take some 25 s, past the 20 s timeout `fuzz/run.sh` sets;
/// the check is the same at either size.
#[cfg(fuzzing)]
const MAX_TRIANGLES: u64 = 1 << 14;

/// Rim segments of a tessellated full circle.
const SEGMENTS: u32 = 128;

/// What a shape becomes.
pub(crate) struct Geometry {
    /// The triangles (object space).
    pub(crate) mesh: SceneMesh,
    /// The exact shape, for a full sphere or disc (object space).
    pub(crate) exact: Option<Shape>,
}

fn f32s(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
}

/// Indices from an `integer` array: in range, whole groups of `group`.
fn indices(
    e: &Entity,
    name: &str,
    vertices: usize,
    group: usize,
) -> Result<Option<Vec<u32>>, FormatError> {
    let Some(v) = e.params.ints(name)? else {
        return Ok(None);
    };
    let p = e.params.get(name).expect("present");
    if v.len() % group != 0 {
        return Err(p.error(format!(
            "{} indices are not a whole number of {group}s",
            v.len()
        )));
    }
    v.iter()
        .map(|&i| {
            if i < 0.0 || i >= vertices as f64 {
                Err(p.error(format!("index {i} is out of range ({vertices} vertices)")))
            } else {
                Ok(i as u32)
            }
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}

/// Positions, normals and texture coordinates.
type VertexArrays = (Vec<Vec3>, Option<Vec<Vec3>>, Option<Vec<Vec2>>);

/// `P`, and `N` and `uv` if given (each one per vertex).
fn vertex_arrays(e: &Entity) -> Result<VertexArrays, FormatError> {
    let Some(p) = e.params.triples("P")? else {
        return Err(e
            .loc
            .error(format!("shape '{}' needs \"point3 P\"", e.kind)));
    };
    if p.len() > u32::MAX as usize {
        return Err(e.loc.error("more than 2^32 vertices"));
    }
    let n = p.len();
    let normals = e.params.triples("N")?;
    if let Some(nn) = &normals {
        if nn.len() != n {
            let par = e.params.get("N").expect("present");
            return Err(par.error(format!("{} normals for {n} vertices", nn.len())));
        }
    }
    let uv_name = ["uv", "st"].into_iter().find(|k| e.params.has(k));
    let uvs = match uv_name {
        Some(k) => {
            let uv = e.params.pairs(k)?.expect("present");
            if uv.len() != n {
                let par = e.params.get(k).expect("present");
                return Err(par.error(format!("{} texture coordinates for {n} vertices", uv.len())));
            }
            Some(
                uv.into_iter()
                    .map(|[u, v]| Vec2::new(u as f32, v as f32))
                    .collect(),
            )
        }
        None => None,
    };
    Ok((
        p.into_iter().map(f32s).collect(),
        normals.map(|v| v.into_iter().map(f32s).collect()),
        uvs,
    ))
}

fn scene_mesh(
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    normals: Option<Vec<Vec3>>,
    uvs: Option<Vec<Vec2>>,
) -> SceneMesh {
    SceneMesh {
        mesh: Mesh { positions, indices },
        normals,
        uvs,
        ..SceneMesh::default()
    }
}

/// The geometry of shape `e`, or `None` (with a warning) for shapes Sahara
/// does not render.
pub(crate) fn shape_geometry(
    e: &Entity,
    w: &mut Warnings,
) -> Result<Option<Geometry>, FormatError> {
    // `alpha` (cut-outs) is read by the caller.
    if e.params.get("shadowalpha").is_some() {
        w.add(
            "shape 'shadowalpha' is not supported; the shape's 'alpha' cuts its shadows too",
            &e.loc,
        );
    }
    e.params.get("emissionfilename");
    let mesh = match e.kind.as_str() {
        "trianglemesh" => {
            let (p, n, uv) = vertex_arrays(e)?;
            let idx = match indices(e, "indices", p.len(), 3)? {
                Some(i) => i,
                None if p.len() == 3 => vec![0, 1, 2],
                None => {
                    return Err(e.loc.error(
                        "trianglemesh needs \"integer indices\" (only a single triangle may leave them out)",
                    ))
                }
            };
            for k in ["S", "faceIndices"] {
                e.params.get(k);
            }
            let tris = idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            scene_mesh(p, tris, n, uv)
        }
        "bilinearmesh" => {
            let (p, n, uv) = vertex_arrays(e)?;
            let idx = match indices(e, "indices", p.len(), 4)? {
                Some(i) => i,
                None if p.len() == 4 => vec![0, 1, 2, 3],
                None => return Err(e.loc.error("bilinearmesh needs \"integer indices\"")),
            };
            e.params.get("faceIndices");
            // Patch corners p00 p10 p01 p11: the quad p00 p10 p11 p01.
            let tris = idx
                .chunks_exact(4)
                .flat_map(|c| [[c[0], c[1], c[3]], [c[0], c[3], c[2]]])
                .collect();
            scene_mesh(p, tris, n, uv)
        }
        "loopsubdiv" => {
            let (p, _, _) = vertex_arrays(e)?;
            let idx = indices(e, "indices", p.len(), 3)?
                .ok_or_else(|| e.loc.error("loopsubdiv needs \"integer indices\""))?;
            let levels = e.params.int("levels", 3)?.clamp(0, 16) as u32;
            let tris: Vec<[u32; 3]> = idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            if (tris.len() as u64).saturating_mul(4u64.saturating_pow(levels)) > MAX_TRIANGLES {
                return Err(e.loc.error(format!(
                    "loopsubdiv: {} triangles subdivided {levels} times make more than {MAX_TRIANGLES}",
                    tris.len()
                )));
            }
            let (p, t) = loop_subdivide(p, tris, levels);
            let n = smooth_normals(&p, &t);
            scene_mesh(p, t, Some(n), None)
        }
        "plymesh" => {
            let Some(file) = e.params.string("filename")? else {
                return Err(e.loc.error("plymesh needs \"string filename\""));
            };
            for k in ["displacement", "edgelength"] {
                if e.params.get(k).is_some() {
                    w.add(
                        "plymesh displacement is not supported; the mesh is not displaced",
                        &e.loc,
                    );
                }
            }
            let path = super::parser::resolve(&e.folders, file);
            let bytes = read_maybe_gz(&path).map_err(|err| e.loc.error(err))?;
            let ply = parse_ply_with_attributes(&bytes, &path.display().to_string())
                .map_err(|err| e.loc.error(err))?;
            scene_mesh(ply.mesh.positions, ply.mesh.indices, ply.normals, ply.uvs)
        }
        "heightfield" => heightfield(e)?,
        "sphere" => return sphere(e, w),
        "disk" => return disk(e, w),
        "cylinder" => match cylinder(e, w)? {
            Some(g) => g,
            None => return Ok(None),
        },
        "curve" | "nurbs" | "cone" | "paraboloid" | "hyperboloid" => {
            w.add(
                format!("shape '{}' is not supported; skipped", e.kind),
                &e.loc,
            );
            e.params.mark_all_used();
            return Ok(None);
        }
        other => return Err(e.loc.error(format!("unknown shape type '{other}'"))),
    };
    Ok(Some(Geometry { mesh, exact: None }))
}

/// A `heightfield`: a grid of `nu` x `nv` heights `Pz` over the unit square.
fn heightfield(e: &Entity) -> Result<SceneMesh, FormatError> {
    let nu = e.params.int("nu", 0)?;
    let nv = e.params.int("nv", 0)?;
    let z = e.params.floats("Pz")?.unwrap_or(&[]);
    if nu < 2 || nv < 2 || (nu as u64).saturating_mul(nv as u64) != z.len() as u64 {
        return Err(e.loc.error(format!(
            "heightfield: nu = {nu}, nv = {nv} need nu, nv >= 2 and nu * nv values of Pz (found {})",
            z.len()
        )));
    }
    let (nu, nv) = (nu as u32, nv as u32);
    Ok(grid(nu - 1, nv - 1, |u, v| {
        let (i, j) = (
            (u * (nu - 1) as f32).round() as usize,
            (v * (nv - 1) as f32).round() as usize,
        );
        Vec3::new(u, v, z[j * nu as usize + i] as f32)
    }))
}

/// A `sphere` (part of one, between `zmin` and `zmax`, up to `phimax`), exact when whole.
fn sphere(e: &Entity, w: &mut Warnings) -> Result<Option<Geometry>, FormatError> {
    let r = e.params.float("radius", 1.0)?;
    let zmin = e.params.float("zmin", -r)?.clamp(-r, r);
    let zmax = e.params.float("zmax", r)?.clamp(-r, r);
    let phimax = e
        .params
        .float("phimax", 360.0)?
        .clamp(0.0, 360.0)
        .to_radians();
    if r <= 0.0 || zmin >= zmax || phimax <= 0.0 {
        w.add(
            "degenerate sphere (radius, zmin / zmax or phimax) skipped",
            &e.loc,
        );
        return Ok(None);
    }
    let (t0, t1) = ((zmin / r).acos(), (zmax / r).acos());
    let full = zmin <= -r && zmax >= r && phimax >= 2.0 * std::f64::consts::PI;
    let (r, t0, t1, phimax) = (r as f32, t0 as f32, t1 as f32, phimax as f32);
    let bands = ((t0 - t1) / std::f32::consts::PI * (SEGMENTS / 2) as f32)
        .ceil()
        .max(1.0) as u32;
    let segs = (phimax / (2.0 * std::f32::consts::PI) * SEGMENTS as f32)
        .ceil()
        .max(1.0) as u32;
    let mut g = grid(segs, bands, |u, v| {
        let phi = u * phimax;
        let theta = t0 + (t1 - t0) * v;
        Vec3::new(
            r * theta.sin() * phi.cos(),
            r * theta.sin() * phi.sin(),
            r * theta.cos(),
        )
    });
    g.normals = Some(
        g.mesh
            .positions
            .iter()
            .map(|p| p.normalize_or_zero())
            .collect(),
    );
    Ok(Some(Geometry {
        mesh: g,
        exact: full.then_some(Shape::Sphere {
            center: Vec3::ZERO,
            radius: r,
        }),
    }))
}

/// A `disk` (an annulus with `innerradius`, up to `phimax`), exact when whole.
fn disk(e: &Entity, w: &mut Warnings) -> Result<Option<Geometry>, FormatError> {
    let h = e.params.float("height", 0.0)? as f32;
    let r = e.params.float("radius", 1.0)? as f32;
    let ri = e.params.float("innerradius", 0.0)?.max(0.0) as f32;
    let phimax = e
        .params
        .float("phimax", 360.0)?
        .clamp(0.0, 360.0)
        .to_radians() as f32;
    if r <= 0.0 || ri >= r || phimax <= 0.0 {
        w.add(
            "degenerate disk (radius, innerradius or phimax) skipped",
            &e.loc,
        );
        return Ok(None);
    }
    let full = ri == 0.0 && phimax >= 2.0 * std::f32::consts::PI - 1e-6;
    let segs = (phimax / (2.0 * std::f32::consts::PI) * SEGMENTS as f32)
        .ceil()
        .max(1.0) as u32;
    let mut g = grid(segs, 1, |u, v| {
        let phi = u * phimax;
        let rr = r + (ri - r) * v;
        Vec3::new(rr * phi.cos(), rr * phi.sin(), h)
    });
    g.normals = Some(vec![Vec3::Z; g.mesh.positions.len()]);
    Ok(Some(Geometry {
        mesh: g,
        exact: full.then_some(Shape::Disc {
            center: Vec3::new(0.0, 0.0, h),
            normal: Vec3::Z,
            radius: r,
        }),
    }))
}

/// A `cylinder` (between `zmin` and `zmax`, up to `phimax`), or `None`
/// (with a warning) if it is degenerate.
fn cylinder(e: &Entity, w: &mut Warnings) -> Result<Option<SceneMesh>, FormatError> {
    let r = e.params.float("radius", 1.0)? as f32;
    let zmin = e.params.float("zmin", -1.0)? as f32;
    let zmax = e.params.float("zmax", 1.0)? as f32;
    let phimax = e
        .params
        .float("phimax", 360.0)?
        .clamp(0.0, 360.0)
        .to_radians() as f32;
    if r <= 0.0 || zmin == zmax || phimax <= 0.0 {
        w.add(
            "degenerate cylinder (radius, zmin = zmax or phimax) skipped",
            &e.loc,
        );
        return Ok(None);
    }
    let segs = (phimax / (2.0 * std::f32::consts::PI) * SEGMENTS as f32)
        .ceil()
        .max(1.0) as u32;
    let mut g = grid(segs, 1, |u, v| {
        let phi = u * phimax;
        Vec3::new(r * phi.cos(), r * phi.sin(), zmin + (zmax - zmin) * v)
    });
    g.normals = Some(
        g.mesh
            .positions
            .iter()
            .map(|p| Vec3::new(p.x, p.y, 0.0).normalize_or_zero())
            .collect(),
    );
    Ok(Some(g))
}

/// A `nu` x `nv` grid of quads over `f(u, v)`, `u, v` in [0, 1], two
/// triangles each wound along `df/du x df/dv`, with `(u, v)` as texture
/// coordinates; triangles collapsed to a point or line (at a pole) are
/// left out.
fn grid(nu: u32, nv: u32, f: impl Fn(f32, f32) -> Vec3) -> SceneMesh {
    let mut positions = Vec::with_capacity(((nu + 1) * (nv + 1)) as usize);
    let mut uvs = Vec::with_capacity(positions.capacity());
    for j in 0..=nv {
        for i in 0..=nu {
            let (u, v) = (i as f32 / nu as f32, j as f32 / nv as f32);
            positions.push(f(u, v));
            uvs.push(Vec2::new(u, v));
        }
    }
    let at = |i: u32, j: u32| j * (nu + 1) + i;
    let mut tris = Vec::with_capacity((2 * nu * nv) as usize);
    for j in 0..nv {
        for i in 0..nu {
            let quad = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            let mut t = Vec::new();
            fan_triangulate(&quad, &mut t);
            tris.extend(t.into_iter().filter(|tri| {
                let [a, b, c] = tri.map(|k| positions[k as usize]);
                (b - a).cross(c - a).length_squared() > 0.0
            }));
        }
    }
    scene_mesh(positions, tris, None, Some(uvs))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_faces_point_along_du_cross_dv() {
        let m = grid(4, 3, |u, v| Vec3::new(u, v, 0.0));
        assert_eq!(m.mesh.indices.len(), 24);
        for t in &m.mesh.indices {
            let [a, b, c] = t.map(|i| m.mesh.positions[i as usize]);
            assert!((b - a).cross(c - a).z > 0.0);
        }
    }
}
