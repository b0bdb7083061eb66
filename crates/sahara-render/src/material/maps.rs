//! A material's textures, one per role, and what they make of the
//! material at a shading point.
//!
//! Every role multiplies the factor it goes with, so a material without
//! textures is its factors: base colour (RGB times the BSDF's colour,
//! alpha times the opacity), metallic, roughness, emission, the clear
//! coat's strength and roughness. The normal map bends the shading normal
//! in the tangent frame of the mesh; occlusion darkens the light that
//! arrives by indirect paths only (see [`OcclusionMap`]).

use glam::{Vec2, Vec3};

use crate::texture::footprint::UvFootprint;
use crate::texture::{ScalarMap, TextureMap};

/// A tangent-space normal map.
///
/// Texels hold `(n + 1) / 2` of a unit normal in the frame (tangent,
/// bitangent, normal), +X towards increasing `u` and +Y towards increasing
/// `v` (up in the image: OpenGL's and glTF's convention). The normal's X
/// and Y are multiplied by `scale` before it is normalised.
#[derive(Clone, Debug, PartialEq)]
pub struct NormalMap {
    /// The texture (linear).
    pub map: TextureMap,
    /// Strength of the bumps (1: as painted).
    pub scale: f32,
}

impl NormalMap {
    /// The tangent-space normal at a hit (`None` where the texel is no
    /// direction).
    #[inline]
    pub fn lookup(&self, uvs: &[Vec2; 2], fp: &UvFootprint) -> Option<Vec3> {
        decode_normal(self.map.lookup(uvs, fp).truncate(), self.scale)
    }
}

/// Ambient occlusion painted into a texture.
///
/// A path tracer finds the occlusion of the geometry it is given by
/// itself; a painted map stands for detail the mesh lacks. It scales the
/// light a point receives by indirect paths (after two or more
/// scatterings) by `1 + strength (occlusion - 1)`, as glTF defines it
/// ("areas that receive less indirect lighting"); light straight from
/// emitters, lights and the environment is left alone.
#[derive(Clone, Debug, PartialEq)]
pub struct OcclusionMap {
    /// The channel holding the occlusion (linear).
    pub map: ScalarMap,
    /// 0: no effect, 1: the full painted occlusion.
    pub strength: f32,
}

/// A material's textures, by role (see the module documentation).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MaterialTextures {
    /// RGB multiplies the BSDF's colour; A multiplies the opacity.
    pub base_color: Option<TextureMap>,
    /// Multiplies the metallic-roughness BSDF's `metallic`.
    pub metallic: Option<ScalarMap>,
    /// Multiplies the BSDF's roughness.
    pub roughness: Option<ScalarMap>,
    /// Bends the shading normal.
    pub normal: Option<NormalMap>,
    /// Darkens indirect light.
    pub occlusion: Option<OcclusionMap>,
    /// RGB multiplies the emitted radiance.
    pub emission: Option<TextureMap>,
}

impl MaterialTextures {
    /// True if no role has a texture.
    pub fn is_empty(&self) -> bool {
        self.base_color.is_none()
            && self.metallic.is_none()
            && self.roughness.is_none()
            && self.normal.is_none()
            && self.occlusion.is_none()
            && self.emission.is_none()
    }
}

/// A clear dielectric coat over a material (glTF's
/// `KHR_materials_clearcoat`, a car's paint, a varnish): GGX reflection
/// off the coat, over the material beneath dimmed by what the coat
/// reflects on the way in and on the way out (see `super::coat`).
#[derive(Clone, Debug, PartialEq)]
pub struct Clearcoat {
    /// How much of the surface the coat covers, in `[0, 1]`.
    pub factor: f32,
    /// Perceptual roughness of the coat.
    pub roughness: f32,
    /// Index of refraction of the coat (glTF: 1.5).
    pub ior: f32,
    /// Multiplies `factor`.
    pub factor_map: Option<ScalarMap>,
    /// Multiplies `roughness`.
    pub roughness_map: Option<ScalarMap>,
    /// The coat's own normal map; without one the coat follows the
    /// surface's normal, not the base's normal map (glTF's rule).
    pub normal_map: Option<NormalMap>,
}

impl Clearcoat {
    /// A coat of the same `factor`, `roughness` and index `ior`
    /// everywhere: no maps.
    pub fn uniform(factor: f32, roughness: f32, ior: f32) -> Self {
        Self {
            factor,
            roughness,
            ior,
            factor_map: None,
            roughness_map: None,
            normal_map: None,
        }
    }
}

/// A tangent-space normal `t` (a normal map's texel, linear RGB) as a
/// unit vector, X and Y scaled by `scale`; `None` for a texel that is no
/// direction.
#[inline]
pub fn decode_normal(t: Vec3, scale: f32) -> Option<Vec3> {
    let n = t * 2.0 - Vec3::ONE;
    let n = Vec3::new(n.x * scale, n.y * scale, n.z);
    let n = n.normalize_or_zero();
    (n != Vec3::ZERO && n.is_finite()).then_some(n)
}

/// The shading normal a normal map gives: the tangent-space normal `m`
/// in the frame of the unit shading normal `ns` and the tangent `t` (a
/// direction along increasing `u`, its handedness `sign`: the bitangent
/// is `sign * ns x t`).
#[inline]
pub fn perturbed_normal(ns: Vec3, t: Vec3, sign: f32, m: Vec3) -> Vec3 {
    let t = (t - ns * ns.dot(t)).normalize_or_zero();
    if t == Vec3::ZERO {
        return ns;
    }
    let b = ns.cross(t) * if sign < 0.0 { -1.0 } else { 1.0 };
    let n = (t * m.x + b * m.y + ns * m.z).normalize_or_zero();
    if n == Vec3::ZERO || !n.is_finite() {
        ns
    } else {
        n
    }
}

/// The scalar factor of `map` at a hit (1 without a map).
#[inline]
pub(crate) fn scalar(map: &Option<ScalarMap>, uvs: &[Vec2; 2], fp: &UvFootprint) -> Option<f32> {
    map.as_ref().map(|m| m.lookup(uvs, fp))
}
