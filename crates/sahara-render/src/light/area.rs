//! Area lights: emissive quads, discs and spheres sampled analytically,
//! and emissive triangle meshes sampled by area.

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

use super::tree::LightBounds;
use super::LightSample;
use crate::math::lanes::{F, M, V};
use crate::math::piecewise::Distribution1D;
use crate::math::warp::{
    concentric_disc, luminance, uniform_cone, uniform_sphere, uniform_triangle, Frame,
};
use crate::texture::TextureMap;

/// The emitting surface.
#[derive(Clone, Debug)]
pub enum Emitter {
    /// `corner + s u + t v`, front face towards `n`.
    Quad {
        /// Corner.
        corner: Vec3,
        /// First edge.
        u: Vec3,
        /// Second edge.
        v: Vec3,
        /// Unit front normal.
        n: Vec3,
    },
    /// A disc.
    Disc {
        /// Centre.
        center: Vec3,
        /// Frame whose `n` is the front normal.
        frame: Frame,
        /// Radius.
        radius: f32,
    },
    /// A sphere.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
    },
    /// Triangles in world space, chosen in proportion to their area.
    Mesh {
        /// Vertices.
        tris: Vec<[Vec3; 3]>,
        /// Emitted radiance per triangle.
        radiance: Vec<Vec3>,
        /// Two-sided emission per triangle.
        two_sided: Vec<bool>,
        /// Per triangle, the emission texture multiplying its radiance
        /// (an index into `maps`) and its corners' uv sets.
        textures: Vec<Option<(u32, [[Vec2; 3]; 2])>>,
        /// The emission textures.
        maps: Vec<TextureMap>,
        /// Power of each triangle relative to its radiance (the
        /// texture's mean over it, estimated), for light selection.
        texture_power: Vec<f32>,
        /// Distribution over triangle areas.
        dist: Distribution1D,
    },
}

/// Triangles' textured emission, for [`AreaLight::mesh`].
#[derive(Clone, Debug, Default)]
pub struct EmissionTextures {
    /// Per triangle, an index into `maps` and the corners' uv sets.
    pub triangles: Vec<Option<(u32, [[Vec2; 3]; 2])>>,
    /// The textures.
    pub maps: Vec<TextureMap>,
}

impl EmissionTextures {
    /// The texture factor at barycentric `(b1, b2)` of triangle `i`.
    fn at(maps: &[TextureMap], t: &Option<(u32, [[Vec2; 3]; 2])>, b1: f32, b2: f32) -> Vec3 {
        let Some((m, uv)) = t else {
            return Vec3::ONE;
        };
        let lerp = |c: [Vec2; 3]| c[0] * (1.0 - b1 - b2) + c[1] * b1 + c[2] * b2;
        let uvs = [lerp(uv[0]), lerp(uv[1])];
        maps[*m as usize]
            .lookup_sharp(&uvs)
            .truncate()
            .max(Vec3::ZERO)
    }
}

/// A point of a mesh light's triangles, uniform by area (`u`): the
/// triangle, the point's barycentrics `(b1, b2)`, the point and the
/// triangle's front normal.
fn mesh_point(tris: &[[Vec3; 3]], dist: &Distribution1D, u: Vec2) -> (usize, f32, f32, Vec3, Vec3) {
    let (x, _, i) = dist.sample_continuous(u.x);
    // Reuse the position within the chosen cell as a fresh uniform
    // number: it is uniform and independent of i.
    let ux = (x * dist.len() as f32 - i as f32).clamp(0.0, 1.0);
    let (b1, b2) = uniform_triangle(Vec2::new(ux, u.y));
    let t = &tris[i];
    let q = t[0] * (1.0 - b1 - b2) + t[1] * b1 + t[2] * b2;
    let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
    (i, b1, b2, q, n)
}

