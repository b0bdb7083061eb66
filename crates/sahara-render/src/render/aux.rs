//! The images a denoiser and a compositor use besides the beauty (render
//! passes, AOVs): albedo, normal, depth, position, texture coordinates and
//! the variance of the pixel's estimate, as exact sums; and the object and
//! material ids of what each pixel's centre shows (`ids`).

use glam::{Vec2, Vec3};

use crate::film::sums::{SumBuffer, FRACTION_BITS};
use crate::integrator::AuxSample;
use crate::names::{name_table, Named};

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
    /// [`AuxImages::position`].
    Position,
    /// [`AuxImages::uv`].
    Uv,
    /// [`AuxImages::variance`].
    Variance,
    /// [`AuxImages::object`].
    Object,
    /// [`AuxImages::material`].
    Material,
}

name_table!(Aov, "render pass", {
    Aov::Albedo => "albedo",
    Aov::Normal => "normal",
    Aov::Depth => "depth",
    Aov::Position => "position",
    Aov::Uv => "uv",
    Aov::Variance => "variance",
    Aov::Object => "object",
    Aov::Material => "material",
});

/// The auxiliary images of a render and the exact sums they come from.
/// Each sample adds to its own pixel alone (a box over the pixel, whatever
/// the reconstruction filter): these images say what the pixel shows, not
/// how its light is filtered.
#[derive(Clone, Debug, PartialEq)]
pub struct Aux {
    /// The images of the window (those asked for; the others empty).
    pub images: AuxImages,
    /// Their exact sums, one buffer per pass asked for (two for the
    /// variance: the radiance and its square).
    pub sums: AuxSums,
}

/// The exact sums of the passes asked for (None: not asked for).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AuxSums {
    /// Albedo.
    pub albedo: Option<SumBuffer>,
    /// Shading normal.
    pub normal: Option<SumBuffer>,
    /// Camera distance in the first channel, over the samples that hit.
    pub depth: Option<SumBuffer>,
    /// World position of the first hit, over the samples that hit.
    pub position: Option<SumBuffer>,
    /// Texture coordinates of the first hit in the first two channels,
    /// over the samples that hit.
    pub uv: Option<SumBuffer>,
    /// The samples' radiance and its square, per channel (the variance).
    pub moments: Option<[SumBuffer; 2]>,
}

impl AuxSums {
    /// The passes present, in the order of [`Aov`].
    pub fn passes(&self) -> Vec<Aov> {
        let mut out: Vec<Aov> = self.buffers().into_iter().map(|(a, _, _)| a).collect();
        out.dedup();
        out
    }

    /// The buffers present, in the order of [`Aov`], each with its pass and
    /// a name: the pass's name, and for the variance `variance.sum` and
    /// `variance.square`.
    pub fn buffers(&self) -> Vec<(Aov, String, &SumBuffer)> {
        let mut out: Vec<(Aov, String, &SumBuffer)> = [
            (Aov::Albedo, &self.albedo),
            (Aov::Normal, &self.normal),
            (Aov::Depth, &self.depth),
            (Aov::Position, &self.position),
            (Aov::Uv, &self.uv),
        ]
        .into_iter()
        .filter_map(|(a, b)| Some((a, a.name().to_string(), b.as_ref()?)))
        .collect();
        if let Some([sum, square]) = &self.moments {
            let v = Aov::Variance.name();
            out.push((Aov::Variance, format!("{v}.sum"), sum));
            out.push((Aov::Variance, format!("{v}.square"), square));
        }
        out
    }

    /// [`AuxSums::buffers`], to fill.
    pub fn buffers_mut(&mut self) -> Vec<(Aov, String, &mut SumBuffer)> {
        let mut out: Vec<(Aov, String, &mut SumBuffer)> = [
            (Aov::Albedo, &mut self.albedo),
            (Aov::Normal, &mut self.normal),
            (Aov::Depth, &mut self.depth),
            (Aov::Position, &mut self.position),
            (Aov::Uv, &mut self.uv),
        ]
        .into_iter()
        .filter_map(|(a, b)| Some((a, a.name().to_string(), b.as_mut()?)))
        .collect();
        if let Some([sum, square]) = &mut self.moments {
            let v = Aov::Variance.name();
            out.push((Aov::Variance, format!("{v}.sum"), sum));
            out.push((Aov::Variance, format!("{v}.square"), square));
        }
        out
    }
}

/// What a denoiser (and a compositor) is told about each pixel, averaged
/// over its samples: the albedo and shading normal of the first surface
/// that is not a perfect mirror or smooth glass (seen through those); the
/// camera distance, world position and texture coordinates of the first
/// hit; and how uncertain the pixel's value is. Where a sample escapes,
/// the albedo is the environment's colour clamped to `[0, 1]` and the
/// normal zero (Intel Open Image Denoise's conventions); the first-hit
/// passes average the samples that hit (0 where none did). Passes not
/// asked for are empty.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AuxImages {
    /// Albedo in `[0, 1]` per pixel.
    pub albedo: Vec<Vec3>,
    /// World-space shading normal per pixel (an average: shorter than 1
    /// where the pixel's samples disagree).
    pub normal: Vec<Vec3>,
    /// Camera distance per pixel.
    pub depth: Vec<f32>,
    /// World-space position of the first hit per pixel.
    pub position: Vec<Vec3>,
    /// Texture coordinates (the first uv set) of the first hit per pixel.
    pub uv: Vec<Vec2>,
    /// Variance of the pixel's estimate per channel: the sample variance
    /// of its own samples divided by their number (0 with fewer than two).
    pub variance: Vec<Vec3>,
    /// The object the pixel's centre shows (not an average: the first
    /// surface the ray through the centre meets): the scene's instance
    /// index plus 1, 0 for none.
    pub object: Vec<u32>,
    /// The material the pixel's centre shows: the scene's material index
    /// plus 1, 0 for none.
    pub material: Vec<u32>,
}

