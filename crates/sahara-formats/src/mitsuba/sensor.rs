//! The `<sensor>` with its `<film>`, `<rfilter>` and `<sampler>`: the
//! camera and the render settings.
//!
//! Camera: Mitsuba's camera looks down `+z` of its `to_world` frame with
//! `+y` up, and its image's right is the frame's `-x` (so a `lookat`
//! frame, whose `+x` is `up x forward`, has the image's right along
//! `forward x up`, as Sahara's camera has). A mirroring `to_world`
//! mirrors the image, as in Mitsuba. `fov` spans the axis `fov_axis`
//! names (`x` by default, `y`, `diagonal`, `smaller`, `larger`);
//! `focal_length` (default `50mm`) is on a 35 mm film's diagonal.
//!
//! | Mitsuba | Sahara |
//! |---|---|
//! | `perspective`, `thinlens` (`aperture_radius`, `focus_distance`) | perspective camera, with a thin lens |
//! | `hdrfilm` (`width`, `height`; `crop_offset_x/y`, `crop_width/height`) | image size; the crop window |
//! | `rfilter` `box`, `tent`, `gaussian` (`stddev`; radius 4 `stddev`), `mitchell`, `catmullrom` | the same filter |
//! | `rfilter` `lanczos` | Gaussian (warned) |
//! | `independent`, `stratified` (`sample_count`, `seed`) | the same sampler |
//! | `multijitter`, `orthogonal`, `ldsampler`, `low_discrepancy`, `sobol`, `halton`, `hammersley` | Owen-scrambled Sobol or stratified (warned) |
//! | `near_clip`, `far_clip`, `principal_point_offset_x/y` | not supported (warned) |
//! | `orthographic` and the other sensors | refused |

use glam::{DMat4, DVec3};
use sahara_readers::FormatError;
use sahara_render::{Camera, Filter, FrameLayer, Integrator, Pick, SamplerKind};

use super::builder::Builder;
use super::properties::Object;
use super::xml::Node;
use crate::description::{FileCrop, SettingsLayer};

/// A 35 mm film's diagonal, in mm (what `focal_length` refers to).
const FILM_DIAGONAL_MM: f64 = 43.266_615_300_557;

/// The film's size and crop.
struct Film {
    width: u32,
    height: u32,
    crop: Option<FileCrop>,
    filter: Filter,
}

/// The `<film>` of a sensor (Mitsuba's default without one: 768 x 576,
/// Gaussian filter).
fn film<'a>(b: &mut Builder<'a>, node: Option<&'a Node>) -> Result<Film, FormatError> {
    let gaussian = Filter::Gaussian {
        radius: 2.0,
        sigma: 0.5,
    };
    let Some(node) = node else {
        return Ok(Film {
            width: 768,
            height: 576,
            crop: None,
            filter: gaussian,
        });
    };
    let o = b.object(node)?;
    match o.ty {
        "hdrfilm" => {}
        "specfilm" | "ldrfilm" => b.w.add(
            format!("film '{}' is read as 'hdrfilm' (Sahara writes RGB)", o.ty),
            &node.loc,
        ),
        other => return Err(o.error(format!("unknown film type '{other}'"))),
    }
    let size = |name: &str, default: i64| -> Result<u32, FormatError> {
        let v = o.int(name, default)?;
        if !(1..=65536).contains(&v) {
            return Err(o.get(name).expect("given").error("must be in 1..=65536"));
        }
        Ok(v as u32)
    };
    let width = size("width", 768)?;
    let height = size("height", 576)?;
    let x0 = o.int("crop_offset_x", 0)?;
    let y0 = o.int("crop_offset_y", 0)?;
    let cw = o.int("crop_width", i64::from(width) - x0)?;
    let ch = o.int("crop_height", i64::from(height) - y0)?;
    let crop = if (x0, y0, cw, ch) == (0, 0, i64::from(width), i64::from(height)) {
        None
    } else {
        if x0 < 0
            || y0 < 0
            || cw < 1
            || ch < 1
            || x0 + cw > i64::from(width)
            || y0 + ch > i64::from(height)
        {
            return Err(o.error(format!(
                "the crop window ({x0}, {y0}) + {cw} x {ch} is not inside the {width} x {height} film"
            )));
        }
        Some(FileCrop::Pixels([x0, x0 + cw, y0, y0 + ch]))
    };
    for k in [
        "pixel_format",
        "component_format",
        "file_format",
        "banner",
        "high_quality_edges",
        "sample_border",
        "compensate",
        "rgb",
    ] {
        o.get(k);
    }
    let filter = match b.child_of(&o, "rfilter")? {
        None => gaussian,
        Some(f) => rfilter(b, f)?,
    };
    o.warn_unused(&mut b.w);
    Ok(Film {
        width,
        height,
        crop,
        filter,
    })
}

