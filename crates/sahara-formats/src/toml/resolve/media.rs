//! `[[medium]]` tables, and the keys of objects and the camera that name
//! media.

use std::collections::HashMap;

use glam::{Affine3A, Quat, Vec3};
use sahara_render::{
    ColourGrid, ColourVolume, DensityGrid, GridCoefficients, GridMedium, HenyeyGreenstein, Medium,
    MediumInterface,
};
use toml::Spanned;

use super::{span, Ctx};
use crate::toml::file::MediumSpec;
use crate::toml::raw::{MediumType, Opt, RawMedium, RawObject};
use sahara_readers::FormatError;

/// The keys every kind of medium takes.
const EVERY_MEDIUM: [&str; 6] = [
    "sigma_a",
    "sigma_s",
    "scale",
    "g",
    "emission",
    "emission_scale",
];

/// A grid medium's density: one value per voxel, or one per colour
/// channel.
enum Density {
    One(DensityGrid),
    Colour(ColourGrid),
}

impl Ctx<'_> {
    /// `[[medium]]`: a homogeneous medium, or a density grid read from a
    /// Mitsuba `.vol` file or a grid of an OpenVDB `.vdb` file, over a box
    /// (the file's own unless `min` and `max` say); either may emit
    /// (`emission` times `emission_scale`, per unit of absorption).
    pub(super) fn medium(&self, raw: &Spanned<RawMedium>) -> Result<MediumSpec, FormatError> {
        let m = raw.get_ref();
        let what = format!("a {} medium", type_name(*m.kind.get_ref()));
        let present = [
            ("sigma_a", span(&m.sigma_a)),
            ("sigma_s", span(&m.sigma_s)),
            ("scale", span(&m.scale)),
            ("g", span(&m.g)),
            ("emission", span(&m.emission)),
            ("emission_scale", span(&m.emission_scale)),
            ("file", span(&m.file)),
            ("grid", span(&m.grid)),
            ("min", span(&m.min)),
            ("max", span(&m.max)),
        ];
        let coefficient = |value: &Opt<[f32; 3]>, key: &str| -> Result<Vec3, FormatError> {
            match value {
                Some(v) => self.power(v, key),
                None => Ok(Vec3::ZERO),
            }
        };
        let scale = self.number(&m.scale, "scale", 1.0, |s| s >= 0.0, "at least 0")?;
        let sigma_a = coefficient(&m.sigma_a, "sigma_a")? * scale;
        let sigma_s = coefficient(&m.sigma_s, "sigma_s")? * scale;
        let g = self.number(
            &m.g,
            "g",
            0.0,
            |g| g > -1.0 && g < 1.0,
            "between -1 and 1 (exclusive)",
        )?;
        let phase = HenyeyGreenstein::new(g);
        let emission_scale = self.number(
            &m.emission_scale,
            "emission_scale",
            1.0,
            |s| s >= 0.0,
            "at least 0",
        )?;
        let emission = coefficient(&m.emission, "emission")? * emission_scale;
        let medium = match m.kind.get_ref() {
            MediumType::Homogeneous => {
                self.only(&present, &EVERY_MEDIUM, &what)?;
                Medium::Homogeneous(sahara_render::Homogeneous {
                    sigma_a,
                    sigma_s,
                    phase,
                    emission,
                })
            }
            MediumType::Grid => {
                let keys = [&EVERY_MEDIUM[..], &["file", "grid", "min", "max"]].concat();
                self.only(&present, &keys, &what)?;
                let (density, to_world) = self.density_grid(raw, &what)?;
                let medium = match density {
                    Density::One(density) => {
                        GridMedium::new(density, sigma_a, sigma_s, phase, to_world)
                    }
                    Density::Colour(colours) => {
                        // Each channel's density scales that channel's
                        // coefficients.
                        let coefficients = GridCoefficients::absorption_scattering(
                            ColourVolume::Grid(colours.clone().tinted(sigma_a)),
                            ColourVolume::Grid(colours.tinted(sigma_s)),
                            1.0,
                        );
                        GridMedium::with_coefficients(coefficients, phase, to_world)
                    }
                };
                Medium::Grid(Box::new(medium)).with_emission(emission)
            }
        };
        Ok(MediumSpec {
            name: m.name.get_ref().clone(),
            medium,
        })
    }

    /// A `grid` medium's density and the map from the unit cube to the
    /// world: the `.vol`, `.vdb` or `.nvdb` file's grid over its own box, or over
    /// `min` to `max`; a `.vol` file of three channels is a density per
    /// channel.
    fn density_grid(
        &self,
        raw: &Spanned<RawMedium>,
        what: &str,
    ) -> Result<(Density, Affine3A), FormatError> {
        let m = raw.get_ref();
        let file = self.required(&m.file, "file", &raw.span(), what)?;
        let path = self.file(file, "density grid")?;
        let extension = |x: &str| path.extension().is_some_and(|e| e.eq_ignore_ascii_case(x));
        let (is_vdb, is_nanovdb) = (extension("vdb"), extension("nvdb"));
        if let (false, false, Some(g)) = (is_vdb, is_nanovdb, &m.grid) {
            return Err(self.at(
                g.span(),
                "'grid' names a grid of a .vdb or .nvdb file; a .vol file holds one",
            ));
        }
        // The grid's values, size, and the box the file places it in.
        let (size, values, file_box, channels) = if is_vdb || is_nanovdb {
            let name = m.grid.as_ref().map_or("density", |g| g.get_ref().as_str());
            let grid = if is_vdb {
                sahara_readers::vdb::read_vdb(&path, name)?
            } else {
                sahara_readers::nanovdb::read_nanovdb(&path, name)?
            };
            let to_world = grid.to_world();
            (grid.size, grid.values, to_world, 1)
        } else {
            let grid = sahara_readers::vol::read_vol(&path)?;
            if grid.channels != 1 && grid.channels != 3 {
                return Err(self.at(
                    file.span(),
                    format!(
                        "'{}' holds {} channels; a density grid holds 1 (or 3: one per colour channel)",
                        file.get_ref(),
                        grid.channels
                    ),
                ));
            }
            let lo = Vec3::from_array(grid.bounds_min);
            let hi = Vec3::from_array(grid.bounds_max);
            let to_world = Affine3A::from_scale_rotation_translation(hi - lo, Quat::IDENTITY, lo);
            (grid.size, grid.values, to_world, grid.channels)
        };
        let to_world = if m.min.is_some() || m.max.is_some() {
            let lo = self.vec_or(&m.min, "min", file_box.transform_point3(Vec3::ZERO))?;
            let hi = self.vec_or(&m.max, "max", file_box.transform_point3(Vec3::ONE))?;
            if (hi - lo).min_element() <= 0.0 {
                return Err(self.at(
                    span(&m.max).or(span(&m.min)).unwrap_or(file.span()),
                    format!("the grid's box {lo} to {hi} must be above its min on every axis"),
                ));
            }
            Affine3A::from_scale_rotation_translation(hi - lo, Quat::IDENTITY, lo)
        } else {
            file_box
        };
        let in_file = |e| FormatError::in_file(&path.display().to_string(), e);
        let density = if channels == 3 {
            let colours: Vec<Vec3> = values.chunks_exact(3).map(Vec3::from_slice).collect();
            Density::Colour(ColourGrid::new(size, colours).map_err(in_file)?)
        } else {
            Density::One(DensityGrid::new(size, values).map_err(in_file)?)
        };
        Ok((density, to_world))
    }

    /// The index of the medium a key names (`None` if the key is absent).
    pub(super) fn medium_named(
        &self,
        value: &Opt<String>,
        media: &HashMap<String, u32>,
    ) -> Result<Option<u32>, FormatError> {
        let Some(v) = value else {
            return Ok(None);
        };
        media.get(v.get_ref()).copied().map(Some).ok_or_else(|| {
            self.at(
                v.span(),
                format!("no [[medium]] is named '{}'", v.get_ref()),
            )
        })
    }

    /// The media an object bounds: `medium_inside` and `medium_outside`;
    /// an object with either and no material only bounds them (light
    /// passes its surface unbent).
    pub(super) fn object_media(
        &self,
        o: &RawObject,
        media: &HashMap<String, u32>,
    ) -> Result<Option<MediumInterface>, FormatError> {
        if o.medium_inside.is_none() && o.medium_outside.is_none() {
            return Ok(None);
        }
        Ok(Some(MediumInterface {
            inside: self.medium_named(&o.medium_inside, media)?,
            outside: self.medium_named(&o.medium_outside, media)?,
            index_matched: o.material.is_none(),
        }))
    }
}

/// The name a `type` is written with.
fn type_name(t: MediumType) -> &'static str {
    match t {
        MediumType::Homogeneous => "homogeneous",
        MediumType::Grid => "grid",
    }
}