/// A point of an emitting surface ([`AreaLight::surface_point`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct SurfacePoint {
    /// The point.
    pub p: Vec3,
    /// The surface's unit front normal there.
    pub n: Vec3,
    /// Whether the surface emits from its back face too.
    pub two_sided: bool,
    /// A mesh light's triangle and the point's barycentrics on it (its
    /// radiance and texture are the triangle's).
    tri: Option<(usize, f32, f32)>,
}

/// An emitting surface with its radiance.
#[derive(Clone, Debug)]
pub struct AreaLight {
    /// Shape.
    pub emitter: Emitter,
    /// Radiance of an analytic shape (mesh lights carry theirs per triangle).
    pub radiance: Vec3,
    /// Emission from both faces (analytic shapes).
    pub two_sided: bool,
    /// Total area.
    pub area: f32,
    /// The instance of an analytic emitter (none for mesh lights).
    pub instance: Option<u32>,
}

/// Radiance leaving a surface point with front normal `n` towards `w`.
#[inline]
fn emitted(radiance: Vec3, two_sided: bool, n: Vec3, w: Vec3) -> Vec3 {
    let c = n.dot(w);
    if c > 0.0 || (two_sided && c < 0.0) {
        radiance
    } else {
        Vec3::ZERO
    }
}

impl AreaLight {
    /// The instance a shadow ray towards this light must ignore: a
    /// sphere's, whose tessellation lies inside the sphere sampled, so
    /// that a segment from inside it to a sampled point would cross it.
    /// Flat emitters need none (see [`AreaLight::sample`]).
    pub fn shadow_ignore(&self) -> Option<u32> {
        match self.emitter {
            Emitter::Sphere { .. } => self.instance,
            _ => None,
        }
    }

    /// A light over an analytic emitter.
    pub fn analytic(emitter: Emitter, radiance: Vec3, two_sided: bool, instance: u32) -> Self {
        let area = match &emitter {
            Emitter::Quad { u, v, .. } => u.cross(*v).length(),
            Emitter::Disc { radius, .. } => PI * radius * radius,
            Emitter::Sphere { radius, .. } => 4.0 * PI * radius * radius,
            Emitter::Mesh { .. } => unreachable!("mesh lights use AreaLight::mesh"),
        };
        Self {
            emitter,
            radiance,
            two_sided,
            area,
            instance: Some(instance),
        }
    }