/// An `<rfilter>`.
fn rfilter<'a>(b: &mut Builder<'a>, node: &'a Node) -> Result<Filter, FormatError> {
    let o = b.object(node)?;
    let positive = |name: &str, v: f64| -> Result<f32, FormatError> {
        if v > 0.0 && v.is_finite() {
            Ok(v as f32)
        } else {
            Err(o.get(name).map_or_else(
                || o.error(format!("'{name}' must be > 0")),
                |p| p.error("must be > 0"),
            ))
        }
    };
    let f = match o.ty {
        "box" => Filter::Box {
            radius: positive("radius", o.float("radius", 0.5)?)?,
        },
        "tent" => Filter::Tent {
            radius: positive("radius", o.float("radius", 1.0)?)?,
        },
        "gaussian" => {
            let s = positive("stddev", o.float("stddev", 0.5)?)?;
            Filter::Gaussian {
                radius: 4.0 * s,
                sigma: s,
            }
        }
        "mitchell" | "catmullrom" => {
            let (db, dc) = if o.ty == "mitchell" {
                (1.0 / 3.0, 1.0 / 3.0)
            } else {
                (0.0, 0.5)
            };
            Filter::Mitchell {
                radius: positive("radius", o.float("radius", 2.0)?)?,
                b: o.float("B", db)? as f32,
                c: o.float("C", dc)? as f32,
            }
        }
        "lanczos" => {
            o.get("lobes");
            b.w.add("rfilter 'lanczos' is replaced by a Gaussian", &node.loc);
            Filter::Gaussian {
                radius: 2.0,
                sigma: 0.5,
            }
        }
        other => return Err(o.error(format!("unknown rfilter type '{other}'"))),
    };
    o.warn_unused(&mut b.w);
    Ok(f)
}

/// The `<sampler>`: kind, samples per pixel and seed (Mitsuba's default:
/// independent, 4 samples).
fn sampler<'a>(
    b: &mut Builder<'a>,
    node: Option<&'a Node>,
) -> Result<(SamplerKind, u32, u64), FormatError> {
    let Some(node) = node else {
        return Ok((SamplerKind::Independent, 4, 0));
    };
    let o = b.object(node)?;
    let kind = match o.ty {
        "independent" => SamplerKind::Independent,
        "stratified" => SamplerKind::Stratified,
        "multijitter" | "orthogonal" => {
            b.w.add(
                format!(
                    "sampler '{}' is replaced by Sahara's stratified sampler",
                    o.ty
                ),
                &node.loc,
            );
            SamplerKind::Stratified
        }
        "ldsampler" | "low_discrepancy" | "sobol" | "halton" | "hammersley" => {
            b.w.add(
                format!(
                    "sampler '{}' is replaced by Sahara's Owen-scrambled Sobol sampler",
                    o.ty
                ),
                &node.loc,
            );
            SamplerKind::Sobol
        }
        other => return Err(o.error(format!("unknown sampler type '{other}'"))),
    };
    let spp = o.int("sample_count", 4)?;
    if !(1..=1 << 24).contains(&spp) {
        return Err(o
            .get("sample_count")
            .expect("given")
            .error("must be in 1..=16777216"));
    }
    let seed = o.int("seed", 0)?.max(0) as u64;
    for k in ["jitter", "strength", "scramble", "dimension"] {
        o.get(k);
    }
    o.warn_unused(&mut b.w);
    Ok((kind, spp as u32, seed))
}

/// The horizontal field of view (degrees) of a camera of `aspect`.
fn x_fov(o: &Object, aspect: f64) -> Result<f64, FormatError> {
    let (fov, axis) = match o.float_opt("fov")? {
        Some(f) => {
            if o.has("focal_length") {
                return Err(o.error("give 'fov' or 'focal_length', not both"));
            }
            (f, o.string("fov_axis")?.unwrap_or("x"))
        }
        None => {
            let text = o.string("focal_length")?.unwrap_or("50mm");
            let mm = text
                .trim()
                .trim_end_matches("mm")
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|v| *v > 0.0)
                .ok_or_else(|| {
                    o.error(format!(
                        "focal_length '{text}': expected a length like 50mm"
                    ))
                })?;
            let axis = o.string("fov_axis")?;
            if axis.is_some() {
                // Mitsuba measures a focal length on the diagonal.
                o.get("fov_axis");
            }
            (
                2.0 * (FILM_DIAGONAL_MM / (2.0 * mm)).atan().to_degrees(),
                "diagonal",
            )
        }
    };
    if !(fov > 0.0 && fov < 180.0) {
        return Err(o.error(format!("fov {fov} must be in (0, 180)")));
    }
    let t = (fov.to_radians() * 0.5).tan();
    let from_y = |t: f64| 2.0 * (t * aspect).atan().to_degrees();
    Ok(match axis {
        "x" => fov,
        "y" => from_y(t),
        "diagonal" => {
            2.0 * (t / (1.0 + 1.0 / (aspect * aspect)).sqrt())
                .atan()
                .to_degrees()
        }
        "smaller" if aspect > 1.0 => from_y(t),
        "smaller" => fov,
        "larger" if aspect > 1.0 => fov,
        "larger" => from_y(t),
        other => {
            return Err(o.error(format!(
                "unknown fov_axis '{other}' (expected x, y, diagonal, smaller or larger)"
            )))
        }
    })
}

