//! Mitsuba's participating media: `<medium>` (`homogeneous`,
//! `heterogeneous` with a `gridvolume` or `constvolume`), its `<phase>`,
//! the media a shape names `interior` and `exterior`, and the sensor's.
//!
//! Mitsuba gives a medium its extinction `sigma_t` and its single-
//! scattering `albedo`, both times `scale`: Sahara's scattering is
//! `albedo sigma_t` and its absorption `(1 - albedo) sigma_t`. A
//! `gridvolume` is a grid over the unit cube placed by its `to_world` (or
//! over the box its file gives, with `use_grid_bbox`). A one-channel
//! `sigma_t` grid under a constant albedo is a density scaling fixed
//! coefficients; a three-channel `sigma_t` grid or an `albedo` grid (one
//! or three channels) gives the medium colours per voxel, each channel
//! interpolated on its own, as Mitsuba's RGB variants do.

use glam::{Affine3A, DMat4, DVec3, Vec3};
use sahara_readers::vol::VolGrid;
use sahara_readers::FormatError;
use sahara_render::{
    ColourGrid, ColourVolume, DensityGrid, GridCoefficients, GridMedium, HenyeyGreenstein, Medium,
    MediumInterface,
};

use super::builder::{key, Builder};
use super::properties::{Child, Object};
use super::spectra::Usage;
use super::xml::Node;

/// A medium's `sigma_t` or `albedo`: a constant, or a grid (one channel
/// or three) and the grid's box in the world.
enum Quantity {
    Constant(Vec3),
    Grid(VolGrid, Affine3A),
}

/// The grid's values, a colour per voxel (one channel repeated in all
/// three), or why not.
fn colours(grid: VolGrid) -> Result<ColourGrid, String> {
    if grid.channels == 1 {
        return DensityGrid::new(grid.size, grid.values).map(ColourGrid::grey);
    }
    let values: Vec<Vec3> = grid.values.chunks_exact(3).map(Vec3::from_slice).collect();
    ColourGrid::new(grid.size, values)
}

impl<'a> Builder<'a> {
    /// The index of the medium `node` describes in
    /// [`crate::description::SceneDescription::media`], made on first use.
    pub(crate) fn medium(&mut self, node: &'a Node) -> Result<u32, FormatError> {
        if let Some(&i) = self.media.get(&key(node)) {
            return Ok(i);
        }
        let o = self.object(node)?;
        if !matches!(o.ty, "homogeneous" | "heterogeneous") {
            return Err(o.error(format!(
                "medium type '{}' is not supported (homogeneous and heterogeneous are)",
                o.ty
            )));
        }
        let sigma_t = self.quantity(&o, "sigma_t", 1.0, Usage::Index)?;
        let albedo = self.quantity(&o, "albedo", 0.75, Usage::Reflectance)?;
        let scale = o.float("scale", 1.0)? as f32;
        if !(scale.is_finite() && scale >= 0.0) {
            return Err(o.error(format!("'scale' {scale} must be finite and not negative")));
        }
        if let Quantity::Constant(albedo) = albedo {
            if albedo.min_element() < 0.0 || albedo.max_element() > 1.0 {
                return Err(o.error(format!("'albedo' {albedo} must lie in [0, 1]")));
            }
        }
        o.get("sample_emitters");
        let g = self.phase(&o)?;
        let medium = match (sigma_t, albedo) {
            (Quantity::Constant(st), Quantity::Constant(albedo)) => {
                let st = st * scale;
                let sigma_s = albedo * st;
                Medium::homogeneous((st - sigma_s).max(Vec3::ZERO), sigma_s, g)
            }
            (Quantity::Grid(grid, to_world), Quantity::Constant(albedo)) if grid.channels == 1 => {
                let density = DensityGrid::new(grid.size, grid.values).map_err(|m| o.error(m))?;
                Medium::Grid(Box::new(GridMedium::new(
                    density,
                    (Vec3::ONE - albedo) * scale,
                    albedo * scale,
                    HenyeyGreenstein::new(g),
                    to_world,
                )))
            }
            (Quantity::Constant(_), Quantity::Grid(..)) => {
                return Err(o.error(
                    "an albedo grid under a constant 'sigma_t' is not supported; \
                     give 'sigma_t' as a gridvolume over the same box",
                ))
            }
            (Quantity::Grid(st, to_world), albedo) => {
                let albedo = match albedo {
                    Quantity::Constant(a) => ColourVolume::Constant(a),
                    Quantity::Grid(a, box_) => {
                        if !box_.abs_diff_eq(to_world, 1e-6) {
                            return Err(o.error(
                                "the 'albedo' grid and the 'sigma_t' grid must span the same box",
                            ));
                        }
                        ColourVolume::Grid(colours(a).map_err(|m| o.error(format!("albedo {m}")))?)
                    }
                };
                let sigma_t = ColourVolume::Grid(colours(st).map_err(|m| o.error(m))?);
                Medium::Grid(Box::new(GridMedium::with_coefficients(
                    GridCoefficients::extinction_albedo(sigma_t, albedo, scale),
                    HenyeyGreenstein::new(g),
                    to_world,
                )))
            }
        };
        if let Some(problem) = medium.problem() {
            return Err(o.error(problem));
        }
        o.warn_unused(&mut self.w);
        self.scene.media.push(medium);
        let i = self.scene.media.len() as u32 - 1;
        self.media.insert(key(node), i);
        Ok(i)
    }

