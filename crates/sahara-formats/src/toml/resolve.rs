//! From the raw TOML shape to checked [`SceneFile`] values, with positioned errors.

use std::collections::{HashMap, HashSet};
use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::Vec3;
use sahara_readers::FormatError;
use sahara_render::{
    AdaptiveChoice, Filter, FilterKind, FrameLayer, Guiding, Integrator, IntegratorKind, Named,
    Parameter, Pick, Shape, ShapeKind,
};
use toml::Spanned;

use super::file::*;
use super::raw::*;
use crate::description::{SettingsLayer, Sky};
use crate::output::frame::OutputLayer;
use crate::output::image::ImageFormat;

mod kinds;
mod media;

/// Largest film width or height.
const MAX_FILM_SIDE: i64 = 65536;

/// Parses `text` and checks every value.
pub(super) fn resolve(text: &str, name: &str, folder: &Path) -> Result<SceneFile, FormatError> {
    let ctx = Ctx { text, name, folder };
    let raw: RawScene = toml::from_str(text).map_err(|e| {
        // Only a file that is not a scene is read a second time, to say so.
        if let Err(other) = refuse_other_toml(text, name) {
            return other;
        }
        let message = sahara_readers::in_words(e.message().trim_end());
        match e.span() {
            Some(span) => ctx.at(span, message),
            None => FormatError::in_file(name, message),
        }
    })?;
    let camera = raw
        .camera
        .as_ref()
        .ok_or_else(|| FormatError::in_file(name, "no [camera] table; a scene needs one"))?;
    let film = raw.film.as_ref().ok_or_else(|| {
        FormatError::in_file(
            name,
            "no [film] table; a scene needs one (width and height)",
        )
    })?;
    let materials = raw
        .material
        .iter()
        .map(|m| ctx.material(m))
        .collect::<Result<Vec<_>, _>>()?;
    let mut seen = HashSet::new();
    for (m, raw_m) in materials.iter().zip(&raw.material) {
        if !seen.insert(m.name.as_str()) {
            let at = raw_m
                .get_ref()
                .get("name")
                .map_or(raw_m.span(), Spanned::span);
            return Err(ctx.at(
                at,
                format!("a material named '{}' is already defined", m.name),
            ));
        }
    }
    let media = raw
        .medium
        .iter()
        .map(|m| ctx.medium(m))
        .collect::<Result<Vec<_>, _>>()?;
    let mut medium_index = HashMap::new();
    for (i, (m, raw_m)) in media.iter().zip(&raw.medium).enumerate() {
        if medium_index.insert(m.name.clone(), i as u32).is_some() {
            return Err(ctx.at(
                raw_m.get_ref().name.span(),
                format!("a medium named '{}' is already defined", m.name),
            ));
        }
    }
    let objects = raw
        .object
        .iter()
        .map(|o| {
            let mut spec = ctx.object(o, &seen)?;
            spec.interface = ctx.object_media(o.get_ref(), &medium_index)?;
            Ok(spec)
        })
        .collect::<Result<Vec<_>, FormatError>>()?;
    let lights = raw
        .light
        .iter()
        .map(|l| ctx.light(l, &seen))
        .collect::<Result<Vec<_>, _>>()?;
    let environments: Vec<_> = lights
        .iter()
        .zip(&raw.light)
        .filter(|(l, _)| matches!(l, LightSpec::Environment(_)))
        .collect();
    if let Some((_, second)) = environments.get(1) {
        return Err(ctx.at(second.span(), "a scene has at most one environment light"));
    }
    Ok(SceneFile {
        sky: raw
            .sky
            .as_ref()
            .map_or(Sky::None, |s| Sky::parse(s.get_ref(), folder)),
        camera: ctx.camera(camera)?,
        camera_medium: ctx.medium_named(&camera.get_ref().medium, &medium_index)?,
        media,
        materials,
        objects,
        lights,
        settings: ctx.settings(&raw, film.get_ref())?,
    })
}

/// The top-level keys of a scene file (those of `RawScene`).
const SCENE_KEYS: [&str; 10] = [
    "sky",
    "camera",
    "material",
    "object",
    "light",
    "medium",
    "integrator",
    "sampler",
    "filter",
    "film",
];

