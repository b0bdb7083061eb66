//! The rendered image: linear RGB floats, and conversions for display.

pub mod filter;
pub(crate) mod splat;
pub mod sums;
pub mod window;

use glam::Vec3;

use crate::names::name_table;

/// A linear-RGB image, rows from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` pixels, row-major from the top-left corner.
    pub pixels: Vec<Vec3>,
}

/// How linear radiance becomes display values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ToneMap {
    /// Clamp to `[0, 1]`.
    #[default]
    Clamp,
    /// Narkowicz's fit of the ACES filmic curve: soft highlights.
    Filmic,
}

name_table!(ToneMap, "tone map", {
    ToneMap::Clamp => "clamp",
    ToneMap::Filmic => "filmic",
});

impl Film {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![Vec3::ZERO; width as usize * height as usize],
        }
    }

    /// The pixel at column `x`, row `y`.
    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[(y * self.width + x) as usize]
    }

    /// Mean of the pixels in the rectangle `[x0, x1) x [y0, y1)`.
    pub fn mean(&self, x0: u32, y0: u32, x1: u32, y1: u32) -> Vec3 {
        let mut sum = glam::DVec3::ZERO;
        for y in y0..y1 {
            for x in x0..x1 {
                sum += self.get(x, y).as_dvec3();
            }
        }
        let n = ((x1 - x0) * (y1 - y0)).max(1) as f64;
        (sum / n).as_vec3()
    }

    /// Interleaved RGB floats (what EXR/PFM writers take).
    pub fn to_rgb_f32(&self) -> Vec<f32> {
        self.pixels.iter().flat_map(|p| p.to_array()).collect()
    }

    /// Interleaved 8-bit sRGB: radiance times `2^exposure`, tone mapped,
    /// sRGB-encoded and rounded.
    pub fn to_srgb8(&self, exposure: f32, tone: ToneMap) -> Vec<u8> {
        let scale = exposure.exp2();
        self.pixels
            .iter()
            .flat_map(|p| {
                let c = *p * scale;
                let c = match tone {
                    ToneMap::Clamp => c,
                    ToneMap::Filmic => c.to_array().map(aces_filmic).into(),
                };
                c.to_array().map(|v| (srgb_encode(v) * 255.0 + 0.5) as u8)
            })
            .collect()
    }

    /// A binary PPM (P6) of [`Film::to_srgb8`], for quick looks.
    pub fn to_ppm(&self, exposure: f32, tone: ToneMap) -> Vec<u8> {
        let mut out = format!("P6\n{} {}\n255\n", self.width, self.height).into_bytes();
        out.extend(self.to_srgb8(exposure, tone));
        out
    }
}

/// The sRGB transfer function on a linear value, clamped to `[0, 1]`
/// (NaN maps to 0).
pub fn srgb_encode(v: f32) -> f32 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Narkowicz 2015's rational fit of the ACES filmic tone curve.
pub fn aces_filmic(x: f32) -> f32 {
    let x = x.max(0.0);
    ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0)
}

/// A black-blue-green-yellow-red-white colour ramp for `t` in `[0, 1]`.
pub fn heat_color(t: f32) -> Vec3 {
    const STOPS: [Vec3; 6] = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, 1.0, 1.0),
    ];
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) } * (STOPS.len() - 1) as f32;
    let i = (t as usize).min(STOPS.len() - 2);
    STOPS[i].lerp(STOPS[i + 1], t - i as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_endpoints_and_midpoint() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        // 0.2140 linear is 0.5 in sRGB (the standard's curve).
        assert!((srgb_encode(0.214_041) - 0.5).abs() < 1e-4);
        let f = Film {
            width: 1,
            height: 1,
            pixels: vec![Vec3::new(0.5, 2.0, f32::NAN)],
        };
        assert_eq!(f.to_srgb8(1.0, ToneMap::Clamp), vec![255, 255, 0]);
    }
}
