//! One level of a texture's MIP pyramid, and building the pyramid.
//!
//! Each level averages the one before it over exact areas (a box filter
//! of width 2 for even sizes, and of the exact ratio for odd ones, so a
//! 5-texel row becomes 2 texels of 2.5 source texels each: no texel is
//! dropped and the mean stays the same). Averages are taken of linear
//! values and stored back in the base level's form.

use glam::{Vec3, Vec4};

use super::{linear_to_srgb8, srgb8_to_linear, Encoding};

/// Texels of one level.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Texels {
    /// Linear float RGB, with an optional alpha channel.
    F32 {
        rgb: Vec<Vec3>,
        alpha: Option<Vec<f32>>,
    },
    /// 8-bit RGBA.
    Rgba8 {
        data: Vec<[u8; 4]>,
        encoding: Encoding,
        has_alpha: bool,
    },
}

/// One level of the pyramid.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Level {
    pub width: u32,
    pub height: u32,
    pub texels: Texels,
}

impl Level {
    pub fn rgb_f32(width: u32, height: u32, rgb: Vec<Vec3>) -> Self {
        assert_eq!(rgb.len(), width as usize * height as usize, "texel count");
        Self {
            width,
            height,
            texels: Texels::F32 { rgb, alpha: None },
        }
    }

    pub fn rgba8(
        width: u32,
        height: u32,
        data: Vec<[u8; 4]>,
        encoding: Encoding,
        has_alpha: bool,
    ) -> Self {
        assert_eq!(data.len(), width as usize * height as usize, "texel count");
        Self {
            width,
            height,
            texels: Texels::Rgba8 {
                data,
                encoding,
                has_alpha,
            },
        }
    }

    pub fn len(&self) -> usize {
        self.width as usize * self.height as usize
    }

    pub fn format(&self) -> &'static str {
        match &self.texels {
            Texels::F32 { alpha: None, .. } => "float RGB",
            Texels::F32 { .. } => "float RGBA",
            Texels::Rgba8 {
                encoding: Encoding::Srgb,
                ..
            } => "8-bit sRGB",
            Texels::Rgba8 { .. } => "8-bit linear",
        }
    }

    pub fn has_alpha(&self) -> bool {
        match &self.texels {
            Texels::F32 { alpha, .. } => alpha.is_some(),
            Texels::Rgba8 { has_alpha, .. } => *has_alpha,
        }
    }

    pub fn set_alpha(&mut self, a: Vec<f32>) {
        assert_eq!(a.len(), self.len(), "alpha count");
        match &mut self.texels {
            Texels::F32 { alpha, .. } => *alpha = Some(a),
            Texels::Rgba8 {
                data, has_alpha, ..
            } => {
                for (t, a) in data.iter_mut().zip(a) {
                    t[3] = (a.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
                }
                *has_alpha = true;
            }
        }
    }

    pub fn memory_bytes(&self) -> usize {
        match &self.texels {
            Texels::F32 { rgb, alpha } => {
                rgb.len() * 12 + alpha.as_ref().map_or(0, |a| a.len() * 4)
            }
            Texels::Rgba8 { data, .. } => data.len() * 4,
        }
    }

    /// Linear RGBA of texel `i` (alpha 1 without an alpha channel).
    #[inline]
    pub fn get(&self, i: usize) -> Vec4 {
        match &self.texels {
            Texels::F32 { rgb, alpha } => rgb[i].extend(alpha.as_ref().map_or(1.0, |a| a[i])),
            Texels::Rgba8 {
                data,
                encoding,
                has_alpha,
            } => {
                let t = data[i];
                let a = if *has_alpha { t[3] as f32 / 255.0 } else { 1.0 };
                match encoding {
                    Encoding::Srgb => Vec4::new(
                        srgb8_to_linear(t[0]),
                        srgb8_to_linear(t[1]),
                        srgb8_to_linear(t[2]),
                        a,
                    ),
                    Encoding::Linear => Vec4::new(
                        t[0] as f32 / 255.0,
                        t[1] as f32 / 255.0,
                        t[2] as f32 / 255.0,
                        a,
                    ),
                }
            }
        }
    }

    /// A level of `width x height` holding `values` (linear RGBA) in this
    /// level's form.
    fn like(&self, width: u32, height: u32, values: Vec<Vec4>) -> Level {
        let texels = match &self.texels {
            Texels::F32 { alpha, .. } => Texels::F32 {
                rgb: values.iter().map(|v| v.truncate()).collect(),
                alpha: alpha.as_ref().map(|_| values.iter().map(|v| v.w).collect()),
            },
            Texels::Rgba8 {
                encoding,
                has_alpha,
                ..
            } => {
                let code = |v: f32| match encoding {
                    Encoding::Srgb => linear_to_srgb8(v),
                    Encoding::Linear => (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8,
                };
                Texels::Rgba8 {
                    data: values
                        .iter()
                        .map(|v| {
                            [
                                code(v.x),
                                code(v.y),
                                code(v.z),
                                (v.w.clamp(0.0, 1.0) * 255.0 + 0.5) as u8,
                            ]
                        })
                        .collect(),
                    encoding: *encoding,
                    has_alpha: *has_alpha,
                }
            }
        };
        Level {
            width,
            height,
            texels,
        }
    }
}

/// The source texels (and their weights) that output texel `i` of a row
/// of `n_out` covers in a row of `n_in` (`n_out = max(1, n_in / 2)`):
/// the exact overlap of `[i r, (i + 1) r)`, `r = n_in / n_out`, with each
/// source texel, weights summing to 1.
pub(crate) fn box_weights(n_in: u32, n_out: u32, i: u32) -> Vec<(u32, f32)> {
    let r = n_in as f64 / n_out as f64;
    let (start, end) = (i as f64 * r, (i as f64 + 1.0) * r);
    let mut out = Vec::with_capacity(4);
    let mut j = start.floor() as u32;
    while (j as f64) < end && j < n_in {
        let w = (end.min(j as f64 + 1.0) - start.max(j as f64)) / r;
        if w > 0.0 {
            out.push((j, w as f32));
        }
        j += 1;
    }
    out
}

/// The next level down: half the size (rounded down, at least 1).
fn downsample(l: &Level) -> Level {
    let (w, h) = ((l.width / 2).max(1), (l.height / 2).max(1));
    let cols: Vec<Vec<(u32, f32)>> = (0..w).map(|x| box_weights(l.width, w, x)).collect();
    // Rows first, then columns (the box filter is separable).
    let mut rows = vec![Vec4::ZERO; w as usize * l.height as usize];
    for y in 0..l.height as usize {
        for (x, c) in cols.iter().enumerate() {
            rows[y * w as usize + x] = c
                .iter()
                .map(|&(j, wt)| l.get(y * l.width as usize + j as usize) * wt)
                .sum();
        }
    }
    let mut out = Vec::with_capacity(w as usize * h as usize);
    for y in 0..h {
        let r = box_weights(l.height, h, y);
        for x in 0..w as usize {
            out.push(
                r.iter()
                    .map(|&(j, wt)| rows[j as usize * w as usize + x] * wt)
                    .sum(),
            );
        }
    }
    l.like(w, h, out)
}

/// Every level below `base`, down to 1x1.
pub(crate) fn build(base: &Level) -> Vec<Level> {
    let mut out: Vec<Level> = Vec::new();
    while {
        let last = out.last().unwrap_or(base);
        last.width > 1 || last.height > 1
    } {
        let next = downsample(out.last().unwrap_or(base));
        out.push(next);
    }
    if out.is_empty() {
        // A 1x1 texture: its only level stands for every other.
        out.push(base.clone());
    }
    out
}