/// Refuses a TOML file that holds none of a scene file's tables (a
/// `Cargo.toml`, say) in one line that says so, rather than blaming its
/// first unknown key.
fn refuse_other_toml(text: &str, name: &str) -> Result<(), FormatError> {
    let Ok(table) = text.parse::<toml::Table>() else {
        return Ok(());
    };
    if table.is_empty() || table.keys().any(|k| SCENE_KEYS.contains(&k.as_str())) {
        return Ok(());
    }
    let keys: Vec<&str> = table.keys().map(String::as_str).take(4).collect();
    Err(FormatError::in_file(
        name,
        format!(
            "not a Sahara scene file: it has none of a scene's tables ([camera], [film], [[object]], ...) but {}{}",
            keys.join(", "),
            if table.len() > keys.len() { ", ..." } else { "" }
        ),
    ))
}

/// 1-based line and column (in characters) of byte `offset` of `text`.
pub(super) fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = 1 + before.matches('\n').count();
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, 1 + before[line_start..].chars().count())
}

/// The span of an optional value, if present.
fn span<T>(value: &Opt<T>) -> Option<Range<usize>> {
    value.as_ref().map(Spanned::span)
}

/// The file being read, for positioned errors and path resolution.
struct Ctx<'a> {
    text: &'a str,
    name: &'a str,
    folder: &'a Path,
}

