//! Instances: a mesh placed by a transform, or moving between two
//! transforms over the shutter interval.

use glam::{Affine3A, Quat, Vec3};
use sahara_kd::Aabb;

/// A transform split into scale, rotation and translation (applied in that
/// order), the form motion is interpolated in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Srt {
    /// Scale per axis.
    pub scale: Vec3,
    /// Rotation.
    pub rotation: Quat,
    /// Translation.
    pub translation: Vec3,
}

impl Default for Srt {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Srt {
    /// The identity.
    pub const IDENTITY: Srt = Srt {
        scale: Vec3::ONE,
        rotation: Quat::IDENTITY,
        translation: Vec3::ZERO,
    };

    /// A pure translation.
    pub fn translation(t: Vec3) -> Self {
        Self {
            translation: t,
            ..Self::IDENTITY
        }
    }

    /// The affine map.
    pub fn to_affine(&self) -> Affine3A {
        Affine3A::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }

    /// Interpolation at `s` in `[0, 1]`: translation and scale linear,
    /// rotation by slerp.
    pub fn interpolate(&self, other: &Srt, s: f32) -> Srt {
        Srt {
            scale: self.scale.lerp(other.scale, s),
            rotation: self.rotation.slerp(other.rotation, s),
            translation: self.translation.lerp(other.translation, s),
        }
    }
}

/// Where an instance is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Placement {
    /// Fixed object-to-world transform.
    Static(Affine3A),
    /// Moving: the object-to-world transform at shutter open and close.
    Moving {
        /// Transform at shutter open.
        open: Srt,
        /// Transform at shutter close.
        close: Srt,
    },
}

impl Default for Placement {
    fn default() -> Self {
        Placement::Static(Affine3A::IDENTITY)
    }
}

/// Time steps at which a moving instance's bounds are evaluated.
const SWEEP_STEPS: u32 = 64;

impl Placement {
    /// True for a moving instance.
    pub fn is_moving(&self) -> bool {
        matches!(self, Placement::Moving { .. })
    }

    /// Object-to-world transform at shutter fraction `s`.
    #[inline]
    pub fn at(&self, s: f32) -> Affine3A {
        match self {
            Placement::Static(a) => *a,
            Placement::Moving { open, close } => open.interpolate(close, s).to_affine(),
        }
    }

    /// World bounds of object bounds `b` over the whole shutter (swept for
    /// moving instances).
    ///
    /// Corners are transformed at `SWEEP_STEPS + 1` times. Between two steps
    /// a corner's path deviates from the chord by at most `h^2 / 8` times
    /// its acceleration, bounded by `(w^2 S + 2 w dS) R` (rotation angle `w`
    /// over the shutter, largest scale `S`, scale change `dS`, corner
    /// distance `R`; translation is linear and adds none); the box is padded
    /// by that.
    pub fn world_bounds(&self, b: Aabb) -> Aabb {
        if b.is_empty() {
            return b;
        }
        let corners = |xf: &Affine3A| {
            (0..8).fold(Aabb::EMPTY, |acc, i| {
                let c = Vec3::new(
                    if i & 1 == 0 { b.min.x } else { b.max.x },
                    if i & 2 == 0 { b.min.y } else { b.max.y },
                    if i & 4 == 0 { b.min.z } else { b.max.z },
                );
                acc.grow(xf.transform_point3(c))
            })
        };
        match self {
            Placement::Static(a) => corners(a),
            Placement::Moving { open, close } => {
                let mut out = Aabb::EMPTY;
                for k in 0..=SWEEP_STEPS {
                    out = out.union(corners(&self.at(k as f32 / SWEEP_STEPS as f32)));
                }
                let w = open.rotation.angle_between(close.rotation);
                let s_max = open.scale.abs().max(close.scale.abs()).max_element();
                let ds = (close.scale - open.scale).abs().max_element();
                let r = b.min.abs().max(b.max.abs()).length();
                let h = 1.0 / SWEEP_STEPS as f32;
                let pad = h * h / 8.0 * (w * w * s_max + 2.0 * w * ds) * r;
                Aabb {
                    min: out.min - Vec3::splat(pad * 1.01),
                    max: out.max + Vec3::splat(pad * 1.01),
                }
            }
        }
    }
}

/// One placed copy of a mesh.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Instance {
    /// Index into the scene's meshes.
    pub mesh: u32,
    /// Transform or motion.
    pub placement: Placement,
    /// Material for every triangle (overrides the mesh's per-triangle ids).
    pub material: Option<u32>,
}

impl Instance {
    /// A static instance.
    pub fn new(mesh: u32, transform: Affine3A, material: Option<u32>) -> Self {
        Self {
            mesh,
            placement: Placement::Static(transform),
            material,
        }
    }

    /// A moving instance.
    pub fn moving(mesh: u32, open: Srt, close: Srt, material: Option<u32>) -> Self {
        Self {
            mesh,
            placement: Placement::Moving { open, close },
            material,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn swept_bounds_contain_every_intermediate_position() {
        let b = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        let p = Placement::Moving {
            open: Srt::translation(Vec3::new(5.0, 0.0, 0.0)),
            close: Srt {
                scale: Vec3::splat(2.0),
                rotation: Quat::from_rotation_y(3.0),
                translation: Vec3::new(0.0, 3.0, 0.0),
            },
        };
        let w = p.world_bounds(b);
        for k in 0..=1000 {
            let xf = p.at(k as f32 / 1000.0);
            for i in 0..8 {
                let c = Vec3::new(
                    if i & 1 == 0 { -1.0 } else { 1.0 },
                    if i & 2 == 0 { -1.0 } else { 1.0 },
                    if i & 4 == 0 { -1.0 } else { 1.0 },
                );
                assert!(w.contains(xf.transform_point3(c)), "k {k}");
            }
        }
    }
}
