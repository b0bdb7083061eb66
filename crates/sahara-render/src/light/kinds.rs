//! The light kinds a scene file names (`type = "spot"`), each described
//! once: its keys ([`LightKind::keys`]) and what it builds from their
//! values ([`LightKind::light`]). Sahara's scene files read lights through
//! this table; a new kind is an entry here and the light it builds.

use glam::Vec3;

use super::Light;
use crate::keys::{flag, number, power, Fallback, Key, KeyError, KeyType, Values};
use crate::names::{name_table, Accepts};

/// A kind of light, as scene files name it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LightKind {
    /// An isotropic point light ([`Light::Point`]).
    Point,
    /// A point light limited to a cone ([`Light::Spot`]).
    Spot,
    /// A distant light ([`Light::Directional`]).
    Directional,
    /// An emitting quad, disc or sphere.
    Area,
    /// Light from infinitely far away in every direction.
    Environment,
}

name_table!(LightKind, "light", {
    LightKind::Point => "point",
    LightKind::Spot => "spot",
    LightKind::Directional => "directional",
    LightKind::Area => "area",
    LightKind::Environment => "environment",
});

/// What a light kind builds: a light, or what the reader completes with
/// what only it has (a shape's placement, a material's name, an image).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightOf {
    /// A point, spot or directional light.
    Explicit(Light),
    /// An emitting surface: the shape named by the `shape` key, from its
    /// keys, emitting `radiance`.
    Area {
        /// Emitted radiance.
        radiance: Vec3,
        /// Emit from both faces.
        two_sided: bool,
    },
    /// The environment: the same radiance everywhere.
    Constant(Vec3),
    /// The environment: the texture given for `radiance` (an image)
    /// times `scale`.
    Map {
        /// Radiance multiplier.
        scale: f32,
    },
}

/// A position that must be given.
const fn point(name: &'static str, about: &'static str) -> Key {
    Key {
        name,
        ty: KeyType::Point,
        default: Fallback::Required,
        textured: false,
        about,
    }
}

/// A key of an area light's shape (which shape takes it: see
/// `ShapeKind`).
const fn shape_key(name: &'static str, ty: KeyType, about: &'static str) -> Key {
    Key {
        name,
        ty,
        default: Fallback::Absent,
        textured: false,
        about,
    }
}

/// The built-in shapes an area light may be.
pub const AREA_SHAPES: [&str; 3] = ["quad", "disc", "sphere"];

