//! `[[material]]` and `[[light]]` tables, read through the renderer's
//! descriptions of its kinds ([`MaterialKind::keys`],
//! [`LightKind::keys`]): the `type` names a kind, every other key is one
//! the kind lists (checked by it), and the kind builds the material or
//! light. Only what the renderer cannot know is read here: an entry's
//! `name`, a texture or image file (`texture`, `map`) for the kind's
//! textured key, an area light's shape and the material it names.

use std::collections::HashSet;
use std::ops::Range;

use sahara_render::{
    Key, KeyError, LightKind, LightOf, MaterialKind, Named, ShapeKind, Value, Values,
};
use toml::Spanned;

use super::{Ctx, ShapeKeys};
use crate::toml::file::{EnvironmentSpec, LightSpec, MaterialSpec};
use crate::toml::raw::{Opt, RawDescribed, ShapeType, V3};
use sahara_readers::FormatError;

/// The file's name for the file of a kind's textured key: a material's
/// `texture`, an environment's `map`.
const MATERIAL_TEXTURE: &str = "texture";
const LIGHT_IMAGE: &str = "map";

/// A table of a described kind, read: its kind, its values, and where
/// each key is.
struct Described<'r, K> {
    kind: K,
    values: Values,
    table: &'r RawDescribed,
    entry: Range<usize>,
    type_at: Range<usize>,
}

impl<K> Described<'_, K> {
    /// The position of `key` if given, else of the entry.
    fn at(&self, key: Option<&str>) -> Range<usize> {
        key.and_then(|k| self.table.get(k))
            .map_or(self.entry.clone(), Spanned::span)
    }

    /// The string value of a key the reader reads itself.
    fn string(&self, ctx: &Ctx, key: &str) -> Result<Option<Spanned<String>>, FormatError> {
        match self.table.get(key) {
            None => Ok(None),
            Some(v) => match v.get_ref() {
                toml::Value::String(s) => Ok(Some(Spanned::new(v.span(), s.clone()))),
                _ => Err(ctx.at(v.span(), format!("`{key}` must be a string"))),
            },
        }
    }
}

