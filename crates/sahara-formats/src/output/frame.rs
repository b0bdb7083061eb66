//! A rendered frame written out: how ([`OutputSettings`]), the image (PNG
//! or EXR, atomically, with its metadata and render passes as layers),
//! the checks on its path made before anything is loaded or rendered, the
//! rule that keeps a complete image from being replaced by a partial one,
//! and the list of names beside the `object` and `material` passes. `sahara render`,
//! `sahara merge` and the Python package's `render` write through here.

use std::io::Write;
use std::path::{Path, PathBuf};

use sahara_readers::FormatError;
use sahara_render::{Aov, AuxImages, FrameSettings, Integrator, Named, RenderResult};

use sahara_render::{layered, ToneMap};

use super::atomic::{check_writable, write_atomically};
use super::image::{write_exr_layers, write_image, ExrLayer, ImageFormat, Pixels};

layered! {
    /// How a frame is written out: the look of an 8-bit image, the render
    /// passes beside it, and whether it is denoised. A render's output
    /// and a farm's part files both carry it.
    pub struct OutputSettings;
    /// Some of how a frame is written, as a scene file or a caller gives
    /// it (`None`: not given).
    pub struct OutputLayer;
    {
        /// Exposure in stops for 8-bit output (pixels scaled by
        /// `2^exposure`).
        exposure: f32 = 0.0;
        /// Tone map for 8-bit output.
        tonemap: ToneMap = ToneMap::Clamp;
        /// Render passes written beside the beauty, as layers of an EXR
        /// (sorted, each once, once decided by the request).
        aovs: Vec<Aov> = Vec::new();
        /// Denoise the image with Intel Open Image Denoise, guided by the
        /// albedo and normal of what each pixel sees.
        denoise: bool = false;
    }
}

/// Checks, before anything is loaded or rendered, that `path` names an
/// image Sahara writes (`.png` or `.exr`, or `.exr` only for a part) in a
/// folder where it can be written, and that an existing file there may be
/// replaced (not read-only).
pub fn check_output(path: &Path, part: bool) -> Result<(), FormatError> {
    let name = path.display().to_string();
    if path.is_dir() {
        return Err(FormatError::in_file(
            &name,
            format!(
                "is a folder; name an image file in it, e.g. {}",
                path.join(if part { "part.exr" } else { "image.png" })
                    .display()
            ),
        ));
    }
    let format = ImageFormat::from_path(path)?;
    if part && format != ImageFormat::Exr {
        return Err(FormatError::in_file(
            &name,
            "a part of a frame is written as OpenEXR: name a .exr file",
        ));
    }
    if path.metadata().is_ok_and(|m| m.permissions().readonly()) {
        return Err(FormatError::in_file(
            &name,
            "the file is read-only: not replaced (make it writable, or write elsewhere)",
        ));
    }
    check_writable(path)
}

/// Where a partial image (a preview, an interrupted render) of `path`
/// goes: `path` itself if nothing is there yet, else beside it as
/// `<stem>.partial.<ext>`, so that a complete image from an earlier run is
/// never replaced by an incomplete one.
pub fn partial_path(path: &Path, existed: bool) -> PathBuf {
    if !existed {
        return path.to_path_buf();
    }
    let stem = path
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let ext = path
        .extension()
        .map_or_else(String::new, |e| e.to_string_lossy().into_owned());
    path.with_file_name(format!("{stem}.partial.{ext}"))
}

/// True if `path` ends in `.exr` (any case).
pub fn is_exr(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

/// Where and how a rendered frame's image is written.
pub struct FrameImage<'a> {
    /// The image file.
    pub path: PathBuf,
    /// The frame (its integrator and seed go into the metadata; the depth
    /// view is mapped to grey in a PNG).
    pub frame: &'a FrameSettings,
    /// Exposure, tone map (for a PNG), and the render passes written as
    /// layers beside the beauty (EXR only).
    pub look: &'a OutputSettings,
    /// The image before denoising (linear RGB), written as the layer
    /// `noisy` of an EXR.
    pub noisy: Option<&'a [f32]>,
}

