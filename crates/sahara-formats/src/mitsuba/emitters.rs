//! Mitsuba emitters as Sahara lights.
//!
//! | Mitsuba | Sahara |
//! |---|---|
//! | `area` in a shape (`radiance`, a colour or texture) | the shape's material emitting from its front |
//! | `point` (`intensity`, `position` or `to_world`) | point light |
//! | `spot` (`intensity`, `cutoff_angle`, `beam_width`, `to_world`: it shines along `+z`) | spot light, full inside `beam_width`, dark beyond `cutoff_angle` (Sahara's smoothstep in between, warned) |
//! | `directional` (`irradiance`, `direction` or `to_world`'s `+z`) | directional light |
//! | `constant` (`radiance`) | constant environment |
//! | `envmap` (`filename`, `scale`, `to_world`) | the lat-long map moved onto Sahara's layout, each texel what Mitsuba's bilinear lookup gives in its direction |
//! | `sunsky`, `sky`, `sun`, `projector` | skipped (warned) |
//! | `sampling_weight` (any emitter) | checked, not used: Sahara picks lights by power |

use std::sync::Arc;

use glam::{DMat3, DVec3, Vec2, Vec3};
use sahara_readers::FormatError;
use sahara_render::{environment_direction, Environment, Light, Texture};

use super::builder::Builder;
use super::properties::Object;
use super::spectra::Usage;
use super::xml::Node;
use crate::common::image::load_rgb_f32;

/// Mitsuba's lat-long coordinates of a direction in the map's own frame.
fn mitsuba_uv(d: DVec3) -> (f64, f64) {
    let mut u = d.x.atan2(-d.z) / std::f64::consts::TAU;
    if u < 0.0 {
        u += 1.0;
    }
    (u, d.y.clamp(-1.0, 1.0).acos() / std::f64::consts::PI)
}

/// Mitsuba's map `img` (row 0 up), whose frame's axes in world space are
/// the columns of `to_world`, on Sahara's lat-long layout; true if every
/// texel landed on a column of the map (the transform turns the map by a
/// whole number of columns about its axis).
///
/// Each texel of Sahara's layout takes the radiance Mitsuba looks up in
/// the texel's centre direction: bilinear between the map's texels, whose
/// columns are centred at u = (i + 1/2) / W (wrapping around) and whose
/// rows lie at v = j / (H - 1), the first on the upward pole and the last
/// on the downward one (Mitsuba's `envmap`, measured), where Sahara's rows
/// are centred at (j + 1/2) / H.
fn to_sahara(img: &Texture, to_world: DMat3) -> (Texture, bool) {
    let inv = to_world.inverse();
    let (w, h) = (img.width, img.height);
    let mut exact = true;
    let mut texels = Vec::with_capacity(w as usize * h as usize);
    let texel =
        |x: i64, y: i64| img.texel(x.rem_euclid(i64::from(w)), y.clamp(0, i64::from(h) - 1));
    for y in 0..h {
        for x in 0..w {
            let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            let (d, _) = environment_direction(uv);
            let (u, v) = mitsuba_uv((inv * d.as_dvec3()).normalize_or_zero());
            let sx = u * f64::from(w) - 0.5;
            let sy = v * f64::from(h.max(2) - 1);
            exact &= (sx - sx.round()).abs() < 1e-3;
            // On a texel (to rounding), that texel alone.
            let snap = |s: f64| {
                if (s - s.round()).abs() < 1e-4 {
                    s.round()
                } else {
                    s
                }
            };
            let (sx, sy) = (snap(sx), snap(sy));
            let (x0, y0) = (sx.floor(), sy.floor());
            let (fx, fy) = ((sx - x0) as f32, (sy - y0) as f32);
            let (x0, y0) = (x0 as i64, y0 as i64);
            let top = texel(x0, y0) * (1.0 - fx) + texel(x0 + 1, y0) * fx;
            let bottom = texel(x0, y0 + 1) * (1.0 - fx) + texel(x0 + 1, y0 + 1) * fx;
            texels.push(top * (1.0 - fy) + bottom * fy);
        }
    }
    (Texture::new(w, h, texels), exact)
}

