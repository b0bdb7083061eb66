//! The sRGB transfer function (IEC 61966-2-1), both ways.

/// A linear value clamped to `[0, 1]`, sRGB-encoded and rounded to 8 bits (NaN gives 0).
pub fn linear_to_srgb8(v: f32) -> u8 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    let s = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5).clamp(0.0, 255.0) as u8
}

/// The linear value of an 8-bit sRGB code.
pub fn srgb8_to_linear(v: u8) -> f32 {
    srgb_to_linear(v as f32 / 255.0)
}

/// The linear value of an sRGB-encoded value in `[0, 1]`.
pub fn srgb_to_linear(s: f32) -> f32 {
    if s <= 0.040_45 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}
