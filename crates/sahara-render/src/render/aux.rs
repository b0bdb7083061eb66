//! The images a denoiser and a compositor use besides the beauty: albedo,
//! normal and depth per pixel, as exact sums.

use glam::Vec3;

use crate::film::sums::SumBuffer;
use crate::integrator::AuxSample;
use crate::names::name_table;

/// An auxiliary image a render can write beside the beauty (a render
/// pass, an AOV).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Aov {
    /// [`AuxImages::albedo`].
    Albedo,
    /// [`AuxImages::normal`].
    Normal,
    /// [`AuxImages::depth`].
    Depth,
}

name_table!(Aov, "render pass", {
    Aov::Albedo => "albedo",
    Aov::Normal => "normal",
    Aov::Depth => "depth",
});

/// The auxiliary images of a render and the exact sums they come from.
/// Each sample adds to its own pixel alone (a box over the pixel, whatever
/// the reconstruction filter): these images say what the pixel shows, not
/// how its light is filtered.
#[derive(Clone, Debug, PartialEq)]
pub struct Aux {
    /// The images of the window.
    pub images: AuxImages,
    /// Their exact sums: albedo, normal, and the depth in the first channel.
    pub sums: [SumBuffer; 3],
}

/// What a denoiser (and a compositor) is told about each pixel, averaged
/// over its samples: the albedo and shading normal of the first surface
/// that is not a perfect mirror or smooth glass (seen through those), and
/// the camera distance of the first hit. Where a sample escapes, the
/// albedo is the environment's colour clamped to `[0, 1]`, the normal zero
/// and the distance 0 (Intel Open Image Denoise's conventions).
#[derive(Clone, Debug, PartialEq)]
pub struct AuxImages {
    /// Albedo in `[0, 1]` per pixel.
    pub albedo: Vec<Vec3>,
    /// World-space shading normal per pixel (an average: shorter than 1
    /// where the pixel's samples disagree).
    pub normal: Vec<Vec3>,
    /// Camera distance per pixel.
    pub depth: Vec<f32>,
}

impl Aux {
    pub(crate) fn new(x0: u32, y0: u32, width: u32, height: u32) -> Self {
        let b = || SumBuffer::new(x0, y0, width, height);
        Self {
            images: AuxImages {
                albedo: Vec::new(),
                normal: Vec::new(),
                depth: Vec::new(),
            },
            sums: [b(), b(), b()],
        }
    }

    /// Adds one sample of pixel `(x, y)`.
    #[inline]
    pub(crate) fn add_sample(&mut self, x: u32, y: u32, a: &AuxSample) {
        let [albedo, normal, depth] = &mut self.sums;
        if let Some(k) = albedo.index(x, y) {
            albedo.sums[k].add_sample(a.albedo, 1.0);
            normal.sums[k].add_sample(a.normal, 1.0);
            // The mean distance of the samples that hit: a miss (0) mixed
            // in would pull silhouettes towards the camera.
            if a.depth > 0.0 {
                depth.sums[k].add_sample(Vec3::new(a.depth, 0.0, 0.0), 1.0);
            }
        }
    }

    /// Adds `other`'s sums.
    pub(crate) fn add(&mut self, other: &Aux) {
        for (a, b) in self.sums.iter_mut().zip(&other.sums) {
            a.add(b);
        }
    }

    /// The images from the sums, black where `finished` says a pixel was
    /// not finished.
    pub(crate) fn develop(&mut self, finished: Option<&[bool]>) {
        let keep = |k: usize| finished.is_none_or(|f| f[k]);
        let mean = |b: &SumBuffer| -> Vec<Vec3> {
            b.sums
                .iter()
                .enumerate()
                .map(|(k, p)| if keep(k) { p.mean() } else { Vec3::ZERO })
                .collect()
        };
        self.images = AuxImages {
            albedo: mean(&self.sums[0]),
            normal: mean(&self.sums[1]),
            depth: mean(&self.sums[2]).iter().map(|d| d.x).collect(),
        };
    }
}