/// The camera of a sensor's `to_world` and fields of view.
fn camera(o: &Object, m: DMat4, x_fov: f64, aspect: f64) -> Result<Camera, FormatError> {
    let eye = m.transform_point3(DVec3::ZERO);
    let fwd = m.transform_vector3(DVec3::Z).normalize_or_zero();
    let right = -m.transform_vector3(DVec3::X);
    let up = m.transform_vector3(DVec3::Y);
    let right = (right - fwd * right.dot(fwd)).normalize_or_zero();
    let up = (up - fwd * up.dot(fwd) - right * up.dot(right)).normalize_or_zero();
    if fwd == DVec3::ZERO || right == DVec3::ZERO || up == DVec3::ZERO {
        return Err(o.error("the sensor's to_world is degenerate"));
    }
    let tan_y = (x_fov.to_radians() * 0.5).tan() / aspect;
    let vfov = 2.0 * tan_y.atan().to_degrees();
    let f = |v: DVec3| v.as_vec3();
    let mut c = Camera::look_at(f(eye), f(eye + fwd), f(up), vfov as f32, aspect as f32);
    c.right = f(right);
    c.up = f(up);
    c.forward = f(fwd);
    Ok(c)
}

/// The camera (none without a sensor: the assembly's automatic one) and
/// the render settings, with `integrator`.
pub(crate) fn sensor<'a>(
    b: &mut Builder<'a>,
    node: Option<&'a Node>,
    integrator: Integrator,
) -> Result<(Option<Camera>, SettingsLayer), FormatError> {
    let settings = |film: &Film, (sampler, spp, seed): (SamplerKind, u32, u64)| SettingsLayer {
        frame: FrameLayer {
            width: Some(film.width),
            height: Some(film.height),
            spp: Some(spp),
            seed: Some(seed),
            sampler: Some(sampler),
            filter: Some(Pick::Value(film.filter)),
            integrator: Some(Pick::Value(integrator)),
            ..Default::default()
        },
        crop_window: film.crop,
        ..Default::default()
    };
    let Some(node) = node else {
        let f = film(b, None)?;
        return Ok((None, settings(&f, sampler(b, None)?)));
    };
    let o = b.object(node)?;
    match o.ty {
        "perspective" | "thinlens" => {}
        "orthographic" | "telecentric" | "radiancemeter" | "irradiancemeter" | "distant"
        | "batch" | "spherical" => {
            return Err(o.error(format!(
                "sensor '{}' is not supported (Sahara has perspective cameras only)",
                o.ty
            )))
        }
        other => return Err(o.error(format!("unknown sensor type '{other}'"))),
    }
    let films = b.child_of(&o, "film")?;
    let f = film(b, films)?;
    let samplers = b.child_of(&o, "sampler")?;
    let s = sampler(b, samplers)?;
    let aspect = f64::from(f.width) / f64::from(f.height);
    let m = o.transform("to_world")?;
    let mut c = camera(&o, m, x_fov(&o, aspect)?, aspect)?;
    if o.ty == "thinlens" {
        let Some(r) = o.float_opt("aperture_radius")? else {
            return Err(o.error("sensor 'thinlens' needs 'aperture_radius'"));
        };
        let d = o.float("focus_distance", 10000.0)?;
        if r < 0.0 || d <= 0.0 {
            return Err(o.error("thinlens: aperture_radius must be >= 0 and focus_distance > 0"));
        }
        c = c.with_thin_lens(r as f32, d as f32);
    } else {
        // A pinhole's focus distance changes nothing (Mitsuba's own
        // scenes give one).
        o.get("focus_distance");
    }
    if o.has("shutter_open") || o.has("shutter_close") {
        let open = o.float("shutter_open", 0.0)?;
        let close = o.float("shutter_close", open)?;
        c = c.with_shutter(open as f32, close as f32);
    }
    let clip = ["near_clip", "far_clip"]
        .into_iter()
        .filter(|k| o.get(k).is_some())
        .count();
    if clip > 0 {
        b.w.add(
            "sensor 'near_clip' / 'far_clip' are not supported (Sahara does not clip); ignored",
            &node.loc,
        );
    }
    for k in ["principal_point_offset_x", "principal_point_offset_y"] {
        if o.float(k, 0.0)? != 0.0 {
            b.w.add(
                format!("sensor '{k}' is not supported; the image is centred"),
                &node.loc,
            );
        }
    }
    o.get("srf");
    b.sensor_medium(&o)?;
    o.warn_unused(&mut b.w);
    Ok((Some(c), settings(&f, s)))
}