impl Ctx<'_> {
    /// A table of a kind the renderer describes (`what`: `material` or
    /// `light`): the kind its `type` names, and the values of its other
    /// keys but `own` (which the reader reads), each checked by the
    /// kind's [`Key`]; a key the kind does not list, a value it does not
    /// take or a key it needs and lacks is an error at its position.
    fn described<'r, K: Named + std::fmt::Display>(
        &self,
        what: &str,
        raw: &'r Spanned<RawDescribed>,
        keys: fn(K) -> &'static [Key],
        own: fn(K) -> Vec<&'static str>,
    ) -> Result<Described<'r, K>, FormatError> {
        let table = raw.get_ref();
        let entry = raw.span();
        let ty = table
            .get("type")
            .ok_or_else(|| self.at(entry.clone(), format!("a [[{what}]] needs the key `type`")))?;
        let kind = match ty.get_ref() {
            toml::Value::String(s) => {
                K::from_name(s).map_err(|e| self.at(ty.span(), e.to_string()))?
            }
            _ => return Err(self.at(ty.span(), "`type` must be a string")),
        };
        let (keys, own) = (keys(kind), own(kind));
        let mut values = Values::new(keys);
        let mut given: Vec<_> = table.iter().filter(|(k, _)| *k != "type").collect();
        given.sort_by_key(|(_, v)| v.span().start);
        for (key, value) in given {
            if own.contains(&key.as_str()) {
                continue;
            }
            if !keys.iter().any(|k| k.name == key) {
                let names: Vec<&str> = own
                    .iter()
                    .copied()
                    .filter(|k| *k != "name")
                    .chain(keys.iter().map(|k| k.name))
                    .collect();
                return Err(self.at(
                    value.span(),
                    format!(
                        "the key `{key}` does not apply to a {kind} {what} (its keys: {})",
                        names.join(", ")
                    ),
                ));
            }
            let v = self.value(key, value)?;
            values
                .set(key, v)
                .map_err(|why| self.at(value.span(), why))?;
        }
        if let Some(key) = values.missing() {
            return Err(self.at(ty.span(), format!("a {kind} {what} needs the key `{key}`")));
        }
        Ok(Described {
            kind,
            values,
            table,
            entry,
            type_at: ty.span(),
        })
    }

    /// A TOML value as a kind's value (its [`Key`] checks the type).
    fn value(&self, key: &str, v: &Spanned<toml::Value>) -> Result<Value, FormatError> {
        let number = |x: &toml::Value| match x {
            toml::Value::Integer(i) => Some(*i as f32),
            toml::Value::Float(f) => Some(*f as f32),
            _ => None,
        };
        Ok(match v.get_ref() {
            toml::Value::Boolean(b) => Value::Flag(*b),
            toml::Value::String(s) => Value::Name(s.clone()),
            toml::Value::Array(a) => match a.iter().map(number).collect::<Option<Vec<f32>>>() {
                Some(xs) if xs.len() == 3 => Value::Triple(glam::Vec3::from_slice(&xs)),
                _ => {
                    return Err(self.at(v.span(), format!("`{key}` must be an array of 3 numbers")))
                }
            },
            other => match number(other) {
                Some(x) => Value::Number(x),
                None => {
                    return Err(self.at(
                        v.span(),
                        format!("`{key}` is a {}, which no key takes", other.type_str()),
                    ))
                }
            },
        })
    }

    /// A kind's error about its values, at the key it names (else at the
    /// entry).
    fn kind_error<K>(&self, d: &Described<K>, e: KeyError) -> FormatError {
        self.at(d.at(e.key), e.message)
    }

    /// `[[material]]`: `name`, `type` and the kind's keys (`texture`: a
    /// file multiplying its textured key).
    pub(super) fn material(
        &self,
        raw: &Spanned<RawDescribed>,
    ) -> Result<MaterialSpec, FormatError> {
        let d = self.described("material", raw, MaterialKind::keys, |kind| {
            let mut own = vec!["name"];
            own.extend(kind.textured_key().map(|_| MATERIAL_TEXTURE));
            own
        })?;
        let name = d
            .string(self, "name")?
            .ok_or_else(|| self.at(d.entry.clone(), "a [[material]] needs the key `name`"))?;
        if name.get_ref().is_empty() {
            return Err(self.at(name.span(), "a material name must not be empty"));
        }
        let texture = match d.string(self, MATERIAL_TEXTURE)? {
            Some(t) => Some(self.file(&t, "texture")?),
            None => None,
        };
        let material = d
            .kind
            .material(&d.values)
            .map_err(|e| self.kind_error(&d, e))?;
        Ok(MaterialSpec {
            name: name.into_inner(),
            material,
            texture,
        })
    }

    /// `[[light]]`: `type` and the kind's keys; an environment's image
    /// (`map`), an area light's shape (its keys those of the shape) and
    /// the material it names are read here.
    pub(super) fn light(
        &self,
        raw: &Spanned<RawDescribed>,
        materials: &HashSet<&str>,
    ) -> Result<LightSpec, FormatError> {
        let d = self.described("light", raw, LightKind::keys, |kind| {
            kind.textured_key()
                .map(|_| LIGHT_IMAGE)
                .into_iter()
                .collect()
        })?;
        let map = d.string(self, LIGHT_IMAGE)?;
        let light = d
            .kind
            .light(&d.values, LIGHT_IMAGE, map.is_some())
            .map_err(|e| self.kind_error(&d, e))?;
        Ok(match light {
            LightOf::Explicit(l) => LightSpec::Explicit(l),
            LightOf::Constant(c) => LightSpec::Environment(EnvironmentSpec::Constant(c)),
            LightOf::Map { scale } => {
                let m = map.expect("an image was given");
                let path = self.file(&m, "environment map")?;
                let extension = path
                    .extension()
                    .map(|e| e.to_string_lossy().to_ascii_lowercase())
                    .unwrap_or_default();
                if !["hdr", "exr", "png", "jpg", "jpeg"].contains(&extension.as_str()) {
                    return Err(self.at(
                        m.span(),
                        format!(
                            "environment map '{}' is not .hdr, .exr, .png or .jpg",
                            m.get_ref()
                        ),
                    ));
                }
                LightSpec::Environment(EnvironmentSpec::Map { path, scale })
            }
            LightOf::Area {
                radiance,
                two_sided,
            } => {
                let shape_name = d.values.name_of("shape");
                let shape = ShapeKind::from_name(shape_name)
                    .expect("an area light's shapes are built-in shapes");
                let triple = |key: &str| -> Opt<V3> {
                    let at = d.table.get(key)?.span();
                    Some(Spanned::new(at, d.values.triple(key)?.to_array()))
                };
                let radius = d
                    .values
                    .number("radius")
                    .map(|r| Spanned::new(d.at(Some("radius")), r));
                let keys = ShapeKeys {
                    file: &None,
                    corner: &triple("corner"),
                    edge_u: &triple("edge_u"),
                    edge_v: &triple("edge_v"),
                    center: &triple("center"),
                    normal: &triple("normal"),
                    radius: &radius,
                    min: &None,
                    max: &None,
                };
                let material = d.string(self, "material")?;
                if let Some(m) = &material {
                    if !materials.contains(m.get_ref().as_str()) {
                        return Err(self.at(
                            m.span(),
                            format!("no [[material]] is named '{}'", m.get_ref()),
                        ));
                    }
                }
                let what = format!("an area light ({shape_name})");
                LightSpec::Area {
                    shape: self.shape(ShapeType::Builtin(shape), &d.type_at, &keys, &what)?,
                    radiance,
                    two_sided,
                    material: material.map(Spanned::into_inner),
                }
            }
        })
    }
}