impl FrameImage<'_> {
    /// Writes `result` (atomically), marked `partial` or not. Returns what
    /// a debug view's colours mean, for the log (the depth view's range).
    pub fn write(
        &self,
        result: &RenderResult,
        partial: bool,
    ) -> Result<Option<String>, FormatError> {
        let frame = self.frame;
        let s = &result.stats;
        let exr = is_exr(&self.path);
        let rgb = result.film.to_rgb_f32();
        let mut said = None;
        let rgb8 = if exr {
            Vec::new()
        } else if matches!(frame.integrator, Integrator::Depth) {
            // Raw distances would be a flat white or grey: map the nearest
            // to the farthest hit onto white to dark grey (EXR keeps them raw).
            let range = depth_range(&rgb, result.film.width, result.film.height);
            said = Some(match range {
                Some((near, far)) => format!(
                    "depth: nearest hit {near:.4} (white) to farthest {far:.4} (dark grey), \
                     no hit black; EXR output keeps the raw distances"
                ),
                None => "depth: no ray hit anything".to_string(),
            });
            depth_to_gray8(&rgb, range)
        } else {
            result.film.to_srgb8(self.look.exposure, self.look.tonemap)
        };
        let pixels = if exr {
            Pixels::LinearRgbF32(&rgb)
        } else {
            Pixels::Rgb8(&rgb8)
        };
        // The film is the window's when the scene file crops the image.
        let (width, height) = (result.film.width, result.film.height);
        let finished = if s.passes == 0 {
            s.first_pass_pixels
        } else {
            u64::from(width) * u64::from(height)
        };
        let metadata = vec![
            (
                "sahara:integrator".to_string(),
                frame.integrator.name().to_string(),
            ),
            ("sahara:spp".to_string(), s.spp.to_string()),
            ("sahara:seed".to_string(), frame.seed.to_string()),
            ("sahara:partial".to_string(), partial.to_string()),
            ("sahara:finished_pixels".to_string(), finished.to_string()),
        ];
        let passes = match &result.aux {
            Some(aux) => aov_layers(&self.look.aovs, &aux.images),
            None => Vec::new(),
        };
        let mut layers: Vec<ExrLayer> = passes
            .iter()
            .map(|(aov, channels, values)| ExrLayer {
                name: aov.name(),
                channels,
                values,
            })
            .collect();
        let samples: Option<Vec<f32>> = result
            .samples
            .as_ref()
            .map(|n| n.iter().map(|&n| n as f32).collect());
        if let Some(samples) = &samples {
            layers.push(ExrLayer {
                name: "samples",
                channels: &["Y"],
                values: samples,
            });
        }
        if let Some(noisy) = self.noisy {
            layers.push(ExrLayer {
                name: "noisy",
                channels: &["R", "G", "B"],
                values: noisy,
            });
        }
        if exr && !layers.is_empty() {
            write_exr_layers(&self.path, width, height, &rgb, &layers, &metadata)?;
        } else {
            write_image(&self.path, width, height, pixels, &metadata)?;
        }
        Ok(said)
    }
}

/// Vectors as interleaved floats.
pub fn flat(v: &[glam::Vec3]) -> Vec<f32> {
    v.iter().flat_map(|p| p.to_array()).collect()
}

/// Ids as floats.
fn ids(v: &[u32]) -> Vec<f32> {
    v.iter().map(|&id| id as f32).collect()
}

/// Each pass's channel names and values, interleaved per pixel.
fn aov_layers(aovs: &[Aov], images: &AuxImages) -> Vec<(Aov, &'static [&'static str], Vec<f32>)> {
    let mut aovs = aovs.to_vec();
    aovs.sort();
    aovs.dedup();
    aovs.into_iter()
        .map(|aov| match aov {
            Aov::Albedo => (aov, &["R", "G", "B"][..], flat(&images.albedo)),
            Aov::Normal => (aov, &["X", "Y", "Z"][..], flat(&images.normal)),
            Aov::Depth => (aov, &["Z"][..], images.depth.clone()),
            Aov::Position => (aov, &["X", "Y", "Z"][..], flat(&images.position)),
            Aov::Uv => (
                aov,
                &["U", "V"][..],
                images.uv.iter().flat_map(|v| v.to_array()).collect(),
            ),
            Aov::Variance => (aov, &["R", "G", "B"][..], flat(&images.variance)),
            // Whole numbers, exact in a float up to 2^24.
            Aov::Object => (aov, &["id"][..], ids(&images.object)),
            Aov::Material => (aov, &["id"][..], ids(&images.material)),
        })
        .collect()
}