impl LightKind {
    /// The keys of this kind, in the order documents list them.
    pub fn keys(self) -> &'static [Key] {
        const INTENSITY: Key = power("intensity", "radiant intensity (W/sr)");
        const POINT: &[Key] = &[point("position", "position"), INTENSITY];
        const SPOT: &[Key] = &[
            point("position", "position"),
            point("target", "point the cone's axis passes through"),
            INTENSITY,
            Key {
                name: "inner_angle",
                ty: KeyType::Number(Accepts::Between(0.0, 180.0)),
                default: Fallback::Absent,
                textured: false,
                about: "half-angle where the falloff starts, degrees (default `outer_angle`)",
            },
            Key {
                name: "outer_angle",
                ty: KeyType::Number(Accepts::Between(0.0, 180.0)),
                default: Fallback::Required,
                textured: false,
                about: "half-angle where the light ends, degrees, in (0, 180]",
            },
        ];
        const DIRECTIONAL: &[Key] = &[
            Key {
                name: "direction",
                ty: KeyType::Direction,
                default: Fallback::Required,
                textured: false,
                about: "direction the light travels",
            },
            power("irradiance", "irradiance on a surface facing the light"),
        ];
        const AREA: &[Key] = &[
            Key {
                name: "shape",
                ty: KeyType::Choice(&AREA_SHAPES),
                default: Fallback::Required,
                textured: false,
                about: "the emitting shape, with its keys below",
            },
            power("radiance", "emitted radiance"),
            flag("two_sided", false, "emit from both faces"),
            Key {
                name: "material",
                ty: KeyType::Reference,
                default: Fallback::Absent,
                textured: false,
                about: "a material the surface also scatters with (default: black)",
            },
            shape_key("corner", KeyType::Point, "quad: a corner"),
            shape_key("edge_u", KeyType::Direction, "quad: one edge from `corner`"),
            shape_key("edge_v", KeyType::Direction, "quad: the other edge"),
            shape_key("center", KeyType::Point, "disc, sphere: centre"),
            shape_key(
                "normal",
                KeyType::Direction,
                "disc: normal of its front face",
            ),
            shape_key(
                "radius",
                KeyType::Number(Accepts::Positive),
                "disc, sphere: radius",
            ),
        ];
        const ENVIRONMENT: &[Key] = &[
            Key {
                name: "radiance",
                ty: KeyType::Colour(Accepts::AtLeast(0.0)),
                default: Fallback::Absent,
                textured: true,
                about: "radiance from every direction",
            },
            number("scale", 1.0, Accepts::Positive, "multiplies the image"),
        ];
        match self {
            LightKind::Point => POINT,
            LightKind::Spot => SPOT,
            LightKind::Directional => DIRECTIONAL,
            LightKind::Area => AREA,
            LightKind::Environment => ENVIRONMENT,
        }
    }

    /// The key a texture (an image) stands in for, if the kind has one.
    pub fn textured_key(self) -> Option<&'static str> {
        self.keys().iter().find(|k| k.textured).map(|k| k.name)
    }

    /// What this kind builds from `values` (given for
    /// [`LightKind::keys`], each checked) and, if `textured`, an image
    /// for its [`LightKind::textured_key`] (given by the file's key
    /// `image_key`, which messages name); or what is wrong with them
    /// together.
    pub fn light(self, v: &Values, image_key: &str, textured: bool) -> Result<LightOf, KeyError> {
        if let Some(key) = v.missing() {
            return Err(KeyError::entry(format!(
                "a {self} light needs the key `{key}`"
            )));
        }
        let rgb = |key: &str| v.triple_of(key);
        Ok(match self {
            LightKind::Point => LightOf::Explicit(Light::point(rgb("position"), rgb("intensity"))),
            LightKind::Spot => {
                let (position, target) = (rgb("position"), rgb("target"));
                if target == position {
                    return Err(KeyError::at(
                        "target",
                        "a spot light's target must differ from its position",
                    ));
                }
                let outer = v.number_of("outer_angle");
                if outer <= 0.0 {
                    return Err(KeyError::at(
                        "outer_angle",
                        format!("`outer_angle` is {outer} but must be in (0, 180] degrees"),
                    ));
                }
                let inner = v.number("inner_angle").unwrap_or(outer);
                if inner > outer {
                    return Err(KeyError::at(
                        "inner_angle",
                        format!("`inner_angle` is {inner} but must be between 0 and outer_angle"),
                    ));
                }
                LightOf::Explicit(Light::spot(
                    position,
                    target,
                    rgb("intensity"),
                    inner,
                    outer,
                ))
            }
            LightKind::Directional => {
                LightOf::Explicit(Light::directional(rgb("direction"), rgb("irradiance")))
            }
            LightKind::Area => LightOf::Area {
                radiance: rgb("radiance"),
                two_sided: v.flag("two_sided"),
            },
            LightKind::Environment => match (v.triple("radiance"), textured) {
                (Some(radiance), false) => {
                    if v.is_given("scale") {
                        return Err(KeyError::at(
                            "scale",
                            format!("`scale` applies only to an environment `{image_key}`"),
                        ));
                    }
                    LightOf::Constant(radiance)
                }
                (None, true) => LightOf::Map {
                    scale: v.number_of("scale"),
                },
                _ => {
                    return Err(KeyError::entry(format!(
                        "an environment light needs exactly one of `radiance` (a constant colour) or `{image_key}` (an image file)"
                    )))
                }
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::keys::Value;
    use crate::names::Named;

    #[test]
    fn spot_angles_are_checked_together() {
        let mut v = Values::new(LightKind::Spot.keys());
        for (k, x) in [
            ("position", Value::Triple(Vec3::ZERO)),
            ("target", Value::Triple(Vec3::NEG_Z)),
            ("intensity", Value::Triple(Vec3::ONE)),
            ("outer_angle", Value::Number(30.0)),
        ] {
            v.set(k, x).unwrap();
        }
        let spot = LightKind::Spot.light(&v, "map", false).unwrap();
        assert_eq!(
            spot,
            LightOf::Explicit(Light::spot(Vec3::ZERO, Vec3::NEG_Z, Vec3::ONE, 30.0, 30.0))
        );
        v.set("inner_angle", Value::Number(40.0)).unwrap();
        let e = LightKind::Spot.light(&v, "map", false).unwrap_err();
        assert_eq!(e.key, Some("inner_angle"));
        for &kind in LightKind::ALL {
            assert!(kind.keys().iter().filter(|k| k.textured).count() <= 1);
        }
        for name in AREA_SHAPES {
            assert!(crate::ShapeKind::from_name(name).is_ok(), "{name}");
        }
    }

    #[test]
    fn an_environment_is_a_colour_or_an_image() {
        let mut v = Values::new(LightKind::Environment.keys());
        let env = LightKind::Environment;
        assert!(env.light(&v, "map", false).is_err());
        assert_eq!(env.light(&v, "map", true), Ok(LightOf::Map { scale: 1.0 }));
        v.set("radiance", Value::Triple(Vec3::ONE)).unwrap();
        assert_eq!(
            env.light(&v, "map", false),
            Ok(LightOf::Constant(Vec3::ONE))
        );
        assert!(env.light(&v, "map", true).is_err());
    }
}