    /// A light over world-space triangles with per-triangle emission,
    /// textured where `textures` says.
    pub fn mesh(
        tris: Vec<[Vec3; 3]>,
        radiance: Vec<Vec3>,
        two_sided: Vec<bool>,
        textures: EmissionTextures,
    ) -> Self {
        let areas: Vec<f32> = tris
            .iter()
            .map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length())
            .collect();
        let area = areas.iter().map(|&a| a as f64).sum::<f64>() as f32;
        let EmissionTextures {
            mut triangles,
            maps,
        } = textures;
        triangles.resize(tris.len(), None);
        // A triangle's share of its texture, from a few points (and a
        // floor from the texture's mean, so no part of it is left out
        // entirely: this only steers which light is sampled).
        let means: Vec<f32> = maps.iter().map(|m| luminance(m.texture.mean())).collect();
        let texture_power = triangles
            .iter()
            .map(|t| match t {
                None => 1.0,
                Some((m, _)) => {
                    let pts = [(1.0 / 3.0, 1.0 / 3.0), (0.1, 0.1), (0.8, 0.1), (0.1, 0.8)];
                    let local: f32 = pts
                        .iter()
                        .map(|&(b1, b2)| luminance(EmissionTextures::at(&maps, t, b1, b2)))
                        .sum::<f32>()
                        / pts.len() as f32;
                    0.9 * local + 0.1 * means[*m as usize]
                }
            })
            .collect();
        Self {
            emitter: Emitter::Mesh {
                tris,
                radiance,
                two_sided,
                textures: triangles,
                maps,
                texture_power,
                dist: Distribution1D::new(areas),
            },
            radiance: Vec3::ZERO,
            two_sided: false,
            area,
            instance: None,
        }
    }

    /// True for a light over a mesh's triangles.
    pub(crate) fn is_mesh(&self) -> bool {
        matches!(self.emitter, Emitter::Mesh { .. })
    }

    /// Emitted power (luminance) for light selection.
    pub fn power(&self) -> f32 {
        match &self.emitter {
            Emitter::Mesh { tris, .. } => (0..tris.len()).map(|i| self.triangle_power(i)).sum(),
            _ => PI * self.area * luminance(self.radiance) * if self.two_sided { 2.0 } else { 1.0 },
        }
    }

    /// Emitted power (luminance) of a mesh light's triangle `i` (zero for
    /// other lights).
    fn triangle_power(&self, i: usize) -> f32 {
        let Emitter::Mesh {
            tris,
            radiance,
            two_sided,
            texture_power,
            ..
        } = &self.emitter
        else {
            return 0.0;
        };
        let t = &tris[i];
        let a = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
        PI * a * luminance(radiance[i]) * texture_power[i] * if two_sided[i] { 2.0 } else { 1.0 }
    }

    /// The emitting pieces the light tree holds of this light: a mesh
    /// light's triangles one by one, another light whole. Each bound's
    /// power is the piece's peak radiant intensity (radiance times the
    /// area seen face on), which a point light's intensity compares with.
    pub(crate) fn tree_bounds(&self) -> Vec<LightBounds> {
        let face = |power: f32, two: bool| power / PI / if two { 2.0 } else { 1.0 };
        match &self.emitter {
            Emitter::Mesh {
                tris, two_sided, ..
            } => tris
                .iter()
                .enumerate()
                .map(|(i, t)| {
                    let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
                    let phi = face(self.triangle_power(i), two_sided[i]);
                    LightBounds::surface(t, n, phi, two_sided[i])
                })
                .collect(),
            Emitter::Quad { corner, u, v, n } => vec![LightBounds::surface(
                &[*corner, *corner + *u, *corner + *v, *corner + *u + *v],
                *n,
                face(self.power(), self.two_sided),
                self.two_sided,
            )],
            Emitter::Disc {
                center,
                frame,
                radius,
            } => {
                let (s, t) = (frame.s * *radius, frame.t * *radius);
                vec![LightBounds::surface(
                    &[
                        *center - s - t,
                        *center + s - t,
                        *center - s + t,
                        *center + s + t,
                    ],
                    frame.n,
                    face(self.power(), self.two_sided),
                    self.two_sided,
                )]
            }
            // A sphere shows a disc of its radius from every side.
            Emitter::Sphere { center, radius } => vec![LightBounds::sphere(
                *center,
                *radius,
                face(self.power(), self.two_sided) / 4.0,
                self.two_sided,
            )],
        }
    }

    /// The index among a mesh light's triangles of triangle `tri` of its
    /// mesh, given the mesh triangles `source` it was made of (in order).
    pub(crate) fn triangle_of(source: &[u32], tri: u32) -> Option<usize> {
        source.binary_search(&tri).ok()
    }

    /// A point of the light, uniform by area (`u`): on a quad or a disc,
    /// anywhere on a sphere, on a mesh's triangles chosen by their area.
    /// Next-event estimation ([`AreaLight::sample`]) and the light leaving
    /// a light (`LightSource::sample_emission`) both draw their points here.
    pub(crate) fn surface_point(&self, u: Vec2) -> SurfacePoint {
        let (p, n, tri) = match &self.emitter {
            Emitter::Quad {
                corner,
                u: eu,
                v: ev,
                n,
            } => (*corner + *eu * u.x + *ev * u.y, *n, None),
            Emitter::Disc {
                center,
                frame,
                radius,
            } => {
                let d = concentric_disc(u) * *radius;
                (*center + frame.s * d.x + frame.t * d.y, frame.n, None)
            }
            Emitter::Sphere { center, radius } => {
                let n = uniform_sphere(u);
                (*center + *radius * n, n, None)
            }
            Emitter::Mesh {
                tris,
                two_sided,
                dist,
                ..
            } => {
                let (i, b1, b2, q, n) = mesh_point(tris, dist, u);
                return SurfacePoint {
                    p: q,
                    n,
                    two_sided: two_sided[i],
                    tri: Some((i, b1, b2)),
                };
            }
        };
        SurfacePoint {
            p,
            n,
            two_sided: self.two_sided,
            tri,
        }
    }

    /// The radiance leaving the front of the light at `s` (and its back,
    /// when two-sided): a mesh triangle's own, times its emission texture
    /// there.
    pub(crate) fn radiance_at(&self, s: &SurfacePoint) -> Vec3 {
        match (&self.emitter, s.tri) {
            (
                Emitter::Mesh {
                    radiance,
                    textures,
                    maps,
                    ..
                },
                Some((i, b1, b2)),
            ) => radiance[i] * EmissionTextures::at(maps, &textures[i], b1, b2),
            _ => self.radiance,
        }
    }

    /// A point on the light as seen from `p`: direction, distance, incident
    /// radiance and solid-angle density.
    pub fn sample(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        if let Emitter::Sphere { center, radius } = self.emitter {
            return self.sample_sphere(center, radius, p, u);
        }
        self.sample_at(p, self.surface_point(u), 1.0 / self.area)
    }

    /// [`AreaLight::sample`] of a mesh light's triangle `i` alone, its
    /// point uniform over the triangle (other lights: the whole light).
    pub(crate) fn sample_triangle(&self, p: Vec3, i: usize, u: Vec2) -> Option<LightSample> {
        let Emitter::Mesh {
            tris, two_sided, ..
        } = &self.emitter
        else {
            return self.sample(p, u);
        };
        let t = &tris[i];
        let (b1, b2) = uniform_triangle(u);
        let e = (t[1] - t[0]).cross(t[2] - t[0]);
        let s = SurfacePoint {
            p: t[0] * (1.0 - b1 - b2) + t[1] * b1 + t[2] * b2,
            n: e.normalize_or_zero(),
            two_sided: two_sided[i],
            tri: Some((i, b1, b2)),
        };
        self.sample_at(p, s, 2.0 / e.length())
    }

    /// The flat piece next-event estimation samples in the lanes
    /// ([`sample_flat_lanes`]): triangle `tri` of a mesh light (None:
    /// the whole light) where no emission texture covers it, or a quad;
    /// None for the others (discs, spheres, textured triangles), which
    /// are sampled lane by lane.
    pub(crate) fn flat_piece(&self, tri: Option<usize>) -> Option<FlatPiece> {
        match (&self.emitter, tri) {
            (
                Emitter::Mesh {
                    tris,
                    radiance,
                    two_sided,
                    textures,
                    ..
                },
                Some(i),
            ) if textures[i].is_none() => Some(FlatPiece {
                a: tris[i][0],
                b: tris[i][1],
                c: tris[i][2],
                n: Vec3::ZERO,
                radiance: radiance[i],
                pdf_area: 0.0,
                two_sided: two_sided[i],
                mesh: true,
            }),
            (Emitter::Quad { corner, u, v, n }, None) => Some(FlatPiece {
                a: *corner,
                b: *u,
                c: *v,
                n: *n,
                radiance: self.radiance,
                pdf_area: 1.0 / self.area,
                two_sided: self.two_sided,
                mesh: false,
            }),
            _ => None,
        }
    }

    /// The light of the point `s` of the surface (drawn with density
    /// `pdf_area` by area) seen from `p`.
    fn sample_at(&self, p: Vec3, s: SurfacePoint, pdf_area: f32) -> Option<LightSample> {
        let (q, n, two) = (s.p, s.n, s.two_sided);
        // A mesh's triangles face their own ways; its texture is looked up
        // only where the face seen emits.
        let le = match (&self.emitter, s.tri) {
            (
                Emitter::Mesh {
                    radiance,
                    textures,
                    maps,
                    ..
                },
                Some((i, b1, b2)),
            ) => {
                let le = emitted(radiance[i], two, n, p - q);
                Some(if le == Vec3::ZERO {
                    le
                } else {
                    le * EmissionTextures::at(maps, &textures[i], b1, b2)
                })
            }
            _ => None,
        };
        let d = q - p;
        let dist2 = d.length_squared();
        if dist2 == 0.0 {
            return None;
        }
        let dist = dist2.sqrt();
        let wi = d / dist;
        let cos = n.dot(-wi).abs();
        if cos == 0.0 {
            return None;
        }
        let li = le.unwrap_or_else(|| emitted(self.radiance, self.two_sided, n, -wi));
        if li == Vec3::ZERO {
            return None;
        }
        Some(LightSample {
            wi,
            dist,
            li,
            pdf: pdf_area * dist2 / cos,
            delta: false,
            // A flat emitter cannot block the segment to its own point,
            // which stops short of it (`World::shadow_query`), so its
            // instance need not be ignored and joins the world tree.
            ignore: None,
            n,
            two_sided: two,
        })
    }

    /// Solid-angle sampling of the cone a sphere subtends from outside;
    /// uniform area sampling from inside.
    fn sample_sphere(&self, c: Vec3, r: f32, p: Vec3, u: Vec2) -> Option<LightSample> {
        let to_c = c - p;
        let d2 = to_c.length_squared();
        if d2 <= r * r {
            // Inside: uniform on the surface.
            let n = uniform_sphere(u);
            let q = c + r * n;
            let d = q - p;
            let dist2 = d.length_squared();
            let dist = dist2.sqrt();
            let wi = d / dist;
            let cos = n.dot(-wi).abs();
            let li = emitted(self.radiance, self.two_sided, n, -wi);
            if cos == 0.0 || li == Vec3::ZERO {
                return None;
            }
            return Some(LightSample {
                wi,
                dist,
                li,
                pdf: dist2 / (cos * self.area),
                delta: false,
                ignore: self.shadow_ignore(),
                n,
                two_sided: self.two_sided,
            });
        }
        let d = d2.sqrt();
        let sin2_max = r * r / d2;
        let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
        // 1 - cos_max without cancellation for small, distant spheres.
        let one_minus = sin2_max / (1.0 + cos_max);
        let frame = Frame::from_normal(to_c / d);
        let local = uniform_cone(u, cos_max);
        let wi = frame.to_world(local);
        // Nearest intersection with the sphere, clamped to the tangent
        // point when rounding puts the direction just outside the cone.
        let b = wi.dot(to_c);
        let disc = (r * r - (d2 - b * b)).max(0.0);
        let dist = b - disc.sqrt();
        let q = p + wi * dist;
        let n = (q - c).normalize_or_zero();
        let li = emitted(self.radiance, self.two_sided, n, -wi);
        if li == Vec3::ZERO || dist <= 0.0 {
            return None;
        }
        Some(LightSample {
            wi,
            dist,
            li,
            pdf: 1.0 / (2.0 * PI * one_minus),
            delta: false,
            ignore: self.shadow_ignore(),
            n,
            two_sided: self.two_sided,
        })
    }

    /// Solid-angle density with which [`AreaLight::sample`] picks the point
    /// `q` (front normal `n`) seen from `p` along unit `wi`.
    pub fn pdf(&self, p: Vec3, q: Vec3, n: Vec3, wi: Vec3) -> f32 {
        if let Emitter::Sphere { center, radius } = self.emitter {
            let d2 = (center - p).length_squared();
            if d2 > radius * radius {
                let sin2_max = radius * radius / d2;
                let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
                return 1.0 / (2.0 * PI * sin2_max / (1.0 + cos_max));
            }
        }
        let cos = n.dot(wi).abs();
        if cos == 0.0 {
            return 0.0;
        }
        (q - p).length_squared() / (cos * self.area)
    }

    /// Solid-angle density with which [`AreaLight::sample_triangle`] of
    /// triangle `i` picks the point `q` (front normal `n`) seen from `p`
    /// along unit `wi`.
    pub(crate) fn pdf_triangle(&self, i: usize, p: Vec3, q: Vec3, n: Vec3, wi: Vec3) -> f32 {
        let Emitter::Mesh { tris, .. } = &self.emitter else {
            return self.pdf(p, q, n, wi);
        };
        let t = &tris[i];
        let area = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
        let cos = n.dot(wi).abs();
        if cos == 0.0 || area == 0.0 {
            return 0.0;
        }
        (q - p).length_squared() / (cos * area)
    }
}