    /// The asymmetry of the medium's `<phase>`: `isotropic` (the default)
    /// 0, `hg` its `g` (default 0.8, as in Mitsuba); other phase functions
    /// are rendered isotropic, warned.
    fn phase(&mut self, o: &Object<'a>) -> Result<f32, FormatError> {
        let Some(node) = self.child_of(o, "phase")? else {
            return Ok(0.0);
        };
        let p = self.object(node)?;
        let g = match p.ty {
            "isotropic" => 0.0,
            "hg" => p.float("g", 0.8)? as f32,
            other => {
                self.w.add(
                    format!("phase function '{other}' is rendered isotropic"),
                    &node.loc,
                );
                p.mark_all_used();
                0.0
            }
        };
        p.warn_unused(&mut self.w);
        Ok(g)
    }

    /// A medium's quantity `name`: a colour or float property, a nested
    /// `constvolume` or `gridvolume`, or `default`.
    fn quantity(
        &mut self,
        o: &Object<'a>,
        name: &str,
        default: f64,
        usage: Usage,
    ) -> Result<Quantity, FormatError> {
        if let Some(c) = o.color(name)? {
            return Ok(Quantity::Constant(c.rgb(usage)));
        }
        let Some(e) = o.named(name) else {
            return Ok(Quantity::Constant(Vec3::splat(default as f32)));
        };
        let node = self.resolve(e.child, &["volume"], "a <volume>")?;
        let v = self.object(node)?;
        let q = match v.ty {
            "constvolume" => {
                Quantity::Constant(v.color("value")?.map_or(Vec3::ONE, |c| c.rgb(usage)))
            }
            "gridvolume" => {
                let Some(path) = v.file("filename", &self.main)? else {
                    return Err(v.error("gridvolume needs 'filename'"));
                };
                let grid = sahara_readers::vol::read_vol(&path)?;
                if grid.channels != 1 && grid.channels != 3 {
                    return Err(v.error(format!(
                        "'{}' holds {} channels; a medium's {name} grid must hold 1 or 3",
                        path.display(),
                        grid.channels
                    )));
                }
                let to_world = v.transform("to_world")?;
                let box_ = if v.bool("use_grid_bbox", false)? {
                    let lo = DVec3::from_array(grid.bounds_min.map(f64::from));
                    let hi = DVec3::from_array(grid.bounds_max.map(f64::from));
                    if (hi - lo).min_element() <= 0.0 {
                        return Err(v.error(format!(
                            "'{}': its box {lo} to {hi} is empty",
                            path.display()
                        )));
                    }
                    DMat4::from_translation(lo) * DMat4::from_scale(hi - lo)
                } else {
                    DMat4::IDENTITY
                };
                match v.string("filter_type")? {
                    None | Some("trilinear") => {}
                    Some(f) => self.w.add(
                        format!("gridvolume filter_type '{f}' is rendered trilinear"),
                        &node.loc,
                    ),
                }
                for k in ["wrap_mode", "raw", "accel"] {
                    v.get(k);
                }
                if let Some((i, x)) = grid
                    .values
                    .iter()
                    .enumerate()
                    .find(|(_, x)| !x.is_finite() || **x < 0.0)
                {
                    return Err(v.error(format!(
                        "'{}': value {i} is {x}; a medium's {name} must be finite and not negative",
                        path.display()
                    )));
                }
                Quantity::Grid(grid, Affine3A::from_mat4((to_world * box_).as_mat4()))
            }
            other => {
                return Err(v.error(format!(
                    "volume type '{other}' is not supported (constvolume and gridvolume are)"
                )))
            }
        };
        v.warn_unused(&mut self.w);
        Ok(q)
    }

    /// The media of shape `o` (its nested or referenced `<medium>`s named
    /// `interior` and `exterior`), if it names any: index-matched (light
    /// passes unbent) when the shape has no bsdf or a `null` one, as
    /// Mitsuba makes such a shape's surface.
    pub(crate) fn shape_media(
        &mut self,
        o: &Object<'a>,
    ) -> Result<Option<MediumInterface>, FormatError> {
        let mut mi = MediumInterface::default();
        let mut any = false;
        let mut bsdf = None;
        for e in o.entries() {
            let tag = e.child.node().tag.as_str();
            if !["ref", "medium", "bsdf"].contains(&tag) {
                continue;
            }
            let node = match e.child {
                Child::Node(n) => n,
                Child::Ref(_) => {
                    self.resolve(e.child, super::properties::OBJECT_TAGS, "an object")?
                }
            };
            match node.tag.as_str() {
                "bsdf" => bsdf = Some(node),
                "medium" => {
                    let i = self.medium(node)?;
                    match e.name {
                        Some("interior") => mi.inside = Some(i),
                        Some("exterior") => mi.outside = Some(i),
                        other => {
                            return Err(e.child.node().error(format!(
                                "a shape's medium is named 'interior' or 'exterior', not {}",
                                other.map_or("nothing".to_owned(), |n| format!("'{n}'"))
                            )))
                        }
                    }
                    e.take();
                    any = true;
                }
                _ => {}
            }
        }
        if !any {
            return Ok(None);
        }
        mi.index_matched = bsdf.is_none_or(|b| b.attr("type") == Some("null"));
        Ok(Some(mi))
    }

    /// The medium the sensor `o` sits in, if it names one.
    pub(crate) fn sensor_medium(&mut self, o: &Object<'a>) -> Result<(), FormatError> {
        if let Some(node) = self.child_of(o, "medium")? {
            self.scene.camera_medium = Some(self.medium(node)?);
        }
        Ok(())
    }
}
