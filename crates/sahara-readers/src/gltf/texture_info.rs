//! glTF `textureInfo` objects, read from the file's JSON: which texture,
//! which uv set, and the `KHR_texture_transform` on them.
//!
//! They are read from the plain JSON rather than through the `gltf` crate
//! because the crate has no accessors for the texture transform of normal
//! and occlusion textures, nor for `KHR_materials_clearcoat`'s textures.

use glam::{Affine2, Mat2, Vec2};
use serde_json::Value;

/// A `textureInfo` as the file writes it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TextureInfo {
    /// Index into the file's `textures`.
    pub index: usize,
    /// The uv set (`texCoord`, overridden by the transform's own).
    pub tex_coord: u32,
    /// `KHR_texture_transform` (identity without it), in glTF's uv
    /// space (v down the image).
    pub transform: Affine2,
    /// `scale` of a normal texture, `strength` of an occlusion texture
    /// (1 when absent).
    pub amount: f32,
}

/// The number at `key` of `v`, if it is one.
fn number(v: &Value, key: &str) -> Option<f32> {
    v.get(key).and_then(Value::as_f64).map(|x| x as f32)
}

/// A pair of numbers at `key`.
fn pair(v: &Value, key: &str) -> Option<Vec2> {
    let a = v.get(key)?.as_array()?;
    match a.as_slice() {
        [x, y] => Some(Vec2::new(x.as_f64()? as f32, y.as_f64()? as f32)),
        _ => None,
    }
}

/// The `KHR_texture_transform` matrix: `T(offset) R(rotation) S(scale)`,
/// the rotation as the Khronos sample viewer and three.js apply it
/// (`u' = cos r u + sin r v`, `v' = -sin r u + cos r v`), which the
/// TextureTransformTest model's markers check.
pub(crate) fn khr_transform(offset: Vec2, rotation: f32, scale: Vec2) -> Affine2 {
    let (s, c) = rotation.sin_cos();
    let r = Mat2::from_cols(Vec2::new(c, -s), Vec2::new(s, c));
    Affine2::from_mat2_translation(r * Mat2::from_diagonal(scale), offset)
}

/// Reads the `textureInfo` at `key` of `parent` (`None` if absent or not
/// an object with an integer `index`; the amount's key is `amount_key`).
pub(crate) fn read(parent: &Value, key: &str, amount_key: &str) -> Option<TextureInfo> {
    let info = parent.get(key)?;
    let index = usize::try_from(info.get("index")?.as_u64()?).ok()?;
    let mut tex_coord = info
        .get("texCoord")
        .and_then(Value::as_u64)
        .map_or(0, |t| t.min(u32::MAX as u64) as u32);
    let mut transform = Affine2::IDENTITY;
    if let Some(t) = info
        .get("extensions")
        .and_then(|e| e.get("KHR_texture_transform"))
    {
        let offset = pair(t, "offset").unwrap_or(Vec2::ZERO);
        let rotation = number(t, "rotation").unwrap_or(0.0);
        let scale = pair(t, "scale").unwrap_or(Vec2::ONE);
        let m = khr_transform(offset, rotation, scale);
        if m.is_finite() {
            transform = m;
        }
        if let Some(t) = t.get("texCoord").and_then(Value::as_u64) {
            tex_coord = t.min(u32::MAX as u64) as u32;
        }
    }
    Some(TextureInfo {
        index,
        tex_coord,
        transform,
        amount: number(info, amount_key).unwrap_or(1.0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transform_order_is_translate_rotate_scale() {
        let m = khr_transform(
            Vec2::new(0.5, 0.25),
            std::f32::consts::FRAC_PI_2,
            Vec2::new(2.0, 3.0),
        );
        // (1, 0) scaled to (2, 0), rotated by a quarter turn the viewers'
        // way to (0, -2), offset to (0.5, -1.75).
        let p = m.transform_point2(Vec2::X);
        assert!((p - Vec2::new(0.5, -1.75)).length() < 1e-6, "{p}");
        let q = m.transform_point2(Vec2::Y);
        // (0, 1) scaled to (0, 3), rotated to (3, 0), offset.
        assert!((q - Vec2::new(3.5, 0.25)).length() < 1e-6, "{q}");
    }

    #[test]
    fn reads_the_extension_and_its_tex_coord() {
        let v: Value = serde_json::from_str(
            r#"{"normalTexture": {"index": 3, "texCoord": 0, "scale": 0.5,
                "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "texCoord": 1}}}}"#,
        )
        .unwrap();
        let t = read(&v, "normalTexture", "scale").unwrap();
        assert_eq!((t.index, t.tex_coord, t.amount), (3, 1, 0.5));
        assert_eq!(t.transform.translation, Vec2::new(0.5, 0.0));
        assert!(read(&v, "occlusionTexture", "strength").is_none());
    }
}
