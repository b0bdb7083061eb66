//! The material kinds a scene file names (`type = "coated_diffuse"`),
//! each described once: its keys ([`MaterialKind::keys`]) and the
//! [`Material`] it builds from their values ([`MaterialKind::material`]).
//! Sahara's scene files read materials through this table; a new kind is
//! an entry here and the BSDF it builds.

use super::{metals, AlphaMode, Bsdf, Distribution, Material};
use crate::keys::{flag, number, power, reflectance, Fallback, Key, KeyError, KeyType, Values};
use crate::names::{name_table, Accepts};

/// A kind of material, as scene files name it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MaterialKind {
    /// Lambertian reflection ([`Bsdf::Diffuse`]).
    Diffuse,
    /// Rough metal: by a reflectance (Schlick, [`Bsdf::Conductor`]), or
    /// by a complex index of refraction, given or a named metal's
    /// ([`Bsdf::ComplexConductor`]).
    Conductor,
    /// A perfect mirror ([`Bsdf::Mirror`]).
    Mirror,
    /// Smooth glass ([`Bsdf::Dielectric`]).
    Dielectric,
    /// Rough glass ([`Bsdf::RoughDielectric`]).
    RoughDielectric,
    /// A thin pane of glass ([`Bsdf::ThinDielectric`]).
    ThinDielectric,
    /// glTF's metallic-roughness model ([`Bsdf::MetallicRoughness`]).
    MetallicRoughness,
    /// A diffuse base under a clear coat ([`Bsdf::CoatedDiffuse`]).
    CoatedDiffuse,
    /// A surface that emits light and reflects diffusely.
    Emission,
}

name_table!(MaterialKind, "material", {
    MaterialKind::Diffuse => "diffuse",
    MaterialKind::Conductor => "conductor",
    MaterialKind::Mirror => "mirror",
    MaterialKind::Dielectric => "dielectric",
    MaterialKind::RoughDielectric => "rough_dielectric",
    MaterialKind::ThinDielectric => "thin_dielectric",
    MaterialKind::MetallicRoughness => "metallic_roughness",
    MaterialKind::CoatedDiffuse => "coated_diffuse",
    MaterialKind::Emission => "emission",
}, aliases {
    "glossy" => MaterialKind::Conductor,
});

/// Perceptual roughness in `[0, 1]`.
const fn roughness(default: f32) -> Key {
    number(
        "roughness",
        default,
        Accepts::Between(0.0, 1.0),
        "perceptual roughness (alpha = roughness^2)",
    )
}

/// Index of refraction of glass.
const IOR: Key = number("ior", 1.5, Accepts::Positive, "index of refraction");

/// The microfacet distribution of the rough kinds.
const DISTRIBUTION: Key = Key {
    name: "distribution",
    ty: KeyType::Choice(&Distribution::NAMES),
    default: Fallback::Choice(Distribution::Ggx.name()),
    textured: false,
    about: "microfacet distribution",
};

/// A reflector's base colour, which the file's texture multiplies.
const fn base(name: &'static str, default: f32) -> Key {
    Key {
        textured: true,
        ..reflectance(name, default, "reflectance")
    }
}

/// The keys every reflector takes after its own: sides and opacity.
const TWO_SIDED: Key = flag(
    "two_sided",
    true,
    "scatter on both faces (false: the back face is black)",
);
const ALPHA: Key = number(
    "alpha",
    1.0,
    Accepts::Between(0.0, 1.0),
    "opacity, times the texture's alpha channel",
);
const ALPHA_MODE: Key = Key {
    name: "alpha_mode",
    ty: KeyType::Choice(&["opaque", "mask", "blend"]),
    default: Fallback::Choice("opaque"),
    textured: false,
    about: "how opacity cuts the surface",
};
const ALPHA_CUTOFF: Key = number(
    "alpha_cutoff",
    0.5,
    Accepts::Between(0.0, 1.0),
    "opacity below which a `mask` surface is absent",
);