/// A flat emitting piece as the lanes sample it ([`AreaLight::flat_piece`]):
/// a mesh light's triangle `a, b, c`, or a quad's corner `a`, sides `b`,
/// `c` and normal `n`.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct FlatPiece {
    a: Vec3,
    b: Vec3,
    c: Vec3,
    /// A quad's unit front normal (a triangle's is computed).
    n: Vec3,
    radiance: Vec3,
    /// A quad's density by area (a triangle's is computed).
    pdf_area: f32,
    two_sided: bool,
    /// A triangle (else a quad).
    mesh: bool,
}

/// Light samples of `N` lanes: per lane the direction, distance, incident
/// radiance and solid-angle density, and whether the lane has one.
pub(crate) struct FlatSamples<const N: usize> {
    pub wi: V<N>,
    pub dist: F<N>,
    pub li: V<N>,
    pub pdf: F<N>,
    pub ok: M<N>,
}

/// [`AreaLight::sample_triangle`] (a triangle) or [`AreaLight::sample`]
/// (a quad) of each lane's piece from `p` with `u`, in the lanes: each
/// lane's sample is the scalar one, bit for bit (the same operations in
/// the same order; a triangle's emission faces the way `p − q` says, a
/// quad's the way `−wi` says, as there).
#[inline(always)]
pub(crate) fn sample_flat_lanes<const N: usize>(
    pieces: &[FlatPiece; N],
    p: V<N>,
    u: (F<N>, F<N>),
) -> FlatSamples<N> {
    let zero = F::splat(0.0);
    let one = F::splat(1.0);
    let a = V::from_fn(|i| pieces[i].a);
    let b = V::from_fn(|i| pieces[i].b);
    let c = V::from_fn(|i| pieces[i].c);
    let mesh = M(std::array::from_fn(|i| pieces[i].mesh));
    // A triangle: a point uniform by area (`uniform_triangle`), the
    // normal normalised as glam's `normalize_or_zero`.
    let s = u.0.sqrt();
    let (b1, b2) = (s * (one - u.1), s * u.1);
    let b0 = one - b1 - b2;
    let q_tri = a * b0 + b * b1 + c * b2;
    let e = (b - a).cross(c - a);
    let len = e.length_squared().sqrt();
    let rcp = one / len;
    let unit = rcp.test(rcp, |r, _| r.is_finite() && r > 0.0);
    let n_tri = unit.select_v(e * rcp, V::default());
    let pdf_tri = F::splat(2.0) / len;
    // A quad: its corner plus its sides scaled.
    let q_quad = a + b * u.0 + c * u.1;
    let q = mesh.select_v(q_tri, q_quad);
    let n = mesh.select_v(n_tri, V::from_fn(|i| pieces[i].n));
    let pdf_area = mesh.select(pdf_tri, F::from_fn(|i| pieces[i].pdf_area));
    let d = q - p;
    let dist2 = d.length_squared();
    let dist = dist2.sqrt();
    let wi = d / dist;
    let cos = n.dot(-wi).abs();
    let facing = mesh.select(n.dot(p - q), n.dot(-wi));
    let two = M(std::array::from_fn(|i| pieces[i].two_sided));
    let lit = facing.gt(zero) | (two & facing.lt(zero));
    let radiance = V::from_fn(|i| pieces[i].radiance);
    let li = lit.select_v(radiance, V::default());
    let black = li.x.eq(zero) & li.y.eq(zero) & li.z.eq(zero);
    let ok = !dist2.eq(zero) & !cos.eq(zero) & !black;
    FlatSamples {
        wi,
        dist,
        li,
        pdf: pdf_area * dist2 / cos,
        ok,
    }
}