/// Reads an emitter's `sampling_weight`, which every Mitsuba emitter takes:
/// how often Mitsuba picks it for light sampling. Sahara picks its lights
/// by their power; the choice changes the noise, not the image, so the
/// weight is checked and not used.
fn sampling_weight(o: &Object) -> Result<(), FormatError> {
    match o.float_opt("sampling_weight")? {
        Some(w) if !(w.is_finite() && w >= 0.0) => {
            Err(o.error("'sampling_weight' must be a finite number >= 0"))
        }
        _ => Ok(()),
    }
}

impl<'a> Builder<'a> {
    /// `material` emitting as the area emitter `node` says.
    pub(crate) fn area_light(&mut self, material: u32, node: &'a Node) -> Result<u32, FormatError> {
        let o = self.object(node)?;
        if o.ty != "area" {
            return Err(o.error(format!(
                "an emitter of type '{}' cannot be attached to a shape (only 'area')",
                o.ty
            )));
        }
        let radiance = self.tint(&o, "radiance", Vec3::ONE, Usage::Emission)?;
        sampling_weight(&o)?;
        o.warn_unused(&mut self.w);
        let mut m = self.scene.materials[material as usize]
            .clone()
            .with_emission(radiance.color);
        m.textures.emission = radiance.image_map();
        m.two_sided_emission = false;
        Ok(self.scene.add_material(m))
    }