impl MaterialKind {
    /// The keys of this kind, in the order documents list them.
    ///
    /// One piece on purpose: it is the table of every kind's keys, read
    /// as a whole (as the document's table generated from it is).
    pub fn keys(self) -> &'static [Key] {
        const COLOR: Key = reflectance("color", 0.9, "reflectance at normal incidence");
        const DIFFUSE: &[Key] = &[
            base("albedo", 0.5),
            TWO_SIDED,
            ALPHA,
            ALPHA_MODE,
            ALPHA_CUTOFF,
        ];
        const CONDUCTOR: &[Key] = &[
            COLOR,
            Key {
                name: "metal",
                ty: KeyType::Choice(&metals::PRESETS),
                default: Fallback::Absent,
                textured: false,
                about: "a measured metal (instead of `color`)",
            },
            Key {
                name: "eta",
                ty: KeyType::Colour(Accepts::Positive),
                default: Fallback::Absent,
                textured: false,
                about: "real part of the index (with `k`, instead of `color`)",
            },
            Key {
                name: "k",
                ty: KeyType::Colour(Accepts::AtLeast(0.0)),
                default: Fallback::Absent,
                textured: false,
                about: "extinction coefficient (with `eta`)",
            },
            flag(
                "multiple_scattering",
                true,
                "add light bounced between microfacets (`metal`, `eta` and `k` only)",
            ),
            roughness(0.2),
            DISTRIBUTION,
            TWO_SIDED,
            ALPHA,
            ALPHA_MODE,
            ALPHA_CUTOFF,
        ];
        const MIRROR: &[Key] = &[
            Key {
                default: Fallback::Triple([1.0; 3]),
                ..COLOR
            },
            TWO_SIDED,
            ALPHA,
            ALPHA_MODE,
            ALPHA_CUTOFF,
        ];
        const GLASS: &[Key] = &[IOR];
        const ROUGH_GLASS: &[Key] = &[IOR, roughness(0.2), DISTRIBUTION];
        const METALLIC_ROUGHNESS: &[Key] = &[
            base("base_color", 0.8),
            number(
                "metallic",
                0.0,
                Accepts::Between(0.0, 1.0),
                "0: dielectric, 1: metal",
            ),
            roughness(0.5),
            number(
                "ior",
                1.5,
                Accepts::AtLeast(1.0),
                "index of refraction of the specular layer",
            ),
            number(
                "specular",
                1.0,
                Accepts::Between(0.0, 1.0),
                "strength of the specular layer",
            ),
            reflectance(
                "specular_color",
                1.0,
                "colour of the specular layer at normal incidence",
            ),
            TWO_SIDED,
            ALPHA,
            ALPHA_MODE,
            ALPHA_CUTOFF,
        ];
        const COATED_DIFFUSE: &[Key] = &[
            base("albedo", 0.5),
            number(
                "ior",
                1.5,
                Accepts::Above(1.0),
                "index of refraction of the coat",
            ),
            roughness(0.1),
            DISTRIBUTION,
            TWO_SIDED,
            ALPHA,
            ALPHA_MODE,
            ALPHA_CUTOFF,
        ];
        const EMISSION: &[Key] = &[
            power("radiance", "emitted radiance"),
            flag(
                "two_sided",
                false,
                "emit from both faces (default: the front face only)",
            ),
            reflectance("albedo", 0.0, "diffuse reflectance besides the emission"),
        ];
        match self {
            MaterialKind::Diffuse => DIFFUSE,
            MaterialKind::Conductor => CONDUCTOR,
            MaterialKind::Mirror => MIRROR,
            MaterialKind::Dielectric | MaterialKind::ThinDielectric => GLASS,
            MaterialKind::RoughDielectric => ROUGH_GLASS,
            MaterialKind::MetallicRoughness => METALLIC_ROUGHNESS,
            MaterialKind::CoatedDiffuse => COATED_DIFFUSE,
            MaterialKind::Emission => EMISSION,
        }
    }

    /// The key a texture multiplies, if the kind has one.
    pub fn textured_key(self) -> Option<&'static str> {
        self.keys().iter().find(|k| k.textured).map(|k| k.name)
    }

    /// The material of this kind with `values` (given for
    /// [`MaterialKind::keys`], each checked), or what is wrong with them
    /// together.
    pub fn material(self, v: &Values) -> Result<Material, KeyError> {
        if let Some(key) = v.missing() {
            return Err(KeyError::entry(format!(
                "a {self} material needs the key `{key}`"
            )));
        }
        let n = |key: &str| v.number_of(key);
        let rgb = |key: &str| v.triple_of(key);
        let distribution = || {
            Distribution::from_name(v.name_of("distribution"))
                .expect("the key lists the distributions' names")
        };
        let bsdf = match self {
            MaterialKind::Diffuse => Bsdf::Diffuse {
                albedo: rgb("albedo"),
            },
            MaterialKind::Conductor => conductor(v, n("roughness"), distribution())?,
            MaterialKind::Mirror => Bsdf::Mirror {
                color: rgb("color"),
            },
            MaterialKind::Dielectric => Bsdf::Dielectric { ior: n("ior") },
            MaterialKind::RoughDielectric => Bsdf::RoughDielectric {
                ior: n("ior"),
                roughness: n("roughness"),
                distribution: distribution(),
            },
            MaterialKind::ThinDielectric => Bsdf::ThinDielectric { ior: n("ior") },
            MaterialKind::MetallicRoughness => Bsdf::MetallicRoughness {
                base_color: rgb("base_color"),
                metallic: n("metallic"),
                roughness: n("roughness"),
                ior: n("ior"),
                specular: n("specular"),
                specular_color: rgb("specular_color"),
            },
            MaterialKind::CoatedDiffuse => Bsdf::CoatedDiffuse {
                albedo: rgb("albedo"),
                ior: n("ior"),
                roughness: n("roughness"),
                distribution: distribution(),
            },
            MaterialKind::Emission => {
                let mut m = Material::diffuse(rgb("albedo")).with_emission(rgb("radiance"));
                m.two_sided_emission = v.flag("two_sided");
                return Ok(m);
            }
        };
        let m = Material::new(bsdf);
        if !v.keys().contains(&ALPHA) {
            return Ok(m);
        }
        let alpha_mode = match v.name_of("alpha_mode") {
            "mask" => AlphaMode::Mask {
                cutoff: n("alpha_cutoff"),
            },
            "blend" => AlphaMode::Blend,
            _ => AlphaMode::Opaque,
        };
        if v.is_given("alpha_cutoff") && !matches!(alpha_mode, AlphaMode::Mask { .. }) {
            return Err(KeyError::at(
                "alpha_cutoff",
                "`alpha_cutoff` applies to `alpha_mode = \"mask\"` only",
            ));
        }
        Ok(m.with_two_sided(v.flag("two_sided"))
            .with_alpha(alpha_mode, n("alpha")))
    }
}