impl Ctx<'_> {
    /// An error at the start of `span`.
    fn at(&self, span: Range<usize>, message: impl Into<String>) -> FormatError {
        let (line, column) = line_column(self.text, span.start);
        FormatError::at_line(
            self.name,
            line,
            format!("column {column}: {}", message.into()),
        )
    }

    /// A required key of an entry, or an error at the entry.
    fn required<'r, T>(
        &self,
        value: &'r Opt<T>,
        key: &str,
        entry: &Range<usize>,
        what: &str,
    ) -> Result<&'r Spanned<T>, FormatError> {
        value
            .as_ref()
            .ok_or_else(|| self.at(entry.clone(), format!("{what} needs the key `{key}`")))
    }

    /// Rejects present keys that do not apply (`allowed` lists those that do).
    fn only(
        &self,
        present: &[(&str, Option<Range<usize>>)],
        allowed: &[&str],
        what: &str,
    ) -> Result<(), FormatError> {
        for (key, at) in present {
            if let Some(at) = at {
                if !allowed.contains(key) {
                    return Err(self.at(
                        at.clone(),
                        format!(
                            "the key `{key}` does not apply to {what} (its keys: {})",
                            allowed.join(", ")
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// A finite vector.
    fn vec(&self, value: &Spanned<V3>, key: &str) -> Result<Vec3, FormatError> {
        let v = Vec3::from_array(*value.get_ref());
        if !v.is_finite() {
            return Err(self.at(value.span(), format!("`{key}` must be finite, not {v}")));
        }
        Ok(v)
    }

    /// A finite vector, or `default` if absent.
    fn vec_or(&self, value: &Opt<V3>, key: &str, default: Vec3) -> Result<Vec3, FormatError> {
        value.as_ref().map_or(Ok(default), |v| self.vec(v, key))
    }

    /// A non-zero finite vector.
    fn direction(&self, value: &Spanned<V3>, key: &str) -> Result<Vec3, FormatError> {
        let v = self.vec(value, key)?;
        if v.length_squared() == 0.0 || !v.length_squared().is_finite() {
            return Err(self.at(
                value.span(),
                format!("`{key}` must be a non-zero direction"),
            ));
        }
        Ok(v)
    }

    /// A colour with every component `>= 0`.
    fn power(&self, value: &Spanned<V3>, key: &str) -> Result<Vec3, FormatError> {
        let v = self.vec(value, key)?;
        if v.min_element() < 0.0 {
            return Err(self.at(value.span(), format!("`{key}` {v} must not be negative")));
        }
        Ok(v)
    }

    /// A finite number satisfying `ok` (described by `rule`), or `default` if absent.
    fn number(
        &self,
        value: &Opt<f32>,
        key: &str,
        default: f32,
        ok: impl Fn(f32) -> bool,
        rule: &str,
    ) -> Result<f32, FormatError> {
        match value {
            None => Ok(default),
            Some(v) => {
                let x = *v.get_ref();
                if x.is_finite() && ok(x) {
                    Ok(x)
                } else {
                    Err(self.at(v.span(), format!("`{key}` is {x} but must be {rule}")))
                }
            }
        }
    }

    /// A whole number `>= min` that fits in 32 bits, or `default` if absent.
    fn count(
        &self,
        value: &Opt<i64>,
        key: &str,
        default: u32,
        min: i64,
    ) -> Result<u32, FormatError> {
        match value {
            None => Ok(default),
            Some(v) => {
                let x = *v.get_ref();
                if x < min {
                    return Err(self.at(
                        v.span(),
                        format!("`{key}` is {x} but must be at least {min}"),
                    ));
                }
                u32::try_from(x)
                    .map_err(|_| self.at(v.span(), format!("`{key}` is {x}, too large")))
            }
        }
    }

    /// An existing file named relative to the scene file.
    fn file(&self, value: &Spanned<String>, what: &str) -> Result<PathBuf, FormatError> {
        let path = self.folder.join(value.get_ref());
        if !path.is_file() {
            return Err(self.at(
                value.span(),
                format!(
                    "{what} '{}' not found (looked for {})",
                    value.get_ref(),
                    path.display()
                ),
            ));
        }
        Ok(path)
    }

    /// `[camera]`.
    fn camera(&self, raw: &Spanned<RawCamera>) -> Result<CameraSpec, FormatError> {
        let c = raw.get_ref();
        let eye = self.vec(&c.eye, "eye")?;
        let target = self.vec(&c.target, "target")?;
        let up = self.vec_or(&c.up, "up", Vec3::Y)?;
        let view = target - eye;
        if view.length_squared() == 0.0 {
            return Err(self.at(
                c.target.span(),
                format!("eye and target are the same point {eye}"),
            ));
        }
        if up.length_squared() == 0.0 || view.normalize().cross(up.normalize()).length() < 1e-6 {
            return Err(self.at(
                span(&c.up).unwrap_or(raw.span()),
                format!("up {up} is zero or parallel to the view direction {view}"),
            ));
        }
        let shutter_open = self.number(&c.shutter_open, "shutter_open", 0.0, |_| true, "finite")?;
        let shutter_close = self.number(
            &c.shutter_close,
            "shutter_close",
            shutter_open,
            |t| t >= shutter_open,
            "at least shutter_open",
        )?;
        Ok(CameraSpec {
            eye,
            target,
            up,
            vfov_deg: self.number(
                &c.vfov,
                "vfov",
                45.0,
                |v| v > 0.0 && v < 180.0,
                "between 0 and 180 degrees (exclusive)",
            )?,
            aperture_radius: self.number(
                &c.aperture_radius,
                "aperture_radius",
                0.0,
                |r| r >= 0.0,
                "at least 0",
            )?,
            focus_distance: self.number(
                &c.focus_distance,
                "focus_distance",
                view.length(),
                |d| d > 0.0,
                "greater than 0",
            )?,
            shutter_open,
            shutter_close,
        })
    }

    /// `[[object]]`.
    fn object(
        &self,
        raw: &Spanned<RawObject>,
        materials: &HashSet<&str>,
    ) -> Result<ObjectSpec, FormatError> {
        let o = raw.get_ref();
        let keys = ShapeKeys {
            file: &o.file,
            corner: &o.corner,
            edge_u: &o.edge_u,
            edge_v: &o.edge_v,
            center: &o.center,
            normal: &o.normal,
            radius: &o.radius,
            min: &o.min,
            max: &o.max,
        };
        let shape = self.shape(
            *o.kind.get_ref(),
            &raw.span(),
            &keys,
            &format!("a {} object", o.kind.get_ref()),
        )?;
        if let Some(m) = &o.material {
            if !materials.contains(m.get_ref().as_str()) {
                return Err(self.at(
                    m.span(),
                    format!("no [[material]] is named '{}'", m.get_ref()),
                ));
            }
        }
        let placement = match (&o.transform, &o.motion) {
            (Some(_), Some(m)) => {
                return Err(self.at(
                    m.span(),
                    "an object has either `transform` or `motion`, not both",
                ))
            }
            (Some(t), None) => Placement::Static(self.transform(t)?),
            (None, Some(m)) => Placement::Motion {
                open: self.transform(&m.get_ref().open)?,
                close: self.transform(&m.get_ref().close)?,
            },
            (None, None) => Placement::Static(TransformSpec::IDENTITY),
        };
        Ok(ObjectSpec {
            shape,
            material: o.material.as_ref().map(|m| m.get_ref().clone()),
            placement,
            name: o.name.as_ref().map(|n| n.get_ref().clone()),
            interface: None,
        })
    }

    /// A shape of type `kind` from an entry's keys; `what` names the entry in errors.
    fn shape(
        &self,
        kind: ShapeType,
        entry: &Range<usize>,
        k: &ShapeKeys,
        what: &str,
    ) -> Result<ShapeSpec, FormatError> {
        let allowed: &[&str] = match kind {
            ShapeType::Mesh => &["file"],
            ShapeType::Builtin(ShapeKind::Quad) => &["corner", "edge_u", "edge_v"],
            ShapeType::Builtin(ShapeKind::Disc) => &["center", "normal", "radius"],
            ShapeType::Builtin(ShapeKind::Sphere) => &["center", "radius"],
            ShapeType::Builtin(ShapeKind::Box) => &["min", "max"],
        };
        let present = [
            ("file", span(k.file)),
            ("corner", span(k.corner)),
            ("edge_u", span(k.edge_u)),
            ("edge_v", span(k.edge_v)),
            ("center", span(k.center)),
            ("normal", span(k.normal)),
            ("radius", span(k.radius)),
            ("min", span(k.min)),
            ("max", span(k.max)),
        ];
        self.only(&present, allowed, what)?;
        let radius = || {
            let r = self.required(k.radius, "radius", entry, what)?;
            self.number(k.radius, "radius", 0.0, |r| r > 0.0, "greater than 0")
                .map_err(|_| {
                    self.at(
                        r.span(),
                        format!("`radius` is {} but must be greater than 0", r.get_ref()),
                    )
                })
        };
        Ok(match kind {
            ShapeType::Mesh => {
                let file = self.required(k.file, "file", entry, what)?;
                let path = self.file(file, "mesh file")?;
                let extension = path
                    .extension()
                    .map(|e| e.to_string_lossy().to_ascii_lowercase())
                    .unwrap_or_default();
                if !["obj", "ply", "gltf", "glb"].contains(&extension.as_str()) {
                    return Err(self.at(
                        file.span(),
                        format!(
                            "mesh file '{}' is not .obj, .ply, .gltf or .glb",
                            file.get_ref()
                        ),
                    ));
                }
                ShapeSpec::Mesh { path }
            }
            ShapeType::Builtin(ShapeKind::Quad) => {
                let corner = self.vec(self.required(k.corner, "corner", entry, what)?, "corner")?;
                let edge_u =
                    self.direction(self.required(k.edge_u, "edge_u", entry, what)?, "edge_u")?;
                let v = self.required(k.edge_v, "edge_v", entry, what)?;
                let edge_v = self.direction(v, "edge_v")?;
                if edge_u.normalize().cross(edge_v.normalize()).length() < 1e-6 {
                    return Err(self.at(
                        v.span(),
                        "`edge_v` is parallel to `edge_u`: the quad has no area",
                    ));
                }
                ShapeSpec::Builtin(Shape::Quad {
                    corner,
                    edge_u,
                    edge_v,
                })
            }
            ShapeType::Builtin(ShapeKind::Disc) => ShapeSpec::Builtin(Shape::Disc {
                center: self.vec(self.required(k.center, "center", entry, what)?, "center")?,
                normal: self
                    .direction(self.required(k.normal, "normal", entry, what)?, "normal")?
                    .normalize(),
                radius: radius()?,
            }),
            ShapeType::Builtin(ShapeKind::Sphere) => ShapeSpec::Builtin(Shape::Sphere {
                center: self.vec(self.required(k.center, "center", entry, what)?, "center")?,
                radius: radius()?,
            }),
            ShapeType::Builtin(ShapeKind::Box) => {
                let min = self.vec(self.required(k.min, "min", entry, what)?, "min")?;
                let max_raw = self.required(k.max, "max", entry, what)?;
                let max = self.vec(max_raw, "max")?;
                if !min.cmplt(max).all() {
                    return Err(self.at(
                        max_raw.span(),
                        format!("box max {max} must exceed min {min} on every axis"),
                    ));
                }
                ShapeSpec::Builtin(Shape::Box { min, max })
            }
        })
    }

    /// `transform = { ... }`.
    fn transform(&self, raw: &Spanned<RawTransform>) -> Result<TransformSpec, FormatError> {
        let t = raw.get_ref();
        let translate = self.vec_or(&t.translate, "translate", Vec3::ZERO)?;
        let (rotate_axis, rotate_deg) = match &t.rotate {
            None => (Vec3::Y, 0.0),
            Some(r) => {
                let axis = Vec3::from_array(r.get_ref().axis);
                let degrees = r.get_ref().degrees;
                if !axis.is_finite() || axis.length_squared() == 0.0 || !degrees.is_finite() {
                    return Err(self.at(
                        r.span(),
                        "`rotate` needs a non-zero finite `axis` and finite `degrees`",
                    ));
                }
                (axis.normalize(), degrees)
            }
        };
        let scale = match &t.scale {
            None => Vec3::ONE,
            Some(s) => {
                let v = match *s.get_ref() {
                    RawScale::Uniform(k) => Vec3::splat(k),
                    RawScale::PerAxis(v) => Vec3::from_array(v),
                };
                if !v.is_finite() || v.cmpeq(Vec3::ZERO).any() {
                    return Err(self.at(
                        s.span(),
                        format!("`scale` {v} must be finite with no zero component"),
                    ));
                }
                v
            }
        };
        Ok(TransformSpec {
            translate,
            rotate_axis,
            rotate_deg,
            scale,
        })
    }

    /// `[integrator]`: `name` and the parameters the renderer lists for
    /// that integrator ([`IntegratorKind::parameters`]), so a new
    /// integrator or parameter needs no change here.
    /// The integrator of `[integrator]`, and its `guiding` key if given
    /// (a frame setting beside the integrator's parameters).
    fn integrator(
        &self,
        table: &Spanned<RawNamedTable>,
    ) -> Result<(Integrator, Option<Guiding>), FormatError> {
        let mut table = table.clone();
        let guiding = match table.get_mut().remove("guiding") {
            None => None,
            Some(v) => match v.get_ref() {
                toml::Value::String(s) => {
                    Some(Guiding::from_name(s).map_err(|e| self.at(v.span(), e.to_string()))?)
                }
                _ => return Err(self.at(v.span(), "`guiding` must be a string")),
            },
        };
        let (kind, values) = self.named_table("integrator", &table, IntegratorKind::parameters)?;
        Ok((Integrator::with_parameters(kind, &values), guiding))
    }

    /// The render settings of `[integrator]`, `[sampler]`, `[filter]` and
    /// `[film]`: what the file gives, each key not given left to the
    /// layers below (the defaults).
    fn settings(&self, raw: &RawScene, film: &RawFilm) -> Result<SettingsLayer, FormatError> {
        let integrator = raw
            .integrator
            .as_ref()
            .map(|i| self.integrator(i))
            .transpose()?;
        let mut layer = SettingsLayer {
            frame: FrameLayer {
                integrator: integrator.map(|(i, _)| Pick::Value(i)),
                guiding: integrator.and_then(|(_, g)| g),
                filter: raw
                    .filter
                    .as_ref()
                    .map(|f| self.filter(f).map(Pick::Value))
                    .transpose()?,
                ..Default::default()
            },
            ..Default::default()
        };
        if let Some(s) = &raw.sampler {
            self.sampler(s.get_ref(), &mut layer.frame)?;
        }
        self.film(film, &mut layer)?;
        Ok(layer)
    }

    /// `[sampler]`, into `frame`.
    fn sampler(&self, s: &RawSampler, frame: &mut FrameLayer) -> Result<(), FormatError> {
        frame.seed = match &s.seed {
            None => None,
            Some(v) if *v.get_ref() >= 0 => Some(*v.get_ref() as u64),
            Some(v) => {
                return Err(self.at(
                    v.span(),
                    format!("`seed` is {} but must be at least 0", v.get_ref()),
                ))
            }
        };
        frame.adaptive = match (&s.noise_threshold, &s.min_spp) {
            (None, None) => None,
            (None, Some(m)) => {
                return Err(self.at(
                    m.span(),
                    "`min_spp` needs `noise_threshold` (adaptive sampling)",
                ))
            }
            (Some(_), min) => Some(AdaptiveChoice {
                threshold: Some(self.number(
                    &s.noise_threshold,
                    "noise_threshold",
                    0.0,
                    |t| t > 0.0,
                    "greater than 0",
                )?),
                min_spp: min
                    .as_ref()
                    .map(|_| self.count(min, "min_spp", 0, 2))
                    .transpose()?,
            }),
        };
        frame.sampler = s.name.as_ref().map(|n| n.get_ref().0);
        frame.spp = s
            .spp
            .as_ref()
            .map(|_| self.count(&s.spp, "spp", 0, 1))
            .transpose()?;
        Ok(())
    }

    /// `[filter]`: `name` and the parameters the renderer lists for that
    /// filter ([`FilterKind::parameters`]), so a new filter needs no change
    /// here.
    fn filter(&self, table: &Spanned<RawNamedTable>) -> Result<Filter, FormatError> {
        let (kind, values) = self.named_table("filter", table, FilterKind::parameters)?;
        Ok(Filter::with_parameters(kind, &values))
    }

    /// A table naming a setting of kind `K` (`name = "..."`) and giving
    /// values to some of the parameters `parameters` lists for it: the
    /// kind and every parameter's value, in the list's order (the default
    /// where not given). A key the kind does not take, a value of the
    /// wrong type or out of range is an error at its position.
    fn named_table<K: Named + std::fmt::Display>(
        &self,
        what: &str,
        table: &Spanned<RawNamedTable>,
        parameters: fn(K) -> &'static [Parameter],
    ) -> Result<(K, Vec<f32>), FormatError> {
        let t = table.get_ref();
        let name = t.get("name").ok_or_else(|| {
            self.at(
                table.span(),
                format!("the [{what}] table needs the key `name`"),
            )
        })?;
        let kind = match name.get_ref() {
            toml::Value::String(s) => {
                K::from_name(s).map_err(|e| self.at(name.span(), e.to_string()))?
            }
            _ => return Err(self.at(name.span(), "`name` must be a string")),
        };
        let parameters = parameters(kind);
        let keys: Vec<&str> = parameters.iter().map(|p| p.name).collect();
        if let Some((key, value)) = t
            .iter()
            .find(|(key, _)| *key != "name" && !keys.contains(&key.as_str()))
        {
            let takes = if keys.is_empty() {
                "it takes no parameters".to_string()
            } else {
                format!("its keys: {}", keys.join(", "))
            };
            return Err(self.at(
                value.span(),
                format!("the key `{key}` does not apply to the {kind} {what} ({takes})"),
            ));
        }
        let values = parameters
            .iter()
            .map(|p| match t.get(p.name) {
                None => Ok(p.default),
                Some(v) => {
                    let x = match v.get_ref() {
                        toml::Value::Integer(i) => *i as f32,
                        toml::Value::Float(f) if !p.is_whole() => *f as f32,
                        _ => {
                            let must = if p.is_whole() {
                                "a whole number"
                            } else {
                                "a number"
                            };
                            return Err(self.at(v.span(), format!("`{}` must be {must}", p.name)));
                        }
                    };
                    p.check(x).map_err(|why| self.at(v.span(), why))
                }
            })
            .collect::<Result<Vec<f32>, FormatError>>()?;
        Ok((kind, values))
    }

    /// `[film]`, into `layer`.
    fn film(&self, f: &RawFilm, layer: &mut SettingsLayer) -> Result<(), FormatError> {
        let side = |v: &Spanned<i64>, key: &str| {
            let x = *v.get_ref();
            if (1..=MAX_FILM_SIDE).contains(&x) {
                Ok(x as u32)
            } else {
                Err(self.at(
                    v.span(),
                    format!("`{key}` is {x} but must be between 1 and {MAX_FILM_SIDE} pixels"),
                ))
            }
        };
        let output = match &f.output {
            None => None,
            Some(o) => {
                // Relative to the working folder, as a command line's
                // output: a scene file in a shared folder does not write there.
                let path = PathBuf::from(o.get_ref());
                ImageFormat::from_path(&path).map_err(|_| {
                    self.at(
                        o.span(),
                        format!("output '{}' must end in .png or .exr", o.get_ref()),
                    )
                })?;
                Some(path)
            }
        };
        layer.frame.width = Some(side(&f.width, "width")?);
        layer.frame.height = Some(side(&f.height, "height")?);
        layer.output = OutputLayer {
            exposure: f
                .exposure
                .as_ref()
                .map(|_| self.number(&f.exposure, "exposure", 0.0, |_| true, "finite"))
                .transpose()?,
            tonemap: f.tonemap.as_ref().map(|t| t.get_ref().0),
            aovs: None,
            denoise: f.denoise.as_ref().map(|d| *d.get_ref()),
        };
        layer.path = output;
        Ok(())
    }
}

/// The keys a shape may use, borrowed from an object or area light entry.
struct ShapeKeys<'r> {
    file: &'r Opt<String>,
    corner: &'r Opt<V3>,
    edge_u: &'r Opt<V3>,
    edge_v: &'r Opt<V3>,
    center: &'r Opt<V3>,
    normal: &'r Opt<V3>,
    radius: &'r Opt<f32>,
    min: &'r Opt<V3>,
    max: &'r Opt<V3>,
}
