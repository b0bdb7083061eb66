//! Wavefront MTL materials as plain values.
//!
//! Only what a renderer uses is kept: `Kd Ks Ns Ke Ni d illum map_Kd`. A
//! material that leaves a value out gets the default of
//! [`MtlMaterial::default_material`]. Texture paths are resolved relative to
//! the folder of the `.mtl` file that names them.

use std::path::{Path, PathBuf};

/// One `newmtl` block of an MTL file.
#[derive(Clone, Debug, PartialEq)]
pub struct MtlMaterial {
    /// The name given after `newmtl`.
    pub name: String,
    /// Diffuse reflectance `Kd`.
    pub kd: [f32; 3],
    /// Specular reflectance `Ks`.
    pub ks: [f32; 3],
    /// Specular exponent `Ns`.
    pub ns: f32,
    /// Emitted radiance `Ke`.
    pub ke: [f32; 3],
    /// Index of refraction `Ni`.
    pub ni: f32,
    /// Opacity `d` (1: opaque).
    pub d: f32,
    /// Illumination model `illum`.
    pub illum: u32,
    /// Diffuse texture `map_Kd`, resolved relative to the `.mtl` file (only set if the file exists).
    pub map_kd: Option<PathBuf>,
}

/// Name of the material used for faces without a (known) material.
pub const DEFAULT_MATERIAL_NAME: &str = "default";

impl MtlMaterial {
    /// The fallback: `Kd 0.8 0.8 0.8`, black `Ks`/`Ke`, `Ns 0`, `Ni 1`, `d 1`, `illum 2`, no texture.
    pub fn default_material() -> MtlMaterial {
        MtlMaterial {
            name: DEFAULT_MATERIAL_NAME.to_owned(),
            kd: [0.8; 3],
            ks: [0.0; 3],
            ns: 0.0,
            ke: [0.0; 3],
            ni: 1.0,
            d: 1.0,
            illum: 2,
            map_kd: None,
        }
    }

    /// Converts tobj's material read from the MTL file `mtl_path`; missing textures add to `warnings`.
    pub(crate) fn from_tobj(
        m: &tobj::Material,
        mtl_path: &Path,
        warnings: &mut Vec<String>,
    ) -> MtlMaterial {
        let d = MtlMaterial::default_material();
        let map_kd = m.diffuse_texture.as_deref().and_then(|spec| {
            let found = resolve_texture(mtl_path, spec);
            if found.is_none() {
                warnings.push(format!(
                    "{}: material '{}': texture map_Kd '{}' not found; the material is untextured",
                    mtl_path.display(),
                    m.name,
                    spec
                ));
            }
            found
        });
        MtlMaterial {
            name: m.name.clone(),
            kd: m.diffuse.unwrap_or(d.kd),
            ks: m.specular.unwrap_or(d.ks),
            ns: m.shininess.unwrap_or(d.ns),
            ke: m.emissive.unwrap_or(d.ke),
            ni: m.optical_density.unwrap_or(d.ni),
            d: m.dissolve.unwrap_or(d.d),
            illum: m.illumination_model.map_or(d.illum, u32::from),
            map_kd,
        }
    }
}

/// The texture file named by a `map_Kd` statement's arguments, if it exists.
///
/// Options (`-s 1 1 1 file.png`) are skipped by taking the last word; a name
/// without options may contain spaces. Backslashes (Windows exports) are
/// tried as `/` when the name as written is not found.
fn resolve_texture(mtl_path: &Path, spec: &str) -> Option<PathBuf> {
    let spec = spec.trim();
    let file = if spec.starts_with('-') {
        spec.split_whitespace().last()?
    } else {
        spec
    };
    let folder = mtl_path.parent().unwrap_or(Path::new(""));
    let candidates = [file.to_owned(), file.replace('\\', "/")];
    candidates
        .iter()
        .map(|f| folder.join(f))
        .find(|p| p.is_file())
}