/// A `conductor`: by `color` (Schlick), by a `metal`, or by `eta` and
/// `k`; one of the three at most (default: `color`).
fn conductor(v: &Values, roughness: f32, distribution: Distribution) -> Result<Bsdf, KeyError> {
    let eta = if v.is_given("eta") { "eta" } else { "k" };
    let mut forms = [("color", "color"), ("metal", "metal"), ("eta", eta)]
        .into_iter()
        .filter(|(_, key)| v.is_given(key));
    if let (Some((a, _)), Some((b, at))) = (forms.next(), forms.next()) {
        return Err(KeyError::at(
            at,
            format!("a conductor has `{a}` or `{b}`, not both (`eta` and `k` go together)"),
        ));
    }
    let index = match (v.name("metal"), v.triple("eta"), v.triple("k")) {
        (Some(metal), _, _) => Some(metals::preset(metal).expect("the key lists the presets")),
        (None, Some(eta), Some(k)) => Some((eta, k)),
        (None, Some(_), None) => {
            return Err(KeyError::at(
                "eta",
                "a conductor given by its index needs the key `k`",
            ))
        }
        (None, None, Some(_)) => {
            return Err(KeyError::at(
                "k",
                "a conductor given by its index needs the key `eta`",
            ))
        }
        (None, None, None) => None,
    };
    Ok(match index {
        Some((eta, k)) => Bsdf::ComplexConductor {
            eta,
            k,
            roughness,
            distribution,
            multiple_scattering: v.flag("multiple_scattering"),
        },
        None if v.is_given("multiple_scattering") => return Err(KeyError::at(
            "multiple_scattering",
            "`multiple_scattering` applies to a conductor given by `metal` or by `eta` and `k` \
                 (the `color` form scatters once)",
        )),
        None => Bsdf::Conductor {
            color: v.triple_of("color"),
            roughness,
            distribution,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::keys::Value;
    use crate::names::Named;
    use glam::Vec3;

    fn build(kind: MaterialKind, given: &[(&str, Value)]) -> Result<Material, KeyError> {
        let mut v = Values::new(kind.keys());
        for (k, x) in given {
            v.set(k, x.clone()).unwrap();
        }
        kind.material(&v)
    }

    #[test]
    fn every_kind_builds_with_its_defaults_but_emission() {
        for &kind in MaterialKind::ALL {
            let keys = kind.keys();
            for (i, k) in keys.iter().enumerate() {
                assert!(
                    !keys[..i].iter().any(|o| o.name == k.name),
                    "{kind} {}",
                    k.name
                );
            }
            assert!(keys.iter().filter(|k| k.textured).count() <= 1);
            let m = build(kind, &[]);
            assert_eq!(m.is_err(), kind == MaterialKind::Emission, "{kind}");
        }
        assert_eq!(
            build(MaterialKind::Diffuse, &[]).unwrap(),
            Material::diffuse(Vec3::splat(0.5))
        );
        let mirror = Values::new(MaterialKind::Mirror.keys());
        assert_eq!(mirror.triple_of("color"), Vec3::ONE);
        assert_eq!(
            MaterialKind::from_name("glossy"),
            Ok(MaterialKind::Conductor)
        );
    }

    #[test]
    fn conductor_forms_exclude_each_other() {
        let gold = Value::Name("gold".into());
        let one = Value::Triple(Vec3::ONE);
        let e = build(
            MaterialKind::Conductor,
            &[("color", one.clone()), ("metal", gold.clone())],
        )
        .unwrap_err();
        assert_eq!(e.key, Some("metal"));
        assert!(e.message.contains("not both"));
        let e = build(MaterialKind::Conductor, &[("eta", one.clone())]).unwrap_err();
        assert!(e.message.contains("`k`"));
        let e = build(
            MaterialKind::Conductor,
            &[("multiple_scattering", Value::Flag(false))],
        )
        .unwrap_err();
        assert_eq!(e.key, Some("multiple_scattering"));
        let m = build(MaterialKind::Conductor, &[("metal", gold)]).unwrap();
        assert!(matches!(m.bsdf, Bsdf::ComplexConductor { .. }));
    }
}