    /// An `<emitter>` directly in the scene.
    pub(crate) fn emitter(&mut self, node: &'a Node) -> Result<(), FormatError> {
        let o = self.object(node)?;
        let m = o.transform("to_world")?;
        sampling_weight(&o)?;
        let color = |b: &mut Self, o: &Object<'a>, name: &str| -> Result<Vec3, FormatError> {
            let t = b.tint(o, name, Vec3::ONE, Usage::Emission)?;
            if t.image.is_some() {
                b.w.add(
                    format!(
                        "{}: a texture for '{name}' is replaced by its mean",
                        o.what()
                    ),
                    &o.node.loc,
                );
            }
            Ok(t.mean())
        };
        match o.ty {
            "point" => {
                let i = color(self, &o, "intensity")?;
                let p = match o.vector("position")? {
                    Some(p) => m.transform_point3(p),
                    None => m.transform_point3(DVec3::ZERO),
                };
                self.scene.lights.push(Light::point(p.as_vec3(), i));
            }
            "spot" => {
                let i = color(self, &o, "intensity")?;
                let cutoff = o.float("cutoff_angle", 20.0)?;
                let beam = o.float("beam_width", cutoff * 0.75)?;
                if !(cutoff > 0.0 && cutoff <= 180.0) {
                    return Err(o.error("spot: 'cutoff_angle' must be in (0, 180]"));
                }
                if o.named("texture").is_some() {
                    self.w.add(
                        "spot: a projected 'texture' is not supported; ignored",
                        &node.loc,
                    );
                }
                self.w.add(
                    "spot: Mitsuba's falloff, linear in angle, becomes Sahara's smoothstep in cosine",
                    &node.loc,
                );
                let p = m.transform_point3(DVec3::ZERO);
                let dir = m.transform_vector3(DVec3::Z);
                if dir.length_squared() == 0.0 {
                    return Err(o.error("spot: the transform is singular"));
                }
                self.scene.lights.push(Light::spot(
                    p.as_vec3(),
                    (p + dir.normalize()).as_vec3(),
                    i,
                    beam.clamp(0.0, cutoff) as f32,
                    cutoff as f32,
                ));
            }
            "directional" => {
                let e = color(self, &o, "irradiance")?;
                let d = match o.vector("direction")? {
                    Some(d) => m.transform_vector3(d),
                    None => m.transform_vector3(DVec3::Z),
                };
                if d.length_squared() == 0.0 {
                    return Err(o.error("directional: the direction is zero"));
                }
                self.scene.lights.push(Light::directional(d.as_vec3(), e));
            }
            "constant" => {
                let l = color(self, &o, "radiance")?;
                self.set_environment(node, Environment::Constant(l));
            }
            "envmap" => {
                let Some(path) = o.file("filename", &self.main)? else {
                    return Err(o.error("envmap needs a 'filename' string"));
                };
                let scale = o.float("scale", 1.0)? as f32;
                o.get("filter_type");
                let (w, h, rgb) = load_rgb_f32(&path).map_err(|e| o.error(e))?;
                if w == 0 || h == 0 {
                    return Err(
                        o.error(format!("{}: the environment map is empty", path.display()))
                    );
                }
                let texels = rgb.chunks_exact(3).map(Vec3::from_slice).collect();
                let img = Texture::new(w, h, texels);
                let rot = DMat3::from_mat4(m);
                if rot.determinant().abs() < 1e-12 {
                    return Err(o.error("envmap: the transform is singular"));
                }
                let (map, exact) = to_sahara(&img, rot);
                if !exact {
                    self.w.add(
                        "envmap: the transform turns the map by part of a texel; resampled (bilinear)",
                        &node.loc,
                    );
                }
                self.set_environment(
                    node,
                    Environment::Map {
                        texture: Arc::new(map),
                        scale,
                    },
                );
            }
            "area" => return Err(o.error("an 'area' emitter belongs inside a <shape>")),
            "sunsky" | "sky" | "sun" | "projector" => {
                self.w.add(
                    format!("emitter '{}' is not supported; skipped", o.ty),
                    &node.loc,
                );
                o.mark_all_used();
            }
            other => return Err(o.error(format!("unknown emitter type '{other}'"))),
        }
        o.warn_unused(&mut self.w);
        Ok(())
    }

    /// Sets the environment (the last of several, warned).
    fn set_environment(&mut self, node: &Node, env: Environment) {
        if self.scene.environment.is_some() {
            self.w.add(
                "more than one environment emitter: the last one is used",
                &node.loc,
            );
        }
        self.scene.environment = Some(env);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mitsubas_map_is_a_quarter_turn_from_saharas() {
        // Mitsuba's u = 0 looks down -z, u = 1/4 down +x; v = 0 is +y.
        let (u, v) = mitsuba_uv(DVec3::new(0.0, 0.0, -1.0));
        assert!(u.abs() < 1e-12 && (v - 0.5).abs() < 1e-12);
        let (u, _) = mitsuba_uv(DVec3::X);
        assert!((u - 0.25).abs() < 1e-12);
        assert!(mitsuba_uv(DVec3::Y).1.abs() < 1e-12);
        // An 8 x 4 map with one bright column lands, exactly, a quarter
        // of the width to the left.
        let mut t = vec![Vec3::ZERO; 32];
        for y in 0..4 {
            t[y * 8 + 2] = Vec3::ONE;
        }
        let (out, exact) = to_sahara(&Texture::new(8, 4, t), DMat3::IDENTITY);
        assert!(exact);
        for y in 0..4 {
            for x in 0..8 {
                let want = if x == 0 { Vec3::ONE } else { Vec3::ZERO };
                assert_eq!(out.texel(x, y), want, "({x}, {y})");
            }
        }
    }

    #[test]
    fn mitsubas_rows_lie_from_pole_to_pole() {
        // Mitsuba 3.9.1's envmap, a map whose row j has value j, looked
        // up at v = 1/16 (8 rows): 0.4375 = v (H - 1). Sahara's row y is
        // centred at v = (y + 1/2) / H.
        let (w, h) = (16u32, 8u32);
        let t = (0..w * h).map(|k| Vec3::splat((k / w) as f32)).collect();
        let (out, exact) = to_sahara(&Texture::new(w, h, t), DMat3::IDENTITY);
        assert!(exact);
        for y in 0..h {
            let want = (y as f32 + 0.5) / h as f32 * (h - 1) as f32;
            for x in 0..w {
                assert!(
                    (out.texel(i64::from(x), i64::from(y)).x - want).abs() < 1e-4,
                    "({x}, {y})"
                );
            }
        }
        // A column's value between two columns is their mean.
        let t = (0..w * h).map(|k| Vec3::splat((k % w) as f32)).collect();
        let turn = DMat3::from_rotation_y(std::f64::consts::TAU / 32.0);
        let (out, exact) = to_sahara(&Texture::new(w, h, t), turn);
        assert!(!exact);
        let row: Vec<f32> = (0..w).map(|x| out.texel(i64::from(x), 3).x).collect();
        assert!(
            row.iter().all(|v| (v.fract() - 0.5).abs() < 1e-3),
            "{row:?}"
        );
    }
}