#[cfg(test)]
mod lane_tests {
    use super::*;

    /// The lanes' samples of flat pieces are the scalar samples, bit for
    /// bit: triangles of a mesh light (one- and two-sided, seen from both
    /// sides) and a quad, from points all around, a degenerate triangle
    /// among them.
    #[test]
    fn flat_lanes_are_the_scalar_samples() {
        const N: usize = 16;
        let mut r = crate::math::hash::test_numbers(1);
        let mut rv = || Vec3::new(r(), r(), r()) * 4.0 - 2.0;
        let mut tris: Vec<[Vec3; 3]> = (0..12).map(|_| [rv(), rv(), rv()]).collect();
        tris.push([Vec3::ZERO, Vec3::X, Vec3::X * 2.0]);
        let k = tris.len();
        let radiance = (0..k).map(|i| Vec3::new(1.0, 0.5, i as f32)).collect();
        let two = (0..k).map(|i| i % 3 == 0).collect();
        let mesh = AreaLight::mesh(tris, radiance, two, EmissionTextures::default());
        let quad = |two_sided| {
            let (u, v) = (Vec3::new(1.5, 0.0, 0.2), Vec3::new(0.0, 0.0, -1.0));
            AreaLight::analytic(
                Emitter::Quad {
                    corner: Vec3::new(-0.5, 1.0, 0.3),
                    u,
                    v,
                    n: u.cross(v).normalize(),
                },
                Vec3::new(4.0, 3.0, 2.0),
                two_sided,
                0,
            )
        };
        let quads = [quad(false), quad(true)];
        let mut r = crate::math::hash::test_numbers(3);
        for _ in 0..500 {
            let which: [usize; N] = std::array::from_fn(|_| (r() * (k + 2) as f32) as usize);
            let pieces: [FlatPiece; N] = std::array::from_fn(|i| match which[i] {
                t if t < k => mesh.flat_piece(Some(t)).unwrap(),
                q => quads[q - k].flat_piece(None).unwrap(),
            });
            let p = V::<N>::from_fn(|_| Vec3::new(r(), r(), r()) * 6.0 - 3.0);
            let u = (F::<N>::from_fn(|_| r()), F::<N>::from_fn(|_| r()));
            let got = sample_flat_lanes(&pieces, p, u);
            for (i, &piece) in which.iter().enumerate() {
                let uv = Vec2::new(u.0 .0[i], u.1 .0[i]);
                let want = match piece {
                    t if t < k => mesh.sample_triangle(p.get(i), t, uv),
                    q => quads[q - k].sample(p.get(i), uv),
                };
                let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                assert_eq!(
                    want.map(|w| (bits(w.wi), w.dist.to_bits(), bits(w.li), w.pdf.to_bits())),
                    got.ok.0[i].then(|| (
                        bits(got.wi.get(i)),
                        got.dist.0[i].to_bits(),
                        bits(got.li.get(i)),
                        got.pdf.0[i].to_bits()
                    )),
                    "lane {i}: piece {piece}"
                );
            }
        }
    }
}