impl Aux {
    /// Empty sums over `[x0, x0 + width) x [y0, y0 + height)` for the
    /// passes `aovs`.
    pub fn new(aovs: &[Aov], x0: u32, y0: u32, width: u32, height: u32) -> Self {
        let b = || SumBuffer::new(x0, y0, width, height);
        let asked = |a: Aov| aovs.contains(&a).then(b);
        Self {
            images: AuxImages::default(),
            sums: AuxSums {
                albedo: asked(Aov::Albedo),
                normal: asked(Aov::Normal),
                depth: asked(Aov::Depth),
                position: asked(Aov::Position),
                uv: asked(Aov::Uv),
                moments: aovs.contains(&Aov::Variance).then(|| [b(), b()]),
            },
        }
    }

    /// The images of `sums` (the passes they hold; the others empty).
    pub fn from_sums(sums: AuxSums) -> Self {
        let mut aux = Self {
            images: AuxImages::default(),
            sums,
        };
        aux.develop(None);
        aux
    }

    /// Adds one sample of pixel `(x, y)`: its auxiliary values `a` and its
    /// radiance `l` (as splatted into the beauty).
    #[inline]
    pub(crate) fn add_sample(&mut self, x: u32, y: u32, a: &AuxSample, l: Vec3) {
        let s = &mut self.sums;
        let add = |b: &mut Option<SumBuffer>, v: Vec3| {
            if let Some(b) = b {
                if let Some(k) = b.index(x, y) {
                    b.sums[k].add_sample(v, 1.0);
                }
            }
        };
        add(&mut s.albedo, a.albedo);
        add(&mut s.normal, a.normal);
        // The first-hit passes average the samples that hit: a miss mixed
        // in would pull silhouettes towards the camera (or the origin).
        if a.depth > 0.0 {
            add(&mut s.depth, Vec3::new(a.depth, 0.0, 0.0));
            add(&mut s.position, a.position);
            add(&mut s.uv, a.uv.extend(0.0));
        }
        if let Some([sum, squares]) = &mut s.moments {
            if let Some(k) = sum.index(x, y) {
                sum.sums[k].add_sample(l, 1.0);
                squares.sums[k].add_sample(l * l, 1.0);
            }
        }
    }

    /// Adds `other`'s sums.
    pub fn add(&mut self, other: &Aux) {
        let (a, b) = (&mut self.sums, &other.sums);
        for (x, y) in [
            (&mut a.albedo, &b.albedo),
            (&mut a.normal, &b.normal),
            (&mut a.depth, &b.depth),
            (&mut a.position, &b.position),
            (&mut a.uv, &b.uv),
        ] {
            if let (Some(x), Some(y)) = (x, y) {
                x.add(y);
            }
        }
        if let (Some(x), Some(y)) = (&mut a.moments, &b.moments) {
            x[0].add(&y[0]);
            x[1].add(&y[1]);
        }
    }

    /// The images from the sums, black where `finished` says a pixel was
    /// not finished.
    pub(crate) fn develop(&mut self, finished: Option<&[bool]>) {
        let keep = |k: usize| finished.is_none_or(|f| f[k]);
        let mean = |b: &Option<SumBuffer>| -> Vec<Vec3> {
            b.as_ref().map_or_else(Vec::new, |b| {
                b.sums
                    .iter()
                    .enumerate()
                    .map(|(k, p)| if keep(k) { p.mean() } else { Vec3::ZERO })
                    .collect()
            })
        };
        let s = &self.sums;
        let variance = s.moments.as_ref().map_or_else(Vec::new, |[sum, squares]| {
            sum.sums
                .iter()
                .zip(&squares.sums)
                .enumerate()
                .map(|(k, (a, b))| {
                    let f = |v: i128| v as f64 / (1u64 << FRACTION_BITS) as f64;
                    // Every sample weighs 1, so the weight is the count.
                    let n = f(a.weight);
                    if !keep(k) || n < 2.0 {
                        return Vec3::ZERO;
                    }
                    // The sample variance from the exact sums, then that
                    // of the mean of n samples.
                    let var = |c: usize| {
                        let (m, m2) = (f(a.rgb[c]) / n, f(b.rgb[c]) / n);
                        ((m2 - m * m).max(0.0) / (n - 1.0)) as f32
                    };
                    Vec3::new(var(0), var(1), var(2))
                })
                .collect()
        });
        self.images = AuxImages {
            albedo: mean(&s.albedo),
            normal: mean(&s.normal),
            depth: mean(&s.depth).iter().map(|d| d.x).collect(),
            position: mean(&s.position),
            uv: mean(&s.uv).iter().map(|v| v.truncate()).collect(),
            variance,
            object: std::mem::take(&mut self.images.object),
            material: std::mem::take(&mut self.images.material),
        };
    }
}