/// The nearest and farthest distance in a depth image (0 is no hit).
///
/// The filter blends hit distances with the zeros of missed samples near
/// silhouettes, which would make them look nearest: the nearest distance
/// is taken from pixels at least [`SILHOUETTE_MARGIN`] pixels from any
/// pixel without a hit (all pixels if none is that far).
fn depth_range(rgb: &[f32], width: u32, height: u32) -> Option<(f32, f32)> {
    let (w, h) = (width as usize, height as usize);
    let d = |x: usize, y: usize| rgb[3 * (y * w + x)];
    let hit = |v: f32| v > 0.0 && v.is_finite();
    let far = (0..w * h)
        .map(|k| rgb[3 * k])
        .filter(|&v| hit(v))
        .fold(0.0f32, f32::max);
    if far <= 0.0 {
        return None;
    }
    let m = SILHOUETTE_MARGIN;
    let interior = |x: usize, y: usize| {
        (y.saturating_sub(m)..(y + m + 1).min(h))
            .all(|j| (x.saturating_sub(m)..(x + m + 1).min(w)).all(|i| hit(d(i, j))))
    };
    let nearest = |only_interior: bool| {
        (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .filter(|&(x, y)| hit(d(x, y)) && (!only_interior || interior(x, y)))
            .map(|(x, y)| d(x, y))
            .fold(f32::INFINITY, f32::min)
    };
    let near = match nearest(true) {
        n if n.is_finite() => n,
        _ => nearest(false),
    };
    Some((near.min(far), far))
}

/// Pixels around a silhouette that [`depth_range`] leaves out of the nearest distance.
const SILHOUETTE_MARGIN: usize = 3;

/// A depth image as 8-bit grey: `near` white, `far` dark grey (26), no hit black.
fn depth_to_gray8(rgb: &[f32], range: Option<(f32, f32)>) -> Vec<u8> {
    let Some((near, far)) = range else {
        return vec![0; rgb.len()];
    };
    let span = (far - near).max(f32::MIN_POSITIVE);
    rgb.iter()
        .step_by(3)
        .flat_map(|&d| {
            let v = if d > 0.0 && d.is_finite() {
                let t = ((d - near) / span).clamp(0.0, 1.0);
                (255.0 * (1.0 - 0.9 * t)).round() as u8
            } else {
                0
            };
            [v; 3]
        })
        .collect()
}

/// Where the list of names of the image `image` goes.
pub fn names_path(image: &Path) -> PathBuf {
    let stem = image
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    image.with_file_name(format!("{stem}.names.json"))
}

/// Writes the list of names `text` beside `image`, atomically.
pub fn write_names_beside(image: &Path, text: &str) -> Result<(), FormatError> {
    let path = names_path(image);
    write_atomically(&path, |out| {
        out.write_all(text.as_bytes())
            .map_err(|e| FormatError::write(&path, e))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `w x h` depth image (three equal channels per pixel) from `f(x, y)`.
    fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> f32) -> Vec<f32> {
        (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .flat_map(|(x, y)| [f(x, y); 3])
            .collect()
    }

    #[test]
    fn depth_range_ignores_silhouette_blends() {
        // A 10x10 object at distance 2 to 3 on a background of misses; its
        // border pixels are blends with the misses (0.5).
        let rgb = image(20, 20, |x, y| {
            let inside = (5..15).contains(&x) && (5..15).contains(&y);
            let border = x == 5 || x == 14 || y == 5 || y == 14;
            match (inside, border) {
                (false, _) => 0.0,
                (true, true) => 0.5,
                (true, false) => 2.0 + x as f32 / 20.0,
            }
        });
        let (near, far) = depth_range(&rgb, 20, 20).unwrap();
        assert!(near >= 2.0, "near {near}");
        assert!((far - (2.0 + 13.0 / 20.0)).abs() < 1e-6, "far {far}");
        let grey = depth_to_gray8(&rgb, Some((near, far)));
        assert_eq!(grey[0], 0, "a miss is black");
        assert_eq!(grey[3 * (20 * 6 + 13)], 26, "the farthest hit is dark grey");
        // No hit at all: no range, a black image.
        let none = image(4, 4, |_, _| 0.0);
        assert_eq!(depth_range(&none, 4, 4), None);
        assert!(depth_to_gray8(&none, None).iter().all(|&v| v == 0));
    }

    #[test]
    fn a_partial_image_goes_beside_an_existing_one() {
        let p = Path::new("out/frame.exr");
        assert_eq!(partial_path(p, false), p);
        assert_eq!(partial_path(p, true), Path::new("out/frame.partial.exr"));
        assert_eq!(
            partial_path(Path::new("x.PNG"), true),
            Path::new("x.partial.PNG")
        );
    }
}
